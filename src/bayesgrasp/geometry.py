"""Planar parts: the convex polygon the gripper sees, and the part the user gave.

A frictionless parallel-jaw gripper only ever touches the convex hull of a part (the seed,
section 4.1, assumption 3, and Appendix A: "the diameter function for C is equal to the
diameter function for the convex hull of C"), so every transfer function is built from a
:class:`ConvexPolygon`. The :class:`Part` keeps the user's outline, name, units and centre of
mass beside the hull; the centre of mass matters for pushing (Goldberg 1993).

The library never rotates the user's coordinates: an orientation ``theta`` is always the
rotation of the part *as given* relative to the gripper frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import PartError
from .tolerance import DEFAULT_TOLERANCE, Tolerance

__all__ = ["ConvexPolygon", "Part", "as_points", "polygon_area_centroid"]

FloatArray = NDArray[np.float64]


def as_points(points: ArrayLike, what: str = "vertices") -> FloatArray:
    """Validate a point list and return it as a float64 array of shape (N, 2).

    Parameters
    ----------
    points : array_like of shape (N, 2)
        Coordinates; must be finite numbers.
    what : str
        Name used in error messages.

    Returns
    -------
    ndarray of shape (N, 2)

    Raises
    ------
    PartError
        If the input is not numeric, has the wrong shape, or holds NaN or infinite values.

    Examples
    --------
    >>> as_points([(0, 0), (1, 0), (0, 1)]).shape
    (3, 2)
    """
    try:
        arr = np.array(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise PartError(
            f"`{what}` must be numbers of shape (N, 2); could not read them: {exc}"
        ) from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise PartError(f"`{what}` must have shape (N, 2); got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.argwhere(~np.isfinite(arr))[0, 0])
        raise PartError(f"`{what}` must be finite; point {bad} is {arr[bad].tolist()}")
    return arr


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
    # Shift to the first vertex: keeps the cross products well conditioned far from the origin.
    origin = vertices[0]
    p = vertices - origin
    q = np.roll(p, -1, axis=0)
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]  # (N,)
    area = 0.5 * float(cross.sum())
    if area == 0.0:
        return 0.0, vertices.mean(axis=0)
    centroid = ((p + q) * cross[:, None]).sum(axis=0) / (6.0 * area)
    return area, centroid + origin


def _hull_indices(points: FloatArray) -> NDArray[np.intp]:
    """Counter-clockwise convex hull vertex indices (Andrew's monotone chain, vectorised sort).

    Collinear points on the hull are dropped. Runs in O(N log N).
    """
    order = np.lexsort((points[:, 1], points[:, 0]))
    pts = points[order]

    def half(idx: NDArray[np.intp]) -> list[int]:
        chain: list[int] = []
        xs = pts[:, 0].tolist()
        ys = pts[:, 1].tolist()
        for k in idx.tolist():
            while len(chain) >= 2:
                a, b = chain[-2], chain[-1]
                cross = (xs[b] - xs[a]) * (ys[k] - ys[a]) - (ys[b] - ys[a]) * (xs[k] - xs[a])
                if cross > 0:
                    break
                chain.pop()
            chain.append(k)
        return chain

    n = len(pts)
    lower = half(np.arange(n))
    upper = half(np.arange(n - 1, -1, -1))
    return order[np.array(lower[:-1] + upper[:-1], dtype=np.intp)]


def _drop_near_collinear(v: FloatArray, eps: float) -> FloatArray:
    """Drop hull vertices closer than ``eps`` to the segment joining their neighbours.

    Each round removes every other vertex of each run of such vertices, so a removed vertex
    always lies within ``eps`` of a chord whose ends stay: the error never accumulates.
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


@dataclass(frozen=True, slots=True, eq=False)
class ConvexPolygon:
    """Convex polygon, vertices counter-clockwise, no repeated closing vertex.

    Build it with :meth:`from_points`, which takes the convex hull of any point list.
    The vertices array is read-only.

    Attributes
    ----------
    vertices : ndarray of shape (N, 2)
        Counter-clockwise hull vertices in the user's coordinates (never rotated).
    tol : Tolerance
        The tolerances used for this polygon.

    Examples
    --------
    >>> ConvexPolygon.from_points([(0, 0), (2, 0), (0, 1), (0.5, 0.2)]).n_sides
    3
    """

    vertices: FloatArray
    tol: Tolerance = DEFAULT_TOLERANCE
    area: float = field(init=False)
    centroid: FloatArray = field(init=False)
    size: float = field(init=False)

    def __post_init__(self) -> None:
        v = as_points(self.vertices)
        area, centroid = polygon_area_centroid(v)
        if len(v) < 3 or area <= 0:
            raise PartError("`vertices` must be a counter-clockwise convex polygon")
        v.setflags(write=False)
        centroid.setflags(write=False)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "area", area)
        object.__setattr__(self, "centroid", centroid)
        object.__setattr__(self, "size", float(np.max(np.hypot(*(v - centroid).T))))

    @classmethod
    def from_points(cls, points: ArrayLike, tol: Tolerance = DEFAULT_TOLERANCE) -> ConvexPolygon:
        """Convex hull of a point list, counter-clockwise, duplicates and collinear points dropped.

        Parameters
        ----------
        points : array_like of shape (N, 2)
            At least 3 distinct points, not all collinear. Order does not matter.
        tol : Tolerance, optional
            Points closer than ``tol.length`` times the part's size are merged.

        Returns
        -------
        ConvexPolygon

        Raises
        ------
        PartError
            Fewer than 3 distinct points, all points collinear, or bad coordinates.

        Examples
        --------
        >>> sq = ConvexPolygon.from_points([(1, 1), (0, 0), (1, 0), (0, 1), (0.5, 0)])
        >>> sq.vertices.tolist()
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        """
        pts = as_points(points)
        extent = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
        eps = tol.length_for(extent)
        if len(pts) >= 1:
            distinct = np.unique(np.round((pts - pts.min(axis=0)) / max(eps, 1e-300)), axis=0)
        if len(pts) < 3 or extent == 0.0 or len(distinct) < 3:
            raise PartError(
                f"a part needs at least 3 distinct points; got {len(pts)} point(s) "
                f"with {len(distinct) if len(pts) else 0} distinct"
            )
        hull = pts[_hull_indices(pts)]
        hull = _drop_near_collinear(hull, eps) if len(hull) >= 3 else hull
        if len(hull) < 3 or polygon_area_centroid(hull)[0] <= eps * extent:
            raise PartError("the part's points are all collinear; a part needs a non-zero area")
        return cls(hull, tol)

    @property
    def n_sides(self) -> int:
        """Number of sides (equal to the number of vertices)."""
        return len(self.vertices)

    def rotated(self, angle: float) -> ConvexPolygon:
        """The polygon rotated counter-clockwise by ``angle`` about the origin.

        Used to place the part in a gripper frame; the user's part is never changed.

        Examples
        --------
        >>> sq = ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> np.round(sq.rotated(np.pi / 2).vertices, 12).tolist()[1]
        [0.0, 1.0]
        """
        c, s = math.cos(angle), math.sin(angle)
        rot = np.array([[c, -s], [s, c]])
        return ConvexPolygon(self.vertices @ rot.T, self.tol)

    @property
    def symmetry_order(self) -> int:
        """Order r of the part's rotational symmetry about its centroid (1 if none).

        A rotation by ``2 pi / r`` must map every vertex within ``tol.symmetry * size`` of
        another vertex. A square is 4, an equilateral triangle 3, a rectangle 2.

        Examples
        --------
        >>> ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).symmetry_order
        2
        """
        v = self.vertices - self.centroid
        n = len(v)
        eps = self.tol.symmetry_for(self.size)
        for r in range(n, 1, -1):
            if n % r:
                continue
            a = 2.0 * math.pi / r
            c, s = math.cos(a), math.sin(a)
            turned = v @ np.array([[c, s], [-s, c]])  # (N, 2) rotated counter-clockwise
            # A rotation keeps the cyclic order: vertex i lands on vertex i + n / r.
            if np.all(np.hypot(*(turned - np.roll(v, -n // r, axis=0)).T) <= eps):
                return r
        return 1


@dataclass(frozen=True, slots=True, eq=False)
class Part:
    """A part as the user gave it: name, outline, hull, centre of mass and units.

    Parameters
    ----------
    name : str
        Name shown in reports.
    hull : ConvexPolygon
        What the gripper touches.
    outline : ndarray of shape (M, 2)
        The user's points, as given (may be non-convex); read-only.
    center_of_mass : ndarray of shape (2,)
        Defaults to the hull's area centroid.
    units : str or None
        The units of the coordinates, when known (reported, never converted).

    Examples
    --------
    >>> p = Part.from_points([(0, 0), (3, 0), (0, 1)], name="wedge")
    >>> p.hull.n_sides, p.center_of_mass.tolist()
    (3, [1.0, 0.3333333333333333])
    """

    name: str
    hull: ConvexPolygon
    outline: FloatArray
    center_of_mass: FloatArray
    units: str | None = None

    @classmethod
    def from_points(
        cls,
        points: ArrayLike,
        name: str = "part",
        center_of_mass: ArrayLike | None = None,
        units: str | None = None,
        tol: Tolerance = DEFAULT_TOLERANCE,
    ) -> Part:
        """Build a part from a point list; the hull is what the gripper sees.

        Raises
        ------
        PartError
            Bad coordinates, or a centre of mass outside the hull.
        """
        outline = as_points(points).copy()
        hull = ConvexPolygon.from_points(outline, tol)
        if center_of_mass is None:
            com = hull.centroid.copy()
        else:
            com = as_points(
                np.reshape(np.asarray(center_of_mass, dtype=object), (1, -1)), "center_of_mass"
            )[0].copy()
            if not hull_contains(hull, com):
                raise PartError(
                    f"`center_of_mass` {com.tolist()} must lie inside the part's convex hull"
                )
        outline.setflags(write=False)
        com.setflags(write=False)
        return cls(name, hull, outline, com, units)


def hull_contains(hull: ConvexPolygon, point: FloatArray) -> bool:
    """Whether ``point`` lies strictly inside the convex polygon (by more than the tolerance)."""
    v = hull.vertices
    e = np.roll(v, -1, axis=0) - v
    rel = point - v
    cross = e[:, 0] * rel[:, 1] - e[:, 1] * rel[:, 0]
    lengths = np.hypot(e[:, 0], e[:, 1])
    return bool(np.all(cross / lengths > hull.tol.length_for(hull.size)))
