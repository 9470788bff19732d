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
positive; maxima are the points inside a piece where its chord lies along x. A minimum less
than ``Tolerance.barrier`` times the part's size below an adjacent maximum is dropped with
that maximum: rounded coordinates make parallel edges and perpendicular chords only nearly
so, which splits one stable orientation into two a hair apart.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import BayesGraspError
from .polygon import ConvexPolygon

__all__ = ["DiameterFunction", "diameter_function"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True, eq=False)
class DiameterFunction:
    """Piecewise-sinusoidal diameter function over one period ``[0, pi)``.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] + pi``);
    on it ``d(theta) = lengths[k] * cos(theta - phases[k])``, with ``phases[k]`` within
    ``pi / 2`` of every angle of the piece. All arrays are read-only.

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
        those shallower than ``polygon.tol.barrier * polygon.size``.
    maxima : ndarray
        Local maxima in ``[0, pi)`` (unstable equilibria of a squeeze), alternating with
        the minima.

    Examples
    --------
    >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> np.degrees(d.minima).round(6).tolist(), d([0.0, np.pi / 2]).round(12).tolist()
    ([0.0, 90.0], [2.0, 1.0])
    """

    polygon: ConvexPolygon
    breaks: FloatArray
    lengths: FloatArray
    phases: FloatArray
    pairs: IntArray
    minima: FloatArray
    maxima: FloatArray

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


def diameter_function(polygon: ConvexPolygon) -> DiameterFunction:
    """Build the exact diameter function of a convex polygon in O(n log n).

    Parameters
    ----------
    polygon : ConvexPolygon

    Returns
    -------
    DiameterFunction

    Examples
    --------
    >>> tri = ConvexPolygon.from_points([(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)])
    >>> d = diameter_function(tri)
    >>> len(d.minima), len(d.maxima)
    (3, 3)
    """
    v = polygon.vertices
    tol = polygon.tol.angle
    if len(v) <= _SMALL:
        breaks, lengths, phases, pairs, extrema = _pieces_python(v, tol)
    else:
        breaks, lengths, phases, pairs, extrema = _pieces_numpy(v, tol)
    min_at, min_d, max_at, max_d = extrema
    if len(max_at) != len(min_at) or len(min_at) == 0:  # pragma: no cover - a bug, not input
        raise BayesGraspError(
            f"internal error: {len(min_at)} minima and {len(max_at)} maxima of the diameter"
        )
    minima, maxima = _drop_shallow(
        min_at, min_d, max_at, max_d, polygon.tol.barrier_for(polygon.size)
    )
    arrays = (breaks, lengths, phases, pairs, minima, maxima)
    for arr in arrays:
        arr.setflags(write=False)
    return DiameterFunction(polygon, *arrays)


# Below this many vertices plain Python floats beat numpy's cost per call; both paths make
# the same decisions (tests/test_diameter.py compares them).
_SMALL = 40

Extrema = tuple[list[float], list[float], list[float], list[float]]


def _pieces_numpy(
    v: FloatArray, tol: float
) -> tuple[FloatArray, FloatArray, FloatArray, IntArray, Extrema]:
    """Pieces and extrema (angles and values of d) by array operations, O(n log n)."""
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
    to_start, to_end = phases - breaks, phases - ends
    slope_start = np.sign(to_start) * (np.abs(to_start) > tol)
    slope_end = np.sign(to_end) * (np.abs(to_end) > tol)
    interior_max = (slope_start > 0) & (slope_end < 0)
    prev_end = np.concatenate((slope_end[-1:], slope_end[:-1]))  # slope before each break
    kink_min = (prev_end < 0) & (slope_start > 0)
    kink_max = (prev_end == 0) & (slope_start == 0)

    at_break = lengths * np.cos(to_start)  # (P,) d at each break
    extrema = (
        breaks[kink_min].tolist(),
        at_break[kink_min].tolist(),
        phases[interior_max].tolist() + breaks[kink_max].tolist(),
        lengths[interior_max].tolist() + at_break[kink_max].tolist(),
    )
    return breaks, lengths, phases, np.stack([i_plus, i_minus], axis=1), extrema


def _pieces_python(
    v: FloatArray, tol: float
) -> tuple[FloatArray, FloatArray, FloatArray, IntArray, Extrema]:
    """The same as :func:`_pieces_numpy`, step for step, in plain Python (small polygons)."""
    pi = math.pi
    xs, ys = v[:, 0].tolist(), v[:, 1].tolist()
    n = len(xs)
    normals = [
        _wrap1(math.atan2(ys[(i + 1) % n] - ys[i], xs[(i + 1) % n] - xs[i]) - pi / 2, TWO_PI)
        for i in range(n)
    ]
    order = sorted(range(n), key=normals.__getitem__)
    normals_sorted = [normals[i] for i in order]
    b = sorted(_wrap1(-x, pi) for x in normals)
    breaks = [x for i, x in enumerate(b) if x - (b[i - 1] if i else b[-1] - pi) > tol] or b[:1]
    p = len(breaks)
    ends = [*breaks[1:], breaks[0] + pi]
    lengths, phases, i_plus, i_minus = [], [], [], []
    min_at, min_d, max_at, max_d, kmax_at, kmax_d = [], [], [], [], [], []
    slope_end = []
    slope_start = []
    at_break = []
    for lo, hi in zip(breaks, ends, strict=True):
        mid = 0.5 * (lo + hi)
        a = order[bisect.bisect_left(normals_sorted, _wrap1(-mid, TWO_PI)) % n]
        c = order[bisect.bisect_left(normals_sorted, _wrap1(pi - mid, TWO_PI)) % n]
        cx, cy = xs[a] - xs[c], ys[a] - ys[c]
        length = math.hypot(cx, cy)
        phase = mid - ((mid + math.atan2(cy, cx) + pi) % TWO_PI - pi)
        to_start, to_end = phase - lo, phase - hi
        i_plus.append(a)
        i_minus.append(c)
        lengths.append(length)
        phases.append(phase)
        slope_start.append((to_start > tol) - (to_start < -tol))
        slope_end.append((to_end > tol) - (to_end < -tol))
        at_break.append(length * math.cos(to_start))
        if slope_start[-1] > 0 and slope_end[-1] < 0:
            max_at.append(phase)
            max_d.append(length)
    for k in range(p):
        before = slope_end[k - 1]
        if before < 0 and slope_start[k] > 0:
            min_at.append(breaks[k])
            min_d.append(at_break[k])
        elif before == 0 and slope_start[k] == 0:
            kmax_at.append(breaks[k])
            kmax_d.append(at_break[k])
    pairs = np.array([i_plus, i_minus], dtype=np.intp).T.copy()
    return (
        np.array(breaks),
        np.array(lengths),
        np.array(phases),
        pairs,
        (min_at, min_d, max_at + kmax_at, max_d + kmax_d),
    )


def _wrap1(x: float, period: float) -> float:
    """``x`` reduced to ``[0, period)``, as :func:`_wrap` does for arrays."""
    out = x % period
    return 0.0 if out >= period else out


def _wrap(x: FloatArray, period: float) -> FloatArray:
    """``x`` reduced to ``[0, period)`` (``np.mod`` can round a tiny negative to ``period``)."""
    out = np.mod(x, period)
    out[out >= period] = 0.0
    return out


def _drop_shallow(
    min_at: list[float], min_d: list[float], max_at: list[float], max_d: list[float], depth: float
) -> tuple[FloatArray, FloatArray]:
    """Extrema over ``[0, pi)`` without the adjacent minimum-maximum pairs shallower than depth.

    Minima and maxima alternate around the circle. Pairs whose values differ by at most
    ``depth`` are cancelled, shallowest first (a persistence simplification), keeping at
    least one minimum and one maximum; cancelling an adjacent pair keeps the alternation.

    Returns
    -------
    minima, maxima : ndarray
        Sorted angles in ``[0, pi)``.
    """
    pi = math.pi
    ext = sorted(
        zip(
            [_wrap1(x, pi) for x in min_at + max_at],
            min_d + max_d,
            [False] * len(min_at) + [True] * len(max_at),
            strict=True,
        )
    )
    while len(ext) > 2:
        m = len(ext)
        rise = [abs(ext[(i + 1) % m][1] - ext[i][1]) for i in range(m)]
        if min(rise) > depth:
            break
        # Cancel every pair shallower than depth that is shallower than the pairs it
        # overlaps (ties go to the first); the rest wait for the next round.
        pick = [
            i
            for i in range(m)
            if rise[i] <= depth and rise[i] < rise[i - 1] and rise[i] <= rise[(i + 1) % m]
        ] or [i for i in range(m) if rise[i] <= depth][:1]
        pick = pick[: (m - 2) // 2]  # keep one minimum and one maximum
        if not pick:
            break
        drop = {*pick, *((i + 1) % m for i in pick)}
        ext = [x for i, x in enumerate(ext) if i not in drop]
    minima = np.array([at for at, _, is_max in ext if not is_max], dtype=np.float64)
    maxima = np.array([at for at, _, is_max in ext if is_max], dtype=np.float64)
    return minima, maxima
