"""The policy search's memory bound: seen and changed by the user, one line when reached."""

from __future__ import annotations

import pytest

from bayesgrasp import shapes
from bayesgrasp.cli import main
from bayesgrasp.errors import PlanningError
from bayesgrasp.model import Problem
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.planning.noisy_policy import plan_noisy_policy
from bayesgrasp.planning.policy import memory_bytes, plan_policy

HOUSE = Problem.build(shapes.load("house"))


def test_a_search_past_its_bound_stops_with_the_reason() -> None:
    with pytest.raises(PlanningError, match=r"take more than 1 MB .*--max-memory"):
        plan_policy(HOUSE, "width:0.5,0.1", 3, max_memory_mb=1.0)
    noise = NoiseModel(TurnNoise("normal", 0.03))
    with pytest.raises(PlanningError, match="take more than 1 MB"):
        plan_noisy_policy(HOUSE, "width:0.5,0.1", 3, noise, max_memory_mb=1.0)


def test_the_default_bound_plans_as_before() -> None:
    bounded = plan_policy(HOUSE, "width:0.5,0.1", 2)
    assert bounded.expected_cost == pytest.approx(
        plan_policy(HOUSE, "width:0.5,0.1", 2, max_memory_mb=2**30).expected_cost, abs=1e-12
    )


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), True, "1"])
def test_bad_bounds_are_refused(bad: object) -> None:
    with pytest.raises(PlanningError, match="`max_memory_mb` must be a number of MB > 0"):
        memory_bytes(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("command", ["plan", "simulate", "plot"])
def test_the_option(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([command, "house", "--max-memory", "10"]) == 2
    assert "--max-memory bounds a policy search: it needs --sense" in capsys.readouterr().err
    args = [command, "house", "--sense", "width:0.5,0.1", "--max-memory", "1"]
    if command == "simulate":
        args += ["--trials", "10"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "take more than 1 MB" in err and len(err.strip().splitlines()) == 1
