"""Squeezes of a resting solid in MuJoCo (bayesgrasp.sim.drops.squeeze_topples).

The independent check is statics (:func:`static_topples` is tested here against hand
computations): a push at height ``h`` tips the part before it slides when ``mu h`` exceeds
the lever ``l`` from the centre of mass to the support's far edge. MuJoCo must agree away
from the boundary ``mu h = l`` (near it, the push's dynamics decide).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from bayesgrasp.errors import SimulationError
from bayesgrasp.sim.drops import squeeze_topples, static_topples
from bayesgrasp.sim.mesh_scene import mass_properties, pose_frame, rotation_between
from sim.test_drops import box, read_stl  # the solids the drop tests use

HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None
needs_mujoco = pytest.mark.skipif(not HAVE_MUJOCO, reason="MuJoCo is not installed")
MESHES = Path(__file__).resolve().parents[2] / "examples" / "meshes"
DOWN = (0.0, 0.0, -1.0)


TALL = box(10, 10, 60)  # a tall thin prism standing on its 10 x 10 end
TALL_COM = np.array([5.0, 5.0, 30.0])


# --- statics (no MuJoCo) ------------------------------------------------------------------


def test_static_threshold_of_a_tall_prism() -> None:
    """Lever 5, friction 0.5: it tips when pushed above 10 of its 60 (jaw height 1/6)."""
    v = TALL[0]
    assert not static_topples(v, TALL_COM, DOWN, 0.0, jaw_height=0.15)
    assert static_topples(v, TALL_COM, DOWN, 0.0, jaw_height=0.18)
    assert static_topples(v, TALL_COM, DOWN, 0.0, jaw_height=0.5, friction=0.2)  # 6 > 5
    assert not static_topples(v, TALL_COM, DOWN, 0.0, jaw_height=0.5, friction=0.15)  # 4.5
    assert not static_topples(v, TALL_COM, DOWN, 0.0, jaw_height=0.9, push=0.0)


def test_static_lever_turns_with_the_gripper() -> None:
    """Turned 45 degrees the square end's lever is its half diagonal, 5 sqrt 2."""
    v = TALL[0]
    h = 5 * math.sqrt(2) / 0.5 / 60  # jaw height fraction where mu h = 5 sqrt 2
    assert not static_topples(v, TALL_COM, DOWN, math.pi / 4, jaw_height=h - 0.01)
    assert static_topples(v, TALL_COM, DOWN, math.pi / 4, jaw_height=h + 0.01)


def test_static_uses_the_nearer_edge_of_an_off_centre_mass() -> None:
    """Centre of mass 2 from the -x edge: a push towards -x tips it early, towards +x late."""
    v, _ = box(10, 10, 20)
    com = np.array([2.0, 5.0, 10.0])
    assert static_topples(v, com, DOWN, 0.0, jaw_height=0.3, push=0.5)  # 0.5 * 6 > 2
    assert not static_topples(v, com, DOWN, 0.0, jaw_height=0.3, push=-0.5)  # 3 < 8


def test_pose_frame_puts_the_face_down() -> None:
    for n in [(0, 0, -1), (0, 0, 1), (1, 0, 0), (0.6, 0, 0.8), (0, -0.6, 0.8)]:
        frame = pose_frame(n)
        np.testing.assert_allclose(frame @ np.asarray(n), [0, 0, -1], atol=1e-12)
        np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
        r = rotation_between(n, (0, 0, -1))
        np.testing.assert_allclose(r @ np.asarray(n), [0, 0, -1], atol=1e-12)
        assert np.linalg.det(r) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"jaw_height": 0.0}, r"`jaw_height` must be a finite number > 0 and <= 1; got 0.0"),
        ({"push": 2.0}, r"`push` must be a finite number >= -1 and <= 1; got 2.0"),
        ({"friction": -1}, r"`friction` must be a finite number > 0; got -1"),
        ({"normal": (0, 0, -2)}, r"`normal` must be unit vectors"),
        ({"gripper_angle": math.nan}, r"`gripper_angle` must be a finite number"),
    ],
)
def test_squeeze_refuses_bad_input(kwargs: dict, message: str) -> None:
    v, f = box(4, 3, 2)
    args = {"vertices": v, "faces": f, "com": (2, 1.5, 1), "normal": DOWN, "gripper_angle": 0.0}
    args.update(kwargs)
    with pytest.raises(SimulationError, match=message):
        squeeze_topples(**args)


# --- MuJoCo -------------------------------------------------------------------------------


@pytest.mark.physics
@needs_mujoco
@pytest.mark.parametrize("angle", [0.0, 0.4, 1.2])
def test_box_on_its_broad_face_never_topples(angle: float) -> None:
    v, f = box(40, 30, 20)
    check = squeeze_topples(v, f, (20, 15, 10), DOWN, angle, jaw_height=0.9)
    assert not check and not check.static_prediction and check.settled
    assert check.max_tilt_deg < 2


@pytest.mark.physics
@needs_mujoco
@pytest.mark.parametrize(
    ("height", "topples"), [(0.05, False), (0.1, False), (0.3, True), (0.5, True), (0.9, True)]
)
def test_tall_prism_topples_when_pushed_high(height: float, topples: bool) -> None:
    """Away from the static threshold (1/6 of its height) MuJoCo agrees with statics."""
    v, f = TALL
    check = squeeze_topples(v, f, TALL_COM, DOWN, 0.0, jaw_height=height)
    assert check.static_prediction is topples
    assert bool(check) is topples


@pytest.mark.physics
@needs_mujoco
def test_squeeze_without_a_push_keeps_even_a_tall_prism() -> None:
    """Both jaws touch together: equal and opposite horizontal forces tip nothing."""
    v, f = TALL
    check = squeeze_topples(v, f, TALL_COM, DOWN, 0.0, jaw_height=0.9, push=0.0)
    assert not check and check.max_tilt_deg < 2


@pytest.mark.physics
@needs_mujoco
def test_wedge_and_l_bracket_on_their_bases() -> None:
    """Low, broad poses keep their pose under a mid-height push; the wedge standing on its
    short end (the 15 x 20 face, 40 tall) tips when pushed high, as statics says."""
    v, f = read_stl(MESHES / "wedge.stl")
    com = mass_properties(v, f)[1]
    assert not squeeze_topples(v, f, com, DOWN, 0.0)
    assert not squeeze_topples(v, f, com, DOWN, math.pi / 2)
    end = squeeze_topples(v, f, com, (-1, 0, 0), 0.0, jaw_height=0.9)
    assert end.static_prediction and end.toppled
    v, f = read_stl(MESHES / "l_bracket.stl")
    com = mass_properties(v, f)[1]
    for angle in (0.0, math.pi / 2):
        check = squeeze_topples(v, f, com, DOWN, angle)
        assert not check and not check.static_prediction


def _unit(v: tuple[float, float, float]) -> tuple[float, ...]:
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


STABLE_POSES = {  # each example's quasi-static stable poses (outward normals, mesh frame)
    "wedge": [_unit((15, 0, 40)), DOWN, (0, 1, 0), (0, -1, 0), (-1, 0, 0)],
    "l_bracket": [DOWN, (0, -1, 0), (0, 1, 0), _unit((24, 0, 34)), (-1, 0, 0)],
}


@pytest.mark.physics
@needs_mujoco
def test_statics_and_mujoco_agree_on_most_squeezes() -> None:
    """Every stable pose of the wedge and the L-bracket, two angles, two jaw heights: the
    static check misses only where the pad meets a sloping or narrow part of the hull
    (measured: 35 of 40 agree)."""
    agree = total = 0
    for name, poses in STABLE_POSES.items():
        v, f = read_stl(MESHES / f"{name}.stl")
        com = mass_properties(v, f)[1]
        for normal in poses:
            for angle in (0.0, math.pi / 2):
                for height in (0.5, 0.9):
                    check = squeeze_topples(v, f, com, normal, angle, jaw_height=height)
                    agree += check.toppled == check.static_prediction
                    total += 1
    assert total == 40 and agree >= 33
