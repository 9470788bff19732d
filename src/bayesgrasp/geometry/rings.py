"""Simple rings: the checks that make a user's outline a simple polygon with holes.

An outline (:meth:`~bayesgrasp.geometry.part.Part.from_outline`) must be a simple polygon:
no two edges cross or touch except consecutive edges at their shared vertex, and no vertex
folds back along its incoming edge. Holes must lie inside the outline, apart from it and
from each other. :func:`find_crossing` finds an offending pair of edges by a sweep (sort
and prune) with exact orientation tests; :func:`point_in_ring` is the even-odd rule.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PartError
from .coordinates import FloatArray, as_points

__all__ = ["clean_ring", "crossing_point", "find_crossing", "fold_back", "point_in_ring"]


def clean_ring(points: ArrayLike, what: str) -> FloatArray:
    """A ring as float64 (N, 2) without repeated consecutive vertices or closing vertex."""
    ring = as_points(points, what)
    if len(ring) > 1:
        ring = ring[~np.all(ring == np.roll(ring, -1, axis=0), axis=1)]
    if len(ring) < 3:
        raise PartError(f"`{what}` must have at least 3 distinct vertices; got {len(ring)}")
    return np.array(ring, dtype=np.float64)


def fold_back(ring: FloatArray) -> int | None:
    """Index of a vertex where the ring turns back along its incoming edge, if any."""
    u = ring - np.roll(ring, 1, axis=0)  # (N, 2) incoming edges
    w = np.roll(ring, -1, axis=0) - ring  # (N, 2) outgoing edges
    cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    dot = (u * w).sum(axis=1)
    scale = np.hypot(u[:, 0], u[:, 1]) * np.hypot(w[:, 0], w[:, 1])
    bad = np.flatnonzero((np.abs(cross) <= 1e-12 * scale) & (dot < 0))
    return int(bad[0]) if len(bad) else None


def point_in_ring(point: FloatArray, ring: FloatArray) -> bool:
    """Even-odd test: whether ``point`` lies inside the ring (vectorised over edges)."""
    x, y = float(point[0]), float(point[1])
    a, b = ring, np.roll(ring, -1, axis=0)
    straddle = (a[:, 1] > y) != (b[:, 1] > y)  # (N,) edges crossing the horizontal line
    dy = np.where(straddle, b[:, 1] - a[:, 1], 1.0)
    x_cross = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
    return bool(np.count_nonzero(straddle & (x < x_cross)) % 2)


def crossing_point(rings: Sequence[FloatArray], hit: tuple[int, int, int, int]) -> FloatArray:
    """A point where the two segments named by ``hit`` meet (for error messages)."""
    ra, sa, rb, sb = hit
    a0, a1 = rings[ra][sa], rings[ra][(sa + 1) % len(rings[ra])]
    b0, b1 = rings[rb][sb], rings[rb][(sb + 1) % len(rings[rb])]
    da, db = a1 - a0, b1 - b0
    denom = da[0] * db[1] - da[1] * db[0]
    if denom == 0.0:  # collinear overlap: any shared point will do
        for p in (b0, b1, a0, a1):
            if min(a0[0], a1[0]) <= p[0] <= max(a0[0], a1[0]) and min(a0[1], a1[1]) <= p[1] <= max(
                a0[1], a1[1]
            ):
                return np.asarray(p, dtype=np.float64)
        return np.asarray(a0, dtype=np.float64)  # pragma: no cover - not reached
    t = ((b0[0] - a0[0]) * db[1] - (b0[1] - a0[1]) * db[0]) / denom
    return np.asarray(a0 + t * da, dtype=np.float64)


_PAIR_CHUNK = 1 << 20  # candidate segment pairs examined per vectorised batch


def find_crossing(rings: Sequence[FloatArray]) -> tuple[int, int, int, int] | None:
    """Find two non-adjacent edges of a set of rings that cross or touch.

    A sweep along the axis where the edges are shortest pairs every edge with the edges whose
    intervals overlap it on that axis (sort and prune); the pairs are filtered on the other
    axis and settled by exact orientation tests, in vectorised batches. Typical outlines
    (short edges) give O(N log N) work; the worst case is O(N^2).

    Parameters
    ----------
    rings : sequence of ndarray of shape (N_k, 2)
        Closed rings without repeated closing vertex and without repeated vertices.

    Returns
    -------
    tuple of int or None
        ``(ring_a, edge_a, ring_b, edge_b)`` for one offending pair (edge ``i`` runs from
        vertex ``i`` to vertex ``i + 1``), or ``None`` when the rings are simple and disjoint.

    Examples
    --------
    >>> square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    >>> find_crossing([square]) is None
    True
    >>> find_crossing([np.array([[0.0, 0], [1, 1], [1, 0], [0, 1]])])
    (0, 0, 0, 2)
    """
    starts = np.concatenate(rings)  # (S, 2)
    ends = np.concatenate([np.roll(r, -1, axis=0) for r in rings])  # (S, 2)
    ring_id = np.concatenate([np.full(len(r), k, dtype=np.intp) for k, r in enumerate(rings)])
    edge_id = np.concatenate([np.arange(len(r), dtype=np.intp) for r in rings])
    ring_len = np.asarray([len(r) for r in rings], dtype=np.intp)[ring_id]
    lo = np.minimum(starts, ends)  # (S, 2) bounding boxes
    hi = np.maximum(starts, ends)
    axis = int(np.argmin((hi - lo).sum(axis=0)))
    other = 1 - axis
    order = np.argsort(lo[:, axis], kind="stable")
    lo_sorted = lo[order, axis]
    stop = np.searchsorted(lo_sorted, hi[order, axis], side="right")  # (S,)
    counts = stop - np.arange(len(order)) - 1  # partners after each edge in sweep order
    cum = np.cumsum(counts)
    row = 0
    n = len(order)
    while row < n:
        base = cum[row - 1] if row else 0
        last = int(np.searchsorted(cum, base + _PAIR_CHUNK, side="right"))
        last = max(last, row + 1)
        c = counts[row:last]
        total = int(c.sum())
        if total:
            i_sorted = np.repeat(np.arange(row, last), c)
            j_sorted = i_sorted + 1 + (np.arange(total) - np.repeat(np.cumsum(c) - c, c))
            a, b = order[i_sorted], order[j_sorted]
            keep = (lo[a, other] <= hi[b, other]) & (lo[b, other] <= hi[a, other])
            gap = np.abs(edge_id[a] - edge_id[b])
            adjacent = (ring_id[a] == ring_id[b]) & ((gap == 1) | (gap == ring_len[a] - 1))
            keep &= ~adjacent
            a, b = a[keep], b[keep]
            hits = _segments_meet(starts[a], ends[a], starts[b], ends[b])
            if hits.any():
                k = int(np.flatnonzero(hits)[0])
                pa, pb = sorted((int(a[k]), int(b[k])))
                return (int(ring_id[pa]), int(edge_id[pa]), int(ring_id[pb]), int(edge_id[pb]))
        row = last
    return None


def _segments_meet(p: FloatArray, q: FloatArray, r: FloatArray, s: FloatArray) -> NDArray[np.bool_]:
    """Whether segments pq and rs share a point, for boxes already known to overlap."""

    def orient(a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
        out: FloatArray = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (
            c[:, 0] - a[:, 0]
        )
        return out

    o1, o2 = orient(p, q, r), orient(p, q, s)
    o3, o4 = orient(r, s, p), orient(r, s, q)
    # With overlapping boxes, opposite (or zero) signs on both sides mean the segments meet,
    # including the collinear case (all four zero).
    return np.asarray(
        (np.sign(o1) * np.sign(o2) <= 0) & (np.sign(o3) * np.sign(o4) <= 0), dtype=np.bool_
    )
