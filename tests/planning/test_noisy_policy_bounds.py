"""The noise-aware policy search at its time and memory bounds: the best answer so far.

Past either bound the search plans again one action deeper at a time from one and answers
with the deepest policy that finished (the exact policy search's machinery,
:func:`~bayesgrasp.planning.search_bounds.deepest_within_bounds`). Held here against
independent runs: the answer is exactly the unbounded search of its depth, it says that it
stopped and how many actions were asked for, and its lower bound lies below the unbounded
optimum of the requested depth.
"""

from __future__ import annotations

import functools
import math
from types import SimpleNamespace

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from bayesgrasp.geometry import Part
from bayesgrasp.model import Problem
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import programme, search_bounds
from bayesgrasp.planning.noisy_policy import plan_noisy_policy
from bayesgrasp.planning.policy import Policy
from bayesgrasp.planning.search_bounds import SearchStopped

HOUSE = Part.from_points([(0, 0), (4, 0), (4, 3), (2, 5), (0, 3)], name="house")
QUAD = Part.from_points([(0.0, 0.0), (4.0, 0.0), (3.6, 2.2), (0.5, 2.6)], name="quad")
PARTS = {"house": HOUSE, "quad": QUAD}
NOISES = {
    "normal": NoiseModel(TurnNoise("normal", math.radians(4))),
    "uniform": NoiseModel(TurnNoise("uniform", math.radians(6))),
    "contact": NoiseModel(contact=0.15),
}
SENSOR = "width:0.05,0.025"
PAYOFF = (1.0, 0.0, 0.5, 0.0, 0.25, 0.0, 0.75, 0.0)  # the house's eight stable states


@functools.cache
def unbounded(part: str, noise: str, depth: int, payoff: bool = False) -> Policy:
    """The search of ``depth`` actions without a bound (the reference)."""
    pb = Problem.build(PARTS[part])
    u = PAYOFF if payoff else None
    return plan_noisy_policy(pb, SENSOR, depth, NOISES[noise], payoff=u)


def _check_stopped(pol: Policy, part: str, noise: str, depth: int, payoff: bool = False) -> None:
    """A stopped answer: the unbounded search of its depth, and a bound below the optimum."""
    assert pol.stopped and not pol.complete
    assert pol.requested_actions == depth and 1 <= pol.max_actions < depth
    ref = unbounded(part, noise, pol.max_actions, payoff)
    assert pol.expected_cost == ref.expected_cost
    assert pol.success_probability == ref.success_probability
    assert pol.depth == ref.depth
    optimum = unbounded(part, noise, depth, payoff).expected_cost
    assert math.isfinite(pol.lower_bound)
    assert pol.lower_bound <= optimum + 1e-12
    assert pol.lower_bound <= pol.expected_cost + 1e-12


@pytest.mark.parametrize(
    ("part", "noise", "mb", "answered"),
    [
        ("house", "normal", 0.5, 1),
        ("house", "normal", 1.5, 2),
        ("house", "contact", 1.5, 2),
        ("house", "uniform", 0.25, 1),
        ("quad", "contact", 0.25, 1),
    ],
)
def test_memory_bound_answers_the_deepest_search_that_finished(
    part: str, noise: str, mb: float, answered: int
) -> None:
    pb = Problem.build(PARTS[part])
    pol = plan_noisy_policy(pb, SENSOR, 3, NOISES[noise], max_memory_mb=mb)
    assert pol.max_actions == answered
    assert "the memory bound" in pol.stopped
    _check_stopped(pol, part, noise, 3)
    assert unbounded(part, noise, 3).complete  # the search without the bound finishes


def test_memory_bound_with_a_payoff() -> None:
    pb = Problem.build(HOUSE)
    pol = plan_noisy_policy(pb, SENSOR, 3, NOISES["normal"], payoff=PAYOFF, max_memory_mb=0.5)
    assert pol.payoff == PAYOFF
    _check_stopped(pol, "house", "normal", 3, payoff=True)


class _WorkClock:
    """A clock that advances a millisecond each time it is read (time as work done)."""

    def __init__(self) -> None:
        self.now = 0.0

    def monotonic(self) -> float:
        self.now += 1e-3
        return self.now


def _use_work_clock(monkeypatch: pytest.MonkeyPatch) -> _WorkClock:
    """The searches read the work clock (the bounds' and the programme's)."""
    clock = _WorkClock()
    fake = SimpleNamespace(monotonic=clock.monotonic)
    monkeypatch.setattr(programme, "time", fake)
    monkeypatch.setattr(search_bounds, "time", fake)
    return clock


def _reads(monkeypatch: pytest.MonkeyPatch, depth: int, limit: float | None) -> tuple[int, Policy]:
    """The clock's reads by one search of ``depth`` actions, and its answer."""
    clock = _use_work_clock(monkeypatch)
    pb = Problem.build(HOUSE)
    pol = plan_noisy_policy(pb, SENSOR, depth, NOISES["normal"], time_limit_s=limit)
    return round(clock.now * 1e3), pol


def test_time_bound_answers_the_deepest_search_that_finished(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With the clock counting work, the bound falls between the searches of 2 and 3."""
    two, _ = _reads(monkeypatch, 2, 1e6)
    three, pol3 = _reads(monkeypatch, 3, 1e6)
    assert pol3.complete and two < three
    # Room for the searches of 1 and 2 actions within the bound, not for the one of 3.
    limit = (two + 40) * 1e-3
    assert limit * 1e3 < three
    _, pol = _reads(monkeypatch, 3, limit)
    assert "the time bound" in pol.stopped and pol.max_actions == 2
    _check_stopped(pol, "house", "normal", 3)


def test_time_bound_without_the_best_so_far_raises(monkeypatch: pytest.MonkeyPatch) -> None:
    three, _ = _reads(monkeypatch, 3, 1e6)
    _use_work_clock(monkeypatch)
    with pytest.raises(SearchStopped, match="the time bound"):
        plan_noisy_policy(
            Problem.build(HOUSE),
            SENSOR,
            3,
            NOISES["normal"],
            time_limit_s=(three // 2) * 1e-3,
            best_so_far=False,
        )


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 10_000), noise=st.sampled_from(sorted(NOISES)))
def test_lower_bound_lies_below_the_optimum(seed: int, noise: str) -> None:
    """Random parts: a stopped search's bound is below the unbounded optimum of its depth."""
    pb = Problem.build(random_polygon(seed))
    nm = NOISES[noise]
    pol = plan_noisy_policy(pb, SENSOR, 2, nm, max_memory_mb=0.01)
    assume(pol.stopped)
    assert pol.max_actions == 1 and pol.requested_actions == 2
    assert pol.expected_cost == plan_noisy_policy(pb, SENSOR, 1, nm).expected_cost
    assert pol.lower_bound <= plan_noisy_policy(pb, SENSOR, 2, nm).expected_cost + 1e-12


def test_a_bound_no_search_meets_says_so() -> None:
    pb = Problem.build(HOUSE)
    with pytest.raises(SearchStopped, match="and so did the search of one action"):
        plan_noisy_policy(pb, SENSOR, 3, NOISES["normal"], time_limit_s=1e-9)
    with pytest.raises(SearchStopped, match="the time bound") as info:
        plan_noisy_policy(pb, SENSOR, 3, NOISES["normal"], time_limit_s=1e-9, best_so_far=False)
    assert "the search of one action" not in str(info.value)


def test_a_finished_search_is_complete_without_a_lower_bound() -> None:
    pol = unbounded("house", "normal", 2)
    assert pol.complete and pol.requested_actions == 2 and math.isnan(pol.lower_bound)


def test_without_noise_the_bounds_reach_the_exact_search() -> None:
    """No noise: the exact policy search, within the bounds given (not its defaults)."""
    pb = Problem.build(HOUSE)
    pol = plan_noisy_policy(pb, SENSOR, 3, None, max_memory_mb=0.5)
    assert pol.stopped and pol.requested_actions == 3 and pol.max_actions < 3
    assert pol.lower_bound <= plan_noisy_policy(pb, SENSOR, 3, None).expected_cost
