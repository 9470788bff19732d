"""Rings of curves read from a file, as exact outlines of segments and circular arcs.

Circular arcs (DXF ARC, CIRCLE and bulges; SVG arcs, circles and round rects, under
transforms that keep circles round) stay arcs: they become the bulges of a
:class:`~bayesgrasp.geometry.curved.CurvedRing` (each arc cut into pieces of at most a
quarter turn, so every bulge is well conditioned). Every other curve (Bezier curves,
splines, ellipses and elliptic arcs, arcs under a shear) is flattened to chords within the
reader's chordal tolerance ``eps``: the outline is then within ``eps`` of the drawn one, and
the part's ``curve_error`` says so; the squeeze model only keeps stable orientations that
this error cannot remove (:mod:`bayesgrasp.geometry.curved`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..geometry import Part
from ..geometry.curved import CurvedRing, CurvePatches, curved_part
from ._flatten import Bezier, Curve, EllipticArc, FlattenBudget, Polyline, Ring

__all__ = ["circle_of", "curved_assembly", "curved_ring", "patches_of"]

FloatArray = NDArray[np.float64]

# An elliptic arc is a circular arc when its two axes are perpendicular and of equal length
# to this relative precision.
_ROUND = 1e-9


def circle_of(arc: EllipticArc) -> tuple[float, float, float] | None:
    """``(radius, start angle, signed sweep)`` of an elliptic arc that is circular, or None.

    ``P(t) = c + M cos t + m sin t`` is a circle of radius ``|M|`` when ``|m| = |M|`` and
    ``m`` is perpendicular to ``M``; it turns counter-clockwise with ``t`` when ``m`` is
    ``M`` turned by +90 degrees, clockwise when a reflection turned it by -90 degrees.

    Examples
    --------
    >>> a = EllipticArc(np.zeros(2), np.array([2.0, 0]), np.array([0, -2.0]), 0.0, 1.0)
    >>> circle_of(a)
    (2.0, 0.0, -1.0)
    """
    major, minor = np.asarray(arc.major, float), np.asarray(arc.minor, float)
    r1, r2 = math.hypot(*major), math.hypot(*minor)
    if r1 == 0 or abs(r1 - r2) > _ROUND * r1:
        return None
    cross = major[0] * minor[1] - major[1] * minor[0]
    if abs(float(major @ minor)) > _ROUND * r1 * r1:
        return None
    turn = 1.0 if cross > 0 else -1.0
    start = math.atan2(major[1], major[0]) + turn * arc.t0
    return r1, start, turn * arc.span


def curved_ring(
    curves: Sequence[Curve], tol: float, limit: int, patches: list[Curve] | None = None
) -> tuple[CurvedRing, float, bool]:
    """One ring of curves as points and bulges, and how far it may be from the curves.

    Parameters
    ----------
    curves : sequence of Curve
        End to end, closed (the last ends within the gap tolerance of the first's start).
    tol : float
        The chordal tolerance non-arc curves are flattened to.
    limit : int
        Largest number of points (the readers checked the count already).
    patches : list, optional
        Receives the curves that were flattened.

    Returns
    -------
    ring : CurvedRing
    error : float
        ``tol`` when a curve was flattened, else 0.
    curved : bool
        Whether the ring holds anything but straight segments.
    """
    points: list[FloatArray] = []
    bulges: list[float] = []
    chords: list[bool] = []
    error = 0.0
    curved = False
    budget = FlattenBudget(max(limit, 4) * 4)
    for c in curves:
        circle = circle_of(c) if isinstance(c, EllipticArc) else None
        if circle is not None and isinstance(c, EllipticArc):
            radius, start, sweep = circle
            k = max(1, math.ceil(abs(sweep) / (math.pi / 2) - 1e-9))
            t = start + sweep * np.arange(k) / k
            pts = np.asarray(c.center) + radius * np.column_stack([np.cos(t), np.sin(t)])
            pts[0] = c.start()
            points.append(pts)
            bulges += [math.tan(sweep / (4 * k))] * k
            chords += [False] * k
            curved = True
            continue
        pts = c.points(tol, budget, "curve")
        flat = not isinstance(c, Polyline)
        if flat:
            error, curved = tol, True
            if patches is not None:
                patches.append(c)
        points.append(pts[:-1])
        bulges += [0.0] * (len(pts) - 1)
        chords += [flat] * (len(pts) - 1)
    p = np.concatenate(points) if points else np.zeros((0, 2))
    b = np.asarray(bulges, dtype=np.float64)
    ch = np.asarray(chords, dtype=bool)
    # Drop repeated points (a piece of no length), keeping the bulge of the piece that moves.
    if len(p) > 1:
        step = np.roll(p, -1, axis=0) - p
        moves = np.hypot(step[:, 0], step[:, 1]) > 1e-12 * max(float(np.ptp(p)), 1e-300)
        p, b, ch = p[moves], b[moves], ch[moves]
    return CurvedRing(p, b, ch), error, curved


def patches_of(curves: Sequence[Curve]) -> CurvePatches:
    """The flattened curves in exact form: Bezier curves of degree <= 3 and elliptic arcs.

    Higher-degree Bezier curves and rational splines are left out (``complete`` False):
    their extrema keep the flattening's error bound.
    """
    bezier: list[FloatArray] = []
    ellipses: list[list[float]] = []
    complete = True
    for c in curves:
        if isinstance(c, Bezier) and c.degree in (2, 3):
            q = np.asarray(c.control, dtype=np.float64)
            if c.degree == 2:  # raise to degree 3
                q = np.array([q[0], (q[0] + 2 * q[1]) / 3, (2 * q[1] + q[2]) / 3, q[2]])
            bezier.append(q)
        elif isinstance(c, EllipticArc):
            ellipses.append([*c.center, *c.major, *c.minor, c.t0, c.span])
        else:
            complete = False
    return CurvePatches(
        np.array(bezier, dtype=np.float64).reshape(-1, 4, 2),
        np.array(ellipses, dtype=np.float64).reshape(-1, 8),
        complete,
    )


def curved_assembly(
    outer: Ring, holes: Sequence[Ring], name: str, units: str | None, tol: float
) -> Part:
    """The part of an outer ring and its holes, with arcs kept exact.

    An outline of straight segments stays a polygon :class:`~bayesgrasp.geometry.Part` (as
    before; holes with arcs only give it their exact centre of mass). An outline with arcs
    or curves is a :class:`~bayesgrasp.geometry.curved.CurvedPart` whose ``curve_error`` is
    ``tol`` when a non-arc curve was flattened.
    """
    limit = sum(len(r.points) for r in (outer, *holes)) + 16
    flat: list[Curve] = []
    ring, error, curved = curved_ring(outer.curves, tol, limit, flat)
    rings = [curved_ring(h.curves, tol, limit)[0] for h in holes]
    if not curved:
        part = curved_part(ring, rings, name, units, display_tol=tol)
        return Part.from_outline(
            outer.points,
            [h.points for h in holes],
            name=name,
            center_of_mass=part.center_of_mass,
            units=units,
        )
    return curved_part(
        ring, rings, name, units, curve_error=error, display_tol=tol, patches=patches_of(flat)
    )
