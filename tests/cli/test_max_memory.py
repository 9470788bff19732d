"""The policy search's memory and time bounds: seen and changed by the user; reaching one
gives the deepest policy that finished (checked against an unbounded search of that depth),
its reason and a lower bound, or one line."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp import shapes
from bayesgrasp.cli import main
from bayesgrasp.errors import PlanningError
from bayesgrasp.model import Problem
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.planning.noisy_policy import plan_noisy_policy
from bayesgrasp.planning.policy import SearchStopped, memory_bytes, plan_policy

HOUSE = Problem.build(shapes.load("house"))


def test_a_search_past_its_bound_answers_with_the_deepest_policy_that_finished() -> None:
    pol = plan_policy(HOUSE, "width:0.5,0.1", 3, max_memory_mb=1.0)
    assert not pol.complete and pol.requested_actions == 3 and pol.max_actions < 3
    assert "took more than 1 MB" in pol.stopped and "--max-memory" in pol.stopped
    # The answer is the exact best policy of the depth that finished ...
    shallow = plan_policy(HOUSE, "width:0.5,0.1", pol.max_actions, max_memory_mb=2**30)
    assert shallow.complete and pol.expected_cost == pytest.approx(shallow.expected_cost, 1e-12)
    # ... and the lower bound holds for the true best policy of the depth asked for.
    full = plan_policy(HOUSE, "width:0.5,0.1", 3, max_memory_mb=2**30)
    assert full.complete and full.lower_bound == full.expected_cost
    assert pol.lower_bound <= full.expected_cost + 1e-12 <= pol.expected_cost + 2e-12


def test_a_search_past_its_time_bound_answers_too() -> None:
    pol = plan_policy(HOUSE, "width:0.5,0.1", 3, time_limit_s=1e-6)
    assert not pol.complete and "ran for 1e-06 s" in pol.stopped and "--time-limit" in pol.stopped
    shallow = plan_policy(HOUSE, "width:0.5,0.1", pol.max_actions)
    assert pol.expected_cost == pytest.approx(shallow.expected_cost, 1e-12)


def test_without_the_fallback_the_search_stops_with_the_reason() -> None:
    with pytest.raises(SearchStopped, match=r"took more than 1 MB .*--max-memory"):
        plan_policy(HOUSE, "width:0.5,0.1", 3, max_memory_mb=1.0, best_so_far=False)
    noise = NoiseModel(TurnNoise("normal", 0.03))
    with pytest.raises(PlanningError, match="took more than 1 MB"):
        plan_noisy_policy(HOUSE, "width:0.5,0.1", 3, noise, max_memory_mb=1.0, best_so_far=False)


@given(
    st.sampled_from(["width", "width:0.5,0.1", "width:0,0.5"]),
    st.integers(1, 3),
    st.sampled_from([("squeeze",), ("squeeze", "push-grasp")]),
)
@settings(max_examples=12, deadline=None)
def test_the_lower_bound_is_below_every_optimum(sensor: str, depth: int, actions: tuple) -> None:
    from bayesgrasp.model.sensing import parse_sensor
    from bayesgrasp.planning.policy import _lower_bound, candidate_first_angles, policy_space

    pb = Problem.build(shapes.load("house"), actions=actions)
    space = policy_space(pb, None, depth)
    angles, _ = candidate_first_angles(space, pb.action_kinds, 512)
    bound = _lower_bound(space, parse_sensor(sensor), angles)
    assert bound <= plan_policy(pb, sensor, depth).expected_cost + 1e-12


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
@pytest.mark.parametrize("option", [("--max-memory", "10"), ("--time-limit", "5")])
def test_the_options_need_sense(
    command: str, option: tuple[str, str], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([command, "house", *option]) == 2
    err = capsys.readouterr().err
    assert "--max-memory and --time-limit bound a policy search: they need --sense" in err


def test_plan_says_when_the_search_stopped(capsys: pytest.CaptureFixture[str]) -> None:
    args = ["plan", "house", "--sense", "width:0.5,0.1", "--max-memory", "1"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "search stopped: its beliefs took more than 1 MB" in out
    assert "best policy of at most" in out and "no policy of 3 actions costs less than" in out


def test_a_noisy_policy_past_its_bound_answers_too(capsys: pytest.CaptureFixture[str]) -> None:
    # The noise-aware policy search answers as the exact one: the deepest that finished.
    args = ["plan", "house", "--sense", "width:0.5,0.1", "--turn-noise", "normal:2"]
    assert main([*args, "--max-memory", "1"]) == 0
    out = capsys.readouterr().out
    assert "search stopped: its beliefs took more than 1 MB" in out
    assert "best policy of at most 1 action" in out and "no policy of 3 actions" in out


def test_progress_reports_the_seconds_of_the_time_bound() -> None:
    calls: list[tuple[int, int]] = []
    pb = Problem.build(shapes.load("key"), actions=("squeeze", "push-grasp"))
    plan_policy(pb, "width:0.2,0.05", 3, time_limit_s=30, progress=lambda *a: calls.append(a))
    assert calls and all(total == 30 and 0 <= used <= 30 for used, total in calls)
    plan_policy(HOUSE, "width", 2, time_limit_s=None, progress=lambda *a: calls.append((-1, -1)))
    assert (-1, -1) not in calls  # no time bound: nothing to show


@pytest.mark.parametrize(
    "noise", [["--turn-noise", "normal:2"], ["--contact-noise", "0.1"]], ids=["turn", "contact"]
)
@pytest.mark.parametrize("command", ["plan", "simulate", "plot"])
def test_the_time_bound_holds_under_noise(
    command: str, noise: list[str], capsys: pytest.CaptureFixture[str], tmp_path
) -> None:
    # The noise-aware policy search keeps the time bound too: when not even the search of
    # one action finishes within it, one line.
    argv = [command, "house", "--sense", "width:0.5,0.1", *noise, "--time-limit", "0.001"]
    argv += ["--out", str(tmp_path / "f")] if command == "plot" else []
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "the policy search stopped: it ran for 0.001 s" in err
    assert len(err.strip().splitlines()) == 1


def test_solve_passes_the_time_bound_to_the_noisy_policy_search() -> None:
    from bayesgrasp.planning.strategy import solve

    noise = NoiseModel(TurnNoise("normal", 0.03))
    with pytest.raises(SearchStopped, match="ran for 1e-06 s"):
        solve(HOUSE, sensor="width:0.5,0.1", noise=noise, time_limit_s=1e-6)
    found = solve(HOUSE, sensor="width", noise=noise, max_actions=2, time_limit_s=60)
    assert found.source.noise == noise
