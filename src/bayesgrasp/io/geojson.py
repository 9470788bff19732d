"""GeoJSON part files: a ``Polygon`` geometry, feature or feature collection.

Interior rings are holes. Several polygons (features, or the parts of a ``MultiPolygon``)
need a choice: ``element`` is a feature's ``id`` or ``properties.name``, or the polygon's
index (0-based) in file order. Units come from ``properties.units`` (or a top-level
``"units"`` member); GeoJSON itself has none for plane coordinates. Parsing of geometries is
shapely's.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..geometry import Part
from ._common import ReadOptions, fail, need, pick, polygon_part, read_text, shapely_polygons

__all__ = ["geojson_part", "read_geojson"]


def read_geojson(path: Path, options: ReadOptions) -> Part:
    """Read a GeoJSON polygon.

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "tab.geojson"
    >>> _ = f.write_text(json.dumps({"type": "Feature", "properties": {"name": "tab",
    ...     "units": "mm"}, "geometry": {"type": "Polygon",
    ...     "coordinates": [[[0, 0], [3, 0], [3, 1], [0, 1], [0, 0]]]}}))
    >>> p = read_geojson(f, ReadOptions())
    >>> p.name, p.units, p.hull.n_sides
    ('tab', 'mm', 4)
    """
    text = read_text(path)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise fail(path, f"not valid JSON ({exc.msg} at line {exc.lineno})") from None
    return geojson_part(path, data, options)


def _features(data: Any) -> list[tuple[dict[str, Any], Any]]:
    """(properties, geometry) of each feature, or of a bare geometry."""
    kind = data.get("type")
    if kind == "FeatureCollection":
        feats = data.get("features")
        if not isinstance(feats, list):
            raise ValueError('a FeatureCollection needs a "features" list')
        return [f for item in feats for f in _features(item)]
    if kind == "Feature":
        props = data.get("properties") or {}
        if not isinstance(props, dict):
            raise ValueError('"properties" must be an object')
        if "id" in data:
            props = {"id": data["id"], **props}
        return [(props, data.get("geometry"))]
    return [({}, data)]


def geojson_part(path: Path, data: Any, options: ReadOptions) -> Part:
    """The part of a parsed GeoJSON object."""
    shapely = need("shapely")
    if not isinstance(data, dict) or not isinstance(data.get("type"), str):
        raise fail(path, 'not GeoJSON: expected an object with a "type" member')
    try:
        features = _features(data)
    except ValueError as exc:
        raise fail(path, f"not valid GeoJSON ({exc})") from None
    candidates: list[tuple[str, Any]] = []
    aliases: dict[str, int] = {}
    units_of: list[Any] = []
    for k, (props, geometry) in enumerate(features):
        if geometry is None:
            continue
        try:
            geom = shapely.geometry.shape(geometry)
        except (shapely.errors.GEOSException, ValueError, TypeError, KeyError, IndexError) as exc:
            raise fail(path, f"feature {k}: not a valid GeoJSON geometry ({exc})") from None
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
        raise fail(path, f'"units" must be a string; got {units!r}')
    name = label if not label.isdigit() else path.stem
    return polygon_part(path, polygon, name, units, options)
