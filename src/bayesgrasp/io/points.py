"""Point-list part files: JSON and CSV.

``.json``: ``{"name": ..., "vertices": [[x, y], ...]}`` with optional ``"units"`` and
``"center_of_mass": [x, y]`` (or a bare list of points). A JSON file holding a GeoJSON object
is read as GeoJSON. ``.csv``: one ``x,y`` row per point; a header row is allowed.

The points are read in the order given, and that order decides what they are:

- an **outline**: taken in order (and closed back to the first point) they make a simple
  polygon, whose edges meet only at consecutive points. The part is that polygon
  (:meth:`Part.from_outline`, no holes): the gripper sees its convex hull and the default
  centre of mass is the polygon's area centroid, as for a WKT or SVG outline. A convex
  outline is read as before (:meth:`Part.from_points`; its area centroid is its hull's).
- a **point cloud**: taken in order they cross themselves (or fold back). The part is their
  convex hull (:meth:`Part.from_points`), its outline is the hull, and the default centre of
  mass is the hull's area centroid; give ``"center_of_mass"`` (JSON) when the part's mass is
  elsewhere.

So a non-convex outline must be given in order around it; the same points shuffled are a
point cloud.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import numbers
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import PartError
from ..geometry import Part, as_points, find_crossing
from ._common import (
    ReadOptions,
    brief,
    check_coordinates,
    check_count,
    decode_text,
    fail,
    load_json,
    quote,
    read_bytes,
    refuse_options,
)

__all__ = ["parse_csv", "parse_json", "point_list_part", "read_csv", "read_json"]

FloatArray = NDArray[np.float64]

GEOJSON_TYPES = {
    "Feature",
    "FeatureCollection",
    "Polygon",
    "MultiPolygon",
    "GeometryCollection",
    "LineString",
    "MultiLineString",
    "Point",
    "MultiPoint",
}

# Turns smaller than this (relative to the edge lengths) count as straight, as in
# Part.from_outline's test for an edge that folds back.
_STRAIGHT = 1e-12


def _ring(points: FloatArray) -> FloatArray:
    """The points without repeated consecutive points or a repeated closing point."""
    if len(points) < 2:
        return points
    out: FloatArray = points[~np.all(points == np.roll(points, -1, axis=0), axis=1)]
    return out


def _is_simple(ring: FloatArray) -> bool:
    """Whether the closed ring is a simple polygon: no fold-back, no two edges meeting."""
    u = ring - np.roll(ring, 1, axis=0)  # (N, 2) incoming edges
    w = np.roll(ring, -1, axis=0) - ring  # (N, 2) outgoing edges
    cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    scale = np.hypot(u[:, 0], u[:, 1]) * np.hypot(w[:, 0], w[:, 1])
    if np.any((np.abs(cross) <= _STRAIGHT * scale) & ((u * w).sum(axis=1) < 0)):
        return False
    return find_crossing([ring]) is None


def _is_convex(ring: FloatArray) -> bool:
    """Whether a simple ring turns one way only (straight runs allowed)."""
    u = ring - np.roll(ring, 1, axis=0)
    w = np.roll(ring, -1, axis=0) - ring
    cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    slack = _STRAIGHT * np.hypot(u[:, 0], u[:, 1]) * np.hypot(w[:, 0], w[:, 1])
    return bool(np.all(cross >= -slack) or np.all(cross <= slack))


def point_list_part(
    path: Path,
    points: Any,
    name: str,
    center_of_mass: Any = None,
    units: str | None = None,
) -> Part:
    """The part of a point list: an ordered simple outline, or the hull of a point cloud.

    Parameters
    ----------
    path : Path
        The file, for messages.
    points : array_like of shape (N, 2)
        The points in the order of the file.
    name, center_of_mass, units
        As for :meth:`Part.from_points`.

    Returns
    -------
    Part

    Examples
    --------
    >>> ell = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    >>> point_list_part(Path("L.csv"), ell, "L").center_of_mass.round(4).tolist()
    [0.8333, 0.8333]
    >>> cloud = [ell[i] for i in (0, 3, 1, 5, 2, 4)]
    >>> point_list_part(Path("L.csv"), cloud, "L").center_of_mass.round(4).tolist()
    [0.9048, 0.9048]
    """
    try:
        pts = as_points(points)
    except PartError as exc:
        raise fail(path, str(exc)) from None
    check_coordinates(path, pts, "the point list")
    ring = _ring(pts)
    simple = len(ring) >= 3 and _is_simple(ring)
    try:
        if simple and not _is_convex(ring):
            return Part.from_outline(ring, name=name, center_of_mass=center_of_mass, units=units)
        part = Part.from_points(pts, name=name, center_of_mass=center_of_mass, units=units)
    except PartError as exc:
        raise fail(path, str(exc)) from None
    if not simple:  # a point cloud: its outline is its hull, not a self-crossing path
        part = dataclasses.replace(part, outline=part.hull.vertices)
    return part


def _center_of_mass(path: Path, value: Any) -> Any:
    """A ``"center_of_mass"`` member: ``null`` or ``[x, y]`` of numbers."""
    if value is None:
        return None
    if (
        not isinstance(value, list)
        or len(value) != 2
        or not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in value)
    ):
        raise fail(path, f'"center_of_mass" must be [x, y] (two numbers); got {brief(value)}')
    if not all(math.isfinite(v) for v in value):
        raise fail(path, f'"center_of_mass" must be finite; got {value!r}')
    return value


def parse_json(data: bytes, path: Path, options: ReadOptions) -> Part:
    """Read a JSON point list (or a GeoJSON object) from the file's bytes.

    Parameters
    ----------
    data : bytes
        The file's contents (UTF-8).
    path : Path
        The file's name, for messages and the default part name.
    options : ReadOptions

    Returns
    -------
    Part

    Examples
    --------
    >>> p = parse_json(b'{"vertices": [[0, 0], [3, 0], [0, 1]]}', Path("w.json"), ReadOptions())
    >>> p.name, p.hull.n_sides
    ('w', 3)
    """
    doc: Any = load_json(path, decode_text(path, data))
    if (
        isinstance(doc, dict)
        and isinstance(doc.get("type"), str)
        and doc["type"] in GEOJSON_TYPES
        and "vertices" not in doc
    ):
        from .geojson import geojson_part

        return geojson_part(path, doc, options)
    refuse_options(path, options, "a JSON point list")
    if isinstance(doc, list):
        doc = {"vertices": doc}
    if not isinstance(doc, dict) or "vertices" not in doc:
        raise fail(path, 'expected an object with "vertices": [[x, y], ...]')
    name = doc.get("name", path.stem)
    units = doc.get("units")
    if not isinstance(name, str) or (units is not None and not isinstance(units, str)):
        raise fail(path, '"name" and "units" must be strings')
    vertices = doc["vertices"]
    if not isinstance(vertices, list):
        raise fail(path, f'"vertices" must be a list of [x, y]; got a {type(vertices).__name__}')
    check_count(path, len(vertices), options)
    com = _center_of_mass(path, doc.get("center_of_mass"))
    return point_list_part(path, vertices, name, com, units)


def read_json(path: Path, options: ReadOptions) -> Part:
    """Read a JSON point list (or a GeoJSON object).

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "wedge.json"
    >>> _ = f.write_text('{"vertices": [[0, 0], [3, 0], [0, 1]], "units": "mm"}')
    >>> p = read_json(f, ReadOptions())
    >>> p.name, p.units, p.hull.n_sides
    ('wedge', 'mm', 3)
    """
    return parse_json(read_bytes(path), path, options)


def parse_csv(data: bytes, path: Path, options: ReadOptions) -> Part:
    r"""Read a CSV point list (``x,y`` per row; a header row is allowed) from bytes.

    Examples
    --------
    >>> parse_csv(b"x,y\n0,0\n1,0\n1,1\n0,1\n", Path("sq.csv"), ReadOptions()).hull.n_sides
    4
    """
    text = decode_text(path, data)
    refuse_options(path, options, "a CSV point list")
    try:
        rows = [r for r in csv.reader(text.splitlines()) if r and any(c.strip() for c in r)]
    except csv.Error as exc:
        raise fail(path, f"not a CSV point list ({exc})") from None
    check_count(path, len(rows), options)
    pts: list[list[float]] = []
    for n, row in enumerate(rows, start=1):
        if len(row) != 2:
            raise fail(path, f"row {n} has {len(row)} fields; expected 2 (x,y)")
        try:
            pts.append([float(row[0]), float(row[1])])
        except ValueError:
            if n == 1 and not pts:
                continue  # a header row
            raise fail(path, f"row {n} is not two numbers: {quote(','.join(row))}") from None
        if not all(math.isfinite(v) for v in pts[-1]):
            raise fail(
                path, f"row {n} is not finite (or too large for a float): {quote(','.join(row))}"
            )
    if not pts:
        raise fail(path, "no points found; expected one x,y row per point")
    return point_list_part(path, pts, path.stem)


def read_csv(path: Path, options: ReadOptions) -> Part:
    r"""Read a CSV point list (``x,y`` per row; a header row is allowed).

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "square.csv"
    >>> _ = f.write_text("x,y\n0,0\n1,0\n1,1\n0,1\n")
    >>> read_csv(f, ReadOptions()).hull.n_sides
    4
    """
    return parse_csv(read_bytes(path), path, options)
