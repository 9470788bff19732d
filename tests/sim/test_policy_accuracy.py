"""Policies planned with a gripper accuracy keep their claims under turn errors below it."""

from __future__ import annotations

import math

import pytest

from bayesgrasp import shapes
from bayesgrasp.model import Problem
from bayesgrasp.planning.policy import plan_policy
from bayesgrasp.sim.noise import GripperNoise
from bayesgrasp.sim.policy import simulate_policy

SENSOR = "width:0.5,0.1"


@pytest.mark.parametrize("name", ["house", "key"])
def test_claims_hold_under_turn_errors_below_the_accuracy(name: str) -> None:
    acc = math.radians(10.0)
    robust = Problem.build(shapes.load(name), accuracy=acc)
    pol = plan_policy(robust, SENSOR, 3)
    assert pol.depth >= 2  # the accuracy leaves turns to make
    assert simulate_policy(robust, pol, 60_000, GripperNoise("uniform", 0.999 * acc), rng=3).agrees


def test_a_policy_for_exact_turns_breaks_under_such_errors() -> None:
    """The control: the same check fails for the policy planned without the accuracy."""
    err = GripperNoise("uniform", 0.999 * math.radians(20.0))
    exact = Problem.build(shapes.load("house"))
    assert not simulate_policy(exact, plan_policy(exact, SENSOR, 3), 60_000, err, rng=3).agrees
    robust = Problem.build(shapes.load("house"), accuracy=math.radians(20.0))
    assert simulate_policy(robust, plan_policy(robust, SENSOR, 3), 60_000, err, rng=3).agrees
