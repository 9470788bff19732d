"""Planning parts with many states (issue 12): the fast paths against the general ones.

- Fronts: the pruned enumeration (:func:`~bayesgrasp.planning.arcs.arc_front` with
  ``prune=True``) against every arc (``prune=False``, itself checked against every pair in
  test_arcs.py), bit for bit, on random, near-regular, thin and many-state parts, squeezes
  and push-grasps, any span limit.
- Witness chains: bisection on the margin against the staircases (the same least margin;
  the chain replayed through the transfer functions keeps its success under every error
  pattern of that size), and the batched bisection against one chain at a time.
- ``report="best"``: the same Bayes and most certain plans as ``report="all"``.
- Memory: the traced peak of a 2 * 10^4-point part stays bounded.
"""

from __future__ import annotations

import itertools
import math
import tracemalloc

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bayesgrasp.errors import PartError, PlanningError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.transfer import TransferFunction
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning.arcs import ArcPlanner, arc_front
from bayesgrasp.planning.exact import plan_exact
from bayesgrasp.planning.result import execute_plan

TWO_PI = 2.0 * math.pi


def circle_points(n: int, seed: int) -> np.ndarray:
    """``n`` random points on the unit circle: about a third of them are states."""
    t = np.random.default_rng(seed).uniform(0.0, TWO_PI, n)
    return np.column_stack([np.cos(t), np.sin(t)])


def near_regular(n: int, noise: float, seed: int) -> np.ndarray:
    """A regular n-gon with its vertices moved by up to ``noise``."""
    t = TWO_PI * np.arange(n) / n
    pts = np.column_stack([np.cos(t), np.sin(t)])
    return pts + np.random.default_rng(seed).uniform(-noise, noise, pts.shape)


def thin(n: int, seed: int) -> np.ndarray:
    """Random points on an ellipse of aspect 50."""
    t = np.sort(np.random.default_rng(seed).uniform(0.0, TWO_PI, n))
    return np.column_stack([50.0 * np.cos(t), np.sin(t)])


def same_front(f: TransferFunction, max_span: float) -> None:
    a, b = arc_front(f, max_span, prune=True), arc_front(f, max_span, prune=False)
    for name in ("lo", "width", "s_first", "span"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.span_list == b.span_list and a.width_list == b.width_list


PARTS = {
    "circle": lambda seed: circle_points(1200, seed),
    "near-regular": lambda seed: near_regular(400, 1e-4, seed),
    "noisy-regular": lambda seed: near_regular(300, 3e-3, seed),
    "thin": lambda seed: thin(600, seed),
    "square": lambda seed: np.random.default_rng(seed).random((2000, 2)),
}


@pytest.mark.parametrize("name", sorted(PARTS))
def test_pruned_front_is_the_front_bit_for_bit(name: str) -> None:
    for seed in range(2):
        pb = Problem.build(Part.from_points(PARTS[name](seed)), actions=("squeeze", "push-grasp"))
        for f in pb.transfers.values():
            planner = ArcPlanner.for_problem(pb)
            for limit in (planner.max_span, 0.3, TWO_PI):
                same_front(f, limit)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    n=st.integers(20, 700),
    seed=st.integers(0, 2**32 - 1),
    limit=st.floats(0.0, TWO_PI),
    family=st.sampled_from(["circle", "near-regular", "thin"]),
)
def test_pruned_front_on_random_parts(n: int, seed: int, limit: float, family: str) -> None:
    pts = {
        "circle": circle_points(n, seed),
        "near-regular": near_regular(n, 1e-3, seed),
        "thin": thin(n, seed),
    }[family]
    same_front(Problem.build(Part.from_points(pts)).states, limit)


def replay_keeps_success(pb: Problem, chain_plan: object, tolerance: float) -> None:
    """Orientations of the success arc end at the goal under errors of 0.99 tolerance."""
    opt = chain_plan
    lo, hi = opt.success_arc  # type: ignore[attr-defined]
    theta = np.linspace(lo, hi, 401)[1:-1]
    steps = list(opt.steps)  # type: ignore[attr-defined]
    rng = np.random.default_rng(0)
    for signs in [
        np.zeros(len(steps) - 1),
        *(rng.choice([-1.0, 1.0], len(steps) - 1) for _ in range(4)),
    ]:
        turned = [steps[0]] + [
            type(s)(s.kind, s.alpha + 0.99 * tolerance * sign)
            for s, sign in zip(steps[1:], signs, strict=True)
        ]
        out = execute_plan(pb, turned, theta)
        err = np.abs(np.mod(out - opt.final_orientation + math.pi, TWO_PI) - math.pi)  # type: ignore[attr-defined]
        assert err.max() < 1e-6


@pytest.mark.parametrize("accuracy", [0.0, 2e-3])
@pytest.mark.parametrize("actions", [("squeeze",), ("squeeze", "push-grasp")])
def test_margin_bisection_equals_the_staircases(accuracy: float, actions: tuple[str, ...]) -> None:
    pb = Problem.build(Part.from_points(circle_points(300, 3)), actions=actions, accuracy=accuracy)
    rep = plan_exact(pb)
    planner = ArcPlanner.for_problem(pb)
    checked = 0
    for opt in rep.options:
        if opt.n_actions < 2:
            continue
        width = opt.success_arc[1] - opt.success_arc[0]
        _, best = planner.witnesses(opt.kinds, width)
        by_margin, margin = planner.witnesses_by_margin(opt.kinds, width)
        assert best is not None and margin is not None
        assert margin == pytest.approx(best, rel=1e-12, abs=1e-15)
        assert margin >= accuracy - 1e-13 and margin > planner.tol
        assert by_margin[0].width >= width - planner.tol
        assert by_margin[-1].span == 0.0
        assert [a.kind for a in by_margin] == list(opt.kinds)
        for a, b in itertools.pairwise(by_margin):
            assert 0.5 * (b.width - a.span) >= margin
        checked += 1
    assert checked >= 5


def test_long_chains_bisect_and_keep_their_success(monkeypatch: pytest.MonkeyPatch) -> None:
    pb = Problem.build(Part.from_points(circle_points(400, 5)))
    reference = plan_exact(pb)
    monkeypatch.setattr("bayesgrasp.planning.arcs.STAIR_CELLS", 0)
    rep = plan_exact(pb)
    assert len(rep.options) == len(reference.options)
    assert (rep.bayes, rep.most_certain) == (reference.bayes, reference.most_certain)
    for a, b in zip(rep.options, reference.options, strict=True):
        assert a.kinds == b.kinds
        assert a.success_probability == b.success_probability
        assert a.expected_cost == b.expected_cost
        if b.tolerance is None:
            assert a.tolerance is None
            continue
        assert a.tolerance == pytest.approx(b.tolerance, rel=1e-12, abs=1e-15)
        replay_keeps_success(pb, a, a.tolerance)


def test_batched_margins_equal_one_chain_at_a_time(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("bayesgrasp.planning.arcs.STAIR_CELLS", 0)
    pb = Problem.build(Part.from_points(circle_points(500, 7)))
    rep = plan_exact(pb)  # prepares the margins of every plan at once
    planner = ArcPlanner.for_problem(pb)
    for opt in rep.options:
        if opt.n_actions > 1:
            width = opt.success_arc[1] - opt.success_arc[0]
            _, margin = planner.witnesses_by_margin(opt.kinds, width)
            assert margin == opt.tolerance


@pytest.mark.parametrize(
    "points",
    [circle_points(400, 1), near_regular(200, 1e-3, 2), np.random.default_rng(4).random((12, 2))],
    ids=["circle", "near-regular", "random"],
)
def test_report_best_is_the_bayes_and_most_certain_of_all(points: np.ndarray) -> None:
    for actions, cost in [
        (("squeeze",), None),
        (("squeeze", "push-grasp"), CostModel({"push-grasp": 0.5})),
    ]:
        pb = Problem.build(Part.from_points(points), actions=actions, cost=cost)
        every, best = plan_exact(pb), plan_exact(pb, report="best")
        assert best.bayes_plan == every.bayes_plan
        assert best.most_certain_plan == every.most_certain_plan
        assert len(best.options) == len({every.bayes, every.most_certain})


def test_report_is_checked() -> None:
    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    with pytest.raises(PlanningError, match="`report`"):
        plan_exact(pb, report="some")  # type: ignore[arg-type]


@pytest.mark.slow
def test_memory_of_a_many_state_part_is_bounded() -> None:
    pts = circle_points(20_000, 0)
    tracemalloc.start()
    try:
        pb = Problem.build(Part.from_points(pts))
        rep = plan_exact(pb, report="best")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    k = pb.n_states
    assert k > 10_000
    assert rep.most_certain_plan.success_probability == pytest.approx(0.5)  # period pi
    # O(K) memory: the K^2 arcs would be 8 bytes x 1.4e8 = 1.1 GB each array.
    assert peak < 200e6, f"{peak / 1e6:.0f} MB for {k} states"


@settings(max_examples=60, deadline=None)
@given(
    pts=st.one_of(
        st.integers(0, 2**32 - 1).map(lambda s: np.random.default_rng(s).random((10, 2))),
        st.integers(0, 2**32 - 1).map(
            lambda s: np.round(np.random.default_rng(s).random((14, 2)) * 4) / 4
        ),
        st.integers(3, 40).map(lambda n: near_regular(n, 1e-9, n)),
        st.integers(0, 2**32 - 1).map(lambda s: thin(30, s)),
    ),
    accuracy=st.sampled_from([0.0, 0.01]),
    actions=st.sampled_from([("squeeze",), ("squeeze", "push-grasp")]),
)
def test_plain_python_and_numpy_plans_are_bit_identical(
    pts: np.ndarray, accuracy: float, actions: tuple[str, ...]
) -> None:
    import bayesgrasp.planning.arcs as arcs

    try:
        part = Part.from_points(pts)
    except PartError:
        return
    pb = Problem.build(part, actions=actions, accuracy=accuracy)
    small = plan_exact(pb)
    for f in pb.transfers.values():
        for limit in (0.0, 1.0, TWO_PI):
            a, b = arcs.arc_front(f, limit), arcs.arc_front(f, limit, prune=False)
            assert a.span_list == b.span_list and a.width_list == b.width_list
            assert np.array_equal(a.lo, b.lo) and np.array_equal(a.s_first, b.s_first)
    saved = arcs.SMALL
    arcs.SMALL = 0  # every front, staircase and pick by numpy
    try:
        large = plan_exact(Problem.build(part, actions=actions, accuracy=accuracy))
    finally:
        arcs.SMALL = saved
    assert large.options == small.options
    assert (large.bayes, large.most_certain) == (small.bayes, small.most_certain)
