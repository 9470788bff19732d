"""The exact planner's plain-list path for parts of few states against its general paths.

``plan_exact`` runs three ways on the same problem, and every number must be the same bit
for bit (``float.hex``): plans, angles, final orientations, probabilities, costs,
tolerances, success arcs, the Bayes and most certain indices, every length's option:

- *fused* (the default at most ``sizes.SMALL`` states): one action type without an
  ``ArcPlanner``, its front taken in order of span only as far as needed
  (``arcs.SpanFront``; also with every arc left to its second batch), staircases,
  witnesses and angles on lists (``exact._plan_one_small``; for several action types
  ``arcs.small_options``);
- *general* (``arcs.FUSED = False``): the ``ArcPlanner`` search with ``ArcFront`` and
  ``Staircase`` objects, still on plain-Python fronts and staircases;
- *numpy* (``arcs.FUSED = False`` and ``arcs.SMALL = 0``): every front, staircase and pick
  by numpy.

The parts: the seed's study polygons, random and lattice (rounded, so with ties) clouds,
near-regular and exactly regular polygons (symmetric: every excess equal), thin ellipses,
rectangles and many-state parts near the cut-off; squeezes, push-grasps and both; accuracy
0 and above; uniform and non-uniform priors; unit, non-unit, first and retry costs; the
single and the symmetry goal; ``max_actions`` and ``report="best"``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bayesgrasp.planning.arcs as arcs
from bayesgrasp.errors import PartError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.transfer import TransferFunction
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.goal import Goal
from bayesgrasp.model.prior import HistogramPrior, Prior, UniformPrior, von_mises
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning.exact import plan_exact
from bayesgrasp.planning.result import PlanResult
from bayesgrasp.sizes import SMALL

TWO_PI = 2.0 * math.pi


@contextmanager
def paths(fused: bool, small: int) -> Iterator[None]:
    saved = arcs.FUSED, arcs.SMALL
    arcs.FUSED, arcs.SMALL = fused, small
    try:
        yield
    finally:
        arcs.FUSED, arcs.SMALL = saved


def bits(res: PlanResult) -> tuple[Any, ...]:
    """Everything a result reports, floats as their exact hex."""

    def h(x: float | None) -> str | None:
        return None if x is None else float(x).hex()

    opts = tuple(
        (
            tuple((s.kind, h(s.alpha)) for s in o.steps),
            h(o.final_orientation),
            h(o.success_probability),
            h(o.expected_cost),
            h(o.tolerance),
            tuple(h(x) for x in o.success_arc),
        )
        for o in res.options
    )
    return res.status, res.method, res.bayes, res.most_certain, opts


@contextmanager
def second_batch_only() -> Iterator[None]:
    """The fused planner's front with no arc in its first batch (all sorted in on demand)."""

    class Late(arcs.SpanFront):
        __slots__ = ()

        def __init__(self, stable: Any, lo: Any, hi: Any, max_span: float, first: float):
            super().__init__(stable, lo, hi, max_span, -1.0)

    saved = arcs.SpanFront
    arcs.SpanFront = Late  # type: ignore[misc]
    try:
        yield
    finally:
        arcs.SpanFront = saved  # type: ignore[misc]


def three_ways(make: Any, **kw: Any) -> PlanResult:
    """Plan a fresh problem (``make()``) the three ways; assert they agree; the fused one.

    The fused way runs twice: as it is, and with every arc of its front left to the second
    batch (:class:`~bayesgrasp.planning.arcs.SpanFront`).
    """
    fused = plan_exact(make(), **kw)
    with second_batch_only():
        late = plan_exact(make(), **kw)
    assert bits(fused) == bits(late), "fused != fused, second batch"
    with paths(False, SMALL):
        general = plan_exact(make(), **kw)
    with paths(False, 0):
        numpy_ = plan_exact(make(), **kw)
    assert bits(fused) == bits(general), "fused != general"
    assert bits(general) == bits(numpy_), "general != numpy"
    return fused


def test_the_fused_path_runs_on_few_states_only() -> None:
    """The fast path is taken where it should be (and the switches turn it off)."""
    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    assert arcs.few_states(pb.transfers.values())
    assert arcs.ArcPlanner.for_problem(pb).small
    with paths(True, 2):
        assert not arcs.ArcPlanner.for_problem(pb).small


def test_plan_exact_goes_through_the_fused_paths(monkeypatch: pytest.MonkeyPatch) -> None:
    """Not only the flag: the fused planner and the list angles run (and not when off)."""
    import bayesgrasp.planning.exact as exact

    calls = {"one": 0, "angles": 0}

    def counted(name: str, fn: Any) -> Any:
        def wrapper(*a: Any, **k: Any) -> Any:
            calls[name] += 1
            return fn(*a, **k)

        return wrapper

    monkeypatch.setattr(exact, "_plan_one_small", counted("one", exact._plan_one_small))
    monkeypatch.setattr(arcs, "small_options", counted("angles", arcs.small_options))
    rect = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    exact.plan_exact(Problem.build(rect))
    assert calls == {"one": 1, "angles": 0}  # one action type: its own angles
    exact.plan_exact(Problem.build(rect, actions=("squeeze", "push-grasp")))
    assert calls == {"one": 1, "angles": 1}  # two action types: the list angles only
    with paths(False, arcs.SMALL):
        exact.plan_exact(Problem.build(rect))
    assert calls == {"one": 1, "angles": 1}


@pytest.mark.parametrize("actions", [("squeeze",), ("push-grasp",), ("squeeze", "push-grasp")])
def test_study_polygons(actions: tuple[str, ...]) -> None:
    """The seed's study polygons (seed 1), every plan of every length."""
    rng = np.random.default_rng(1)
    count = 150 if actions == ("squeeze",) else 40
    for _ in range(count):
        part = random_polygon(rng)
        three_ways(lambda part=part: Problem.build(part, actions=actions))


@pytest.mark.parametrize("actions", [("squeeze",), ("push-grasp",)])
def test_every_study_polygon_fused_against_general(actions: tuple[str, ...]) -> None:
    """All 2000 of the seed's study polygons (seed 1): the fused planner against the
    general one, bit for bit (a few plans only tell them apart: the fused staircase of the
    longest plan evaluated at its first witness alone, the span front's bounds)."""
    rng = np.random.default_rng(1)
    parts = [random_polygon(rng) for _ in range(2000)]
    for part in parts if actions == ("squeeze",) else parts[:600]:
        fused = plan_exact(Problem.build(part, actions=actions))
        with paths(False, SMALL):
            general = plan_exact(Problem.build(part, actions=actions))
        assert bits(fused) == bits(general)


@pytest.mark.parametrize("accuracy", [0.3, 0.7, 0.78, 0.8, 1.2, 1.5, 1.57, 1.5708, 2.0])
@pytest.mark.parametrize("goal", ["single", "symmetry"])
def test_large_accuracies(accuracy: float, goal: str) -> None:
    """Gripper accuracies up to and past a quarter turn, the fused planner against the
    general one: the bound ``cap - 2 max(tol, accuracy - ROUNDING)`` up to which the fused
    one takes its front before the widths falls to and below ``tol`` here (it then takes
    the arcs below ``tol``, and the widths stop at the widest basin)."""
    rng = np.random.default_rng(4)
    parts = [Part.from_points(regular(4) * [1.5, 1.0]), Part.from_points(regular(3))]
    parts += [random_polygon(rng) for _ in range(12)]
    for part in parts:
        three_ways(lambda part=part: Problem.build(part, goal=Goal(goal), accuracy=accuracy))


def regular(n: int, rotation: float = 0.0) -> np.ndarray:
    t = TWO_PI * np.arange(n) / n + rotation
    return np.column_stack([np.cos(t), np.sin(t)])


def clouds() -> st.SearchStrategy[np.ndarray]:
    seed = st.integers(0, 2**32 - 1)
    return st.one_of(
        seed.map(lambda s: np.random.default_rng(s).random((10, 2))),  # like the study
        seed.map(lambda s: np.random.default_rng(s).random((25, 2))),  # more states
        seed.map(lambda s: np.round(np.random.default_rng(s).random((14, 2)) * 4) / 4),
        st.tuples(st.integers(3, 30), seed).map(
            lambda a: regular(a[0]) + np.random.default_rng(a[1]).uniform(-1e-9, 1e-9, (a[0], 2))
        ),
        st.tuples(st.integers(3, 30), seed).map(
            lambda a: regular(a[0]) + np.random.default_rng(a[1]).uniform(-3e-3, 3e-3, (a[0], 2))
        ),
        st.integers(3, 30).map(regular),  # exactly regular: symmetric, every excess equal
        seed.map(
            lambda s: (lambda t: np.column_stack([50.0 * np.cos(t), np.sin(t)]))(
                np.sort(np.random.default_rng(s).uniform(0.0, TWO_PI, 30))
            )
        ),  # thin
        st.floats(1.0, 3.0).map(lambda a: np.array([(0, 0), (a, 0), (a, 1), (0, 1)])),
    )


PRIORS: dict[str, Prior] = {
    "uniform": UniformPrior(),
    "von-mises": von_mises(1.0, 4.0, bins=720),
    "histogram": HistogramPrior([3, 1, 0, 2, 5, 1, 1, 4]),
}
COSTS = {
    "unit": CostModel(),
    "non-unit": CostModel({"squeeze": 0.7, "push-grasp": 1.3}, verify=0.3),
    "first": CostModel({"push-grasp": 4.0}, first={"squeeze": 5.0, "push-grasp": 0.1}, retry=0.2),
}


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pts=clouds(),
    actions=st.sampled_from([("squeeze",), ("push-grasp",), ("squeeze", "push-grasp")]),
    accuracy=st.sampled_from([0.0, 0.0, 0.01, 0.08]),
    prior=st.sampled_from(sorted(PRIORS)),
    cost=st.sampled_from(sorted(COSTS)),
    goal=st.sampled_from(["single", "single", "symmetry"]),
    max_actions=st.sampled_from([None, None, 1, 2]),
    report=st.sampled_from(["all", "all", "best"]),
)
def test_adversarial_parts(
    pts: np.ndarray,
    actions: tuple[str, ...],
    accuracy: float,
    prior: str,
    cost: str,
    goal: str,
    max_actions: int | None,
    report: str,
) -> None:
    try:
        part = Part.from_points(pts)
    except PartError:
        return

    def make() -> Problem:
        return Problem.build(
            part,
            prior=PRIORS[prior],
            cost=COSTS[cost],
            goal=Goal(goal),  # type: ignore[arg-type]
            actions=actions,
            accuracy=accuracy,
        )

    three_ways(make, max_actions=max_actions, report=report)


@pytest.mark.parametrize("n", [29, 31, 32, 33])
def test_many_states_at_the_cut_off(n: int) -> None:
    """Near-regular polygons of about SMALL states (either side of the cut-off)."""
    pts = regular(n) + np.random.default_rng(n).uniform(-1e-4, 1e-4, (n, 2))
    part = Part.from_points(pts)
    res = three_ways(lambda: Problem.build(part))
    assert res.ok
    res = three_ways(lambda: Problem.build(part, actions=("squeeze", "push-grasp")))
    assert res.ok


def small_transfer(pts: np.ndarray, kind: str) -> TransferFunction | None:
    """The ``kind`` transfer function of the hull of ``pts``, if it has at most SMALL states
    (``None`` for no part or more states)."""
    try:
        part = Part.from_points(pts)
    except PartError:
        return None
    f = Problem.build(part, actions=(kind,)).transfers[kind]
    return f if f.n_states <= SMALL else None


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(pts=clouds(), kind=st.sampled_from(["squeeze", "push-grasp"]), extra=st.floats(-0.5, 7.0))
def test_list_front_is_the_enumerated_front(pts: np.ndarray, kind: str, extra: float) -> None:
    """The plain-list front is numpy's enumeration of every arc, bit for bit, for any span
    bound."""
    f = small_transfer(pts, kind)
    if f is None:
        return
    fast = arcs.arc_front(f, f.period + extra)
    slow = arcs.arc_front(f, f.period + extra, prune=False)

    def lists(a: arcs.ArcFront) -> list[list[str]]:
        values = (a.span_list, a.width_list, a.s_first_list, a.lo_list)
        return [[x.hex() for x in v] for v in values]

    assert lists(fast) == lists(slow)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pts=clouds(),
    kind=st.sampled_from(["squeeze", "push-grasp"]),
    extra=st.floats(-0.5, 7.0),
    first=st.one_of(st.floats(-1.0, 8.0), st.integers(0, 40)),
    bounds=st.lists(st.one_of(st.floats(-1.0, 8.0), st.integers(0, 40)), max_size=6),
)
def test_span_front_is_a_prefix_of_the_enumerated_front(
    pts: np.ndarray, kind: str, extra: float, first: float | int, bounds: list[float | int]
) -> None:
    """The front taken in order of span (any first batch, any bounds asked, in any order)
    is the prefix of numpy's enumeration of every arc below the largest bound, bit for bit.

    An integer ``n`` stands for the span of front arc ``n`` (the batches' and the bounds'
    edges on an arc), and a bound for the next float above it."""
    f = small_transfer(pts, kind)
    if f is None:
        return
    max_span = f.period + extra
    slow = arcs.arc_front(f, max_span, prune=False)
    spans = slow.span_list
    stable, lo, _ = f.values
    if isinstance(first, int):
        first = spans[first % len(spans)]
    edges = [
        b if isinstance(b, float) else math.nextafter(spans[b % len(spans)], 9) for b in bounds
    ]
    front = arcs.SpanFront(*f.values, max_span, first)
    top = -math.inf
    for bound in [-math.inf, *edges]:
        front.cover(bound)
        top = max(top, bound)
        n = max(1, sum(x < top for x in slow.span_list))  # arc 0 (span 0) is always there
        assert [x.hex() for x in front.spans] == [x.hex() for x in slow.span_list[:n]]
        assert [x.hex() for x in front.widths] == [x.hex() for x in slow.width_list[:n]]
        assert [stable[i] for i in front.rows] == slow.s_first_list[:n]
        assert [lo[i] for i in front.rows] == slow.lo_list[:n]


def test_fast_constructors_make_the_same_objects() -> None:
    """The planners' fast constructors set every field as the dataclasses' own do."""
    from bayesgrasp.model.actions import SQUEEZE
    from bayesgrasp.planning.result import (
        PlanOption,
        PlanStep,
        new_option,
        new_result,
        short_turns,
        slot_setters,
    )

    for cls in (PlanStep, PlanOption, PlanResult):
        assert not hasattr(cls, "__post_init__"), cls  # nothing the fast paths would skip
    (step,), _ = short_turns([SQUEEZE], [-0.5])
    assert step == PlanStep("squeeze", -0.5) and type(step) is PlanStep
    steps = (PlanStep("squeeze", 0.25), PlanStep("push-grasp", -1.0))
    fields = (steps, 1.5, 0.75, 4.0, None, (0.1, 2.0))
    assert new_option(*fields) == PlanOption(*fields)
    for cls, values in ((PlanStep, ("squeeze", 0.25)), (PlanOption, fields)):
        made = object.__new__(cls)
        for setter, value in zip(slot_setters(cls), values, strict=True):
            setter(made, value)
        assert made == cls(*values)  # type: ignore[arg-type]
    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    opts = (PlanOption(*fields),)
    fast, slow = new_result(pb, opts, 0, 0, "exact"), PlanResult(pb, opts, 0, 0, "exact")
    for name in PlanResult.__slots__:
        assert getattr(fast, name) == getattr(slow, name), name


def test_choose_among_needs_plans() -> None:
    from bayesgrasp.planning.result import choose_among

    with pytest.raises(ValueError, match="no plans"):
        choose_among([], [])
    assert choose_among([math.inf, math.inf], [0.2, 0.2]) == (0, 0)
    assert choose_among([6.0, 6.0 * (1 + 1e-13), 5.0], [0.1, 0.5, 0.5 - 1e-10]) == (2, 1)


def test_short_turns_wrap_as_the_angle_helpers() -> None:
    """short_turns (its wrapping inlined) against angles.wrap and wrap_period, edges too."""
    from bayesgrasp.angles import wrap, wrap_period
    from bayesgrasp.model.actions import PUSH_GRASP, SQUEEZE
    from bayesgrasp.planning.result import short_turns

    edges = [q * math.pi / 2 + e for q in range(-9, 10) for e in (0.0, 1e-15, -1e-15, 1e-9)]
    rng = np.random.default_rng(5)
    angles = edges + rng.uniform(-20.0, 20.0, 200).tolist()
    actions = [SQUEEZE if b else PUSH_GRASP for b in rng.integers(0, 2, len(angles))]
    steps, carry = short_turns(actions, angles)
    ref_carry = 0.0
    for action, angle, step in zip(actions, angles, steps, strict=True):
        a = wrap(angle + ref_carry)
        short = wrap_period(a, action.gripper_period)
        ref_carry = a - short
        assert (step.kind, step.alpha.hex()) == (action.name, short.hex())
    assert carry.hex() == ref_carry.hex()
