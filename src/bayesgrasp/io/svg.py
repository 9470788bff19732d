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
"""

from __future__ import annotations

import io
import logging
import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..geometry import Part
from ._common import (
    ReadOptions,
    Ring,
    assemble_part,
    chordal_tolerance,
    fail,
    flatten_rings,
    need,
    read_bytes,
)
from ._flatten import Bezier, Curve, EllipticArc, Polyline

__all__ = ["read_svg"]

log = logging.getLogger("bayesgrasp.io")

FloatArray = NDArray[np.float64]

MM_PER_PX = 25.4 / 96.0  # CSS: 96 px per inch
_PHYSICAL = re.compile(r"^\s*([-+0-9.eE]+)\s*(mm|cm|in|pt|pc|q)\s*$", re.IGNORECASE)
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


def _curves(element: Any, affine: _Affine, svgelements: Any) -> list[tuple[list[Curve], bool]]:
    """Each subpath of a shape as (curves, closed), in the part's coordinates."""
    subpaths: list[tuple[list[Curve], bool]] = []
    curves: list[Curve] = []
    closed = False
    first: tuple[float, float] | None = None
    for seg in element.segments(transformed=False):
        if isinstance(seg, svgelements.Move):
            if curves:
                subpaths.append((curves, closed))
            curves, closed, first = [], False, _xy(seg.end)
            continue
        start, end = _xy(seg.start), _xy(seg.end)
        if first is None:
            first = start
        if isinstance(seg, svgelements.Close):
            closed = True
            if start != end:
                curves.append(Polyline(affine.points([start, end])))
        elif isinstance(seg, svgelements.Line):
            if start != end:
                curves.append(Polyline(affine.points([start, end])))
        elif isinstance(seg, svgelements.QuadraticBezier):
            curves.append(Bezier(affine.points([start, _xy(seg.control), end])))
        elif isinstance(seg, svgelements.CubicBezier):
            ctrl = [start, _xy(seg.control1), _xy(seg.control2), end]
            curves.append(Bezier(affine.points(ctrl)))
        elif isinstance(seg, svgelements.Arc):
            curves.append(_arc(seg, affine))
        else:  # pragma: no cover - svgelements has no other segment types
            curves.append(Polyline(affine.points([start, end])))
    if curves:
        subpaths.append((curves, closed))
    out = []
    for cs, is_closed in subpaths:
        ends_meet = np.allclose(cs[0].start(), cs[-1].end(), rtol=0, atol=1e-12 * _size(cs))
        out.append((cs, is_closed or ends_meet))
    return out


def _size(curves: list[Curve]) -> float:
    box = np.array([c.bounds() for c in curves])
    return float(np.max(box[:, 1] - box[:, 0])) or 1.0


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
    svgelements = need("svgelements")
    data = read_bytes(path)
    if options.layer is not None:
        raise fail(path, "`layer` applies to DXF files; choose an SVG element with `element`")
    try:
        svg = svgelements.SVG.parse(io.BytesIO(data), reify=False)
    except Exception as exc:  # the XML parser and svgelements raise many types on bad input
        raise fail(path, f"not a readable SVG file ({type(exc).__name__}: {exc})") from None
    if not isinstance(svg, svgelements.SVG):
        raise fail(path, "not an SVG document (no <svg> root element)")
    scale, units = _unit_scale(svg)

    shapes = [e for e in svg.elements() if isinstance(e, svgelements.Shape)]
    groups: list[tuple[str, list[Any]]]
    if options.element is not None:
        target = svg.get_element_by_id(options.element)
        if target is None:
            ids = [str(e.id) for e in svg.elements() if getattr(e, "id", None)]
            listed = ", ".join(ids[:12]) or "none"
            raise fail(path, f"no element with id {options.element!r}; ids in the file: {listed}")
        members = (
            [target]
            if isinstance(target, svgelements.Shape)
            else [e for e in target.select() if isinstance(e, svgelements.Shape)]
        )
        groups = [(options.element, members)]
    else:
        groups = [(getattr(e, "id", None) or "", [e]) for e in shapes]  # each shape is a candidate

    candidates: list[tuple[str, list[Ring]]] = []
    for name, members in groups:
        rings: list[Ring] = []
        for element in members:
            index = shapes.index(element) if element in shapes else 0
            label = _label(element, index)
            values = element.values
            for attr in _GEOMETRY_ATTRS:
                value = values.get(attr)
                if isinstance(value, str) and _NOT_FINITE.search(value):
                    raise fail(path, f"{label} has a coordinate that is not finite ({attr}=...)")
            affine = _Affine(element.transform, scale)
            subpaths = _curves(element, affine, svgelements)
            n_open = sum(1 for _, c in subpaths if not c)
            if n_open:
                log.info("%s: %s: ignored %d open subpath(s)", path, label, n_open)
            for k, (curves, closed) in enumerate(subpaths):
                if closed:
                    sub = f" subpath {k + 1}" if len(subpaths) > 1 else ""
                    rings.append(Ring(tuple(curves), f"{label}{sub}", name))
        if rings:
            candidates.append((name or _label(members[0], shapes.index(members[0])), rings))

    if not candidates:
        what = f"{len(shapes)} shape(s), none closed" if shapes else "no shape elements"
        raise fail(path, f"no closed outline ({what})")
    if len(candidates) > 1:
        listed = ", ".join(c[0] for c in candidates[:12])
        raise fail(
            path,
            f"{len(candidates)} shapes with a closed outline ({listed}); choose one with "
            "--element ID",
        )
    name, rings = candidates[0]
    curves = [c for r in rings for c in r.curves]
    boxes = np.array([c.bounds() for c in curves])
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
    )
