"""Pushing: the radius function, the push function and the push-grasp function.

Convention (the documentation's conventions): the *pushing jaw* is the jaw on the gripper's ``-x``
side. It moves toward ``+x`` and touches the part first; the part, at orientation ``theta``
(counter-clockwise, user coordinates, relative to the gripper frame), turns under
quasi-static frictionless pushing until an edge lies flat against that jaw; then the other
jaw arrives and the jaws squeeze.

Radius function (Mason 1986; Goldberg 1993, section 5): ``r(theta)`` is the distance from
the centre of mass ``c`` to the pushing jaw's line of support when the part is at
``theta``. Seen from the part, the jaw's outward direction is ``w(theta) = (-cos theta,
sin theta)`` (the direction at angle ``pi - theta``), so

    r(theta) = max_k <v_k - c, w(theta)> = rho_k cos(theta - (pi - beta_k)),

where vertex ``v_k = c + rho_k (cos beta_k, sin beta_k)`` is the one touching the jaw. The
touching vertex only changes at *edge alignments*, ``theta = pi - nu_i`` for the outward
normal angle ``nu_i`` of edge ``i`` (the edge flat against the jaw), so ``r`` is a sinusoid
on each of the ``n`` pieces between them: concave inside a piece, with convex kinks at the
alignments. Its period is ``2 pi`` (``2 pi / r`` when the part is r-fold symmetric about its
centre of mass): unlike the diameter, it tells ``theta`` from ``theta + pi``.

Why the part descends ``r``: the frictionless jaw pushes along ``+x`` at the contact point
``p`` (relative to ``c``, gripper frame); the part turns the way the force's torque about the
centre of mass, ``-p_y``, turns it (Mason 1986: for a frictionless pusher the rotation sense
is set by the side of the centre of mass the pushing line passes), and
``dr/dtheta = p_y``: so ``theta`` moves against the slope of ``r``. Stable orientations are
the local minima of ``r``: edges whose foot of the perpendicular from ``c`` lies strictly
inside the edge. Unstable equilibria are the local maxima: a vertex whose direction from
``c`` lies inside its normal cone (the pushing line passes through ``c``). The push
function ``p`` sends ``theta`` to the minimum reached by descending ``r``.

Push-grasp (Goldberg 1993; the pushing phase of Brost 1988): after the push, an edge is
flat against the pushing jaw and the second jaw arrives. From then on both jaws touch and
the part moves as in a pure squeeze from ``p(theta)``: it turns to decrease the diameter
``d``. The squeeze **can still rotate the part**: the push stops at an alignment of an edge
with the jaws, which is a kink of ``d`` but a minimum of ``d`` only when the vertex touching
the other jaw projects inside the flat edge. If it projects outside, no balance of the three
contact forces exists (the opposite jaw's force passes outside the flat contact), the edge
lifts off about one of its ends and the part turns down ``d`` to the neighbouring minimum
of ``d``. So the push-grasp function is exactly the composition

    g(theta) = s(p(theta)),

``s`` the squeeze function: a non-decreasing step function with ``g(theta + 2 pi) =
g(theta) + 2 pi``, whose stable orientations are squeeze-stable orientations (the planner's
states) and whose basins are unions of consecutive push basins with the same image. Its
period is ``2 pi`` for a part without rotational symmetry about its centre of mass and
``2 pi / r`` for an r-fold symmetric one (measured, not assumed: see
:func:`~bayesgrasp.geometry.transfer.detect_period`). The centre of mass matters only to the push;
the squeeze does not depend on it (nor on the support friction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import BayesGraspError
from .polygon import ConvexPolygon, Part
from .transfer import TransferFunction, detect_period, squeeze_function, transfer_from_extrema

__all__ = [
    "RadiusFunction",
    "compose_push_grasp",
    "push_function",
    "push_grasp_function",
    "radius_function",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True, eq=False)
class RadiusFunction:
    """Piecewise-sinusoidal radius function about the centre of mass, over ``[0, 2 pi)``.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] +
    2 pi``); on it vertex ``vertex[k]`` touches the pushing jaw and ``r(theta) =
    radii[k] * cos(theta - phases[k])``. All arrays are read-only.

    Attributes
    ----------
    polygon : ConvexPolygon
        The hull (what the jaw touches).
    center_of_mass : ndarray of shape (2,)
    breaks : ndarray of shape (n,)
        Edge-alignment angles in ``[0, 2 pi)``, increasing; ``edge_at_break[k]`` is the hull
        edge (from vertex ``i`` to ``i + 1``) flat against the pushing jaw at ``breaks[k]``.
    edge_at_break : ndarray of shape (n,)
    vertex : ndarray of shape (n,)
        Hull vertex touching the pushing jaw on each piece.
    radii : ndarray of shape (n,)
        Distance of that vertex from the centre of mass.
    phases : ndarray of shape (n,)
        Orientation at which that vertex is straight ahead of the centre of mass (the
        sinusoid's peak; inside the piece only when it is a local maximum of ``r``).
    minima : ndarray
        Stable orientations of pushing in ``[0, 2 pi)``, increasing (edge alignments). For a
        part r-fold symmetric about its centre of mass within ``tol.symmetry``
        (``symmetry_order`` and a centre of mass within that tolerance of the centroid), the
        extrema are those of the symmetrized hull, exactly ``2 pi / r``-periodic (see
        :func:`~bayesgrasp.geometry.diameter.diameter_function`).
    stable_edges : ndarray
        Hull edge flat against the jaw at each minimum.
    maxima : ndarray
        Unstable equilibria in ``[0, 2 pi)``, increasing.

    Examples
    --------
    >>> r = radius_function(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> np.degrees(r.minima).round(6).tolist()
    [0.0, 90.0, 180.0, 270.0]
    >>> np.round(r([0.0, np.pi / 2]), 12).tolist()
    [1.0, 0.5]
    """

    polygon: ConvexPolygon
    center_of_mass: FloatArray
    breaks: FloatArray
    edge_at_break: IntArray
    vertex: IntArray
    radii: FloatArray
    phases: FloatArray
    minima: FloatArray
    stable_edges: IntArray
    maxima: FloatArray

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Evaluate ``r`` at any angles (radians), vectorised.

        Examples
        --------
        >>> r = radius_function(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
        >>> np.round(r([0.0, np.pi / 4]), 12).tolist()
        [0.5, 0.707106781187]
        """
        th = np.asarray(theta, dtype=np.float64)
        k = self.piece_index(th)
        return self.radii[k] * np.cos(th - self.phases[k])

    def piece_index(self, theta: ArrayLike) -> IntArray:
        """Index of the piece holding each angle."""
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], TWO_PI)
        k = np.searchsorted(self.breaks - self.breaks[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.breaks) - 1), dtype=np.intp)


def _hull_and_com(part: Part | ConvexPolygon) -> tuple[ConvexPolygon, FloatArray]:
    if isinstance(part, Part):
        return part.hull, np.asarray(part.center_of_mass, dtype=np.float64)
    return part, np.asarray(part.centroid, dtype=np.float64)


def radius_function(part: Part | ConvexPolygon) -> RadiusFunction:
    """Build the exact radius function about the part's centre of mass in O(n log n).

    Parameters
    ----------
    part : Part or ConvexPolygon
        A :class:`~bayesgrasp.geometry.polygon.Part` uses its ``center_of_mass``; a bare polygon its
        area centroid.

    Returns
    -------
    RadiusFunction

    Examples
    --------
    >>> r = radius_function(Part.from_points([(0, 0), (4, 0), (0, 1)]))
    >>> len(r.minima), len(r.maxima), r.stable_edges.tolist()
    (3, 3, [2, 1, 0])
    """
    poly, c = _hull_and_com(part)
    v = poly.vertices
    n = len(v)
    tol = poly.tol
    ltol = tol.length_for(poly.size)
    align = _alignments(v)
    order = np.argsort(align)
    breaks = align[order]
    # As theta grows past the alignment of edge i, vertex i touches (until edge i - 1).
    vertex = order.astype(np.intp)
    rel = v - c  # (n, 2)
    radii = np.hypot(rel[:, 0], rel[:, 1])[vertex]
    beta = np.arctan2(rel[:, 1], rel[:, 0])[vertex]
    ends = np.append(breaks[1:], breaks[0] + TWO_PI)
    mids = 0.5 * (breaks + ends)
    # Write each phase within pi of its piece's middle.
    phases = mids + (np.mod(math.pi - beta - mids + math.pi, TWO_PI) - math.pi)

    r = poly.symmetry_order
    if r > 1 and math.dist(c, poly.centroid) <= tol.symmetry_for(poly.size):
        # Symmetric about the centre of mass within the tolerance: treated as exactly
        # symmetric, like the diameter function (its extrema over one period 2 pi / r of
        # the symmetrized hull, repeated; vertex i + k n / r is vertex i turned k times).
        step, period = n // r, TWO_PI / r
        at, is_max, angle = _push_extrema(poly.symmetrized(centred=True), np.zeros(2), ltol, step)
        turns = np.arange(r)
        minima = (angle[~is_max][:, None] + period * turns).ravel()
        # Turning the part by 2 pi k / r brings edge i - k n / r where edge i was.
        edges = (at[~is_max][:, None] - step * turns) % n
        maxima = (angle[is_max][:, None] + period * turns).ravel()
        minima, maxima = _wrap(minima), np.sort(_wrap(maxima))
    else:
        at, is_max, angle = _push_extrema(v, c, ltol, n)
        minima, edges, maxima = angle[~is_max], at[~is_max], np.sort(angle[is_max])
    mo = np.argsort(minima, kind="stable")
    minima, minima_edges = minima[mo], np.asarray(edges.ravel()[mo], dtype=np.intp)
    if len(minima) != len(maxima) or len(minima) == 0 or n < 3:  # pragma: no cover - a bug
        raise BayesGraspError(
            f"internal error: {len(minima)} minima and {len(maxima)} maxima of the radius"
        )
    arrays = (breaks, order.astype(np.intp), vertex, radii, phases, minima, minima_edges, maxima)
    for arr in arrays:
        arr.setflags(write=False)
    com = c.copy()
    com.setflags(write=False)
    return RadiusFunction(poly, com, *arrays)


def _wrap(x: FloatArray) -> FloatArray:
    """``x`` reduced to ``[0, 2 pi)`` (``np.mod`` can round a tiny negative to ``2 pi``)."""
    out = np.mod(x, TWO_PI)
    out[out >= TWO_PI] = 0.0
    return out


def _alignments(v: FloatArray) -> FloatArray:
    """Orientation in ``[0, 2 pi)`` at which each edge lies flat against the pushing jaw."""
    e = np.roll(v, -1, axis=0) - v  # (n, 2) edge i runs from v_i to v_{i+1}
    normals = np.arctan2(e[:, 1], e[:, 0]) - math.pi / 2  # outward normals, CCW hull
    return np.asarray(np.mod(math.pi - normals, TWO_PI), dtype=np.float64)


def _push_extrema(
    v: FloatArray, c: FloatArray, ltol: float, w: int
) -> tuple[IntArray, NDArray[np.bool_], FloatArray]:
    """Extrema of the radius function over the first ``w`` pieces, read as one period.

    As for the diameter (see diameter.py): the slopes of ``r`` at the start and end of the
    pieces, in angle order, form one cyclic sequence of signs (zero within the length
    tolerance: a foot of the perpendicular from ``c`` at a vertex); without the zeros, each
    change from - to + is a minimum at an edge alignment and each change from + to - a
    maximum, so they alternate whatever the zeros. A maximum with no zero between, inside a
    piece, is at its vertex's direction from ``c``; every other extremum is at the first
    edge alignment after the last nonzero sign. ``w`` is ``n``, or ``n / r`` for a polygon
    with that symmetry about ``c``: the first ``w`` pieces from the first alignment are then
    one period, read as one cyclic sequence.

    Returns
    -------
    at : ndarray of int
        For a minimum, the edge flat against the jaw; for a maximum, -1.
    is_max : ndarray of bool
    angle : ndarray
        Where each extremum lies (from ``[0, 2 pi)``; an interior maximum of the last piece
        may be a little past ``2 pi``).
    """
    e = np.roll(v, -1, axis=0) - v  # (n, 2) edge i runs from v_i to v_{i+1}
    eu = e / np.hypot(e[:, 0], e[:, 1])[:, None]  # unit edge directions
    rel = v - c  # (n, 2)
    # Slopes of r at the ends of piece k (vertex k touching): at the alignment of edge k
    # (its left end) dr/dtheta = <c - v_k, e_k>, at that of edge k - 1 (its right end)
    # <c - v_k, e_{k-1}>; zero within the length tolerance (a foot exactly at a vertex).
    a = -np.einsum("ij,ij->i", rel, eu)  # (n,)
    b = -np.einsum("ij,ij->i", rel, np.roll(eu, 1, axis=0))  # (n,)
    align = _alignments(v)
    order = np.argsort(align)  # piece k starts at the alignment of edge order[k]
    breaks = align[order]
    signs = np.empty(2 * w, dtype=np.int8)
    signs[0::2] = (a[order[:w]] > ltol).astype(np.int8) - (a[order[:w]] < -ltol)
    signs[1::2] = (b[order[:w]] > ltol).astype(np.int8) - (b[order[:w]] < -ltol)
    nonzero = np.flatnonzero(signs)
    sig = signs[nonzero]
    change = np.flatnonzero(sig != np.roll(sig, 1))
    last = np.roll(nonzero, 1)[change]
    is_max = np.roll(sig, 1)[change] > 0
    interior = is_max & (np.mod(nonzero[change] - last, 2 * w) == 1) & (last % 2 == 0)
    k = (last + 2) // 2 % w  # the alignment after entry `last`
    angle = breaks[k].copy()
    top = order[last[interior] // 2]  # the vertex straight ahead of c at an interior maximum
    angle[interior] = np.mod(math.pi - np.arctan2(rel[top, 1], rel[top, 0]), TWO_PI)
    at = np.where(is_max, -1, order[k]).astype(np.intp)
    return at, is_max, angle


def _basins(minima: FloatArray, maxima: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Sorted minima in ``[0, 2 pi)`` and the maxima just below and above each.

    Both arrays are sorted in ``[0, 2 pi)`` and alternate (as transfer_from_extrema builds
    them).
    """
    k = np.searchsorted(maxima, minima)  # (K,) index of the first maximum above
    hi = np.where(k < len(maxima), maxima[k % len(maxima)], maxima[0] + TWO_PI)
    lo = np.where(k > 0, maxima[k - 1], maxima[-1] - TWO_PI)
    return minima, lo, hi


def push_function(part: Part | ConvexPolygon | RadiusFunction) -> TransferFunction:
    """The push function: descend the radius function (period ``2 pi``).

    Parameters
    ----------
    part : Part, ConvexPolygon or RadiusFunction

    Returns
    -------
    TransferFunction
        ``kind == "push"``; stable orientations are the minima of ``r`` (an edge flat
        against the pushing jaw), basins run between consecutive maxima.

    Examples
    --------
    >>> p = push_function(Part.from_points([(0, 0), (4, 0), (0, 1)]))
    >>> np.degrees(p.stable).round(3).tolist(), round(float(np.degrees(p.period)), 3)
    ([0.0, 104.036, 270.0], 360.0)
    """
    r = part if isinstance(part, RadiusFunction) else radius_function(part)
    tol = r.polygon.tol
    return transfer_from_extrema("push", r.minima, r.maxima, tol.angle, tol.angle)


def push_grasp_function(
    part: Part | ConvexPolygon, squeeze: TransferFunction | None = None
) -> TransferFunction:
    """The push-grasp function ``g = s o p``: push until an edge is flat, then squeeze.

    See the module docstring for why the squeeze may still turn the part.

    Parameters
    ----------
    part : Part or ConvexPolygon
    squeeze : TransferFunction, optional
        The part's squeeze function, if already built.

    Returns
    -------
    TransferFunction
        ``kind == "push-grasp"``; its stable orientations are squeeze-stable orientations
        (exactly the same floats), its basins unions of push basins.

    Examples
    --------
    >>> part = Part.from_points([(0, 0), (4, 0), (0, 1)])
    >>> g = push_grasp_function(part)
    >>> np.degrees(g.stable).round(3).tolist(), round(float(np.degrees(g.period)), 3)
    ([104.036, 284.036], 360.0)
    >>> set(g.stable.tolist()) <= set(squeeze_function(part.hull).stable.tolist())
    True
    """
    poly, _ = _hull_and_com(part)
    r = radius_function(part)
    s = squeeze if squeeze is not None else squeeze_function(poly)
    return compose_push_grasp(r.minima, r.maxima, s, poly.tol.angle)


def compose_push_grasp(
    push_minima: FloatArray, push_maxima: FloatArray, s: TransferFunction, angle_tol: float
) -> TransferFunction:
    """``g = s o p`` from the push function's extrema (sorted in ``[0, 2 pi)``) and ``s``.

    See :func:`push_grasp_function`; also used by curved parts (geometry/curved.py).
    """
    p_stable, p_lo, p_hi = _basins(push_minima, push_maxima)
    idx = s.state_index(p_stable)  # squeeze basin holding each push-stable orientation
    image = s.stable[idx]  # (K,) in [0, 2 pi)
    # Lift the images next to their push orientations: a non-decreasing sequence whose
    # wrap-around step is 2 pi less (s moves a part by less than pi).
    lifted = p_stable + (np.mod(image - p_stable + math.pi, TWO_PI) - math.pi)
    prev = np.roll(lifted, 1)
    prev[0] -= TWO_PI
    first = np.flatnonzero(np.abs(lifted - prev) > s.angle_tol)  # (G,) groups' first basins
    last = np.append(first[1:], first[0] + len(lifted)) - 1
    lo_ext = np.concatenate([p_lo, p_lo + TWO_PI])
    hi_ext = np.concatenate([p_hi, p_hi + TWO_PI])
    lo, hi, img = lo_ext[first], hi_ext[last], lifted[first]
    # The image need not lie in its own basin (the squeeze may carry the part past the
    # push's unstable equilibria). Index states by image in [0, 2 pi) and shift each basin
    # by the turns its image was shifted: consecutive basins stay consecutive.
    shift = np.floor(img / TWO_PI) * TWO_PI
    order = np.argsort(img - shift, kind="stable")
    stable = np.asarray(s.stable[idx[first]][order], dtype=np.float64)
    lo, hi = lo[order] - shift[order], hi[order] - shift[order]
    if (
        np.any(np.abs(lo[1:] - hi[:-1]) > s.angle_tol) or abs(hi[-1] - lo[0] - TWO_PI) > s.angle_tol
    ):  # pragma: no cover - a bug
        raise BayesGraspError("internal error: push-grasp basins do not tile the circle")
    for arr in (stable, lo, hi):
        arr.setflags(write=False)
    period = detect_period(stable, np.sort(np.mod(hi, TWO_PI)), angle_tol)
    return TransferFunction("push-grasp", stable, lo, hi, period, angle_tol)
