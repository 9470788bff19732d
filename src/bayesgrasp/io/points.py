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
import json
import math
import numbers
from pathlib import Path
from typing import Any

import numpy as np
import orjson
from numpy.typing import NDArray

from ..errors import PartError
from ..files import json_float, json_int, nesting_depth
from ..geometry import Part, as_points, find_crossing
from ..sizes import SMALL
from ._common import (
    MAX_BYTES,
    MAX_COORDINATE,
    MAX_NESTING,
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

__all__ = [
    "json_line_part",
    "parse_csv",
    "parse_json",
    "point_list_part",
    "read_csv",
    "read_json",
]

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


# Where math.hypot and np.hypot (an ulp apart at most) could decide a straightness test
# differently: within this relative band of the threshold the numpy test decides.
_BAND = 1e-9

# Python ints above this may convert to float differently through numpy's integer arrays.
_EXACT_INT = 2**53


def _small_floats(
    points: Any, limit: float = MAX_COORDINATE
) -> tuple[list[float], list[float]] | None:
    """A short plain list of ``[x, y]`` numbers as Python floats; ``None`` for any other input.

    The fast path of :func:`point_list_part` (at most :data:`bayesgrasp.sizes.SMALL` points):
    only lists whose every coordinate is an ``int`` or ``float``, finite and within ``limit``
    (at most :data:`MAX_COORDINATE`), so these are exactly the values ``np.asarray`` would
    give, as the lists of the x and of the y coordinates. Anything else (booleans, text, big
    integers, bad shapes, non-finite values) returns ``None`` and takes the general path,
    which gives its errors.
    """
    if not isinstance(points, list) or not 3 <= len(points) <= SMALL:
        return None
    xs: list[float] = []
    ys: list[float] = []
    for p in points:
        if type(p) is not list or len(p) != 2:
            return None
        x, y = p
        tx, ty = type(x), type(y)
        if (tx is not float and tx is not int) or (ty is not float and ty is not int):
            return None
        if (tx is int and abs(x) > _EXACT_INT) or (ty is int and abs(y) > _EXACT_INT):
            return None
        fx, fy = float(x), float(y)
        # abs(nan) <= M is False: NaN and infinities take the general path too.
        if not (abs(fx) <= limit and abs(fy) <= limit):
            return None
        xs.append(fx)
        ys.append(fy)
    return xs, ys


# The types _line_floats admits.
_FLOAT = {float}
_NUMBER = {float, int}


def _line_floats(points: Any) -> tuple[list[float], list[float]] | None:
    """:func:`_small_floats` of a value orjson read, without its limit on the coordinates.

    The same floats, or ``None``, as ``_small_floats(points, math.inf)``, in bulk: orjson
    makes only dicts, lists, strings, ints, booleans, ``None`` and finite floats, so an item
    of ``points`` that unpacks into two is a list of two, or a string or a dict whose
    characters or keys (strings) are then refused as coordinates.
    """
    if type(points) is not list or not 3 <= len(points) <= SMALL:
        return None
    try:
        xs = [x for x, _ in points]
        ys = [y for _, y in points]
    except (TypeError, ValueError):  # a number, a boolean, null; a list of another length
        return None
    kinds = {*map(type, xs), *map(type, ys)}
    if kinds != _FLOAT:
        if not kinds <= _NUMBER:
            return None
        if any(type(c) is int and abs(c) > _EXACT_INT for c in xs + ys):
            return None  # (within 2^53 an int converts exactly)
        xs = [float(c) for c in xs]
        ys = [float(c) for c in ys]
    return xs, ys


def _small_ring(pts: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """:func:`_ring` on Python floats: drop each point equal to the next (cyclically)."""
    n = len(pts)
    return [p for i, p in enumerate(pts) if p != pts[(i + 1) % n]]


def _turns(ring: list[tuple[float, float]]) -> list[tuple[float, float, float]]:
    """(cross, dot, |u| |w|) at each vertex of the ring (u incoming, w outgoing edge).

    The cross and dot products are the numpy paths' operations, in the same order.
    """
    n = len(ring)
    out = []
    for i in range(n):
        (ax, ay), (bx, by), (cx, cy) = ring[i - 1], ring[i], ring[(i + 1) % n]
        ux, uy, wx, wy = bx - ax, by - ay, cx - bx, cy - by
        out.append((ux * wy - uy * wx, ux * wx + uy * wy, math.hypot(ux, uy) * math.hypot(wx, wy)))
    return out


def _near(value: float, threshold: float) -> bool:
    """Whether ``value`` is too close to ``threshold`` for math.hypot to decide."""
    return abs(value - threshold) <= _BAND * abs(threshold)


def _small_is_simple(
    ring: list[tuple[float, float]], turns: list[tuple[float, float, float]]
) -> bool:
    """:func:`_is_simple` on Python floats, for rings of at most :data:`SMALL` points.

    The fold-back test as :func:`_is_simple` (numpy decides within :data:`_BAND` of the
    threshold); the crossing test pairs every two non-adjacent edges whose bounding boxes
    overlap (the pairs ``find_crossing``'s sweep examines) and settles them by the same
    orientation signs as ``_segments_meet``.
    """
    for cross, dot, scale in turns:
        if dot < 0:
            if _near(abs(cross), _STRAIGHT * scale):
                return _is_simple(np.array(ring, dtype=np.float64))
            if abs(cross) <= _STRAIGHT * scale:
                return False
    n = len(ring)
    edges = []
    for i in range(n):
        (px, py), (qx, qy) = ring[i], ring[(i + 1) % n]
        edges.append((px, py, qx, qy, min(px, qx), max(px, qx), min(py, qy), max(py, qy)))
    for i in range(n):
        px, py, qx, qy, xlo, xhi, ylo, yhi = edges[i]
        for j in range(i + 2, n if i else n - 1):
            rx, ry, sx, sy, xlo2, xhi2, ylo2, yhi2 = edges[j]
            if xlo > xhi2 or xlo2 > xhi or ylo > yhi2 or ylo2 > yhi:
                continue
            o1 = (qx - px) * (ry - py) - (qy - py) * (rx - px)
            o2 = (qx - px) * (sy - py) - (qy - py) * (sx - px)
            if (o1 > 0 and o2 > 0) or (o1 < 0 and o2 < 0):
                continue
            o3 = (sx - rx) * (py - ry) - (sy - ry) * (px - rx)
            o4 = (sx - rx) * (qy - ry) - (sy - ry) * (qx - rx)
            if not ((o3 > 0 and o4 > 0) or (o3 < 0 and o4 < 0)):
                return False
    return True


def _small_is_convex(
    ring: list[tuple[float, float]], turns: list[tuple[float, float, float]]
) -> bool:
    """:func:`_is_convex` on Python floats (numpy decides within :data:`_BAND` of a threshold)."""
    left = right = True
    for cross, _, scale in turns:
        slack = _STRAIGHT * scale
        if _near(cross, -slack) or _near(cross, slack):
            return _is_convex(np.array(ring, dtype=np.float64))
        left = left and cross >= -slack
        right = right and cross <= slack
    return left or right


# A turn whose cross product exceeds this fraction of the squared bounding-box diagonal is
# far beyond every threshold and rounding error of the tests below (see _firm_turn).
_FIRM = 2e-12


def _firm_turn(
    xs: list[float], ys: list[float], x0: float, x1: float, y0: float, y1: float
) -> float:
    """Whether the ring is firmly convex: every turn one way, by a margin, winding once.

    ``xs`` and ``ys``: the ring's coordinates (a point repeated next to itself makes a turn
    of 0: not firm); ``x0, x1, y0, y1``: their least and largest. Then
    :func:`_small_is_simple` and :func:`_small_is_convex` both return True, found in O(N)
    rather than their O(N^2) pairs of edges. Returns the cross product ``u x w`` (``u`` the
    incoming, ``w`` the outgoing edge) of least magnitude (positive: the ring runs
    counter-clockwise); ``0.0`` means only "not shown here".

    Why: a ring that turns one way at every vertex and once in all (exterior angles in
    (0, pi) summing to 2 pi) is a convex polygon. Every vertex R off an edge PQ then lies at
    least as far from PQ's line as the vertex after Q or the one before P (distance to a line
    is unimodal around a convex polygon), so the exact orientation ``PQ x PR`` is at least
    the smaller of the cross products at P and Q. Each orientation computed in floats is
    within ``4 u D^2`` of its exact value (``u`` the unit roundoff, ``D`` the bounding-box
    diagonal: differences, products, one subtraction). A cross product above
    ``_FIRM * D^2`` (about 10^4 times that) therefore leaves every orientation the
    crossing test computes strictly on one side, and it is also above twice the fold-back and
    convexity thresholds (``_STRAIGHT * |u| |w|``, with ``|u| |w| <= D^2``), outside their
    bands.

    Winding once, counted exactly: each computed cross product is within ``2 u |u| |w|`` of
    the exact one of the computed edges, so when all are beyond ``_FIRM * D^2`` the edges'
    direction turns the same way at every vertex, by an angle strictly between 0 and pi.
    Turning so, it reaches the direction pi/2 (or -pi/2, turning clockwise) once in each
    revolution, and there only: at the vertices where the edges' x component goes from
    positive to not positive. One such vertex: one revolution (the sum of the exterior
    angles, 2 pi, where a star has 4 pi or more).
    """
    firm = _FIRM * ((x1 - x0) ** 2 + (y1 - y0) ** 2)
    bx, by = xs[-1], ys[-1]
    ux, uy = bx - xs[-2], by - ys[-2]  # the edge into the first point
    crosses: list[float] = []
    push = crosses.append
    ups = 0
    for cx, cy in zip(xs, ys):  # noqa: B905
        wx = cx - bx
        wy = cy - by
        push(ux * wy - uy * wx)
        if ux > 0.0 >= wx:
            ups += 1
        ux = wx
        uy = wy
        bx = cx
        by = cy
    if ups != 1:
        return 0.0
    crosses.sort()
    low, high = crosses[0], crosses[-1]
    return low if low > firm else high if high < -firm else 0.0


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
    small = _small_floats(points)
    if small is not None:  # the same decisions on Python floats
        part = _small_point_list_part(path, *small, name, center_of_mass, units)
        if part is not None:  # (always: no limit)
            return part
    try:
        pts = as_points(points)
    except PartError as exc:
        raise fail(path, str(exc)) from None
    check_coordinates(path, pts, "the point list")
    ring = _ring(pts)
    simple = len(ring) >= 3 and _is_simple(ring)
    concave = simple and not _is_convex(ring)
    return _outline_or_cloud(path, pts, ring, simple, concave, name, center_of_mass, units)


def _small_point_list_part(
    path: Path | str,
    xs: list[float],
    ys: list[float],
    name: str,
    center_of_mass: Any = None,
    units: str | None = None,
    limit: float = math.inf,
) -> Part | None:
    """:func:`point_list_part` of the coordinates :func:`_small_floats` gave.

    ``None`` when a coordinate is beyond ``limit`` (the caller reads the points another
    way).
    """
    sx, sy = sorted(xs), sorted(ys)  # (cheaper than min and max)
    x0, x1, y0, y1 = sx[0], sx[-1], sy[0], sy[-1]
    if not (-limit <= x0 and x1 <= limit and -limit <= y0 and y1 <= limit):
        return None
    least = _firm_turn(xs, ys, x0, x1, y0, y1)  # most files: convex, found in O(N)
    small = list(zip(xs, ys, strict=True))
    pts = np.array(small, dtype=np.float64)
    sring = _small_ring(small)
    if not least and 3 <= len(sring) < len(small):  # points repeated: firm without them?
        least = _firm_turn([p[0] for p in sring], [p[1] for p in sring], x0, x1, y0, y1)
    if least:
        simple, concave = True, False
    else:
        turns = _turns(sring) if len(sring) >= 3 else []
        simple = len(sring) >= 3 and _small_is_simple(sring, turns)
        concave = simple and not _small_is_convex(sring, turns)
    ring = np.array(sring, dtype=np.float64) if concave else pts
    return _outline_or_cloud(path, pts, ring, simple, concave, name, center_of_mass, units)


def _outline_or_cloud(
    path: Path | str,
    pts: FloatArray,
    ring: FloatArray,
    simple: bool,
    concave: bool,
    name: str,
    center_of_mass: Any,
    units: str | None,
) -> Part:
    """The part of the decisions: a non-convex outline, or the points' hull.

    ``path`` names the file in a message (a string: as ``Path(path)`` prints).
    """
    try:
        if concave:
            return Part.from_outline(ring, name=name, center_of_mass=center_of_mass, units=units)
        part = Part.from_points(pts, name=name, center_of_mass=center_of_mass, units=units)
    except PartError as exc:
        raise fail(Path(path), str(exc)) from None
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
    return _json_document_part(load_json(path, decode_text(path, data)), path, options)


# load_json's parser (numbers too large refused) and the default options, made once.
_DECODER = json.JSONDecoder(parse_int=json_int, parse_float=json_float)
# The first reading of a batch line, by orjson: it reads a number as json does (the nearest
# float, or the int), but an integer beyond 64 bits as a float, where json keeps the int; so a
# line read by it takes the fast path only when every coordinate is within 2^53, and a float
# there is what the strict decoder reads too (an integer literal would have stayed an int).
_FIRST_LIMIT = float(_EXACT_INT)
_NAMED_POINTS = {"name", "vertices"}
_DEFAULTS = ReadOptions()  # frozen


def json_line_part(text: str, name: str) -> Part | None:
    """The part of one line of a JSONL batch holding a part object, as :func:`parse_json`.

    The same part, or the same error, as ``parse_json(text.encode(), Path(name), ...)`` with
    the default options, without encoding the text and parsing it twice. ``None`` when the
    line is not a JSON object that parses cleanly (malformed, a number too large, nested too
    deep, too long, not an object): the caller then reads it the general way.

    Examples
    --------
    >>> json_line_part('{"vertices": [[0, 0], [3, 0], [0, 1]]}', "b.jsonl:1").hull.n_sides
    3
    >>> json_line_part('[1, 2]', "b.jsonl:2") is None
    True
    """
    if len(text) > MAX_BYTES // 4:  # UTF-8 may take 4 bytes a character: check the bytes
        return None
    try:
        doc = orjson.loads(text)
    except orjson.JSONDecodeError:  # NaN, a number beyond a float...: the strict decoder's
        doc = None
    if type(doc) is dict and doc.keys() <= _NAMED_POINTS:  # most lines: one look at them
        points, label = doc.get("vertices"), doc.get("name", name)
        small = _line_floats(points) if type(label) is str else None
        if small is not None:
            # Every number of the line is a coordinate; within 2^53, the strict decoder
            # reads the same line, and _json_document_part then reads the points so.
            if "name" not in doc:
                label = Path(name).stem
            part = _small_point_list_part(name, *small, label, limit=_FIRST_LIMIT)
            if part is not None:
                return part
    try:
        doc = _DECODER.decode(text)
    except Exception:  # any failure: the general path gives its error
        return None
    if not isinstance(doc, dict):
        return None
    # Nesting deeper than MAX_NESTING needs more brackets than that (counted in C).
    if text.count("[") + text.count("{") > MAX_NESTING and nesting_depth(doc) > MAX_NESTING:
        return None
    return _json_document_part(doc, Path(name), _DEFAULTS)


def _json_document_part(doc: Any, path: Path, options: ReadOptions) -> Part:
    """:func:`parse_json` of the parsed document."""
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
