"""Errors of the gripper: what a simulation adds to every commanded gripper angle.

A plan's angular tolerance (:attr:`~bayesgrasp.planning.result.PlanOption.tolerance`) bounds
the error on ``alpha_2 .. alpha_k`` that keeps its success probability; the simulations
(:func:`~bayesgrasp.sim.kinematic.simulate_kinematic`,
:func:`~bayesgrasp.sim.engine.simulate_mujoco`) draw such errors to check it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..errors import SimulationError

__all__ = ["GripperNoise"]


@dataclass(frozen=True, slots=True)
class GripperNoise:
    """An error added to every commanded gripper angle (radians).

    Parameters
    ----------
    kind : {"normal", "uniform"}
        ``normal``: zero-mean normal with standard deviation ``scale``; ``uniform``: uniform
        on ``[-scale, scale]``.
    scale : float
        Standard deviation or bound (radians, >= 0). ``0`` means no error.

    Raises
    ------
    SimulationError
        An unknown ``kind``, or a ``scale`` that is not a finite number >= 0.

    Examples
    --------
    >>> e = GripperNoise("uniform", 0.1).draw((1000,), 0)
    >>> bool(np.all(np.abs(e) <= 0.1))
    True
    """

    kind: Literal["normal", "uniform"] = "normal"
    scale: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("normal", "uniform"):
            raise SimulationError(
                f"gripper noise `kind` must be 'normal' or 'uniform'; got {self.kind!r}"
            )
        if not (isinstance(self.scale, int | float) and math.isfinite(self.scale)) or (
            self.scale < 0
        ):
            raise SimulationError(
                f"gripper noise `scale` must be a finite number >= 0; got {self.scale!r}"
            )

    def draw(
        self, shape: tuple[int, ...], rng: np.random.Generator | int | None
    ) -> NDArray[np.float64]:
        """Angle errors of the given shape (zeros when ``scale`` is 0)."""
        gen = np.random.default_rng(rng)
        if self.scale == 0.0:
            return np.zeros(shape)
        if self.kind == "normal":
            return gen.normal(0.0, self.scale, shape)
        return gen.uniform(-self.scale, self.scale, shape)
