"""WKT part files: a ``POLYGON`` (its interior rings are holes).

A ``MULTIPOLYGON`` or ``GEOMETRYCOLLECTION`` with several polygons needs a choice:
``element`` is the polygon's index (0-based). Parsing is shapely's (GEOS). WKT has no units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..geometry import Part
from ._common import ReadOptions, fail, need, pick, polygon_part, read_text, shapely_polygons

__all__ = ["read_wkt"]


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
    shapely = need("shapely")
    text = read_text(path)
    try:
        with np.errstate(invalid="ignore"):  # NaN coordinates are reported below
            geom = shapely.from_wkt(text.strip())
    except (shapely.errors.GEOSException, ValueError) as exc:
        raise fail(path, f"not valid WKT ({exc})") from None
    polygons = shapely_polygons(geom)
    if not polygons:
        kind = "an empty geometry" if geom is None or geom.is_empty else f"a {geom.geom_type}"
        raise fail(path, f"no polygon: the file holds {kind}")
    index = pick(path, [str(i) for i in range(len(polygons))], options, "polygon")
    name = path.stem if len(polygons) == 1 else f"{path.stem}[{index}]"
    return polygon_part(path, polygons[index], name, None, options)
