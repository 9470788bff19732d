"""Strategies over poses: the pose policy against the recognition planner on the footprints,
and the ``poses`` and ``plan MESH`` commands."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.geometry import Part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.policy import Declare, Reject, plan_policy
from bayesgrasp.solid.mesh import read_mesh
from bayesgrasp.solid.parts import pose_parts
from bayesgrasp.solid.policy import plan_pose_policy
from bayesgrasp.solid.poses import resting_poses


def _wedge() -> trimesh.Trimesh:
    """A wedge: a right triangle (legs 3 and 1.5) extruded by 1: poses of distinct widths."""
    tri = np.array([[0, 0], [3, 0], [0, 1.5]], dtype=float)
    pts = np.array([[x, y, z] for x, z in tri for y in (0, 1)], dtype=float)
    return trimesh.convex.convex_hull(pts)


@pytest.fixture
def wedge_file(tmp_path: Path) -> Path:
    f = tmp_path / "wedge.stl"
    _wedge().export(f)
    return f


def _leaves(node):
    for b in node.branches:
        nxt = b.next
        if isinstance(nxt, Declare | Reject):
            yield nxt
        else:
            yield from _leaves(nxt)


def test_goal_pose_any_equals_the_recognition_planner(wedge_file: Path, capsys) -> None:
    solid = read_mesh(wedge_file)
    study = resting_poses(solid.vertices, solid.center_of_mass)
    parts = pose_parts(study)
    ref = plan_policy(
        [Problem.build(p) for p in parts], "width", 3, part_prior=list(study.probabilities)
    )
    pol = plan_pose_policy(study, "width", goal_pose=None, max_actions=3)
    assert_allclose(pol.expected_cost, ref.expected_cost, rtol=1e-12)
    assert main(["plan", str(wedge_file), "--sense", "width", "--goal-pose", "any", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["parts"] == [f"pose-{k}" for k in range(len(study.poses))]
    assert_allclose(doc["part_prior"], study.probabilities, rtol=1e-12)
    assert_allclose(doc["expected_cost"], ref.expected_cost, rtol=1e-12)
    # The footprints as separate part files, their probabilities as --part-prior: the same.
    files = []
    for p in parts:
        f = wedge_file.with_name(f"{p.name}.json")
        f.write_text(json.dumps({"vertices": p.hull.vertices.tolist(), "center_of_mass": [0, 0]}))
        files.append(str(f))
    prior = ",".join(repr(float(w)) for w in study.probabilities)
    argv = ["plan", files[0], *files[1:], "--sense", "width", "--part-prior", prior, "--json"]
    assert main(argv) == 0
    other = json.loads(capsys.readouterr().out)
    assert_allclose(other["expected_cost"], doc["expected_cost"], rtol=1e-12)


def test_goal_pose_k_declares_only_pose_k(wedge_file: Path, capsys) -> None:
    solid = read_mesh(wedge_file)
    study = resting_poses(solid.vertices, solid.center_of_mass)
    for k in (0, 1):
        pol = plan_pose_policy(study, "width", goal_pose=k, max_actions=3)
        leaves = list(_leaves(pol.root))
        assert all(x.part == k for x in leaves if isinstance(x, Declare))
        assert any(isinstance(x, Reject) for x in leaves)
        # Success is the goal pose's mass at most (others are dropped again).
        assert pol.success_probability <= study.poses[k].probability + 1e-12
    anyp = plan_pose_policy(study, "width", goal_pose=None, max_actions=3)
    assert anyp.expected_cost <= pol.expected_cost + 1e-12
    # a retry cost makes rejection dearer: the policy's cost rises
    dear = plan_pose_policy(study, "width", goal_pose=0, cost=None, max_actions=3)
    assert main(["plan", str(wedge_file), "--sense", "width", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert_allclose(doc["expected_cost"], dear.expected_cost, rtol=1e-12)
    argv = ["plan", str(wedge_file), "--sense", "width", "--retry-cost", "2", "--json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["expected_cost"] > doc["expected_cost"]


def test_plan_mesh_pose_k_is_the_footprint_part(wedge_file: Path, capsys) -> None:
    solid = read_mesh(wedge_file)
    study = resting_poses(solid.vertices, solid.center_of_mass)
    for k in range(len(study.poses)):
        assert main(["plan", str(wedge_file), "--pose", str(k), "--json"]) == 0
        doc = json.loads(capsys.readouterr().out)
        fp = Part.from_points(study.poses[k].footprint, name="x", center_of_mass=[0, 0])
        ref = plan_exact(Problem.build(fp))
        assert doc["part"]["name"] == f"wedge-pose-{k}"
        assert_allclose(doc["part"]["vertices"], fp.hull.vertices, atol=1e-12)
        got = doc["options"][doc["bayes"]]["expected_cost"]
        assert_allclose(got, ref.bayes_plan.expected_cost, rtol=1e-12)


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--pose", "7"], "pose '7' does not exist"),
        (["--goal-pose", "1"], "add --sense"),
        (["--sense", "width", "--pose", "1"], "--goal-pose K, not --pose"),
        (["--sense", "width", "--goal-pose", "9"], "does not exist"),
        (["--sense", "width", "--also", "house"], "candidates are its poses"),
        (["--sense", "width", "--pose-prior", "drops:0"], "N >= 1"),
        (["--sense", "width", "--pose-prior", "nosuch.json"], "expected quasi-static"),
        (["--com", "1,2"], "X,Y,Z"),
    ],
)
def test_plan_mesh_bad_options(wedge_file: Path, argv, match, capsys) -> None:
    assert main(["plan", str(wedge_file), *argv]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1


def test_pose_options_need_a_mesh(capsys) -> None:
    assert main(["plan", "house", "--pose", "1"]) == 2
    assert "for a mesh PART" in capsys.readouterr().err


def test_poses_json_schema_and_prior_file(wedge_file: Path, tmp_path: Path, capsys) -> None:
    assert main(["poses", str(wedge_file), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["schema"] == "bayesgrasp.poses/1"
    probs = [p["probability"] for p in doc["poses"]]
    assert probs == sorted(probs, reverse=True) and abs(sum(probs) - 1) < 1e-12
    for p in doc["poses"]:
        assert set(p) == {"probability", "normal", "com_height", "footprint"}
        assert abs(np.linalg.norm(p["normal"]) - 1) < 1e-12
    # a poses file as the pose prior: the same policy as the default quasi-static prior
    f = tmp_path / "poses.json"
    f.write_text(json.dumps(doc))
    assert (
        main(["plan", str(wedge_file), "--sense", "width", "--pose-prior", str(f), "--json"]) == 0
    )
    a = json.loads(capsys.readouterr().out)
    assert main(["plan", str(wedge_file), "--sense", "width", "--json"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert_allclose(a["expected_cost"], b["expected_cost"], rtol=1e-12)
    # text and figure
    png = tmp_path / "poses.png"
    assert main(["poses", str(wedge_file), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "stable poses (quasi-static)" in out and png.stat().st_size > 1000


def test_drops_glue_with_a_fake_engine(wedge_file: Path, monkeypatch, capsys) -> None:
    """FAKE ENGINE: ``bayesgrasp.sim.drops`` is replaced by a stand-in with the agreed
    interface (its counts are made up); this tests our glue, not the physics."""
    import sys
    import types

    calls = {}

    def drop_poses(vertices, faces, com, normals, trials, *, seed=0, **kw):
        calls["normals"] = np.array(normals)
        k = len(normals)
        counts = np.zeros(k, dtype=int)
        counts[-1] = trials  # every drop on the least probable pose
        return SimpleNamespace(
            counts=counts,
            unmatched=0,
            trials=trials,
            settings={"height": 0.1, "restitution": 0.2, "friction": 0.5, "time step": 0.001},
            frequencies=lambda: counts / trials,
            intervals=lambda confidence=0.95: np.c_[counts / trials - 0.01, counts / trials],
        )

    fake = types.ModuleType("bayesgrasp.sim.drops")
    fake.drop_poses = drop_poses  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "bayesgrasp.sim.drops", fake)
    assert main(["poses", str(wedge_file), "--drops", "50", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert_allclose(calls["normals"], [p["normal"] for p in doc["poses"]])
    assert doc["drops"]["counts"][-1] == 50 and doc["drops"]["trials"] == 50
    assert main(["poses", str(wedge_file), "--drops", "50"]) == 0
    assert "drops: 50 from uniform random orientations" in capsys.readouterr().out
    argv = ["plan", str(wedge_file), "--sense", "width", "--goal-pose", "any", "--json"]
    assert main([*argv, "--pose-prior", "drops:50"]) == 0
    pol = json.loads(capsys.readouterr().out)
    assert pol["part_prior"][-1] == 1.0 and sum(pol["part_prior"][:-1]) == 0


def test_simulate_and_plot_take_a_mesh_policy(wedge_file: Path, tmp_path: Path, capsys) -> None:
    """simulate and plot --sense plan the same pose policy as plan (goal pose 0)."""
    assert main(["plan", str(wedge_file), "--sense", "width", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    argv = ["simulate", str(wedge_file), "--sense", "width", "--trials", "4000", "--json"]
    assert main(argv) == 0
    sim = json.loads(capsys.readouterr().out)
    text = json.dumps(sim)
    assert "pose-0" in text and str(round(doc["expected_cost"], 6))[:6] in text
    assert main(["plot", str(wedge_file), "--sense", "width", "--out", str(tmp_path / "f")]) == 0
    assert (tmp_path / "f" / "policy.png").exists()
    assert main(["simulate", str(wedge_file), "--sense", "width", "--also", "house"]) == 2
    assert "candidates are its poses" in capsys.readouterr().err


def test_pose_prior_perturbed_is_near_the_quasi_static(wedge_file: Path, capsys) -> None:
    argv = ["plan", str(wedge_file), "--sense", "width", "--goal-pose", "any", "--json"]
    assert main([*argv, "--pose-prior", "perturbed"]) == 0
    pert = json.loads(capsys.readouterr().out)["part_prior"]
    assert main(argv) == 0
    qs = json.loads(capsys.readouterr().out)["part_prior"]
    assert_allclose(sum(pert), 1.0, atol=1e-12)
    assert_allclose(pert, qs, atol=0.03)


@pytest.mark.parametrize("command", ["simulate", "plot"])
def test_simulate_and_plot_take_the_pose_options(
    wedge_file: Path, tmp_path: Path, capsys, command: str
) -> None:
    """--goal-pose and --pose-prior reach simulate and plot as they reach plan."""
    plan = ["plan", str(wedge_file), "--sense", "width", "--goal-pose", "any", "--json"]
    assert main(plan) == 0
    doc = json.loads(capsys.readouterr().out)
    argv = [command, str(wedge_file), "--sense", "width", "--goal-pose", "any", "--json"]
    argv += ["--trials", "2000"] if command == "simulate" else ["--out", str(tmp_path / "f")]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    if command == "simulate":
        assert out["expected_cost"]["predicted"] == pytest.approx(doc["expected_cost"], 1e-12)
    else:
        assert (tmp_path / "f" / "policy.png").exists()
    assert main([command, str(wedge_file), "--goal-pose", "1"]) == 2  # no --sense
    assert "add --sense" in capsys.readouterr().err
    assert main([command, "house", "--sense", "width", "--pose-prior", "perturbed"]) == 2
    assert "for a mesh PART" in capsys.readouterr().err


def test_free_verification_rejects_a_pose_that_cannot_be_the_goal(wedge_file: Path) -> None:
    """Verify cost 0: declaring a non-goal pose costs what rejecting it does (a retry); the
    policy rejects it, and every declaration left can succeed. The cost is the tie's either
    way: the brute-force check prices each leaf by hand (declare s: -lambda s + rho (1 - s))."""
    from bayesgrasp.model.cost import CostModel

    solid = read_mesh(wedge_file)
    study = resting_poses(solid.vertices, solid.center_of_mass)
    free = CostModel(verify=0.0)
    pol = plan_pose_policy(study, "width", goal_pose=0, cost=free, max_actions=2)
    leaves = list(_leaves(pol.root))
    assert all(x.success_probability > 0 for x in leaves if isinstance(x, Declare))
    assert any(isinstance(x, Reject) for x in leaves)
    tiny = plan_pose_policy(study, "width", goal_pose=0, cost=CostModel(verify=1e-9), max_actions=2)
    assert_allclose(pol.expected_cost, tiny.expected_cost, rtol=1e-6)
    assert_allclose(pol.success_probability, tiny.success_probability, rtol=1e-6)
