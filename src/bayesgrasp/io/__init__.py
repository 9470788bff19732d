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
stl, obj,  ``.stl``, ``.obj``,  a solid (:mod:`bayesgrasp.solid.mesh`): the footprint
ply, 3mf,  ``.ply``, ``.3mf``,  of one of its resting poses (``element``: the pose,
glb        ``.glb``             default 0, the most probable; extra ``mesh``)
=========  ===================  =====================================================

Outline formats (WKT, GeoJSON, SVG, DXF) give an ordered outline that may be non-convex,
with holes: the gripper sees its convex hull, and the default centre of mass is the area
centroid of the outline minus its holes (:meth:`bayesgrasp.geometry.Part.from_outline`).
Point lists (JSON, CSV) are read in order: points that make a simple polygon in that order
(edges meeting only at consecutive points) are an outline like the others (area centroid,
no holes), so the same outline gives the same part from CSV, JSON and WKT; points that cross
themselves in order are a *point cloud*, and the part is their convex hull with the hull's
centroid as centre of mass (give ``"center_of_mass"`` in JSON when it is elsewhere). See
:mod:`bayesgrasp.io.points`. Coordinates keep the file's units, reported in
:attr:`Part.units` (DXF ``$INSUNITS``, ``None`` when the file has none; SVG millimetres when
the document has a physical size, else user units ``"px"``; ``"units"`` members of JSON and
GeoJSON).

Curves (Bezier curves, arcs, circles, ellipses, splines) are flattened to a chordal
tolerance: no point of the curve is farther than ``tolerance`` from the polyline (default
0.1% of the drawing's diagonal). An SVG or DXF outline with curves is a
:class:`~bayesgrasp.geometry.curved.CurvedPart`: its circular arcs stay exact, its other
curves keep that error bound and their exact form (:mod:`bayesgrasp.geometry.curved`).
A file whose outlines flatten to more than ``max_points``
points (default :data:`MAX_POINTS` = 100 000) is refused, before the points are made.

Parts can also be read from memory (:func:`read_part_bytes`: an upload, a pipe; nothing is
written to disk) and from standard input (``resolve_part("-", fmt)``, the command line's
``-``).

Every failure is a :class:`~bayesgrasp.errors.PartFileError` whose message starts with the
file name and says why: missing, empty, not a regular file, too large, not UTF-8, truncated
or of the wrong format, nested too deeply, non-finite or too large coordinates, no closed
outline, several candidate outlines and no choice, a self-intersecting outline, too many
points, entities or elements. The work a file can cause is bounded: see the limits
:data:`MAX_BYTES`, :data:`MAX_COORDINATE`, :data:`MAX_ENTITIES`, :data:`MAX_NESTING` and
:data:`MAX_POINTS`.

The readers of WKT and GeoJSON need shapely, SVG needs svgelements and DXF needs ezdxf
(the ``io`` extra: ``pip install 'bayesgrasp[io]'``).
"""

from __future__ import annotations

import functools
import numbers
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import PartFileError
from ..geometry import Part
from ..solid.mesh import MESH_FORMATS
from ._common import (
    DEFAULT_RELATIVE_TOLERANCE,
    MAX_BYTES,
    MAX_COORDINATE,
    MAX_ENTITIES,
    MAX_NESTING,
    MAX_POINTS,
    ReadOptions,
    check_bytes,
    fail,
    quote,
    read_bytes,
)

__all__ = [
    "DEFAULT_RELATIVE_TOLERANCE",
    "EXTENSIONS",
    "FORMATS",
    "MAX_BYTES",
    "MAX_COORDINATE",
    "MAX_ENTITIES",
    "MAX_NESTING",
    "MAX_POINTS",
    "STDIN",
    "ReadOptions",
    "read_part",
    "read_part_bytes",
    "resolve_part",
]

#: The part path that means standard input (:func:`resolve_part`).
STDIN = "-"

Parser = Callable[[bytes, Path, ReadOptions], Part]


def _parser(fmt: str) -> Parser:
    """The parser of a format: bytes to Part (modules are imported on demand)."""
    if fmt in ("json", "csv"):
        from . import points

        return points.parse_json if fmt == "json" else points.parse_csv
    if fmt in MESH_FORMATS:  # a solid: the footprint of one resting pose (bayesgrasp.solid)
        from ..solid.parts import mesh_part

        return functools.partial(mesh_part, fmt=fmt)
    if fmt == "wkt":
        from .wkt import parse_wkt

        return parse_wkt
    if fmt == "geojson":
        from .geojson import parse_geojson

        return parse_geojson
    if fmt == "svg":
        from .svg import parse_svg

        return parse_svg
    from .dxf import parse_dxf

    return parse_dxf


def _options(element: Any, layer: Any, tolerance: Any, max_points: Any) -> ReadOptions:
    """Validated reader options (PartFileError naming the parameter)."""
    for what, value in (("element", element), ("layer", layer)):
        if value is not None and not isinstance(value, str):
            raise PartFileError(
                f"`{what}` must be a string or None; got {type(value).__name__} ({value!r:.40})"
            )
    if tolerance is not None:
        if isinstance(tolerance, bool) or not isinstance(tolerance, numbers.Real):
            raise PartFileError(
                f"`tolerance` must be a number > 0 or None; got {type(tolerance).__name__} "
                f"({tolerance!r:.40})"
            )
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 3:
        raise PartFileError(f"`max_points` must be an integer >= 3; got {max_points!r:.40}")
    return ReadOptions(element, layer, None if tolerance is None else float(tolerance), max_points)


def _format(fmt: Any, path: Path | None) -> str:
    """The format name: ``fmt``, or from the extension of ``path``."""
    if fmt is not None and not isinstance(fmt, str):
        raise PartFileError(f"`fmt` must be a string or None; got {type(fmt).__name__}")
    suffix = path.suffix.lstrip(".") if path is not None else ""
    kind = (fmt or EXTENSIONS.get(suffix.lower(), suffix)).lower()
    if kind not in FORMATS:
        if path is not None and fmt is None and path.is_dir():
            raise fail(path, "is a folder, not a part file (sweep takes folders of parts)")
        shown = quote(kind) if kind else "(no extension)"
        message = f"unknown part format {shown}; expected one of {', '.join(FORMATS)}"
        raise fail(path, message) if path is not None else PartFileError(f"`fmt`: {message}")
    return kind


#: Format names, in the order the documentation lists them.
FORMATS = ("json", "csv", "wkt", "geojson", "svg", "dxf", *MESH_FORMATS)

#: File extensions (lower case, without the dot) and their formats.
EXTENSIONS = {
    "json": "json",
    "csv": "csv",
    "wkt": "wkt",
    "geojson": "geojson",
    "svg": "svg",
    "dxf": "dxf",
    **{f: f for f in MESH_FORMATS},
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
        A regular file of at most :data:`MAX_BYTES` bytes.
    fmt : str, optional
        One of :data:`FORMATS`; default from the extension.
    element : str, optional
        Which outline, when the file has several: an SVG element id, a GeoJSON feature
        ``id`` or ``properties.name``, or a polygon's index (GeoJSON, WKT). Refused for
        formats that have no such choice.
    layer : str, optional
        DXF: read only this layer (case-insensitive). Refused for other formats.
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
    if not isinstance(path, str | os.PathLike):
        raise PartFileError(f"`path` must be a str or Path; got {type(path).__name__}")
    p = Path(path)
    kind = _format(fmt, p)
    options = _options(element, layer, tolerance, max_points)
    return _parser(kind)(read_bytes(p), p, options)


def read_part_bytes(
    data: bytes,
    fmt: str,
    name: str = "<stdin>",
    *,
    element: str | None = None,
    layer: str | None = None,
    tolerance: float | None = None,
    max_points: int = MAX_POINTS,
) -> Part:
    r"""Read a part from the contents of a part file, in memory.

    Nothing is written to disk and ``name`` is never opened: it only names the part (its
    stem, as a file's would) and starts the error messages. For uploads and pipes.

    Parameters
    ----------
    data : bytes
        The contents of a part file, at most :data:`MAX_BYTES` bytes.
    fmt : str
        One of :data:`FORMATS` (there is no extension to go by).
    name : str, optional
        A file name for messages and the part's default name.
    element, layer, tolerance, max_points
        As for :func:`read_part`.

    Returns
    -------
    Part

    Raises
    ------
    PartFileError
        As for :func:`read_part`; the messages start with ``name``.
    MissingExtraError
        The format needs a package of the ``io`` extra that is not installed.

    Examples
    --------
    >>> p = read_part_bytes(b"0,0\n4,0\n4,1\n1,1\n1,3\n0,3\n", "csv", "plate.csv")
    >>> p.name, p.center_of_mass.round(4).tolist()
    ('plate', [1.5, 1.0])
    """
    if not isinstance(name, str):
        raise PartFileError(f"`name` must be a string; got {type(name).__name__}")
    if fmt is None:
        raise PartFileError(f"`fmt` is needed to read bytes; expected one of {', '.join(FORMATS)}")
    kind = _format(fmt, None)
    options = _options(element, layer, tolerance, max_points)
    if not isinstance(data, bytes | bytearray | memoryview):
        hint = " (encode text as UTF-8)" if isinstance(data, str) else ""
        raise PartFileError(f"`data` must be bytes; got {type(data).__name__}{hint}")
    p = Path(name)
    return _parser(kind)(check_bytes(p, bytes(data)), p, options)


def _read_stdin(fmt: str | None, **options: Any) -> Part:
    """A part from standard input (at most :data:`MAX_BYTES` bytes)."""
    if fmt is None:
        raise PartFileError(
            f"reading a part from standard input ({STDIN!r}) needs its format, one of "
            f"{', '.join(FORMATS)} (--format on the command line, `fmt` in the library)"
        )
    stream = getattr(sys.stdin, "buffer", None)
    if stream is None:
        raise PartFileError("standard input cannot be read as bytes")
    data = stream.read(MAX_BYTES + 1)
    return read_part_bytes(data, fmt, "<stdin>", **options)


def resolve_part(
    spec: str,
    fmt: str | None = None,
    *,
    element: str | None = None,
    layer: str | None = None,
    tolerance: float | None = None,
    max_points: int = MAX_POINTS,
) -> Part:
    """A catalogue name (see :func:`bayesgrasp.shapes.names`), a part file, or ``-``.

    ``-`` (:data:`STDIN`) reads the part from standard input; it needs ``fmt``. The keyword
    options are those of :func:`read_part`.

    Examples
    --------
    >>> resolve_part("rectangle").hull.n_sides
    4
    """
    from ..shapes import names

    if not isinstance(spec, str | os.PathLike):
        raise PartFileError(
            f"a part must be a catalogue name or a file path; got {type(spec).__name__}"
        )
    options: dict[str, Any] = {
        "element": element,
        "layer": layer,
        "tolerance": tolerance,
        "max_points": max_points,
    }
    if spec == STDIN:
        return _read_stdin(fmt, **options)
    if fmt is None and spec in names():
        from ..shapes import load

        return load(str(spec))
    p = Path(spec)
    if not p.suffix and not p.exists() and fmt is None:
        raise PartFileError(
            f"{quote(str(spec))} is neither a catalogue part ({', '.join(names())}) nor a file"
        )
    return read_part(p, fmt, **options)
