"""Transfer functions: what one action does to the part's orientation.

A transfer function here is a step function on the circle: the part, at orientation
``theta`` in the gripper frame, ends at ``F(theta)``. Both the squeeze function (the seed,
section 4.2) and the push-grasp function (Goldberg 1993) have this form: finitely many stable
orientations, each with a *basin* (an open arc between consecutive unstable equilibria) that
it attracts, and ``F(theta + 2 pi) = F(theta) + 2 pi`` with ``F`` non-decreasing. An
orientation exactly at a basin boundary is an unstable equilibrium and stays where it is.

The squeeze function descends the diameter function: each minimum of ``d`` over ``[0, 2 pi)``
is a stable orientation and its basin runs between the neighbouring maxima. It commutes with
the part's symmetry: ``s(theta + T) = s(theta) + T`` for the period ``T`` (pi, or
``2 pi / (r (1 + r mod 2))`` for an r-fold symmetric part, Goldberg 1993).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .diameter import DiameterFunction, diameter_function
from .errors import BayesGraspError
from .geometry import ConvexPolygon

__all__ = ["TransferFunction", "detect_period", "squeeze_function", "transfer_from_extrema"]

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class TransferFunction:
    """A monotone step function on the circle: stable orientations and their basins.

    State ``i`` is the stable orientation ``stable[i]`` in ``[0, 2 pi)`` (increasing); its
    basin is the open arc ``(basin_lo[i], basin_hi[i])`` around it (``basin_lo[0]`` may be
    negative and ``basin_hi[-1]`` may pass ``2 pi``). Basins tile the circle.

    Attributes
    ----------
    kind : str
        ``"squeeze"`` or ``"push-grasp"`` (or ``"push"``).
    stable, basin_lo, basin_hi : ndarray of shape (K,)
    period : float
        Smallest ``T`` with ``F(theta + T) = F(theta) + T`` (divides ``2 pi``).
    angle_tol : float
        Angles closer than this are equal.

    Examples
    --------
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    >>> np.degrees(s.stable).round(6).tolist(), round(float(np.degrees(s.period)), 6)
    ([0.0, 90.0, 180.0, 270.0], 90.0)
    >>> float(np.degrees(s(np.radians(30.0))))
    0.0
    """

    kind: str
    stable: FloatArray
    basin_lo: FloatArray
    basin_hi: FloatArray
    period: float
    angle_tol: float

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Final orientation in ``[0, 2 pi)`` for each initial orientation (vectorised).

        An orientation within ``angle_tol`` of a basin boundary is an unstable equilibrium
        and is returned unchanged (reduced to ``[0, 2 pi)``).
        """
        th = np.mod(np.asarray(theta, dtype=np.float64), TWO_PI)
        idx = self.state_index(th)
        out = self.stable[idx]
        at_edge = (
            np.minimum(
                np.abs(np.mod(th - self.basin_lo[idx] + math.pi, TWO_PI) - math.pi),
                np.abs(np.mod(th - self.basin_hi[idx] + math.pi, TWO_PI) - math.pi),
            )
            <= self.angle_tol
        )
        return np.where(at_edge, th, out)

    def state_index(self, theta: ArrayLike) -> NDArray[np.intp]:
        """Index of the basin that holds each orientation."""
        th = np.mod(np.asarray(theta, dtype=np.float64), TWO_PI)
        hi = np.mod(self.basin_hi, TWO_PI)
        order = np.argsort(hi)
        k = np.searchsorted(hi[order], th, side="right")
        return order[k % len(order)]

    @property
    def n_states(self) -> int:
        """Number of stable orientations over ``[0, 2 pi)``."""
        return len(self.stable)

    @property
    def boundaries(self) -> FloatArray:
        """Basin boundaries (unstable equilibria) in ``[0, 2 pi)``, increasing."""
        return np.sort(np.mod(self.basin_hi, TWO_PI))

    @property
    def widths(self) -> FloatArray:
        """Width of each basin (radians)."""
        return self.basin_hi - self.basin_lo


def detect_period(stable: FloatArray, boundaries: FloatArray, tol: float) -> float:
    """Smallest shift ``T = 2 pi / m`` mapping both point sets onto themselves.

    ``m`` runs over the divisors of ``K = len(stable)``; a shift by ``T`` moves every point
    ``K / m`` places along, so the test is exact up to ``tol`` radians for any ``m``.

    Examples
    --------
    >>> T = detect_period(np.radians([0.0, 120, 240]), np.radians([60.0, 180, 300]), 1e-9)
    >>> round(float(np.degrees(T)), 9)
    120.0
    """
    k = len(stable)
    for m in range(k, 1, -1):
        if k % m:
            continue
        step = k // m
        t = TWO_PI / m
        ok = True
        for pts in (stable, boundaries):
            diff = np.mod(np.roll(pts, -step) - pts - t + math.pi, TWO_PI) - math.pi
            if np.max(np.abs(diff)) > tol:
                ok = False
                break
        if ok:
            return t
    return TWO_PI


def transfer_from_extrema(
    kind: str, minima: FloatArray, maxima: FloatArray, angle_tol: float, period_tol: float
) -> TransferFunction:
    """Build a transfer function from its stable orientations and unstable equilibria.

    Parameters
    ----------
    kind : str
    minima, maxima : ndarray
        Stable orientations and basin boundaries over ``[0, 2 pi)``; they must alternate.
    angle_tol, period_tol : float
        Angle equality, and the looser tolerance of the period test.
    """
    stable = np.sort(np.mod(minima, TWO_PI))
    bounds = np.sort(np.mod(maxima, TWO_PI))
    if len(stable) != len(bounds) or len(stable) == 0:  # pragma: no cover - a bug
        raise BayesGraspError("internal error: stable orientations and boundaries differ")
    # The boundary above each stable orientation (wrapping past 2 pi).
    k = np.searchsorted(bounds, stable, side="right")
    hi = np.where(k < len(bounds), bounds[k % len(bounds)], bounds[0] + TWO_PI)
    lo = np.where(k > 0, bounds[k - 1], bounds[-1] - TWO_PI)
    if len(np.unique(k % len(bounds))) != len(stable):  # pragma: no cover - a bug
        raise BayesGraspError("internal error: extrema of the transfer function do not alternate")
    for arr in (stable, lo, hi):
        arr.setflags(write=False)
    period = detect_period(stable, bounds, period_tol)
    return TransferFunction(kind, stable, lo, hi, period, angle_tol)


def squeeze_function(
    part: ConvexPolygon | DiameterFunction,
) -> TransferFunction:
    """The squeeze function of a polygon (the seed, section 4.2).

    Parameters
    ----------
    part : ConvexPolygon or DiameterFunction

    Returns
    -------
    TransferFunction
        Stable orientations are the minima of ``d`` over ``[0, 2 pi)``; basins run between
        consecutive maxima.

    Examples
    --------
    >>> tri = ConvexPolygon.from_points([(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)])
    >>> s = squeeze_function(tri)
    >>> s.n_states, round(float(np.degrees(s.period)), 9), s.widths.round(9).tolist()[0]
    (6, 60.0, 1.047197551)
    """
    d = part if isinstance(part, DiameterFunction) else diameter_function(part)
    poly = d.polygon
    period_tol = poly.tol.symmetry
    minima = np.concatenate([d.minima, d.minima + math.pi])
    maxima = np.concatenate([d.maxima, d.maxima + math.pi])
    return transfer_from_extrema("squeeze", minima, maxima, poly.tol.angle, period_tol)
