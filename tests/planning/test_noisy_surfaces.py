"""The noise-aware planner at zero noise, its guaranteed plan, its best-only view.

- Zero noise (no noise model, ``normal:0``, ``uniform:0``, contact 0): the noisy planner's
  documents equal the exact planner's field by field where both have the field (options,
  tolerances, Bayes, most certain; the method is the planner's name and differs).
- With noise the lengths searched reach at least the noise-free most certain plan.
- The guaranteed plan under noise, against simulation with the noise drawn
  (:func:`~bayesgrasp.sim.noisy.simulate_noise`): under uniform turn error and contact noise
  every trial ends on the goal's orbit (also with the turns moved by the tolerance); the
  noise-free guaranteed plan, whose tolerance is below the error, does not. Where no plan
  is found, no plan at random turns guarantees either.
- The search over sets of states finds plans of the guaranteed planner's length (arcs,
  with the error as the gripper accuracy): two independent algorithms.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from bayesgrasp import shapes
from bayesgrasp.errors import PlanningError
from bayesgrasp.io.plans import plan_document
from bayesgrasp.model.noise import NoiseModel, NoisyTransitions, TurnNoise
from bayesgrasp.model.payoff import Payoff
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.guaranteed import plan_guaranteed
from bayesgrasp.planning.noisy import evaluate_plan, plan_noisy, step_distributions_noisy
from bayesgrasp.planning.robust import UNBOUNDED_GUARANTEE, plan_guaranteed_noisy, support_search
from bayesgrasp.sim.noisy import simulate_noise

CATALOGUE = shapes.names()
DEG = math.pi / 180
ZERO = [
    NoiseModel(),
    NoiseModel(TurnNoise("normal", 0.0)),
    NoiseModel(TurnNoise("uniform", 0.0)),
    NoiseModel(TurnNoise("normal", 0.0), 0.0),
]


def _problems() -> list[Problem]:
    return [Problem.build(shapes.load(n)) for n in CATALOGUE] + [
        Problem.build(random_polygon(s)) for s in range(4)
    ]


def assert_same_where_shared(mine: Any, ref: Any, path: str = "") -> None:
    """Equal field by field where both documents have the field (``method`` aside)."""
    if isinstance(ref, dict) and isinstance(mine, dict):
        for key in ref.keys() & mine.keys():
            if key != "method":
                assert_same_where_shared(mine[key], ref[key], f"{path}.{key}")
        return
    if isinstance(ref, list) and isinstance(mine, list):
        assert len(mine) == len(ref), f"{path}: {len(mine)} entries, not {len(ref)}"
        for i, (a, b) in enumerate(zip(mine, ref, strict=True)):
            assert_same_where_shared(a, b, f"{path}[{i}]")
        return
    assert mine == ref, f"{path}: {mine!r} != {ref!r}"


@pytest.mark.parametrize("noise", ZERO, ids=lambda n: f"{n.turn.spec()},{n.contact:g}")
@pytest.mark.parametrize("pb", _problems(), ids=lambda p: p.part.name)
def test_zero_noise_documents_equal_the_exact_ones(pb: Problem, noise: NoiseModel) -> None:
    exact = plan_exact(pb)
    res = plan_noisy(pb, noise)
    assert res.bayes == exact.bayes and res.most_certain == exact.most_certain
    assert [o.option.tolerance for o in res.options] == [o.tolerance for o in exact.options]
    assert_same_where_shared(plan_document(res.plan_result()), plan_document(exact))
    best = res.best_only()
    assert_same_where_shared(
        plan_document(best.plan_result()), plan_document(plan_exact(pb, report="best"))
    )
    # Each option's matrix evaluation agrees with the exact planner's probability.
    for o, ref in zip(res.options, exact.options, strict=True):
        assert o.evaluation.success_probability == pytest.approx(ref.success_probability, abs=1e-9)


def test_zero_noise_most_certain_is_the_most_certain_plan() -> None:
    """The tuning fork: a 1-squeeze plan of 0.41 and a 2-squeeze plan of 0.5."""
    pb = Problem.build(shapes.load("tuning-fork"))
    res = plan_noisy(pb, NoiseModel(TurnNoise("uniform", 0.0)))
    probs = [o.option.success_probability for o in res.options]
    assert probs[0] == pytest.approx(0.408, abs=1e-3) and probs[1] == pytest.approx(0.5)
    assert res.most_certain == 1 and res.options[1].option.tolerance is not None


@pytest.mark.parametrize("name", ["tuning-fork", "house", "ic-chip", "key"])
@pytest.mark.parametrize(
    "noise", [NoiseModel(TurnNoise("normal", 2 * DEG)), NoiseModel(contact=0.1)]
)
def test_noise_searches_the_noise_free_lengths(name: str, noise: NoiseModel) -> None:
    pb = Problem.build(shapes.load(name))
    res = plan_noisy(pb, noise)
    assert len(res.options) >= len(plan_exact(pb).options)
    pays = [o.expected_payoff for o in res.options]
    assert res.options[res.most_certain].expected_payoff == max(pays)


def test_best_only_keeps_the_bayes_and_most_certain_plans() -> None:
    pb = Problem.build(shapes.load("house"))
    res = plan_noisy(pb, NoiseModel(TurnNoise("normal", 2 * DEG)))
    best = res.best_only()
    keep = sorted({res.bayes, res.most_certain})
    assert [o.option.steps for o in best.options] == [res.options[i].option.steps for i in keep]
    assert best.bayes_plan is res.bayes_plan
    assert best.options[best.most_certain] is res.options[res.most_certain]


def test_noisy_step_distributions_agree_with_the_simulation() -> None:
    pb = Problem.build(shapes.load("key"))
    noise = NoiseModel(TurnNoise("normal", 3 * DEG), 0.2)
    steps = plan_noisy(pb, noise).bayes_plan.option.steps
    qs = step_distributions_noisy(pb, noise, steps)
    n = 100_000
    for k in range(1, len(steps) + 1):
        counts = simulate_noise(pb, noise, steps[:k], n, rng=k)
        sd = np.sqrt(qs[k - 1] * (1 - qs[k - 1]) / n)
        assert np.all(np.abs(counts / n - qs[k - 1]) < 5 * sd + 3 / n)
    with pytest.raises(PlanningError, match="at least one step"):
        step_distributions_noisy(pb, noise, [])


def _off_orbit(pb: Problem, counts: NDArray[np.intp], final: float, period: float) -> int:
    s = pb.states.stable
    off = np.abs(np.mod(s - final + period / 2, period) - period / 2) > 1e-6
    return int(counts[off].sum())


@pytest.mark.parametrize("name", CATALOGUE)
def test_guaranteed_under_uniform_error_holds_in_simulation(name: str) -> None:
    pb = Problem.build(shapes.load(name))
    plain = plan_guaranteed(pb).option
    assert plain.tolerance is not None
    a = 1.2 * plain.tolerance  # more error than the noise-free plan tolerates
    noise = NoiseModel(TurnNoise("uniform", a))
    g = plan_guaranteed_noisy(pb, noise)
    if g.status != "ok":
        assert g.reason is not None and "under turn error uniform:" in g.reason
        return
    o = g.option
    assert o.tolerance is not None and o.tolerance >= a
    counts = simulate_noise(pb, noise, o.steps, 50_000, rng=1)
    assert _off_orbit(pb, counts, o.final_orientation, g.period) == 0
    ev = evaluate_plan(pb, noise, o.steps)
    assert o.success_probability == pytest.approx(ev.success_probability, abs=1e-9)
    # The noise-free plan does fail under this error (the check is not vacuous).
    fragile = simulate_noise(pb, noise, plain.steps, 50_000, rng=2)
    assert _off_orbit(pb, fragile, plain.final_orientation, g.period) > 0


@pytest.mark.parametrize("name", CATALOGUE)
def test_guaranteed_under_contact_noise_holds_in_simulation(name: str) -> None:
    pb = Problem.build(shapes.load(name))
    noise = NoiseModel(TurnNoise("uniform", 2 * DEG), 0.2)
    g = plan_guaranteed_noisy(pb, noise)
    if g.status != "ok":
        assert g.reason is not None and "contact noise 0.2" in g.reason
        _no_random_plan_guarantees(pb, noise, g.period)
        return
    o = g.option
    assert o.tolerance is not None and o.tolerance >= 2 * DEG
    counts = simulate_noise(pb, noise, o.steps, 50_000, rng=3)
    assert _off_orbit(pb, counts, o.final_orientation, g.period) == 0
    # ...and so does every other execution the tolerance allows (turns moved by it).
    moved = [o.steps[0]] + [
        dataclasses.replace(s, alpha=s.alpha + sign * (o.tolerance - 2 * DEG) * 0.99)
        for s, sign in zip(o.steps[1:], [1, -1] * len(o.steps), strict=False)
    ]
    counts = simulate_noise(pb, noise, moved, 50_000, rng=4)
    assert _off_orbit(pb, counts, o.final_orientation, g.period) == 0
    ev = evaluate_plan(pb, noise, o.steps)
    assert o.success_probability == pytest.approx(ev.success_probability, abs=1e-9)


def _no_random_plan_guarantees(pb: Problem, noise: NoiseModel, period: float) -> None:
    """Plans of 2 to 4 squeezes at random turns: none ends on one orbit (the search is right)."""
    rng = np.random.default_rng(5)
    nt = NoisyTransitions(pb, noise)
    for _ in range(300):
        k = int(rng.integers(2, 5))
        q = nt.initial("squeeze", 0.0)
        for alpha in rng.uniform(-math.pi / 2, math.pi / 2, k - 1):
            q = q @ nt.matrix("squeeze", float(alpha))
        assert _off_orbit_mass(pb, q, period) > 1e-9


def _off_orbit_mass(pb: Problem, q: NDArray[np.float64], period: float) -> float:
    s = pb.states.stable
    j = int(np.argmax(q))
    off = np.abs(np.mod(s - s[j] + period / 2, period) - period / 2) > 1e-6
    return float(q[off].sum())


@pytest.mark.parametrize("degrees", [0.0, 2.0, 5.0])
@pytest.mark.parametrize("pb", _problems(), ids=lambda p: p.part.name)
def test_the_set_search_agrees_with_the_guaranteed_planner(pb: Problem, degrees: float) -> None:
    """Goldberg's search over sets of states and the arcs find plans of one length."""
    noise = NoiseModel(TurnNoise("uniform", degrees * DEG))
    accurate = dataclasses.replace(pb, accuracy=degrees * DEG)
    arcs = plan_guaranteed(accurate)
    # The error as turn noise, or as the problem's gripper accuracy: the same search.
    for found in (support_search(pb, noise), support_search(accurate, NoiseModel())):
        if arcs.status != "ok":
            assert isinstance(found, str)
            continue
        assert not isinstance(found, str)
        assert len(found.kinds) == arcs.n_actions
        assert found.error == degrees * DEG
        if len(found.kinds) > 1:
            assert found.margin > 0


def test_guaranteed_refuses_unbounded_error_and_keeps_zero_noise() -> None:
    pb = Problem.build(shapes.load("key"))
    with pytest.raises(PlanningError, match="unbounded") as info:
        plan_guaranteed_noisy(pb, NoiseModel(TurnNoise("normal", 1 * DEG)))
    assert str(info.value) == UNBOUNDED_GUARANTEE
    ref = plan_guaranteed(pb).option
    for noise in ZERO:
        got = plan_guaranteed_noisy(pb, noise).option
        assert got.steps == ref.steps and got.tolerance == ref.tolerance


def test_a_payoff_keeps_the_search_at_zero_noise() -> None:
    pb = Problem.build(shapes.load("key"))
    bayes = plan_exact(pb).bayes_plan
    res = plan_noisy(pb, NoiseModel(), Payoff.one_state(bayes.final_orientation))
    assert res.bayes_plan.expected_payoff >= bayes.success_probability - 1e-9
