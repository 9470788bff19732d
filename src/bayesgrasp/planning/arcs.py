"""Arcs, fronts, staircases and witness chains: what the exact and guaranteed planners share.

See design.md, "The fact that makes exact planning fast". :mod:`~bayesgrasp.planning.exact`
runs this machinery to the Bayes plans, :mod:`~bayesgrasp.planning.guaranteed` to the
shortest plan that collapses the whole circle.

Arc lengths
-----------
Every transfer function here is a non-decreasing step function with
``F(theta + 2 pi) = F(theta) + 2 pi``, and so is every composition of them. Hence the initial
orientations that a plan sends to one final orientation form an arc, and because the gripper
may be turned freely before each action, whether an arc can be collapsed to a point by a
given sequence of action types depends only on its length. Let ``L(seq)`` be the supremum of
those lengths. For a sequence whose first action has transfer function ``F`` and whose rest
is ``seq'``:

    L(F, seq') = the widest open arc (B_i, B_j) between basin boundaries of F whose stable
                 orientations S_{i+1} .. S_j span strictly less than L(seq')

(the image of the arc is the closed arc [S_{i+1}, S_j]; it must fit inside an open arc of
length ``L(seq')``; an arc reaching past a basin boundary takes the next stable orientation
along, and the boundary itself, an unstable equilibrium, stays where it is). The last action
alone collapses exactly one basin. ``L`` grows with the allowed arc, so for a fixed count of
each action type only the type of the *first* action matters for cost; the rest take the
order that gives the widest arc (:meth:`ArcPlanner.extend`, :meth:`ArcPlanner.order`).
Comparisons keep a margin of the angle tolerance: an image must span less than
``L(seq') - 2 tol``, so no plan relies on hitting an unstable equilibrium.

Fronts
------
Only arcs on the *front* matter: an arc is useless if another is at least as wide and spans
no more. The front of a transfer function (:func:`arc_front`: at most one arc for each span,
sorted by span, widths increasing) is computed once; the widest arc under a span limit is
then a binary search (:meth:`ArcFront.widest`).

Ties between copies
-------------------
A transfer function of period ``P`` has ``2 pi / P`` copies of every arc, shifted by ``P``:
the same width and span, hence plans of the same probability and cost whose success arcs
(and final orientations) differ by ``P``. Computed widths of the copies differ in the last
bits, so the front's rule (of equal arcs the first) would follow the rounding. For a part
whose diameter function is computed anew at each shape (a curved outline, flattened at a
chordal tolerance) the planner takes the arcs of one period only (:func:`period_rows`: the
basins whose stable orientation lies in ``[-tol, P - tol)``), so the same copy wins at
every tolerance. Polygons keep every row (their plans are the ones documented).

Witness chains and staircases
-----------------------------
Angles come from a chain of *witness* arcs ``a_1, ..., a_k``, one per action, each an open arc
between basin boundaries of that action's transfer function: ``a_1`` is the success arc (of
length ``L``), ``a_k`` a single basin, and the image of ``a_m`` (its stable orientations, of
span ``x_m``) is placed in the middle of ``a_{m+1}`` (of length ``W_{m+1}``). Relative rotation
``m + 1`` may then err by ``(W_{m+1} - x_m) / 2`` and every orientation of the success arc still
ends at the goal; the plan's tolerance is the least of these margins (:func:`chain_option`
turns a chain into gripper angles).

The witnesses are not simply the widest arcs of each count: a wider ``a_{m+1}`` gives more
margin before action ``m + 1`` but may have a larger image, leaving less before action
``m + 2``. The chain is chosen to maximise the least margin (a bottleneck dynamic programme
from the last action back, :meth:`ArcPlanner.witnesses`): ``tau_m(x)``, the best least margin
of actions ``m..k`` when an image of span ``x`` arrives before action ``m``, is
``max over front arcs a of min((W(a) - x) / 2, tau_{m+1}(span(a)))``, a non-increasing
staircase in ``x`` kept as the Pareto front of its (width, later margin) pairs
(:class:`Staircase`). Under errors of at most ``t`` on every turn, the orientations that can
arrive before an action fill the basins of an arc whose width exceeds the arriving span by
``2 t``; so no plan with this success arc has a larger tolerance than the chain's.

Gripper accuracy
----------------
With ``Problem.accuracy`` (``A``) the same argument runs with margin ``A``. An image must span
less than ``L(seq') - 2 max(tol, A)``, so that it fits the next witness with more than ``A``
to spare on each side, and the staircases admit only margins of at least ``A``: every plan
of two or more actions then has tolerance at least ``A``, and since under errors up to ``A``
the arriving orientations fill an arc ``2 A`` wider than the image, no plan robust to such
errors collapses more. The widest arc of ``k + 1`` actions is ``G(W_k)`` with ``G``
non-decreasing (the widest arc of any action type whose image fits an arc ``W_k`` wide), so
``W_k`` is monotone; with ``A > 0`` it may stop short of the period, and a search stops at
the fixed point (:meth:`ArcPlanner.widest_reachable`).

Cost: O(K^2) once per action type for the front (K stable orientations; usually far fewer
arcs survive), then O(log K) per (count, type) for the lengths and O(F log F) per action of
each reported plan for its witnesses (F arcs on the front).

Examples
--------
The rectangle 2 x 1: one squeeze collapses its widest basin (a single basin, span 0), two
collapse half the circle.

>>> from bayesgrasp.geometry.polygon import Part
>>> from bayesgrasp.model.problem import Problem
>>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
>>> planner = ArcPlanner.for_problem(pb)
>>> front = planner.front("squeeze")
>>> one = front.widest(planner.tol)
>>> [round(math.degrees(w), 6) for w in (one, front.widest(one - 2 * planner.tol))]
[126.869898, 180.0]
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import PlanningError
from ..geometry.transfer import TransferFunction
from ..model.problem import Problem
from ..sizes import SMALL
from .chains import (
    Counts,
    Plans,
    Scored,
    chain_option,
    one_period_arcs,
    period_cap,
    small_options,
    widest_reachable,
)
from .fronts import (
    ARC_CHUNK,
    PRUNE_STATES,
    SPAN_SLACK,
    Arc,
    ArcFront,
    SpanFront,
    arc_front_arrays,
    pareto_front,
    period_rows,
)
from .result import PlanOption
from .staircases import ROUNDING, Staircase, staircase_python

__all__ = [
    "ARC_CHUNK",
    "PRUNE_STATES",
    "ROUNDING",
    "SPAN_SLACK",
    "STAIR_CELLS",
    "Arc",
    "ArcFront",
    "ArcPlanner",
    "Counts",
    "Plans",
    "Scored",
    "SpanFront",
    "Staircase",
    "arc_front",
    "chain_option",
    "few_states",
    "one_period_arcs",
    "pareto_front",
    "period_cap",
    "period_rows",
    "small_options",
    "staircase",
    "widest_arc",
    "widest_reachable",
]

FloatArray = NDArray[np.float64]

STAIR_CELLS = 2_000_000
"""Most staircase entries one witness chain may build; longer chains bisect on the margin."""

FUSED = True
"""Run the plain-list paths of parts of few states (:meth:`ArcPlanner.plan_options` and the
fused one-action planner of :func:`bayesgrasp.planning.exact.plan_exact`); the tests turn it
off to compare them with the general paths."""


def arc_front(
    f: TransferFunction,
    max_span: float,
    *,
    chunk: int = ARC_CHUNK,
    prune: bool | None = None,
    rows: Sequence[int] | None = None,
) -> ArcFront:
    """The front of the arcs of ``f`` whose image spans less than ``max_span``.

    Single basins (span 0) are always arcs, even when ``max_span <= 0``. Of arcs equal in
    width and span the one of the first basin is kept.

    Parameters
    ----------
    f : TransferFunction
    max_span : float
        Only arcs whose image spans less than this count.
    chunk : int
        Candidate arcs enumerated at once (the front does not depend on it).
    prune : bool, optional
        Enumerate only the arcs that can be on the front
        (:func:`~bayesgrasp.planning.fronts.pruned_candidates`; the default above
        :data:`PRUNE_STATES` states) or every arc (O(K^2)). The front is the same, bit for
        bit.
    rows : sequence of int, optional
        Only arcs that start at these basins (increasing; :func:`period_rows`); default all.

    Returns
    -------
    ArcFront

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.angles import TWO_PI
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> front = arc_front(s, TWO_PI)
    >>> np.degrees(front.span).round(6).tolist(), np.degrees(front.width).round(6).tolist()
    ([0.0, 90.0, 180.0, 270.0], [126.869898, 180.0, 306.869898, 360.0])
    """
    if f.n_states <= SMALL and prune is None:
        return _arc_front_python(f, max_span, rows)
    return arc_front_arrays(f, max_span, chunk=chunk, prune=prune, rows=rows)


def _arc_front_python(
    f: TransferFunction, max_span: float, rows: Sequence[int] | None = None
) -> ArcFront:
    """:func:`arc_front` in plain Python floats for a few states (:func:`_front_lists`)."""
    stable, lo, hi = f.values  # no arrays made for a few states
    lists = _front_lists(stable, lo, hi, max_span, rows)
    return ArcFront(f.kind, *lists)


def _front_lists(
    stable: Sequence[float],
    lo: Sequence[float],
    hi: Sequence[float],
    max_span: float,
    rows: Sequence[int] | None = None,
) -> tuple[list[float], list[float], list[float], list[float]]:
    """Span, width, first stable orientation and start of the front's arcs, step for step.

    The whole front of a :class:`SpanFront` (every arc enumerated at once).
    """
    if rows is None:
        front = SpanFront(stable, lo, hi, max_span, max_span)
    else:
        front = SpanFront(stable, lo, hi, max_span, max_span, rows=rows)
    front.cover(math.inf)
    firsts, los = [], []
    for i in front.rows:
        firsts.append(stable[i])
        los.append(lo[i])
    return front.spans, front.widths, firsts, los


def widest_arc(f: TransferFunction, limit: float, tol: float) -> Arc:
    """Widest boundary-to-boundary arc of ``f`` whose image spans less than ``limit``.

    The last arc of the front of ``f`` under that span limit (:func:`arc_front`); among the
    arcs as wide within ``tol`` the one of least span is returned (it leaves the most room
    to the next action). O(K^2) for K stable orientations.

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
        ``kind``, ``lo``, ``hi`` (the open arc), ``s_first``, ``s_last`` (its image), with
        ``width`` and ``span``.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> one = widest_arc(s, 0.0, 1e-9)  # a single basin
    >>> two = widest_arc(s, one.width, 1e-9)
    >>> [round(math.degrees(a.width), 6) for a in (one, two)]
    [126.869898, 180.0]
    """
    front = arc_front(f, limit - 2.0 * tol)
    widths = front.width_list  # increasing with the span
    return front.arc(bisect.bisect_left(widths, widths[-1] - tol))


def staircase(
    front: ArcFront, after: Staircase | None, tol: float, accuracy: float = 0.0
) -> Staircase:
    """The staircase of an action whose arcs are ``front``, given the one of the next action.

    ``after`` is ``None`` for the last action (it collapses one basin: only single basins
    count). Only margins above ``tol`` and at least ``accuracy`` count (``tau`` is ``-inf``
    below).

    Examples
    --------
    Two squeezes of the rectangle 2 x 1: an image of span 0 arriving before the first leaves
    at most half the widest arc less a basin, (180 - 126.87) / 2 deg, to the second.

    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.angles import TWO_PI
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> front = arc_front(s, TWO_PI)
    >>> last = staircase(front, None, 1e-9)
    >>> np.degrees(last.tau(np.radians([0.0, 90.0, 130.0]))).round(6).tolist()
    [63.434949, 18.434949, -inf]
    """
    if len(front) <= SMALL:
        return staircase_python(front, after, tol, accuracy)
    if after is None:  # the last action collapses one basin: only single basins count
        index = np.flatnonzero(front.span <= 0.0)
        rest = np.full(len(index), np.inf)
    else:
        rest = after.tau(front.span)
        index = np.flatnonzero(rest > tol)
        rest = rest[index]
    keep = pareto_front(-rest, front.width[index])  # most rest first, widths increasing
    index, rest = index[keep], rest[keep]
    width = front.width[index]
    c = width - 2.0 * rest
    return Staircase(front, index, rest, width, c, c.tolist(), tol, accuracy)


@dataclass(slots=True)
class ArcPlanner:
    """The fronts, widest arcs and staircases of one problem, computed on first use.

    Build it with :meth:`for_problem`. ``best[counts]`` is the widest arc that actions of
    those counts collapse (their best order) and the type of the first action of that order.

    Attributes
    ----------
    problem : Problem
    tol : float
        The angle tolerance (of the problem's states).
    max_span : float
        The fronts keep arcs whose images span less than this.
    period : float
        No plan orients beyond this: the largest period of the action types, or ``2 pi / g``
        for a goal counting ``g`` symmetric orientations as one, whichever is less.
    one_period : bool
        The fronts hold the arcs of one period only (:func:`period_rows`): of copies of a
        plan shifted by a period, the same one at every flattening of a curved part.
    """

    problem: Problem
    tol: float
    max_span: float
    one_period: bool = False
    fronts: dict[str, ArcFront] = field(default_factory=dict)
    # Staircase of an action type followed by the actions of staircase ``next_id`` (-1:
    # none), with its own id: a suffix of a plan is found in O(1) from the next one.
    stairs: dict[tuple[str, int], tuple[int, Staircase]] = field(default_factory=dict)
    best: dict[Counts, tuple[float, str]] = field(default_factory=dict)
    orders: dict[Counts, tuple[str, ...]] = field(default_factory=dict)  # see _rest_order
    # Least margins bisected ahead, by (action types, length): see prepare_margins.
    margins: dict[tuple[tuple[str, ...], float], float] = field(default_factory=dict)
    index: dict[str, int] = field(init=False)  # position of each action type in a Counts
    period: float = field(init=False)
    # Every action has at most SMALL states: plan_options works on the fronts' lists.
    small: bool = field(init=False)

    def __post_init__(self) -> None:
        kinds = self.problem.action_kinds
        self.index = {t: i for i, t in enumerate(kinds)}
        transfers = [self.problem.transfers[t] for t in kinds]
        self.period = period_cap(self.problem)
        self.small = few_states(transfers)

    @classmethod
    def for_problem(cls, problem: Problem) -> ArcPlanner:
        """The planner of a problem: its angle tolerance, fronts up to the largest period."""
        tol = problem.states.angle_tol
        periods = [problem.transfers[t].period for t in problem.action_kinds]
        return cls(problem, tol, max(periods) + tol, one_period_arcs(problem))

    def front(self, kind: str) -> ArcFront:
        """The arc front of one action type."""
        if kind not in self.fronts:
            f = self.problem.transfers[kind]
            rows = period_rows(f, self.tol) if self.one_period else None
            self.fronts[kind] = arc_front(f, self.max_span, rows=rows)
        return self.fronts[kind]

    def extend(self, level: list[Counts]) -> tuple[list[tuple[Counts, str, float]], list[Counts]]:
        """The plans one action longer than those of ``level`` (all zeros: no action yet).

        For each counts in ``level`` and each action type put before them: the new counts,
        that type, and the widest arc the plan collapses (the later actions in their best
        order). Updates ``best``. Returns these candidates and the next level (the new
        counts, in order of first appearance).
        """
        kinds = self.problem.action_kinds
        tol = self.tol
        margin = max(tol, self.problem.accuracy)
        candidates: list[tuple[Counts, str, float]] = []
        nxt: dict[Counts, None] = {}
        for rest in level:
            # The last action must leave a single stable orientation: an image under tol.
            # Before it, the image must fit the next arc with ``margin`` to spare each side.
            max_span = self.best[rest][0] - 2.0 * margin if any(rest) else tol
            for i, t in enumerate(kinds):
                key = (*rest[:i], rest[i] + 1, *rest[i + 1 :])
                width = self.front(t).widest(max_span)
                candidates.append((key, t, width))
                nxt[key] = None
                if key not in self.best or width > self.best[key][0] + tol:
                    self.best[key] = (width, t)
        return candidates, list(nxt)

    def widest_reachable(self, cap: float, max_actions: int) -> float:
        """The widest arc any plan collapses, up to ``cap`` (at most ``max_actions`` actions).

        See :func:`widest_reachable`.
        """
        fronts = [self.front(t) for t in self.problem.action_kinds]
        margin = max(self.tol, self.problem.accuracy)
        return widest_reachable(fronts, self.tol, margin, cap, max_actions)

    def order(self, counts: Counts, first: str) -> tuple[str, ...]:
        """Action types of a plan in order: ``first``, then the best order of the rest."""
        left = list(counts)
        left[self.index[first]] -= 1
        return (first, *self._rest_order(tuple(left)))

    def _rest_order(self, counts: Counts) -> tuple[str, ...]:
        """The best order of actions of these counts (memoised: each is one longer)."""
        if counts in self.orders:
            return self.orders[counts]
        chain: list[Counts] = []  # counts whose order is not known yet, longest first
        c = counts
        while any(c) and c not in self.orders:
            chain.append(c)
            left = list(c)
            left[self.index[self.best[c][1]]] -= 1
            c = tuple(left)
        out = self.orders.get(c, ())
        for c in reversed(chain):
            out = (self.best[c][1], *out)
            self.orders[c] = out
        return out

    def _margin_bracket(self) -> tuple[float, float]:
        """A least margin every chain attains, and one none does (bisection's start)."""
        return max(self.tol, self.problem.accuracy), 4.0

    def prepare_margins(self, plans: list[tuple[tuple[str, ...], float]]) -> None:
        """Bisect the margins of many chains of one action type at once (same results).

        ``plans`` are (action types, success-arc length) pairs. For a single action type
        the widths ``U`` of :meth:`witnesses_by_margin` depend only on the distance from
        the last action, so one pass of array operations advances the bisection of every
        chain by one step: the same steps, hence the same margins, as one chain at a time,
        in O(62 k_max) array operations instead of O(62 sum k) scalar ones. Only chains that
        :meth:`witnesses` would bisect are done; the rest are left to it.
        """
        if len(self.problem.action_kinds) != 1:
            return
        todo = [
            (kinds, length)
            for kinds, length in plans
            if len(kinds) > 1 and len(kinds) * len(self.front(kinds[0])) > STAIR_CELLS
        ]
        if len(todo) < 16:  # one array pass per step pays off only for many chains
            return
        front = self.front(todo[0][0][0])
        spans, widths = front.span, front.width
        steps = np.array([len(kinds) - 1 for kinds, _ in todo])  # fronts after the basin
        need = np.array([length - self.tol for _, length in todo])
        lo0, hi0 = self._margin_bracket()
        lo, hi = np.full(len(todo), lo0), np.full(len(todo), hi0)

        def attainable(t: FloatArray) -> NDArray[np.bool_]:
            w = np.full(len(t), widths[0])  # the widest single basin
            ok = np.ones(len(t), dtype=bool)
            for d in range(int(steps.max())):
                going = steps > d
                n = np.searchsorted(spans, w[going] - 2.0 * t[going], side="right") - 1
                ok[np.flatnonzero(going)[n < 0]] = False
                w[going] = widths[np.maximum(n, 0)]
            return ok & (w >= need)

        start = attainable(lo)  # chains that fail here are left to witnesses()
        active = start.copy()
        while active.any():
            mid = 0.5 * (lo + hi)
            active &= (mid != lo) & (mid != hi)
            yes = attainable(mid)
            lo = np.where(active & yes, mid, lo)
            hi = np.where(active & ~yes, mid, hi)
        for (kinds, length), t, ok in zip(todo, lo.tolist(), start.tolist(), strict=True):
            if ok:
                self.margins[(kinds, length)] = t

    def plan_options(self, plans: Plans) -> list[PlanOption]:
        """The plan options of ``(p, cost, action types, success-arc length)`` plans.

        Each plan's witnesses (:meth:`witnesses`) turned into gripper angles
        (:func:`chain_option`), the prior placed on the success arc capped at the period.
        For parts of few states (:attr:`small`) the same steps run on the fronts' lists
        (:func:`small_options`): the same options, bit for bit.
        """
        if self.small and FUSED:
            longest = max(len(kinds) for _, _, kinds, _ in plans)
            fronts = [self.front(t) for t in self.problem.action_kinds]
            if longest * max(len(f) for f in fronts) <= STAIR_CELLS:
                return small_options(
                    self.problem,
                    dict(zip(self.problem.action_kinds, fronts, strict=True)),
                    self.tol,
                    plans,
                )
        self.prepare_margins([(kinds, width) for _, _, kinds, width in plans])
        out = []
        for p, cost, kinds, width in plans:
            chain, tolerance = self.witnesses(kinds, width)
            placed = min(width, self.period)
            out.append(
                chain_option(self.problem, chain, tolerance, placed, p, cost, chain[0].width)
            )
        return out

    def staircases(self, kinds: tuple[str, ...]) -> list[Staircase]:
        """The staircase of ``kinds[m:]`` for each ``m``."""
        out: list[Staircase] = []
        next_id, after = -1, None
        for kind in reversed(kinds):
            key = (kind, next_id)
            if key not in self.stairs:
                stair = staircase(self.front(kind), after, self.tol, self.problem.accuracy)
                self.stairs[key] = (len(self.stairs), stair)
            next_id, after = self.stairs[key]
            out.append(after)
        return out[::-1]

    def witnesses(self, kinds: tuple[str, ...], length: float) -> tuple[list[Arc], float | None]:
        """The chain of witness arcs of largest least margin, and that margin.

        ``length`` is the success arc's length; the first witness is an arc that wide.
        The margin is ``None`` for a single action. Chains whose staircases would hold more
        than :data:`STAIR_CELLS` entries are found by :meth:`witnesses_by_margin` (the same
        margin, in memory O(F)).
        """
        front = self.front(kinds[0])
        wide = bisect.bisect_left(front.width_list, length - self.tol)  # arcs wide..end
        if len(kinds) == 1:
            single = next(n for n, x in enumerate(front.span_list[wide:]) if x <= 0.0)
            return [front.arc(wide + single)], None
        cells = len(kinds) * max(len(self.front(t)) for t in set(kinds))
        if cells > STAIR_CELLS:
            return self.witnesses_by_margin(kinds, length)
        stairs = self.staircases(kinds[1:])
        if len(front) <= SMALL:
            values = stairs[0].tau_list(front.span_list[wide:])
            best = max(values)
            at = next(n for n, v in enumerate(values) if v >= best - self.tol)
        else:
            rest = stairs[0].tau(front.span[wide:])
            best = float(rest.max())
            at = int(np.flatnonzero(rest >= best - self.tol)[0])
        if not math.isfinite(best):  # pragma: no cover - the lengths guarantee a chain
            raise PlanningError("internal error: no witness chain for a plan the lengths allow")
        chain = [front.arc(wide + at)]
        for stair in stairs:
            chain.append(stair.pick(chain[-1].span))
        return chain, best

    def witnesses_by_margin(
        self, kinds: tuple[str, ...], length: float
    ) -> tuple[list[Arc], float | None]:
        """:meth:`witnesses` by bisection on the margin, without staircases.

        A least margin ``t`` is attainable when, from the last action back,
        ``U_{k-1}`` = the widest single basin and ``U_m`` = the widest front arc of action
        ``m`` whose image spans at most ``U_{m+1} - 2 t`` give ``U_0 >= length - tol``: the
        image of each witness then fits the next with ``t`` to spare on each side, and no
        chain does better (a wider witness is never worse for the actions before it). The
        largest such ``t`` is found by bisection to the last bit (O(k log F) a step), and
        the chain is read off its ``U``: the first witness is the narrowest arc at least
        ``length - tol`` wide, each later one the widest that still fits. The margin reported
        is that chain's least ``(W(a_{m+1}) - span(a_m)) / 2``, the staircases' value to
        rounding; the witnesses may differ from theirs where several chains attain it.
        """
        k = len(kinds)
        fronts = [self.front(t) for t in kinds]
        need = length - self.tol

        lists = [(f.span_list, f.width_list) for f in fronts[-2::-1]]  # last but one first
        right = bisect.bisect_right

        def widths(t: float) -> list[float] | None:
            u = [fronts[-1].width_list[0]]  # the widest single basin (span 0), then back
            w, t2 = u[0], 2.0 * t
            for spans, widths_ in lists:
                n = right(spans, w - t2) - 1
                if n < 0:
                    return None
                w = widths_[n]
                u.append(w)
            u.reverse()
            return u if w >= need else None

        lo = self.margins.get((kinds, length))
        if lo is None:
            lo, hi = self._margin_bracket()
            if widths(lo) is None:  # pragma: no cover - the lengths guarantee a chain
                raise PlanningError("internal error: no witness chain for a plan the lengths allow")
            while True:
                mid = 0.5 * (lo + hi)
                if mid in (lo, hi):
                    break
                lo, hi = (mid, hi) if widths(mid) is not None else (lo, mid)
        u = widths(lo)
        assert u is not None
        first = fronts[0]
        chain = [first.arc(bisect.bisect_left(first.width_list, need))]
        for m in range(1, k - 1):
            fr = fronts[m]
            chain.append(fr.arc(bisect.bisect_right(fr.span_list, u[m + 1] - 2.0 * lo) - 1))
        chain.append(fronts[-1].arc(0))
        margin = min(0.5 * (b.width - a.span) for a, b in itertools.pairwise(chain))
        return chain, margin


def few_states(transfers: Iterable[TransferFunction]) -> bool:
    """Whether every transfer function has at most :data:`~bayesgrasp.sizes.SMALL` states.

    The plain-list paths of the planners (:func:`small_options`) run for such problems.
    """
    for f in transfers:
        if f.n_states > SMALL:
            return False
    return True
