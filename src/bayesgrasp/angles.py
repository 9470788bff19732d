"""Angle helpers shared by every layer: one home for ``2 pi`` and for wrapping.

Angles are radians, counter-clockwise (design.md). Orientations live on the circle; a
gripper turn is reported in ``(-pi, pi]`` (or ``(-pi/2, pi/2]`` for an action whose gripper
turned by ``pi`` is the same gripper, see :attr:`bayesgrasp.model.actions.Action.gripper_period`).

Examples
--------
>>> round(wrap(3 * math.pi / 2), 6)
-1.570796
>>> wrap(-math.pi) == math.pi
True
>>> float(circle_distance(0.1, TWO_PI - 0.1).round(12))
0.2
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["TWO_PI", "circle_distance", "mod_2pi", "wrap", "wrap_array", "wrap_period"]

TWO_PI = 2.0 * math.pi


def wrap(a: float) -> float:
    """Angle ``a`` wrapped into ``(-pi, pi]``."""
    r = math.remainder(a, TWO_PI)
    return math.pi if r == -math.pi else r


def wrap_period(a: float, period: float) -> float:
    """Angle ``a`` wrapped into ``(-period/2, period/2]``.

    Examples
    --------
    >>> round(wrap_period(math.radians(100), math.pi), 6) == round(math.radians(-80), 6)
    True
    """
    r = math.remainder(a, period)
    return period / 2.0 if r == -period / 2.0 else r


def wrap_array(x: ArrayLike) -> NDArray[np.float64]:
    """Angles wrapped into ``(-pi, pi]`` (vectorised)."""
    y = np.asarray(x, dtype=np.float64)
    return np.asarray(math.pi - np.mod(math.pi - y, TWO_PI), dtype=np.float64)


def mod_2pi(x: ArrayLike) -> NDArray[np.float64]:
    """Angles in ``[0, 2 pi)`` (vectorised; ``np.mod`` alone rounds a tiny negative to 2 pi).

    Examples
    --------
    >>> mod_2pi([-1e-20, 7.0]).round(6).tolist()
    [0.0, 0.716815]
    """
    out = np.mod(np.asarray(x, dtype=np.float64), TWO_PI)
    return np.asarray(np.where(out >= TWO_PI, 0.0, out), dtype=np.float64)


def circle_distance(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Distance on the circle between angles ``a`` and ``b`` (in ``[0, pi]``, vectorised)."""
    d = np.mod(np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64), TWO_PI)
    return np.asarray(np.minimum(d, TWO_PI - d), dtype=np.float64)
