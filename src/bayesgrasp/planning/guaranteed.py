"""Guaranteed plans: the shortest plan that orients every initial orientation (Goldberg 1993).

A guaranteed plan sends every initial orientation (but the measure-zero unstable
equilibria) to one final orientation, up to the period ``T`` of the transfer functions: a
squeeze cannot tell ``theta`` from ``theta + pi`` (nor from ``theta + T`` for a symmetric
part), so the best any squeeze plan can do is to collapse the circle onto the ``2 pi / T``
orientations ``phi + j T``. Push-grasps have period ``2 pi`` for an asymmetric part; with
them the plan can orient the part uniquely. The goal's symmetry group (a ``"symmetry"``
goal) can only make ``T`` smaller: ``T = min(largest period of the action types,
2 pi / group)``.

Backchaining (Goldberg 1993, section 4): every transfer function commutes with a shift by
``T``, so collapsing one open arc of length ``T`` collapses its copies too, hence the whole
circle up to ``T``. Let ``W_k`` be the widest arc collapsible by ``k`` actions. An arc
``(B_i, B_j)`` between two basin boundaries of the first action's transfer function ``F``
goes to the stable orientations ``S_{i+1} .. S_j``; the remaining actions collapse them iff
their span is strictly less than the arc the remaining actions can collapse. So ``W_1`` is
the widest basin and ``W_{k+1}`` the widest boundary-to-boundary arc of any action type
whose stable orientations span less than ``W_k``; the guaranteed plan has the least ``k``
with ``W_k >= T``. Goldberg proved it exists for every polygon (the widths grow strictly
until they reach ``T``); Chen and Ierardi bounded its length by ``2 n - 1`` for an n-gon.

With several action types and costs, plans with the same number of actions may differ in
cost; the plan returned is the cheapest of the shortest (the width of an arc collapsible
with given counts of each type does not depend on their order after the first action, the
argument of :mod:`bayesgrasp.planning.exact`).

Cost: O(K log K) per (count of each type, first type) with K stable orientations, memory
O(K). The exact planner computes the same lengths another way (Pareto fronts of arcs and
staircases), so the two check each other; the tests add a search over sets of states.

The plan's angles centre each image in the next arc, so each turn may err by half the room
left (the plan's tolerance). The arcs are the widest ones, of least span among equals; the
exact planner instead chooses the chain that maximises the least margin, so its most certain
plan of the same length may have a larger tolerance.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import PlanningError
from ..problem import Problem
from ..transfer import TransferFunction
from .plan import PlanOption, PlanStep

__all__ = ["GuaranteedPlan", "plan_guaranteed", "widest_arc"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class Arc:
    """A collapsible arc ``(lo, hi)`` of one action, in that action's gripper frame.

    ``s_first .. s_last`` are the stable orientations it is sent to (its image).
    """

    kind: str
    lo: float
    hi: float
    s_first: float
    s_last: float

    @property
    def width(self) -> float:
        """Length of the arc."""
        return self.hi - self.lo

    @property
    def span(self) -> float:
        """Length of its image."""
        return self.s_last - self.s_first


@dataclass(frozen=True, slots=True)
class GuaranteedPlan:
    """The shortest plan that orients every initial orientation up to ``period``.

    Attributes
    ----------
    option : PlanOption
        Its steps, final orientation, tolerance, and (for the problem's single or symmetry
        goal and prior) success probability and expected cost.
    period : float
        The plan sends every orientation to ``final_orientation + j * period``.
    widths : tuple of float
        ``W_1 .. W_k``: the widest collapsible arc with 1 .. k actions.
    """

    option: PlanOption
    period: float
    widths: tuple[float, ...]

    @property
    def n_actions(self) -> int:
        """Number of actions."""
        return self.option.n_actions


def widest_arc(f: TransferFunction, limit: float, tol: float) -> Arc:
    """Widest boundary-to-boundary arc of ``f`` whose image spans less than ``limit``.

    For each first basin ``i`` the arc runs to the last basin whose stable orientation lies
    within the limit of ``S_i`` (a binary search, O(K log K) in all, memory O(K)); among the
    widest arcs the one of least span is returned (it leaves the most room to the next
    action).

    Parameters
    ----------
    f : TransferFunction
    limit : float
        The image must fit in an open arc of this length (``span < limit - 2 tol``); a
        limit at most ``2 tol`` admits a single basin (its image is one point).
    tol : float
        Angle tolerance.

    Returns
    -------
    Arc

    Examples
    --------
    >>> from bayesgrasp.geometry import ConvexPolygon
    >>> from bayesgrasp.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> one = widest_arc(s, 0.0, 1e-9)  # a single basin
    >>> two = widest_arc(s, one.width, 1e-9)
    >>> [round(float(np.degrees(a.width)), 6) for a in (one, two)]
    [126.869898, 180.0]
    """
    k = f.n_states
    s = np.concatenate([f.stable, f.stable + TWO_PI])  # (2K,)
    hi = np.concatenate([f.basin_hi, f.basin_hi + TWO_PI])
    i = np.arange(k)  # (K,) first basin of each arc
    # (K,) last basin: the last stable orientation below S_i + limit - 2 tol, at least i
    # (one basin, image a point), at most i + K - 1 (the whole circle).
    j = np.searchsorted(s, f.stable + (limit - 2.0 * tol), side="left") - 1
    j = np.clip(j, i, i + k - 1)
    width = hi[j] - f.basin_lo  # (K,)
    span = s[j] - f.stable  # (K,)
    cand = np.flatnonzero(width >= width.max() - tol)
    b = int(cand[np.argmin(span[cand])])
    jb = int(j[b])
    return Arc(f.kind, float(f.basin_lo[b]), float(hi[jb]), float(s[b]), float(s[jb]))


def _wrap(a: float) -> float:
    """Angle in (-pi, pi]."""
    r = math.remainder(a, TWO_PI)
    return math.pi if r == -math.pi else r


def plan_guaranteed(problem: Problem) -> GuaranteedPlan:
    """The shortest plan (then the cheapest) that orients the part up to the period.

    Uses the problem's action types, cost model (to break ties between plans of the same
    length), goal (its symmetry group may shorten the period) and prior (only to place the
    first action and report the success probability of the single goal). The first action
    may be made at any gripper angle: the plan is guaranteed from every orientation.

    Parameters
    ----------
    problem : Problem

    Returns
    -------
    GuaranteedPlan

    Raises
    ------
    PlanningError
        If no plan is found within ``4 n + 8`` actions (a degenerate part; Goldberg 1993
        bounds plans by O(n)).

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)])
    >>> g = plan_guaranteed(Problem.build(rect))
    >>> g.n_actions, round(float(np.degrees(g.period)), 6), g.option.success_probability
    (2, 180.0, 0.5)
    """
    tol = problem.states.angle_tol
    kinds = problem.action_kinds
    transfers = problem.transfers
    poly = problem.part.hull
    period = min(max(transfers[t].period for t in kinds), TWO_PI / problem.goal_group)
    reach = period - max(tol, poly.tol.symmetry)
    index = {t: i for i, t in enumerate(kinds)}
    zero = (0,) * len(kinds)
    best: dict[tuple[int, ...], Arc] = {}  # widest arc for each count of action types
    widths: list[float] = []
    level = [zero]
    for _ in range(4 * poly.n_sides + 8):
        found: list[tuple[float, float, tuple[int, ...], Arc]] = []
        nxt: dict[tuple[int, ...], None] = {}
        for rest in level:
            limit = best[rest].width if rest != zero else 0.0
            for t in kinds:
                key = tuple(c + (i == index[t]) for i, c in enumerate(rest))
                arc = widest_arc(transfers[t], limit, tol)
                nxt[key] = None
                if key not in best or arc.width > best[key].width + tol:
                    best[key] = arc
                if arc.width >= reach:
                    chain = _chain(best, rest, arc, index)
                    cost = problem.cost.attempt_cost(tuple(a.kind for a in chain))
                    found.append((cost, -_margin(chain), key, arc))
        level = list(nxt)
        widths.append(max(best[key].width for key in level))
        if found:
            cost, _, key, arc = min(found, key=lambda x: (x[0], x[1]))
            rest = tuple(c - (i == index[arc.kind]) for i, c in enumerate(key))
            chain = _chain(best, rest, arc, index)
            return GuaranteedPlan(_option(problem, chain, period), period, tuple(widths))
    raise PlanningError(
        f"no guaranteed plan within {4 * poly.n_sides + 8} actions for part "
        f"{problem.part.name!r} (widest collapsible arc {math.degrees(widths[-1]):.6f} deg, "
        f"period {math.degrees(period):.6f} deg)"
    )


def _chain(
    best: dict[tuple[int, ...], Arc], rest: tuple[int, ...], first: Arc, index: dict[str, int]
) -> list[Arc]:
    """The arcs of a plan, first action first: ``first``, then the widest arcs of ``rest``."""
    chain = [first]
    counts = list(rest)
    while any(counts):
        arc = best[tuple(counts)]
        chain.append(arc)
        counts[index[arc.kind]] -= 1
    return chain


def _margin(chain: list[Arc]) -> float:
    """Least slack of an image inside the next arc (half the room left)."""
    gaps = [0.5 * (w.width - prev.span) for prev, w in itertools.pairwise(chain)]
    return min(gaps) if gaps else math.inf


def _option(problem: Problem, chain: list[Arc], period: float) -> PlanOption:
    """Angles, tolerance, success probability and expected cost of a chain of arcs."""
    first = chain[0]
    p, start = problem.prior.max_arc_mass(
        min(first.width, period), problem.goal_group, prefer=first.lo
    )
    angles = [start - first.lo]
    for prev, arc in itertools.pairwise(chain):
        # Centre the previous image in this arc: each angle may then err by the margin.
        angles.append(0.5 * (prev.s_first + prev.s_last - arc.lo - arc.hi))
    # A squeeze gripper turned by pi is the same gripper (jaws swapped): show each squeeze
    # angle in (-pi/2, pi/2] and carry the pi to the next angle (or the final orientation),
    # as the exact planner does. A push-grasp has a pushing side: its angle stays in (-pi, pi].
    steps = []
    carry = 0.0
    for arc, angle in zip(chain, angles, strict=True):
        a = _wrap(angle + carry)
        carry = 0.0
        if arc.kind == "squeeze":
            short = _wrap(2.0 * a) / 2.0
            carry, a = a - short, short
        steps.append(PlanStep(arc.kind, a))
    margin = _margin(chain)
    kinds = tuple(a.kind for a in chain)
    return PlanOption(
        tuple(steps),
        math.fmod(chain[-1].s_first + carry + TWO_PI, TWO_PI),
        p,
        problem.cost.expected_cost(kinds, p),
        None if math.isinf(margin) else margin,
        (start, start + min(first.width, period)),
    )
