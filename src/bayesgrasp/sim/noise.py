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

__all__ = ["GripperNoise", "as_generator"]


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
        gen = as_generator(rng)
        if self.scale == 0.0:
            return np.zeros(shape)
        if self.kind == "normal":
            return gen.normal(0.0, self.scale, shape)
        return gen.uniform(-self.scale, self.scale, shape)


def as_generator(rng: object, name: str = "rng") -> np.random.Generator:
    """``np.random.default_rng(rng)``, refusing a bad seed with a :class:`SimulationError`.

    A generator, bit generator or seed sequence is used as is; ``None`` seeds from the
    operating system; an integer must be >= 0 (numpy's own ``ValueError`` for a negative
    seed named no parameter).

    Raises
    ------
    SimulationError
        ``rng`` is a negative integer, a bool, or anything numpy cannot seed with.

    Examples
    --------
    >>> as_generator(3).integers(10) == np.random.default_rng(3).integers(10)
    np.True_
    >>> as_generator(-1)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.SimulationError: `rng` must be ... an integer seed >= 0; got -1
    """
    if isinstance(rng, np.random.Generator):
        return rng
    want = f"`{name}` must be a numpy Generator, None or an integer seed >= 0; got {rng!r}"
    if isinstance(rng, bool | float | str | bytes) or (
        isinstance(rng, int | np.integer) and rng < 0
    ):
        raise SimulationError(want)
    try:
        return np.random.default_rng(rng)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise SimulationError(want) from None
