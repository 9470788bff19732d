"""Point-list part files: JSON and CSV.

``.json``: ``{"name": ..., "vertices": [[x, y], ...]}`` with optional ``"units"`` and
``"center_of_mass"`` (or a bare list of points). A JSON file holding a GeoJSON object is read
as GeoJSON. ``.csv``: one ``x,y`` row per point; a header row is allowed.

The points may be in any order: the part is their convex hull (:meth:`Part.from_points`),
and the default centre of mass is the hull's centroid.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

from ..errors import PartError
from ..geometry import Part
from ._common import ReadOptions, check_count, fail, read_text

__all__ = ["read_csv", "read_json"]

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
    text = read_text(path)
    try:
        data: Any = json.loads(text)
    except json.JSONDecodeError as exc:
        raise fail(path, f"not valid JSON ({exc.msg} at line {exc.lineno})") from None
    if isinstance(data, dict) and data.get("type") in GEOJSON_TYPES and "vertices" not in data:
        from .geojson import geojson_part

        return geojson_part(path, data, options)
    if isinstance(data, list):
        data = {"vertices": data}
    if not isinstance(data, dict) or "vertices" not in data:
        raise fail(path, 'expected an object with "vertices": [[x, y], ...]')
    name = data.get("name", path.stem)
    units = data.get("units")
    if not isinstance(name, str) or (units is not None and not isinstance(units, str)):
        raise fail(path, '"name" and "units" must be strings')
    if isinstance(data["vertices"], list):
        check_count(path, len(data["vertices"]), options)
    try:
        return Part.from_points(
            data["vertices"], name=name, center_of_mass=data.get("center_of_mass"), units=units
        )
    except PartError as exc:
        raise fail(path, str(exc)) from None


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
    text = read_text(path)
    rows = [r for r in csv.reader(text.splitlines()) if r and any(c.strip() for c in r)]
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
            raise fail(path, f"row {n} is not two numbers: {','.join(row)!r}") from None
        if not all(math.isfinite(v) for v in pts[-1]):
            raise fail(path, f"row {n} is not finite: {','.join(row)!r}")
    if not pts:
        raise fail(path, "no points found; expected one x,y row per point")
    try:
        return Part.from_points(pts, name=path.stem)
    except PartError as exc:
        raise fail(path, str(exc)) from None
