"""The convex polygon the gripper sees: :class:`ConvexPolygon`.

A frictionless parallel-jaw gripper only ever touches the convex hull of a part (the seed,
section 4.1, assumption 3, and Appendix A: "the diameter function for C is equal to the
diameter function for the convex hull of C"), so every transfer function is built from a
:class:`ConvexPolygon`: the hull's vertices counter-clockwise (:mod:`.hull`), its area,
centroid and size, and its order of rotational symmetry (:mod:`.symmetry`).

The library never rotates the user's coordinates: an orientation ``theta`` is always the
rotation of the part *as given* relative to the gripper frame.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import ArrayLike

from ..errors import PartError
from ..sizes import SMALL
from ..tolerance import DEFAULT_TOLERANCE, Tolerance
from .coordinates import FloatArray, as_points, check_magnitude, check_tolerance, odd_magnitude
from .hull import (
    drop_near_collinear,
    hull_indices,
    hull_of_few,
    largest_distance,
    polygon_area_centroid,
    refuse_hull,
)
from .symmetry import (
    orders_between,
    orders_from,
    symmetrized_vertices,
    symmetry_order_arrays,
    symmetry_order_python,
)

__all__ = ["ConvexPolygon"]


def _restored(
    vertices: FloatArray, tol: Tolerance, area: float, centroid: FloatArray, size: float
) -> ConvexPolygon:
    """A pickled :class:`ConvexPolygon` (its fields, already checked)."""
    return ConvexPolygon._trusted(vertices, tol, area, centroid, size)


# Up to this many points the hull, the symmetry test and the polygon's fields are computed
# on Python floats (numpy's cost of a call exceeds the work); the same decisions either way.
_SMALL = SMALL


class ConvexPolygon:
    """Convex polygon, vertices counter-clockwise, no repeated closing vertex.

    Build it with :meth:`from_points`, which takes the convex hull of any point list.
    A frozen value: the arrays are read-only (made on first use when the hull was taken in
    plain Python, from its Python floats).

    Attributes
    ----------
    vertices : ndarray of shape (N, 2)
        Counter-clockwise hull vertices in the user's coordinates (never rotated).
    tol : Tolerance
        The tolerances used for this polygon.
    area : float
    centroid : ndarray of shape (2,)
        The area centroid.
    size : float
        The largest distance of a vertex from the centroid.

    Examples
    --------
    >>> ConvexPolygon.from_points([(0, 0), (2, 0), (0, 1), (0.5, 0.2)]).n_sides
    3
    """

    __slots__ = ("_c", "_cxy", "_symmetry", "_v", "_xy", "area", "size", "tol")
    __match_args__ = ("vertices", "tol")

    tol: Tolerance
    area: float
    size: float
    # symmetry_order once known; -k when only known to be below k; 0 before any test.
    _symmetry: int
    # The vertices and the centroid as read-only arrays, or as Python floats (for the
    # plain-Python paths): at least one of each pair is set, the other made when asked for.
    _v: FloatArray | None
    _xy: tuple[list[float], list[float]] | None
    _c: FloatArray | None
    _cxy: tuple[float, float] | None

    def __init__(self, vertices: ArrayLike, tol: Tolerance = DEFAULT_TOLERANCE) -> None:
        check_tolerance(tol)
        v = as_points(vertices)
        n = len(v)
        what = "`vertices` must be a counter-clockwise convex polygon"
        if n < 3:
            raise PartError(f"{what} of at least 3 vertices; got {n}")
        area, centroid = polygon_area_centroid(v)
        size = float(np.max(np.hypot(*(v - centroid).T)))
        e = np.concatenate((v[1:], v[:1])) - v  # (N, 2) edge i runs from vertex i to i + 1
        elen = np.hypot(e[:, 0], e[:, 1])
        short = np.flatnonzero(elen <= tol.length_for(size))
        if len(short):
            raise PartError(f"{what}; vertices {short[0]} and {(short[0] + 1) % n} coincide")
        en = np.concatenate((e[1:], e[:1]))  # (N, 2) the edge after each edge
        cross = e[:, 0] * en[:, 1] - e[:, 1] * en[:, 0]
        right = np.flatnonzero(cross < -tol.angle * elen * np.roll(elen, -1))
        if len(right):
            raise PartError(f"{what}; it turns clockwise at vertex {(right[0] + 1) % n}")
        turns = float(np.sum(np.arctan2(cross, np.sum(e * en, axis=1)))) / (2.0 * math.pi)
        if abs(turns - 1.0) > 1e-6:
            raise PartError(f"{what}; it winds {turns:.3g} times around")
        self._set_arrays(tol, v, area, centroid, size)

    def _set_arrays(
        self, tol: Tolerance, v: FloatArray, area: float, centroid: FloatArray, size: float
    ) -> None:
        v.setflags(write=False)
        centroid.setflags(write=False)
        _poly_tol(self, tol)
        _poly_v(self, v)
        _poly_xy(self, None)
        _poly_area(self, area)
        _poly_c(self, centroid)
        _poly_cxy(self, None)
        _poly_size(self, size)
        _poly_symmetry(self, 0)

    def __setattr__(self, name: str, value: object) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[object, ...]:
        return (_restored, (self.vertices, self.tol, self.area, self.centroid, self.size))

    def __repr__(self) -> str:
        return (
            f"ConvexPolygon(vertices={self.vertices!r}, tol={self.tol!r}, area={self.area!r}, "
            f"centroid={self.centroid!r}, size={self.size!r})"
        )

    @property
    def vertices(self) -> FloatArray:
        """Counter-clockwise hull vertices, shape (N, 2), read-only."""
        v = self._v
        if v is None:
            assert self._xy is not None
            v = np.array(self._xy, dtype=np.float64).T.copy()
            v.setflags(write=False)
            object.__setattr__(self, "_v", v)
        return v

    @property
    def centroid(self) -> FloatArray:
        """The area centroid, shape (2,), read-only."""
        c = self._c
        if c is None:
            assert self._cxy is not None
            c = np.array(self._cxy)  # float64: two Python floats
            c.setflags(write=False)
            object.__setattr__(self, "_c", c)
        return c

    def _coords(self) -> tuple[list[float], list[float]]:
        """The vertices' x and y coordinates as lists of Python floats (made once)."""
        xy = self._xy
        if xy is None:
            xs, ys = self.vertices.T.tolist()
            xy = (xs, ys)
            object.__setattr__(self, "_xy", xy)
        return xy

    def _centroid_xy(self) -> tuple[float, float]:
        """The centroid as two Python floats (made once)."""
        cxy = self._cxy
        if cxy is None:
            cx, cy = self.centroid.tolist()
            cxy = (cx, cy)
            object.__setattr__(self, "_cxy", cxy)
        return cxy

    @classmethod
    def _trusted(
        cls,
        v: FloatArray,
        tol: Tolerance,
        area: float,
        centroid: FloatArray,
        size: float | None = None,
    ) -> ConvexPolygon:
        """A polygon known to be convex and counter-clockwise (from a hull or a rotation)."""
        poly = object.__new__(cls)
        if size is None:
            d = v - centroid
            size = math.sqrt(float(np.max(d[:, 0] ** 2 + d[:, 1] ** 2)))
        poly._set_arrays(tol, v, area, centroid, size)
        return poly

    @classmethod
    def _of_floats(
        cls,
        xs: list[float],
        ys: list[float],
        tol: Tolerance,
        area: float,
        cx: float,
        cy: float,
        size: float,
    ) -> ConvexPolygon:
        """A hull taken in plain Python, from its floats; the arrays are made on first use."""
        poly = object.__new__(cls)
        _poly_tol(poly, tol)
        _poly_v(poly, None)
        _poly_xy(poly, (xs, ys))
        _poly_area(poly, area)
        _poly_c(poly, None)
        _poly_cxy(poly, (cx, cy))
        _poly_size(poly, size)
        _poly_symmetry(poly, 0)
        return poly

    @classmethod
    def from_points(cls, points: ArrayLike, tol: Tolerance = DEFAULT_TOLERANCE) -> ConvexPolygon:
        """Convex hull of a point list, counter-clockwise, duplicates and collinear points dropped.

        Andrew's monotone chain (:func:`~bayesgrasp.geometry.hull.hull_indices`; on Python
        floats up to :data:`~bayesgrasp.sizes.SMALL` points,
        :func:`~bayesgrasp.geometry.hull.hull_of_few`), then the vertices within
        ``tol.length_for(extent)`` of their neighbours' chord dropped
        (:func:`~bayesgrasp.geometry.hull.drop_near_collinear`), and the area and centroid by
        the shoelace formula. The vertices start at the lexicographically least one.

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
        check_tolerance(tol)
        return cls._hull_of(as_points(points), tol)

    @classmethod
    def _hull_of(cls, pts: FloatArray, tol: Tolerance) -> ConvexPolygon:
        """:meth:`from_points` of points already checked by :func:`as_points`."""
        if 3 <= len(pts) <= _SMALL:
            px, py = pts.T.tolist()
            return cls._hull_of_floats(pts, px, py, tol)
        extent = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
        check_magnitude(pts, extent)
        eps = tol.length_for(extent)
        area = 0.0
        if len(pts) < 3 or extent == 0.0:
            hull = pts[:0]
        else:
            hull = pts[hull_indices(pts)]
            if len(hull) > 3:
                hull = drop_near_collinear(hull, eps)
            if len(hull) >= 3:
                area, centroid = polygon_area_centroid(hull)
        if len(hull) < 3 or area <= eps * extent:
            refuse_hull(pts, eps)
        return cls._trusted(hull, tol, area, centroid)

    @classmethod
    def _hull_of_floats(
        cls, pts: FloatArray, px: list[float], py: list[float], tol: Tolerance
    ) -> ConvexPolygon:
        """:meth:`_hull_of` of 3 to :data:`_SMALL` points, in plain Python.

        ``px`` and ``py`` are the coordinates of ``pts`` as Python floats (the same values).
        """
        ordered = sorted(zip(px, py, strict=True))  # the least and largest x at the ends
        by_y = sorted(py)  # the least and largest y at the ends
        x0, x1, y0, y1 = ordered[0][0], ordered[-1][0], by_y[0], by_y[-1]
        extent = max(x1 - x0, y1 - y0)
        if odd_magnitude(x0, x1, y0, y1, extent):
            check_magnitude(pts, extent)
        eps = tol.length_for(extent)
        if extent == 0.0:
            refuse_hull(pts, eps)
        xs, ys, area, cx, cy = hull_of_few(ordered, eps)
        if len(xs) < 3 or area <= eps * extent:
            refuse_hull(pts, eps)
        size = largest_distance(zip(xs, ys, strict=True), cx, cy)
        return cls._of_floats(xs, ys, tol, area, cx, cy, size)

    @property
    def n_sides(self) -> int:
        """Number of sides (equal to the number of vertices)."""
        xy = self._xy
        return len(xy[0]) if xy is not None else len(self.vertices)

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
        return ConvexPolygon._trusted(
            self.vertices @ rot.T, self.tol, self.area, rot @ self.centroid
        )

    @property
    def symmetry_order(self) -> int:
        """Order r of the part's rotational symmetry about its centroid (1 if none).

        A rotation by ``2 pi / r`` must map every vertex within ``tol.symmetry * size`` of
        another vertex. A square is 4, an equilateral triangle 3, a rectangle 2. A part
        symmetric within that tolerance is treated as exactly symmetric everywhere
        downstream: its diameter function's extrema, hence its squeeze function, are those
        of :meth:`symmetrized` (see :func:`~bayesgrasp.geometry.diameter.diameter_function`).
        Only divisors of the number of vertices can be orders, tested largest first
        (:mod:`~bayesgrasp.geometry.symmetry`).

        Examples
        --------
        >>> ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).symmetry_order
        2
        """
        return self.symmetry_order_from(2)

    def symmetry_order_from(self, lowest: int) -> int:
        """:attr:`symmetry_order` if it is at least ``lowest``, else 1.

        Only the orders from ``lowest`` up are tested (the answer is cached), so asking
        whether a part has an order of 3 or more skips the test of a half turn: the
        diameter function needs no more.

        Examples
        --------
        >>> rect = ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
        >>> rect.symmetry_order_from(3), rect.symmetry_order
        (1, 2)
        """
        known = self._symmetry
        if known > 0:
            return known if known >= lowest else 1
        n = self.n_sides  # the arrays are made on first use: not here
        if known < 0:
            if lowest >= -known:
                return 1  # every order from -known up failed
            orders = orders_between(n, lowest, -known)
        else:
            orders = orders_from(n, lowest)
        if not orders:  # (as an odd part's half turn, after the orders from 3 failed)
            _poly_symmetry(self, -lowest)
            return 1
        eps = self.tol.symmetry_for(self.size)
        if n <= _SMALL:
            found = symmetry_order_python(*self._coords(), self._centroid_xy(), orders, eps)
        else:
            found = symmetry_order_arrays(self.vertices, self.centroid, orders, eps)
        _poly_symmetry(self, found if found > 1 else -lowest)
        return found

    def symmetrized(self, centred: bool = False) -> FloatArray:
        """The vertices made exactly r-fold symmetric, ``r = symmetry_order``.

        Each vertex is replaced by the mean of its orbit under the rotations by ``2 pi k / r``
        about the centroid (vertex ``i + k n / r`` turned back by ``2 pi k / r``), and the
        mean is turned forward again: the nearest exactly symmetric polygon with the same
        vertex correspondence, no vertex moved by more than ``tol.symmetry * size``. It is
        what the diameter function of a near-symmetric part is built from (its extrema), so
        that the squeeze function has the symmetry's period to rounding. For ``r = 1`` the
        vertices are returned unchanged.

        ``centred=True`` gives them relative to the centroid, the centroid not added back:
        symmetric to the rounding of the part's size rather than of its coordinates. Edge
        directions, the diameter and the radius about the centroid are the same; a part
        far from the origin (a 7 mm part at 500 m) keeps its symmetry to 1e-16 rad and not
        to 1e-8 rad, where the squeeze function's period test needs ``tol.angle``.

        Returns
        -------
        ndarray of shape (N, 2)

        Examples
        --------
        >>> sq = ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1.000001)])
        >>> v = sq.symmetrized() - sq.centroid
        >>> turned = v @ np.array([[0.0, 1.0], [-1.0, 0.0]])  # a quarter turn
        >>> sq.symmetry_order, bool(np.abs(turned - np.roll(v, -1, axis=0)).max() < 1e-15)
        (4, True)
        >>> bool(np.abs(sq.symmetrized() - sq.vertices).max() < 1e-6)
        True
        """
        r = self.symmetry_order
        if r == 1:
            v = self.vertices
            return v - self.centroid if centred else np.array(v, dtype=np.float64)
        return symmetrized_vertices(self.vertices, self.centroid, r, centred)


# The fields' setters, for the constructors: the class itself refuses assignment (a value).
_poly_c, _poly_cxy, _poly_symmetry, _poly_v, _poly_xy, _poly_area, _poly_size, _poly_tol = (
    ConvexPolygon.__dict__[name].__set__ for name in ConvexPolygon.__slots__
)
