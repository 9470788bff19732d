"""The batched MuJoCo engine: settled stop, C rollout threads, against a fine reference.

Marked ``physics``; a few seconds on one core.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")

from bayesgrasp.angles import circle_distance
from bayesgrasp.errors import SimulationError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact
from bayesgrasp.shapes import load
from bayesgrasp.sim import SimParams, boundary_distance, simulate_mujoco
from bayesgrasp.sim.rollout import BatchSqueezer

pytestmark = pytest.mark.physics

#: The accuracy study's reference: fine steps, slow jaws, the notes' long settle.
REFERENCE = SimParams(
    timestep=0.0005, jaw_speed=0.005, jaw_damping=20.0, clearance=0.003, settle_time=0.1
)


def _starts(pb: Problem, kind: str, n: int, seed: int) -> np.ndarray:
    """Seeded random yaws at least 2.5 degrees from a basin boundary of the action."""
    th = np.random.default_rng(seed).uniform(0, 2 * math.pi, 4 * n)
    away = boundary_distance(pb.transfer(kind).boundaries, th) >= math.radians(2.5)
    return th[away][:n]


def _state(pb: Problem, kind: str, end: np.ndarray, settled: np.ndarray) -> np.ndarray:
    """Index of the stable orientation each action ended in; -1 jammed, -2 not settled."""
    d = circle_distance(end[:, None], pb.transfer(kind).stable)
    c = d.argmin(axis=1)
    c[d.min(axis=1) > SimParams().jam_tol] = -1
    c[~settled] = -2
    return c


@pytest.mark.parametrize(
    ("name", "kind", "n"),
    [("triangle", "squeeze", 10), ("rectangle", "squeeze", 10), ("triangle", "push-grasp", 3)],
)
def test_default_settings_end_where_the_reference_does(name: str, kind: str, n: int) -> None:
    part = load(name)
    pb = Problem.build(part, actions=(kind,))
    th = _starts(pb, kind, n, seed=11)
    push = kind == "push-grasp"
    ref = BatchSqueezer(part, 0.001, REFERENCE).act(th, push=push)
    fast = BatchSqueezer(part, 0.001).act(th, push=push)
    want = _state(pb, kind, ref.end, ref.settled)
    assert (want >= 0).all()  # away from boundaries the reference reaches a stable state
    assert _state(pb, kind, fast.end, fast.settled).tolist() == want.tolist()
    # the settled stop: far less simulated time than the reference
    assert fast.sim_time.mean() < 0.25 * ref.sim_time.mean()


def test_thread_count_does_not_change_results() -> None:
    part = load("house")
    th = np.random.default_rng(3).uniform(0, 2 * math.pi, 12)
    one = BatchSqueezer(part, 0.001, nthread=1).act(th)
    with BatchSqueezer(part, 0.001, nthread=2) as bs:
        two = bs.act(th)
    assert np.array_equal(one.end, two.end) and np.array_equal(one.sim_time, two.sim_time)
    pb = Problem.build(part)
    plan = plan_exact(pb).bayes_plan
    a = simulate_mujoco(pb, plan, 8, rng=5, workers=1)
    b = simulate_mujoco(pb, plan, 8, rng=5, workers=2)
    assert np.array_equal(a.final, b.final) and a.observed.tolist() == b.observed.tolist()


def test_rollout_and_stepped_engines_agree_on_states() -> None:
    part = load("triangle")
    pb = Problem.build(part)
    plan = plan_exact(pb).bayes_plan
    a = simulate_mujoco(pb, plan, 10, rng=2)
    b = simulate_mujoco(pb, plan, 10, rng=2, method="stepped")
    assert a.observed.tolist() == b.observed.tolist() and a.jams == b.jams
    assert float(circle_distance(a.final, b.final).max()) < math.radians(0.5)
    with pytest.raises(SimulationError, match="`method` must be rollout or stepped"):
        simulate_mujoco(pb, plan, 2, method="euler")


def test_bad_thread_count_is_refused() -> None:
    with pytest.raises(SimulationError, match="`nthread` must be an integer >= 1"):
        BatchSqueezer(load("triangle"), 0.001, nthread=0)


def _stalling_part() -> Part:
    """A 1.3 cm random 10-gon that stalls under fast sluggish jaws; at 1 cm/s it turns."""
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(2)
    hulls = []
    for _ in range(3):
        pts = rng.random((10, 2))
        hulls.append(pts[ConvexHull(pts).vertices])
    return Part.from_points(hulls[2].tolist(), units="cm")


def test_jammed_actions_are_retried_with_slow_jaws() -> None:
    """A 1.3 cm random 10-gon stalls under fast sluggish jaws; at 1 cm/s it turns."""
    part = _stalling_part()
    stable = Problem.build(part).states.stable
    th = np.random.default_rng(0).uniform(0, 2 * math.pi, 40)

    def off(ends: np.ndarray) -> np.ndarray:
        return circle_distance(ends[:, None], stable).min(axis=1) > SimParams().jam_tol

    sluggish = SimParams(scale_jaw_mass=False)  # 0.1 kg jaws pushing with 4 mN
    bs = BatchSqueezer(part, 0.01, sluggish)
    fast = bs.act(th)
    kept = bs.act(th, stable=stable)
    slow = BatchSqueezer(part, 0.01, SimParams(jaw_speed=0.01, scale_jaw_mass=False)).act(th)
    bad = off(fast.end)
    assert bad.sum() >= 5 and not off(kept.end).any()
    assert np.array_equal(kept.end[bad], slow.end[bad])  # the retried actions: slow jaws
    assert np.array_equal(kept.end[~bad], fast.end[~bad])  # the rest untouched


def test_stepped_engine_retries_jams_as_the_batched_one_does() -> None:
    """The same jam test and retry (jaws at retry_speed) in both engines."""
    from bayesgrasp.sim import Squeezer
    from bayesgrasp.sim.squeezer import jammed, retry_params

    part = _stalling_part()
    stable = Problem.build(part).states.stable
    th = np.random.default_rng(0).uniform(0, 2 * math.pi, 12)
    sluggish = SimParams(scale_jaw_mass=False)
    slow_params = retry_params(sluggish)
    assert slow_params is not None and slow_params.jaw_speed == sluggish.retry_speed
    sq, slow = Squeezer(part, 0.01, sluggish), Squeezer(part, 0.01, slow_params)
    batched = BatchSqueezer(part, 0.01, sluggish).act(th, stable=stable)
    retried = 0
    for i, t in enumerate(th):
        fast = sq.act(float(t))
        kept = sq.act(float(t), stable=stable)
        if jammed([fast.end], [fast.settled], stable, sluggish.jam_tol)[0]:
            retried += 1
            again = slow.act(float(t))
            assert float(circle_distance(kept.end, again.end)) < 1e-6
            assert kept.sim_time == pytest.approx(fast.sim_time + again.sim_time)
        else:  # a reused model carries the solver's warm start: equal to rounding
            assert float(circle_distance(kept.end, fast.end)) < 1e-6
            assert kept.sim_time == pytest.approx(fast.sim_time)
        # one retry rule: the stepped and batched engines end in the same state
        assert float(circle_distance(kept.end, batched.end[i])) < math.radians(0.5)
    assert retried >= 2
    # and simulate_mujoco's stepped path counts the same jams as its rollout path
    pb = Problem.build(part)
    plan = plan_exact(pb).bayes_plan
    a = simulate_mujoco(pb, plan, 10, params=sluggish, rng=4, scale=0.01)
    b = simulate_mujoco(pb, plan, 10, params=sluggish, rng=4, scale=0.01, method="stepped")
    assert a.observed.tolist() == b.observed.tolist() and a.jams == b.jams


def test_jaw_mass_scales_with_the_force() -> None:
    """A 1 cm part's light jaws settle in a fraction of the time 0.1 kg jaws take."""
    part = Part.from_points([(0, 0), (1, 0), (0.8, 0.6), (0.1, 0.7)], units="cm")
    th = np.random.default_rng(1).uniform(0, 2 * math.pi, 6)
    light = BatchSqueezer(part, 0.01).act(th)
    heavy = BatchSqueezer(part, 0.01, SimParams(scale_jaw_mass=False)).act(th)
    assert light.settled.all() and light.sim_time.mean() < 0.5 * heavy.sim_time.mean()
    assert float(circle_distance(light.end, heavy.end).max()) < math.radians(1.0)
