"""Curved parts as they are: convex hulls of segments and circular arcs, kept exact.

The seed (section 4.2): "the analysis of grasp mechanics using the diameter function is not
limited to polygonal objects. Any two-dimensional object can be analyzed if we can compute
its diameter function." This module computes it exactly for outlines made of line segments
and circular arcs (DXF ARC, CIRCLE and bulges; SVG arcs and circles), and with a stated error
bound for outlines that also hold other curves (Bezier curves, splines, ellipses), which the
readers flatten to chords within a chordal tolerance ``eps``.

Outline (:class:`CurvedRing`): points ``P_0 .. P_{n-1}`` and one *bulge* per piece, the piece
from ``P_i`` to ``P_{i+1}``: ``b_i = tan(sweep_i / 4)``, 0 for a segment, positive for an
arc turning counter-clockwise (the DXF convention). Area and centroid are exact: the
shoelace polygon plus each arc's circular segment.

Convex hull (:class:`CurvedHull`). With ``u(phi) = (cos phi, sin phi)`` the support function
of the outline is ``h(phi) = max_k f_k(phi)`` over *sites*: every point ``P_i`` (``f =
P_i . u``) and every arc of centre ``c`` and radius ``r`` (``f = c . u + r``, only for the
directions ``phi`` of the arc's own points seen from its centre). ``f_j - f_k = D cos(phi -
psi) + (r_j - r_k)`` has one upward zero, ``phi = psi - acos((r_k - r_j) / D)``, so the upper
envelope is found by *wrapping*: from the site that supports direction ``phi``, the next is
the site whose upward crossing comes first (a Jarvis march over sites, O(n h)). The result
is a cyclic sequence of pieces (a vertex or an arc) over normal angles, with a straight
edge wherever the supporting point jumps (its length is the jump). ``h`` is exact on each
piece: ``c . u + r`` (``r = 0`` at a vertex).

Diameter (:class:`CurvedDiameter`). The gripper's squeeze axis seen from the part rotated by
``theta`` is ``u(-theta)``, so ``d(theta) = h(-theta) + h(pi - theta)``; between the angles
where either contact changes piece,

    d(theta) = g . (cos theta, -sin theta) + R = L cos(theta - phase) + R,

``g = c_a - c_b`` the chord between the two pieces' centres and ``R = r_a + r_b``. ``d`` is
smooth except at *edge alignments* (a straight edge parallel to the jaws), where its slope
jumps up by the length of the flush edges (a convex kink). Its local minima are the stable
orientations of a squeeze: flush edges (kinks with slopes - then +), and smooth minima at
``theta = phase + pi`` inside a piece (two arcs touching, e.g. an oval's minor axis); its
maxima, the basin boundaries, lie inside pieces at ``theta = phase`` (or at flat stretches:
``L = 0``, a jaw on each side of one circle, where the part is neutral; the boundary is
put at the middle of the stretch).

Certainty. If every point of the outline may be off by ``e`` (the flattening tolerance of
non-arc curves plus the user's shape tolerance), then ``h`` is off by at most ``e`` and
``d`` by at most ``delta = 2 e``. A local minimum of the true ``d`` is certain only if it lies
more than ``2 delta`` below both neighbouring maxima (persistence: the minimum can rise by
``delta`` and the maximum drop by ``delta``), so minimum/maximum pairs shallower than
``4 e`` (and than ``Tolerance.barrier`` times the size, as for polygons) are cancelled,
shallowest first. What is left are the states; a part without any (a disc, a regular
polygon flattened from a circle) cannot be oriented by squeezing and every plan is refused.
A state whose depth is less than :data:`SHALLOW` of its jaw opening is *shallow*: a small
shape error, friction or inertia may carry the part across it (reports warn).

Polygons (all bulges 0, no error) go through :mod:`.diameter` unchanged; this module only
takes over for parts with curves or a shape tolerance (:func:`squeeze_model`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import PartError, PlanningError
from ..tolerance import DEFAULT_TOLERANCE, Tolerance
from .curved_extrema import (
    PUSHER_JAW,
    CurvedDiameter,
    Extremum,
    cancel_shallow,
    curved_diameter,
    extrema_of_pieces,
    refined_extrema,
)
from .curved_ring import SAFE_SIZE, CurvedRing
from .curved_support import CurvedHull, CurvePatches, curved_hull
from .diameter import DiameterFunction, diameter_function
from .polygon import ConvexPolygon, Part
from .push import RadiusFunction
from .transfer import TransferFunction, squeeze_function, transfer_from_extrema

__all__ = [
    "FLAT",
    "SHALLOW",
    "CurvePatches",
    "CurvedDiameter",
    "CurvedHull",
    "CurvedPart",
    "CurvedRadius",
    "CurvedRing",
    "Extremum",
    "RestingState",
    "curved_diameter",
    "curved_hull",
    "curved_part",
    "curved_push",
    "curved_push_grasp",
    "curved_radius",
    "mesh_vertices",
    "push_model",
    "resting_states",
    "squeeze_model",
    "with_shape_tol",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

SHALLOW = 0.01

#: A state is *flat* when ``d`` stays within ``SHALLOW`` of its minimum over more than this
#: angle (radians, 5 degrees) around it.
FLAT = math.radians(5.0)


# Largest coordinate of a part's points (as for polygons), its arcs sampled.
_MAX_REACH = 1e150


# --------------------------------------------------------------------------------------
# Parts


@dataclass(frozen=True, slots=True, eq=False)
class CurvedPart(Part):
    """A part whose outline has arcs or curves: the exact model beside the polygon.

    ``hull`` (a :class:`ConvexPolygon`) is the hull flattened for display, documents and
    simulation; the squeeze and push models use :attr:`curved_hull` and :attr:`ring`.

    Attributes
    ----------
    ring : CurvedRing
        The outline (counter-clockwise), arcs exact, other curves flattened.
    curve_error : float
        Distance within which the flattened non-arc curves follow the drawn ones (0 when
        the outline is made of segments and arcs only).
    shape_tol : float
        A manufacturing tolerance the user gives (``--shape-tol``): every point of the real
        part lies within it of the drawn outline.
    patches : CurvePatches or None
        The flattened curves in exact form (they place the extrema the curves carry).
    hole_rings : tuple of CurvedRing
        The holes with their arcs exact (counter-clockwise), for drawing.
    """

    ring: CurvedRing | None = None
    curve_error: float = 0.0
    shape_tol: float = 0.0
    patches: CurvePatches | None = None
    _model: dict[str, object] = field(default_factory=dict, repr=False)
    hole_rings: tuple[CurvedRing, ...] = ()

    def scaled(self, factor: float, units: str) -> Part:
        """Refused: the exact curves are not converted (save the drawing in ``units``)."""
        raise PartError(
            f"part {self.name!r} is curved and in {self.units}: save the drawing in {units} "
            "(its exact curves are not converted)"
        )

    @property
    def error(self) -> float:
        """The bound on the distance between the model and the real outline."""
        return self.curve_error + self.shape_tol

    @property
    def curved_hull(self) -> CurvedHull:
        """The exact convex hull (computed once)."""
        if "hull" not in self._model:
            if self.ring is None:  # pragma: no cover - built by curved_part
                raise PartError("a curved part needs its `ring`")
            self._model["hull"] = curved_hull(self.ring, self.hull.tol)
        return self._model["hull"]  # type: ignore[return-value]

    @property
    def diameter_function(self) -> CurvedDiameter:
        """The exact diameter function with the certain extrema (computed once)."""
        if "diameter" not in self._model:
            self._model["diameter"] = curved_diameter(
                self.curved_hull, self.error, self.patches, self.shape_tol
            )
        return self._model["diameter"]  # type: ignore[return-value]


def curved_part(
    ring: CurvedRing,
    holes: Sequence[CurvedRing] = (),
    name: str = "part",
    units: str | None = None,
    curve_error: float = 0.0,
    shape_tol: float = 0.0,
    tol: Tolerance = DEFAULT_TOLERANCE,
    display_tol: float | None = None,
    patches: CurvePatches | None = None,
) -> CurvedPart:
    """A part from an outline of segments and arcs (and holes), exact centre of mass.

    The centre of mass is the area centroid of the outline minus the holes, with every arc
    exact. The polygon ``hull`` (display, documents, simulation) is the exact hull sampled
    within ``display_tol`` (default ``1e-3`` of the size).

    Examples
    --------
    >>> p = curved_part(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1]), name="slot")
    >>> np.round(p.center_of_mass, 12).tolist(), p.diameter_function.minima.size
    ([1.0, 0.0], 1)
    """
    a0, c0 = ring.area_centroid()
    if a0 < 0:
        ring = ring.reversed()
        a0, c0 = -a0, c0
    # The holes' areas as fractions of the outline's: their moments relative to it, so
    # that the products stay within range for outlines up to 1e150 across.
    scale = a0 if a0 > 0 and not SAFE_SIZE[0] ** 2 <= a0 <= SAFE_SIZE[1] ** 2 else 1.0
    area, moment = a0 / scale, a0 / scale * c0
    oriented = []
    for h in holes:
        a, c = h.area_centroid()
        area -= abs(a) / scale
        moment = moment - abs(a) / scale * c
        oriented.append(h if a > 0 else h.reversed())
    if not area > 0:
        area *= scale
        raise PartError(f"`outline` must enclose a non-zero area; got area {area:.6g}")
    com = moment / area
    hull = curved_hull(ring, tol)
    step = 1e-3 * hull.size if display_tol is None else display_tol
    outline, around = ring.flattened(step), hull.boundary(step)
    reach = max(float(np.max(np.abs(outline))), float(np.max(np.abs(around))))
    if reach > _MAX_REACH:  # an arc reaching (or sampled) past the limit its points keep
        raise PartError(
            f"`outline` reaches {reach:.17g} in absolute value along its arcs; the limit is "
            f"{_MAX_REACH:g} (rescale the part's units)"
        )
    sampled = ConvexPolygon.from_points(around, hull.tol)
    base = Part.from_outline(
        outline,
        [h.flattened(step) for h in oriented],
        name=name,
        center_of_mass=com,
        units=units,
        tol=tol,
    )
    part = CurvedPart(
        base.name,
        sampled,
        base.outline,
        base.center_of_mass,
        base.units,
        base.holes,
        ring,
        float(curve_error),
        float(shape_tol),
        patches,
        hole_rings=tuple(oriented),
    )
    part._model["hull"] = hull
    return part


def with_shape_tol(part: Part, shape_tol: float) -> Part:
    """The part with a manufacturing tolerance: minima it could lose are not states.

    A polygon becomes a :class:`CurvedPart` of straight pieces (the same hull and centre
    of mass) so that the tolerance can apply. ``shape_tol`` 0 returns the part unchanged.

    Raises
    ------
    PartError
        ``shape_tol`` is negative or not finite.
    """
    if isinstance(shape_tol, bool) or not math.isfinite(shape_tol) or shape_tol < 0:
        raise PartError(f"`shape_tol` must be a finite number >= 0; got {shape_tol!r}")
    if shape_tol == 0:
        return part
    if isinstance(part, CurvedPart):
        out = replace(part, shape_tol=float(shape_tol), _model={})
        return out
    ring = CurvedRing(part.outline, np.zeros(len(part.outline)))
    return CurvedPart(
        part.name,
        part.hull,
        part.outline,
        part.center_of_mass,
        part.units,
        part.holes,
        ring,
        0.0,
        float(shape_tol),
    )


# --------------------------------------------------------------------------------------
# What the squeeze sees: states, and what the part rests on


@dataclass(frozen=True, slots=True)
class RestingState:
    """How the part lies at a stable orientation over ``[0, pi)``.

    Attributes
    ----------
    theta : float
        The stable orientation (radians).
    width : float
        The jaw opening there.
    depth : float
        How far ``d`` rises to the lower of the neighbouring maxima.
    edges : tuple of tuple of ndarray
        The straight edges flush with a jaw (their two ends), empty for a smooth minimum.
    shallow : bool
        ``depth < SHALLOW * width``.
    flat : tuple of float
        ``(lo, hi)``: the stretch of the basin around ``theta`` where ``d`` stays within
        ``SHALLOW`` of ``width``. A squeeze turns the part there with so little torque that
        support friction may stop it anywhere in the stretch: when it is wider than
        :data:`FLAT` the final orientation is only known to lie in it.
    """

    theta: float
    width: float
    depth: float
    edges: tuple[tuple[FloatArray, FloatArray], ...]
    shallow: bool
    flat: tuple[float, float] = (0.0, 0.0)

    @property
    def is_flat(self) -> bool:
        """Whether the flat stretch is wider than :data:`FLAT`."""
        return self.flat[1] - self.flat[0] > FLAT


def resting_states(d: CurvedDiameter) -> list[RestingState]:
    """The certain minima over ``[0, pi)`` with their flush edges and depths.

    Examples
    --------
    >>> slot = CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1])
    >>> [(round(float(np.degrees(s.theta)), 6), len(s.edges)) for s in
    ...  resting_states(curved_diameter(curved_hull(slot)))]
    [(90.0, 2)]
    """
    kept = list(d.kept)
    out: list[RestingState] = []
    hull = d.hull
    tol = hull.tol.angle
    for i, e in enumerate(kept):
        if e.is_max:
            continue
        lo, hi = kept[i - 1].value, kept[(i + 1) % len(kept)].value
        depth = min(lo, hi) - e.value
        edges = []
        for phi in (-e.theta, math.pi - e.theta):
            k = int(hull.piece_index(phi + tol))
            if abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol and hull.edges[k]:
                edges.append(hull.edge_ends(k))
        a = kept[i - 1].theta if len(kept) > 1 else e.theta - math.pi / 2
        b = kept[(i + 1) % len(kept)].theta if len(kept) > 1 else e.theta + math.pi / 2
        lo = e.theta - ((e.theta - a) % math.pi or math.pi)
        hi = e.theta + ((b - e.theta) % math.pi or math.pi)
        grid = np.linspace(lo, hi, 2001)
        low = d(grid) <= e.value * (1.0 + SHALLOW)
        at = int(np.argmin(np.abs(grid - e.theta)))
        left = at - int(np.argmin(low[at::-1])) if not low[at::-1].all() else 0
        right = at + int(np.argmin(low[at:])) if not low[at:].all() else len(grid) - 1
        flat = (float(grid[max(left, 0)]), float(grid[min(right, len(grid) - 1)]))
        out.append(
            RestingState(e.theta, e.value, depth, tuple(edges), depth < SHALLOW * e.value, flat)
        )
    return out


def squeeze_model(part: Part) -> tuple[DiameterFunction | CurvedDiameter, TransferFunction]:
    """The diameter function and the squeeze function of any part.

    A polygon (a plain :class:`Part`) gets those of :mod:`.diameter` and :mod:`.transfer`,
    unchanged; a :class:`CurvedPart` the exact curved ones (states: the certain minima).

    Raises
    ------
    PlanningError
        The part has no certain stable orientation (a disc, or every minimum within the
        error bound): a squeeze cannot orient it.
    """
    if not isinstance(part, CurvedPart):
        d = diameter_function(part.hull)
        return d, squeeze_function(d)
    cd = part.diameter_function
    if cd.minima.size == 0:
        raise PlanningError(_no_state_reason(part, cd))
    mins = np.concatenate([cd.minima, cd.minima + math.pi])
    maxs = np.concatenate([cd.maxima, cd.maxima + math.pi])
    angle = part.hull.tol.angle
    return cd, transfer_from_extrema("squeeze", mins, maxs, angle, angle)


def _no_state_reason(part: CurvedPart, d: CurvedDiameter) -> str:
    """Why a part has no stable orientation (one line)."""
    grid = d(np.linspace(0.0, math.pi, 4097))
    spread = float(grid.max() - grid.min())
    units = f" {part.units}" if part.units else ""
    if spread <= d.hull.tol.length_for(d.hull.size) * 10:
        return (
            f"part {part.name!r} has no stable orientation: its width is the same "
            f"({float(grid.mean()):.6g}{units}) at every orientation (a disc), so a squeeze "
            "leaves it where it is and no plan can orient it"
        )
    return (
        f"part {part.name!r} has no stable orientation that is certain: its width varies by "
        f"{spread:.3g}{units}, no more than the error bound allows "
        f"(4 x {d.error:.3g}{units}: flattening and --shape-tol), so no plan can orient it"
    )


def mesh_vertices(part: Part, fine: float = 1e-4) -> FloatArray:
    """Hull vertices for a simulation: a curved part's arcs within ``fine`` times its size.

    A polygon's own hull vertices; for a :class:`CurvedPart` the exact hull sampled so
    finely that no chord is a facet the part could rest on in the engine.
    """
    if isinstance(part, CurvedPart):
        hull = part.curved_hull
        tol = fine * hull.size
        pts = [hull.boundary(tol)]
        if part.patches is not None:
            pts.append(part.patches.points(tol))
        return ConvexPolygon.from_points(np.concatenate(pts), hull.tol).vertices
    return np.asarray(part.hull.vertices, dtype=np.float64)


# --------------------------------------------------------------------------------------
# Pushing: the radius function about the centre of mass


@dataclass(frozen=True, slots=True, eq=False)
class CurvedRadius:
    """The exact radius function of a curved part over ``[0, 2 pi)``, and its extrema.

    ``r(theta) = h(pi - theta) - c . u(pi - theta)`` (``c`` the centre of mass; Mason 1986,
    Goldberg 1993 section 5): on each piece ``chords[k] . (cos theta, -sin theta) +
    offsets[k]`` with ``chords = c - centre`` of the touching vertex or arc. Minima are
    stable pushes (an edge flush with the pushing jaw whose foot of the perpendicular from
    ``c`` lies inside it, or a smooth minimum on an arc: a disc rolls its centre of mass
    down), maxima the unstable equilibria; pairs shallower than ``2 error`` (``r`` is off by
    at most ``error``) are cancelled.
    """

    breaks: FloatArray
    chords: FloatArray
    offsets: FloatArray
    minima: FloatArray
    maxima: FloatArray
    center_of_mass: FloatArray

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """``r(theta)``, vectorised."""
        th = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], TWO_PI)
        k = np.clip(np.searchsorted(self.breaks - self.breaks[0], th, side="right") - 1, 0, None)
        th = th + self.breaks[0]
        g = self.chords[k]
        out: FloatArray = g[..., 0] * np.cos(th) - g[..., 1] * np.sin(th) + self.offsets[k]
        return out


def curved_radius(part: CurvedPart) -> CurvedRadius:
    """The radius function of a curved part about its centre of mass (see CurvedRadius).

    Examples
    --------
    >>> slot = curved_part(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1]))
    >>> np.degrees(curved_radius(slot).minima).round(6).tolist()
    [90.0, 270.0]
    """
    if "radius" in part._model:
        return part._model["radius"]  # type: ignore[return-value]
    hull = part.curved_hull
    com = np.asarray(part.center_of_mass, dtype=np.float64)
    atol = hull.tol.angle
    b = np.sort(np.mod(math.pi - hull.starts, TWO_PI))
    wide = np.diff(b, prepend=b[-1] - TWO_PI) > atol
    breaks = b[wide] if wide.any() else b[:1]
    ends = np.append(breaks[1:], breaks[0] + TWO_PI)
    k = hull.piece_index(math.pi - 0.5 * (breaks + ends))
    chords = com - hull.centers[k]
    offsets = np.array(hull.radii[k], dtype=np.float64)
    ext = extrema_of_pieces(breaks, chords, offsets, hull, atol, TWO_PI, PUSHER_JAW)
    depth = max(hull.tol.barrier_for(hull.size), 2.0 * part.error)
    kept = cancel_shallow(ext, depth)
    patches = part.patches
    if patches is not None and (len(patches.bezier) or len(patches.ellipses)):
        kept = refined_extrema(hull, kept, patches, TWO_PI, PUSHER_JAW, com)
    if not kept:
        raise PlanningError(
            f"part {part.name!r} has no stable orientation under a push: its radius about the "
            "centre of mass varies by no more than the error bound allows"
        )
    minima = np.array(sorted(e.theta for e in kept if not e.is_max), dtype=np.float64)
    maxima = np.array(sorted(e.theta for e in kept if e.is_max), dtype=np.float64)
    out = CurvedRadius(breaks, chords, offsets, minima, maxima, com)
    part._model["radius"] = out
    return out


def curved_push(part: CurvedPart) -> TransferFunction:
    """The push function of a curved part: descend its exact radius function."""
    r = curved_radius(part)
    angle = part.hull.tol.angle
    return transfer_from_extrema("push", r.minima, r.maxima, angle, angle)


def curved_push_grasp(
    part: CurvedPart, squeeze: TransferFunction | None = None
) -> TransferFunction:
    """The push-grasp function ``s o p`` of a curved part (its exact push and squeeze)."""
    from .push import compose_push_grasp

    s = squeeze if squeeze is not None else squeeze_model(part)[1]
    r = curved_radius(part)
    return compose_push_grasp(r.minima, r.maxima, s, part.hull.tol.angle)


def push_model(part: Part) -> tuple[RadiusFunction, TransferFunction, TransferFunction]:
    """The radius function of the hull polygon, the push and the push-grasp function.

    A polygon's as :mod:`.push` builds them; a :class:`CurvedPart`'s push and push-grasp
    functions are the exact curved ones (the polygon's radius function then only names the
    nearest hull edges in reports).
    """
    from .push import push_function, push_grasp_function, radius_function

    r = radius_function(part)
    if isinstance(part, CurvedPart):
        return r, curved_push(part), curved_push_grasp(part)
    return r, push_function(r), push_grasp_function(part)
