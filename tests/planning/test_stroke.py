"""Plans within the gripper's stroke against a brute-force search and the robot files' check.

The brute force (:func:`_brute`) runs every plan of a grid of first angles and turns on the
prior's sample orientations through the transfer functions, and measures the openings as the
robot files define them (the part's widest before the first action; before a later action the
widest ``d`` of the orientations the samples are in, turned; after each action ``d`` of the
orientations reached); no arcs, classes or hyperstates.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import PlanningError
from bayesgrasp.io import resolve_part
from bayesgrasp.io.export import Stroke, check_stroke
from bayesgrasp.model import Problem
from bayesgrasp.model.prior import SamplePrior
from bayesgrasp.planning import plan_exact, solve
from bayesgrasp.planning.strategy import evaluate, plan_strategy
from bayesgrasp.planning.stroke import fitting_turns, plan_within_stroke, too_wide

SAMPLES = {"three": [0.1, 0.2, 1.3], "two": [0.3, 2.0]}


def _problem(name: str, samples: str) -> Problem:
    return Problem.build(resolve_part(name), prior=SamplePrior(np.array(SAMPLES[samples])))


def _brute(pb: Problem, k: int, lo: float, hi: float, n: int) -> float:
    """The best success of a k-squeeze plan on an n-point grid (first angle and turns)."""
    d, f = pb.diameter, pb.transfers["squeeze"]
    widest = float(np.max(d(np.linspace(0, math.pi, 20001))))
    if widest > hi * (1 + 1e-9):
        return 0.0
    samples = np.asarray(pb.prior.angles)
    grid = np.linspace(-math.pi, math.pi, n, endpoint=False) + 1e-3 * math.sqrt(2)
    goals = [pb.success_states(float(s)) for s in pb.states.stable]
    stable = np.asarray(pb.states.stable)
    best = 0.0
    for angles in itertools.product(grid, repeat=k):
        t = np.mod(f(samples - angles[0]), 2 * math.pi)
        ok = np.min(d(t)) >= lo * (1 - 1e-9)
        for a in angles[1:]:
            if not ok:
                break
            ok = np.max(d(t - a)) <= hi * (1 + 1e-9)
            t = np.mod(f(t - a), 2 * math.pi)
            ok = ok and np.min(d(t)) >= lo * (1 - 1e-9)
        if not ok:
            continue
        state = np.argmin(np.abs(np.angle(np.exp(1j * (t[:, None] - stable[None, :])))), axis=1)
        best = max(best, max(float(np.mean(g[state])) for g in goals))
    return best


@pytest.mark.parametrize(
    ("name", "samples", "lo"),
    [("key", "three", 24.3), ("key", "two", 24.3), ("triangle", "three", 36.0)],
)
def test_no_grid_plan_within_the_stroke_beats_the_planner(
    name: str, samples: str, lo: float
) -> None:
    pb = _problem(name, samples)
    res = plan_within_stroke(pb, min_opening=lo, max_actions=2)
    assert res.ok
    stroke = Stroke(lo, math.inf)
    for k, opt in enumerate(res.options, start=1):
        brute = _brute(pb, k, lo, math.inf, 180 if k == 1 else 90)
        assert brute <= opt.success_probability + 1e-12
        assert brute >= opt.success_probability - 1e-12  # the grid finds the planner's best
        check_stroke(pb, opt, stroke)  # the robot files' check passes
        ev = evaluate(pb, plan_strategy(pb, opt))
        assert_allclose(ev.success_probability, opt.success_probability, rtol=1e-9)


def test_the_stroke_costs_success_where_it_binds() -> None:
    pb = _problem("key", "three")
    free = plan_exact(pb, max_actions=2)
    tight = plan_within_stroke(pb, min_opening=24.3, max_actions=2)
    assert tight.options[0].success_probability < free.options[0].success_probability
    with pytest.raises(Exception, match="less than the least opening"):
        check_stroke(pb, free.options[0], Stroke(24.3, math.inf))


@pytest.mark.parametrize("name", ["rectangle", "key", "triangle", "house", "hand"])
def test_an_unbounded_stroke_gives_the_exact_planners_probabilities(name: str) -> None:
    pb = Problem.build(resolve_part(name))
    res = plan_within_stroke(pb, max_actions=3)
    exact = plan_exact(pb, max_actions=3, report="all")
    for ours, theirs in zip(res.options, exact.options, strict=False):
        assert_allclose(ours.success_probability, theirs.success_probability, atol=1e-12)
        ev = evaluate(pb, plan_strategy(pb, ours))
        assert_allclose(ev.success_probability, ours.success_probability, atol=1e-12)


def test_a_part_wider_than_the_stroke_has_no_plan() -> None:
    pb = Problem.build(resolve_part("rectangle"))
    res = plan_within_stroke(pb, max_opening=30.0)
    assert res.status == "no-plan" and "widest" in str(res.reason)


def test_too_wide_and_fitting_turns_by_sampling() -> None:
    pb = Problem.build(resolve_part("key"))
    d = pb.diameter
    limit = float(np.quantile(d(np.linspace(0, math.pi, 1001)), 0.9))
    arcs = too_wide(d, limit)
    th = np.linspace(0, math.pi, 20011, endpoint=False)
    inside = np.zeros(len(th), dtype=bool)
    for a, b in arcs:
        inside |= (np.mod(th - a, math.pi) < b - a) & (np.mod(th - a, math.pi) > 0)
    wide = d(th) > limit * (1 + 1e-9)
    assert np.mean(inside == wide) > 0.999  # all but the grid points at an arc's end
    thetas = np.asarray(pb.states.stable[:2])
    fit = fitting_turns(-1.0, 2.0, thetas, arcs)
    assert fit is not None
    al = np.linspace(fit[0], fit[1], 501)[1:-1]
    assert np.all(np.max(d(thetas[:, None] - al[None, :]), axis=0) <= limit * (1 + 1e-6))


def test_solve_plans_within_the_stroke() -> None:
    pb = _problem("key", "three")
    res = solve(pb, stroke=(24.3, math.inf), max_actions=2)
    assert res.method == "stroke" and res.plans is not None
    assert_allclose(res.plans.most_certain_plan.success_probability, 1.0)
    assert_allclose(res.evaluation.success_probability, res.success_probability)
    with pytest.raises(PlanningError, match="stroke"):
        solve(pb, stroke=(24.3, math.inf), sensor="width")
