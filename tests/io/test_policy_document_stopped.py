"""A policy whose search stopped at its bound says so in its document; a finished one does not."""

from __future__ import annotations

import math

from bayesgrasp import shapes
from bayesgrasp.io.policies import policy_document
from bayesgrasp.model.problem import Problem
from bayesgrasp.model.sensing import WidthSensor
from bayesgrasp.planning.policy import plan_policy


def test_a_stopped_search_writes_why_and_its_bound() -> None:
    pb = Problem.build(shapes.load("house"))
    sensor = WidthSensor(0.5, 0.1)
    stopped = plan_policy(pb, sensor, 3, max_memory_mb=1)
    assert stopped.stopped
    doc = policy_document(stopped)
    assert doc["stopped"] == stopped.stopped
    assert doc["requested_actions"] == 3 and doc["max_actions"] < 3
    assert math.isfinite(doc["lower_bound"])
    assert doc["lower_bound"] <= plan_policy(pb, sensor, 3).expected_cost + 1e-9
    finished = policy_document(plan_policy(pb, sensor, 1))
    assert not {"stopped", "requested_actions", "lower_bound"} & set(finished)
