"""Readers of part files; the format is chosen by the file's extension (or ``fmt``).

=========  ===================  =====================================================
format     extensions           what is read
=========  ===================  =====================================================
json       ``.json``            ``{"vertices": [[x, y], ...]}`` (a point list; any
                                GeoJSON object is read as GeoJSON)
csv        ``.csv``             one ``x,y`` row per point (a header row is allowed)
wkt        ``.wkt``             a ``POLYGON`` (interior rings are holes)
geojson    ``.geojson``         a ``Polygon`` geometry, feature or collection
svg        ``.svg``             the outline of a path, polygon, rect, circle or ellipse
dxf        ``.dxf``             closed polylines, circles, ellipses, splines, and loops
                                of lines and arcs
=========  ===================  =====================================================

Point lists (JSON, CSV) give the convex hull of their points. Outline formats (WKT,
GeoJSON, SVG, DXF) give an ordered outline that may be non-convex, with holes: the gripper
sees its convex hull, and the default centre of mass is the area centroid of the outline
minus its holes (:meth:`bayesgrasp.geometry.Part.from_outline`). Coordinates keep the file's
units, reported in :attr:`Part.units` (DXF ``$INSUNITS``; SVG millimetres when the document
has a physical size, else user units ``"px"``; ``"units"`` members of JSON and GeoJSON).

Curves (Bezier curves, arcs, circles, ellipses, splines) are flattened to a chordal
tolerance: no point of the curve is farther than ``tolerance`` from the polyline (default
0.1% of the drawing's diagonal). A file whose outlines flatten to more than ``max_points``
points (default :data:`MAX_POINTS` = 100 000) is refused, before the points are made.

Every failure is a :class:`~bayesgrasp.errors.PartFileError` whose message starts with the
file name and says why: missing, empty, truncated or of the wrong format, non-finite
coordinates, no closed outline, several candidate outlines and no choice, a
self-intersecting outline, too many points.

The readers of WKT and GeoJSON need shapely, SVG needs svgelements and DXF needs ezdxf
(the ``io`` extra: ``pip install 'bayesgrasp[io]'``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from ..errors import PartFileError
from ..geometry import Part
from ._common import DEFAULT_RELATIVE_TOLERANCE, MAX_POINTS, ReadOptions, fail

__all__ = [
    "DEFAULT_RELATIVE_TOLERANCE",
    "EXTENSIONS",
    "FORMATS",
    "MAX_POINTS",
    "ReadOptions",
    "read_part",
    "resolve_part",
]

Reader = Callable[[Path, ReadOptions], Part]


def _reader(fmt: str) -> Reader:
    """The reader of a format (modules are imported on demand)."""
    if fmt in ("json", "csv"):
        from . import points

        return points.read_json if fmt == "json" else points.read_csv
    if fmt == "wkt":
        from .wkt import read_wkt

        return read_wkt
    if fmt == "geojson":
        from .geojson import read_geojson

        return read_geojson
    if fmt == "svg":
        from .svg import read_svg

        return read_svg
    from .dxf import read_dxf

    return read_dxf


#: Format names, in the order the documentation lists them.
FORMATS = ("json", "csv", "wkt", "geojson", "svg", "dxf")

#: File extensions (lower case, without the dot) and their formats.
EXTENSIONS = {
    "json": "json",
    "csv": "csv",
    "wkt": "wkt",
    "geojson": "geojson",
    "svg": "svg",
    "dxf": "dxf",
}


def read_part(
    path: str | Path,
    fmt: str | None = None,
    *,
    element: str | None = None,
    layer: str | None = None,
    tolerance: float | None = None,
    max_points: int = MAX_POINTS,
) -> Part:
    """Read a part file.

    Parameters
    ----------
    path : str or Path
    fmt : str, optional
        One of :data:`FORMATS`; default from the extension.
    element : str, optional
        Which outline, when the file has several: an SVG element id, a GeoJSON feature
        ``id`` or ``properties.name``, or a polygon's index (GeoJSON, WKT).
    layer : str, optional
        DXF: read only this layer (case-insensitive).
    tolerance : float, optional
        Chordal tolerance of curve flattening, in the file's units (default 0.1% of the
        drawing's diagonal).
    max_points : int, optional
        Largest number of points the outlines may have (default :data:`MAX_POINTS`).

    Returns
    -------
    Part

    Raises
    ------
    PartFileError
        The file is missing, unreadable, of an unknown format, or holds no usable part; the
        message names the file and the reason.
    MissingExtraError
        The format needs a package of the ``io`` extra that is not installed.

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "plate.wkt"
    >>> _ = f.write_text("POLYGON ((0 0, 4 0, 4 1, 1 1, 1 3, 0 3, 0 0))")
    >>> p = read_part(f)
    >>> p.hull.n_sides, p.center_of_mass.round(4).tolist()
    (5, [1.5, 1.0])
    """
    p = Path(path)
    kind = (fmt or EXTENSIONS.get(p.suffix.lstrip(".").lower(), p.suffix.lstrip("."))).lower()
    if kind not in FORMATS:
        shown = kind or "(no extension)"
        raise fail(p, f"unknown part format {shown!r}; expected one of {', '.join(FORMATS)}")
    if not isinstance(max_points, int) or max_points < 3:
        raise PartFileError(f"`max_points` must be an integer >= 3; got {max_points!r}")
    options = ReadOptions(element, layer, tolerance, max_points)
    return _reader(kind)(p, options)


def resolve_part(
    spec: str,
    fmt: str | None = None,
    *,
    element: str | None = None,
    layer: str | None = None,
    tolerance: float | None = None,
    max_points: int = MAX_POINTS,
) -> Part:
    """A catalogue name (see :func:`bayesgrasp.shapes.names`) or a part file.

    The keyword options are those of :func:`read_part`.

    Examples
    --------
    >>> resolve_part("rectangle").hull.n_sides
    4
    """
    from ..shapes import names

    if fmt is None and spec in names():
        from ..shapes import load

        return load(spec)
    p = Path(spec)
    if not p.suffix and not p.exists() and fmt is None:
        raise PartFileError(
            f"{spec!r} is neither a catalogue part ({', '.join(names())}) nor a file"
        )
    return read_part(
        p, fmt, element=element, layer=layer, tolerance=tolerance, max_points=max_points
    )
