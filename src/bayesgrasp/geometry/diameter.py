"""The exact diameter function of a convex polygon (the seed, Appendix A).

``d(theta)`` is the width, along the gripper's squeeze axis x, of the part rotated
counter-clockwise by ``theta``. With the part's vertices ``v`` and the world x-axis seen from
the part, ``u(theta) = (cos theta, -sin theta)``,

    d(theta) = max_i <v_i, u> - min_j <v_j, u> = <v_i* - v_j*, u> = l |cos(theta - phi)|,

where ``(v_i*, v_j*)`` is the antipodal vertex pair touching the two jaws, ``l`` its length and
``phi`` the orientation at which that chord lies along x. The touching pair only changes when
an edge becomes parallel to the jaws (an *edge alignment*, ``theta = -nu_e mod pi`` for the
edge's outward normal angle ``nu_e``), so ``d`` is a sinusoid on each interval between
consecutive alignments (Appendix A). We find each interval's pair by rotating calipers
done as a binary search of the sorted edge normals: O(n log n) for all pieces.

Extrema: ``d`` is the maximum of sinusoids, so it is concave inside a piece and has convex
kinks at alignments. Minima can only be kinks whose left slope is negative and right slope
positive; maxima are the points inside a piece where its chord lies along x, or kinks where
the slopes on both sides are zero within the angle tolerance. Read around the circle, with
the slopes that are zero within the tolerance left out, minima and maxima alternate and pair
up by construction (see ``_pieces_numpy``). A minimum less than ``Tolerance.barrier`` times
the part's size below an adjacent maximum is dropped with that maximum: rounded coordinates
make parallel edges and perpendicular chords only nearly so, which splits one stable
orientation into two a hair apart.

Near-symmetric parts: a part whose ``symmetry_order`` is r >= 3 (every vertex lands within
``Tolerance.symmetry`` times the size of another under a turn by ``2 pi / r``) is taken to be
exactly symmetric. Its extrema are those of the symmetrized polygon
(:meth:`~bayesgrasp.geometry.polygon.ConvexPolygon.symmetrized`) over one period, simplified
there and repeated, so they have the period ``2 pi / (r (1 + r mod 2))`` exactly and the
squeeze, push and push-grasp functions built on them agree with the symmetry order (a part
with 1e-8 noise on a regular 1000-gon would otherwise break ``s(theta + T) = s(theta) + T``
by 1e-5 rad, and shallow pairs could be dropped in some periods and not in others). The
pieces stay those of the polygon itself: ``d(theta)`` is the part's own width.
"""

from __future__ import annotations

import bisect
import dataclasses
import heapq
import math
from operator import lt

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import BayesGraspError
from ..sizes import SMALL
from .polygon import ConvexPolygon

__all__ = ["DiameterFunction", "diameter_function"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


class DiameterFunction:
    """Piecewise-sinusoidal diameter function over one period ``[0, pi)``.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] + pi``);
    on it ``d(theta) = lengths[k] * cos(theta - phases[k])``, with ``phases[k]`` within
    ``pi / 2`` of every angle of the piece. A frozen value: all arrays are read-only, and
    made on first use when the function was built on Python floats (a polygon of a few
    vertices; :attr:`extrema` gives the extrema as floats).

    Attributes
    ----------
    polygon : ConvexPolygon
    breaks : ndarray of shape (P,)
        Edge-alignment angles in ``[0, pi)``, increasing (parallel edges give one).
    lengths : ndarray of shape (P,)
        Length of the chord touching both jaws on each piece.
    phases : ndarray of shape (P,)
        Orientation at which that chord lies along the squeeze axis.
    pairs : ndarray of shape (P, 2)
        Indices of the vertices touching the +x and -x jaws on each piece.
    minima : ndarray
        Local minima in ``[0, pi)`` (edge alignments where ``d`` is locally least), except
        those shallower than ``polygon.tol.barrier * polygon.size``; for a part symmetric
        within the tolerance (order 3 or more), those of its symmetrized vertices, exactly
        periodic (see the module docstring).
    maxima : ndarray
        Local maxima in ``[0, pi)`` (unstable equilibria of a squeeze), alternating with
        the minima.

    Examples
    --------
    >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> np.degrees(d.minima).round(6).tolist(), d([0.0, np.pi / 2]).round(12).tolist()
    ([0.0, 90.0], [2.0, 1.0])
    >>> d.extrema == (tuple(d.minima.tolist()), tuple(d.maxima.tolist()))
    True
    """

    __slots__ = ("_arrays", "_data", "polygon")

    polygon: ConvexPolygon
    # breaks, lengths, phases, pairs, minima, maxima: arrays, or (pairs: two) float tuples
    _data: tuple[object, ...]
    _arrays: tuple[NDArray[np.generic], ...] | None

    def __init__(
        self,
        polygon: ConvexPolygon,
        breaks: ArrayLike,
        lengths: ArrayLike,
        phases: ArrayLike,
        pairs: ArrayLike,
        minima: ArrayLike,
        maxima: ArrayLike,
    ) -> None:
        f8 = np.float64
        cols = (
            np.array(breaks, dtype=f8),
            np.array(lengths, dtype=f8),
            np.array(phases, dtype=f8),
            np.array(pairs, dtype=np.intp).reshape(-1, 2),
            np.array(minima, dtype=f8),
            np.array(maxima, dtype=f8),
        )  # copies: the caller's arrays stay theirs (and writeable)
        self._set(polygon, cols)

    def _set(self, polygon: ConvexPolygon, data: tuple[object, ...]) -> None:
        _SET_POLYGON(self, polygon)
        _SET_DATA(self, data)
        _SET_ARRAYS(self, None)

    @classmethod
    def _of_floats(
        cls,
        polygon: ConvexPolygon,
        pieces: tuple[list[float], list[float], list[float], list[int], list[int]],
        minima: list[float],
        maxima: list[float],
    ) -> DiameterFunction:
        """From the pieces as :func:`_pieces_python` (lists) or :func:`_pieces_numpy` gives them.

        Unchecked; lists become read-only arrays on first use.
        """
        breaks, lengths, phases, i_plus, i_minus = pieces
        out = cls.__new__(cls)
        _SET_POLYGON(out, polygon)
        _SET_DATA(out, (breaks, lengths, phases, (i_plus, i_minus), minima, maxima))
        _SET_ARRAYS(out, None)
        return out

    def __setattr__(self, name: str, value: object) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[object, ...]:
        return (DiameterFunction, (self.polygon, *self._columns()))

    def __repr__(self) -> str:
        names = ("breaks", "lengths", "phases", "pairs", "minima", "maxima")
        cols = ", ".join(f"{k}={v!r}" for k, v in zip(names, self._columns(), strict=True))
        return f"DiameterFunction(polygon={self.polygon!r}, {cols})"

    def _columns(self) -> tuple[NDArray[np.generic], ...]:
        arrays = self._arrays
        if arrays is None:
            out: list[NDArray[np.generic]] = []
            for k, col in enumerate(self._data):
                if type(col) is np.ndarray:
                    arr = col
                elif k == 3:  # the jaws' vertex indices (i_plus, i_minus), as two columns
                    arr = np.array(col, dtype=np.intp).reshape(2, -1).T.copy()
                else:
                    arr = np.array(col, dtype=np.float64)
                arr.setflags(write=False)
                out.append(arr)
            arrays = tuple(out)
            object.__setattr__(self, "_arrays", arrays)
        return arrays

    @property
    def extrema(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """``minima`` and ``maxima`` as tuples of Python floats (what the squeeze needs)."""
        lows, highs = self._data[4], self._data[5]
        return (
            tuple(lows.tolist() if isinstance(lows, np.ndarray) else lows),  # type: ignore[arg-type]
            tuple(highs.tolist() if isinstance(highs, np.ndarray) else highs),  # type: ignore[arg-type]
        )

    def _extrema_lists(self) -> tuple[list[float], list[float]]:
        """``minima`` and ``maxima`` as lists of Python floats (the caller must not change them)."""
        lows, highs = self._data[4], self._data[5]
        return (
            lows.tolist() if isinstance(lows, np.ndarray) else lows,  # type: ignore[return-value]
            highs.tolist() if isinstance(highs, np.ndarray) else highs,
        )

    @property
    def breaks(self) -> FloatArray:
        """Edge-alignment angles in ``[0, pi)``, increasing (read-only)."""
        return self._columns()[0]  # type: ignore[return-value]

    @property
    def lengths(self) -> FloatArray:
        """Length of the chord touching both jaws on each piece (read-only)."""
        return self._columns()[1]  # type: ignore[return-value]

    @property
    def phases(self) -> FloatArray:
        """Orientation at which each piece's chord lies along the squeeze axis (read-only)."""
        return self._columns()[2]  # type: ignore[return-value]

    @property
    def pairs(self) -> IntArray:
        """Vertices touching the +x and -x jaws on each piece, shape (P, 2) (read-only)."""
        return self._columns()[3]  # type: ignore[return-value]

    @property
    def minima(self) -> FloatArray:
        """Local minima in ``[0, pi)`` (read-only)."""
        return self._columns()[4]  # type: ignore[return-value]

    @property
    def maxima(self) -> FloatArray:
        """Local maxima in ``[0, pi)`` (read-only)."""
        return self._columns()[5]  # type: ignore[return-value]

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Evaluate ``d`` at any angles (radians), vectorised.

        Examples
        --------
        >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
        >>> np.round(d([0.0, np.pi / 4]), 12).tolist()
        [1.0, 1.414213562373]
        """
        th = np.asarray(theta, dtype=np.float64)
        k = self.piece_index(th)
        return self.lengths[k] * np.abs(np.cos(th - self.phases[k]))

    def piece_index(self, theta: ArrayLike) -> IntArray:
        """Index of the piece holding each angle."""
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        k = np.searchsorted(self.breaks - self.breaks[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.breaks) - 1), dtype=np.intp)

    @property
    def diameter(self) -> float:
        """The polygon's diameter (the largest value of ``d``)."""
        return float(self.lengths.max())


# The slots' own setters: about half the cost of object.__setattr__ (see transfer.py).
_SET_POLYGON, _SET_DATA, _SET_ARRAYS = (
    DiameterFunction.__dict__[name].__set__ for name in ("polygon", "_data", "_arrays")
)


def diameter_function(polygon: ConvexPolygon) -> DiameterFunction:
    """Build the exact diameter function of a convex polygon in O(n log n).

    The pieces (``breaks``, ``lengths``, ``phases``, ``pairs``) are those of the polygon.
    The extrema are those of ``d`` too, except for a part that is r-fold symmetric within
    ``tol.symmetry`` (``polygon.symmetry_order``, r >= 3): it is treated as exactly
    symmetric, and its extrema are those of :meth:`ConvexPolygon.symmetrized` over one
    period ``T = 2 pi / (r (1 + r mod 2))``, repeated every ``T``. They then have the period
    exactly (to rounding), and lie within the part's own round-off (about ``tol.symmetry``
    times the size over an edge length, in radians) of its own extrema.

    Parameters
    ----------
    polygon : ConvexPolygon

    Returns
    -------
    DiameterFunction

    Raises
    ------
    BayesGraspError
        An internal error (a bug): no extremum, or minima and maxima that do not pair up.

    Examples
    --------
    >>> tri = ConvexPolygon.from_points([(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)])
    >>> d = diameter_function(tri)
    >>> len(d.minima), len(d.maxima)
    (3, 3)
    """
    tol = polygon.tol.angle
    small = len(polygon.vertices) <= _SMALL
    depth = polygon.tol.barrier_for(polygon.size)
    r = polygon.symmetry_order_from(3)  # a half turn changes nothing: d has the period pi
    periods = r * (1 + r % 2) // 2 if r > 1 else 1  # periods of d in [0, pi)
    pieces: Pieces
    if small:
        breaks, ends, lengths, phases, i_plus, i_minus, events = _piece_lists(
            *polygon._coords(), tol
        )
        lists = (breaks, lengths, phases, i_plus, i_minus)
        if periods == 1:
            found = _in_order(breaks, ends, lengths, phases, events, tol, depth)  # most parts
            if found is None:
                ext = _extrema_python(breaks, ends, lengths, phases, len(breaks), tol)
                kept = _drop_shallow(_merged(ext, 0.0, math.pi), depth)
                found = [x for x, _, top in kept if not top], [x for x, _, top in kept if top]
            return DiameterFunction._of_floats(polygon, lists, *found)
        pieces = (*lists, ([], [], [], []))  # the extrema come from the symmetrized polygon
    else:
        pieces = _pieces_numpy(polygon.vertices, tol, math.pi)
    if periods > 1:
        # One period of the exactly symmetric part, simplified as a periodic function and
        # repeated: the shallow pairs go in every period or in none.
        period = math.pi / periods
        sym = polygon.symmetrized(centred=True)  # translation-free: see its docstring
        if small:
            one = _pieces_python(sym[:, 0].tolist(), sym[:, 1].tolist(), tol, period)
        else:
            one = _pieces_numpy(sym, tol, period)
        origin = float(one[0][0])
        kept = _drop_shallow(_merged(one[5], origin, period), depth)
        minima, maxima = (
            np.sort(
                np.array(
                    [
                        _wrap1(origin + at + k * period, math.pi)
                        for at, _, top in kept
                        if top is is_max
                        for k in range(periods)
                    ],
                    dtype=np.float64,
                )
            ).tolist()
            for is_max in (False, True)
        )
    else:
        kept = _drop_shallow(_merged(pieces[5], 0.0, math.pi), depth)
        minima = [at for at, _, top in kept if not top]
        maxima = [at for at, _, top in kept if top]
    return DiameterFunction._of_floats(polygon, pieces[:5], minima, maxima)  # type: ignore[arg-type]


# At or below this many vertices plain Python floats beat numpy's cost per call; both paths
# make the same decisions (tests/geometry/test_diameter.py and test_numerics.py compare them).
_SMALL = SMALL

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


def _pieces_numpy(v: FloatArray, tol: float, period: float = math.pi) -> Pieces:
    """Pieces over ``[0, pi)`` and extrema over one period, by array operations, O(n log n).

    ``period`` is ``pi`` or, for a symmetric polygon, ``pi / j``: the extrema are then those
    of the pieces that start in ``[breaks[0], breaks[0] + period)``, read as one cyclic
    sequence (the polygon must have that period).
    """
    n = len(v)
    e = np.concatenate((v[1:], v[:1])) - v  # (n, 2) edge i runs from v_i to v_{i+1}
    normals = _wrap(np.arctan2(e[:, 1], e[:, 0]) - math.pi / 2, TWO_PI)  # outward, CCW hull
    order = np.argsort(normals)
    normals_sorted = normals[order]

    # Edge alignments: edge parallel to the jaws when its normal is along +-x.
    b = _wrap(-normals, math.pi)
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
    k = np.searchsorted(normals_sorted, _wrap(np.concatenate((-mids, math.pi - mids)), TWO_PI))
    touching = order[k % n]  # (2P,)
    i_plus, i_minus = touching[:p], touching[p:]
    chord = v[i_plus] - v[i_minus]  # (P, 2)
    lengths = np.hypot(chord[:, 0], chord[:, 1])
    gamma = np.arctan2(chord[:, 1], chord[:, 0])
    # d = <chord, u(theta)> = l cos(theta + gamma); write phase near the piece's midpoint.
    phases = mids - (np.mod(mids + gamma + math.pi, TWO_PI) - math.pi)

    # Slopes at the ends of each piece: sign of (phase - angle), zero within tolerance.
    w = _window(breaks.tolist(), period, tol)
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


def _pieces_python(xs: list[float], ys: list[float], tol: float, period: float = math.pi) -> Pieces:
    """The same as :func:`_pieces_numpy`, step for step, in plain Python (small polygons).

    ``xs`` and ``ys`` are the vertices' coordinates; the pieces are lists.
    """
    breaks, ends, lengths, phases, i_plus, i_minus, _ = _piece_lists(xs, ys, tol)
    extrema = _extrema_python(breaks, ends, lengths, phases, _window(breaks, period, tol), tol)
    return breaks, lengths, phases, i_plus, i_minus, extrema


Events = tuple[list[float], list[float], bool]
"""Angles and values of d at the extrema in order from the first break (a kink there
first, real or not), and whether a slope is flat within the tolerance (they are then moot)."""


def _piece_lists(
    xs: list[float], ys: list[float], tol: float
) -> tuple[list[float], list[float], list[float], list[float], list[int], list[int], Events]:
    """``breaks``, their ends, ``lengths``, ``phases``, ``i_plus``, ``i_minus`` and the events."""
    pi, two_pi, quarter = math.pi, TWO_PI, math.pi / 2
    atan2, hypot, cos, find = math.atan2, math.hypot, math.cos, bisect.bisect_left
    n = len(xs)
    # Edge i runs from vertex i to vertex i + 1; its outward normal, reduced to [0, 2 pi),
    # and the edge's alignment -normal reduced to [0, pi) (the same from 2 pi as from 0).
    normals, b = [], []
    # (Equal lengths by construction, here and below: zip's strict= would cost a third of
    # the loop on a few vertices.)
    for x0, y0, x1, y1 in zip(xs, ys, [*xs[1:], xs[0]], [*ys[1:], ys[0]]):  # noqa: B905
        x = (atan2(y1 - y0, x1 - x0) - quarter) % two_pi
        normals.append(x)
        b.append(-x % pi)
    if two_pi in normals:  # _wrap1: % can round a tiny negative up to 2 pi (never above)
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
    # (used only when none is: see _in_order). The first is a kink at the first break,
    # there or not (_in_order decides). d is concave on a piece: phase - start >= phase - end.
    at: list[float] = []
    val: list[float] = []
    ntol = -tol
    flat = False
    rising: bool | None = None
    for lo, hi in zip(breaks, ends):  # noqa: B905
        mid = 0.5 * (lo + hi)
        # The sorted normals lie in [0, 2 pi): a direction % rounded up to 2 pi finds the
        # same edge as 0 would (_wrap1 changes nothing here).
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


def _extrema_python(
    breaks: list[float],
    ends: list[float],
    lengths: list[float],
    phases: list[float],
    w: int,
    tol: float,
) -> Extrema:
    """The extrema over the first ``w`` pieces (see the comment above :func:`_pieces_numpy`)."""
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


def _in_order(
    breaks: list[float],
    ends: list[float],
    lengths: list[float],
    phases: list[float],
    events: Events,
    tol: float,
    depth: float,
) -> tuple[list[float], list[float]] | None:
    """Minima and maxima over ``[0, pi)`` of most parts, from the pieces' pass.

    What :func:`_extrema_python`, :func:`_merged` (origin 0, period pi) and
    :func:`_drop_shallow` give when no slope is flat within the tolerance and no pair is
    shallower than ``depth``: the extrema then come piece by piece in order of angle, the
    ``events`` of :func:`_piece_lists` (the first break's kink only when the last piece
    ends with the other slope than the first starts), and an interior maximum of the last
    piece past pi wraps to the front. Returns None for any other part, which the general
    path then decides.
    """
    at, val, flat = events
    if flat:
        return None  # a slope flat within the tolerance somewhere
    first_up = phases[0] - breaks[0] > 0  # the slopes, as _extrema_python computes them
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
    # The angles increase strictly, as _merged sorts them: breaks < phase < next break on a
    # piece whose slopes are not flat; a last phase past pi stays below the first break +
    # pi by more than one rounding there once the tolerance is one (1e-15: ulp(2 pi) is
    # 8.9e-16). Below that tolerance it is tested.
    if tol < 1e-15 and not all(map(lt, at, at[1:])):
        return None
    if m > 2:  # no pair shallower than depth (_drop_shallow would cancel it)
        prev, low = val[-1], -depth
        for x in val:
            if low <= x - prev <= depth:
                return None
            prev = x
    return (at[1::2], at[0::2]) if first_is_max else (at[0::2], at[1::2])


def _window(breaks: list[float], period: float, tol: float) -> int:
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


def _wrap1(x: float, period: float) -> float:
    """``x`` reduced to ``[0, period)``, as :func:`_wrap` does for arrays."""
    out = x % period
    return 0.0 if out >= period else out


def _wrap(x: FloatArray, period: float) -> FloatArray:
    """``x`` reduced to ``[0, period)`` (``np.mod`` can round a tiny negative to ``period``)."""
    out = np.mod(x, period)
    out[out >= period] = 0.0
    return out


Extremum = tuple[float, float, bool]
"""Angle (from the start of the period), value of d, and whether it is a maximum."""


def _merged(extrema: Extrema, origin: float, period: float) -> list[Extremum]:
    """Minima and maxima as one list sorted by angle from ``origin``, reduced to the period."""
    min_at, min_d, max_at, max_d = extrema
    if len(max_at) != len(min_at) or len(min_at) == 0:  # pragma: no cover - a bug, not input
        raise BayesGraspError(
            f"internal error: {len(min_at)} minima and {len(max_at)} maxima of the diameter"
        )
    at = [(x - origin) % period for x in min_at + max_at]
    if period in at:  # _wrap1: % can round a tiny negative up to the period
        at = [0.0 if x >= period else x for x in at]
    return sorted(
        zip(
            at,
            min_d + max_d,
            [False] * len(min_at) + [True] * len(max_at),
            strict=True,
        )
    )


def _drop_shallow(ext: list[Extremum], depth: float) -> list[Extremum]:
    """Cyclic, alternating extrema without the adjacent pairs shallower than ``depth``.

    Pairs of neighbours whose values differ by at most ``depth`` are cancelled, shallowest
    first (a persistence simplification; ties go to the first in angle), keeping at least
    one minimum and one maximum; cancelling an adjacent pair keeps the alternation. A heap
    of the neighbours' differences over a cyclic linked list: O(m log m), also when every
    pair is shallow (a regular 99,999-gon).

    Examples
    --------
    >>> _drop_shallow([(0.0, 1.0, False), (0.1, 1.0 + 1e-12, True), (0.2, 1.0, False),
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
