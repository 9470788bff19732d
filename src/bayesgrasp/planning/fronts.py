"""Arc fronts: the arcs of one transfer function that no other arc beats.

The arcs of :mod:`bayesgrasp.planning.arcs` (see its notes): an open arc between basin
boundaries of one action's frame, with the image its basins' stable orientations span. The
front of a transfer function keeps, for each span, the widest arc (:class:`ArcFront`), built
in plain Python floats for a few states (:class:`SpanFront`, in order of span on demand) or
on numpy arrays (:func:`arc_front_arrays`, with the pruning of :func:`pruned_candidates`);
:func:`~bayesgrasp.planning.arcs.arc_front` chooses between them. :func:`period_rows`
limits the arcs to those of one period.
"""

from __future__ import annotations

import bisect
import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..geometry.transfer import TransferFunction

__all__ = [
    "ARC_CHUNK",
    "PRUNE_STATES",
    "SPAN_SLACK",
    "Arc",
    "ArcFront",
    "ArcGeometry",
    "SpanFront",
    "arc_front_arrays",
    "pareto_front",
    "period_rows",
    "pruned_candidates",
]

FloatArray = NDArray[np.float64]

ARC_CHUNK = 1 << 20
"""Arcs :func:`~bayesgrasp.planning.arcs.arc_front` enumerates at once (bounds memory for parts
with many states)."""


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

# Steps of the front filled by enumeration in one round; more, and the threshold is lowered.
_MAX_STEPS = 16


def arc_front_arrays(
    f: TransferFunction,
    max_span: float,
    *,
    chunk: int = ARC_CHUNK,
    prune: bool | None = None,
    rows: Sequence[int] | None = None,
) -> ArcFront:
    """:func:`~bayesgrasp.planning.arcs.arc_front` on numpy arrays (any number of states).

    ``prune``: enumerate only the arcs that can be on the front (:func:`pruned_candidates`;
    the default above :data:`PRUNE_STATES` states) or every arc, ``chunk`` at once (O(K^2)).
    The front is the same, bit for bit.
    """
    geo = ArcGeometry(f, max_span, rows)
    cand = None
    if prune if prune is not None else f.n_states > PRUNE_STATES:
        cand = pruned_candidates(geo)
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


@dataclass(frozen=True, slots=True, eq=False)
class ArcGeometry:
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


def pruned_candidates(geo: ArcGeometry) -> tuple[NDArray[np.intp], NDArray[np.intp]] | None:
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
