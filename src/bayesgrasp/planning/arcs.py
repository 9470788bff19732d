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
import operator
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..geometry.curved import CurvedPart
from ..geometry.transfer import TransferFunction
from ..model.actions import Action
from ..model.problem import Problem
from ..sizes import SMALL
from .result import PlanOption, new_option, plan_actions, short_turns

__all__ = [
    "ARC_CHUNK",
    "PRUNE_STATES",
    "STAIR_CELLS",
    "Arc",
    "ArcFront",
    "ArcPlanner",
    "Counts",
    "Plans",
    "SpanFront",
    "Staircase",
    "arc_front",
    "chain_option",
    "few_states",
    "one_period_arcs",
    "pareto_front",
    "period_rows",
    "small_options",
    "staircase",
    "widest_arc",
    "widest_reachable",
]

FloatArray = NDArray[np.float64]
Counts = tuple[int, ...]
"""How many actions of each type, in ``problem.action_kinds`` order."""
Scored = tuple[float, float, tuple[str, ...], float]
"""``(p, cost, action types, success-arc length)`` of a plan, as the exact planner finds it."""
Plans = list[Scored]

ARC_CHUNK = 1 << 20
"""Arcs :func:`arc_front` enumerates at once (bounds memory for parts with many states)."""

# The lengths admit a margin above ``accuracy`` by ``span < L - 2 accuracy``, the staircases
# compute it as ``(L - span) / 2``: these may differ by rounding, and the witness chain must
# exist whenever the lengths allow it.
ROUNDING = 1e-13


@dataclass(frozen=True, slots=True)
class Arc:
    """An open arc ``(lo, hi)`` of one action's frame and its image ``[s_first, s_last]``.

    ``s_first .. s_last`` are the stable orientations of the basins the arc covers.

    Examples
    --------
    >>> a = Arc("squeeze", 0.0, 2.0, 0.5, 1.5)
    >>> a.width, a.span
    (2.0, 1.0)
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


@dataclass(frozen=True, slots=True, eq=False)
class ArcFront:
    """The arcs of one transfer function that no other arc beats.

    Sorted by ``span`` (of the image) increasing, with ``width`` strictly increasing: an
    arc is dropped when another is at least as wide and spans no more. Arc ``n`` is the
    open arc ``(lo[n], lo[n] + width[n])`` with image ``[s_first[n], s_first[n] + span[n]]``.
    The values are held as lists (the scalar binary searches of the planners, and the
    plain-Python paths of few states); the arrays ``lo``, ``width``, ``s_first`` and ``span``
    are made from them on first use (numpy's paths). Build it with :func:`arc_front`.
    """

    kind: str
    span_list: list[float]
    width_list: list[float]
    s_first_list: list[float]
    lo_list: list[float]
    _arrays: dict[str, FloatArray] = field(default_factory=dict, repr=False)

    @classmethod
    def from_arrays(
        cls, kind: str, lo: FloatArray, width: FloatArray, s_first: FloatArray, span: FloatArray
    ) -> ArcFront:
        """The front of these arrays (kept, and repeated as lists)."""
        out = cls(kind, span.tolist(), width.tolist(), s_first.tolist(), lo.tolist())
        out._arrays.update(lo=lo, width=width, s_first=s_first, span=span)
        return out

    def _array(self, name: str, values: list[float]) -> FloatArray:
        if name not in self._arrays:
            self._arrays[name] = np.array(values, dtype=np.float64)
        return self._arrays[name]

    @property
    def lo(self) -> FloatArray:
        """Start of each arc."""
        return self._array("lo", self.lo_list)

    @property
    def width(self) -> FloatArray:
        """Length of each arc (increasing)."""
        return self._array("width", self.width_list)

    @property
    def s_first(self) -> FloatArray:
        """First stable orientation of each arc's image."""
        return self._array("s_first", self.s_first_list)

    @property
    def span(self) -> FloatArray:
        """Length of each arc's image (increasing)."""
        return self._array("span", self.span_list)

    def __len__(self) -> int:
        return len(self.width_list)

    def arc(self, n: int) -> Arc:
        """Arc ``n`` as plain floats."""
        lo, s = self.lo_list[n], self.s_first_list[n]
        return Arc(self.kind, lo, lo + self.width_list[n], s, s + self.span_list[n])

    def widest(self, max_span: float) -> float:
        """Width of the widest arc whose image spans less than ``max_span`` (0 if none does).

        Every front holds a single basin (span 0), so only ``max_span <= 0`` gives 0: the
        arc after this action is too narrow to take even one point with the margin asked for.
        """
        n = bisect.bisect_left(self.span_list, max_span) - 1
        return self.width_list[n] if n >= 0 else 0.0


def period_rows(f: TransferFunction, tol: float) -> list[int] | None:
    """The basins of one period of ``f``: those whose stable orientation is in ``[-tol, P - tol)``.

    Every arc of ``f`` is a copy, shifted by a multiple of the period ``P``, of an arc that
    starts at one of these basins, so a front of these rows alone holds every width and
    span, and of copies always the same one (the window starts at ``-tol`` so that a state
    at 0 computed as ``2 pi`` less a rounding stays the first). ``None`` when ``f`` has no
    shorter period than ``2 pi`` (every row).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> np.degrees(s.stable).round(6).tolist(), period_rows(s, 1e-9)
    ([0.0, 90.0, 180.0, 270.0], [0, 1])
    """
    k = f.n_states
    copies = round(TWO_PI / f.period)
    if copies <= 1 or k % copies:
        return None
    period = f.period
    rows = [i for i, s in enumerate(f.values[0]) if (s + tol) % TWO_PI < period]
    return rows if len(rows) == k // copies else None


def one_period_arcs(problem: Problem) -> bool:
    """Whether the planners take the arcs of one period only (:func:`period_rows`).

    For curved parts (and parts with a shape tolerance), whose transfer functions are
    computed anew at each flattening: ties between copies of a plan are then broken the
    same way at every chordal tolerance.
    """
    return isinstance(problem.part, CurvedPart)


def period_cap(problem: Problem) -> float:
    """The angle no plan orients beyond: the largest period of the action types, or less.

    ``2 pi / g`` when that is smaller (``g`` the goal's group order).
    """
    period = 0.0
    for t in problem.action_kinds:
        if problem.transfers[t].period > period:
            period = problem.transfers[t].period
    cap = TWO_PI / problem.goal_group
    return period if period < cap else cap


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
        Enumerate only the arcs that can be on the front (:func:`_pruned_candidates`; the
        default above :data:`PRUNE_STATES` states) or every arc (O(K^2)). The front is the
        same, bit for bit.
    rows : sequence of int, optional
        Only arcs that start at these basins (increasing; :func:`period_rows`); default all.

    Returns
    -------
    ArcFront

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> front = arc_front(s, TWO_PI)
    >>> np.degrees(front.span).round(6).tolist(), np.degrees(front.width).round(6).tolist()
    ([0.0, 90.0, 180.0, 270.0], [126.869898, 180.0, 306.869898, 360.0])
    """
    if f.n_states <= SMALL and prune is None:
        return _arc_front_python(f, max_span, rows)
    geo = _ArcGeometry(f, max_span, rows)
    cand = None
    if prune if prune is not None else f.n_states > PRUNE_STATES:
        cand = _pruned_candidates(geo)
    if cand is not None:
        lo, width, first, span = geo.arcs(*cand)
        keep = pareto_front(span, width)
        return ArcFront.from_arrays(f.kind, lo[keep], width[keep], first[keep], span[keep])
    i_all = geo.rows
    n_off = int(np.max(geo.last[i_all] - i_all)) + 1
    step = max(1, chunk // n_off)
    parts: list[tuple[FloatArray, ...]] = []
    for start in range(0, len(i_all), step):
        i = i_all[start : start + step]
        j = i[:, None] + np.arange(n_off)[None, :]  # (R, J) candidate last basins
        ok = j <= geo.last[i, None]
        lo, width, first, span = geo.arcs(np.broadcast_to(i[:, None], j.shape)[ok], j[ok])
        keep = pareto_front(span, width)
        parts.append((lo[keep], width[keep], first[keep], span[keep]))
    lo, width, first, span = (np.concatenate(x) for x in zip(*parts, strict=True))
    keep = pareto_front(span, width)
    return ArcFront.from_arrays(f.kind, lo[keep], width[keep], first[keep], span[keep])


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


_span_of = operator.itemgetter(0)

# Slack of the span bounds of SpanFront (and of the fused planner's staircases): far above
# the rounding of sums and differences of angles below 4 pi (a few ulps, about 1e-15).
SPAN_SLACK = 1e-12


class SpanFront:
    """The front of :func:`arc_front` in plain Python floats, built in order of span on demand.

    ``spans``, ``widths`` and ``rows`` (the first basin of each arc) are the front's arcs
    whose image spans less than the largest bound passed to :meth:`cover` so far, bit for
    bit those of the whole front: the same candidates, the same float operations and the
    same Pareto rule (:func:`pareto_front`: a stable sort by span, widths strictly
    increasing, of equal spans the last kept; so of an equal span and width the arc of the
    first basin). In this order:

    - the single basins (span 0, the first of any ``(i, j)``) first: the first widest;
    - the arcs of two or more basins by a stable sort on the span alone, ties in the order
      ``(i, j)``. Of the arcs of one span the front keeps the widest, and of those the
      first, the least ``i`` (one row has one arc of each span and width): the same arc as
      the order ``(span, width, i)`` keeps, which the second batch below uses. A prefix
      of either order gives the front's arcs of spans below the first span not taken
      (later arcs span more, so they can neither join the front below it nor replace an
      arc there): :meth:`cover` takes the arcs one by one, only as far as asked.
    - The arcs are enumerated in two batches: first those of each row ``i`` whose last
      stable orientation lies below ``s_i + first`` (``first`` at most ``max_span`` and
      ``2 pi``), then, only if a bound above ``first - SPAN_SLACK`` is asked, the rest
      (sorted in with the arcs not taken yet). An arc of the second batch spans at least
      ``first`` less a rounding, so the first batch holds every arc that spans less than
      ``first - SPAN_SLACK``. The planner of one action type passes the spans its widths
      ask for at most (``cap - 2 max(tol, accuracy)``, see
      :func:`bayesgrasp.planning.exact.plan_exact`), so the arcs of a squeeze that span a
      half-turn (K of about K^2 / 2) are seldom made.
    - ``rows`` (increasing) limits the arcs to those starting at these basins (one period of
      a periodic function, :func:`period_rows`); default every basin.
    """

    __slots__ = (
        "_cand",
        "_complete",
        "_first",
        "_hi2",
        "_pos",
        "_rows",
        "_s2",
        "covered",
        "lo",
        "max_span",
        "rows",
        "spans",
        "stable",
        "widths",
    )

    def __init__(
        self,
        stable: Sequence[float],
        lo: Sequence[float],
        hi: Sequence[float],
        max_span: float,
        first: float,
        rows: Sequence[int] | None = None,
    ) -> None:
        k = len(stable)
        starts = range(k) if rows is None else rows
        add_turn = TWO_PI.__add__  # TWO_PI + x is x + TWO_PI, bit for bit
        s2 = [*stable, *map(add_turn, stable)]
        hi2 = [*hi, *map(add_turn, hi)]
        if first > max_span:
            first = max_span
        if first > TWO_PI:  # then s2[i + k] >= s_i + first: the arcs below end before i + k
            first = TWO_PI
        widest = -math.inf
        top = 0
        cand: list[tuple[float, float, int]] = []
        add = cand.append
        left = bisect.bisect_left
        for i in starts:
            si, li = stable[i], lo[i]
            w = hi[i] - li
            if w > widest:
                widest, top = w, i
            # Arcs (i, j), i < j < i + K: the image spans less than `first` (of max_span).
            for j in range(i + 1, left(s2, si + first)):
                add((s2[j] - si, hi2[j] - li, i))
        cand.sort(key=_span_of)
        self.stable, self.lo, self.max_span = stable, lo, max_span
        self._s2, self._hi2, self._first = s2, hi2, first
        self._cand, self._pos, self._rows = cand, 0, starts
        self._complete = math.inf if first >= max_span else first - SPAN_SLACK
        self.spans, self.widths, self.rows = [0.0], [widest], [top]
        self.covered = -math.inf

    def cover(self, bound: float) -> None:
        """Take every arc whose image spans less than ``bound`` (at once: O(arcs taken))."""
        if bound <= self.covered:
            return
        if bound > self._complete:
            self._second_batch()
        cand, pos = self._cand, self._pos
        end = bisect.bisect_left(cand, (bound,), pos)  # the arcs of span < bound
        if end > pos:
            spans, widths, rows = self.spans, self.widths, self.rows
            best = widths[-1]
            for arc in cand[pos:end]:
                if arc[1] > best:
                    x, best, i = arc
                    if spans[-1] == x:  # of equal spans only the widest stays
                        widths[-1], rows[-1] = best, i
                    else:
                        spans.append(x)
                        widths.append(best)
                        rows.append(i)
            self._pos = end
        self.covered = bound

    def _second_batch(self) -> None:
        """The arcs of spans from ``first`` to ``max_span``, sorted in with those not taken.

        By ``(span, width, i)``: arcs of one span from both batches are then in an order
        that keeps the same arc of each span (the class notes).
        """
        stable, lo, s2, hi2 = self.stable, self.lo, self._s2, self._hi2
        k = len(stable)
        left = bisect.bisect_left
        cand = self._cand[self._pos :]
        add = cand.append
        first, max_span = self._first, self.max_span
        for i in self._rows:
            si, li = stable[i], lo[i]
            start = left(s2, si + first, i + 1, i + k)
            for j in range(start, left(s2, si + max_span, i + 1, i + k)):
                add((s2[j] - si, hi2[j] - li, i))
        cand.sort()
        self._cand, self._pos, self._complete = cand, 0, math.inf


PRUNE_STATES = 256
"""Above this many states :func:`arc_front` enumerates only the arcs that can be on the front."""

# An arc's width less its span is computed as left(i) + right(j) for the pruning; the two
# differ from ``width - span`` by rounding (a few ulps of 4 pi), far below this.
_EXCESS_SLACK = 1e-12
STAIR_CELLS = 2_000_000
"""Most staircase entries one witness chain may build; longer chains bisect on the margin."""

# Steps of the front filled by enumeration in one round; more, and the threshold is lowered.
_MAX_STEPS = 16

FUSED = True
"""Run the plain-list paths of parts of few states (:meth:`ArcPlanner.plan_options` and the
fused one-action planner of :func:`bayesgrasp.planning.exact.plan_exact`); the tests turn it
off to compare them with the general paths."""


@dataclass(frozen=True, slots=True, eq=False)
class _ArcGeometry:
    """The arcs of one transfer function: arc ``(i, j)`` covers basins ``i..j`` (j < i + K).

    ``j`` indexes the basins repeated once round the circle (``j >= K`` is basin ``j - K``
    2 pi on); ``last[i]`` is the last basin an arc from ``i`` may reach (its image spans
    less than ``max_span``, and at least basin ``i`` itself). Only arcs from the basins
    ``rows`` (increasing) are enumerated.
    """

    f: TransferFunction
    k: int
    rows: NDArray[np.intp]
    s2: FloatArray
    hi2: FloatArray
    last: NDArray[np.intp]

    def __init__(
        self, f: TransferFunction, max_span: float, rows: Sequence[int] | None = None
    ) -> None:
        k = f.n_states
        s2 = np.concatenate([f.stable, f.stable + TWO_PI])  # (2K,)
        hi2 = np.concatenate([f.basin_hi, f.basin_hi + TWO_PI])
        i_all = np.arange(k)
        last = np.clip(
            np.searchsorted(s2, f.stable + max_span, side="left") - 1, i_all, i_all + k - 1
        )
        starts = i_all if rows is None else np.asarray(rows, dtype=np.intp)
        for name, value in (("f", f), ("k", k), ("rows", starts), ("s2", s2), ("hi2", hi2)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "last", last)

    def arcs(self, ii: NDArray[np.intp], jj: NDArray[np.intp]) -> tuple[FloatArray, ...]:
        """``lo``, ``width``, ``s_first`` and ``span`` of the arcs ``(ii, jj)``."""
        lo = self.f.basin_lo[ii]
        return lo, self.hi2[jj] - lo, self.f.stable[ii], self.s2[jj] - self.f.stable[ii]

    def spans_between(self, a: float, b: float) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """Every arc whose image spans between ``a`` and ``b`` (a little more, never less)."""
        i_all = self.rows
        s = self.f.stable[i_all]
        j0 = np.maximum(np.searchsorted(self.s2, s + (a - _EXCESS_SLACK), side="left"), i_all)
        j1 = np.minimum(
            np.searchsorted(self.s2, s + (b + _EXCESS_SLACK), side="right") - 1,
            self.last[i_all],
        )
        return _ranges(i_all, j0, j1)


def _ranges(
    i: NDArray[np.intp], j0: NDArray[np.intp], j1: NDArray[np.intp]
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The pairs ``(i[r], j)`` for ``j0[r] <= j <= j1[r]``, by ``r`` then ``j``."""
    count = np.maximum(j1 - j0 + 1, 0)
    total = int(count.sum())
    ii = np.repeat(i, count)
    starts = np.repeat(np.cumsum(count) - count, count)
    jj = np.repeat(j0, count) + (np.arange(total) - starts)
    return ii, jj


def _pruned_candidates(geo: _ArcGeometry) -> tuple[NDArray[np.intp], NDArray[np.intp]] | None:
    """The arcs that can be on the front (or tie with it), in the order ``(i, j)``.

    An arc's width is its span plus its *excess* ``l_i + r_j``: the half of basin ``i``
    before its stable orientation and the half of basin ``j`` after. The front is a
    staircase of points ``(span_n, width_n)``; an arc of span in ``[span_n, span_{n+1})``
    and excess below ``T`` is strictly narrower than point ``n`` when
    ``width_n >= span_{n+1} + T``. So: take the arcs of excess at least ``T`` (a few per
    state, the threshold found by bisection on the counts) and the arcs of one or two
    basins, compute their front, and enumerate every arc whose span falls in a step where
    that inequality fails (also past the last point); repeat until no step fails. Each
    round only adds arcs, so the front found is that of all arcs, and every arc tied with
    a front point has an excess above ``T`` and is among the candidates. When the steps to
    fill grow too many the threshold is lowered; ``None`` when the candidates would be
    nearly all arcs (a regular polygon: every excess is equal), which are then enumerated
    in chunks. Memory O(C), time O((K + C) log K) for C candidates (a few per state on
    random parts).
    """
    k, f = geo.k, geo.f
    i_all = geo.rows
    last = geo.last[i_all]
    left = (f.stable - f.basin_lo)[i_all]  # (R,) l_i of the rows
    right = f.basin_hi - f.stable  # (K,) r_j
    r_order = np.argsort(-right, kind="stable")
    r_desc = right[r_order]
    neg = -r_desc  # increasing
    max_span = float(np.max(geo.s2[geo.last] - f.stable))
    total = int(np.sum(last - i_all + 1))
    budget = 8 * k
    while True:
        if 16 * budget >= total:  # nearly as many as all arcs
            return None
        # Threshold T with about `budget` pairs of excess >= T - slack.
        lo_t, hi_t = float(left.min() + right.min()), float(left.max() + right.max())
        for _ in range(60):
            mid = 0.5 * (lo_t + hi_t)
            n = int(np.searchsorted(neg, left - (mid - _EXCESS_SLACK), side="right").sum())
            lo_t, hi_t = (mid, hi_t) if n > budget else (lo_t, mid)
        t = hi_t
        count = np.searchsorted(neg, left - (t - _EXCESS_SLACK), side="right")
        ii = np.repeat(i_all, count)
        starts = np.repeat(np.cumsum(count) - count, count)
        jj = r_order[np.arange(len(ii)) - starts]
        jj = np.where(jj >= ii, jj, jj + k)
        ok = jj <= geo.last[ii]
        few_i, few_j = _ranges(i_all, i_all, np.minimum(i_all + 1, last))
        ii, jj = np.concatenate([ii[ok], few_i]), np.concatenate([jj[ok], few_j])
        done: list[tuple[float, float]] = []  # span intervals enumerated in full
        limit = 16 * budget
        while True:
            key = np.sort(ii * (2 * k) + jj)  # by (i, j), without repeats
            key = key[np.append(True, key[1:] != key[:-1])]
            ii, jj = key // (2 * k), key % (2 * k)
            if len(ii) > limit:
                break
            _, width, _, span = geo.arcs(ii, jj)
            keep = pareto_front(span, width)
            fs, fw = span[keep], width[keep]
            nxt = np.append(fs[1:], max_span)
            bad = np.flatnonzero(fw < nxt + t)
            todo = [
                (float(fs[n]), float(nxt[n]))
                for n in bad
                if not any(a <= fs[n] and nxt[n] <= b for a, b in done)
            ]
            if not todo:
                return ii, jj
            steps = _merge(todo)
            if len(steps) > _MAX_STEPS:  # the threshold is too high: lower it
                break
            new_i, new_j = [ii], [jj]
            for a, b in steps:
                more_i, more_j = geo.spans_between(a, b)
                new_i.append(more_i)
                new_j.append(more_j)
                done.append((a, b))
            ii, jj = np.concatenate(new_i), np.concatenate(new_j)
            if len(ii) > limit:
                break
        budget *= 4


def _merge(intervals: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Touching or overlapping intervals joined (sorted by start)."""
    out: list[tuple[float, float]] = []
    for a, b in sorted(intervals):
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def pareto_front(cost: FloatArray, value: FloatArray) -> NDArray[np.intp]:
    """Indices of the Pareto front (least ``cost``, most ``value``), by cost increasing.

    On the front ``value`` strictly increases; of equal pairs the first index is kept.

    Examples
    --------
    >>> pareto_front(np.array([1.0, 0.0, 1.0, 2.0, 2.0]), np.array([3.0, 1.0, 3.0, 2.0, 5.0]))
    array([1, 0, 4])
    """
    order = np.argsort(cost, kind="stable")
    v = value[order]
    best_before = np.maximum.accumulate(np.concatenate([[-np.inf], v[:-1]]))
    kept = order[v > best_before]  # value increases; cost non-decreasing
    # Of entries with equal cost only the last (the most value) is on the front.
    c = cost[kept]
    return np.asarray(kept[np.append(c[1:] != c[:-1], True)], dtype=np.intp)


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


@dataclass(frozen=True, slots=True, eq=False)
class Staircase:
    """``tau(x)`` of one action: the best least margin of it and the actions after it.

    Entry ``r`` is arc ``index[r]`` of ``front``, with ``rest[r]`` the least margin of the
    later actions after that arc. Entries are sorted by ``rest`` decreasing, with widths
    strictly increasing: the Pareto front of (width, rest). With ``c = width - 2 rest``
    (non-decreasing), ``tau(x)`` is attained at the first entry with ``c >= x`` (value
    ``rest``) or at the one before it (value ``(width - x) / 2``). Build it with
    :func:`staircase`.
    """

    front: ArcFront
    index: NDArray[np.intp]
    rest: FloatArray
    width: FloatArray
    c: FloatArray
    c_list: list[float]
    tol: float
    accuracy: float
    rest_list: list[float] = field(default_factory=list)
    width_list: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        if len(self.rest_list) != len(self.c_list):
            object.__setattr__(self, "rest_list", self.rest.tolist())
            object.__setattr__(self, "width_list", self.width.tolist())

    def tau_list(self, xs: list[float]) -> list[float]:
        """:meth:`tau` in plain Python floats (the same operations, for a few spans)."""
        return _tau(self.c_list, self.rest_list, self.width_list, self.tol, self.accuracy, xs)

    def tau(self, x: FloatArray) -> FloatArray:
        """Best least margin for images of spans ``x`` (``-inf`` where none fits)."""
        n = len(self.rest)
        r = np.searchsorted(self.c, x, side="left")  # (M,) first entry with c >= x
        at = np.where(r < n, self.rest[np.minimum(r, n - 1)], -np.inf)
        before = np.where(r > 0, 0.5 * (self.width[np.maximum(r - 1, 0)] - x), -np.inf)
        value = np.maximum(at, before)
        ok = (value > self.tol) & (value >= self.accuracy - ROUNDING)
        return np.asarray(np.where(ok, value, -np.inf), dtype=np.float64)

    def pick(self, x: float) -> Arc:
        """The arc that attains ``tau(x)`` for one span ``x``."""
        r = _pick(self.c_list, self.rest_list, self.width_list, x)
        return self.front.arc(int(self.index[r]))


def _tau(
    c: list[float],
    rest: list[float],
    width: list[float],
    tol: float,
    accuracy: float,
    xs: list[float],
) -> list[float]:
    """:meth:`Staircase.tau` of the staircase ``(c, rest, width)`` on plain Python floats.

    With ``r`` the first entry with ``c >= x``: the larger of ``rest[r]`` (``-inf`` past
    the last) and ``(width[r - 1] - x) / 2`` (``-inf`` before the first), then ``-inf``
    unless above ``tol`` and at least ``accuracy`` (less the rounding slack).
    """
    inf = math.inf
    n = len(c)
    floor = accuracy - ROUNDING
    left = bisect.bisect_left
    out: list[float] = []
    add = out.append
    for x in xs:
        r = left(c, x)
        at = rest[r] if r < n else -inf
        before = 0.5 * (width[r - 1] - x) if r > 0 else -inf
        value = at if at >= before else before
        add(value if value > tol and value >= floor else -inf)
    return out


def _pick(c: list[float], rest: list[float], width: list[float], x: float) -> int:
    """The entry of the staircase ``(c, rest, width)`` that attains ``tau(x)``."""
    r = bisect.bisect_left(c, x)
    at = rest[r] if r < len(c) else -math.inf
    before = 0.5 * (width[r - 1] - x) if r > 0 else -math.inf
    return r if at >= before else r - 1


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
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> front = arc_front(s, TWO_PI)
    >>> last = staircase(front, None, 1e-9)
    >>> np.degrees(last.tau(np.radians([0.0, 90.0, 130.0]))).round(6).tolist()
    [63.434949, 18.434949, -inf]
    """
    if len(front) <= SMALL:
        return _staircase_python(front, after, tol, accuracy)
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


def _staircase_python(
    front: ArcFront, after: Staircase | None, tol: float, accuracy: float
) -> Staircase:
    """:func:`staircase` in plain Python floats for a small front (:func:`_stair_lists`)."""
    values = None if after is None else after.tau_list(front.span_list)
    idx, rest, width, c = _stair_lists(front.span_list, front.width_list, values, tol)
    return Staircase(
        front,
        np.array(idx, dtype=np.intp),
        np.array(rest, dtype=np.float64),
        np.array(width, dtype=np.float64),
        np.array(c, dtype=np.float64),
        c,
        tol,
        accuracy,
        rest,
        width,
    )


def _stair_lists(
    spans: list[float], widths: list[float], values: list[float] | None, tol: float
) -> tuple[list[int], list[float], list[float], list[float]]:
    """Front index, rest, width and ``c`` of a staircase's entries, step for step.

    ``values`` is the next action's ``tau`` at each arc of the front (``None``: this is the
    last action, and only single basins count). The entries are what :func:`staircase`
    keeps, ``pareto_front(-rest, width)`` of the arcs with ``rest > tol``: since the front's
    widths increase with the index, that is every arc whose rest exceeds the rest of each
    wider arc, found by one scan from the widest down, and already in the front's order
    (rest decreasing, widths increasing). For the last action every single basin has rest
    ``inf``: the widest of them (the front's spans increase from 0, so they come first).
    """
    if values is None:
        n = bisect.bisect_right(spans, 0.0)  # the arcs of span <= 0: single basins
        if n == 0:
            return [], [], [], []
        return [n - 1], [math.inf], [widths[n - 1]], [widths[n - 1] - 2.0 * math.inf]
    idx: list[int] = []
    rest: list[float] = []
    best = -math.inf
    for n in range(len(values) - 1, -1, -1):
        v = values[n]
        if v > tol and v > best:
            best = v
            idx.append(n)
            rest.append(v)
    idx.reverse()
    rest.reverse()
    width: list[float] = []
    c: list[float] = []
    for n, r in zip(idx, rest, strict=True):
        w = widths[n]
        width.append(w)
        c.append(w - 2.0 * r)
    return idx, rest, width, c


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


def widest_reachable(
    fronts: list[ArcFront], tol: float, margin: float, cap: float, max_actions: int
) -> float:
    """The widest arc any plan collapses, up to ``cap`` (at most ``max_actions`` actions).

    ``fronts`` are those of the action types; each image must fit the next arc with
    ``margin`` to spare on each side. The widest arc of ``k + 1`` actions is ``G(W_k)``,
    with ``G(L)`` the widest arc of any action type whose image fits an arc ``L`` wide (the
    best counts of each length keep the widest arc, and ``G`` is non-decreasing). So the
    widths ``W_k`` are monotone from the first step on: once ``W_{k+1} <= W_k`` no longer
    plan collapses more. Without accuracy they grow to the period (Goldberg 1993); with it
    they may stop short.
    """
    width = max(f.widest(tol) for f in fronts)
    for _ in range(max_actions - 1):
        if width >= cap:
            break
        wider = max(f.widest(width - 2.0 * margin) for f in fronts)
        if wider <= width + tol:
            break
        width = wider
    return width


def small_options(
    problem: Problem, fronts: dict[str, ArcFront], tol: float, plans: Plans
) -> list[PlanOption]:
    """:meth:`ArcPlanner.plan_options` on the fronts' lists: no :class:`Staircase` nor :class:`Arc`.

    The staircase of each suffix of action types (keyed, as in :meth:`ArcPlanner.staircases`,
    by its first action and the staircase after it), and its ``tau`` at every arc of the
    front of the action before it, are computed once for all the plans (a plan of ``k``
    actions needs the ``tau`` that makes the staircase of ``k`` actions); the witnesses are
    front indices. Every float operation is the one of :meth:`ArcPlanner.witnesses`,
    :meth:`Staircase.pick` and :func:`chain_option`, so the options are the same, bit for bit
    (the planner checks that no chain would need more than :data:`STAIR_CELLS` entries).
    """
    accuracy = problem.accuracy
    prior, group = problem.prior, problem.goal_group
    cap = period_cap(problem)
    actions: dict[str, Action] = {}
    for a in problem.actions:  # (a loop: a comprehension costs more on few actions)
        actions[a.name] = a
    inf = math.inf
    # (kind, id of the staircase after it, or -1) -> (id, front index, rest, width, c)
    stairs: dict[tuple[str, int], tuple[int, list[int], list[float], list[float], list[float]]]
    stairs = {}
    taus: dict[tuple[str, int], list[float]] = {}  # (kind, staircase id) -> tau at its front

    out = []
    for p, cost, kinds, length in plans:
        k = len(kinds)
        chain_stairs = []  # the staircases of kinds[k-1:], kinds[k-2:], ..., kinds[1:]
        after = None
        for m in range(k - 1, 0, -1):
            t = kinds[m]
            key = (t, -1 if after is None else after[0])
            st = stairs.get(key)
            if st is None:
                g = fronts[t]
                later: list[float] | None = None
                if after is not None:
                    later = _tau_at(taus, t, g, after, tol, accuracy)
                st = (len(stairs), *_stair_lists(g.span_list, g.width_list, later, tol))
                stairs[key] = st
            chain_stairs.append(st)
            after = st
        f = fronts[kinds[0]]
        spans = f.span_list
        at = bisect.bisect_left(f.width_list, length - tol)  # the arcs at..end are wide enough
        if after is None:  # one action: a single basin
            tolerance = None
            while spans[at] > 0.0:
                at += 1
        else:
            values = _tau_at(taus, kinds[0], f, after, tol, accuracy)
            best = -inf
            for n in range(at, len(values)):
                if values[n] > best:
                    best = values[n]
            if not math.isfinite(best):  # pragma: no cover - the lengths guarantee a chain
                raise PlanningError("internal error: no witness chain for a plan the lengths allow")
            while values[at] < best - tol:
                at += 1
            tolerance = best
        # chain_option, witness by witness: the first placed by the prior, each later one
        # picked by its staircase for the span of the one before (Arc.span: s_last - s),
        # the turn centring that image in it.
        lo = f.lo_list[at]
        _, start = prior.max_arc_mass(length if length < cap else cap, group, prefer=lo)
        angles = [start - lo]
        arc = (lo + f.width_list[at]) - lo  # Arc.width
        for m in range(1, k):
            s = f.s_first_list[at]
            s_last = s + f.span_list[at]
            _, idx, rest, width, c = chain_stairs[k - 1 - m]
            at = idx[_pick(c, rest, width, s_last - s)]
            f = fronts[kinds[m]]
            lo = f.lo_list[at]
            angles.append(0.5 * (s + s_last) - 0.5 * (lo + (lo + f.width_list[at])))
        steps, turned = short_turns(list(map(actions.__getitem__, kinds)), angles)
        final = math.fmod(f.s_first_list[at] + turned + TWO_PI, TWO_PI)
        out.append(new_option(tuple(steps), final, p, cost, tolerance, (start, start + arc)))
    return out


def _tau_at(
    taus: dict[tuple[str, int], list[float]],
    kind: str,
    front: ArcFront,
    stair: tuple[int, list[int], list[float], list[float], list[float]],
    tol: float,
    accuracy: float,
) -> list[float]:
    """``tau`` of ``stair`` at every arc of ``front`` (of action ``kind``), memoised."""
    key = (kind, stair[0])
    values = taus.get(key)
    if values is None:
        _, _, rest, width, c = stair
        values = taus[key] = _tau(c, rest, width, tol, accuracy, front.span_list)
    return values


def chain_option(
    problem: Problem,
    chain: list[Arc],
    tolerance: float | None,
    placed: float,
    p: float,
    cost: float,
    arc: float,
) -> PlanOption:
    """The plan option of a chain of witness arcs: gripper angles and final orientation.

    The first action's world angle puts ``chain[0]`` where the prior's mass on an arc of
    length ``placed`` is largest; each later turn centres the image of the previous witness
    in the next one. The success arc is reported ``arc`` long from the placement;
    ``tolerance``, ``p`` and ``cost`` are reported as given.
    """
    _, start = problem.prior.max_arc_mass(placed, problem.goal_group, prefer=chain[0].lo)
    angles = [start - chain[0].lo]
    for prev, w in itertools.pairwise(chain):
        # Centre the image [s_first, s_last] of the previous arc inside this witness.
        angles.append(0.5 * (prev.s_first + prev.s_last) - 0.5 * (w.lo + w.hi))
    steps, turned = short_turns(plan_actions(problem, [a.kind for a in chain]), angles)
    final = math.fmod(chain[-1].s_first + turned + TWO_PI, TWO_PI)
    return PlanOption(tuple(steps), final, p, cost, tolerance, (start, start + arc))
