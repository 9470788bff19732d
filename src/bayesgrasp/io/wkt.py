"""WKT part files: a ``POLYGON`` (its interior rings are holes).

A ``MULTIPOLYGON`` or ``GEOMETRYCOLLECTION`` with several polygons needs a choice:
``element`` is the polygon's index (0-based). Parsing is shapely's (GEOS). WKT has no units.
Parentheses may nest at most :data:`~bayesgrasp.io._common.MAX_NESTING` deep (GEOS's parser
recurses on them and crashes on very deep nesting, so the text is checked first).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..geometry import Part
from ._common import (
    MAX_NESTING,
    ReadOptions,
    decode_text,
    fail,
    need,
    pick,
    polygon_part,
    read_bytes,
    refuse_options,
    shapely_polygons,
)

__all__ = ["parse_wkt", "read_wkt"]


def _paren_depth(data: bytes) -> int:
    """Deepest nesting of parentheses (a running sum over the bytes, vectorised)."""
    b = np.frombuffer(data, dtype=np.uint8)
    step = (b == ord("(")).astype(np.int64) - (b == ord(")")).astype(np.int64)
    return int(np.cumsum(step).max()) if len(step) else 0


def parse_wkt(data: bytes, path: Path, options: ReadOptions) -> Part:
    """Read a WKT polygon from the file's bytes.

    Examples
    --------
    >>> parse_wkt(b"POLYGON ((0 0, 4 0, 4 2, 0 0))", Path("t.wkt"), ReadOptions()).hull.n_sides
    3
    """
    shapely = need("shapely")
    text = decode_text(path, data)
    refuse_options(path, options, "a WKT file", element=True)
    depth = _paren_depth(data)
    if depth > MAX_NESTING:
        raise fail(path, f"parentheses nest {depth} deep; the limit is {MAX_NESTING}")
    try:
        with np.errstate(invalid="ignore", over="ignore"):  # NaN and inf: reported below
            geom = shapely.from_wkt(text.strip())
    except (shapely.errors.ShapelyError, ValueError) as exc:
        raise fail(path, f"not valid WKT ({str(exc)[:200]})") from None
    polygons = shapely_polygons(geom)
    if not polygons:
        kind = "an empty geometry" if geom is None or geom.is_empty else f"a {geom.geom_type}"
        raise fail(path, f"no polygon: the file holds {kind}")
    index = pick(path, [str(i) for i in range(len(polygons))], options, "polygon")
    name = path.stem if len(polygons) == 1 else f"{path.stem}[{index}]"
    return polygon_part(path, polygons[index], name, None, options)


def read_wkt(path: Path, options: ReadOptions) -> Part:
    """Read a WKT polygon.

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "plate.wkt"
    >>> _ = f.write_text("POLYGON ((0 0, 4 0, 4 2, 0 2, 0 0), (1 0.5, 1 1.5, 2 1.5, 1 0.5))")
    >>> p = read_wkt(f, ReadOptions())
    >>> p.hull.n_sides, len(p.holes)
    (4, 1)
    """
    return parse_wkt(read_bytes(path), path, options)
