"""Contact asynchrony in MuJoCo: the jaw lag and the calibration of ``q``."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

from bayesgrasp.angles import TWO_PI, circle_distance
from bayesgrasp.errors import SimulationError
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.geometry.transfer import squeeze_function
from bayesgrasp.shapes import load
from bayesgrasp.sim.asynchrony import AsynchronyResult, differing_starts, measure_asynchrony
from bayesgrasp.sim.params import SimParams, SimParamsError
from bayesgrasp.sim.result import boundary_distance

HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None
needs_mujoco = pytest.mark.skipif(
    not HAVE_MUJOCO, reason="MuJoCo is not installed: pip install 'bayesgrasp[sim]'"
)
TRIANGLE = load("triangle")


def test_jaw_lag_settings_validate() -> None:
    assert SimParams().jaw_lag == 0.0 and SimParams().lead_jaw == "random"
    with pytest.raises(SimParamsError, match="jaw_lag"):
        SimParams(jaw_lag=-0.1)
    with pytest.raises(SimParamsError, match="lead_jaw"):
        SimParams(lead_jaw="left")


def test_differing_starts_against_a_direct_evaluation() -> None:
    """Each start's two predictions, recomputed point by point, differ; leads are balanced."""
    th, lead, sq, pg = differing_starts(TRIANGLE, 400, np.random.default_rng(4))
    s = squeeze_function(TRIANGLE.hull)
    g = push_grasp_function(TRIANGLE)
    for t, side, a, b in zip(th[:50], lead[:50], sq[:50], pg[:50], strict=True):
        # the +x jaw pushes as the -x jaw of the gripper turned by pi
        want = float(g(t)) if side < 0 else float(g(t - math.pi)) + math.pi
        assert circle_distance(b, want) < 1e-9 and circle_distance(a, float(s(t))) < 1e-9
        assert circle_distance(a, b) > 1e-3
    assert np.all(boundary_distance(s.boundaries, th) >= math.radians(2.5))
    assert set(lead.tolist()) == {-1, 1} and abs(np.mean(lead > 0) - 0.5) < 0.1
    assert np.all((th >= 0) & (th < TWO_PI))


def test_asynchrony_result_q_and_interval() -> None:
    r = AsynchronyResult(1.0, 5.0, 10, 3, 6, 1, 0.0)
    assert r.q == pytest.approx(1 / 3)
    lo, hi = r.interval()
    assert lo < r.q < hi
    assert math.isnan(AsynchronyResult(1.0, 5.0, 1, 0, 0, 1, 0.0).q)


@pytest.mark.physics
@needs_mujoco
def test_a_lag_of_zero_ignores_the_lead() -> None:
    from bayesgrasp.sim import Squeezer

    # fresh squeezers: MuJoCo's warm start makes a second run on one model differ in 1e-15
    a, b = Squeezer(TRIANGLE, 0.001).act(1.0), Squeezer(TRIANGLE, 0.001).act(1.0, lead=1)
    assert a.end == b.end and a.sim_time == b.sim_time
    with pytest.raises(SimulationError, match="lead"):
        Squeezer(TRIANGLE, 0.001, SimParams(jaw_lag=0.1)).act(1.0, lead=0)


@pytest.mark.physics
@needs_mujoco
def test_a_large_jaw_lag_acts_as_a_push_grasp_more_often() -> None:
    """Lag 4 s (a 20 mm push by the leading jaw) against lag 0, on the same kind of starts."""
    zero = measure_asynchrony(TRIANGLE, 0.001, 0.0, 10, rng=1)
    big = measure_asynchrony(TRIANGLE, 0.001, 4.0, 10, rng=1)
    assert zero.push == 0, zero  # both jaws together: the pure squeeze
    assert big.push >= zero.push + 5, (zero, big)
    # both leading sides are classified right, else q could not pass one half
    assert big.q >= 0.6, big


@pytest.mark.physics
@needs_mujoco
def test_simulate_mujoco_draws_the_leading_jaws_up_front() -> None:
    """With a jaw lag the results do not depend on the workers, and the lag acts."""
    from bayesgrasp.model.problem import Problem
    from bayesgrasp.planning import plan_exact
    from bayesgrasp.sim import simulate_mujoco

    pb = Problem.build(TRIANGLE)
    plan = plan_exact(pb).options[0]
    lagged = SimParams(jaw_lag=8.0, clearance=0.045)
    one = simulate_mujoco(pb, plan, 6, params=lagged, rng=3)
    two = simulate_mujoco(pb, plan, 6, params=lagged, rng=3, workers=2)
    np.testing.assert_allclose(one.final, two.final, atol=0.0)
    plain = simulate_mujoco(pb, plan, 6, params=SimParams(clearance=0.045), rng=3)
    assert np.any(circle_distance(one.final, plain.final) > math.radians(1.0))
