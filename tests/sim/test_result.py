"""Simulation results (bayesgrasp.sim.result): the exact prediction, summaries, checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import bayesgrasp.sim as sim
from bayesgrasp.angles import TWO_PI
from bayesgrasp.errors import SimulationError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.prior import UniformPrior, von_mises
from bayesgrasp.model.problem import Goal, Problem
from bayesgrasp.planning import PlanOption, PlanStep, plan_exact
from bayesgrasp.shapes import load, names
from bayesgrasp.sim.result import (
    boundary_distance,
    check_steps,
    check_trials,
    predicted_distribution,
    summarize,
)
from strategies import convex_points

RECTANGLE = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])


def test_boundary_distance_wraps() -> None:
    b = np.array([0.5, 3.0])
    assert_allclose(boundary_distance(b, [0.4, 1.0, 6.2, 3.0]), [0.1, 0.5, 0.5 + TWO_PI - 6.2, 0])


@pytest.mark.parametrize("trials", [0, -3, 2.0, "10"])
def test_check_trials_rejects_what_is_not_a_positive_integer(trials: object) -> None:
    with pytest.raises(SimulationError, match="`trials` must be an integer >= 1; got"):
        check_trials(trials)  # type: ignore[arg-type]
    check_trials(1)
    check_trials(np.int64(5))  # type: ignore[arg-type]


def test_check_steps_names_the_problem_s_actions() -> None:
    pb = Problem.build(RECTANGLE)
    check_steps(pb, [PlanStep("squeeze", 0.0)])
    with pytest.raises(SimulationError, match="uses 'push-grasp' actions but the problem has only"):
        check_steps(pb, [PlanStep("squeeze", 0.0), PlanStep("push-grasp", 1.0)])


# --- prediction ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", names())
def test_prediction_matches_the_planner(name: str) -> None:
    pb = Problem.build(load(name))
    for opt in plan_exact(pb).options:
        pred = predicted_distribution(pb, opt.steps)
        assert_allclose(pred.sum(), 1.0, atol=1e-12)
        assert_allclose(pred[pb.success_states(opt.final_orientation)].sum(),
                        opt.success_probability, atol=1e-9)  # fmt: skip


@settings(max_examples=30)
@given(convex_points(), st.sampled_from(["uniform", "vonmises"]), st.booleans())
def test_prediction_is_a_distribution_that_matches_the_planner(
    points: np.ndarray, prior_kind: str, symmetry: bool
) -> None:
    prior = UniformPrior() if prior_kind == "uniform" else von_mises(0.7, 2.0, bins=360)
    pb = Problem.build(
        Part.from_points(points), prior, goal=Goal("symmetry" if symmetry else "single")
    )
    for opt in plan_exact(pb).options:
        pred = predicted_distribution(pb, opt.steps)
        assert np.all(pred >= 0)
        assert_allclose(pred.sum(), 1.0, atol=1e-9)
        got = pred[pb.success_states(opt.final_orientation)].sum()
        assert_allclose(got, opt.success_probability, atol=1e-7)


def test_prediction_needs_a_step() -> None:
    with pytest.raises(SimulationError, match="a plan needs at least one step"):
        predicted_distribution(Problem.build(RECTANGLE), [])


# --- summaries -----------------------------------------------------------------------------


@pytest.mark.parametrize("goal", [Goal(), Goal("symmetry")], ids=["single", "symmetry"])
def test_summary_counts_states_jams_and_the_goal(goal: Goal) -> None:
    pb = Problem.build(RECTANGLE, goal=goal)
    opt = PlanOption((PlanStep("squeeze", 0.0),), math.pi / 2, 0.5, 4.0, None, (0.0, 1.0))
    stable = pb.states.stable
    final = np.array([stable[1], stable[1] + TWO_PI, stable[3], pb.states.boundaries[0]])
    near = np.array([True, False, False, False])
    res = summarize("kinematic", pb, opt, final, np.zeros(4, bool), near, 2.0, 1e-6)
    assert res.trials == 4
    assert res.goal.tolist() == pb.success_states(math.pi / 2).tolist()
    assert res.observed.tolist() == [0, 2, 0, 1]
    assert (res.jams, res.final_jams, res.near_boundary) == (1, 1, 1)
    assert res.jammed_trials.tolist() == [False, False, False, True]
    assert res.successes == (3 if goal.kind == "symmetry" else 2)
    assert_allclose(res.final[1], stable[1], atol=1e-12)
    assert_allclose(res.predicted, predicted_distribution(pb, opt.steps), atol=0)
    assert_allclose(res.predicted_success, res.predicted[res.goal].sum(), atol=0)
    assert res.executions_per_second == 2.0


def test_the_package_re_exports_the_names_callers_import() -> None:
    """Names imported from bayesgrasp.sim.kinematic before the split are still there."""
    from bayesgrasp.sim import kinematic

    for name in ("GripperNoise", "SimulationResult", "boundary_distance", "simulate_kinematic"):
        assert getattr(kinematic, name) is getattr(sim, name)
    assert set(sim.__all__) <= set(dir(sim))


def _physics_run(n_goal: int, n_other: int, n_jam: int, engine: str = "mujoco") -> object:
    """A rectangle's one-squeeze plan with outcomes given: goal, another state, jammed."""
    from bayesgrasp.sim.result import summarize

    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    stable = pb.states.stable
    goal = stable[np.flatnonzero(pb.success_states(0.0))[0]]
    other = stable[np.flatnonzero(~pb.success_states(0.0))[0]]
    off = goal + math.radians(20.0)  # away from every stable orientation: a jam
    final = np.concatenate([np.full(n_goal, goal), np.full(n_other, other), np.full(n_jam, off)])
    n = len(final)
    return summarize(engine, pb, opt, final, np.zeros(n, bool), np.zeros(n, bool), 1.0, 1e-3)


def test_physics_verdict_counts_every_trial_and_flags_jams() -> None:
    from bayesgrasp.sim.result import PHYSICS_FIT, verdict_document, verdict_lines

    r = _physics_run(40, 160, 100)  # predicted success 0.148; observed 40/300
    assert r.fit_unavailable == PHYSICS_FIT and math.isnan(r.p_value)
    p = r.predicted_success
    # brute force: the exact two-sided binomial p-value, every trial (jams too) counted
    k = np.arange(301)
    pmf = np.array([math.comb(300, int(i)) * p**i * (1 - p) ** (300 - i) for i in k])
    brute = float(pmf[pmf <= pmf[40] * (1 + 1e-7)].sum())
    assert r.success_p_value == pytest.approx(brute, rel=1e-6)
    lines = verdict_lines(r)
    assert "every trial counted" in lines[0] and "40/300" in lines[0]
    assert any("100 of 300 trials jammed" in s for s in lines)
    doc = verdict_document(r)
    assert doc["assumption_flags"] and doc["ci95"][0] < 40 / 300 < doc["ci95"][1]
    # with no jams, no flag; the kinematic engine keeps its chi-square and its lines
    assert _physics_run(44, 256, 0).assumption_flags == []
    kin = _physics_run(44, 256, 0, engine="kinematic")
    assert not math.isnan(kin.p_value) and len(verdict_lines(kin)) == 1


def test_prediction_interval_holds_95_percent_of_sampled_runs() -> None:
    r = _physics_run(50, 250, 0)
    lo, hi = r.prediction_interval
    rates = np.random.default_rng(0).binomial(300, r.predicted_success, 20_000) / 300
    inside = float(np.mean((rates >= lo) & (rates <= hi)))
    assert 0.95 <= inside <= 0.975


def test_near_boundary_flag_only_where_the_success_strays() -> None:
    from bayesgrasp.sim.result import summarize

    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    stable = pb.states.stable
    goal = stable[np.flatnonzero(pb.success_states(0.0))[0]]
    other = stable[np.flatnonzero(~pb.success_states(0.0))[0]]
    near = np.ones(300, bool)  # every trial started near a boundary

    def run(n_goal: int) -> list[str]:
        final = np.concatenate([np.full(n_goal, goal), np.full(300 - n_goal, other)])
        r = summarize("mujoco", pb, opt, final, np.zeros(300, bool), near, 1.0, 1e-3)
        return r.assumption_flags

    assert run(44) == []  # 0.147 observed, 0.148 predicted: a tight plan that works
    flags = run(25)  # 0.083: the success strays
    assert len(flags) == 1 and "300 of 300 trials started an action within" in flags[0]
