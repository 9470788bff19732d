"""Gripper angle errors (bayesgrasp.sim.noise)."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from bayesgrasp.errors import SimulationError
from bayesgrasp.sim.noise import GripperNoise


def test_gripper_noise_validation() -> None:
    with pytest.raises(SimulationError, match="`kind` must be 'normal' or 'uniform'; got 'x'"):
        GripperNoise("x", 0.1)  # type: ignore[arg-type]
    with pytest.raises(SimulationError, match="`scale` must be a finite number >= 0; got -1"):
        GripperNoise("normal", -1)
    e = GripperNoise("normal", 0.2).draw((50_000,), 0)
    assert_allclose(e.std(), 0.2, atol=0.005)
    assert not GripperNoise().draw((4,), 0).any()


@pytest.mark.parametrize("kind", ["normal", "uniform"])
def test_gripper_noise_is_reproducible_and_shaped(kind: Literal["normal", "uniform"]) -> None:
    e = GripperNoise(kind, 0.1).draw((3, 5), 7)
    assert e.shape == (3, 5)
    assert_array_equal(e, GripperNoise(kind, 0.1).draw((3, 5), np.random.default_rng(7)))
