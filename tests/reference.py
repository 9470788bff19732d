"""Brute-force references the exact code must agree with.

Nothing here uses bayesgrasp: the diameter function is the width of the rotated vertices
along the squeeze axis, and the squeeze function is found by walking downhill on a fine grid
of that width, the way the part itself turns between the jaws.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


def width(points: ArrayLike, theta: ArrayLike) -> FloatArray:
    """Width along x of the points rotated counter-clockwise by each ``theta``."""
    p = np.asarray(points, dtype=np.float64)
    th = np.asarray(theta, dtype=np.float64)
    x = np.cos(th)[..., None] * p[:, 0] - np.sin(th)[..., None] * p[:, 1]  # (..., N)
    return np.asarray(x.max(axis=-1) - x.min(axis=-1), dtype=np.float64)


def wrap(angle: ArrayLike, period: float = TWO_PI) -> FloatArray:
    """Signed angle difference reduced to ``[-period / 2, period / 2)``."""
    a = np.asarray(angle, dtype=np.float64)
    return np.asarray(np.mod(a + period / 2, period) - period / 2, dtype=np.float64)


def circle_distance(a: ArrayLike, b: ArrayLike, period: float = TWO_PI) -> FloatArray:
    """Distance between angles on a circle of the given period."""
    return np.abs(wrap(np.asarray(a) - np.asarray(b), period))


def descend(points: ArrayLike, m: int = 1 << 15) -> tuple[FloatArray, FloatArray, IntArray]:
    """Grid descent of the width over ``[0, 2 pi)``.

    From every grid angle the part takes steps of ``2 pi / m`` downhill (to the smaller of
    its two neighbours while that is smaller) until it stops. The walk is iterated by pointer
    doubling: ``2**25`` steps, more than any walk needs.

    Returns
    -------
    theta : ndarray of shape (m,)
        The grid.
    d : ndarray of shape (m,)
        The width on the grid.
    end : ndarray of shape (m,)
        Index of the grid angle where the walk from each grid angle stops.
    """
    theta = np.arange(m) * (TWO_PI / m)
    d = width(points, theta)
    idx = np.arange(m)
    cand = np.stack([(idx - 1) % m, idx, (idx + 1) % m])  # (3, m) stay or step
    step = cand[np.argmin(d[cand], axis=0), idx]  # argmin prefers staying on ties
    for _ in range(25):
        step = step[step]
    return theta, d, step


def local_minima(d: FloatArray) -> IntArray:
    """Indices of strict local minima of a periodic sampled function."""
    return np.flatnonzero((d < np.roll(d, 1)) & (d < np.roll(d, -1)))


def local_maxima(d: FloatArray) -> IntArray:
    """Indices of local maxima (at least one strict side) of a periodic sampled function."""
    left, right = np.roll(d, 1), np.roll(d, -1)
    return np.flatnonzero((d >= left) & (d >= right) & ((d > left) | (d > right)))


def max_pair_distance(points: ArrayLike) -> float:
    """Largest distance between two of the points (O(N^2))."""
    p = np.asarray(points, dtype=np.float64)
    diff = p[:, None, :] - p[None, :, :]
    return float(np.sqrt((diff**2).sum(axis=-1)).max())


def regular_polygon(
    n: int, radius: float = 1.0, phase: float = 0.0, center: tuple[float, float] = (0.0, 0.0)
) -> FloatArray:
    """Vertices of a regular n-gon, counter-clockwise."""
    a = phase + TWO_PI * np.arange(n) / n
    return np.column_stack([center[0] + radius * np.cos(a), center[1] + radius * np.sin(a)])


def rotate(points: ArrayLike, beta: float) -> FloatArray:
    """Points rotated counter-clockwise by ``beta`` about the origin."""
    p = np.asarray(points, dtype=np.float64)
    c, s = math.cos(beta), math.sin(beta)
    return np.column_stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]])


def round_significant(points: ArrayLike, digits: int) -> FloatArray:
    """Every coordinate rounded to ``digits`` significant digits (as printed with %g)."""
    p = np.asarray(points, dtype=np.float64)
    return np.array([[float(f"{x:.{digits}g}") for x in row] for row in p])
