"""The part the user gave: :class:`Part`, its outline, hull, centre of mass and units.

The gripper sees the part's convex hull (:class:`~bayesgrasp.geometry.convex.ConvexPolygon`);
the :class:`Part` keeps the user's outline, name, units and centre of mass beside it. The
centre of mass matters for pushing (Goldberg 1993): by default the area centroid of the
outline less its holes (uniform density), which must lie strictly inside the hull.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..errors import PartError
from ..sizes import SMALL
from ..tolerance import DEFAULT_TOLERANCE, Tolerance
from ..units import unit_name
from .convex import ConvexPolygon
from .coordinates import FloatArray, as_points, check_tolerance
from .hull import polygon_area_centroid
from .rings import clean_ring, crossing_point, find_crossing, fold_back, point_in_ring

__all__ = ["Part", "holds_centroid", "hull_contains"]

_FLOAT64 = np.dtype(np.float64)

# Up to this many points :meth:`Part.from_points` takes the hull on Python floats.
_SMALL = SMALL


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
        The units of the coordinates, when known: a name of :mod:`bayesgrasp.units`
        (others are refused; :func:`bayesgrasp.units.convert` converts a part).
    holes : tuple of ndarray of shape (K, 2)
        Holes inside the outline (parts built by :meth:`from_outline`); they move the
        centre of mass, never the hull.

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
    holes: tuple[FloatArray, ...] = ()

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
        hull = None
        if (  # a few float64 points: the finite check on Python floats (a sum is finite
            # only if every term is; else as_points decides and words its refusal)
            type(points) is np.ndarray
            and points.dtype is _FLOAT64  # (a non-native byte order is not)
            and points.ndim == 2
            and points.shape[1] == 2
            and 3 <= len(points) <= _SMALL
        ):
            outline = points.copy()
            px, py = outline.T.tolist()
            if math.isfinite(sum(px, sum(py))):
                if tol is not DEFAULT_TOLERANCE:
                    check_tolerance(tol)
                hull = ConvexPolygon._hull_of_floats(outline, px, py, tol)
            else:
                outline = as_points(points)
        else:
            outline = as_points(points)  # a fresh array
        if hull is None:
            if tol is not DEFAULT_TOLERANCE:
                check_tolerance(tol)
            hull = ConvexPolygon._hull_of(outline, tol)
        return cls._of_hull(hull, outline, name, center_of_mass, units)

    @classmethod
    def _of_hull(
        cls,
        hull: ConvexPolygon,
        outline: FloatArray,
        name: str,
        center_of_mass: ArrayLike | None,
        units: str | None,
    ) -> Part:
        """:meth:`from_points` of points whose hull is ``hull``.

        ``outline``: a fresh array, or a view of one that no one else holds.

        Raises
        ------
        PartError
            A centre of mass outside the hull.
        """
        if units is not None:
            units = unit_name(units)
        outline.setflags(write=False)
        if center_of_mass is None:  # the hull's centroid (the same read-only array)
            cx, cy = hull._centroid_xy()
            if math.isfinite(cx) and math.isfinite(cy) and holds_centroid(hull):
                if cls is not Part:
                    return cls(name, hull, outline, hull.centroid, units)
                part = object.__new__(Part)  # Part(...) of fields already checked
                _part_name(part, name)
                _part_hull(part, hull)
                _part_outline(part, outline)
                _part_center_of_mass(part, hull.centroid)
                _part_units(part, units)
                _part_holes(part, ())
                return part
        com = _center_of_mass(hull, hull.centroid if center_of_mass is None else center_of_mass)
        com.setflags(write=False)
        return cls(name, hull, outline, com, units)

    @classmethod
    def from_outline(
        cls,
        outline: ArrayLike,
        holes: Sequence[ArrayLike] = (),
        name: str = "part",
        center_of_mass: ArrayLike | None = None,
        units: str | None = None,
        tol: Tolerance = DEFAULT_TOLERANCE,
    ) -> Part:
        """Build a part from a simple (possibly non-convex) outline, optionally with holes.

        The outline is an ordered ring, closed implicitly (a repeated closing vertex is
        dropped). The gripper sees its convex hull; the default centre of mass is the area
        centroid of the outline minus the holes (uniform density), not the hull's.

        Parameters
        ----------
        outline : array_like of shape (N, 2)
            Vertices in order around the outline, either direction.
        holes : sequence of array_like of shape (K, 2), optional
            Rings strictly inside the outline, not touching it or each other.
        name : str
        center_of_mass : array_like of shape (2,), optional
            Overrides the area centroid; must lie inside the hull.
        units : str, optional
        tol : Tolerance, optional

        Returns
        -------
        Part
            ``outline`` and ``holes`` are stored counter-clockwise without repeated
            vertices.

        Raises
        ------
        PartError
            Fewer than 3 distinct vertices, non-finite coordinates, a self-intersecting
            outline (two edges that cross or touch, or an edge that folds back), a hole
            outside the outline or crossing it, zero area, or a centre of mass outside the
            hull.

        Examples
        --------
        >>> p = Part.from_outline([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)], name="L")
        >>> p.hull.n_sides, np.round(p.center_of_mass, 6).tolist()
        (5, [0.833333, 0.833333])
        >>> Part.from_outline([(0, 0), (1, 1), (1, 0), (0, 1)])  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        bayesgrasp.errors.PartError: `outline` must be a simple polygon; it crosses itself ...
        """
        if units is not None:
            units = unit_name(units)
        ring = clean_ring(outline, "outline")
        rings = [ring] + [clean_ring(h, f"holes[{k}]") for k, h in enumerate(holes)]
        names = ["outline"] + [f"holes[{k}]" for k in range(len(rings) - 1)]
        for r, what in zip(rings, names, strict=True):
            fold = fold_back(r)
            if fold is not None:
                x, y = r[fold]
                raise PartError(
                    f"`{what}` must be a simple polygon; it folds back on itself at vertex "
                    f"{fold} ({x:.6g}, {y:.6g})"
                )
        hit = find_crossing(rings)
        if hit is not None:
            ra, _, rb, _ = hit
            point = crossing_point(rings, hit)
            where = "it crosses itself" if ra == rb else f"it crosses `{names[rb]}`"
            raise PartError(
                f"`{names[ra]}` must be a simple polygon; {where} near "
                f"({point[0]:.6g}, {point[1]:.6g})"
            )
        oriented: list[FloatArray] = []
        areas: list[float] = []
        centroids: list[FloatArray] = []
        for r in rings:
            a, c = polygon_area_centroid(r)
            oriented.append(r if a > 0 else r[::-1].copy())
            areas.append(abs(a))
            centroids.append(c)
        extent = float(np.max(np.ptp(ring, axis=0)))
        for k in range(1, len(rings)):
            if not point_in_ring(oriented[k][0], oriented[0]):
                raise PartError(f"`{names[k]}` must lie inside `outline`; it lies outside")
            for m in range(1, len(rings)):
                if m != k and point_in_ring(oriented[k][0], oriented[m]):
                    raise PartError(f"`{names[k]}` lies inside `{names[m]}`; holes cannot nest")
        net = areas[0] - sum(areas[1:])
        if net <= tol.length_for(extent) * extent:
            raise PartError(f"`outline` must enclose a non-zero area; got area {net:.6g}")
        hull = ConvexPolygon.from_points(oriented[0], tol)
        if center_of_mass is None:
            # The centroid of the outline less its holes: sum(+-A_i c_i) / sum(+-A_i).
            with np.errstate(over="ignore", invalid="ignore"):
                weighted = areas[0] * centroids[0] - sum(
                    (a * c for a, c in zip(areas[1:], centroids[1:], strict=True)), np.zeros(2)
                )
            point = weighted / net
            if not np.all(np.isfinite(weighted)) or areas[0] < 1e-200:
                # Near the largest coordinates an area times a coordinate overflows, near the
                # smallest it underflows: weigh by area fractions instead (the same point,
                # rounded differently).
                point = (areas[0] / net) * centroids[0] - sum(
                    ((a / net) * c for a, c in zip(areas[1:], centroids[1:], strict=True)),
                    np.zeros(2),
                )
            com = _center_of_mass(hull, point)
        else:
            com = _center_of_mass(hull, center_of_mass)
        for arr in (*oriented, com):
            arr.setflags(write=False)
        return cls(name, hull, oriented[0], com, units, tuple(oriented[1:]))

    def scaled(self, factor: float, units: str) -> Part:
        """The part with its outline, holes and centre of mass multiplied by ``factor``.

        :func:`bayesgrasp.units.convert` uses it to change units; ``units`` are the new ones.

        Examples
        --------
        >>> p = Part.from_points([(0, 0), (1, 0), (0, 1)], units="cm").scaled(10, "mm")
        >>> p.units, float(p.hull.vertices.max())
        ('mm', 10.0)
        """
        com = self.center_of_mass * factor
        if self.holes:
            return Part.from_outline(
                self.outline * factor, [h * factor for h in self.holes], self.name, com, units
            )
        return Part.from_points(self.outline * factor, self.name, com, units)


# The fields' setters, for _of_hull: the class itself refuses assignment (a frozen value).
_part_name, _part_hull, _part_outline, _part_center_of_mass, _part_units, _part_holes = (
    Part.__dict__[f.name].__set__ for f in dataclasses.fields(Part)
)


def _center_of_mass(hull: ConvexPolygon, point: ArrayLike) -> FloatArray:
    """A centre of mass as a fresh (2,) array, refused unless strictly inside the hull."""
    try:
        flat = np.reshape(np.asarray(point, dtype=object), (1, -1))
    except (TypeError, ValueError, RecursionError) as exc:
        raise PartError(f"`center_of_mass` must be 2 numbers; could not read it: {exc}") from None
    com = as_points(flat, "center_of_mass")[0]
    if not hull_contains(hull, com):
        raise PartError(f"`center_of_mass` {com.tolist()} must lie inside the part's convex hull")
    return np.array(com, dtype=np.float64)


# Rounding allowance of holds_centroid: far more than the error of the computed distances.
_CENTROID_SLACK = 1e-12


def holds_centroid(hull: ConvexPolygon) -> bool:
    """``hull_contains(hull, hull.centroid)``, without the test when it cannot fail.

    The centroid of a convex polygon lies at least a third of the polygon's width from each
    edge's line (Minkowski and Radon), and the width is at least ``area / (2 size)`` (the
    polygon lies within ``size`` of its centroid): so when ``area / (6 size)`` exceeds the
    margin by far more than the rounding of the distances, every edge passes the test. Only
    thin polygons are tested edge by edge.
    """
    cx, cy = hull._centroid_xy()
    margin = hull.tol.length_for(hull.size)
    slack = _CENTROID_SLACK * (abs(cx) + abs(cy) + hull.size)
    if hull.area > 6.0 * hull.size * (2.0 * margin + slack):
        return True
    return hull_contains(hull, hull.centroid)


def hull_contains(hull: ConvexPolygon, point: FloatArray) -> bool:
    """Whether ``point`` lies strictly inside the convex polygon (by more than the tolerance)."""
    margin = hull.tol.length_for(hull.size)
    if hull.n_sides <= SMALL:  # on Python floats (math.hypot may differ from numpy's by an ulp)
        xs, ys = hull._coords()
        px, py = float(point[0]), float(point[1])
        n = len(xs)
        for i in range(n):
            ex, ey = xs[(i + 1) % n] - xs[i], ys[(i + 1) % n] - ys[i]
            cross = ex * (py - ys[i]) - ey * (px - xs[i])
            if not cross / math.hypot(ex, ey) > margin:
                return False
        return True
    v = hull.vertices
    e = np.roll(v, -1, axis=0) - v
    rel = point - v
    crosses = e[:, 0] * rel[:, 1] - e[:, 1] * rel[:, 0]
    lengths = np.hypot(e[:, 0], e[:, 1])
    return bool(np.all(crosses / lengths > margin))
