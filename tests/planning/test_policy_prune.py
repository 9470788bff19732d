"""The policy planner's prunings against the same search without them.

``plan_policy(..., _prune=...)`` turns each pruning off: budgets passed down the search
("cut"), values found at higher prices used as lower bounds ("floor"), and the parametric
search started from the best ratio one action shorter ("deepen"). Each must leave the
optimal expected cost unchanged (to 1e-9); the exhaustive AND-OR test in
``test_policy.py`` checks the pruned search against an independent reference.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.model import CostModel, HistogramPrior, Problem
from bayesgrasp.model.sensing import StateSpace, WidthSensor
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning.policy import Policy, make_solver, plan_policy
from bayesgrasp.planning.programme import Solver

ALL = frozenset({"cut", "floor", "deepen"})
SUBSETS = [frozenset(), frozenset({"cut"}), frozenset({"floor"}), frozenset({"deepen"}), ALL]
ACTIONS = [("squeeze",), ("push-grasp",), ("squeeze", "push-grasp")]


def noisy(pb: Problem, rel: float, res: float) -> WidthSensor:
    sigma = rel * float(pb.diameter.lengths.max())
    return WidthSensor(sigma, res * sigma)


def agree(a: Policy, b: Policy) -> None:
    assert_allclose(a.expected_cost, b.expected_cost, rtol=0, atol=1e-9)
    assert_allclose(a.success_probability * a.expected_cost, a.cycle_cost, atol=1e-12)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    points=st.integers(4, 9),
    rel=st.sampled_from([0.003, 0.01, 0.03, 0.1]),
    res=st.sampled_from([0.5, 1.0, 2.0]),
    depth=st.integers(1, 3),
    actions=st.sampled_from(ACTIONS),
    verify=st.sampled_from([1.0, 4.0]),
    accuracy_deg=st.sampled_from([0.0, 0.0, 3.0]),
)
def test_prunings_keep_the_optimum(
    seed: int,
    points: int,
    rel: float,
    res: float,
    depth: int,
    actions: tuple[str, ...],
    verify: float,
    accuracy_deg: float,
) -> None:
    acc = math.radians(accuracy_deg)
    cost = CostModel(verify=verify)
    pb = Problem.build(random_polygon(seed, points), actions=actions, cost=cost, accuracy=acc)
    if depth == 3 and len(actions) > 1:
        depth = 2  # mixed noisy push-grasp trees at depth 3 take seconds without pruning
    sensor = noisy(pb, rel, res)
    plain = plan_policy(pb, sensor, depth, sensorless=False, _prune=())
    for prune in SUBSETS[1:]:
        agree(plan_policy(pb, sensor, depth, sensorless=False, _prune=prune), plain)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), rel=st.sampled_from([0.01, 0.05]))
def test_prunings_keep_the_optimum_of_recognition(seed: int, rel: float) -> None:
    g = np.random.default_rng(seed)
    pbs = [Problem.build(random_polygon(g, 5)) for _ in range(2)]
    sensor = noisy(pbs[0], rel, 1.0)
    prior = (0.3, 0.7)
    plain = plan_policy(pbs, sensor, 2, part_prior=prior, _prune=())
    agree(plan_policy(pbs, sensor, 2, part_prior=prior), plain)


@pytest.mark.parametrize("prune", SUBSETS[1:], ids=lambda s: "+".join(sorted(s)) or "none")
def test_prunings_with_several_first_angles(prune: frozenset[str]) -> None:
    """A non-uniform prior: several roots share the programme (and its floors)."""
    prior = HistogramPrior([4.0, 1.0, 1.0, 2.0, 1.0, 1.0])
    pb = Problem.build(random_polygon(5, 6), prior=prior)
    sensor = noisy(pb, 0.02, 1.0)
    plain = plan_policy(pb, sensor, 3, _prune=())
    agree(plan_policy(pb, sensor, 3, _prune=prune), plain)


def test_prunings_visit_fewer_beliefs() -> None:
    """The benchmark's polygon 1402 (every reading fits several states): the bounds bite."""
    g = np.random.default_rng(0)
    for _ in range(1403):
        part = random_polygon(g)
    pb = Problem.build(part)
    sensor = noisy(pb, 0.01, 0.5)
    plain = plan_policy(pb, sensor, 3, sensorless=False, _prune=())
    for prune in SUBSETS[1:]:
        pruned = plan_policy(pb, sensor, 3, sensorless=False, _prune=prune)
        agree(pruned, plain)
        if "floor" in prune:
            assert pruned.searched < plain.searched


# -- the bounds themselves ----------------------------------------------------------------


def programme(seed: int, rel: float, prune: frozenset[str]) -> Solver:
    pb = Problem.build(random_polygon(seed, 8))
    space = StateSpace.build([pb])
    return make_solver(space, noisy(pb, rel, 0.5), prune)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    rel=st.sampled_from([0.01, 0.03, 0.1]),
    r=st.integers(1, 2),
    shift=st.floats(-0.3, 0.3),
)
def test_a_cut_bounds_the_value_and_values_fall_with_the_price(
    seed: int, rel: float, r: int, shift: float
) -> None:
    """``value(q, r, budget)``: the exact value, or a bound in ``[budget, V]``; and ``V``
    does not fall when the price falls (``c - lambda p`` grows as ``lambda`` shrinks: what
    makes the values of earlier, higher prices lower bounds later)."""
    exact = programme(seed, rel, frozenset())
    cut = programme(seed, rel, ALL)
    g = np.random.default_rng(seed)
    qs = g.dirichlet(np.full(exact.space.n_states, 0.5), size=4)
    last = None
    for lam in (12.0, 8.0, 5.0):
        exact.set_price(lam)
        cut.set_price(lam)
        vals = np.array([exact.value(q, r)[0] for q in qs])
        if last is not None:
            assert np.all(vals >= last - 1e-12)
        last = vals
        for q, v in zip(qs, vals, strict=True):
            for budget in (v + shift, v - abs(shift), v + abs(shift) + 1e-6):
                got, c, p, ok = cut.value(q, r, budget)
                if ok:
                    assert_allclose(got, v, rtol=0, atol=1e-9)
                    assert_allclose(c - lam * p, v, rtol=0, atol=1e-9)
                else:
                    assert budget - 1e-12 <= got <= v + 1e-9
