"""DXF part files: the closed outline drawn in the model space (parsing is ezdxf's).

Outlines come from closed entities (LWPOLYLINE and 2D/3D POLYLINE with bulges, CIRCLE, a
full ELLIPSE, a closed SPLINE) and from loops of open entities (LINE, ARC, elliptic arcs,
open SPLINEs and polylines) joined end to end: endpoints closer than the chordal tolerance
are the same point. Chains that end, or that branch (three entities at a point), are not
outlines and are left out. Block references (INSERT) are expanded.

The outer ring is the outline; rings inside it are holes (they move the centre of mass).
Several separate outer rings need a choice: ``layer`` keeps the entities of one layer.
Units come from the header's ``$INSUNITS`` (``None`` when it is 0, unknown, or not in the
file: ezdxf would otherwise fill in its own default, metres). Entities are projected onto
the xy plane of the world coordinate system. The file is parsed in memory (ASCII or binary
DXF; the text encoding of old versions comes from ``$DWGCODEPAGE``).

Limits, each refused with the limit named: at most
:data:`~bayesgrasp.io._common.MAX_ENTITIES` entities, counted in the file before parsing and
again as block references are expanded; blocks nest at most ``MAX_BLOCK_DEPTH`` deep and a
block that inserts itself (directly or through others) is refused; SPLINE degree at most
``MAX_SPLINE_DEGREE``. Also refused: an INSERT with a scale factor of 0, a CIRCLE or ARC
without a positive radius, and coordinates that are not finite or larger than
:data:`~bayesgrasp.io._common.MAX_COORDINATE`.
"""

from __future__ import annotations

import io
import logging
import math
import re
from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import PartFileError
from ..geometry import Part
from ._common import (
    MAX_ENTITIES,
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
from ._flatten import Adaptive, Bezier, Curve, EllipticArc, Polyline

__all__ = ["INSUNITS", "MAX_BLOCK_DEPTH", "MAX_SPLINE_DEGREE", "parse_dxf", "read_dxf"]

log = logging.getLogger("bayesgrasp.io")

FloatArray = NDArray[np.float64]

#: ``$INSUNITS`` codes and the unit names reported in :attr:`Part.units` (0 is unitless).
INSUNITS = {
    1: "in",
    2: "ft",
    3: "mi",
    4: "mm",
    5: "cm",
    6: "m",
    7: "km",
    8: "µin",
    9: "mil",
    10: "yd",
    11: "Å",
    12: "nm",
    13: "µm",
    14: "dm",
    15: "dam",
    16: "hm",
    17: "Gm",
    18: "au",
    19: "ly",
    20: "pc",
    21: "US ft",
    22: "US in",
    23: "US yd",
    24: "US mi",
}

#: Deepest nesting of block references (an INSERT in a block inserted by an INSERT ...).
MAX_BLOCK_DEPTH = 8

#: Highest SPLINE degree (CAD programs draw degree 1 to 11; Bezier pieces of degree d cost
#: O(d) per point).
MAX_SPLINE_DEGREE = 25

_BINARY_SENTINEL = b"AutoCAD Binary DXF\r\n\x1a\x00"
# ``$INSUNITS`` as a header variable name (group code 9), ASCII or binary DXF.
_HAS_INSUNITS = re.compile(rb"(?m)^[ \t]*9[ \t]*\r?\n[ \t]*\$INSUNITS[ \t]*\r?$|\$INSUNITS\x00")


def _xy(v: Any) -> FloatArray:
    return np.array([float(v[0]), float(v[1])], dtype=np.float64)


class _Frame:
    """Object coordinates (OCS) of an entity, projected onto the world xy plane."""

    def __init__(self, entity: Any) -> None:
        ocs = entity.ocs()
        self.linear = np.array(
            [[ocs.ux[0], ocs.uy[0]], [ocs.ux[1], ocs.uy[1]]], dtype=np.float64
        )  # (2, 2) OCS x, y axes seen in world x, y
        self.uz = np.array([ocs.uz[0], ocs.uz[1]], dtype=np.float64)

    def point(self, x: float, y: float, z: float = 0.0) -> FloatArray:
        out: FloatArray = self.linear @ np.array([x, y]) + z * self.uz
        return out

    def vector(self, x: float, y: float) -> FloatArray:
        out: FloatArray = self.linear @ np.array([x, y])
        return out


def _circle_arc(
    frame: _Frame, center: Any, radius: float, t0: float, span: float, elevation: float
) -> EllipticArc:
    return EllipticArc(
        frame.point(center[0], center[1], elevation),
        frame.vector(radius, 0.0),
        frame.vector(0.0, radius),
        t0,
        span,
    )


def _bulge_curve(
    frame: _Frame, p: FloatArray, q: FloatArray, bulge: float, elevation: float
) -> Curve:
    """The segment from ``p`` to ``q`` (OCS) with a bulge: a line, or a circular arc."""
    wp, wq = frame.point(p[0], p[1], elevation), frame.point(q[0], q[1], elevation)
    if bulge == 0.0:
        return Polyline(np.array([wp, wq]))
    from ezdxf.math import bulge_center

    sweep = 4.0 * math.atan(bulge)  # signed: positive is counter-clockwise
    c = bulge_center(tuple(p), tuple(q), bulge)
    radius = float(np.hypot(p[0] - c[0], p[1] - c[1]))
    t0 = math.atan2(p[1] - c[1], p[0] - c[0])
    arc = _circle_arc(frame, c, radius, t0, sweep, elevation)
    return EllipticArc(arc.center, arc.major, arc.minor, arc.t0, arc.span, pin=(wp, wq))


def _polyline_curves(
    frame: _Frame, points: list[tuple[float, float, float]], closed: bool, elevation: float
) -> list[Curve]:
    """Curves of a polyline given as (x, y, bulge) in its OCS."""
    pts = [(np.array([x, y], dtype=np.float64), b) for x, y, b in points]
    if closed and len(pts) > 1 and np.array_equal(pts[0][0], pts[-1][0]):
        pts = pts[:-1]
    n = len(pts)
    curves: list[Curve] = []
    for i in range(n if closed else n - 1):
        (p, b), (q, _) = pts[i], pts[(i + 1) % n]
        if not np.array_equal(p, q):
            curves.append(_bulge_curve(frame, p, q, float(b), elevation))
    return curves


def _insert_knot(
    ctrl: FloatArray, knots: list[float], degree: int, t: float
) -> tuple[FloatArray, list[float]]:
    """Boehm's knot insertion: the same curve with one more knot at ``t`` (any dimension)."""
    # The span holding t (knots[k] <= t < knots[k + 1]); the domain's end uses the last span.
    k = min(int(np.searchsorted(knots, t, side="right")) - 1, len(ctrl) - 1)
    new = np.empty((len(ctrl) + 1, ctrl.shape[1]))
    new[: k - degree + 1] = ctrl[: k - degree + 1]
    for i in range(k - degree + 1, k + 1):
        alpha = (t - knots[i]) / (knots[i + degree] - knots[i])
        new[i] = (1.0 - alpha) * ctrl[i - 1] + alpha * ctrl[i]
    new[k + 1 :] = ctrl[k:]
    return new, [*knots[: k + 1], t, *knots[k + 1 :]]


def _clamped(bs: Any) -> Any:
    """The B-spline restricted to its valid domain ``[knots[p], knots[n]]``, clamped.

    An unclamped spline (a periodic "closed" spline) is only defined between those knots;
    evaluating it outside gives points that are not on the drawn curve. Inserting each end
    knot up to multiplicity ``p`` and dropping the control points outside makes the same
    curve with clamped ends (rational splines in homogeneous coordinates).
    """
    from ezdxf.math import BSpline

    p = bs.degree
    knots = [float(k) for k in bs.knots()]
    n = bs.count
    a, b = knots[p], knots[n]
    weights = np.asarray(bs.weights(), dtype=np.float64) if bs.is_rational else np.ones(n)
    pts = np.array([[v[0], v[1]] for v in bs.control_points], dtype=np.float64)
    ctrl = np.column_stack([pts * weights[:, None], weights])  # (n, 3) homogeneous
    for t in (a, b):
        while sum(1 for k in knots if math.isclose(k, t, rel_tol=0, abs_tol=1e-12)) < p:
            ctrl, knots = _insert_knot(ctrl, knots, p, t)
    at_a = [i for i, k in enumerate(knots) if math.isclose(k, a, rel_tol=0, abs_tol=1e-12)]
    at_b = [i for i, k in enumerate(knots) if math.isclose(k, b, rel_tol=0, abs_tol=1e-12)]
    first = at_a[0] + len(at_a) - p - 1  # control points whose support meets [a, b]
    last = at_b[0] - 1
    sub = ctrl[first : last + 1]
    sub_knots = [a] * (p + 1) + knots[at_a[-1] + 1 : at_b[0]] + [b] * (p + 1)
    w = sub[:, 2]
    xyz = [(x / wi, y / wi, 0.0) for (x, y, _), wi in zip(sub, w, strict=True)]
    if bs.is_rational:
        return BSpline(xyz, order=p + 1, knots=sub_knots, weights=list(w))
    return BSpline(xyz, order=p + 1, knots=sub_knots)


def _spline_curves(entity: Any) -> list[Curve]:
    degree = entity.dxf.degree
    if not 1 <= degree <= MAX_SPLINE_DEGREE:
        raise _Refused(
            f"{_source(entity)} has degree {degree}; the limit is 1 to {MAX_SPLINE_DEGREE}"
        )
    bs = entity.construction_tool()
    if not bs.is_clamped:
        bs = _clamped(bs)
    if not bs.is_rational:
        return [
            Bezier(np.array([[v[0], v[1]] for v in piece], dtype=np.float64))
            for piece in bs.bezier_decomposition()
        ]
    ctrl = np.array([[v[0], v[1]] for v in bs.control_points], dtype=np.float64)
    first, last = _xy(bs.point(0.0)), _xy(bs.point(bs.max_t))
    box = np.array([ctrl.min(axis=0), ctrl.max(axis=0)])  # weights > 0: convex hull property
    return [Adaptive(lambda tol: ((v[0], v[1]) for v in bs.flattening(tol)), first, last, box)]


def _entity_curves(entity: Any) -> tuple[list[Curve], bool] | None:
    """(curves, closed) of one entity, or None for entities that are not outlines."""
    kind = entity.dxftype()
    dxf = entity.dxf
    if kind == "LINE":
        s, e = _xy(dxf.start), _xy(dxf.end)
        return ([Polyline(np.array([s, e]))] if not np.array_equal(s, e) else [], False)
    if kind in ("ARC", "CIRCLE"):
        if not dxf.hasattr("radius"):
            raise _Refused(f"{_source(entity)} has no radius (group code 40)")
        if not (math.isfinite(dxf.radius) and dxf.radius >= 0):
            raise _Refused(f"{_source(entity)} has radius {dxf.radius!r}; it must be >= 0")
        if dxf.radius == 0:
            return [], kind == "CIRCLE"  # a point
        frame = _Frame(entity)
        center = dxf.center
        if kind == "CIRCLE":
            return [_circle_arc(frame, center, dxf.radius, 0.0, 2 * math.pi, center[2])], True
        if not (math.isfinite(dxf.start_angle) and math.isfinite(dxf.end_angle)):
            raise _Refused(
                f"{_source(entity)} has angles {dxf.start_angle!r} to {dxf.end_angle!r}; "
                "they must be finite"
            )
        t0 = math.radians(dxf.start_angle)
        span = math.radians((dxf.end_angle - dxf.start_angle) % 360.0) or 2 * math.pi
        arc = _circle_arc(frame, center, dxf.radius, t0, span, center[2])
        pin = (_xy(entity.start_point), _xy(entity.end_point))
        return [EllipticArc(arc.center, arc.major, arc.minor, t0, span, pin)], False
    if kind == "ELLIPSE":
        ce = entity.construction_tool()
        if not (math.isfinite(ce.start_param) and math.isfinite(ce.end_param)):
            raise _Refused(f"{_source(entity)} has parameters that are not finite")
        span = (ce.end_param - ce.start_param) % (2 * math.pi)
        full = span < 1e-12 or abs(span - 2 * math.pi) < 1e-12
        span = 2 * math.pi if full else span
        arc = EllipticArc(
            _xy(ce.center), _xy(ce.major_axis), _xy(ce.minor_axis), ce.start_param, span
        )
        return [arc], full
    if kind == "SPLINE":
        curves = _spline_curves(entity)
        closed = bool(entity.closed) or bool(
            np.allclose(curves[0].start(), curves[-1].end(), rtol=0, atol=0)
        )
        return curves, closed
    if kind == "LWPOLYLINE":
        frame = _Frame(entity)
        pts = [(float(x), float(y), float(b)) for x, y, b in entity.get_points("xyb")]
        closed = bool(entity.closed) or (len(pts) > 2 and pts[0][:2] == pts[-1][:2])
        return _polyline_curves(frame, pts, closed, float(dxf.elevation)), closed
    if kind == "POLYLINE":
        closed = bool(entity.is_closed)
        if entity.is_2d_polyline:
            frame = _Frame(entity)
            verts = [v for v in entity.vertices if not v.dxf.flags & 16]  # not spline frame
            pts = [(v.dxf.location[0], v.dxf.location[1], v.dxf.bulge) for v in verts]
            closed = closed or (len(pts) > 2 and pts[0][:2] == pts[-1][:2])
            elevation = float(entity.dxf.elevation[2])
            return _polyline_curves(frame, pts, closed, elevation), closed
        if entity.is_3d_polyline:
            loc = np.array([_xy(v.dxf.location) for v in entity.vertices])
            if closed:
                loc = np.vstack([loc, loc[:1]])
            return [Polyline(loc)], closed
    return None


class _Refused(ValueError):
    """An entity the reader refuses (turned into PartFileError with the file's name)."""


def _source(entity: Any) -> str:
    return f"{entity.dxftype()} #{entity.dxf.handle} on layer {entity.dxf.layer}"


def _check_blocks(msp: Any, layer: str | None) -> None:
    """Refuse block references that expand too far, before anything is expanded.

    The size and depth of each block's expansion are counted from the block definitions
    (memoised, so a bomb of nested references costs one pass over its definitions).
    """
    doc = msp.doc
    cap = MAX_ENTITIES + 1
    memo: dict[str, tuple[int, int]] = {}  # block -> (entities once expanded, levels)

    def expansion(name: str, chain: tuple[str, ...]) -> tuple[int, int]:
        if name in memo:
            return memo[name]
        path = " -> ".join([*chain, name])
        if name in chain:
            raise _Refused(f"block {quote(name)} inserts itself ({path})")
        if len(chain) >= MAX_BLOCK_DEPTH:
            raise _Refused(f"block references nest deeper than {MAX_BLOCK_DEPTH} levels ({path})")
        block = doc.blocks.get(name)
        count, levels = 0, 1
        for entity in block if block is not None else ():
            count += 1
            if entity.dxftype() == "INSERT":
                n, depth = expansion(str(entity.dxf.name), (*chain, name))
                count, levels = count + n, max(levels, depth + 1)
            if count >= cap:
                break
        memo[name] = (min(count, cap), levels)
        return memo[name]

    total = 0
    for entity in msp:
        if layer is not None and str(entity.dxf.layer).lower() != layer.lower():
            continue
        total += 1
        if entity.dxftype() == "INSERT":
            total += expansion(str(entity.dxf.name), ())[0]
        if total > MAX_ENTITIES:
            raise _Refused(
                f"more than {MAX_ENTITIES} entities with block references expanded "
                f"(the limit is {MAX_ENTITIES})"
            )


def _entities(msp: Any, layer: str | None) -> Iterator[Any]:
    """Model-space entities of the layer, with block references expanded.

    At most :data:`MAX_ENTITIES` entities are yielded or expanded (counted from the block
    definitions first, then again as ezdxf expands them); a block that inserts itself, or
    references nested deeper than :data:`MAX_BLOCK_DEPTH`, are refused.
    """
    _check_blocks(msp, layer)
    count = 0

    def expand(entity: Any, chain: tuple[str, ...]) -> Iterator[Any]:
        nonlocal count
        count += 1
        if count > MAX_ENTITIES:
            raise _Refused(
                f"more than {MAX_ENTITIES} entities with block references expanded "
                f"(the limit is {MAX_ENTITIES})"
            )
        if entity.dxftype() != "INSERT":
            yield entity
            return
        dxf = entity.dxf
        block = str(dxf.name)
        if block in chain:
            raise _Refused(f"block {quote(block)} inserts itself ({' -> '.join([*chain, block])})")
        if len(chain) >= MAX_BLOCK_DEPTH:
            raise _Refused(
                f"block references nest deeper than {MAX_BLOCK_DEPTH} levels "
                f"({' -> '.join([*chain, block])})"
            )
        for axis in ("xscale", "yscale", "zscale"):
            factor = dxf.get(axis, 1.0)
            if not math.isfinite(factor) or factor == 0:
                raise _Refused(
                    f"{_source(entity)} inserts block {quote(block)} with {axis} {factor!r}; "
                    "scale factors must be finite and non-zero"
                )
        for sub in entity.virtual_entities():
            yield from expand(sub, (*chain, block))

    for entity in msp:
        if layer is None or str(entity.dxf.layer).lower() == layer.lower():
            yield from expand(entity, ())


def _chain(pieces: list[tuple[list[Curve], str, str]], gap: float) -> tuple[list[Ring], list[str]]:
    """Join open pieces end to end into loops; return the loops and why others were left."""
    from scipy.cluster.hierarchy import DisjointSet
    from scipy.spatial import cKDTree

    if not pieces:
        return [], []
    ends = np.array([[c[0].start(), c[-1].end()] for c, _, _ in pieces]).reshape(-1, 2)
    nodes = DisjointSet(range(len(ends)))
    for i, j in cKDTree(ends).query_pairs(gap):
        nodes.merge(i, j)
    node = np.array([nodes[k] for k in range(len(ends))]).reshape(-1, 2)  # (P, 2) node ids
    alive = np.ones(len(pieces), dtype=bool)
    notes: list[str] = []
    # Peel pieces at dangling ends (degree 1) and branches (degree > 2), a queue of nodes
    # whose degree changed: O(P) in all.
    degree: dict[int, int] = {}
    at_node: dict[int, list[int]] = {}
    for k, (a, b) in enumerate(node.tolist()):
        for n in (a, b):
            degree[n] = degree.get(n, 0) + 1
            at_node.setdefault(n, []).append(k)
    queue = deque(n for n, d in degree.items() if d != 2)
    while queue:
        n = queue.popleft()
        if degree[n] == 2:
            continue
        for k in at_node[n]:
            if not alive[k]:
                continue
            end = 0 if int(node[k, 0]) == n else 1
            at = ends[2 * k + end]
            why = "branches" if degree[n] > 2 else "ends"
            notes.append(f"{pieces[k][1]}: its chain {why} at ({at[0]:.6g}, {at[1]:.6g})")
            alive[k] = False
            for m in (int(node[k, 0]), int(node[k, 1])):
                degree[m] -= 1
                if m != n:
                    queue.append(m)
        degree[n] = 0
    incident: dict[int, list[int]] = {}
    for k in np.flatnonzero(alive).tolist():
        for n in node[k]:
            incident.setdefault(int(n), []).append(int(k))
    rings: list[Ring] = []
    used = np.zeros(len(pieces), dtype=bool)
    for k0 in np.flatnonzero(alive).tolist():
        if used[k0]:
            continue
        curves: list[Curve] = []
        sources: list[str] = []
        k, forward = k0, True
        start_node = int(node[k0, 0])
        while True:
            used[k] = True
            cs, source, _ = pieces[k]
            curves += cs if forward else [c.reverse() for c in reversed(cs)]
            sources.append(source)
            at = int(node[k, 1] if forward else node[k, 0])
            if at == start_node:
                break
            nxt = [m for m in incident[at] if not used[m]]
            if not nxt:  # pragma: no cover - degree-2 nodes always continue the loop
                break
            k = int(nxt[0])
            forward = int(node[k, 0]) == at
        label = (
            sources[0]
            if len(sources) == 1
            else f"loop of {sources[0]} and {len(sources) - 1} more entities"
        )
        rings.append(Ring(tuple(curves), label, pieces[int(k0)][2]))
    return rings, notes


def _entity_count(path: Path, data: bytes) -> None:
    """Refuse an ASCII DXF with more than MAX_ENTITIES entities, before ezdxf parses it.

    Every entity (and every VERTEX, table record, object) starts with group code 0; the
    file alternates group-code lines and value lines.
    """
    if data.startswith(_BINARY_SENTINEL):
        return
    codes = data.splitlines()[0::2]
    count = sum(1 for c in codes if c.strip() == b"0")
    if count > MAX_ENTITIES:
        raise fail(
            path,
            f"the file has {count} entities and records; the limit is {MAX_ENTITIES}",
        )


def _load(ezdxf: Any, path: Path, data: bytes) -> Any:
    """Parse a DXF document from memory, as ``ezdxf.readfile`` does from a file."""
    from ezdxf.document import Drawing
    from ezdxf.filemanagement import dxf_stream_info
    from ezdxf.lldxf.tagger import binary_tags_loader
    from ezdxf.lldxf.validator import is_dxf_stream

    if data.startswith(_BINARY_SENTINEL):
        return Drawing.load(binary_tags_loader(data, errors="surrogateescape"))
    probe = io.TextIOWrapper(io.BytesIO(data), encoding="utf-8", errors="ignore")
    if not is_dxf_stream(probe):
        raise ValueError("no DXF SECTION found")
    info = dxf_stream_info(io.TextIOWrapper(io.BytesIO(data), encoding="utf-8", errors="ignore"))
    try:
        codec = info.encoding
        "".encode(codec)
    except LookupError:
        codec = "cp1252"
    return ezdxf.read(io.TextIOWrapper(io.BytesIO(data), encoding=codec, errors="surrogateescape"))


def _units(path: Path, doc: Any, data: bytes) -> str | None:
    """The unit name of ``$INSUNITS``, or None when the file does not give it."""
    if _HAS_INSUNITS.search(data) is None:
        return None  # ezdxf's default header would say metres
    code = doc.header.get("$INSUNITS", 0)
    if isinstance(code, bool) or not isinstance(code, int | float) or not math.isfinite(code):
        log.info("%s: ignored $INSUNITS %r (not a unit code)", path, code)
        return None
    if code != int(code):
        return None
    return INSUNITS.get(int(code))


def parse_dxf(data: bytes, path: Path, options: ReadOptions) -> Part:
    """Read the outline of a DXF drawing from the file's bytes.

    Examples
    --------
    >>> import ezdxf, io
    >>> doc = ezdxf.new(units=4)
    >>> _ = doc.modelspace().add_circle((0, 0), 5)
    >>> text = io.StringIO()
    >>> doc.write(text)
    >>> p = parse_dxf(text.getvalue().encode(), Path("disc.dxf"), ReadOptions())
    >>> p.units, p.hull.n_sides > 20
    ('mm', True)
    """
    ezdxf = need("ezdxf")
    refuse_options(path, options, "a DXF file", layer=True)
    _entity_count(path, data)
    try:
        doc = _load(ezdxf, path, data)
    except Exception as exc:  # ezdxf raises several types on malformed input
        raise fail(
            path, f"not a readable DXF file ({type(exc).__name__}: {str(exc)[:200]})"
        ) from None
    units = _units(path, doc, data)
    msp = doc.modelspace()

    closed_rings: list[Ring] = []
    pieces: list[tuple[list[Curve], str, str]] = []
    skipped: dict[str, int] = {}
    try:
        # Huge coordinates overflow in the transforms; the box check below says so.
        with np.errstate(over="ignore", invalid="ignore"):
            for entity in _entities(msp, options.layer):
                layer = str(entity.dxf.layer)
                source = f"{entity.dxftype()} #{entity.dxf.handle} on layer {layer}"
                got = _entity_curves(entity)
                if got is None:
                    skipped[entity.dxftype()] = skipped.get(entity.dxftype(), 0) + 1
                    continue
                curves, closed = got
                if not curves:
                    continue
                if closed:
                    closed_rings.append(Ring(tuple(curves), source, layer))
                else:
                    pieces.append((curves, source, layer))
    except _Refused as exc:
        raise fail(path, str(exc)) from None
    except PartFileError:
        raise
    except Exception as exc:  # ezdxf raises many types on malformed entities
        raise fail(
            path, f"an entity cannot be read ({type(exc).__name__}: {str(exc)[:200]})"
        ) from None
    if skipped:
        log.info("%s: skipped entities that are not outlines: %s", path, skipped)

    every = [c for r in closed_rings for c in r.curves] + [c for p in pieces for c in p[0]]
    if not every:
        layers = sorted({str(e.dxf.layer) for e in msp})
        where = (
            f" on layer {quote(options.layer)} (layers: {', '.join(layers)})"
            if options.layer
            else ""
        )
        raise fail(path, f"no lines, arcs, circles, ellipses, splines or polylines{where}")
    with np.errstate(over="ignore", invalid="ignore"):
        boxes = np.array([c.bounds() for c in every])
    check_coordinates(path, boxes.reshape(-1, 2), "the drawing")
    bounds = np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])
    tol = chordal_tolerance(path, options, bounds)
    loops, notes = _chain(pieces, tol)
    for note in notes[:20]:
        log.info("%s: left out %s", path, note)
    if len(notes) > 20:
        log.info("%s: left out %d more pieces", path, len(notes) - 20)
    rings = closed_rings + loops
    if not rings:
        detail = f"; {notes[0]}" if notes else ""
        raise fail(path, f"no closed outline{detail}")
    flat = flatten_rings(path, rings, tol, options)
    layers = sorted({r.group for r in rings})
    if options.layer is None and len(layers) > 1:
        choose = f"choose one with --layer (layers: {', '.join(layers)})"
    else:
        choose = "keep one part per layer (or per file) and choose it with --layer"
    name = path.stem if options.layer is None else f"{path.stem}:{options.layer}"
    return assemble_part(path, flat, name, units, choose, tol)


def read_dxf(path: Path, options: ReadOptions) -> Part:
    """Read the outline of a DXF drawing.

    Examples
    --------
    >>> import ezdxf, tempfile
    >>> doc = ezdxf.new(units=4)
    >>> _ = doc.modelspace().add_lwpolyline(
    ...     [(0, 0, 0), (20, 0, 1), (20, 10, 0), (0, 10, 0)], format="xyb", close=True)
    >>> f = Path(tempfile.mkdtemp()) / "tab.dxf"
    >>> doc.saveas(f)
    >>> p = read_dxf(f, ReadOptions(tolerance=0.001))
    >>> p.units, round(float(p.outline[:, 0].max()), 2)
    ('mm', 25.0)
    """
    return parse_dxf(read_bytes(path), path, options)
