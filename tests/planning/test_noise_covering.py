"""Turn noise that covers a whole period: every turn leaves the part uniformly oriented.

With ``e`` uniform on ``[-pi, pi]`` the orientation after any turn is uniform over the
circle whatever the turn was, so the value of a plan does not depend on its turns and the
noisy planner's line search has no critical turn to examine. It must still answer, and its
claims must agree with the kinematic simulation of the same noise.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bayesgrasp import shapes
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning.noisy import plan_noisy
from bayesgrasp.sim.kinematic import GripperNoise, simulate_kinematic


@pytest.mark.parametrize("name", ["house", "triangle"])
@pytest.mark.parametrize("actions", [("squeeze",), ("squeeze", "push-grasp")])
def test_noise_over_a_whole_turn_is_planned_and_agrees_with_simulation(
    name: str, actions: tuple[str, ...]
) -> None:
    pb = Problem.build(shapes.load(name), actions=actions)
    res = plan_noisy(pb, NoiseModel(TurnNoise("uniform", math.pi)))
    n = 40_000
    for i, o in enumerate(res.options):
        sim = simulate_kinematic(pb, o.option, n, GripperNoise("uniform", math.pi), rng=i)
        predicted = o.evaluation.distribution
        sd = np.sqrt(np.clip(predicted * (1 - predicted), 0.0, None) / n)
        assert np.all(np.abs(sim.observed / n - predicted) < 5 * sd + 3 / n)
