"""GeoJSON part files: a ``Polygon`` geometry, feature or feature collection.

Interior rings are holes. Several polygons (features, or the parts of a ``MultiPolygon``)
need a choice: ``element`` is a feature's ``id`` or ``properties.name``, or the polygon's
index (0-based) in file order. Units come from ``properties.units`` (or a top-level
``"units"`` member); GeoJSON itself has none for plane coordinates.

The document's structure and every coordinate are checked before shapely builds the
geometries: features must be objects, geometries objects or ``null`` with a known ``type``,
positions ``[x, y]`` or ``[x, y, z]`` of finite numbers (not strings or booleans) no larger
than :data:`~bayesgrasp.io._common.MAX_COORDINATE`; at most
:data:`~bayesgrasp.io._common.MAX_ENTITIES` features and geometries.
"""

from __future__ import annotations

import math
import numbers
from pathlib import Path
from typing import Any

from ..geometry import Part
from ._common import (
    MAX_COORDINATE,
    MAX_ENTITIES,
    ReadOptions,
    brief,
    decode_text,
    fail,
    load_json,
    need,
    pick,
    polygon_part,
    read_bytes,
    refuse_options,
    shapely_polygons,
)

__all__ = ["geojson_part", "parse_geojson", "read_geojson"]

# Nesting depth of the coordinates of each geometry type (a position is depth 1).
_COORDINATE_DEPTH = {
    "Point": 1,
    "MultiPoint": 2,
    "LineString": 2,
    "MultiLineString": 3,
    "Polygon": 3,
    "MultiPolygon": 4,
}


class _Invalid(ValueError):
    """A GeoJSON document that breaks the format (turned into PartFileError)."""


def _kind(value: Any) -> str:
    return "null" if value is None else f"a {type(value).__name__}"


def _check_position(pos: Any, where: str) -> None:
    if not isinstance(pos, list) or len(pos) not in (2, 3):
        raise _Invalid(f"{where} must be a position [x, y] or [x, y, z]; got {_kind(pos)}")
    for k, v in enumerate(pos):
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise _Invalid(f"{where}[{k}] must be a number; got {_kind(v)} ({brief(v)})")
        if not math.isfinite(v):
            raise _Invalid(f"{where}[{k}]: coordinates must be finite; got {v!r}")
        if abs(float(v)) > MAX_COORDINATE:
            raise _Invalid(
                f"{where}[{k}]: coordinates too large ({float(v):.3g}); the limit is "
                f"{MAX_COORDINATE:g} in absolute value (rescale the units)"
            )


def _check_coordinates(coords: Any, depth: int, where: str) -> None:
    """Check nested coordinate arrays of the given depth (iterative)."""
    stack: list[tuple[Any, int, str]] = [(coords, depth, where)]
    while stack:
        item, d, at = stack.pop()
        if d == 1:
            _check_position(item, at)
        elif not isinstance(item, list):
            raise _Invalid(f"{at} must be an array; got {_kind(item)}")
        else:
            stack.extend((c, d - 1, f"{at}[{k}]") for k, c in enumerate(item))


def _check_geometry(geometry: Any, where: str, budget: list[int]) -> None:
    """Check a geometry object before shapely sees it (collections iteratively)."""
    stack = [(geometry, where)]
    while stack:
        g, at = stack.pop()
        budget[0] += 1
        if budget[0] > MAX_ENTITIES:
            raise _Invalid(f"more than {MAX_ENTITIES} features and geometries (the limit)")
        if not isinstance(g, dict):
            raise _Invalid(f"{at} must be a geometry object or null; got {_kind(g)}")
        kind = g.get("type")
        if kind == "GeometryCollection":
            members = g.get("geometries")
            if not isinstance(members, list):
                raise _Invalid(f'{at}: a GeometryCollection needs a "geometries" list')
            stack.extend((m, f"{at}.geometries[{k}]") for k, m in enumerate(members))
        elif isinstance(kind, str) and kind in _COORDINATE_DEPTH:
            if "coordinates" not in g:
                raise _Invalid(f'{at}: a {kind} needs "coordinates"')
            _check_coordinates(g["coordinates"], _COORDINATE_DEPTH[kind], f"{at}.coordinates")
        else:
            known = ", ".join([*_COORDINATE_DEPTH, "GeometryCollection"])
            raise _Invalid(f"{at} has an unknown geometry type {brief(kind)}; expected {known}")


def _features(data: dict[str, Any]) -> list[tuple[dict[str, Any], Any, str]]:
    """(properties, geometry, where) of each feature, or of a bare geometry."""
    out: list[tuple[dict[str, Any], Any, str]] = []
    stack: list[tuple[Any, str]] = [(data, "feature 0")]
    count = 0
    while stack:
        item, where = stack.pop()
        count += 1
        if count > MAX_ENTITIES:
            raise _Invalid(f"more than {MAX_ENTITIES} features (the limit)")
        if not isinstance(item, dict):
            raise _Invalid(f"{where} must be a Feature object; got {_kind(item)}")
        kind = item.get("type")
        if kind == "FeatureCollection":
            feats = item.get("features")
            if not isinstance(feats, list):
                raise _Invalid(f'{where}: a FeatureCollection needs a "features" list')
            stack.extend((f, f"feature {k}") for k, f in reversed(list(enumerate(feats))))
        elif kind == "Feature":
            props = item.get("properties")
            props = {} if props is None else props
            if not isinstance(props, dict):
                raise _Invalid(
                    f'{where}: "properties" must be an object or null; got {_kind(props)}'
                )
            if "id" in item:
                props = {"id": item["id"], **props}
            out.append((props, item.get("geometry"), where))
        else:
            out.append(({}, item, where))
    return out


def geojson_part(path: Path, data: Any, options: ReadOptions) -> Part:
    """The part of a parsed GeoJSON object.

    Examples
    --------
    >>> doc = {"type": "Polygon", "coordinates": [[[0, 0], [3, 0], [3, 1], [0, 1], [0, 0]]]}
    >>> geojson_part(Path("tab.geojson"), doc, ReadOptions()).hull.n_sides
    4
    """
    shapely = need("shapely")
    refuse_options(path, options, "a GeoJSON file", element=True)
    if not isinstance(data, dict) or not isinstance(data.get("type"), str):
        raise fail(path, 'not GeoJSON: expected an object with a "type" member')
    try:
        features = _features(data)
    except _Invalid as exc:
        raise fail(path, f"not valid GeoJSON ({exc})") from None
    budget = [len(features)]
    for _, geometry, where in features:
        if geometry is not None:
            try:
                _check_geometry(geometry, "geometry", budget)
            except _Invalid as exc:
                raise fail(path, f"{where}: not a valid GeoJSON geometry ({exc})") from None
    candidates: list[tuple[str, Any]] = []
    aliases: dict[str, int] = {}
    units_of: list[Any] = []
    for props, geometry, where in features:
        if geometry is None:
            continue
        try:
            geom = shapely.geometry.shape(geometry)
        except (shapely.errors.ShapelyError, ValueError, TypeError, KeyError, IndexError) as exc:
            raise fail(path, f"{where}: not a valid GeoJSON geometry ({exc})") from None
        polys = shapely_polygons(geom)
        keys = [str(props[key]) for key in ("name", "id") if props.get(key) is not None]
        for j, poly in enumerate(polys):
            suffix = f".{j}" if len(polys) > 1 else ""
            label = (keys[0] + suffix) if keys else str(len(candidates))
            for key in keys[1:]:
                aliases[key + suffix] = len(candidates)
            candidates.append((label, poly))
            units_of.append(props.get("units", data.get("units")))
    if options.element in aliases:
        index = aliases[options.element]
    else:
        index = pick(path, [c[0] for c in candidates], options, "polygon")
    label, polygon = candidates[index]
    units = units_of[index]
    if units is not None and not isinstance(units, str):
        raise fail(path, f'"units" must be a string; got {brief(units)}')
    name = label if not label.isdigit() else path.stem
    return polygon_part(path, polygon, name, units, options)


def parse_geojson(data: bytes, path: Path, options: ReadOptions) -> Part:
    """Read a GeoJSON polygon from the file's bytes (UTF-8).

    Examples
    --------
    >>> doc = b'{"type": "Polygon", "coordinates": [[[0, 0], [3, 0], [0, 1], [0, 0]]]}'
    >>> parse_geojson(doc, Path("w.geojson"), ReadOptions()).hull.n_sides
    3
    """
    return geojson_part(path, load_json(path, decode_text(path, data)), options)


def read_geojson(path: Path, options: ReadOptions) -> Part:
    """Read a GeoJSON polygon.

    Examples
    --------
    >>> import json, tempfile
    >>> f = Path(tempfile.mkdtemp()) / "tab.geojson"
    >>> _ = f.write_text(json.dumps({"type": "Feature", "properties": {"name": "tab",
    ...     "units": "mm"}, "geometry": {"type": "Polygon",
    ...     "coordinates": [[[0, 0], [3, 0], [3, 1], [0, 1], [0, 0]]]}}))
    >>> p = read_geojson(f, ReadOptions())
    >>> p.name, p.units, p.hull.n_sides
    ('tab', 'mm', 4)
    """
    return parse_geojson(read_bytes(path), path, options)
