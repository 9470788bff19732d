"""The arc machinery (planning/arcs.py) against brute forces that share none of its logic.

- Every arc: each (first basin, number of basins) pair of a transfer function, its width
  and the span of its image, enumerated in plain Python loops.
- Fronts: the arcs that no other arc dominates (as wide or wider and spanning no more),
  found by comparing every pair.
- Staircases: ``tau(x)``, the best least margin of the actions left, by maximising over
  every arc (not only those of the front) for the last two actions.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.transfer import TransferFunction
from bayesgrasp.model.problem import Goal, Problem
from bayesgrasp.planning import plan_exact, plan_guaranteed
from bayesgrasp.planning.arcs import (
    ArcPlanner,
    Counts,
    arc_front,
    chain_option,
    pareto_front,
    staircase,
    widest_arc,
)
from bayesgrasp.planning.result import execute_plan

TWO_PI = 2.0 * math.pi
TOL = 1e-9


def random_parts(rng: np.random.Generator, count: int, points: int = 10) -> list[Part]:
    """The seed's random polygons: the hull of uniform points in the unit square."""
    return [Part.from_points(rng.random((points, 2))) for _ in range(count)]


def transfers(rng: np.random.Generator, count: int) -> list[TransferFunction]:
    """Squeeze and push-grasp functions of random parts."""
    out: list[TransferFunction] = []
    for part in random_parts(rng, count):
        out.extend(Problem.build(part, actions=("squeeze", "push-grasp")).transfers.values())
    return out


def all_arcs(f: TransferFunction) -> list[tuple[float, float, float, float]]:
    """(lo, width, s_first, span) of every arc of ``f``: basins i .. i + m, m < K."""
    k = f.n_states
    out = []
    for i in range(k):
        for m in range(k):
            j = i + m
            hi = f.basin_hi[j % k] + TWO_PI * (j // k)
            s = f.stable[j % k] + TWO_PI * (j // k)
            out.append((float(f.basin_lo[i]), hi - f.basin_lo[i], f.stable[i], s - f.stable[i]))
    return out


def brute_front(f: TransferFunction, max_span: float) -> set[tuple[float, float]]:
    """(span, width) of the undominated arcs whose image spans less than ``max_span``."""
    arcs = [(span, width) for _, width, _, span in all_arcs(f) if span < max_span or span == 0]
    pairs = set(arcs)
    return {
        (s, w)
        for s, w in pairs
        if not any((s2 <= s and w2 >= w) and (s2, w2) != (s, w) for s2, w2 in pairs)
    }


def test_front_against_every_pair(rng: np.random.Generator) -> None:
    for f in transfers(rng, 25):
        for max_span in [0.0, *rng.uniform(0.0, TWO_PI + 0.5, 4)]:
            front = arc_front(f, max_span)
            got = sorted(zip(front.span_list, front.width_list, strict=True))
            want = sorted(brute_front(f, max_span))
            assert len(got) == len(want) == len(front)
            assert_allclose(np.array(got), np.array(want), atol=1e-12)
            # Sorted by span, widths strictly increasing; every arc is a real arc of f.
            assert np.all(np.diff(front.span) > 0) and np.all(np.diff(front.width) > 0)
            for n in range(len(front)):
                a = front.arc(n)
                assert a.kind == f.kind
                assert a.span < max_span or a.span == 0.0
                assert np.isclose(np.mod(a.lo - f.basin_lo, TWO_PI), 0.0).any()
                ends = f(np.array([a.lo + 1e-7, a.hi - 1e-7])) - [a.s_first, a.s_last]
                assert_allclose(np.mod(ends + math.pi, TWO_PI) - math.pi, 0.0, atol=1e-9)


def test_widest_against_every_pair(rng: np.random.Generator) -> None:
    for f in transfers(rng, 25):
        front = arc_front(f, TWO_PI + 1.0)
        arcs = all_arcs(f)
        for max_span in [-1.0, 0.0, 1e-9, *rng.uniform(0.0, TWO_PI + 0.5, 6)]:
            want = max((w for _, w, _, s in arcs if s < max_span), default=0.0)
            assert front.widest(max_span) == pytest.approx(want, abs=1e-12)


@given(
    st.lists(
        st.tuples(st.integers(0, 6), st.integers(0, 6)).map(lambda t: (float(t[0]), float(t[1]))),
        min_size=1,
        max_size=30,
    )
)
def test_pareto_front_against_dominance(pairs: list[tuple[float, float]]) -> None:
    cost = np.array([c for c, _ in pairs])
    value = np.array([v for _, v in pairs])
    idx = pareto_front(cost, value)
    undominated = {
        (c, v)
        for c, v in pairs
        if not any(c2 <= c and v2 >= v and (c2, v2) != (c, v) for c2, v2 in pairs)
    }
    assert {(cost[i], value[i]) for i in idx} == undominated
    assert len(idx) == len(undominated)  # each pair once: the first index of equal pairs
    for i in idx:
        assert i == pairs.index((cost[i], value[i]))
    assert np.all(np.diff(cost[idx]) > 0) and np.all(np.diff(value[idx]) > 0)


def brute_tau_last(f: TransferFunction, x: float, tol: float, accuracy: float) -> float:
    """Best margin of the last action for an image of span x: a single basin, centred."""
    best = max((w - x) / 2.0 for _, w, _, s in all_arcs(f) if s == 0.0)
    return best if best > tol and best >= accuracy - 1e-13 else -math.inf


def brute_tau_two(f: TransferFunction, g: TransferFunction, x: float, tol: float) -> float:
    """Best least margin of the actions f then g for an image of span x, over every arc."""
    best = -math.inf
    for _, w, _, s in all_arcs(f):
        rest = brute_tau_last(g, s, tol, 0.0)
        if rest > tol:
            best = max(best, min((w - x) / 2.0, rest))
    return best if best > tol else -math.inf


def test_staircases_against_every_arc(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 15, points=7):
        pb = Problem.build(part, actions=("squeeze", "push-grasp"))
        fs = list(pb.transfers.values())
        for f, g in [(fs[0], fs[0]), (fs[0], fs[1]), (fs[1], fs[0])]:
            last = staircase(arc_front(g, TWO_PI + TOL), None, TOL)
            two = staircase(arc_front(f, TWO_PI + TOL), last, TOL)
            xs = np.concatenate([[0.0], rng.uniform(0.0, TWO_PI, 12)])
            want_last = [brute_tau_last(g, x, TOL, 0.0) for x in xs]
            want_two = [brute_tau_two(f, g, x, TOL) for x in xs]
            assert_allclose(last.tau(xs), want_last, atol=1e-12)
            assert_allclose(two.tau(xs), want_two, atol=1e-12)
            for x, w in zip(xs, want_two, strict=True):
                if math.isfinite(w):  # the arc picked attains the margin
                    a = two.pick(float(x))
                    got = min((a.width - x) / 2.0, float(last.tau(np.array([a.span]))[0]))
                    assert got == pytest.approx(w, abs=1e-12)


def test_staircase_honours_accuracy(rng: np.random.Generator) -> None:
    for f in transfers(rng, 10):
        front = arc_front(f, TWO_PI + TOL)
        xs = rng.uniform(0.0, math.pi, 20)
        for acc in (0.0, 0.05, 0.3):
            tau = staircase(front, None, TOL, acc).tau(xs)
            want = [brute_tau_last(f, x, TOL, acc) for x in xs]
            assert_allclose(tau, want, atol=1e-12)
            assert np.all((tau == -np.inf) | (tau >= acc - 1e-13))


def test_widest_arc_is_the_widest_of_least_span(rng: np.random.Generator) -> None:
    for f in transfers(rng, 20):
        for limit in [0.0, *rng.uniform(0.0, TWO_PI + 0.5, 4)]:
            a = widest_arc(f, limit, TOL)
            fits = [(w, s) for _, w, _, s in all_arcs(f) if s < limit - 2 * TOL or s == 0.0]
            widest = max(w for w, _ in fits)
            assert a.width == pytest.approx(widest, abs=1e-12)
            assert a.span == pytest.approx(min(s for w, s in fits if w >= widest - TOL), abs=1e-12)


def test_widest_reachable_is_where_the_guaranteed_widths_stop(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 20):
        for deg in (0.0, 2.0, 8.0):
            pb = Problem.build(part, accuracy=math.radians(deg))
            planner = ArcPlanner.for_problem(pb)
            g = plan_guaranteed(pb)
            reach = planner.widest_reachable(planner.period, 50)
            if g.status == "ok":
                assert reach >= planner.period - 1e-6
            else:
                assert reach == pytest.approx(max(g.widths), abs=1e-12)
            # The exact planner's most certain plan collapses the widest reachable arc.
            best = plan_exact(pb).most_certain_plan
            arc = best.success_arc[1] - best.success_arc[0]
            assert arc == pytest.approx(min(reach, TWO_PI), abs=1e-9) or arc >= planner.period


def test_planner_period_and_tolerance() -> None:
    rect = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    planner = ArcPlanner.for_problem(Problem.build(rect))
    assert planner.period == pytest.approx(math.pi)
    assert planner.tol == Problem.build(rect).states.angle_tol
    tri = Part.from_points([(0, 0), (3, 0), (1, 2)])
    both = ArcPlanner.for_problem(Problem.build(tri, actions=("squeeze", "push-grasp")))
    assert both.period == pytest.approx(TWO_PI)
    assert both.max_span == pytest.approx(TWO_PI + both.tol)
    # The rectangle's symmetry halves its push-grasp period; a symmetry goal halves again.
    sym = Problem.build(rect, goal=Goal("symmetry"), actions=("squeeze", "push-grasp"))
    assert ArcPlanner.for_problem(sym).period == pytest.approx(math.pi)


def test_chain_options_keep_their_success_under_errors(rng: np.random.Generator) -> None:
    """Every (counts, first type) the planner extends to: its witness chain, turned into a
    plan, sends its success arc to the final orientation, also with every turn off by just
    under the chain's margin (replayed through the transfer functions)."""
    for part in random_parts(rng, 12, points=7):
        pb = Problem.build(part, actions=("squeeze", "push-grasp"))
        planner = ArcPlanner.for_problem(pb)
        level: list[Counts] = [(0, 0)]
        for _ in range(3):
            candidates, level = planner.extend(level)
            for key, first, width in candidates:
                kinds = planner.order(key, first)
                assert sorted(kinds) == sorted(["squeeze"] * key[0] + ["push-grasp"] * key[1])
                chain, margin = planner.witnesses(kinds, width)
                assert [a.kind for a in chain] == list(kinds)
                assert chain[0].width >= width - planner.tol and chain[-1].span == 0.0
                placed = min(width, planner.period)
                o = chain_option(pb, chain, margin, placed, 0.5, 1.0, chain[0].width)
                assert o.kinds == kinds and o.tolerance == margin
                lo, hi = o.success_arc
                theta = np.linspace(lo, hi, 301)[1:-1]
                patterns = [np.zeros(len(kinds) - 1)]
                if margin is not None:
                    patterns += [0.999 * margin * rng.choice([-1.0, 1.0], len(kinds) - 1)]
                for e in patterns:
                    steps = [o.steps[0]] + [
                        replace(s, alpha=s.alpha + d) for s, d in zip(o.steps[1:], e, strict=True)
                    ]
                    out = execute_plan(pb, steps, theta)
                    d = np.mod(out - o.final_orientation + math.pi, TWO_PI) - math.pi
                    # Orientations within the tolerance of a basin boundary may go either way.
                    edge = np.min(np.abs(np.subtract.outer(theta, [lo, hi])), axis=1) < 1e-6
                    assert np.all((np.abs(d) < 1e-9) | edge)
