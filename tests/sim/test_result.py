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
