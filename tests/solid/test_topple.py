"""Which squeezes topple a resting part (bayesgrasp.solid.topple) and ``plan MESH --jaw-height``.

Independent checks: the closed form of a rectangle's lever (``a |cos| + b |sin|``, half
sides ``a, b``), :func:`bayesgrasp.sim.drops.static_topples` per jaw and angle, and MuJoCo's
:func:`bayesgrasp.sim.drops.squeeze_topples` on a few seeded squeezes away from the
boundary ``mu h = l``.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp.cli import main
from bayesgrasp.sim.drops import squeeze_topples, static_topples
from bayesgrasp.solid.poses import PoseStudy, resting_poses
from bayesgrasp.solid.topple import ANGLE_STEPS, toppling_angles, toppling_report

HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None


def _box(a: float, b: float, c: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    mesh = trimesh.creation.box(extents=(a, b, c))
    return np.asarray(mesh.vertices), np.asarray(mesh.faces), np.zeros(3)


def _study(a: float, b: float, c: float) -> PoseStudy:
    v, _, com = _box(a, b, c)
    return resting_poses(v, com)


def _pose_of(study: PoseStudy, height: float) -> int:
    return next(k for k, p in enumerate(study.poses) if abs(p.com_height - height / 2) < 1e-9)


def test_tall_prism_topples_upright_only_with_high_jaws() -> None:
    """10 x 10 x 60 upright: lever 5 to 5 sqrt 2, so mu h = 0.5 h topples it for h > 10 sqrt 2."""
    study = _study(10, 10, 60)
    up = _pose_of(study, 60)
    assert toppling_angles(study, up, 40.0).all()
    assert not toppling_angles(study, up, 9.9).any()
    mixed = toppling_angles(study, up, 12.0)  # 6 > 5 near the faces, < 5 sqrt 2 at corners
    assert 0 < mixed.mean() < 1
    side = [k for k in range(len(study.poses)) if k != up and study.poses[k].com_height < 6]
    for k in side:  # lying down: height 10, lever >= 5 = 0.5 * 10
        assert not toppling_angles(study, k, 1000.0).any()


def test_a_box_keeps_every_squeeze() -> None:
    """A cube never (mu h <= 0.5 * 20 = its least lever); a 20 x 30 x 10 box with low jaws."""
    assert all(r.fraction == 0 for r in toppling_report(_study(20, 20, 20), 1000.0))
    study = _study(20, 30, 10)
    assert all(r.fraction == 0 for r in toppling_report(study, 9.9))
    assert all(r.fraction == 0 for r in toppling_report(study, 0.0))
    standing = toppling_report(study, 1000.0)[_pose_of(study, 30)]  # mu h = 15 > 5 sqrt 5
    assert standing.fraction == 1


@settings(max_examples=30, deadline=None)
@given(st.floats(2, 40), st.floats(2, 40), st.floats(2, 80), st.floats(0.5, 100), st.floats(0.1, 1))
def test_rectangle_lever_closed_form(a: float, b: float, c: float, h: float, mu: float) -> None:
    """On the a x b face the lever is min over both jaws of a/2 |cos| + b/2 |sin|."""
    v, _, com = _box(a, b, c)
    study = resting_poses(v, com)
    k = _pose_of(study, c)
    frame = study.poses[k].frame
    x = abs(frame[0] @ np.array([1.0, 0.0, 0.0]))  # the pose's x along the box's a side?
    ha, hb = (a / 2, b / 2) if x > 0.5 else (b / 2, a / 2)
    phi = 2 * np.pi * np.arange(ANGLE_STEPS) / ANGLE_STEPS
    lever = ha * np.abs(np.cos(phi)) + hb * np.abs(np.sin(phi))
    expect = mu * min(h, c) > lever
    got = toppling_angles(study, k, h, mu)
    near = np.abs(mu * min(h, c) - lever) < 1e-9 * (1 + lever)
    assert (got == expect)[~near].all()


@pytest.mark.parametrize("shape", [(10, 10, 60), (10, 40, 60), (8, 20, 30)])
def test_agrees_with_static_topples_of_either_jaw(shape: tuple[float, float, float]) -> None:
    """Topples at a direction iff static_topples says so for one of the two jaws pushing."""
    v, _, com = _box(*shape)
    study = resting_poses(v, com)
    rng = np.random.default_rng(3)
    for k, pose in enumerate(study.poses):
        height = 2 * pose.com_height
        for h in (0.3 * height, 0.8 * height):
            mask = toppling_angles(study, k, h)
            for i in rng.integers(0, ANGLE_STEPS, 12):
                a = 2 * math.pi * i / ANGLE_STEPS
                either = any(
                    static_topples(v, com, pose.normal, a, jaw_height=h / height, push=s)
                    for s in (0.5, -0.5)
                )
                assert mask[i] == either, (shape, k, h, i)


@pytest.mark.physics
@pytest.mark.skipif(not HAVE_MUJOCO, reason="MuJoCo is not installed")
@pytest.mark.parametrize(
    ("shape", "height", "degrees", "jaw", "expect"),
    [
        ((10, 10, 60), 60, 0.0, 0.8, True),  # upright, jaws high: mu h = 24 > 5
        ((10, 10, 60), 60, 45.0, 0.8, True),
        ((10, 10, 60), 60, 0.0, 0.1, False),  # jaws low: slides (mu h = 3 < 5)
        ((10, 10, 60), 10, 30.0, 0.9, False),  # lying down: never
        ((20, 30, 10), 10, 60.0, 0.9, False),  # a box: never
        ((10, 40, 60), 60, 0.0, 1 / 3, True),  # across the slab: mu h = 10 > 5
        ((10, 40, 60), 60, 90.0, 1 / 3, False),  # along it: 10 < 20
    ],
)
def test_agrees_with_mujoco(
    shape: tuple[float, float, float], height: float, degrees: float, jaw: float, expect: bool
) -> None:
    v, f, com = _box(*shape)
    study = resting_poses(v, com)
    k = _pose_of(study, height)
    i = round(degrees / 360 * ANGLE_STEPS)
    predicted = bool(toppling_angles(study, k, jaw * height)[i])
    assert predicted == expect
    check = squeeze_topples(v, f, com, study.poses[k].normal, math.radians(degrees), jaw_height=jaw)
    assert bool(check) == predicted


# --- plan MESH --jaw-height ---------------------------------------------------------------


@pytest.fixture
def prism(tmp_path: Path) -> Path:
    f = tmp_path / "prism.stl"
    trimesh.creation.box(extents=(10, 10, 60)).export(f)
    return f


def test_plan_refuses_a_pose_that_topples(prism: Path, capsys) -> None:
    study = _study(10, 10, 60)
    up = _pose_of(study, 60)
    assert main(["plan", str(prism), "--pose", str(up), "--jaw-height", "40"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"topples pose {up}" in err
    assert "every closing direction" in err
    assert main(["plan", str(prism), "--pose", str(up), "--jaw-height", "9"]) == 0


def test_plan_keeps_a_pose_that_does_not_topple(prism: Path, capsys) -> None:
    """Pose 0 lies down: the plan is the one without --jaw-height, with a note."""
    assert main(["plan", str(prism), "--json"]) == 0
    plain = capsys.readouterr().out
    assert main(["plan", str(prism), "--json", "--jaw-height", "40"]) == 0
    out = capsys.readouterr()
    assert out.out == plain
    assert "no squeeze with the jaws at height 40 topples pose 0" in out.err


def test_policy_refuses_when_a_pose_of_positive_weight_topples(prism: Path, capsys) -> None:
    argv = ["plan", str(prism), "--sense", "width", "--max-actions", "1"]
    assert main([*argv, "--jaw-height", "40"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pose 4 at every closing direction; pose 5" in err
    assert main([*argv, "--json"]) == 0
    plain = capsys.readouterr().out
    assert main([*argv, "--json", "--jaw-height", "9"]) == 0
    assert capsys.readouterr().out == plain


def test_jaw_height_needs_a_mesh(tmp_path: Path, capsys) -> None:
    part = tmp_path / "square.txt"
    part.write_text("0 0\n1 0\n1 1\n0 1\n")
    assert main(["plan", str(part), "--jaw-height", "1"]) == 2
    err = capsys.readouterr().err
    assert "--jaw-height needs a mesh PART" in err and err.count("\n") == 1


def test_jaw_height_refuses_standard_input(prism: Path, capsys, monkeypatch) -> None:
    import io
    import sys

    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(prism.read_bytes())))
    assert main(["plan", "-", "--format", "stl", "--jaw-height", "40"]) == 2
    err = capsys.readouterr().err
    assert "not on standard input" in err and err.count("\n") == 1
