"""Documents say which part they are for and how they were made; a re-run from one agrees.

- A plan document names its part (``part.id``, :func:`bayesgrasp.io.plans.part_id`): a plan
  for another part is exit 2 for ``simulate`` and ``plot`` unless ``--force``.
- ``provenance`` records version, prior, cost model, goal, actions, accuracy, planner and
  the part-file options; rebuilding the problem from it gives the same plans.
- ``simulate --plan FILE`` runs under the file's prior and goal unless told otherwise, so
  its prediction is the plan's own probability; a simulation re-run from its provenance
  gives the same counts.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp import Goal, Part, Problem, plan_exact, resolve_part
from bayesgrasp.cli import main
from bayesgrasp.io.plans import part_id, prior_from_document, read_plan, same_part
from bayesgrasp.model.cost import CostModel

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def plan_file(capsys: pytest.CaptureFixture[str], path: Path, *args: str) -> dict:
    code, out, err = run(capsys, "plan", *args, "--json")
    assert code == 0, err
    path.write_text(out, encoding="utf-8")
    return json.loads(out)


def test_plan_for_another_part_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    p = tmp_path / "p.json"
    plan_file(capsys, p, "house")
    code, out, err = run(capsys, "simulate", "triangle", "--plan", str(p), "--trials", "10")
    assert (code, out) == (2, "")
    assert len(err.strip().splitlines()) == 1
    assert "'house'" in err and "'triangle'" in err and "--force" in err
    code, out, err = run(
        capsys, "simulate", "triangle", "--plan", str(p), "--trials", "10", "--force"
    )
    assert code == 0, err
    code, _, err = run(capsys, "plot", "triangle", "--plan", str(p), "--out", str(tmp_path / "f"))
    assert code == 2 and "is for part 'house'" in err
    # the same part from a file, moved and with another vertex order, is the same part
    house = resolve_part("house")
    moved = tmp_path / "house.json"
    pts = (house.hull.vertices[::-1] + np.array([100.0, -7.0])).tolist()
    com = (house.center_of_mass + np.array([100.0, -7.0])).tolist()
    moved.write_text(json.dumps({"vertices": pts, "center_of_mass": com}), encoding="utf-8")
    code, _, err = run(capsys, "simulate", str(moved), "--plan", str(p), "--trials", "10")
    assert code == 0, err


def test_part_id_and_same_part() -> None:
    tri = resolve_part("triangle")
    v = tri.hull.vertices
    assert part_id(tri) == part_id(
        Part.from_points(v[[2, 0, 1]] + 5.0, center_of_mass=tri.center_of_mass + 5.0)
    )
    # 7 significant digits: same part; a turned part or a moved centre of mass: another
    rounded = Part.from_points(np.array([float(f"{x:.7g}") for x in v.ravel()]).reshape(-1, 2))
    assert same_part({"vertices": rounded.hull.vertices.tolist()}, tri)
    c, s = math.cos(0.01), math.sin(0.01)
    turned = Part.from_points(v @ np.array([[c, s], [-s, c]]))
    assert part_id(turned) != part_id(tri)
    assert same_part({"vertices": turned.hull.vertices.tolist()}, tri) is False
    shifted = Part.from_points(v, center_of_mass=tri.center_of_mass + np.array([1.0, 0.0]))
    assert part_id(shifted) != part_id(tri)
    doc = {"vertices": v.tolist(), "center_of_mass": shifted.center_of_mass.tolist()}
    assert same_part(doc, tri) is False
    assert same_part({"vertices": v.tolist()}, tri)  # older documents: the hull alone
    assert same_part({"steps": []}, tri) is None  # a bare option names no part


def test_old_documents_still_read(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    p = tmp_path / "old.json"
    doc = plan_file(capsys, p, "house")
    for key in ("provenance",):
        doc.pop(key)
    for key in ("id", "center_of_mass"):
        doc["part"].pop(key)
    p.write_text(json.dumps(doc), encoding="utf-8")
    code, _, err = run(capsys, "simulate", "house", "--plan", str(p), "--trials", "100")
    assert code == 0, err
    code, _, err = run(capsys, "simulate", "triangle", "--plan", str(p), "--trials", "10")
    assert code == 2 and "is for part 'house'" in err


@pytest.mark.parametrize(
    "args",
    [
        ["house", "--prior", "vonmises:135,6"],
        ["key", "--goal", "symmetry", "--squeeze-cost", "2", "--verify-cost", "0.5"],
        [
            "house",
            "--actions",
            "squeeze,push-grasp",
            "--first-squeeze-cost",
            "3",
            "--accuracy",
            "1",
        ],
        ["rectangle", "--prior", "histogram:{tmp}/h.txt", "--retry-cost", "0.25"],
        ["triangle", "--prior", "sample:{tmp}/s.txt", "--max-squeezes", "2"],
    ],
)
def test_plan_provenance_rebuilds_the_plans(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: list[str]
) -> None:
    (tmp_path / "h.txt").write_text("1 3 2 5 0 1 4 2\n", encoding="utf-8")
    (tmp_path / "s.txt").write_text("10 12 15 100 181 185 300\n", encoding="utf-8")
    args = [a.format(tmp=tmp_path) for a in args]
    doc = plan_file(capsys, tmp_path / "p.json", *args)
    prov = doc["provenance"]
    from bayesgrasp import __version__

    assert prov["version"] == __version__
    assert {"prior", "cost", "goal", "actions", "accuracy_rad", "method"} <= set(prov)
    pb = Problem.build(
        resolve_part(args[0]),
        prior=prior_from_document(prov["prior"]),
        cost=CostModel(**prov["cost"]),
        goal=Goal(prov["goal"]),
        actions=tuple(prov["actions"]),
        accuracy=prov["accuracy_rad"],
    )
    again = plan_exact(pb, max_actions=prov.get("max_actions"))
    assert len(again.options) == len(doc["options"])
    for mine, theirs in zip(again.options, doc["options"], strict=True):
        assert_allclose(mine.success_probability, theirs["success_probability"], rtol=1e-12)
        assert_allclose(mine.expected_cost, theirs["expected_cost"], rtol=1e-12)
    assert again.bayes == doc["bayes"]


@pytest.mark.parametrize(
    "args",
    [["house", "--prior", "vonmises:135,6"], ["rectangle", "--goal", "symmetry"]],
)
def test_simulate_uses_the_plan_files_prior_and_goal(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: list[str]
) -> None:
    p = tmp_path / "p.json"
    doc = plan_file(capsys, p, *args)
    claimed = doc["options"][doc["bayes"]]["success_probability"]
    code, out, err = run(
        capsys, "simulate", args[0], "--plan", str(p), "--trials", "2000", "--json"
    )
    assert code == 0, err
    sim = json.loads(out)
    assert_allclose(sim["predicted_success"], claimed, rtol=1e-9)
    assert sim["provenance"]["prior"] == doc["provenance"]["prior"]
    assert read_plan(p).goal == doc["provenance"]["goal"]


def test_simulate_rerun_from_its_document(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    base = ["simulate", "example", "--noise", "1.5", "--noise-kind", "uniform", "--seed", "11"]
    code, out, err = run(capsys, *base, "--trials", "3000", "--json")
    assert code == 0, err
    first = json.loads(out)
    prov = first["provenance"]
    assert {k: prov[k] for k in ("engine", "seed", "noise_deg", "noise_kind")} == {
        "engine": "kinematic",
        "seed": 11,
        "noise_deg": 1.5,
        "noise_kind": "uniform",
    }
    assert prov["prior"] == {"kind": "uniform"} and prov["trials"] == 3000
    sim = tmp_path / "sim.json"
    sim.write_text(out, encoding="utf-8")
    again = [
        "simulate", "example", "--plan", str(sim), "--seed", str(prov["seed"]),
        "--noise", str(prov["noise_deg"]), "--noise-kind", prov["noise_kind"],
        "--trials", str(prov["trials"]), "--json",
    ]  # fmt: skip
    code, out, err = run(capsys, *again)
    assert code == 0, err
    second = json.loads(out)
    for key in ("predicted_success", "observed_success", "jams", "per_orientation"):
        assert second[key] == first[key]


def test_trials_stream_in_blocks(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Blocks of trials draw what one call draws; memory is one block's."""
    import bayesgrasp.cli.simulate as cmd
    import bayesgrasp.sim.kinematic as kin

    args = ["simulate", "house", "--trials", "700000", "--seed", "4", "--json"]
    _, out, _ = run(capsys, *args)
    whole = json.loads(out)
    sizes: list[int] = []
    real = kin.simulate_kinematic

    def spy(*a, **k):  # type: ignore[no-untyped-def]
        sizes.append(a[2])
        return real(*a, **k)

    monkeypatch.setattr(cmd, "BLOCK", 1 << 18)
    monkeypatch.setattr(kin, "simulate_kinematic", spy)
    _, out, _ = run(capsys, *args)
    blocks = json.loads(out)
    assert sizes == [1 << 18, 1 << 18, 700000 - (2 << 18)]
    for key in (
        "trials",
        "observed_success",
        "jams",
        "near_boundary",
        "per_orientation",
        "p_value",
    ):
        assert blocks[key] == whole[key]


def test_absurd_runs_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    cases = [
        (["simulate", "triangle", "--trials", "1000000000000"], "at most 1,000,000,000 trials"),
        (["simulate", "triangle", "--engine", "mujoco", "--offset", "1000"], "part's size"),
        (["simulate", "triangle", "--noise", "90"], "less than 90"),
        (["plan", "triangle", "--accuracy", "1000"], "no plan keeps a tolerance of 1000 deg"),
        (["plan", "triangle", "--squeeze-cost", "1e308"], "at most 1e+280"),
        (["plan", "triangle", "--squeeze-cost", "nan"], "is not a number"),
        (["plan", "triangle", "--verify-cost", "-1"], "should be >= 0"),
        (["simulate", "triangle", "--seed", "-1", "--trials", "10"], "--seed"),
        (["study", "--seed", "-1", "--polygons", "3"], "--seed"),
        (["plan", "triangle", "--accuracy", "2", "--method", "bfs"], "= 2 deg"),
    ]
    for argv, words in cases:
        code, out, err = run(capsys, *argv)
        assert (code, out) == (2, ""), argv
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        assert words in err, (argv, err)


def test_huge_costs_stay_finite() -> None:
    from bayesgrasp.errors import CostError

    with pytest.raises(CostError, match="at most 1e"):
        CostModel({"squeeze": 1e308})
    big = CostModel({"squeeze": 1e280}, verify=1e280)
    res = plan_exact(Problem.build(resolve_part("house"), cost=big))
    assert all(math.isfinite(o.expected_cost) for o in res.options)
    unit = plan_exact(Problem.build(resolve_part("house")))
    assert res.bayes == unit.bayes


def test_part_file_options_are_recorded(capsys: pytest.CaptureFixture[str]) -> None:
    root = Path(__file__).resolve().parents[2]
    code, out, err = run(
        capsys, "plan", str(root / "examples" / "peanut.svg"), "--flatten-tol", "0.5", "--json"
    )
    assert code == 0, err
    prov = json.loads(out)["provenance"]
    assert prov["flatten_tolerance"] == 0.5 and "element" not in prov  # not given: default


def test_the_default_flattening_tolerance_is_recorded(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Issue 15: provenance named the flattening tolerance only when it was given.

    The lever's Bezier curves are flattened at the reader's default (1e-3 of the drawing's
    diagonal), which the part keeps as its curve error: the document records it, and a re-run
    with it gives the same plans. The slot (segments and arcs only) flattens nothing.
    """
    lever = str(Path(__file__).resolve().parents[2] / "examples" / "lever.svg")
    doc = plan_file(capsys, tmp_path / "p.json", lever)
    tol = doc["provenance"]["flatten_tolerance"]
    assert tol == doc["part"]["curved"]["curve_error"] > 0
    again = plan_file(capsys, tmp_path / "q.json", lever, "--flatten-tol", repr(tol))
    assert again["provenance"]["flatten_tolerance"] == tol
    assert again["options"] == doc["options"] and again["part"] == doc["part"]
    given = plan_file(capsys, tmp_path / "r.json", lever, "--flatten-tol", "0.5")
    assert given["provenance"]["flatten_tolerance"] == 0.5
    slot = str(Path(__file__).resolve().parents[2] / "examples" / "slot.dxf")
    assert "flatten_tolerance" not in plan_file(capsys, tmp_path / "s.json", slot)["provenance"]
