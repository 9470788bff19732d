"""Errors of the gripper as the simulations draw them.

The noise vocabulary is the model's (:mod:`bayesgrasp.model.noise`): a
:class:`~bayesgrasp.model.noise.NoiseModel` of a turn error
(:class:`~bayesgrasp.model.noise.TurnNoise`) and a contact asynchrony ``q``. The simulations
take it (:func:`~bayesgrasp.sim.kinematic.simulate_kinematic` draws both,
:func:`~bayesgrasp.sim.engine.simulate_mujoco` the turn error) and predict with its exact
matrices. :class:`GripperNoise` is the sampler of a turn error, the form the simulators
draw from (:meth:`GripperNoise.of`); given to a simulator in place of a noise model it means
the turn error alone (:func:`noise_model`).

A plan's angular tolerance (:attr:`~bayesgrasp.planning.result.PlanOption.tolerance`) bounds
the error on ``alpha_2 .. alpha_k`` that keeps its noise-free success probability.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..errors import PlanningError, SimulationError
from ..model.noise import NoiseModel, TurnNoise

__all__ = ["AnyNoise", "GripperNoise", "as_generator", "noise_model"]


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

    @classmethod
    def of(cls, turn: TurnNoise) -> GripperNoise:
        """The sampler of a model's turn error (the same kind and scale).

        Examples
        --------
        >>> GripperNoise.of(TurnNoise("uniform", 0.1))
        GripperNoise(kind='uniform', scale=0.1)
        """
        return cls(turn.kind, turn.scale)

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


AnyNoise = NoiseModel | GripperNoise | None
"""What the simulators take as noise: a noise model, a turn error alone, or none."""


def noise_model(noise: AnyNoise) -> NoiseModel:
    """The noise model a simulator draws from and predicts with.

    ``None`` is no noise; a :class:`GripperNoise` is that turn error with simultaneous jaw
    contacts.

    Raises
    ------
    SimulationError
        A turn error the model cannot evaluate exactly (a normal error of standard deviation
        above :data:`~bayesgrasp.model.noise.MAX_NORMAL_SIGMA`, a uniform one beyond pi), or
        something that is no noise.

    Examples
    --------
    >>> noise_model(GripperNoise("normal", 0.05)).describe()
    'turn error normal:2.86479 deg'
    >>> noise_model(None).exact
    True
    """
    if noise is None:
        return NoiseModel()
    if isinstance(noise, NoiseModel):
        return noise
    if not isinstance(noise, GripperNoise):
        raise SimulationError(
            f"`noise` must be a NoiseModel, a GripperNoise or None; got {type(noise).__name__}"
        )
    try:
        return NoiseModel(TurnNoise(noise.kind, noise.scale))
    except PlanningError as exc:
        raise SimulationError(f"no exact prediction for this gripper error: {exc}") from None
