"""The exact convex hull of a curved outline (its support function), and exact curve patches.

See :mod:`bayesgrasp.geometry.curved`, "Convex hull": :class:`CurvedHull` and
:func:`curved_hull` (a Jarvis march over the sites: points and arcs), and
:class:`CurvePatches`, the curves that are not arcs kept exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import PartError
from ..tolerance import DEFAULT_TOLERANCE, Tolerance
from .curved_ring import CurvedRing
from .polygon import ConvexPolygon

__all__ = ["CurvePatches", "CurvedHull", "curved_hull"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

# Angles closer than this are the same crossing of two support functions (ties of the march).
_TIE = 1e-12


# --------------------------------------------------------------------------------------
# The exact convex hull


@dataclass(frozen=True, slots=True, eq=False)
class CurvedHull:
    """The convex hull of segments and arcs: vertices, straight edges and arcs.

    Piece ``k`` supports the normal directions ``[starts[k], starts[k + 1])`` (the last
    ends at ``starts[0] + 2 pi``): its supporting point is ``centers[k] + radii[k] u(phi)``
    (a vertex when ``radii[k] == 0``), so ``h(phi) = centers[k] . u(phi) + radii[k]``.
    Between piece ``k - 1`` and piece ``k`` runs a straight edge of length ``edges[k]`` (0
    where the two join smoothly), with outward normal ``starts[k]``.

    Attributes
    ----------
    starts : ndarray of shape (P,)
        Increasing, ``starts[0]`` in ``[0, 2 pi)``.
    centers : ndarray of shape (P, 2)
    radii : ndarray of shape (P,)
    edges : ndarray of shape (P,)
    size : float
        Largest distance of the hull from its area centroid (sets the length tolerance).
    tol : Tolerance
    chord_edges : ndarray of bool of shape (P,)
        Whether edge ``k`` is a chord of a flattened curve (not a flat of the part).
    approximate : ndarray of bool of shape (P,)
        Whether piece ``k`` is a point of a flattened curve (the true contact is nearby).

    Examples
    --------
    >>> slot = curved_hull(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1]))
    >>> int((slot.edges > 0).sum()), np.round(slot.edges.max(), 12)
    (2, np.float64(2.0))
    """

    starts: FloatArray
    centers: FloatArray
    radii: FloatArray
    edges: FloatArray
    size: float
    tol: Tolerance = DEFAULT_TOLERANCE
    chord_edges: NDArray[np.bool_] | None = None
    approximate: NDArray[np.bool_] | None = None

    @property
    def n_pieces(self) -> int:
        """Number of pieces (vertices and arcs) around the hull."""
        return len(self.starts)

    def piece_index(self, phi: ArrayLike) -> IntArray:
        """Index of the piece that supports each normal direction ``phi``."""
        t = np.mod(np.asarray(phi, dtype=np.float64) - self.starts[0], TWO_PI)
        k = np.searchsorted(self.starts - self.starts[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.starts) - 1), dtype=np.intp)

    def support(self, phi: ArrayLike) -> FloatArray:
        """``h(phi) = max over the outline of <x, u(phi)>``, exact (vectorised).

        Examples
        --------
        >>> disc = curved_hull(CurvedRing([(1, 0), (-1, 0)], [1.0, 1.0]))
        >>> np.round(disc.support([0.0, 1.0, 2.0]), 12).tolist()
        [1.0, 1.0, 1.0]
        """
        ph = np.asarray(phi, dtype=np.float64)
        k = self.piece_index(ph)
        c = self.centers[k]
        out: FloatArray = c[..., 0] * np.cos(ph) + c[..., 1] * np.sin(ph) + self.radii[k]
        return out

    def edge_ends(self, k: int) -> tuple[FloatArray, FloatArray]:
        """The two ends of the edge before piece ``k`` (counter-clockwise)."""
        phi = float(self.starts[k])
        u = np.array([math.cos(phi), math.sin(phi)])
        j = (k - 1) % len(self.starts)
        return self.centers[j] + self.radii[j] * u, self.centers[k] + self.radii[k] * u

    def boundary(self, tol: float | None = None) -> FloatArray:
        """Points around the hull, counter-clockwise, arcs sampled within ``tol``.

        ``tol`` defaults to ``1e-4`` times the size. Every point lies on the hull.
        """
        tol = 1e-4 * self.size if tol is None else tol
        out: list[FloatArray] = []
        ends = np.append(self.starts[1:], self.starts[0] + TWO_PI)
        for k in range(len(self.starts)):
            a, b, r = float(self.starts[k]), float(ends[k]), float(self.radii[k])
            if r == 0.0:
                out.append(self.centers[k][None, :])
                continue
            step = 2.0 * math.acos(max(-1.0, 1.0 - tol / r)) if tol < r else 1.0
            n = max(1, math.ceil((b - a) / max(step, 1e-6)))
            t = a + (b - a) * np.arange(n + 1) / n
            out.append(self.centers[k] + r * np.column_stack([np.cos(t), np.sin(t)]))
        pts = np.concatenate(out)
        keep = np.append(np.hypot(*np.diff(pts, axis=0).T) > 1e-12 * self.size, True)
        pts = pts[keep]
        if len(pts) > 1 and math.dist(pts[0], pts[-1]) <= 1e-12 * self.size:
            pts = pts[:-1]
        return np.asarray(pts, dtype=np.float64)

    def polygon(self, tol: float | None = None) -> ConvexPolygon:
        """The hull flattened to a convex polygon (points on the hull, within ``tol``)."""
        return ConvexPolygon.from_points(self.boundary(tol), self.tol)


def _sites(
    ring: CurvedRing,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, IntArray, IntArray]:
    """Support sites of an outline: its points, then its arcs.

    Returns centres (S, 2), radii (S,), the start ``lo`` and width ``w`` of each site's
    normal directions (vertices: all), and for arcs the site of their first and last point
    in the direction of increasing normal angle (-1 for vertices).
    """
    p = ring.points
    n = len(p)
    centers, radii, starts, sweeps, idx = ring.arcs()
    a = len(idx)
    lo = np.zeros(n + a)
    w = np.full(n + a, TWO_PI + 1.0)  # vertices: every direction
    first = np.full(n + a, -1, dtype=np.intp)
    last = np.full(n + a, -1, dtype=np.intp)
    # An arc's points have normals from its start angle through its sweep; as a set, from
    # min(start, start + sweep). Its first point in increasing normal angle is the piece's
    # start for a counter-clockwise arc, its end for a clockwise one.
    ccw = sweeps > 0
    lo[n:] = np.where(ccw, starts, starts + sweeps)
    w[n:] = np.abs(sweeps)
    nxt = (idx + 1) % n
    first[n:] = np.where(ccw, idx, nxt)
    last[n:] = np.where(ccw, nxt, idx)
    return (
        np.concatenate([p, centers]),
        np.concatenate([np.zeros(n), radii]),
        lo,
        w,
        first,
        last,
    )


def _prune(
    c: FloatArray, r: FloatArray, lo: FloatArray, w: FloatArray, n_points: int, ltol: float
) -> NDArray[np.bool_]:
    """Which sites may lie on the hull, from the convex hull of points on the outline.

    The polygon ``Q`` of the outline's points and of samples of its arcs (every ``_STEP``
    radians) lies inside the outline's hull. A point strictly inside ``Q`` is inside the
    hull, so it is dropped; so is an arc all of whose samples lie deeper inside ``Q`` than
    the arc can bulge between two samples (``r (1 - cos(_STEP / 2))``). What is left are the
    sites the march must consider (often a small fraction of a detailed outline).
    """
    keep = np.ones(len(c), dtype=bool)
    if len(c) < 48:
        return keep
    from scipy.spatial import ConvexHull, QhullError

    arcs = np.arange(n_points, len(c))
    counts = np.maximum(2, np.ceil(w[arcs] / _STEP).astype(np.intp) + 1)  # (A,)
    owner = np.repeat(arcs, counts)
    frac = (
        np.concatenate([np.linspace(0.0, 1.0, k) for k in counts.tolist()])
        if len(arcs)
        else np.zeros(0)
    )
    t = lo[owner] + w[owner] * frac
    samples = c[owner] + r[owner, None] * np.column_stack([np.cos(t), np.sin(t)])
    pts = np.concatenate([c[:n_points], samples])
    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError):
        return keep
    eq = hull.equations  # (F, 3): unit normal and offset, <n, x> + b <= 0 inside
    depth = -(pts @ eq[:, :2].T + eq[:, 2]).max(axis=1)  # (N,) distance inside Q
    keep[:n_points] = depth[:n_points] <= ltol
    if len(arcs):
        sag = r[arcs] * (1.0 - math.cos(0.5 * _STEP)) + ltol
        deepest_out = np.minimum.reduceat(depth[n_points:], np.cumsum(counts) - counts)
        keep[arcs] = deepest_out <= sag
    return keep


# Sampling step of arcs (radians) for pruning the sites.
_STEP = 0.2


def curved_hull(ring: CurvedRing, tol: Tolerance = DEFAULT_TOLERANCE) -> CurvedHull:
    """The exact convex hull of an outline of segments and arcs (see the module docstring).

    Parameters
    ----------
    ring : CurvedRing
    tol : Tolerance, optional

    Returns
    -------
    CurvedHull

    Raises
    ------
    PartError
        The outline has no area (all points collinear and no arc).

    Examples
    --------
    >>> rounded = CurvedRing([(1, 0), (3, 0), (4, 1), (4, 2), (3, 3), (1, 3), (0, 2), (0, 1)],
    ...                      [0, np.tan(np.pi / 8)] * 4)
    >>> h = curved_hull(rounded)
    >>> h.n_pieces, np.round(h.support([0.0, np.pi / 4]), 12).tolist()
    (4, [4.0, 4.535533905933])
    """
    c, r, lo, w, first, last = _sites(ring)
    n_points = len(ring.points)
    box = np.concatenate([c - r[:, None], c + r[:, None]])
    ltol = tol.length_for(float(np.max(np.ptp(box, axis=0))))
    keep = _prune(c, r, lo, w, n_points, ltol)
    sites = np.flatnonzero(keep)
    c, r, lo, w, first, last = c[sites], r[sites], lo[sites], w[sites], first[sites], last[sites]
    renum = np.full(len(keep), -1, dtype=np.intp)
    renum[sites] = np.arange(len(sites))
    first = np.where(first >= 0, renum[np.maximum(first, 0)], -1)
    last = np.where(last >= 0, renum[np.maximum(last, 0)], -1)
    is_arc = r > 0
    # Arcs that start at each point site: they take over there exactly at their `lo`.
    starts_at: dict[int, list[int]] = {}
    ends_at: dict[int, list[int]] = {}
    for j in np.flatnonzero(is_arc).tolist():
        starts_at.setdefault(int(first[j]), []).append(j)
        ends_at.setdefault(int(last[j]), []).append(j)

    def value(j: IntArray | int, phi: float) -> FloatArray:
        return np.asarray(c[j, 0] * math.cos(phi) + c[j, 1] * math.sin(phi) + r[j])

    def valid(j: IntArray, phi: FloatArray) -> NDArray[np.bool_]:
        return np.asarray(np.mod(phi - lo[j], TWO_PI) <= w[j] + _TIE)

    # Start: the site of largest support at phi = 0 (ties: the one that continues past 0).
    phi0 = 0.0
    vals = np.where(
        valid(np.arange(len(c)), np.zeros(len(c))), value(np.arange(len(c)), 0.0), -np.inf
    )
    top = float(vals.max())
    tied = np.flatnonzero(vals >= top - ltol)
    along = c[tied, 1] + r[tied] * 0.0  # the tangent at phi = 0 is +y
    k = int(tied[np.argmax(along)])
    pieces: list[tuple[int, float]] = [(k, phi0)]
    phi = phi0
    idx = np.arange(len(c))
    for _ in range(4 * len(c) + 8):
        # Where each site's support first rises above the current one's, after phi.
        g = c - c[k]
        dist = np.hypot(g[:, 0], g[:, 1])
        dr = r - r[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            x = -dr / dist
        ok = (dist > ltol) & (np.abs(x) < 1.0)
        cross = np.arctan2(g[:, 1], g[:, 0]) - np.arccos(np.clip(x, -1.0, 1.0))
        if not is_arc[k]:
            for j in starts_at.get(k, ()):
                cross[j], ok[j] = lo[j], True
            for j in ends_at.get(k, ()):
                ok[j] = False
        else:
            for j in (first[k], last[k]):
                if j >= 0:  # the arc's own ends (unless pruned) never take over inside it
                    ok[j] = False
        ok[k] = False
        delta = np.mod(cross - phi + _TIE, TWO_PI) - _TIE
        ok &= valid(idx, cross)
        room = np.inf
        if is_arc[k]:
            room = float(np.mod(lo[k] + w[k] - phi + _TIE, TWO_PI) - _TIE)
        ok &= delta <= room + _TIE
        if ok.any():
            cand = np.flatnonzero(ok)
            best = float(delta[cand].min())
            tie = cand[delta[cand] <= best + 1e2 * _TIE]
            at = phi + max(best, 0.0)
            t = np.array([-math.sin(at), math.cos(at)])
            reach = c[tie] @ t  # the farthest along the edge continues the hull
            nxt = int(tie[np.argmax(reach)])
        else:
            if not is_arc[k]:
                break  # a single vertex supports every direction: no area
            if last[k] < 0:  # pragma: no cover - an arc on the hull keeps its last end
                raise PartError("internal error: an arc's end was pruned from the hull")
            at, nxt = phi + max(room, 0.0), int(last[k])
        if at >= phi0 + TWO_PI - _TIE * 1e3:
            break
        pieces.append((nxt, at))
        k, phi = nxt, at
    else:  # pragma: no cover - a bug
        raise PartError("internal error: the convex hull of the outline does not close")
    return _finish(c, r, pieces, ltol, tol, ring, sites)


def _finish(
    c: FloatArray,
    r: FloatArray,
    pieces: list[tuple[int, float]],
    ltol: float,
    tol: Tolerance,
    ring: CurvedRing,
    orig: IntArray,
) -> CurvedHull:
    """Drop pieces of no angular width and measure the edges between the others."""
    site = np.array([s for s, _ in pieces], dtype=np.intp)
    starts = np.array([a for _, a in pieces])
    ends = np.append(starts[1:], starts[0] + TWO_PI)
    wide = ends - starts > 1e3 * _TIE
    if not wide.any():
        raise PartError("the part's outline has no area (a point or a segment)")
    site, starts = site[wide], starts[wide]
    # Merge consecutive pieces of the same site (a circle split into arcs).
    same = site == np.roll(site, 1)
    if len(site) > 1 and same.all():
        site, starts = site[:1], starts[:1]
    elif same.any():
        site, starts = site[~same], starts[~same]
    u = np.column_stack([np.cos(starts), np.sin(starts)])
    prev = np.roll(site, 1)
    jump = (c[site] + r[site, None] * u) - (c[prev] + r[prev, None] * u)
    edges = np.hypot(jump[:, 0], jump[:, 1])
    edges[edges <= ltol] = 0.0
    if len(site) == 1:
        edges[:] = 0.0
    shift = math.floor(starts[0] / TWO_PI) * TWO_PI
    starts = starts - shift
    centers, radii = c[site].copy(), r[site].copy()
    # Which pieces and edges come from flattened curves: ring point i of a chord piece.
    n = len(ring.points)
    chords = np.asarray(ring.chords, dtype=bool)
    point = orig[site]  # (P,) ring point of each piece (>= n: an arc)
    is_point = point < n
    approx = is_point & (
        chords[np.minimum(point, n - 1)] | chords[(np.minimum(point, n - 1) - 1) % n]
    )
    a, b = np.roll(point, 1), point
    forward = is_point & np.roll(is_point, 1) & (b == (a + 1) % n)
    backward = is_point & np.roll(is_point, 1) & (a == (b + 1) % n)
    chord_edges = (forward & chords[np.minimum(a, n - 1)]) | (
        backward & chords[np.minimum(b, n - 1)]
    )
    chord_edges &= edges > 0
    # Size: the largest distance of the hull from the middle of its box (the scale of the
    # length tolerance; within a factor of 2 of the distance from the area centroid).
    right = [float((centers[:, 0] + radii).max()), float((centers[:, 1] + radii).max())]
    left = [float((centers[:, 0] - radii).min()), float((centers[:, 1] - radii).min())]
    mid = 0.5 * (np.array(right) + np.array(left))
    size = float(np.max(np.hypot(*(centers - mid).T) + radii))
    for arr in (starts, centers, radii, edges, chord_edges, approx):
        arr.setflags(write=False)
    return CurvedHull(starts, centers, radii, edges, size, tol, chord_edges, approx)


# --------------------------------------------------------------------------------------
# Curves that are not arcs, kept exactly to place the extrema they carry


@dataclass(frozen=True, slots=True, eq=False)
class CurvePatches:
    """The outline's non-arc curves in exact form: cubic Bezier curves and elliptic arcs.

    The flattened outline is inscribed in them (its points lie on the curves), so the true
    support function is ``max(h_flat, h_patches)``. Used to place the extrema that the
    flattened chords only approximate (:func:`curved_diameter`).

    Attributes
    ----------
    bezier : ndarray of shape (B, 4, 2)
        Control points of cubic Bezier curves (quadratic ones raised to degree 3).
    ellipses : ndarray of shape (E, 8)
        ``cx, cy, Mx, My, mx, my, t0, span``: ``c + M cos t + m sin t`` over the span.
    complete : bool
        Whether every flattened curve is here (rational splines are not).
    """

    bezier: FloatArray
    ellipses: FloatArray
    complete: bool = True

    def points(self, tol: float) -> FloatArray:
        """Points on the curves, no farther than ``tol`` from them between samples.

        A cubic's chords are within ``h^2 / 8 max |B''|`` of it (``h`` the parameter step,
        ``|B''| <= 6 max |P_i - 2 P_{i+1} + P_{i+2}|``); an elliptic arc's within
        ``h^2 / 8`` times its major radius.
        """
        out = [np.zeros((0, 2))]
        for q in self.bezier:
            second = 6.0 * float(np.max(np.hypot(*(q[:-2] - 2 * q[1:-1] + q[2:]).T)))
            n = max(2, min(100_000, math.ceil(math.sqrt(second / (8.0 * tol)))))
            t = np.linspace(0.0, 1.0, n + 1)[:, None]
            out.append(
                (1 - t) ** 3 * q[0]
                + 3 * (1 - t) ** 2 * t * q[1]
                + 3 * (1 - t) * t**2 * q[2]
                + t**3 * q[3]
            )
        for cx, cy, mx, my, nx, ny, t0, span in self.ellipses:
            big = max(math.hypot(mx, my), math.hypot(nx, ny))
            n = max(2, min(100_000, math.ceil(abs(span) / math.sqrt(8.0 * tol / big))))
            t = t0 + span * np.linspace(0.0, 1.0, n + 1)
            out.append(
                np.column_stack(
                    [cx + mx * np.cos(t) + nx * np.sin(t), cy + my * np.cos(t) + ny * np.sin(t)]
                )
            )
        return np.concatenate(out)

    def support(self, phi: float) -> float:
        """``max over the curves of <x, u(phi)>`` (closed forms; -inf without curves)."""
        u = np.array([math.cos(phi), math.sin(phi)])
        best = -math.inf
        if len(self.bezier):
            p = self.bezier @ u  # (B, 4) projections of the control points
            a0, a1 = p[:, 0], 3.0 * (p[:, 1] - p[:, 0])
            a2 = 3.0 * (p[:, 2] - 2.0 * p[:, 1] + p[:, 0])
            a3 = p[:, 3] - 3.0 * p[:, 2] + 3.0 * p[:, 1] - p[:, 0]
            qa, qb, qc = 3.0 * a3, 2.0 * a2, a1  # f'(t) = qa t^2 + qb t + qc
            disc = np.maximum(qb * qb - 4.0 * qa * qc, 0.0)
            root = np.sqrt(disc)
            with np.errstate(divide="ignore", invalid="ignore"):
                flat = np.abs(qa) <= 1e-14 * (np.abs(qb) + np.abs(qc) + 1e-300)
                t1 = np.where(flat, -qc / np.where(qb == 0, 1.0, qb), (-qb + root) / (2 * qa))
                t2 = np.where(flat, 0.0, (-qb - root) / (2 * qa))
            ts = np.stack([np.zeros_like(a0), np.ones_like(a0), t1, t2], axis=1)
            ts = np.clip(np.nan_to_num(ts, nan=0.0, posinf=0.0, neginf=0.0), 0.0, 1.0)
            f = a0[:, None] + ts * (a1[:, None] + ts * (a2[:, None] + ts * a3[:, None]))
            best = max(best, float(f.max()))
        if len(self.ellipses):
            e = self.ellipses
            cu = e[:, 0] * u[0] + e[:, 1] * u[1]
            al, be = e[:, 2] * u[0] + e[:, 3] * u[1], e[:, 4] * u[0] + e[:, 5] * u[1]
            t0, span = e[:, 6], e[:, 7]
            star = np.arctan2(be, al)
            inside = np.mod((star - t0) * np.sign(span), TWO_PI) <= np.abs(span)
            ends = np.maximum(
                al * np.cos(t0) + be * np.sin(t0), al * np.cos(t0 + span) + be * np.sin(t0 + span)
            )
            f = cu + np.where(inside, np.hypot(al, be), ends)
            best = max(best, float(f.max()))
        return best
