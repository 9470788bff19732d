"""The convex hull of a point set (Andrew's monotone chain), its area and its centroid.

A frictionless parallel-jaw gripper touches only the convex hull of a part (the seed,
section 4.1 and Appendix A), so every part is reduced to its hull first.

**Andrew's monotone chain** (A. M. Andrew, "Another efficient algorithm for convex hulls in
two dimensions", *Information Processing Letters* 9(5), 216-219, 1979; also de Berg et al.,
*Computational Geometry*, 3rd ed., section 1.1). Sort the points by x, then y. The *lower
hull* is built by taking the points in that order: push each point onto a chain after
popping the chain's last point for as long as the last two points and the new one do not
turn strictly left, that is while

    cross(a, b, p) = (b_x - a_x)(p_y - a_y) - (b_y - a_y)(p_x - a_x) <= 0

for the chain's last two points ``a, b``. The *upper hull* is the same pass over the points
in reverse order. Each ends where the other starts; joined, without repeating those ends,
they are the hull counter-clockwise from the lexicographically least point. Only strict
left turns are kept, so repeated points and points inside an edge are dropped. Each point is
pushed and popped at most once: O(N) after the O(N log N) sort.

Two implementations of the chain, held together index for index by a property test
(tests/geometry/test_hull.py):

- :func:`monotone_chain`, the reference: the algorithm as written above, one point at a
  time. Plain Python; it also takes the hull of a few points (:func:`hull_of_few`).
- :func:`monotone_chain_vectorised`, for large parts (on 10^4 to 10^5 sorted points the
  chain is 9x to 15x faster, a large part's hull 2.5x to 4.6x): every point that does not
  turn strictly left between its neighbours is removed at once, by array operations, until
  none is left (see :func:`pruned_half_chain`); :func:`hull_indices` falls back to the
  reference when that takes too many rounds.

**Tolerances.** Rounded coordinates leave hull vertices a hair off the chord of their
neighbours; :func:`drop_near_collinear` removes those within ``eps`` (``Tolerance.length``
times the part's extent) so that a square given with noise has four sides.

**Area and centroid** by the shoelace formula (Green's theorem over the polygon's edges; e.g.
Bourke, "Calculating the area and centroid of a polygon", 1988):

    A = 1/2 sum_i (x_i y_{i+1} - x_{i+1} y_i),
    C = 1/(6A) sum_i (v_i + v_{i+1}) (x_i y_{i+1} - x_{i+1} y_i).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import NoReturn

import numpy as np
from numpy.typing import NDArray

from ..errors import PartError
from .coordinates import FloatArray

__all__ = [
    "drop_and_measure",
    "drop_near_collinear",
    "hull_indices",
    "hull_of_few",
    "largest_distance",
    "monotone_chain",
    "monotone_chain_vectorised",
    "polygon_area_centroid",
    "pruned_half_chain",
    "refuse_hull",
]


def polygon_area_centroid(vertices: FloatArray) -> tuple[float, FloatArray]:
    """Signed area and area centroid of a simple polygon (shoelace formula).

    Parameters
    ----------
    vertices : ndarray of shape (N, 2)
        Vertices in order, no repeated closing vertex.

    Returns
    -------
    area : float
        Signed area (positive when counter-clockwise).
    centroid : ndarray of shape (2,)

    Examples
    --------
    >>> a, c = polygon_area_centroid(np.array([[0.0, 0], [2, 0], [2, 1], [0, 1]]))
    >>> a, c.tolist()
    (2.0, [1.0, 0.5])
    """
    # Shift to the first vertex: keeps the cross products well conditioned far from the origin;
    # and scale to unit size: the products neither overflow nor underflow (1e150 or 1e-150).
    origin = vertices[0]
    p = vertices - origin
    scale = float(np.max(np.abs(p)))
    if not 0.0 < scale < math.inf:
        return 0.0, vertices.mean(axis=0)
    p = p / scale
    q = np.concatenate((p[1:], p[:1]))
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]  # (N,)
    unit_area = 0.5 * float(cross.sum())
    if unit_area == 0.0:
        return 0.0, vertices.mean(axis=0)
    centroid = ((p + q) * cross[:, None]).sum(axis=0) * (scale / (6.0 * unit_area))
    return unit_area * scale * scale, centroid + origin


def monotone_chain(points: Sequence[tuple[float, float]]) -> list[int]:
    """Andrew's monotone chain: the hull of points sorted by x, then y (the reference).

    Parameters
    ----------
    points : sequence of (x, y)
        Sorted lexicographically (as ``sorted`` or ``np.lexsort((y, x))`` order them).

    Returns
    -------
    list of int
        Indices into ``points`` of the hull's vertices, counter-clockwise from the first
        point; repeated points and points inside an edge are left out.

    Examples
    --------
    >>> monotone_chain([(0.0, 0.0), (0.0, 1.0), (0.5, 0.0), (0.5, 0.5), (1.0, 0.0), (1.0, 1.0)])
    [0, 4, 5, 1]
    """
    n = len(points)
    lower = _half_chain(points, range(n))
    upper = _half_chain(points, range(n - 1, -1, -1))
    return lower[:-1] + upper[:-1]  # each ends where the other starts


def _half_chain(points: Sequence[tuple[float, float]], order: range) -> list[int]:
    """One half of :func:`monotone_chain`: the points in ``order``, left turns only.

    Each point is pushed after popping the chain's last point while the last two and the
    new one do not turn strictly left (cross product ``<= 0``). The chain's points are kept
    beside their indices.
    """
    chain: list[tuple[float, float]] = []
    indices: list[int] = []
    for k in order:
        p = points[k]
        x, y = p
        while len(chain) >= 2:
            ax, ay = chain[-2]
            bx, by = chain[-1]
            if (bx - ax) * (y - ay) - (by - ay) * (x - ax) > 0:
                break
            chain.pop()
            indices.pop()
        chain.append(p)
        indices.append(k)
    return indices


def pruned_half_chain(
    xs: FloatArray, ys: FloatArray, idx: NDArray[np.intp], rounds: int = 64
) -> NDArray[np.intp] | None:
    """One half of the monotone chain by array operations: the points ``idx`` pruned.

    ``idx`` lists sorted points (left to right for the lower half, right to left for the
    upper). A point that does not turn strictly left between its two neighbours lies on or
    above the segment joining them (below, for the upper half), so it is no vertex of this
    half of the hull, and every such point can be removed at once. What is left when no
    point is removed, a chain from the first point to the last turning strictly left at
    every point, is the chain :func:`monotone_chain` builds. Usually a few rounds of O(N)
    each; ``None`` after ``rounds`` rounds (the caller then runs the reference).

    Repeated points are first reduced to the one the monotone chain keeps: the first of
    those equal to the starting point, the last of every other run.

    Examples
    --------
    >>> xs, ys = np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, -1.0, 0.5, 0.0])
    >>> pruned_half_chain(xs, ys, np.arange(4)).tolist()
    [0, 1, 3]
    """
    x, y = xs[idx], ys[idx]
    same = (x[1:] == x[:-1]) & (y[1:] == y[:-1])  # point i + 1 repeats point i
    if same.any():
        run0 = int(np.argmin(np.append(same, False)))  # points 1..run0 repeat the first
        drop = np.append(same, False)  # keep the last of a run ...
        drop[: run0 + 1] = False
        drop[1 : run0 + 1] = True  # ... but the first of the starting run
        idx = idx[~drop]
    for _ in range(rounds):
        if len(idx) < 3:
            return idx
        x, y = xs[idx], ys[idx]
        cross = (x[1:-1] - x[:-2]) * (y[2:] - y[:-2]) - (y[1:-1] - y[:-2]) * (x[2:] - x[:-2])
        bad = cross <= 0.0
        if not bad.any():
            return idx
        keep = np.ones(len(idx), dtype=bool)
        keep[1:-1] = ~bad
        idx = idx[keep]
    return None


def monotone_chain_vectorised(
    xs: FloatArray, ys: FloatArray, rounds: int = 64
) -> NDArray[np.intp] | None:
    """:func:`monotone_chain` of sorted points by array operations (large parts).

    The lower and the upper half by :func:`pruned_half_chain`; ``None`` when either takes
    more than ``rounds`` rounds.

    Examples
    --------
    >>> xs, ys = np.array([0.0, 0.0, 0.5, 0.5, 1.0, 1.0]), np.array([0.0, 1, 0, 0.5, 0, 1])
    >>> monotone_chain_vectorised(xs, ys).tolist()
    [0, 4, 5, 1]
    """
    idx = np.arange(len(xs))
    lower = pruned_half_chain(xs, ys, idx, rounds)
    upper = pruned_half_chain(xs, ys, idx[::-1], rounds)
    if lower is None or upper is None:
        return None
    return np.concatenate([lower[:-1], upper[:-1]])


def hull_indices(points: FloatArray) -> NDArray[np.intp]:
    """Indices of the convex hull's vertices, counter-clockwise, in O(N log N).

    Sorted by ``np.lexsort``; the chain by :func:`monotone_chain_vectorised`, or by the
    reference :func:`monotone_chain` when that gives up. Repeated points and points inside
    an edge are left out.

    Examples
    --------
    >>> hull_indices(np.array([[1.0, 1], [0, 0], [0.5, 0.5], [1, 0], [0, 1]])).tolist()
    [1, 3, 0, 4]
    """
    order = np.lexsort((points[:, 1], points[:, 0]))
    pts = points[order]
    xs, ys = pts[:, 0], pts[:, 1]
    chain = monotone_chain_vectorised(xs, ys)
    if chain is None:
        pairs = list(zip(xs.tolist(), ys.tolist(), strict=True))
        chain = np.array(monotone_chain(pairs), dtype=np.intp)
    return order[chain]


def drop_near_collinear(v: FloatArray, eps: float) -> FloatArray:
    """Drop hull vertices closer than ``eps`` to the segment joining their neighbours.

    Each round removes every other vertex of each run of such vertices, so a removed vertex
    always lies within ``eps`` of a chord whose ends stay: the error never accumulates.

    Examples
    --------
    >>> drop_near_collinear(np.array([[0.0, 0], [0.5, 1e-12], [1, 0], [1, 1], [0, 1]]), 1e-9)
    array([[0., 0.],
           [1., 0.],
           [1., 1.],
           [0., 1.]])
    """
    while len(v) > 3:
        prev = np.roll(v, 1, axis=0)
        base = np.roll(v, -1, axis=0) - prev
        blen = np.hypot(base[:, 0], base[:, 1])
        cross = base[:, 0] * (v[:, 1] - prev[:, 1]) - base[:, 1] * (v[:, 0] - prev[:, 0])
        bad = np.abs(cross) <= eps * blen  # (N,) within eps of the neighbours' chord
        if not bad.any():
            break
        idx = np.arange(len(v))
        run_start = np.maximum.accumulate(np.where(~bad, idx + 1, 0))
        drop = bad & ((idx - run_start) % 2 == 0)
        if drop[0] and drop[-1]:
            drop[-1] = False
        keep = ~drop
        if keep.sum() < 3:
            keep[np.flatnonzero(drop)[: 3 - keep.sum()]] = True
        v = v[keep]
    return v


def hull_of_few(
    ordered: list[tuple[float, float]], eps: float
) -> tuple[list[float], list[float], float, float, float]:
    """Hull, area and centroid of a few points, in plain Python floats.

    ``ordered``: the points sorted lexicographically (``sorted(zip(xs, ys))``, the order of
    ``np.lexsort``). The reference :func:`monotone_chain`, then :func:`drop_and_measure`:
    the steps of :func:`hull_indices`, :func:`drop_near_collinear` and
    :func:`polygon_area_centroid` with the same vertices (tests/geometry/test_hull.py holds
    the two together). Up to :data:`~bayesgrasp.sizes.SMALL` points the work is smaller
    than numpy's cost of a call.

    Returns
    -------
    xs, ys : list of float
        Hull vertices, counter-clockwise from the lexicographically least point.
    area, cx, cy : float
        Area and centroid (area 0 when degenerate).

    Examples
    --------
    >>> hull_of_few(sorted([(0.0, 0.0), (2.0, 0.0), (1.0, 0.5), (0.0, 1.0)]), 1e-12)
    ([0.0, 2.0, 0.0], [0.0, 0.0, 1.0], 1.0, 0.6666666666666666, 0.3333333333333333)
    """
    chain = monotone_chain(ordered)
    return drop_and_measure([ordered[i][0] for i in chain], [ordered[i][1] for i in chain], eps)


def drop_and_measure(
    xs: list[float], ys: list[float], eps: float
) -> tuple[list[float], list[float], float, float, float]:
    """:func:`drop_near_collinear` and :func:`polygon_area_centroid` of a hull, on floats.

    The same decisions, step for step, on Python floats (a few vertices). Returns the
    vertices kept, the area and the centroid (area 0 when degenerate).
    """
    hypot = math.hypot
    while len(xs) > 3:
        n = len(xs)
        bad = []  # within eps of the chord of the neighbours
        ax, ay = xs[-1], ys[-1]
        for x, y, bx, by in zip(xs, ys, [*xs[1:], xs[0]], [*ys[1:], ys[0]], strict=True):
            ux, uy = bx - ax, by - ay
            bad.append(abs(ux * (y - ay) - uy * (x - ax)) <= eps * hypot(ux, uy))
            ax, ay = x, y
        if True not in bad:
            break
        drop, run_start = [], 0  # every other vertex of each run of bad ones
        for i in range(n):
            if not bad[i]:
                run_start = i + 1
            drop.append(bad[i] and (i - run_start) % 2 == 0)
        if drop[0] and drop[-1]:
            drop[-1] = False
        kept = n - sum(drop)
        if kept < 3:
            for i in [i for i in range(n) if drop[i]][: 3 - kept]:
                drop[i] = False
        xs = [x for x, d in zip(xs, drop, strict=True) if not d]
        ys = [y for y, d in zip(ys, drop, strict=True) if not d]
    if len(xs) < 3:
        return xs, ys, 0.0, 0.0, 0.0
    # The shoelace sums about the first vertex, in units of the extent (as the array version).
    ox, oy = xs[0], ys[0]
    scale = max(max([abs(x - ox) for x in xs]), max([abs(y - oy) for y in ys]))
    if not 0.0 < scale < math.inf:
        return xs, ys, 0.0, 0.0, 0.0
    qx, qy = [(x - ox) / scale for x in xs], [(y - oy) / scale for y in ys]
    twice, cx, cy = 0.0, 0.0, 0.0
    for x0, y0, x1, y1 in zip(qx, qy, [*qx[1:], qx[0]], [*qy[1:], qy[0]], strict=True):
        c = x0 * y1 - x1 * y0
        twice += c
        cx += (x0 + x1) * c
        cy += (y0 + y1) * c
    if twice == 0.0:
        return xs, ys, 0.0, 0.0, 0.0
    unit = scale / (3.0 * twice)
    return xs, ys, 0.5 * twice * scale * scale, cx * unit + ox, cy * unit + oy


def largest_distance(points: Iterable[tuple[float, float]], cx: float, cy: float) -> float:
    """The largest distance of the points from ``(cx, cy)`` (a polygon's size).

    Examples
    --------
    >>> largest_distance([(0.0, 0.0), (3.0, 4.0)], 0.0, 0.0)
    5.0
    """
    top = 0.0
    for x, y in points:
        d = (x - cx) ** 2 + (y - cy) ** 2
        if d > top:
            top = d
    return math.sqrt(top)


def refuse_hull(pts: FloatArray, eps: float) -> NoReturn:
    """Refuse points with no hull: too few distinct points, or all collinear.

    Examples
    --------
    >>> refuse_hull(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), 1e-9)
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.PartError: the part's points are all collinear; a part needs a non-zero area
    """
    # Counting distinct points is slow (np.unique), so it is done only to word a refusal.
    distinct = 0
    if len(pts):
        grid = np.round((pts - pts.min(axis=0)) / max(eps, 1e-300))
        distinct = len(np.unique(grid, axis=0))
    if distinct < 3:
        raise PartError(
            f"a part needs at least 3 distinct points; got {len(pts)} point(s) "
            f"with {distinct} distinct"
        )
    raise PartError("the part's points are all collinear; a part needs a non-zero area")
