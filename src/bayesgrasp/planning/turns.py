"""Choosing gripper turns: the arcs between unstable equilibria and the grid of a normal error.

What the noise-aware planners (:mod:`.noisy` for plans, :mod:`.noisy_policy` for policies)
share when they choose a turn ``alpha`` for an action whose value ``f(alpha) = left M(alpha)
right`` they maximise:

- :func:`free_arcs`: with exact turns ``f`` is constant between the *boundary turns*, the
  turns ``S_i - B - o`` that put a state ``S_i`` on a basin boundary ``B`` of a way ``o``
  the action may go (:meth:`~bayesgrasp.model.noise.NoisyTransitions.boundary_turns`).
  At such a turn the part sits on an unstable equilibrium and the squeeze goes either way,
  or jams: a turn is taken in the middle of an arc between them, its *margin*
  (:func:`margin`) the arc's half-width.
- :func:`turn_grid`: under a normal turn error of scale ``sigma``, ``f`` is smooth and, farther
  than :data:`FLAT_SIGMAS` sigma from every critical turn, flat; its maximum is searched on a
  grid of step ``sigma / GRID_PER_SIGMA`` near the critical turns (the planners state the
  grid's bound from ``|f''|``, :attr:`~bayesgrasp.model.noise.TurnNoise.curvature_bound`).

Examples
--------
>>> import numpy as np
>>> starts, mids, half = free_arcs(np.array([0.0, 1.0]), 2 * np.pi, 1e-9)
>>> mids.round(4).tolist(), half.round(4).tolist()
([0.5, -2.6416], [0.5, 2.6416])
>>> round(margin(0.25, np.array([0.0, 1.0]), 2 * np.pi), 6)
0.25
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["FLAT_SIGMAS", "GRID_PER_SIGMA", "free_arcs", "margin", "turn_grid"]

FloatArray = NDArray[np.float64]

GRID_PER_SIGMA = 6
"""Grid points per standard deviation of a normal turn error in the refinement."""
FLAT_SIGMAS = 8.0
"""Farther than this many sigma from every critical turn, ``f`` is flat (to 1e-15)."""


def free_arcs(
    turns: FloatArray, period: float, tol: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The arcs between boundary turns on the circle of turns ``(-g/2, g/2]``.

    Returns their starts (the sorted boundary turns, those closer than ``tol`` merged),
    middles (wrapped) and half-widths: the middle of an arc is its point farthest from every
    boundary turn, by its half-width.
    """
    c = np.unique(np.mod(turns + period / 2, period) - period / 2)
    if len(c) > 1:
        keep = np.append(True, np.diff(c) > tol)
        if c[0] + period - c[-1] <= tol:
            keep[0] = False
        c = c[keep]
    widths = np.diff(np.append(c, c[0] + period))
    mids = np.mod(c + widths / 2 + period / 2, period) - period / 2
    return c, mids, widths / 2


def margin(alpha: float, turns: FloatArray, period: float) -> float:
    """Distance of the turn ``alpha`` to the nearest boundary turn (modulo ``period``)."""
    d = np.mod(turns - alpha + period / 2, period) - period / 2
    return float(np.min(np.abs(d))) if len(d) else math.inf


def turn_grid(crit: FloatArray, period: float, h: float, reach: float) -> FloatArray:
    """Turns to try: a grid of step ``h`` within ``reach`` of the critical turns, one per gap.

    Farther than ``reach`` from every critical turn the line ``f`` is constant to rounding
    (its CDF terms are 0 or 1), so one point of each gap stands for all of it. Where the
    windows cover the period the grid is the whole period's, of step at most ``h``.
    """
    n = max(8, math.ceil(period / h))
    if len(crit) == 0:
        return np.zeros(1)
    c = np.unique(np.mod(crit + period / 2, period) - period / 2)
    per = 2 * math.ceil(reach / h) + 1
    if len(c) * per >= n:
        return -period / 2 + period * (np.arange(n) + 0.5) / n
    offsets = h * (np.arange(per) - per // 2)
    pts = (c[:, None] + offsets[None, :]).ravel()
    gaps = np.diff(np.append(c, c[0] + period))
    wide = gaps > 2.0 * reach
    mids = c[wide] + gaps[wide] / 2
    return np.mod(np.concatenate([pts, mids]) + period / 2, period) - period / 2
