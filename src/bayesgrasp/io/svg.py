"""SVG part files: the outline of one shape element (path, polygon, rect, circle, ellipse).

Parsing is svgelements'. Each closed subpath of the chosen element is a ring; the outer ring
is the outline, rings inside it are holes. Transforms (the element's, its groups' and the
viewBox's) are applied exactly to the control points: lines and Bezier curves are affine
invariant and an elliptic arc's image is an elliptic arc, so the flattening bound holds in
the final coordinates.

- Choosing: with several shapes that have a closed outline, ``element`` names one by its
  ``id`` (a group's id takes the shapes inside it together).
- Units: when the root ``<svg>`` has a physical ``width`` (mm, cm, in, pt, pc, Q) the
  coordinates are converted to millimetres (``units="mm"``); otherwise they stay in user
  units, CSS pixels (``units="px"``).
- Axes: SVG's y axis points down; the reader negates y so the part appears as drawn, with
  x to the right and y up (a mirror image would have a different squeeze function).
- Limits: before svgelements parses the file, the XML is checked: elements nest at most
  :data:`~bayesgrasp.io._common.MAX_NESTING` deep, there are at most
  :data:`~bayesgrasp.io._common.MAX_ENTITIES` elements once ``<use>`` references are
  expanded (a ``<use>`` that refers to itself is refused), and the paths and polygons have
  at most ``max_points`` segments in all (each segment flattens to at least one point).
- Refused: negative ``width``, ``height``, ``r``, ``rx`` or ``ry`` (an error in SVG), and
  coordinates that are not finite or larger than
  :data:`~bayesgrasp.io._common.MAX_COORDINATE` after the transforms.
"""

from __future__ import annotations

import io
import logging
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..geometry import Part
from ._common import (
    MAX_ENTITIES,
    MAX_NESTING,
    ReadOptions,
    Ring,
    assemble_part,
    check_coordinates,
    chordal_tolerance,
    fail,
    flatten_rings,
    need,
    quote,
    read_bytes,
    refuse_options,
)
from ._flatten import Bezier, Curve, EllipticArc, Polyline

__all__ = ["parse_svg", "read_svg"]

log = logging.getLogger("bayesgrasp.io")

FloatArray = NDArray[np.float64]

MM_PER_PX = 25.4 / 96.0  # CSS: 96 px per inch
_PHYSICAL = re.compile(
    r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(mm|cm|in|pt|pc|q)\s*$", re.IGNORECASE
)
_MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "in": 25.4, "pt": 25.4 / 72, "pc": 25.4 / 6, "q": 0.25}
_NOT_FINITE = re.compile(r"(?i)\bnan\b|\binf")
_GEOMETRY_ATTRS = (
    "d",
    "points",
    "x",
    "y",
    "width",
    "height",
    "cx",
    "cy",
    "r",
    "rx",
    "ry",
    "transform",
)

_COMMAND = re.compile(r"([MmLlHhVvCcSsQqTtAaZz])([^MmLlHhVvCcSsQqTtAaZz]*)")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_ARITY = {"m": 2, "l": 2, "t": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "a": 7, "z": 0}
_SHAPE_SEGMENTS = {"rect": 4, "circle": 4, "ellipse": 4, "line": 1}
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"


def _path_segments(d: str) -> int:
    """Number of segments of path data (each command's numbers over its arity)."""
    total = 0
    for letter, args in _COMMAND.findall(d):
        arity = _ARITY[letter.lower()]
        if arity == 0:
            total += 1
        else:
            total += max(1, -(-len(_NUMBER.findall(args)) // arity))
    return total


def _own_segments(tag: str, el: ET.Element) -> int:
    if tag == "path":
        return _path_segments(el.get("d", ""))
    if tag in ("polygon", "polyline"):
        return len(_NUMBER.findall(el.get("points", ""))) // 2 + 1
    if tag == "rect" and (el.get("rx") or el.get("ry")):
        return 8  # four sides and four rounded corners
    return _SHAPE_SEGMENTS.get(tag, 0)


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _prescan(path: Path, data: bytes, options: ReadOptions) -> None:
    """Bound the work before svgelements parses the file (depth, elements, segments).

    svgelements expands every ``<use>`` by copying its target, recursively, and parses all
    path data eagerly: a few kilobytes of nested ``<use>`` can stand for millions of elements.
    """
    try:
        root = ET.fromstring(data)  # expat: entity-expansion bombs are refused by the parser
    except ET.ParseError as exc:
        head = data[:200].lower()
        try:
            data.decode("utf-8")
        except UnicodeDecodeError as bad:
            if b"encoding=" not in head:
                raise fail(
                    path,
                    f"not a readable SVG file (not UTF-8 text: byte {bad.start} is "
                    f"0x{data[bad.start]:02x} and no encoding is declared)",
                ) from None
        raise fail(path, f"not a readable SVG file (ParseError: {exc})") from None
    if _local(root.tag) != "svg":
        raise fail(path, f"not an SVG document (the root element is <{_local(root.tag)}>)")
    ids: dict[str, ET.Element] = {}
    stack: list[tuple[ET.Element, int]] = [(root, 1)]
    while stack:
        el, depth = stack.pop()
        if depth > MAX_NESTING:
            raise fail(path, f"elements nest deeper than the limit of {MAX_NESTING} levels")
        ident = el.get("id")
        if ident is not None:
            ids.setdefault(ident, el)
        stack.extend((child, depth + 1) for child in el)

    def target(el: ET.Element) -> ET.Element | None:
        if _local(el.tag) != "use":
            return None
        href = el.get("href") or el.get(_XLINK_HREF) or ""
        return ids.get(href[1:]) if href.startswith("#") else None

    # (elements, segments) of each subtree with its <use> targets expanded, post-order.
    # Counts saturate just past their limits: a bomb's totals stay small integers.
    n_cap, s_cap = MAX_ENTITIES + 1, options.max_points + 1
    memo: dict[int, tuple[int, int]] = {}
    started: set[int] = set()
    work: list[tuple[ET.Element, bool]] = [(root, False)]
    while work:
        el, done = work.pop()
        key = id(el)
        ref = target(el)
        if done:
            n, segs = 1, _own_segments(_local(el.tag), el)
            for sub in [*el, *([ref] if ref is not None else [])]:
                dn, ds = memo[id(sub)]
                n, segs = min(n + dn, n_cap), min(segs + ds, s_cap)
            memo[key] = (n, segs)
            started.discard(key)
            continue
        if key in memo:
            continue
        if key in started:
            raise fail(path, f"<use> references form a cycle through id={quote(el.get('id', ''))}")
        started.add(key)
        work.append((el, True))
        if ref is not None:
            if id(ref) in started:
                raise fail(
                    path, f"a <use> refers to its own ancestor id={quote(ref.get('id', ''))}"
                )
            work.append((ref, False))
        work.extend((child, False) for child in el)
    elements, segments = memo[id(root)]
    if elements > MAX_ENTITIES:
        raise fail(
            path,
            f"the drawing has more than {MAX_ENTITIES} elements with <use> references "
            f"expanded; the limit is {MAX_ENTITIES}",
        )
    if segments > options.max_points:
        count = f"more than {options.max_points}" if segments >= s_cap else str(segments)
        raise fail(
            path,
            f"the paths and shapes have {count} segments in all; the limit is max_points = "
            f"{options.max_points} (remove other drawings from the file; `max_points` in "
            "the library)",
        )


def _check_sizes(element: Any, label: str, svgelements: Any, path: Path) -> None:
    """Refuse negative sizes (an error in SVG; svgelements would draw them mirrored)."""
    if isinstance(element, svgelements.Rect):
        sizes = {"width": element.width, "height": element.height}
        sizes |= {k: getattr(element, k) for k in ("rx", "ry") if k in element.values}
    elif isinstance(element, svgelements.Circle):
        sizes = {"r": element.rx}
    elif isinstance(element, svgelements.Ellipse):
        sizes = {"rx": element.rx, "ry": element.ry}
    else:
        return
    for attr, value in sizes.items():
        if value is not None and float(value) < 0:
            raise fail(
                path, f"{label} has a negative {attr} ({float(value):g}); sizes must be >= 0"
            )


def _label(element: Any, index: int) -> str:
    tag = type(element).__name__.lower()
    ident = getattr(element, "id", None)
    return f"<{tag} id={ident!r}>" if ident else f"<{tag}> number {index}"


class _Affine:
    """The map from SVG user coordinates to the part's: matrix, unit scale, y flip."""

    def __init__(self, matrix: Any, scale: float) -> None:
        lin = np.array([[matrix.a, matrix.c], [matrix.b, matrix.d]], dtype=np.float64)
        flip = np.diag([scale, -scale])
        self.linear = flip @ lin
        self.offset = flip @ np.array([matrix.e, matrix.f], dtype=np.float64)

    def points(self, pts: Any) -> FloatArray:
        arr = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
        out: FloatArray = arr @ self.linear.T + self.offset
        return out

    def vector(self, v: FloatArray) -> FloatArray:
        out: FloatArray = self.linear @ v
        return out


def _xy(p: Any) -> tuple[float, float]:
    return (float(p[0]), float(p[1]))


def _subpaths(element: Any, svgelements: Any) -> list[tuple[list[Any], bool]]:
    """Each subpath of a shape as (segments, closed), in the element's own coordinates.

    Degenerate lines (start = end) are dropped; a subpath is closed by a ``Z`` or when its
    ends meet (within 1e-12 of its extent: an affine map keeps that, up to round-off).
    Plain floats, no arrays: this runs on every shape of the file.
    """
    found: list[list[Any]] = []
    flags: list[bool] = []
    segs: list[Any] = []
    closed = False
    for seg in element.segments(transformed=False):
        if isinstance(seg, svgelements.Move):
            if segs:
                found.append(segs)
                flags.append(closed)
            segs, closed = [], False
            continue
        if isinstance(seg, svgelements.Close):
            closed = True
        if isinstance(seg, svgelements.Line | svgelements.Close) and _xy(seg.start) == _xy(seg.end):
            continue
        segs.append(seg)
    if segs:
        found.append(segs)
        flags.append(closed)
    out = []
    for segs, is_closed in zip(found, flags, strict=True):
        if not is_closed:
            xs = [v for g in segs for v in (float(g.start[0]), float(g.end[0]))]
            ys = [v for g in segs for v in (float(g.start[1]), float(g.end[1]))]
            size = max(max(xs) - min(xs), max(ys) - min(ys)) or 1.0
            (x0, y0), (x1, y1) = _xy(segs[0].start), _xy(segs[-1].end)
            is_closed = max(abs(x1 - x0), abs(y1 - y0)) <= 1e-12 * size
        out.append((segs, is_closed))
    return out


def _curves(
    subpaths: list[tuple[list[Any], bool]], affine: _Affine, svgelements: Any
) -> list[tuple[list[Curve], bool]]:
    """Each subpath as (curves, closed), in the part's coordinates."""
    out: list[tuple[list[Curve], bool]] = []
    for segs, closed in subpaths:
        curves: list[Curve] = []
        for seg in segs:
            start, end = _xy(seg.start), _xy(seg.end)
            if isinstance(seg, svgelements.QuadraticBezier):
                curves.append(Bezier(affine.points([start, _xy(seg.control), end])))
            elif isinstance(seg, svgelements.CubicBezier):
                ctrl = [start, _xy(seg.control1), _xy(seg.control2), end]
                curves.append(Bezier(affine.points(ctrl)))
            elif isinstance(seg, svgelements.Arc):
                curves.append(_arc(seg, affine))
            else:  # Line and Close
                curves.append(Polyline(affine.points([start, end])))
        out.append((curves, closed))
    return out


def _overflowed_arc(seg: Any, svgelements: Any) -> bool:
    """Whether svgelements' centre form of an arc overflowed (its squares pass 1e308)."""
    if not isinstance(seg, svgelements.Arc) or seg.rx == 0 or seg.ry == 0:
        return False
    return not np.all(np.isfinite([*_xy(seg.center), float(seg.rx), float(seg.ry)]))


def _arc(seg: Any, affine: _Affine) -> Curve:
    """An SVG arc (svgelements computes the centre form, radii corrected as the spec says)."""
    start, end = affine.points([_xy(seg.start), _xy(seg.end)])
    if seg.rx == 0 or seg.ry == 0 or seg.sweep == 0:
        return Polyline(np.array([start, end]))
    phi = float(seg.get_rotation())
    major = seg.rx * np.array([np.cos(phi), np.sin(phi)])
    minor = seg.ry * np.array([-np.sin(phi), np.cos(phi)])
    center = affine.points([_xy(seg.center)])[0]
    return EllipticArc(
        center,
        affine.vector(major),
        affine.vector(minor),
        float(seg.get_start_t()),
        float(seg.sweep),
        pin=(start, end),
    )


def _unit_scale(svg: Any) -> tuple[float, str]:
    """Millimetres per unit of svgelements' output coordinates, and the units reported.

    svgelements maps the viewBox onto the document's width in its own pixels, so with a
    viewBox the exact scale is the physical width over that pixel width (whatever constant
    svgelements uses); without one, user units are CSS pixels (25.4 / 96 mm).
    """
    width = svg.values.get("width")
    match = _PHYSICAL.match(width) if isinstance(width, str) else None
    if match is None:
        return 1.0, "px"
    width_mm = float(match.group(1)) * _MM_PER_UNIT[match.group(2).lower()]
    px = float(svg.width or 0.0)
    if svg.values.get("viewBox") and px > 0 and width_mm > 0:
        return width_mm / px, "mm"
    return MM_PER_PX, "mm"


def parse_svg(data: bytes, path: Path, options: ReadOptions) -> Part:
    """Read the outline of one SVG shape from the file's bytes.

    Examples
    --------
    >>> doc = b'<svg xmlns="http://www.w3.org/2000/svg"><rect id="r" width="3" height="1"/></svg>'
    >>> p = parse_svg(doc, Path("r.svg"), ReadOptions())
    >>> p.name, p.units, p.hull.n_sides
    ('r', 'px', 4)
    """
    svgelements = need("svgelements")
    refuse_options(path, options, "an SVG file", element=True)
    _prescan(path, data, options)
    try:
        svg = svgelements.SVG.parse(io.BytesIO(data), reify=False)
        every = list(svg.elements())
    except Exception as exc:  # the XML parser and svgelements raise many types on bad input
        detail = f"{type(exc).__name__}: {str(exc)[:200]}"
        raise fail(path, f"not a readable SVG file ({detail})") from None
    if not isinstance(svg, svgelements.SVG):
        raise fail(path, "not an SVG document (no <svg> root element)")
    scale, units = _unit_scale(svg)

    shapes = [e for e in every if isinstance(e, svgelements.Shape)]
    # svgelements' elements compare by value (slow, and equal shapes are not the same
    # element): index them by identity.
    index_of = {id(e): i for i, e in enumerate(shapes)}
    subpaths_of: dict[int, list[tuple[list[Any], bool]]] = {}

    def subpaths(element: Any, label: str) -> list[tuple[list[Any], bool]]:
        if id(element) not in subpaths_of:
            values = element.values
            for attr in _GEOMETRY_ATTRS:
                value = values.get(attr)
                if isinstance(value, str) and _NOT_FINITE.search(value):
                    raise fail(path, f"{label} has a coordinate that is not finite ({attr}=...)")
            _check_sizes(element, label, svgelements, path)
            try:
                subpaths_of[id(element)] = _subpaths(element, svgelements)
            except (ArithmeticError, ValueError, TypeError) as exc:
                raise fail(path, f"{label} cannot be read ({type(exc).__name__}: {exc})") from None
            for segs, _ in subpaths_of[id(element)]:
                if any(_overflowed_arc(seg, svgelements) for seg in segs):
                    raise fail(
                        path,
                        f"{label} has an arc too large to compute: its centre overflows "
                        "floating point (coordinates or radii beyond about 1e77); scale the "
                        "drawing down",
                    )
        return subpaths_of[id(element)]

    groups: list[tuple[str, list[Any]]]
    if options.element is not None:
        target = svg.get_element_by_id(options.element)
        if target is None:
            ids = [str(e.id) for e in every if getattr(e, "id", None)]
            listed = ", ".join(ids[:12]) or "none"
            raise fail(
                path, f"no element with id {quote(options.element)}; ids in the file: {listed}"
            )
        members = (
            [target]
            if isinstance(target, svgelements.Shape)
            else [e for e in target.select() if isinstance(e, svgelements.Shape)]
        )
        groups = [(options.element, members)]
    else:
        # Each shape with a closed subpath is a candidate; only a single one is built.
        closed = [
            (k, e) for k, e in enumerate(shapes) if any(c for _, c in subpaths(e, _label(e, k)))
        ]
        if len(closed) > 1:
            listed = ", ".join(getattr(e, "id", None) or _label(e, k) for k, e in closed[:12])
            more = ", ..." if len(closed) > 12 else ""
            raise fail(
                path,
                f"{len(closed)} shapes with a closed outline ({listed}{more}); choose one with "
                "--element ID",
            )
        groups = [(getattr(e, "id", None) or "", [e]) for _, e in closed]

    candidates: list[tuple[str, list[Ring]]] = []
    for name, members in groups:
        rings: list[Ring] = []
        for element in members:
            label = _label(element, index_of.get(id(element), 0))
            pieces = subpaths(element, label)
            try:
                # Huge coordinates or transforms overflow here; the box check below says so.
                with np.errstate(over="ignore", invalid="ignore"):
                    affine = _Affine(element.transform, scale)
                    built = _curves(pieces, affine, svgelements)
            except (ArithmeticError, ValueError, TypeError) as exc:
                raise fail(path, f"{label} cannot be read ({type(exc).__name__}: {exc})") from None
            n_open = sum(1 for _, c in built if not c)
            if n_open:
                log.info("%s: %s: ignored %d open subpath(s)", path, label, n_open)
            for k, (curves, is_closed) in enumerate(built):
                if is_closed:
                    sub = f" subpath {k + 1}" if len(built) > 1 else ""
                    rings.append(Ring(tuple(curves), f"{label}{sub}", name))
        if rings:
            candidates.append((name or _label(members[0], index_of.get(id(members[0]), 0)), rings))

    if not candidates:
        what = f"{len(shapes)} shape(s), none closed" if shapes else "no shape elements"
        raise fail(path, f"no closed outline ({what})")
    name, rings = candidates[0]
    curves = [c for r in rings for c in r.curves]
    with np.errstate(over="ignore", invalid="ignore"):
        boxes = np.array([c.bounds() for c in curves])
    check_coordinates(path, boxes.reshape(-1, 2), name or "the outline")
    bounds = np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])
    tol = chordal_tolerance(path, options, bounds)
    flat = flatten_rings(path, rings, tol, options)
    part_name = name if name and not name.startswith("<") else path.stem
    return assemble_part(
        path,
        flat,
        part_name,
        units,
        "an element's outline must be one ring with holes inside it; split it or choose "
        "another element with --element ID",
        tol,
    )


def read_svg(path: Path, options: ReadOptions) -> Part:
    """Read the outline of one SVG shape.

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "cam.svg"
    >>> _ = f.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="40mm" '
    ...     'height="20mm" viewBox="0 0 40 20"><path id="cam" '
    ...     'd="M 0 10 C 0 0 40 0 40 10 C 40 20 0 20 0 10 Z"/></svg>')
    >>> p = read_svg(f, ReadOptions(tolerance=0.01))
    >>> p.name, p.units, round(float(np.ptp(p.outline[:, 0])), 6)
    ('cam', 'mm', 40.0)
    """
    return parse_svg(read_bytes(path), path, options)
