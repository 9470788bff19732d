"""The Bayes plan under noise (planning/noisy.py), against independent references.

- No noise: the planner gives the exact planner's plans, the same steps, probabilities and
  costs; a vanishing error (1e-7 rad) gives the same plans too.
- Uniform error below a plan's tolerance keeps its success probability exactly.
- Brute force over the turns: for plans of 2 and 3 squeezes every turn on a grid of step
  ``h`` is tried (all pairs for 3), each evaluated exactly by matrix products written here
  from the transition matrices. The planner's best k-action plan must be at least as good as
  the grid's best, and cannot beat it by more than the grid's resolution bound
  ``peak_density * h / 2`` per turn (``|d payoff / d alpha| <= sup density``).
- Simulation: every option's claimed distribution against the kinematic Monte Carlo with the
  same noise drawn (``simulate_kinematic`` for turn error, ``simulate_noise`` for contact
  asynchrony), per state within binomial bounds; its expected cost against the cost implied
  by the observed success.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.typing import NDArray

from bayesgrasp import shapes
from bayesgrasp.errors import PlanningError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.noise import NoiseModel, NoisyTransitions, TurnNoise
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.noisy import evaluate_plan, plan_noisy
from bayesgrasp.sim.kinematic import GripperNoise, simulate_kinematic
from bayesgrasp.sim.noisy import simulate_noise

CATALOGUE = shapes.names()
RECT = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
DEG = math.pi / 180


def _problems() -> list[Problem]:
    return [Problem.build(shapes.load(n)) for n in CATALOGUE] + [
        Problem.build(random_polygon(s)) for s in range(6)
    ]


@pytest.mark.parametrize("pb", _problems(), ids=lambda p: p.part.name)
def test_no_noise_gives_the_exact_plans(pb: Problem) -> None:
    exact = plan_exact(pb)
    res = plan_noisy(pb, NoiseModel())
    got = res.plan_result()
    assert got.bayes == exact.bayes
    for mine, ref in zip(got.options, exact.options, strict=False):
        assert mine.steps == ref.steps
        assert mine.final_orientation == pytest.approx(ref.final_orientation, abs=1e-12)
        assert mine.success_probability == pytest.approx(ref.success_probability, abs=1e-12)
        assert mine.expected_cost == pytest.approx(ref.expected_cost, rel=1e-12)


@pytest.mark.parametrize("kind", ["normal", "uniform"])
@pytest.mark.parametrize("name", ["key", "rectangle", "triangle"])
def test_vanishing_noise_gives_the_exact_plans(kind: str, name: str) -> None:
    pb = Problem.build(shapes.load(name))
    exact = plan_exact(pb)
    res = plan_noisy(pb, NoiseModel(TurnNoise(kind, 1e-7)))  # type: ignore[arg-type]
    assert res.bayes_plan.option.steps == exact.bayes_plan.steps
    bayes = res.bayes_plan.option
    assert bayes.success_probability == pytest.approx(
        exact.bayes_plan.success_probability, abs=1e-9
    )


@pytest.mark.parametrize("pb", _problems(), ids=lambda p: p.part.name)
def test_uniform_noise_below_the_tolerance_keeps_the_probability(pb: Problem) -> None:
    checked = 0
    for o in plan_exact(pb).options:
        if o.tolerance is None or o.tolerance <= 0:
            continue
        a = min(0.99 * o.tolerance, math.pi)
        ev = evaluate_plan(pb, NoiseModel(TurnNoise("uniform", a)), o.steps)
        assert ev.success_probability == pytest.approx(o.success_probability, abs=1e-12)
        checked += 1
    # ... and an error well above it loses probability on some plan with turns.
    if checked:
        o = max(
            (o for o in plan_exact(pb).options if o.tolerance),
            key=lambda o: o.success_probability,
        )
        big = evaluate_plan(pb, NoiseModel(TurnNoise("uniform", 3 * o.tolerance + 0.2)), o.steps)
        assert big.success_probability <= o.success_probability + 1e-12


def _brute(
    pb: Problem, noise: NoiseModel, k: int, step: float
) -> tuple[float, NDArray[np.float64]]:
    """Best success probability of k squeezes over a grid of turns (first at angle 0)."""
    nt = NoisyTransitions(pb, noise)
    q1 = nt.initial("squeeze", 0.0)
    grid = -math.pi / 2 + step * (np.arange(round(math.pi / step)) + 0.5)
    m = nt.matrices("squeeze", grid)  # (N, K, K)
    q2 = np.einsum("i,nij->nj", q1, m)  # (N, K)
    if k == 2:
        return float(q2.max()), grid
    q3 = np.einsum("ai,bij->abj", q2, m)  # (N, N, K)
    return float(q3.max()), grid


NOISES = [
    NoiseModel(TurnNoise("normal", 3 * DEG)),
    NoiseModel(TurnNoise("uniform", 4 * DEG)),
    NoiseModel(TurnNoise("normal", 2 * DEG), 0.2),
]


@pytest.mark.parametrize("noise", NOISES, ids=lambda n: n.describe())
@pytest.mark.parametrize(
    "part",
    [RECT, shapes.load("key"), shapes.load("example"), random_polygon(3)],
    ids=["rect", "key", "example", "random3"],
)
def test_best_plans_match_a_brute_force_grid(part: Part, noise: NoiseModel) -> None:
    pb = Problem.build(part)
    res = plan_noisy(pb, noise, max_actions=3, all_lengths=True)
    step = 0.5 * DEG
    for k in (2, 3):
        best, _ = _brute(pb, noise, k, step)
        got = res.options[k - 1].expected_payoff
        # At least as good as the grid, to the refinement's coordinate-wise bound.
        tol = res.refinement_bound + 1e-9
        assert got >= best - tol, f"{k} squeezes: planner {got} below the grid's {best}"
        slack = noise.turn.peak_density * step / 2 * (k - 1)
        assert got <= best + slack + 1e-12


def _binomial_ok(observed: NDArray[np.intp], predicted: NDArray[np.float64], n: int) -> None:
    # Five standard deviations, and three trials for the rare states (Poisson counts).
    sd = np.sqrt(np.clip(predicted * (1 - predicted), 0.0, None) / n)
    assert np.all(np.abs(observed / n - predicted) < 5 * sd + 3 / n), (observed / n, predicted)


@pytest.mark.parametrize("name", ["key", "rectangle", "tuning-fork"])
@pytest.mark.parametrize("kind", ["normal", "uniform"])
def test_claims_agree_with_the_kinematic_simulation(name: str, kind: str) -> None:
    pb = Problem.build(shapes.load(name))
    noise = NoiseModel(TurnNoise(kind, 3 * DEG))  # type: ignore[arg-type]
    res = plan_noisy(pb, noise)
    n = 100_000
    for i, o in enumerate(res.options):
        sim = simulate_kinematic(pb, o.option, n, GripperNoise(kind, 3 * DEG), rng=i)
        _binomial_ok(sim.observed, o.evaluation.distribution, n)
        p_obs = sim.observed[o.evaluation.target > 0].sum() / n
        cost_obs = pb.cost.expected_cost(o.option.kinds, p_obs)
        sd = math.sqrt(p_obs * (1 - p_obs) / n)
        lo = pb.cost.expected_cost(o.option.kinds, p_obs + 5 * sd)
        hi = pb.cost.expected_cost(o.option.kinds, max(p_obs - 5 * sd, 1e-9))
        assert lo <= o.option.expected_cost <= hi, (cost_obs, o.option.expected_cost)


def test_a_peaked_prior_agrees_with_the_kinematic_simulation() -> None:
    # The simulation errs the first angle too: the prior convolved with the error.
    from bayesgrasp.model.prior import von_mises

    pb = Problem.build(shapes.load("key"), prior=von_mises(0.7, 4.0))
    noise = NoiseModel(TurnNoise("normal", 6 * DEG))
    res = plan_noisy(pb, noise, max_actions=2, all_lengths=True)
    n = 100_000
    for i, o in enumerate(res.options):
        sim = simulate_kinematic(pb, o.option, n, GripperNoise("normal", 6 * DEG), rng=20 + i)
        _binomial_ok(sim.observed, o.evaluation.distribution, n)


@pytest.mark.parametrize("name", ["key", "house"])
def test_contact_noise_agrees_with_its_simulation(name: str) -> None:
    pb = Problem.build(shapes.load(name))
    noise = NoiseModel(TurnNoise("normal", 2 * DEG), 0.3)
    res = plan_noisy(pb, noise, max_actions=3)
    n = 100_000
    for i, o in enumerate(res.options):
        counts = simulate_noise(pb, noise, o.option.steps, n, rng=10 + i)
        _binomial_ok(counts, o.evaluation.distribution, n)


def test_noise_aware_plan_beats_the_noise_free_plan_under_noise() -> None:
    pb = Problem.build(shapes.load("key"))
    noise = NoiseModel(TurnNoise("normal", 2 * DEG))
    res = plan_noisy(pb, noise)
    fragile = evaluate_plan(pb, noise, plan_exact(pb).bayes_plan.steps)
    assert res.bayes_plan.option.expected_cost < fragile.expected_cost - 0.1
    # The refinement's bound: no single turn can gain more than eps (checked on a grid).
    o = res.options[1]
    nt = NoisyTransitions(pb, noise)
    q1 = nt.initial("squeeze", o.option.steps[0].alpha)
    grid = np.linspace(-math.pi / 2, math.pi / 2, 4001)
    vals = np.einsum("i,nij,j->n", q1, nt.matrices("squeeze", grid), o.evaluation.target)
    assert vals.max() <= o.expected_payoff + res.refinement_bound + 1e-12


def test_bad_arguments_are_refused() -> None:
    pb = Problem.build(RECT)
    with pytest.raises(PlanningError, match="max_actions"):
        plan_noisy(pb, NoiseModel(), max_actions=0)
    with pytest.raises(PlanningError, match="beam"):
        plan_noisy(pb, NoiseModel(), beam=0)
    with pytest.raises(PlanningError, match="all_lengths"):
        plan_noisy(pb, NoiseModel(), all_lengths=True)
    with pytest.raises(PlanningError, match="at least one step"):
        evaluate_plan(pb, NoiseModel(), [])
