"""The exact diameter function of a convex polygon (the seed, Appendix A).

``d(theta)`` is the width, along the gripper's squeeze axis x, of the part rotated
counter-clockwise by ``theta``. With the part's vertices ``v`` and the world x-axis seen from
the part, ``u(theta) = (cos theta, -sin theta)``,

    d(theta) = max_i <v_i, u> - min_j <v_j, u> = <v_i* - v_j*, u> = l |cos(theta - phi)|,

where ``(v_i*, v_j*)`` is the antipodal vertex pair touching the two jaws, ``l`` its length and
``phi`` the orientation at which that chord lies along x. The touching pair only changes when
an edge becomes parallel to the jaws (an *edge alignment*, ``theta = -nu_e mod pi`` for the
edge's outward normal angle ``nu_e``), so ``d`` is a sinusoid on each interval between
consecutive alignments (Appendix A). We find each interval's pair by rotating calipers
done as a binary search of the sorted edge normals: O(n log n) for all pieces.

Extrema: ``d`` is the maximum of sinusoids, so it is concave inside a piece and has convex
kinks at alignments. Minima can only be kinks whose left slope is negative and right slope
positive; maxima are the points inside a piece where its chord lies along x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import BayesGraspError
from .geometry import ConvexPolygon

__all__ = ["DiameterFunction", "diameter_function"]

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


def _support_index(normals_sorted: FloatArray, order: IntArray, phi: FloatArray) -> IntArray:
    """Index of the vertex of largest projection on direction ``phi`` (rotating calipers).

    Vertex ``i`` is extreme for directions between the outward normals of edges ``i - 1`` and
    ``i``; so the first sorted normal at or after ``phi`` names the edge that starts there.
    """
    k = np.searchsorted(normals_sorted, np.mod(phi, TWO_PI), side="left")
    return order[k % len(order)]


@dataclass(frozen=True, slots=True, eq=False)
class DiameterFunction:
    """Piecewise-sinusoidal diameter function over one period ``[0, pi)``.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] + pi``);
    on it ``d(theta) = lengths[k] * cos(theta - phases[k])``, with ``phases[k]`` within
    ``pi / 2`` of every angle of the piece. All arrays are read-only.

    Attributes
    ----------
    polygon : ConvexPolygon
    breaks : ndarray of shape (P,)
        Edge-alignment angles in ``[0, pi)``, increasing (parallel edges give one).
    lengths : ndarray of shape (P,)
        Length of the chord touching both jaws on each piece.
    phases : ndarray of shape (P,)
        Orientation at which that chord lies along the squeeze axis.
    pairs : ndarray of shape (P, 2)
        Indices of the vertices touching the +x and -x jaws on each piece.
    minima : ndarray
        Local minima in ``[0, pi)`` (edge alignments where ``d`` is locally least).
    maxima : ndarray
        Local maxima in ``[0, pi)`` (unstable equilibria of a squeeze).

    Examples
    --------
    >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> np.degrees(d.minima).round(6).tolist(), d([0.0, np.pi / 2]).round(12).tolist()
    ([0.0, 90.0], [2.0, 1.0])
    """

    polygon: ConvexPolygon
    breaks: FloatArray
    lengths: FloatArray
    phases: FloatArray
    pairs: IntArray
    minima: FloatArray
    maxima: FloatArray

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Evaluate ``d`` at any angles (radians), vectorised.

        Examples
        --------
        >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
        >>> np.round(d([0.0, np.pi / 4]), 12).tolist()
        [1.0, 1.414213562373]
        """
        th = np.asarray(theta, dtype=np.float64)
        k = self.piece_index(th)
        return self.lengths[k] * np.abs(np.cos(th - self.phases[k]))

    def piece_index(self, theta: ArrayLike) -> IntArray:
        """Index of the piece holding each angle."""
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        k = np.searchsorted(self.breaks - self.breaks[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.breaks) - 1), dtype=np.intp)

    @property
    def diameter(self) -> float:
        """The polygon's diameter (the largest value of ``d``)."""
        return float(self.lengths.max())


def diameter_function(polygon: ConvexPolygon) -> DiameterFunction:
    """Build the exact diameter function of a convex polygon in O(n log n).

    Parameters
    ----------
    polygon : ConvexPolygon

    Returns
    -------
    DiameterFunction

    Examples
    --------
    >>> tri = ConvexPolygon.from_points([(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)])
    >>> d = diameter_function(tri)
    >>> len(d.minima), len(d.maxima)
    (3, 3)
    """
    v = polygon.vertices
    tol = polygon.tol.angle
    e = np.roll(v, -1, axis=0) - v  # (n, 2) edge i runs from v_i to v_{i+1}
    normals = np.mod(np.arctan2(e[:, 1], e[:, 0]) - math.pi / 2, TWO_PI)  # outward, CCW hull
    order = np.argsort(normals)
    normals_sorted = normals[order]

    # Edge alignments: edge parallel to the jaws when its normal is along +-x.
    b = np.sort(np.mod(-normals, math.pi))
    gaps = np.diff(np.append(b, b[0] + math.pi))
    keep = gaps > tol  # merge parallel edges (the later of two equal angles is dropped)
    if not keep.any():  # pragma: no cover - a polygon has two non-parallel edges
        raise BayesGraspError("internal error: no edge alignments")
    # Keep b[i] when the gap *before* it is wide; the first angle always survives.
    gaps_before = np.diff(np.append(b[-1] - math.pi, b))
    breaks = b[gaps_before > tol] if (gaps_before > tol).any() else b[:1]
    if len(breaks) == 0:  # pragma: no cover
        breaks = b[:1]
    ends = np.append(breaks[1:], breaks[0] + math.pi)
    mids = 0.5 * (breaks + ends)  # (P,)

    # The jaw at +x touches the vertex of largest projection on u(theta) = direction -theta.
    i_plus = _support_index(normals_sorted, order, -mids)
    i_minus = _support_index(normals_sorted, order, math.pi - mids)
    chord = v[i_plus] - v[i_minus]  # (P, 2)
    lengths = np.hypot(chord[:, 0], chord[:, 1])
    gamma = np.arctan2(chord[:, 1], chord[:, 0])
    # d = <chord, u(theta)> = l cos(theta + gamma); write phase near the piece's midpoint.
    phases = mids - (np.mod(mids + gamma + math.pi, TWO_PI) - math.pi)

    # Slopes at the ends of each piece: sign of (phase - angle), zero within tolerance.
    slope_left_end = np.sign(phases - breaks) * (np.abs(phases - breaks) > tol)
    slope_right_end = np.sign(phases - ends) * (np.abs(phases - ends) > tol)
    interior_max = (slope_left_end > 0) & (slope_right_end < 0)
    prev_right = np.roll(slope_right_end, 1)  # slope of the piece before each break
    kink_min = (prev_right < 0) & (slope_left_end > 0)
    kink_max = (prev_right == 0) & (slope_left_end == 0)

    maxima = np.sort(np.mod(np.concatenate([phases[interior_max], breaks[kink_max]]), math.pi))
    minima = np.sort(np.mod(breaks[kink_min], math.pi))
    if len(maxima) != len(minima) or len(minima) == 0:  # pragma: no cover - a bug, not input
        raise BayesGraspError(
            f"internal error: {len(minima)} minima and {len(maxima)} maxima of the diameter"
        )

    arrays = (breaks, lengths, phases, np.stack([i_plus, i_minus], axis=1), minima, maxima)
    for arr in arrays:
        arr.setflags(write=False)
    return DiameterFunction(polygon, *arrays)
