"""What every reader shares: options, limits, errors naming the file, and outline assembly.

Limits on the work a file may cause, each refused with a message that names it:

- :data:`MAX_BYTES` (64 MiB): the bytes read from a file or given in memory; only regular
  files are read (a FIFO, a device such as ``/dev/zero`` or a socket is refused unopened);
- :data:`MAX_COORDINATE` (1e150): coordinates beyond it in absolute value (areas and
  cross products of such numbers overflow a float);
- :data:`MAX_ENTITIES` (100 000): DXF entities after block references are expanded, and SVG
  elements after ``<use>`` references are expanded;
- :data:`MAX_NESTING` (100): nesting depth of JSON arrays and objects, XML elements and WKT
  parentheses (part files need a handful of levels; parsers recurse, or crash, on deep ones);
- ``max_points`` (:data:`MAX_POINTS`): the points the outlines flatten to, and the segments of
  all the paths in an SVG file.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import files
from ..errors import MissingExtraError, PartError, PartFileError
from ..geometry import Part, find_crossing
from ._flatten import (
    FlattenBudget,
    Polyline,
    Ring,
    TooManyPoints,
    join,
    predicted_points,
)

__all__ = [
    "DEFAULT_RELATIVE_TOLERANCE",
    "MAX_BYTES",
    "MAX_COORDINATE",
    "MAX_ENTITIES",
    "MAX_NESTING",
    "MAX_POINTS",
    "ReadOptions",
    "Ring",
    "assemble_part",
    "brief",
    "check_bytes",
    "check_coordinates",
    "check_count",
    "chordal_tolerance",
    "decode_text",
    "fail",
    "flatten_rings",
    "load_json",
    "need",
    "pick",
    "polygon_part",
    "quote",
    "read_bytes",
    "read_text",
    "refuse_options",
    "shapely_polygons",
]

log = logging.getLogger("bayesgrasp.io")

FloatArray = NDArray[np.float64]

#: Largest number of points a part file may flatten to (all its curves together, after
#: ``layer``/``element`` filtering). Exact hull and diameter computations are O(N log N),
#: but an outline this fine is finer than any gripper can feel.
MAX_POINTS = 100_000

#: Default chordal tolerance, relative to the diagonal of the drawing's bounding box.
DEFAULT_RELATIVE_TOLERANCE = 1e-3

#: Largest part file, in bytes (64 MiB): read from disk or given in memory.
MAX_BYTES = files.MAX_BYTES

#: Largest coordinate magnitude: products of two coordinates (areas, cross products) must
#: not overflow a float, so :class:`~bayesgrasp.geometry.Part` refuses larger ones too.
MAX_COORDINATE = 1e150

#: Largest number of DXF entities (after expanding block references) or SVG elements (after
#: expanding ``<use>`` references) a file may hold.
MAX_ENTITIES = 100_000

#: Deepest nesting of JSON arrays and objects, XML elements or WKT parentheses.
MAX_NESTING = files.MAX_NESTING


@dataclass(frozen=True, slots=True)
class ReadOptions:
    """Options of the part readers.

    Parameters
    ----------
    element : str, optional
        Which candidate outline to use: an SVG element id (a shape, or a group whose shapes
        are taken together), a GeoJSON feature ``id`` or ``properties.name`` (or its index),
        a WKT polygon's index.
    layer : str, optional
        DXF only: use the entities of this layer (case-insensitive).
    tolerance : float, optional
        Chordal tolerance of curve flattening, in the file's units; default
        ``DEFAULT_RELATIVE_TOLERANCE`` times the diagonal of the drawing's bounding box.
    max_points : int
        Refuse files whose outlines flatten to more points (default :data:`MAX_POINTS`).
    """

    element: str | None = None
    layer: str | None = None
    tolerance: float | None = None
    max_points: int = MAX_POINTS


def fail(path: Path, reason: str) -> PartFileError:
    """The error for a part file: ``"<path>: <reason>"``, on one line.

    Reasons quoting a parser (GEOS, ezdxf, expat) may hold line breaks; they become spaces.
    """
    return PartFileError(f"{path}: {' '.join(reason.split())}")


def need(module: str) -> Any:
    """Import an optional package of the ``io`` extra, or raise MissingExtraError."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(module, "io") from None


def quote(text: str, limit: int = 60) -> str:
    """``repr`` of a piece of the file for a message, cut to ``limit`` characters."""
    return repr(text) if len(text) <= limit else repr(text[:limit]) + f" ... ({len(text)} chars)"


def brief(value: Any, limit: int = 60) -> str:
    """``repr`` of a value for a message, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + " ..."


def refuse_options(
    path: Path, options: ReadOptions, what: str, *, element: bool = False, layer: bool = False
) -> None:
    """Refuse ``element`` or ``layer`` for a file that has no such choice.

    ``what`` names the kind of file in the message; ``element`` and ``layer`` say which
    choices it has.
    """
    if options.element is not None and not element:
        hint = "; in DXF choose a `layer`" if layer else " (it holds one part)"
        raise fail(
            path,
            f"`element` applies to SVG, GeoJSON and WKT files, not to {what}{hint}; got "
            f"element={quote(options.element)}",
        )
    if options.layer is not None and not layer:
        hint = "; choose an outline with `element`" if element else ""
        raise fail(
            path,
            f"`layer` applies to DXF files, not to {what}{hint}; got layer={quote(options.layer)}",
        )


def _too_large(path: Path) -> PartFileError:
    return files.too_large(PartFileError, path, "part file")  # type: ignore[return-value]


def check_bytes(path: Path, data: bytes) -> bytes:
    """Refuse empty or oversized contents (:data:`MAX_BYTES`)."""
    if len(data) > MAX_BYTES:
        raise _too_large(path)
    if not data.strip():
        raise fail(path, "the file is empty")
    return data


def read_bytes(path: Path) -> bytes:
    """The part file's bytes (:func:`bayesgrasp.files.read_bytes`)."""
    return files.read_bytes(path, PartFileError, "part file")


def decode_text(path: Path, data: bytes) -> str:
    """The bytes as UTF-8 text (a byte-order mark is allowed)."""
    return files.decode_text(path, data, PartFileError)


def read_text(path: Path) -> str:
    """The file as UTF-8 text (a byte-order mark is allowed)."""
    return decode_text(path, read_bytes(path))


def load_json(path: Path, text: str) -> Any:
    """Parse JSON text; malformed, too deeply nested or oversized numbers are errors."""
    return files.load_json(path, text, PartFileError, "coordinates")


def check_coordinates(path: Path, points: FloatArray, what: str) -> None:
    """Refuse non-finite coordinates and coordinates beyond :data:`MAX_COORDINATE`."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if np.isnan(pts).any():
        raise fail(path, f"coordinates must be finite; {what} has a coordinate that is NaN")
    if np.isinf(pts).any():
        raise fail(
            path,
            f"coordinates too large: {what} has an infinite coordinate (beyond the range of a "
            f"float); the limit is {MAX_COORDINATE:g} in absolute value",
        )
    if pts.size:
        biggest = float(np.max(np.abs(pts)))
        if biggest > MAX_COORDINATE:
            raise fail(
                path,
                f"coordinates too large: {what} reaches {biggest:.3g}; the limit is "
                f"{MAX_COORDINATE:g} in absolute value (rescale the drawing's units)",
            )


def chordal_tolerance(path: Path, options: ReadOptions, bounds: FloatArray) -> float:
    """The tolerance to flatten with: the user's, or relative to the drawing's box."""
    if options.tolerance is not None:
        tol = float(options.tolerance)
        if not math.isfinite(tol) or tol <= 0:
            raise fail(path, f"the flattening tolerance must be a number > 0; got {tol!r}")
        return tol
    diag = float(np.hypot(*(bounds[1] - bounds[0])))
    if not math.isfinite(diag):
        raise fail(path, "coordinates must be finite; the drawing's extent is not")
    if diag == 0.0:
        raise fail(path, "the drawing has zero extent: no usable outline")
    return DEFAULT_RELATIVE_TOLERANCE * diag


def check_count(path: Path, count: int, options: ReadOptions) -> None:
    """Refuse a part with more points than allowed."""
    if count > options.max_points:
        raise fail(
            path,
            f"the outline has {count} points; the limit is {options.max_points} "
            "(simplify the outline or raise max_points)",
        )


def flatten_rings(
    path: Path, rings: Sequence[Ring], tol: float, options: ReadOptions
) -> list[Ring]:
    """Flatten every ring (the count is checked before any point is made)."""
    curves = [c for r in rings for c in r.curves]
    predicted = sum(predicted_points(curves, tol)) + len(rings)
    if predicted > options.max_points:
        count = f"{predicted}" if predicted < 10**12 else f"more than {10**12:.0e}"
        raise fail(
            path,
            f"the curves flatten to {count} points at chordal tolerance {tol:.6g}; the "
            f"limit is {options.max_points} (give a coarser tolerance)",
        )
    budget = FlattenBudget(options.max_points)
    out: list[Ring] = []
    try:
        for r in rings:
            pts = join(r.curves, tol, budget, r.source)
            if len(pts) > 1 and np.hypot(*(pts[-1] - pts[0])) <= tol:
                pts = pts[:-1]  # the closing point (within the gap tolerance of the start)
            if not np.all(np.isfinite(pts)):
                raise fail(path, f"{r.source} has coordinates that are not finite (NaN)")
            out.append(Ring(r.curves, r.source, r.group, pts))
    except TooManyPoints as exc:
        raise fail(
            path,
            f"{exc.what} flattens to more than {exc.limit} points at chordal tolerance "
            f"{tol:.6g} (give a coarser tolerance)",
        ) from None
    return out


def _nesting(path: Path, rings: Sequence[Ring]) -> tuple[list[int], set[int]]:
    """Depth of each ring (how many others contain it) and the indices of duplicate rings.

    Rings that cross or touch without one containing the other are an error.
    """
    shapely = need("shapely")
    for r in rings:
        hit = find_crossing([r.points])
        if hit is not None:
            p = r.points[hit[1]]
            raise fail(
                path, f"{r.source} is a self-intersecting outline (near {p[0]:.6g}, {p[1]:.6g})"
            )
    polys = [shapely.Polygon(r.points) for r in rings]
    tree = shapely.STRtree(polys)
    contains = tree.query(polys, predicate="contains")  # (2, M): [container, contained]
    inside = {(int(a), int(b)) for a, b in contains.T if a != b}
    # The same ring twice (a duplicated entity): keep the first.
    duplicates = {max(a, b) for a, b in inside if (b, a) in inside}
    meets = tree.query(polys, predicate="intersects")
    for a, b in meets.T:
        a, b = int(a), int(b)
        if a < b and (a, b) not in inside and (b, a) not in inside:
            p = shapely.get_coordinates(polys[a].boundary.intersection(polys[b].boundary))
            where = f" near ({p[0][0]:.6g}, {p[0][1]:.6g})" if len(p) else ""
            raise fail(path, f"{rings[a].source} and {rings[b].source} cross or touch{where}")
    depth = [0] * len(rings)
    for a, b in inside:
        if a not in duplicates and b not in duplicates:
            depth[b] += 1
    return depth, duplicates


def assemble_part(
    path: Path,
    rings: Sequence[Ring],
    name: str,
    units: str | None,
    choose: str,
    tol: float | None = None,
) -> Part:
    """The part of a set of flattened rings: one outer ring, the rings inside it are holes.

    Rings inside holes (an island in a hole, a drawn thread) are ignored and logged. More
    than one outer ring is an error that names the candidates and says how to choose
    (``choose``). With the chordal tolerance ``tol``, an outline with arcs or curves is a
    :class:`~bayesgrasp.geometry.curved.CurvedPart` (arcs exact; see :mod:`._curves`).
    """
    usable = [r for r in rings if len(r.points) >= 3]
    if not usable:
        raise fail(path, "no closed outline with at least 3 points")
    depth, duplicates = _nesting(path, usable)
    if duplicates:
        log.info("%s: ignored %d duplicated outline(s)", path, len(duplicates))
        usable = [r for i, r in enumerate(usable) if i not in duplicates]
        depth = [d for i, d in enumerate(depth) if i not in duplicates]
    outer = [r for r, d in zip(usable, depth, strict=True) if d == 0]
    if len(outer) > 1:
        listed = ", ".join(r.source for r in outer[:8]) + (", ..." if len(outer) > 8 else "")
        raise fail(path, f"{len(outer)} separate closed outlines ({listed}); {choose}")
    holes = [r for r, d in zip(usable, depth, strict=True) if d == 1]
    ignored = sum(1 for d in depth if d >= 2)
    if ignored:
        log.info("%s: ignored %d outline(s) nested inside holes", path, ignored)
    try:
        if tol is not None and any(
            not isinstance(c, Polyline) for r in (outer[0], *holes) for c in r.curves
        ):
            from ._curves import curved_assembly

            return curved_assembly(outer[0], holes, name, units, tol)
        return Part.from_outline(outer[0].points, [h.points for h in holes], name=name, units=units)
    except PartError as exc:
        raise fail(path, str(exc)) from None


def shapely_polygons(geom: Any) -> list[Any]:
    """The non-empty polygons of a shapely geometry, in order (collections flattened)."""
    out: list[Any] = []
    stack = [geom]
    while stack:
        g = stack.pop()
        if g is None or g.is_empty:
            continue
        kind = g.geom_type
        if kind == "Polygon":
            out.append(g)
        elif kind in ("MultiPolygon", "GeometryCollection"):
            stack.extend(reversed(list(g.geoms)))
    return out


def polygon_part(
    path: Path, polygon: Any, name: str, units: str | None, options: ReadOptions
) -> Part:
    """A part from a shapely polygon: exterior ring outline, interior rings holes."""
    rings = [np.asarray(polygon.exterior.coords, dtype=np.float64)[:, :2]]
    rings += [np.asarray(r.coords, dtype=np.float64)[:, :2] for r in polygon.interiors]
    check_count(path, sum(len(r) for r in rings), options)
    for k, r in enumerate(rings):
        check_coordinates(path, r, f"the {'exterior ring' if k == 0 else f'hole {k}'}")
    try:
        return Part.from_outline(rings[0], rings[1:], name=name, units=units)
    except PartError as exc:
        raise fail(path, str(exc)) from None


def pick(path: Path, labels: Sequence[str], options: ReadOptions, what: str) -> int:
    """Index of the candidate chosen by ``options.element`` (a label or an index).

    With no choice there must be exactly one candidate.
    """
    if not labels:
        raise fail(path, f"no {what} found")
    listed = ", ".join(labels[:12]) + (", ..." if len(labels) > 12 else "")
    if options.element is not None:
        if options.element in labels:
            return list(labels).index(options.element)
        index = options.element
        if index.isascii() and index.isdigit() and len(index) < 10 and int(index) < len(labels):
            return int(index)
        raise fail(path, f"no {what} {quote(options.element)}; found: {listed}")
    if len(labels) > 1:
        raise fail(
            path,
            f"{len(labels)} {what}s ({listed}); choose one with --element (name or index)",
        )
    return 0
