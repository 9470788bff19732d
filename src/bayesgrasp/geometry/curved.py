"""Curved parts as they are: convex hulls of segments and circular arcs, kept exact.

The seed (section 4.2): "the analysis of grasp mechanics using the diameter function is not
limited to polygonal objects. Any two-dimensional object can be analyzed if we can compute
its diameter function." This module computes it exactly for outlines made of line segments
and circular arcs (DXF ARC, CIRCLE and bulges; SVG arcs and circles), and with a stated error
bound for outlines that also hold other curves (Bezier curves, splines, ellipses), which the
readers flatten to chords within a chordal tolerance ``eps``.

Outline (:class:`CurvedRing`): points ``P_0 .. P_{n-1}`` and one *bulge* per piece, the piece
from ``P_i`` to ``P_{i+1}``: ``b_i = tan(sweep_i / 4)``, 0 for a segment, positive for an
arc turning counter-clockwise (the DXF convention). Area and centroid are exact: the
shoelace polygon plus each arc's circular segment.

Convex hull (:class:`CurvedHull`). With ``u(phi) = (cos phi, sin phi)`` the support function
of the outline is ``h(phi) = max_k f_k(phi)`` over *sites*: every point ``P_i`` (``f =
P_i . u``) and every arc of centre ``c`` and radius ``r`` (``f = c . u + r``, only for the
directions ``phi`` of the arc's own points seen from its centre). ``f_j - f_k = D cos(phi -
psi) + (r_j - r_k)`` has one upward zero, ``phi = psi - acos((r_k - r_j) / D)``, so the upper
envelope is found by *wrapping*: from the site that supports direction ``phi``, the next is
the site whose upward crossing comes first (a Jarvis march over sites, O(n h)). The result
is a cyclic sequence of pieces (a vertex or an arc) over normal angles, with a straight
edge wherever the supporting point jumps (its length is the jump). ``h`` is exact on each
piece: ``c . u + r`` (``r = 0`` at a vertex).

Diameter (:class:`CurvedDiameter`). The gripper's squeeze axis seen from the part rotated by
``theta`` is ``u(-theta)``, so ``d(theta) = h(-theta) + h(pi - theta)``; between the angles
where either contact changes piece,

    d(theta) = g . (cos theta, -sin theta) + R = L cos(theta - phase) + R,

``g = c_a - c_b`` the chord between the two pieces' centres and ``R = r_a + r_b``. ``d`` is
smooth except at *edge alignments* (a straight edge parallel to the jaws), where its slope
jumps up by the length of the flush edges (a convex kink). Its local minima are the stable
orientations of a squeeze: flush edges (kinks with slopes - then +), and smooth minima at
``theta = phase + pi`` inside a piece (two arcs touching, e.g. an oval's minor axis); its
maxima, the basin boundaries, lie inside pieces at ``theta = phase`` (or at flat stretches:
``L = 0``, a jaw on each side of one circle, where the part is neutral; the boundary is
put at the middle of the stretch).

Certainty. If every point of the outline may be off by ``e`` (the flattening tolerance of
non-arc curves plus the user's shape tolerance), then ``h`` is off by at most ``e`` and
``d`` by at most ``delta = 2 e``. A local minimum of the true ``d`` is certain only if it lies
more than ``2 delta`` below both neighbouring maxima (persistence: the minimum can rise by
``delta`` and the maximum drop by ``delta``), so minimum/maximum pairs shallower than
``4 e`` (and than ``Tolerance.barrier`` times the size, as for polygons) are cancelled,
shallowest first. What is left are the states; a part without any (a disc, a regular
polygon flattened from a circle) cannot be oriented by squeezing and every plan is refused.
A state whose depth is less than :data:`SHALLOW` of its jaw opening is *shallow*: a small
shape error, friction or inertia may carry the part across it (reports warn).

Polygons (all bulges 0, no error) go through :mod:`.diameter` unchanged; this module only
takes over for parts with curves or a shape tolerance (:func:`squeeze_model`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import PartError, PlanningError
from ..tolerance import DEFAULT_TOLERANCE, Tolerance
from .diameter import DiameterFunction, diameter_function
from .polygon import ConvexPolygon, Part, as_points
from .push import RadiusFunction
from .transfer import TransferFunction, squeeze_function, transfer_from_extrema

__all__ = [
    "FLAT",
    "SHALLOW",
    "CurvePatches",
    "CurvedDiameter",
    "CurvedHull",
    "CurvedPart",
    "CurvedRadius",
    "CurvedRing",
    "Extremum",
    "RestingState",
    "curved_diameter",
    "curved_hull",
    "curved_part",
    "curved_push",
    "curved_push_grasp",
    "curved_radius",
    "mesh_vertices",
    "push_model",
    "resting_states",
    "squeeze_model",
    "with_shape_tol",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

#: A state is *shallow* when it lies less than this fraction of its jaw opening below the
#: lower of its two neighbouring maxima.
SHALLOW = 0.01

#: A state is *flat* when ``d`` stays within ``SHALLOW`` of its minimum over more than this
#: angle (radians, 5 degrees) around it.
FLAT = math.radians(5.0)

# Angles closer than this are the same crossing of two support functions (ties of the march).
_TIE = 1e-12

# Outline sizes whose areas and moments (squares and cubes of coordinates) are computed as
# they come; others are computed at unit size and scaled back.
_SAFE_SIZE = (1e-90, 1e90)

# Largest coordinate of a part's points (as for polygons), its arcs sampled.
_MAX_REACH = 1e150


# --------------------------------------------------------------------------------------
# Outlines of segments and arcs


@dataclass(frozen=True, slots=True, eq=False)
class CurvedRing:
    """A closed outline of segments and circular arcs, given by points and bulges.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        The ends of the pieces, in order, no repeated closing point.
    bulges : array_like of shape (N,)
        ``tan(sweep / 4)`` of the piece from point ``i`` to point ``i + 1`` (0: a segment;
        positive: an arc turning counter-clockwise; 1: a half circle).
    chords : array_like of bool of shape (N,), optional
        Which pieces are chords of a flattened curve (not straight edges of the part).

    Examples
    --------
    >>> disc = CurvedRing([(1, 0), (-1, 0)], [1.0, 1.0])  # two half circles
    >>> a, c = disc.area_centroid()
    >>> round(a, 12), np.round(c, 12).tolist()
    (3.14159265359, [0.0, 0.0])
    """

    points: FloatArray
    bulges: FloatArray
    chords: NDArray[np.bool_] | None = None

    def __post_init__(self) -> None:
        p = as_points(self.points, "points")
        b = np.asarray(self.bulges, dtype=np.float64).reshape(-1)
        ch = np.zeros(len(p), dtype=bool) if self.chords is None else np.asarray(self.chords, bool)
        if ch.shape != (len(p),):
            raise PartError(f"`chords` must have one value per point ({len(p)})")
        ch = ch.copy()
        ch.setflags(write=False)
        object.__setattr__(self, "chords", ch)
        if len(b) != len(p):
            raise PartError(f"`bulges` must have one value per point ({len(p)}); got {len(b)}")
        if not np.all(np.isfinite(b)):
            raise PartError("`bulges` must be finite")
        if len(p) < 2 or (len(p) == 2 and not np.any(b != 0)):
            raise PartError(f"a curved outline needs at least 3 points or arcs; got {len(p)}")
        step = np.roll(p, -1, axis=0) - p
        gaps = np.hypot(step[:, 0], step[:, 1])
        extent = float(np.max(np.ptp(p, axis=0)))
        if not extent > 1e-150 or float(np.max(np.abs(p))) > 1e150:
            raise PartError(
                f"the outline is {extent:g} across; it must be between 1e-150 and 1e150 "
                "(rescale the part's units)"
            )
        short = np.flatnonzero(gaps <= 1e-12 * extent)
        if len(short):
            i = int(short[0])
            raise PartError(f"`points` {i} and {(i + 1) % len(p)} of the outline coincide")
        p = p.copy()
        b = b.copy()
        p.setflags(write=False)
        b.setflags(write=False)
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "bulges", b)

    @property
    def n_arcs(self) -> int:
        """Number of arc pieces."""
        return int(np.count_nonzero(self.bulges))

    def arcs(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, IntArray]:
        """Centre, radius, start angle and signed sweep of each arc piece, and its index.

        Returns
        -------
        centers : ndarray of shape (A, 2)
        radii, starts, sweeps : ndarray of shape (A,)
            The arc runs from angle ``starts`` (about its centre) through ``sweeps``.
        index : ndarray of shape (A,)
            The piece (from point ``index`` to the next).
        """
        idx = np.flatnonzero(self.bulges)
        p = self.points[idx]
        q = np.roll(self.points, -1, axis=0)[idx]
        b = self.bulges[idx]
        chord = q - p
        length = np.hypot(chord[:, 0], chord[:, 1])
        left = np.column_stack([-chord[:, 1], chord[:, 0]]) / length[:, None]
        centers = 0.5 * (p + q) + left * (0.5 * length * (1.0 - b * b) / (2.0 * b))[:, None]
        sweeps = 4.0 * np.arctan(b)
        radii = 0.5 * length / np.abs(np.sin(0.5 * sweeps))
        starts = np.arctan2(p[:, 1] - centers[:, 1], p[:, 0] - centers[:, 0])
        return centers, radii, starts, sweeps, idx

    def area_centroid(self) -> tuple[float, FloatArray]:
        """Signed area (positive counter-clockwise) and area centroid, exact.

        The shoelace polygon of the points, plus for each arc the circular segment between
        its chord and the arc: area ``r^2 (a - sin a) / 2`` (``a`` the sweep), centroid at
        ``4 r sin^3(a / 2) / (3 (a - sin a))`` from the centre toward the arc.
        """
        p = self.points
        origin = p[0]
        rel = p - origin
        size = float(np.max(np.abs(rel)))
        if not _SAFE_SIZE[0] <= size <= _SAFE_SIZE[1] and size > 0.0:
            # Moments are cubes of coordinates: at unit size they neither overflow nor
            # underflow (outlines may reach 1e150 across, or be 1e-150 small).
            unit = CurvedRing(rel / size, self.bulges).area_centroid()
            return unit[0] * size * size, np.asarray(unit[1] * size + origin, dtype=np.float64)
        q = np.roll(rel, -1, axis=0)
        cross = rel[:, 0] * q[:, 1] - q[:, 0] * rel[:, 1]
        area = 0.5 * float(cross.sum())
        moment = ((rel + q) * cross[:, None]).sum(axis=0) / 6.0  # (2,) area times centroid
        if self.n_arcs:
            centers, radii, _, sweeps, idx = self.arcs()
            a = np.abs(sweeps)
            seg = np.sign(sweeps) * 0.5 * radii**2 * (a - np.sin(a))  # (A,) signed areas
            start, end = rel[idx], q[idx]
            chord = end - start
            length = np.hypot(chord[:, 0], chord[:, 1])
            right = np.column_stack([chord[:, 1], -chord[:, 0]]) / length[:, None]
            tip = 0.5 * (start + end) + right * (0.5 * self.bulges[idx] * length)[:, None]
            c = centers - origin
            toward = (tip - c) / radii[:, None]  # unit vector from the centre to the arc
            dist = 4.0 * radii * np.sin(0.5 * a) ** 3 / (3.0 * (a - np.sin(a)))
            area += float(seg.sum())
            moment = moment + ((c + toward * dist[:, None]) * seg[:, None]).sum(axis=0)
        if area == 0.0:
            return 0.0, p.mean(axis=0)
        return area, np.asarray(moment / area + origin, dtype=np.float64)

    def flattened(self, tol: float) -> FloatArray:
        """Points within ``tol`` of the outline (arcs sampled on the arc), in order."""
        if not self.n_arcs:
            return np.array(self.points, dtype=np.float64)
        centers, radii, starts, sweeps, idx = self.arcs()
        out: list[FloatArray] = []
        arc_of = {int(i): k for k, i in enumerate(idx.tolist())}
        for i in range(len(self.points)):
            out.append(self.points[i : i + 1])
            k = arc_of.get(i)
            if k is None:
                continue
            step = 2.0 * math.acos(max(-1.0, 1.0 - tol / radii[k])) if tol < radii[k] else 1.0
            n = max(2, math.ceil(abs(sweeps[k]) / max(step, 1e-6)))
            t = starts[k] + sweeps[k] * np.arange(1, n) / n
            out.append(centers[k] + radii[k] * np.column_stack([np.cos(t), np.sin(t)]))
        return np.concatenate(out)

    def reversed(self) -> CurvedRing:
        """The same outline run the other way."""
        p = self.points[::-1]
        b = -np.roll(self.bulges[::-1], -1)
        chords = np.asarray(self.chords, dtype=bool)
        return CurvedRing(p, b, np.roll(chords[::-1], -1))


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


# --------------------------------------------------------------------------------------
# The diameter function and its extrema


@dataclass(frozen=True, slots=True)
class Extremum:
    """A local extremum of ``d``: where, how wide the jaws are, and which kind."""

    theta: float
    value: float
    is_max: bool
    kink: bool  # at an edge alignment (a flush edge for a minimum)


@dataclass(frozen=True, slots=True, eq=False)
class CurvedDiameter:
    """The exact diameter function of a curved hull over ``[0, pi)``, and its extrema.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] + pi``);
    on it ``d(theta) = chords[k] . (cos theta, -sin theta) + offsets[k]``.

    Attributes
    ----------
    hull : CurvedHull
    breaks : ndarray of shape (B,)
    chords : ndarray of shape (B, 2)
    offsets : ndarray of shape (B,)
    extrema : tuple of Extremum
        Every local extremum of ``d`` over ``[0, pi)``, alternating, before the uncertain
        pairs are cancelled.
    minima, maxima : ndarray
        The certain ones (states and basin boundaries over ``[0, pi)``), alternating.
    error : float
        The bound on how far the outline may be from the true part (flattening and shape
        tolerance); ``d`` is within ``2 error`` of the true diameter function.
    depth : float
        Pairs shallower than this were cancelled (``4 error``, at least the barrier).

    Examples
    --------
    >>> slot = CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1])
    >>> d = curved_diameter(curved_hull(slot))
    >>> np.degrees(d.minima).round(9).tolist(), np.round(d([0.0, np.pi / 2]), 12).tolist()
    ([90.0], [4.0, 2.0])
    """

    hull: CurvedHull
    breaks: FloatArray
    chords: FloatArray
    offsets: FloatArray
    extrema: tuple[Extremum, ...]
    minima: FloatArray
    maxima: FloatArray
    error: float = 0.0
    depth: float = 0.0
    _kept: tuple[Extremum, ...] = field(default=(), repr=False)

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """``d(theta)``, vectorised."""
        th = self._representative(theta)
        k = self.piece_index(th)
        g = self.chords[k]
        out: FloatArray = g[..., 0] * np.cos(th) - g[..., 1] * np.sin(th) + self.offsets[k]
        return out

    def _representative(self, theta: ArrayLike) -> FloatArray:
        """The angle in ``[breaks[0], breaks[0] + pi)`` equal to ``theta`` mod pi.

        A piece's chord belongs to its own angles: a half turn swaps the contacts.
        """
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        return np.asarray(t + self.breaks[0], dtype=np.float64)

    def slope(self, theta: ArrayLike) -> FloatArray:
        """``d'(theta)`` (from the right at a kink)."""
        th = self._representative(theta)
        k = self.piece_index(th)
        g = self.chords[k]
        out: FloatArray = -g[..., 0] * np.sin(th) - g[..., 1] * np.cos(th)
        return out

    def piece_index(self, theta: ArrayLike) -> IntArray:
        """Index of the piece holding each angle."""
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        k = np.searchsorted(self.breaks - self.breaks[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.breaks) - 1), dtype=np.intp)

    @property
    def diameter(self) -> float:
        """The largest width of the part."""
        if self.maxima.size:
            return float(np.max(self(self.maxima)))
        return float(np.max(self(np.linspace(0.0, math.pi, 721))))

    @property
    def kept(self) -> tuple[Extremum, ...]:
        """The certain extrema over ``[0, pi)`` (minima and maxima, alternating)."""
        return self._kept


def _sub_pieces(hull: CurvedHull, tol: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Breaks of ``d`` in ``[0, pi)`` and each piece's chord and offset."""
    b = np.sort(np.mod(-hull.starts, math.pi))
    wide = np.diff(b, prepend=b[-1] - math.pi) > tol
    breaks = b[wide] if wide.any() else b[:1]
    ends = np.append(breaks[1:], breaks[0] + math.pi)
    mids = 0.5 * (breaks + ends)
    a = hull.piece_index(-mids)
    o = hull.piece_index(math.pi - mids)
    chords = hull.centers[a] - hull.centers[o]
    offsets = hull.radii[a] + hull.radii[o]
    return breaks, chords, offsets


_BOTH = (0.0, math.pi)  # the jaws' outward directions are u(jaw - theta): both jaws
_PUSHER = (math.pi,)  # the pushing jaw only (the radius function)


def _flush(hull: CurvedHull, theta: float, tol: float, jaws: tuple[float, ...] = _BOTH) -> float:
    """Total length of the edges parallel to the jaws at ``theta`` (0: a smooth point)."""
    total = 0.0
    for phi in (j - theta for j in jaws):
        k = int(hull.piece_index(phi + tol))
        if abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol:
            total += float(hull.edges[k])
    return total


def _extrema(
    breaks: FloatArray,
    chords: FloatArray,
    offsets: FloatArray,
    hull: CurvedHull,
    atol: float,
    period: float = math.pi,
    jaws: tuple[float, ...] = _BOTH,
) -> list[Extremum]:
    """Every local extremum of ``d`` over ``[0, pi)``, in order (see the module docstring).

    The same for the radius function (``period`` 2 pi, the pushing jaw only): any function
    ``chords[k] . (cos theta, -sin theta) + offsets[k]`` on pieces starting at ``breaks``.

    The slope of ``d`` is cut into runs of one sign: each piece is split at the zeros of
    its slope inside it; a run whose slope is within the length tolerance of zero is flat.
    Reading the runs around the circle without the flat ones, each change from - to + is a
    minimum and each change from + to - a maximum: at the junction of the two runs, or the
    middle of the flat stretch between them.
    """
    ltol = hull.tol.length_for(hull.size)
    ends = np.append(breaks[1:], breaks[0] + period)
    runs: list[tuple[float, float, int, bool]] = []  # start, end, sign, starts at a break
    for k in range(len(breaks)):
        s, e = float(breaks[k]), float(ends[k])
        gx, gy = float(chords[k, 0]), float(chords[k, 1])
        z0 = math.atan2(-gy, gx)  # the slope -gx sin - gy cos is zero at z0 + j pi
        zeros = sorted(
            z
            for j in range(-2, 4)
            if s + atol < (z := z0 + j * math.pi + math.floor(s / math.pi) * math.pi) < e - atol
        )
        cuts = [s, *zeros, e]
        for i in range(len(cuts) - 1):
            a, b = cuts[i], cuts[i + 1]
            m = 0.5 * (a + b)
            slope = -gx * math.sin(m) - gy * math.cos(m)
            sign = 0 if abs(slope) <= ltol else (1 if slope > 0 else -1)
            runs.append((a, b, sign, i == 0))
    signed = [i for i, run in enumerate(runs) if run[2] != 0]
    out: list[Extremum] = []
    if not signed:
        return out
    n = len(runs)
    for t, j in enumerate(signed):
        i = signed[t - 1]
        if runs[i][2] == runs[j][2]:
            continue
        lo = runs[i][1]
        hi = runs[j][0] if j > i else runs[j][0] + period
        if (j - i) % n == 1:
            at = lo
            kink = runs[j][3] and _flush(hull, lo, atol, jaws) > 0.0
        else:
            at = 0.5 * (lo + hi)
            kink = False
        at = at % period
        if period - at <= atol:  # the start of the period, not its end
            at = 0.0
        value = float(_evaluate(breaks, chords, offsets, at, period))
        out.append(Extremum(at, value, runs[i][2] > 0, kink))
    out.sort(key=lambda e: e.theta)
    return out


def _evaluate(
    breaks: FloatArray, chords: FloatArray, offsets: FloatArray, th: float, period: float
) -> float:
    t = (th - breaks[0]) % period
    k = int(np.clip(np.searchsorted(breaks - breaks[0], t, side="right") - 1, 0, len(breaks) - 1))
    th = t + float(breaks[0])  # a half turn swaps the contacts: use the piece's own angle
    return float(chords[k, 0] * math.cos(th) - chords[k, 1] * math.sin(th) + offsets[k])


def _cancel(
    ext: list[Extremum],
    depth: float,
    exact: Sequence[Extremum] = (),
    exact_depth: float = 0.0,
) -> list[Extremum]:
    """Cancel adjacent minimum/maximum pairs at most ``depth`` apart, shallowest first.

    A persistence simplification of a cyclic, alternating sequence: what remains are the
    extrema that a perturbation of ``d`` by less than ``depth / 2`` cannot remove. Unlike
    the polygons' barrier, nothing is kept when every pair is shallow (a disc).

    The minima in ``exact`` exist whatever the flattening did (see :func:`_exact_minima`): a
    pair holding one is cancelled only when at most ``exact_depth`` deep (the uncertainty
    that is really there: the shape tolerance and the barrier).
    """
    ext = list(ext)
    sure = {id(e) for e in exact}
    while len(ext) >= 2:
        best, at = math.inf, -1
        for i in range(len(ext)):
            gap = abs(ext[i].value - ext[i - 1].value)
            limit = exact_depth if (id(ext[i]) in sure or id(ext[i - 1]) in sure) else depth
            if gap <= limit and gap < best:
                best, at = gap, i
        if at < 0:
            break
        if len(ext) == 2:
            return []
        j = (at - 1) % len(ext)
        ext = [e for m, e in enumerate(ext) if m not in (at, j)]
    return ext


def _exact_support(hull: CurvedHull, patches: CurvePatches | None) -> Callable[[float], float]:
    """The true support function ``H = max(h_flat, h_patches)`` (the outline is inscribed)."""
    if patches is None or not (len(patches.bezier) or len(patches.ellipses)):
        return lambda phi: float(hull.support(phi))
    return lambda phi: max(float(hull.support(phi)), patches.support(phi))


def _exact_minima(
    hull: CurvedHull, ext: list[Extremum], patches: CurvePatches | None
) -> list[Extremum]:
    """The minima placed exactly: a straight edge of the part flush, and ``d`` falling to it.

    At such a kink the jaw on the edge is exact; the other jaw's contact is on the exact
    curves (``patches``), so the true ``d = H(-theta) + H(pi - theta)`` is known near it. The
    minimum is real when the true one-sided slopes are ``-`` and ``+`` (each beyond the
    rounding of a central difference), however shallow: flattening cannot remove it, only
    the shape tolerance can. Chords of flattened curves are never exact; nor is anything
    when some curve has no exact form (rational splines).
    """
    if hull.chord_edges is None or (patches is not None and not patches.complete):
        return []
    if patches is None and hull.approximate is not None and bool(np.any(hull.approximate)):
        return []
    support = _exact_support(hull, patches)
    tol = hull.tol.angle
    step = 1e-7
    margin = 1e-5 * hull.size  # slopes within this (per radian) count as flat

    def d(th: float) -> float:
        return support(-th) + support(math.pi - th)

    out = []
    for e in ext:
        if e.is_max or not e.kink:
            continue
        real = False
        for phi in (-e.theta, math.pi - e.theta):
            k = int(hull.piece_index(phi + tol))
            if abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol and hull.edges[k]:
                real = real or not bool(hull.chord_edges[k])
        if not real:
            continue
        at = d(e.theta)
        if (at - d(e.theta - step)) / step < -margin and (d(e.theta + step) - at) / step > margin:
            out.append(e)
    return out


def _needs_refining(hull: CurvedHull, e: Extremum, jaws: tuple[float, ...]) -> bool:
    """Whether an extremum lies where the model only approximates a curve."""
    if hull.approximate is None or hull.chord_edges is None:
        return False
    tol = hull.tol.angle
    for phi in (j - e.theta for j in jaws):
        k = int(hull.piece_index(phi + tol))
        at_start = abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol
        if at_start and hull.edges[k] > 0:
            if hull.chord_edges[k]:
                return True
            continue  # a straight edge of the part is flush: exact
        if hull.approximate[int(hull.piece_index(phi))]:
            return True
    return False


def _signed(f: Callable[[float], float], sign: float, t: float) -> float:
    return sign * f(t)


def _refined(
    hull: CurvedHull,
    kept: list[Extremum],
    patches: CurvePatches,
    period: float = math.pi,
    jaws: tuple[float, ...] = _BOTH,
    center: FloatArray | None = None,
    placed: Sequence[Extremum] = (),
) -> list[Extremum]:
    """The extrema that flattened curves carry, placed on the exact curves.

    The minima in ``placed`` (a straight edge flush) stay where they are; only their width
    is read on the exact curves.

    Each such extremum of the flattened model is searched again on the exact diameter
    ``d(theta) = H(-theta) + H(pi - theta)``, ``H = max(h_flat, h_curves)``, between the
    midpoints to its neighbours (bounded Brent): a smooth extremum of the true curve, to
    about 1e-8 rad, instead of a kink of a chord. For the radius function (the pushing jaw
    only, ``center`` the centre of mass): ``r(theta) = H(pi - theta) - center . u``.
    """
    from scipy.optimize import minimize_scalar

    c = np.zeros(2) if center is None else center

    def exact(th: float) -> float:
        total = 0.0
        for phi in (j - th for j in jaws):
            h = max(float(hull.support(phi)), patches.support(phi))
            total += h - (c[0] * math.cos(phi) + c[1] * math.sin(phi) if center is not None else 0)
        return total

    out = list(kept)
    m = len(kept)
    sure = {id(e) for e in placed}
    for i, e in enumerate(kept):
        if not _needs_refining(hull, e, jaws):
            continue
        if id(e) in sure:
            out[i] = Extremum(e.theta, exact(e.theta), False, True)
            continue
        if m > 1:
            before = (e.theta - kept[i - 1].theta) % period or period
            after = (kept[(i + 1) % m].theta - e.theta) % period or period
        else:
            before = after = period
        sign = -1.0 if e.is_max else 1.0
        res = minimize_scalar(
            functools.partial(_signed, exact, sign),
            bounds=(e.theta - 0.5 * before, e.theta + 0.5 * after),
            method="bounded",
            options={"xatol": 1e-12},
        )
        th = float(res.x) % period
        if period - th <= hull.tol.angle:  # the start of the period, not its end
            th = 0.0
        out[i] = Extremum(th, exact(th), e.is_max, False)
    out.sort(key=lambda e: e.theta)  # a refined extremum may have crossed 0
    return out


def curved_diameter(
    hull: CurvedHull,
    error: float = 0.0,
    patches: CurvePatches | None = None,
    shape_tol: float = 0.0,
) -> CurvedDiameter:
    """The diameter function of a curved hull, its extrema and the certain ones.

    Parameters
    ----------
    hull : CurvedHull
    error : float
        How far the outline may be from the true part, in its units: the flattening
        tolerance of non-arc curves plus a shape tolerance. Minimum/maximum pairs shallower
        than ``4 error`` (and than ``tol.barrier`` times the size) are not states.
    patches : CurvePatches, optional
        The flattened curves in exact form: the certain extrema they carry are placed on
        them (see :func:`_refined`).
    shape_tol : float
        The part of ``error`` that is the user's shape tolerance. A minimum where a straight
        edge of the part lies flush is placed exactly and, when the exact curves show the
        true ``d`` falling to it from both sides, it is real however shallow: only pairs
        shallower than ``4 shape_tol`` (and the barrier) remove it (:func:`_exact_minima`).

    Returns
    -------
    CurvedDiameter

    Examples
    --------
    >>> disc = curved_diameter(curved_hull(CurvedRing([(1, 0), (-1, 0)], [1.0, 1.0])))
    >>> disc.minima.size, float(disc(0.3))
    (0, 2.0)
    """
    atol = hull.tol.angle
    breaks, chords, offsets = _sub_pieces(hull, atol)
    ext = _extrema(breaks, chords, offsets, hull, atol)
    barrier = hull.tol.barrier_for(hull.size)
    depth = max(barrier, 4.0 * float(error))
    sure = _exact_minima(hull, ext, patches) if error > shape_tol else []
    kept = _cancel(ext, depth, sure, max(barrier, 4.0 * float(shape_tol)))
    if patches is not None and (len(patches.bezier) or len(patches.ellipses)):
        kept = _refined(hull, kept, patches, placed=sure)
    minima = np.array([e.theta for e in kept if not e.is_max], dtype=np.float64)
    maxima = np.array([e.theta for e in kept if e.is_max], dtype=np.float64)
    for arr in (breaks, chords, offsets, minima, maxima):
        arr.setflags(write=False)
    return CurvedDiameter(
        hull, breaks, chords, offsets, tuple(ext), minima, maxima, float(error), depth, tuple(kept)
    )


# --------------------------------------------------------------------------------------
# Parts


@dataclass(frozen=True, slots=True, eq=False)
class CurvedPart(Part):
    """A part whose outline has arcs or curves: the exact model beside the polygon.

    ``hull`` (a :class:`ConvexPolygon`) is the hull flattened for display, documents and
    simulation; the squeeze and push models use :attr:`curved_hull` and :attr:`ring`.

    Attributes
    ----------
    ring : CurvedRing
        The outline (counter-clockwise), arcs exact, other curves flattened.
    curve_error : float
        Distance within which the flattened non-arc curves follow the drawn ones (0 when
        the outline is made of segments and arcs only).
    shape_tol : float
        A manufacturing tolerance the user gives (``--shape-tol``): every point of the real
        part lies within it of the drawn outline.
    patches : CurvePatches or None
        The flattened curves in exact form (they place the extrema the curves carry).
    hole_rings : tuple of CurvedRing
        The holes with their arcs exact (counter-clockwise), for drawing.
    """

    ring: CurvedRing | None = None
    curve_error: float = 0.0
    shape_tol: float = 0.0
    patches: CurvePatches | None = None
    _model: dict[str, object] = field(default_factory=dict, repr=False)
    hole_rings: tuple[CurvedRing, ...] = ()

    def scaled(self, factor: float, units: str) -> Part:
        """Refused: the exact curves are not converted (save the drawing in ``units``)."""
        raise PartError(
            f"part {self.name!r} is curved and in {self.units}: save the drawing in {units} "
            "(its exact curves are not converted)"
        )

    @property
    def error(self) -> float:
        """The bound on the distance between the model and the real outline."""
        return self.curve_error + self.shape_tol

    @property
    def curved_hull(self) -> CurvedHull:
        """The exact convex hull (computed once)."""
        if "hull" not in self._model:
            if self.ring is None:  # pragma: no cover - built by curved_part
                raise PartError("a curved part needs its `ring`")
            self._model["hull"] = curved_hull(self.ring, self.hull.tol)
        return self._model["hull"]  # type: ignore[return-value]

    @property
    def diameter_function(self) -> CurvedDiameter:
        """The exact diameter function with the certain extrema (computed once)."""
        if "diameter" not in self._model:
            self._model["diameter"] = curved_diameter(
                self.curved_hull, self.error, self.patches, self.shape_tol
            )
        return self._model["diameter"]  # type: ignore[return-value]


def curved_part(
    ring: CurvedRing,
    holes: Sequence[CurvedRing] = (),
    name: str = "part",
    units: str | None = None,
    curve_error: float = 0.0,
    shape_tol: float = 0.0,
    tol: Tolerance = DEFAULT_TOLERANCE,
    display_tol: float | None = None,
    patches: CurvePatches | None = None,
) -> CurvedPart:
    """A part from an outline of segments and arcs (and holes), exact centre of mass.

    The centre of mass is the area centroid of the outline minus the holes, with every arc
    exact. The polygon ``hull`` (display, documents, simulation) is the exact hull sampled
    within ``display_tol`` (default ``1e-3`` of the size).

    Examples
    --------
    >>> p = curved_part(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1]), name="slot")
    >>> np.round(p.center_of_mass, 12).tolist(), p.diameter_function.minima.size
    ([1.0, 0.0], 1)
    """
    a0, c0 = ring.area_centroid()
    if a0 < 0:
        ring = ring.reversed()
        a0, c0 = -a0, c0
    # The holes' areas as fractions of the outline's: their moments relative to it, so
    # that the products stay within range for outlines up to 1e150 across.
    scale = a0 if a0 > 0 and not _SAFE_SIZE[0] ** 2 <= a0 <= _SAFE_SIZE[1] ** 2 else 1.0
    area, moment = a0 / scale, a0 / scale * c0
    oriented = []
    for h in holes:
        a, c = h.area_centroid()
        area -= abs(a) / scale
        moment = moment - abs(a) / scale * c
        oriented.append(h if a > 0 else h.reversed())
    if not area > 0:
        area *= scale
        raise PartError(f"`outline` must enclose a non-zero area; got area {area:.6g}")
    com = moment / area
    hull = curved_hull(ring, tol)
    step = 1e-3 * hull.size if display_tol is None else display_tol
    outline, around = ring.flattened(step), hull.boundary(step)
    reach = max(float(np.max(np.abs(outline))), float(np.max(np.abs(around))))
    if reach > _MAX_REACH:  # an arc reaching (or sampled) past the limit its points keep
        raise PartError(
            f"`outline` reaches {reach:.17g} in absolute value along its arcs; the limit is "
            f"{_MAX_REACH:g} (rescale the part's units)"
        )
    sampled = ConvexPolygon.from_points(around, hull.tol)
    base = Part.from_outline(
        outline,
        [h.flattened(step) for h in oriented],
        name=name,
        center_of_mass=com,
        units=units,
        tol=tol,
    )
    part = CurvedPart(
        base.name,
        sampled,
        base.outline,
        base.center_of_mass,
        base.units,
        base.holes,
        ring,
        float(curve_error),
        float(shape_tol),
        patches,
        hole_rings=tuple(oriented),
    )
    part._model["hull"] = hull
    return part


def with_shape_tol(part: Part, shape_tol: float) -> Part:
    """The part with a manufacturing tolerance: minima it could lose are not states.

    A polygon becomes a :class:`CurvedPart` of straight pieces (the same hull and centre
    of mass) so that the tolerance can apply. ``shape_tol`` 0 returns the part unchanged.

    Raises
    ------
    PartError
        ``shape_tol`` is negative or not finite.
    """
    if isinstance(shape_tol, bool) or not math.isfinite(shape_tol) or shape_tol < 0:
        raise PartError(f"`shape_tol` must be a finite number >= 0; got {shape_tol!r}")
    if shape_tol == 0:
        return part
    if isinstance(part, CurvedPart):
        out = replace(part, shape_tol=float(shape_tol), _model={})
        return out
    ring = CurvedRing(part.outline, np.zeros(len(part.outline)))
    return CurvedPart(
        part.name,
        part.hull,
        part.outline,
        part.center_of_mass,
        part.units,
        part.holes,
        ring,
        0.0,
        float(shape_tol),
    )


# --------------------------------------------------------------------------------------
# What the squeeze sees: states, and what the part rests on


@dataclass(frozen=True, slots=True)
class RestingState:
    """How the part lies at a stable orientation over ``[0, pi)``.

    Attributes
    ----------
    theta : float
        The stable orientation (radians).
    width : float
        The jaw opening there.
    depth : float
        How far ``d`` rises to the lower of the neighbouring maxima.
    edges : tuple of tuple of ndarray
        The straight edges flush with a jaw (their two ends), empty for a smooth minimum.
    shallow : bool
        ``depth < SHALLOW * width``.
    flat : tuple of float
        ``(lo, hi)``: the stretch of the basin around ``theta`` where ``d`` stays within
        ``SHALLOW`` of ``width``. A squeeze turns the part there with so little torque that
        support friction may stop it anywhere in the stretch: when it is wider than
        :data:`FLAT` the final orientation is only known to lie in it.
    """

    theta: float
    width: float
    depth: float
    edges: tuple[tuple[FloatArray, FloatArray], ...]
    shallow: bool
    flat: tuple[float, float] = (0.0, 0.0)

    @property
    def is_flat(self) -> bool:
        """Whether the flat stretch is wider than :data:`FLAT`."""
        return self.flat[1] - self.flat[0] > FLAT


def resting_states(d: CurvedDiameter) -> list[RestingState]:
    """The certain minima over ``[0, pi)`` with their flush edges and depths.

    Examples
    --------
    >>> slot = CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1])
    >>> [(round(float(np.degrees(s.theta)), 6), len(s.edges)) for s in
    ...  resting_states(curved_diameter(curved_hull(slot)))]
    [(90.0, 2)]
    """
    kept = list(d.kept)
    out: list[RestingState] = []
    hull = d.hull
    tol = hull.tol.angle
    for i, e in enumerate(kept):
        if e.is_max:
            continue
        lo, hi = kept[i - 1].value, kept[(i + 1) % len(kept)].value
        depth = min(lo, hi) - e.value
        edges = []
        for phi in (-e.theta, math.pi - e.theta):
            k = int(hull.piece_index(phi + tol))
            if abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol and hull.edges[k]:
                edges.append(hull.edge_ends(k))
        a = kept[i - 1].theta if len(kept) > 1 else e.theta - math.pi / 2
        b = kept[(i + 1) % len(kept)].theta if len(kept) > 1 else e.theta + math.pi / 2
        lo = e.theta - ((e.theta - a) % math.pi or math.pi)
        hi = e.theta + ((b - e.theta) % math.pi or math.pi)
        grid = np.linspace(lo, hi, 2001)
        low = d(grid) <= e.value * (1.0 + SHALLOW)
        at = int(np.argmin(np.abs(grid - e.theta)))
        left = at - int(np.argmin(low[at::-1])) if not low[at::-1].all() else 0
        right = at + int(np.argmin(low[at:])) if not low[at:].all() else len(grid) - 1
        flat = (float(grid[max(left, 0)]), float(grid[min(right, len(grid) - 1)]))
        out.append(
            RestingState(e.theta, e.value, depth, tuple(edges), depth < SHALLOW * e.value, flat)
        )
    return out


def squeeze_model(part: Part) -> tuple[DiameterFunction | CurvedDiameter, TransferFunction]:
    """The diameter function and the squeeze function of any part.

    A polygon (a plain :class:`Part`) gets those of :mod:`.diameter` and :mod:`.transfer`,
    unchanged; a :class:`CurvedPart` the exact curved ones (states: the certain minima).

    Raises
    ------
    PlanningError
        The part has no certain stable orientation (a disc, or every minimum within the
        error bound): a squeeze cannot orient it.
    """
    if not isinstance(part, CurvedPart):
        d = diameter_function(part.hull)
        return d, squeeze_function(d)
    cd = part.diameter_function
    if cd.minima.size == 0:
        raise PlanningError(_no_state_reason(part, cd))
    mins = np.concatenate([cd.minima, cd.minima + math.pi])
    maxs = np.concatenate([cd.maxima, cd.maxima + math.pi])
    angle = part.hull.tol.angle
    return cd, transfer_from_extrema("squeeze", mins, maxs, angle, angle)


def _no_state_reason(part: CurvedPart, d: CurvedDiameter) -> str:
    """Why a part has no stable orientation (one line)."""
    grid = d(np.linspace(0.0, math.pi, 4097))
    spread = float(grid.max() - grid.min())
    units = f" {part.units}" if part.units else ""
    if spread <= d.hull.tol.length_for(d.hull.size) * 10:
        return (
            f"part {part.name!r} has no stable orientation: its width is the same "
            f"({float(grid.mean()):.6g}{units}) at every orientation (a disc), so a squeeze "
            "leaves it where it is and no plan can orient it"
        )
    return (
        f"part {part.name!r} has no stable orientation that is certain: its width varies by "
        f"{spread:.3g}{units}, no more than the error bound allows "
        f"(4 x {d.error:.3g}{units}: flattening and --shape-tol), so no plan can orient it"
    )


def mesh_vertices(part: Part, fine: float = 1e-4) -> FloatArray:
    """Hull vertices for a simulation: a curved part's arcs within ``fine`` times its size.

    A polygon's own hull vertices; for a :class:`CurvedPart` the exact hull sampled so
    finely that no chord is a facet the part could rest on in the engine.
    """
    if isinstance(part, CurvedPart):
        hull = part.curved_hull
        tol = fine * hull.size
        pts = [hull.boundary(tol)]
        if part.patches is not None:
            pts.append(part.patches.points(tol))
        return ConvexPolygon.from_points(np.concatenate(pts), hull.tol).vertices
    return np.asarray(part.hull.vertices, dtype=np.float64)


# --------------------------------------------------------------------------------------
# Pushing: the radius function about the centre of mass


@dataclass(frozen=True, slots=True, eq=False)
class CurvedRadius:
    """The exact radius function of a curved part over ``[0, 2 pi)``, and its extrema.

    ``r(theta) = h(pi - theta) - c . u(pi - theta)`` (``c`` the centre of mass; Mason 1986,
    Goldberg 1993 section 5): on each piece ``chords[k] . (cos theta, -sin theta) +
    offsets[k]`` with ``chords = c - centre`` of the touching vertex or arc. Minima are
    stable pushes (an edge flush with the pushing jaw whose foot of the perpendicular from
    ``c`` lies inside it, or a smooth minimum on an arc: a disc rolls its centre of mass
    down), maxima the unstable equilibria; pairs shallower than ``2 error`` (``r`` is off by
    at most ``error``) are cancelled.
    """

    breaks: FloatArray
    chords: FloatArray
    offsets: FloatArray
    minima: FloatArray
    maxima: FloatArray
    center_of_mass: FloatArray

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """``r(theta)``, vectorised."""
        th = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], TWO_PI)
        k = np.clip(np.searchsorted(self.breaks - self.breaks[0], th, side="right") - 1, 0, None)
        th = th + self.breaks[0]
        g = self.chords[k]
        out: FloatArray = g[..., 0] * np.cos(th) - g[..., 1] * np.sin(th) + self.offsets[k]
        return out


def curved_radius(part: CurvedPart) -> CurvedRadius:
    """The radius function of a curved part about its centre of mass (see CurvedRadius).

    Examples
    --------
    >>> slot = curved_part(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1]))
    >>> np.degrees(curved_radius(slot).minima).round(6).tolist()
    [90.0, 270.0]
    """
    if "radius" in part._model:
        return part._model["radius"]  # type: ignore[return-value]
    hull = part.curved_hull
    com = np.asarray(part.center_of_mass, dtype=np.float64)
    atol = hull.tol.angle
    b = np.sort(np.mod(math.pi - hull.starts, TWO_PI))
    wide = np.diff(b, prepend=b[-1] - TWO_PI) > atol
    breaks = b[wide] if wide.any() else b[:1]
    ends = np.append(breaks[1:], breaks[0] + TWO_PI)
    k = hull.piece_index(math.pi - 0.5 * (breaks + ends))
    chords = com - hull.centers[k]
    offsets = np.array(hull.radii[k], dtype=np.float64)
    ext = _extrema(breaks, chords, offsets, hull, atol, TWO_PI, _PUSHER)
    depth = max(hull.tol.barrier_for(hull.size), 2.0 * part.error)
    kept = _cancel(ext, depth)
    patches = part.patches
    if patches is not None and (len(patches.bezier) or len(patches.ellipses)):
        kept = _refined(hull, kept, patches, TWO_PI, _PUSHER, com)
    if not kept:
        raise PlanningError(
            f"part {part.name!r} has no stable orientation under a push: its radius about the "
            "centre of mass varies by no more than the error bound allows"
        )
    minima = np.array(sorted(e.theta for e in kept if not e.is_max), dtype=np.float64)
    maxima = np.array(sorted(e.theta for e in kept if e.is_max), dtype=np.float64)
    out = CurvedRadius(breaks, chords, offsets, minima, maxima, com)
    part._model["radius"] = out
    return out


def curved_push(part: CurvedPart) -> TransferFunction:
    """The push function of a curved part: descend its exact radius function."""
    r = curved_radius(part)
    angle = part.hull.tol.angle
    return transfer_from_extrema("push", r.minima, r.maxima, angle, angle)


def curved_push_grasp(
    part: CurvedPart, squeeze: TransferFunction | None = None
) -> TransferFunction:
    """The push-grasp function ``s o p`` of a curved part (its exact push and squeeze)."""
    from .push import compose_push_grasp

    s = squeeze if squeeze is not None else squeeze_model(part)[1]
    r = curved_radius(part)
    return compose_push_grasp(r.minima, r.maxima, s, part.hull.tol.angle)


def push_model(part: Part) -> tuple[RadiusFunction, TransferFunction, TransferFunction]:
    """The radius function of the hull polygon, the push and the push-grasp function.

    A polygon's as :mod:`.push` builds them; a :class:`CurvedPart`'s push and push-grasp
    functions are the exact curved ones (the polygon's radius function then only names the
    nearest hull edges in reports).
    """
    from .push import push_function, push_grasp_function, radius_function

    r = radius_function(part)
    if isinstance(part, CurvedPart):
        return r, curved_push(part), curved_push_grasp(part)
    return r, push_function(r), push_grasp_function(part)
