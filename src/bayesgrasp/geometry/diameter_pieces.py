"""The pieces of the diameter function and its extrema (the seed, Appendix A).

The computations behind :func:`~bayesgrasp.geometry.diameter.diameter_function` (see that
module for the mathematics): the piecewise-sinusoidal pieces of ``d`` found by sorting the
edge normals and a binary search for each piece's antipodal pair (rotating calipers), the
extrema read from the slopes at the ends of the pieces, and the persistence simplification
that drops pairs of extrema shallower than the barrier tolerance.

The pieces and extrema exist twice, making the same decisions, held together by
tests/geometry/test_diameter.py and test_numerics.py: by array operations
(:func:`pieces_numpy`, O(n log n)) and on Python floats for a few vertices
(:func:`pieces_python`, :func:`piece_lists`, :func:`extrema_python`; below
:data:`~bayesgrasp.sizes.SMALL` vertices numpy's cost of a call exceeds the work).
:func:`in_order` reads the extrema of most parts straight from the pieces' pass.
"""

from __future__ import annotations

import bisect
import heapq
import math
from operator import lt

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import BayesGraspError

__all__ = [
    "Events",
    "Extrema",
    "Extremum",
    "Pieces",
    "drop_shallow",
    "extrema_python",
    "in_order",
    "merged",
    "piece_lists",
    "pieces_numpy",
    "pieces_python",
    "window",
    "wrap",
    "wrap1",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

Extrema = tuple[list[float], list[float], list[float], list[float]]
"""Angles and values of d at the minima, then angles and values at the maxima."""

Pieces = tuple[
    FloatArray | list[float],
    FloatArray | list[float],
    FloatArray | list[float],
    IntArray | list[int],
    IntArray | list[int],
    Extrema,
]
"""``breaks``, ``lengths``, ``phases``, the vertices touching the +x and the -x jaw on each
piece (arrays, or lists on the plain-Python path), and the extrema over one period."""

# How the extrema are found (both paths). Each piece has a slope sign at its start and at
# its end: the sign of (phase - angle), zero when the chord is within the angle tolerance of
# lying along x there (nearly flat). Around the circle these signs form one cyclic sequence
# (start and end of piece 0, of piece 1, ...); d is concave inside a piece (the signs do not
# rise there) and has convex kinks at the breaks. Dropping the zeros, each change from - to +
# is a minimum and each change from + to - a maximum, so minima and maxima alternate and
# pair up whatever the zeros (the 1e-10 noise of a regular 12-gon leaves opposite edges
# parallel to about 1e-9 rad: a piece of that width between their alignments, flat at both
# ends, on which the earlier rules lost a minimum). With i the entry of the last nonzero
# sign before a change: a maximum with no zero between, inside piece i / 2 (i even), is at
# that piece's phase; every other extremum is at the first break after entry i, the break
# (i + 2) // 2 (d is flat to the angle tolerance across the zeros, so which break is moot).


def pieces_numpy(v: FloatArray, tol: float, period: float = math.pi) -> Pieces:
    """Pieces over ``[0, pi)`` and extrema over one period, by array operations, O(n log n).

    ``period`` is ``pi`` or, for a symmetric polygon, ``pi / j``: the extrema are then those
    of the pieces that start in ``[breaks[0], breaks[0] + period)``, read as one cyclic
    sequence (the polygon must have that period).
    """
    n = len(v)
    e = np.concatenate((v[1:], v[:1])) - v  # (n, 2) edge i runs from v_i to v_{i+1}
    normals = wrap(np.arctan2(e[:, 1], e[:, 0]) - math.pi / 2, TWO_PI)  # outward, CCW hull
    order = np.argsort(normals)
    normals_sorted = normals[order]

    # Edge alignments: edge parallel to the jaws when its normal is along +-x.
    b = wrap(-normals, math.pi)
    b.sort()
    # Keep b[i] when the gap *before* it is wide: parallel edges give one alignment.
    wide = np.diff(b, prepend=b[-1] - math.pi) > tol
    breaks = b[wide] if wide.any() else b[:1]
    ends = np.concatenate((breaks[1:], breaks[:1] + math.pi))
    mids = 0.5 * (breaks + ends)  # (P,)
    p = len(breaks)

    # The jaw at +x touches the vertex of largest projection on u(theta), direction -theta;
    # the jaw at -x the vertex of largest projection on direction pi - theta. Vertex i is
    # extreme for directions between the normals of edges i - 1 and i, so the first sorted
    # normal at or after a direction names the edge that starts at the touching vertex.
    k = np.searchsorted(normals_sorted, wrap(np.concatenate((-mids, math.pi - mids)), TWO_PI))
    touching = order[k % n]  # (2P,)
    i_plus, i_minus = touching[:p], touching[p:]
    chord = v[i_plus] - v[i_minus]  # (P, 2)
    lengths = np.hypot(chord[:, 0], chord[:, 1])
    gamma = np.arctan2(chord[:, 1], chord[:, 0])
    # d = <chord, u(theta)> = l cos(theta + gamma); write phase near the piece's midpoint.
    phases = mids - (np.mod(mids + gamma + math.pi, TWO_PI) - math.pi)

    # Slopes at the ends of each piece: sign of (phase - angle), zero within tolerance.
    w = window(breaks.tolist(), period, tol)
    to_start, to_end = phases[:w] - breaks[:w], phases[:w] - ends[:w]
    signs = np.empty(2 * w, dtype=np.int8)  # (2W,) start and end of each piece, in turn
    signs[0::2] = (to_start > tol).astype(np.int8) - (to_start < -tol)
    signs[1::2] = (to_end > tol).astype(np.int8) - (to_end < -tol)
    nonzero = np.flatnonzero(signs)
    sig = signs[nonzero]
    change = np.flatnonzero(sig != np.roll(sig, 1))
    last = np.roll(nonzero, 1)[change]  # (X,) entry of the last nonzero sign before each
    is_max = np.roll(sig, 1)[change] > 0
    interior = is_max & (np.mod(nonzero[change] - last, 2 * w) == 1) & (last % 2 == 0)
    at = (last + 2) // 2 % w  # the break after entry `last`
    at_break = lengths[:w] * np.cos(to_start)  # (W,) d at each break
    kink_max = is_max & ~interior
    kink_min = ~is_max
    extrema = (
        breaks[at[kink_min]].tolist(),
        at_break[at[kink_min]].tolist(),
        phases[last[interior] // 2].tolist() + breaks[at[kink_max]].tolist(),
        lengths[last[interior] // 2].tolist() + at_break[at[kink_max]].tolist(),
    )
    return breaks, lengths, phases, i_plus, i_minus, extrema


def pieces_python(xs: list[float], ys: list[float], tol: float, period: float = math.pi) -> Pieces:
    """The same as :func:`pieces_numpy`, step for step, in plain Python (small polygons).

    ``xs`` and ``ys`` are the vertices' coordinates; the pieces are lists.
    """
    breaks, ends, lengths, phases, i_plus, i_minus, _ = piece_lists(xs, ys, tol)
    extrema = extrema_python(breaks, ends, lengths, phases, window(breaks, period, tol), tol)
    return breaks, lengths, phases, i_plus, i_minus, extrema


Events = tuple[list[float], list[float], bool]
"""Angles and values of d at the extrema in order from the first break (a kink there
first, real or not), and whether a slope is flat within the tolerance (they are then moot)."""


def piece_lists(
    xs: list[float], ys: list[float], tol: float
) -> tuple[list[float], list[float], list[float], list[float], list[int], list[int], Events]:
    """The pieces of ``d`` on Python floats, and the extrema as they come.

    Edge ``i``'s outward normal ``nu_i`` (counter-clockwise polygon: the edge direction
    less ``pi / 2``) aligns the edge with the jaws at ``theta = -nu_i mod pi``: those
    angles, sorted, with gaps within ``tol`` merged (parallel edges), are the ``breaks``.
    On the piece from a break to the next, the jaw at +x touches the vertex of greatest
    projection on the direction ``-theta``, the vertex whose normal cone (between the
    normals of its two edges) holds that direction: a binary search of the sorted normals
    at the piece's midpoint (rotating calipers as a search, Toussaint 1983); likewise the
    jaw at -x, direction ``pi - theta``. The chord between the two has length ``l`` and
    angle ``gamma``, and ``d(theta) = l cos(theta + gamma)`` on the piece: ``phase =
    -gamma``, written within ``pi / 2`` of the midpoint.

    Returns ``breaks``, their ends, ``lengths``, ``phases``, ``i_plus``, ``i_minus`` and
    the :data:`Events` (:func:`in_order` reads most parts' extrema from them).
    """
    pi, two_pi, quarter = math.pi, TWO_PI, math.pi / 2
    atan2, hypot, cos, find = math.atan2, math.hypot, math.cos, bisect.bisect_left
    n = len(xs)
    # Edge i runs from vertex i to vertex i + 1; its outward normal, reduced to [0, 2 pi),
    # and the edge's alignment -normal reduced to [0, pi) (the same from 2 pi as from 0).
    normals, b = [], []
    # (The lists zipped here and below have equal lengths by construction.)
    for x0, y0, x1, y1 in zip(xs, ys, [*xs[1:], xs[0]], [*ys[1:], ys[0]]):  # noqa: B905
        x = (atan2(y1 - y0, x1 - x0) - quarter) % two_pi
        normals.append(x)
        b.append(-x % pi)
    if two_pi in normals:  # wrap1: % can round a tiny negative up to 2 pi (never above)
        normals = [0.0 if x >= two_pi else x for x in normals]
    if pi in b:
        b = [0.0 if x >= pi else x for x in b]
    order = sorted(range(n), key=normals.__getitem__)
    normals_sorted = sorted(normals)
    order.append(order[0])  # a direction past the last normal: the least one's edge
    b.sort()
    # Keep b[i] when the gap *before* it is wide: parallel edges give one alignment.
    prev = b[-1] - pi
    breaks = []
    for x in b:
        if x - prev > tol:
            breaks.append(x)
        prev = x
    if not breaks:
        breaks = b[:1]
    ends = [*breaks[1:], breaks[0] + pi]
    lengths: list[float] = []
    phases: list[float] = []
    i_plus: list[int] = []
    i_minus: list[int] = []
    # The extrema in order from the first break, read from the slopes as if none were flat
    # (used only when none is: see in_order). The first is a kink at the first break,
    # there or not (in_order decides). d is concave on a piece: phase - start >= phase - end.
    at: list[float] = []
    val: list[float] = []
    ntol = -tol
    flat = False
    rising: bool | None = None
    for lo, hi in zip(breaks, ends):  # noqa: B905
        mid = 0.5 * (lo + hi)
        # The sorted normals lie in [0, 2 pi): a direction % rounded up to 2 pi finds the
        # same edge as 0 would (wrap1 changes nothing here).
        a = order[find(normals_sorted, -mid % two_pi)]
        c = order[find(normals_sorted, (pi - mid) % two_pi)]
        cx, cy = xs[a] - xs[c], ys[a] - ys[c]
        length = hypot(cx, cy)
        phase = mid - ((mid + atan2(cy, cx) + pi) % two_pi - pi)
        i_plus.append(a)
        i_minus.append(c)
        lengths.append(length)
        phases.append(phase)
        # The slope's signs at the start and the end (zero within the tolerance: flat).
        x, y = phase - lo, phase - hi
        up = x > tol
        if not up and x >= ntol:
            flat = True
        if up != rising:  # a kink at the break: a maximum if d turns down
            at.append(lo)
            val.append(length * cos(x))
        rising = y > tol
        if not rising and y >= ntol:
            flat = True
        if up and not rising:  # a maximum inside the piece
            at.append(phase)
            val.append(length)
    return breaks, ends, lengths, phases, i_plus, i_minus, (at, val, flat)


def extrema_python(
    breaks: list[float],
    ends: list[float],
    lengths: list[float],
    phases: list[float],
    w: int,
    tol: float,
) -> Extrema:
    """The extrema over the first ``w`` pieces (see the comment above :func:`pieces_numpy`)."""
    to_start = [x - lo for x, lo in zip(phases[:w], breaks, strict=False)]
    to_end = [x - hi for x, hi in zip(phases[:w], ends, strict=False)]
    # Slope signs at the start and end of each piece, zero within the tolerance of flat.
    starts = [(x > tol) - (x < -tol) for x in to_start]
    stops = [(x > tol) - (x < -tol) for x in to_end]
    at_break = [x * math.cos(y) for x, y in zip(lengths, to_start, strict=False)]  # d at starts
    min_at, min_d, max_at, max_d, kmax_at, kmax_d = [], [], [], [], [], []
    if 0 not in starts and 0 not in stops:
        # Most parts: no zeros, so each change is between neighbouring entries: at a break
        # (the entry before is the end of the previous piece) or inside a piece.
        before = stops[-1]
        for k in range(w):
            start, stop = starts[k], stops[k]
            if before != start:
                if before < 0:
                    min_at.append(breaks[k])
                    min_d.append(at_break[k])
                else:
                    kmax_at.append(breaks[k])
                    kmax_d.append(at_break[k])
            if start != stop:
                if start > 0:
                    max_at.append(phases[k])
                    max_d.append(lengths[k])
                else:
                    at = (k + 1) % w
                    min_at.append(breaks[at])
                    min_d.append(at_break[at])
            before = stop
    else:
        signs = [x for pair in zip(starts, stops, strict=True) for x in pair]
        nonzero = [i for i, x in enumerate(signs) if x]
        for t, j in enumerate(nonzero):
            last = nonzero[t - 1]
            if signs[last] == signs[j]:
                continue
            at = (last + 2) // 2 % w
            if signs[last] < 0:
                min_at.append(breaks[at])
                min_d.append(at_break[at])
            elif (j - last) % (2 * w) == 1 and last % 2 == 0:
                max_at.append(phases[last // 2])
                max_d.append(lengths[last // 2])
            else:
                kmax_at.append(breaks[at])
                kmax_d.append(at_break[at])
    return min_at, min_d, max_at + kmax_at, max_d + kmax_d


def in_order(
    breaks: list[float],
    ends: list[float],
    lengths: list[float],
    phases: list[float],
    events: Events,
    tol: float,
    depth: float,
) -> tuple[list[float], list[float]] | None:
    """Minima and maxima over ``[0, pi)`` of most parts, from the pieces' pass.

    What :func:`extrema_python`, :func:`merged` (origin 0, period pi) and
    :func:`drop_shallow` give when no slope is flat within the tolerance and no pair is
    shallower than ``depth``: the extrema then come piece by piece in order of angle, the
    ``events`` of :func:`piece_lists` (the first break's kink only when the last piece
    ends with the other slope than the first starts), and an interior maximum of the last
    piece past pi wraps to the front. Returns None for any other part, which the general
    path then decides.
    """
    at, val, flat = events
    if flat:
        return None  # a slope flat within the tolerance somewhere
    first_up = phases[0] - breaks[0] > 0  # the slopes, as extrema_python computes them
    last_up = phases[-1] - ends[-1] > 0
    if first_up == last_up:  # no kink at the first break
        del at[0], val[0]
        first_is_max = first_up
    else:
        first_is_max = last_up
    if phases[-1] - breaks[-1] > 0 > phases[-1] - ends[-1] and phases[-1] >= math.pi:
        at.insert(0, at.pop() % math.pi)  # the last piece's maximum, past pi
        val.insert(0, val.pop())
        first_is_max = True
    m = len(at)
    if m < 2:  # pragma: no cover - d rises or falls all round: a bug
        return None
    # The angles increase strictly, as merged sorts them: breaks < phase < next break on a
    # piece whose slopes are not flat; a last phase past pi stays below the first break +
    # pi by more than one rounding there once the tolerance is one (1e-15: ulp(2 pi) is
    # 8.9e-16). Below that tolerance it is tested.
    if tol < 1e-15 and not all(map(lt, at, at[1:])):
        return None
    if m > 2:  # no pair shallower than depth (drop_shallow would cancel it)
        prev, low = val[-1], -depth
        for x in val:
            if low <= x - prev <= depth:
                return None
            prev = x
    return (at[1::2], at[0::2]) if first_is_max else (at[0::2], at[1::2])


def window(breaks: list[float], period: float, tol: float) -> int:
    """How many pieces start within one period of the first break (all of them for pi).

    The breaks of an exactly symmetric polygon repeat every ``period``, so ``pi / period``
    windows of equal count hold them all: that count, when it divides. Otherwise (a gap
    that the angle tolerance merges in one period and not in another) those below
    ``breaks[0] + period - tol``. The count comes first because rounding can put the first
    break of the next period below that bound when ``tol`` is only a few rounding errors.
    """
    n = len(breaks)
    if period >= math.pi:
        return n
    windows = round(math.pi / period)
    if n % windows == 0:
        return n // windows
    return max(1, bisect.bisect_left(breaks, breaks[0] + period - tol))


def wrap1(x: float, period: float) -> float:
    """``x`` reduced to ``[0, period)``, as :func:`wrap` does for arrays."""
    out = x % period
    return 0.0 if out >= period else out


def wrap(x: FloatArray, period: float) -> FloatArray:
    """``x`` reduced to ``[0, period)`` (``np.mod`` can round a tiny negative to ``period``)."""
    out = np.mod(x, period)
    out[out >= period] = 0.0
    return out


Extremum = tuple[float, float, bool]
"""Angle (from the start of the period), value of d, and whether it is a maximum."""


def merged(extrema: Extrema, origin: float, period: float) -> list[Extremum]:
    """Minima and maxima as one list sorted by angle from ``origin``, reduced to the period."""
    min_at, min_d, max_at, max_d = extrema
    if len(max_at) != len(min_at) or len(min_at) == 0:  # pragma: no cover - a bug, not input
        raise BayesGraspError(
            f"internal error: {len(min_at)} minima and {len(max_at)} maxima of the diameter"
        )
    at = [(x - origin) % period for x in min_at + max_at]
    if period in at:  # wrap1: % can round a tiny negative up to the period
        at = [0.0 if x >= period else x for x in at]
    return sorted(
        zip(
            at,
            min_d + max_d,
            [False] * len(min_at) + [True] * len(max_at),
            strict=True,
        )
    )


def drop_shallow(ext: list[Extremum], depth: float) -> list[Extremum]:
    """Cyclic, alternating extrema without the adjacent pairs shallower than ``depth``.

    Pairs of neighbours whose values differ by at most ``depth`` are cancelled, shallowest
    first (a persistence simplification: Edelsbrunner, Letscher and Zomorodian,
    "Topological persistence and simplification", 2002; ties go to the first in angle),
    keeping at least one minimum and one maximum; cancelling an adjacent pair keeps the
    alternation. A heap of the neighbours' differences over a cyclic linked list:
    O(m log m), also when every pair is shallow (a regular 99,999-gon).

    Examples
    --------
    >>> drop_shallow([(0.0, 1.0, False), (0.1, 1.0 + 1e-12, True), (0.2, 1.0, False),
    ...                (1.0, 2.0, True)], 1e-9)
    [(0.2, 1.0, False), (1.0, 2.0, True)]
    """
    m = len(ext)
    rise = [abs(ext[i][1] - ext[i - 1][1]) for i in range(m)]  # rise[i]: from i - 1 to i
    if m <= 2 or min(rise) > depth:
        return ext
    nxt = [*range(1, m), 0]
    prv = [m - 1, *range(m - 1)]
    alive = [True] * m
    heap = [(rise[j], (j - 1) % m, j) for j in range(m) if rise[j] <= depth]
    heapq.heapify(heap)
    left = m
    while heap and left > 2:
        x, i, j = heapq.heappop(heap)
        if not (alive[i] and nxt[i] == j and alive[j]):
            continue  # stale: one end was cancelled, or a new neighbour came
        a, b = prv[i], nxt[j]
        alive[i] = alive[j] = False
        nxt[a], prv[b] = b, a
        left -= 2
        x = abs(ext[b][1] - ext[a][1])
        if x <= depth and a != b:
            heapq.heappush(heap, (x, a, b))
    return [x for x, keep in zip(ext, alive, strict=True) if keep]
