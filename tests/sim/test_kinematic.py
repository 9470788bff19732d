"""Kinematic Monte Carlo of plans (bayesgrasp.sim) and the `simulate` command with it.

Plan documents (read by ``simulate --plan FILE``) are tested in tests/io/test_plans.py.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.stats import kstest

from bayesgrasp.angles import TWO_PI, circle_distance
from bayesgrasp.cli import main
from bayesgrasp.errors import SimulationError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.noise import MAX_NORMAL_SIGMA
from bayesgrasp.model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior, von_mises
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import PlanOption, PlanStep, execute_plan, plan_exact
from bayesgrasp.shapes import load, names
from bayesgrasp.sim import (
    GripperNoise,
    goodness_of_fit,
    predicted_distribution,
    sample_prior,
    simulate_kinematic,
    wilson_interval,
)
from reference import descend

P_MIN = 1e-3  # goodness-of-fit threshold at a fixed seed


def random_parts(count: int, seed: int) -> list[Part]:
    """The seed paper's random polygons: 10 uniform points in the unit square."""
    rng = np.random.default_rng(seed)
    return [Part.from_points(rng.random((10, 2)), name=f"random{i}") for i in range(count)]


def brute_execute(points: np.ndarray, steps: tuple[PlanStep, ...], theta: np.ndarray) -> np.ndarray:
    """Run squeezes by walking downhill on a grid of the width (no bayesgrasp code)."""
    grid, _, end = descend(points, 1 << 16)
    h = TWO_PI / len(grid)
    th = np.asarray(theta, dtype=np.float64)
    for s in steps:
        k = np.round(np.mod(th - s.alpha, TWO_PI) / h).astype(np.intp) % len(grid)
        th = grid[end[k]]
    return th


# --- sampling the prior -------------------------------------------------------------------


class Wedge(Prior):
    """A prior of no built-in type: density proportional to theta on [0, 2 pi)."""

    def cdf(self, theta: object) -> np.ndarray:
        th = np.asarray(theta, dtype=np.float64)
        turns = np.floor(th / TWO_PI)
        r = th - turns * TWO_PI
        return turns + (r / TWO_PI) ** 2

    @property
    def breakpoints(self) -> np.ndarray:
        return np.zeros(1)


@pytest.mark.parametrize(
    "prior",
    [UniformPrior(), HistogramPrior([3, 0, 1, 2]), von_mises(1.0, 3.0), Wedge()],
    ids=["uniform", "histogram", "von-mises", "custom"],
)
def test_sample_prior_follows_the_cdf(prior: Prior, rng: np.random.Generator) -> None:
    x = sample_prior(prior, 20_000, rng)
    assert x.shape == (20_000,)
    assert np.all((x >= 0) & (x < TWO_PI))
    res = kstest(x, lambda t: prior.cdf(t) - prior.cdf(0.0))
    assert res.pvalue > P_MIN


def test_sample_prior_draws_atoms_of_a_sample_prior(rng: np.random.Generator) -> None:
    prior = SamplePrior([0.5, 0.5, 2.0, 4.0])
    x = sample_prior(prior, 40_000, rng)
    assert set(np.unique(x).tolist()) == {0.5, 2.0, 4.0}
    assert_allclose(np.mean(x == 0.5), 0.5, atol=0.01)


def test_sample_prior_uses_the_prior_s_own_sampler() -> None:
    class Fixed(UniformPrior):
        def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
            return np.full(n, 7.0)

    assert_allclose(sample_prior(Fixed(), 3, 0), np.full(3, 7.0 - TWO_PI), atol=1e-12)


def test_sample_prior_rejects_negative_counts() -> None:
    with pytest.raises(SimulationError, match="`n` must be >= 0; got -1"):
        sample_prior(UniformPrior(), -1)


# --- prediction ----------------------------------------------------------------------------


def test_prediction_against_a_grid_walk() -> None:
    """The exact prediction equals the fraction of a fine grid that the walk sends there."""
    for part in random_parts(5, 7):
        pb = Problem.build(part)
        for opt in plan_exact(pb).options:
            grid = np.arange(1 << 16) * (TWO_PI / (1 << 16))
            end = brute_execute(part.hull.vertices, opt.steps, grid)
            dist = circle_distance(end[:, None], pb.states.stable)
            frac = np.bincount(dist.argmin(axis=1), minlength=pb.n_states) / len(grid)
            assert_allclose(frac, predicted_distribution(pb, opt.steps), atol=1e-3)


# --- the Monte Carlo -----------------------------------------------------------------------


def test_kinematic_agrees_with_execute_plan_and_a_grid_walk(rng: np.random.Generator) -> None:
    for part in [*random_parts(4, 11), load("triangle")]:
        pb = Problem.build(part)
        for opt in plan_exact(pb).options:
            res = simulate_kinematic(pb, opt, 300, rng=5, boundary_margin=0.0)
            theta0 = sample_prior(pb.prior, 300, np.random.default_rng(5))
            assert_allclose(res.final, execute_plan(pb, opt.steps, theta0), atol=0.0)
            # away from basin boundaries the grid walk lands on the same orientation
            walk = brute_execute(part.hull.vertices, opt.steps, theta0)
            err = circle_distance(walk, res.final)
            assert np.mean(err < 1e-3) > 0.99


@pytest.mark.parametrize("part", [*random_parts(6, 3), *(load(n) for n in names())],
                         ids=lambda p: p.name)  # fmt: skip
def test_observed_distribution_matches_prediction(part: Part) -> None:
    pb = Problem.build(part)
    for opt in plan_exact(pb).options:
        res = simulate_kinematic(pb, opt, 100_000, rng=2024)
        assert res.trials == 100_000
        assert res.jams == 0
        assert res.p_value > P_MIN
        lo, hi = res.ci95
        assert lo <= res.observed_success <= hi
        # many plans are checked: a 99.99% interval keeps false alarms rare
        lo, hi = wilson_interval(res.successes, res.trials, confidence=0.9999)
        assert lo <= res.predicted_success <= hi
        assert_allclose(res.observed.sum(), res.trials, atol=0)


def test_observed_distribution_matches_prediction_under_a_prior() -> None:
    pb = Problem.build(load("triangle"), von_mises(2.0, 4.0))
    for opt in plan_exact(pb).options:
        res = simulate_kinematic(pb, opt, 100_000, rng=9)
        assert res.p_value > P_MIN
        assert_allclose(res.predicted_success, opt.success_probability, atol=1e-9)


def test_a_wrong_prediction_is_detected() -> None:
    """The test has teeth: a plan run with a shifted first angle misses the prediction."""
    pb = Problem.build(load("triangle"), von_mises(2.0, 4.0))
    opt = plan_exact(pb).options[1]
    moved = type(opt)(
        (PlanStep("squeeze", opt.steps[0].alpha + 1.0), *opt.steps[1:]),
        opt.final_orientation, opt.success_probability, opt.expected_cost, opt.tolerance,
        opt.success_arc,
    )  # fmt: skip
    res = simulate_kinematic(pb, moved, 20_000, rng=1)
    # the prediction is recomputed for the steps actually run, so it still matches ...
    assert res.p_value > P_MIN
    # ... but running the moved steps against the original prediction fails
    orig = simulate_kinematic(pb, opt, 1, rng=1).predicted
    assert goodness_of_fit(res.observed, orig) < 1e-9


def plans_with_tolerance() -> list[tuple[Problem, PlanOption]]:
    out = []
    for part in [load("triangle"), load("rectangle"), *random_parts(3, 5)]:
        pb = Problem.build(part)
        for opt in plan_exact(pb).options:
            if opt.tolerance is not None and opt.tolerance > math.radians(2):
                out.append((pb, opt))
    return out


@pytest.mark.parametrize("kind", ["uniform", "normal"])
def test_noise_below_the_tolerance_keeps_the_success_rate(kind: str) -> None:
    cases = plans_with_tolerance()
    assert len(cases) >= 3
    for pb, opt in cases:
        tol = opt.tolerance
        assert tol is not None
        # a normal error of sigma tol / 5 exceeds tol with probability 6e-7
        scale = 0.95 * tol if kind == "uniform" else tol / 5
        res = simulate_kinematic(pb, opt, 50_000, GripperNoise(kind, scale), rng=4)
        sd = math.sqrt(res.predicted_success * (1 - res.predicted_success) / res.trials)
        assert res.observed_success >= res.predicted_success - 4 * sd


@pytest.mark.parametrize("kind", ["uniform", "normal"])
def test_noise_above_the_tolerance_lowers_the_success_rate(kind: str) -> None:
    for pb, opt in plans_with_tolerance():
        tol = opt.tolerance
        assert tol is not None
        # (within the model's range: a normal error's sigma at most 30 deg)
        scale = 4.0 * tol if kind == "uniform" else min(2.0 * tol, MAX_NORMAL_SIGMA)
        res = simulate_kinematic(pb, opt, 50_000, GripperNoise(kind, scale), rng=4)
        claim = opt.success_probability  # without noise
        sd = math.sqrt(claim * (1 - claim) / res.trials)
        assert res.observed_success < claim - 6 * sd
        noise_free = predicted_distribution(pb, opt.steps)
        assert goodness_of_fit(res.observed, noise_free) < 1e-6
        # ... and the prediction is the exact one under the noise, which the trials agree with.
        assert res.predicted_success < claim - 6 * sd
        assert res.agrees and res.p_value > 1e-4


def test_noise_within_the_tolerance_changes_no_successful_trial() -> None:
    """Errors on alpha_2..alpha_k within the tolerance keep every success (same starts)."""
    for pb, opt in plans_with_tolerance():
        tol = opt.tolerance
        assert tol is not None
        theta0 = sample_prior(pb.prior, 20_000, 3)
        base = execute_plan(pb, opt.steps, theta0)
        goal = pb.success_states(opt.final_orientation)
        idx = np.argmin(circle_distance(base[:, None], pb.states.stable), axis=1)
        ok = goal[idx]
        for sign in (-1.0, 1.0):
            steps = (
                opt.steps[0],
                *(PlanStep(s.kind, s.alpha + sign * 0.99 * tol) for s in opt.steps[1:]),
            )
            moved = execute_plan(pb, steps, theta0)
            assert_allclose(moved[ok], base[ok], atol=1e-12)


def test_near_boundary_counts_starts_within_the_margin() -> None:
    pb = Problem.build(load("rectangle"))
    opt = plan_exact(pb).options[0]
    res = simulate_kinematic(pb, opt, 200_000, rng=0, boundary_margin=math.radians(2.5))
    # 4 boundaries, 5 degrees around each, over 360 degrees
    assert_allclose(res.near_boundary / res.trials, 20 / 360, atol=0.003)
    assert simulate_kinematic(pb, opt, 1000, rng=0, boundary_margin=0.0).near_boundary == 0


def test_progress_is_reported_per_chunk() -> None:
    pb = Problem.build(load("rectangle"))
    calls: list[tuple[int, int]] = []
    simulate_kinematic(pb, plan_exact(pb).bayes_plan, 1000, rng=0, chunk=300,
                       progress=lambda d, t: calls.append((d, t)))  # fmt: skip
    assert calls == [(300, 1000), (600, 1000), (900, 1000), (1000, 1000)]


def test_kinematic_rejects_bad_settings() -> None:
    pb = Problem.build(load("rectangle"))
    opt = plan_exact(pb).bayes_plan
    with pytest.raises(SimulationError, match="`trials` must be an integer >= 1; got 0"):
        simulate_kinematic(pb, opt, 0)
    with pytest.raises(SimulationError, match="`chunk` must be >= 1; got 0"):
        simulate_kinematic(pb, opt, 10, chunk=0)
    bad = type(opt)((PlanStep("push-grasp", 0.0),), 0.0, 1.0, 2.0, None, (0.0, 1.0))
    with pytest.raises(SimulationError, match="uses 'push-grasp' actions but the problem"):
        simulate_kinematic(pb, bad, 10)


def test_push_grasp_plans_run_kinematically() -> None:
    pytest.importorskip("bayesgrasp.geometry.push")
    pb = Problem.build(load("triangle"), actions=("squeeze", "push-grasp"))
    for opt in plan_exact(pb).options:
        res = simulate_kinematic(pb, opt, 50_000, rng=8)
        assert res.p_value > P_MIN
        assert_allclose(res.predicted_success, opt.success_probability, atol=1e-9)


# --- the command line ----------------------------------------------------------------------


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_simulate_kinematic_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "simulate", "rectangle", "--trials", "20000", "--seed", "3",
                         "--json")  # fmt: skip
    assert code == 0, err
    doc = json.loads(out)
    assert doc["schema"] == "bayesgrasp.simulate/1"
    assert doc["engine"] == "kinematic"
    assert doc["trials"] == 20000
    assert doc["plan"]["squeezes"] == 2
    assert_allclose(doc["predicted_success"], 0.5, atol=1e-12)
    lo, hi = doc["ci95"]
    assert lo <= doc["observed_success"] <= hi
    assert doc["jams"] == 0
    assert doc["seconds"] >= 0
    rows = doc["per_orientation"]
    assert_allclose(sum(r["predicted"] for r in rows), 1.0, atol=1e-12)
    assert_allclose(sum(r["observed"] for r in rows), 1.0, atol=1e-12)
    assert {"orientation_rad", "predicted", "observed"} <= set(rows[0])


def test_cli_simulate_text_and_plans(capsys: pytest.CaptureFixture[str], tmp_path: object) -> None:
    code, out, _ = run(capsys, "simulate", "triangle", "--plan", "most-certain", "--trials",
                       "5000", "--noise", "1", "--noise-kind", "uniform")  # fmt: skip
    assert code == 0
    assert "predicted" in out and "observed" in out
    assert "95% interval" in out and "jams" in out and "near-boundary" in out
    code, out, err = run(capsys, "plan", "triangle", "--json")
    assert code == 0, err
    from pathlib import Path

    f = Path(str(tmp_path)) / "plan.json"
    f.write_text(out)
    code, out, err = run(capsys, "simulate", "triangle", "--plan", str(f), "--trials", "1000",
                         "--json")  # fmt: skip
    assert code == 0, err
    assert json.loads(out)["plan"]["squeezes"] == json.loads(f.read_text())["options"][
        json.loads(f.read_text())["bayes"]]["squeezes"]  # fmt: skip


def test_cli_simulate_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "simulate", "triangle", "--plan", "nope.json")
    assert code == 2
    assert err.startswith("bayesgrasp: error:") and "nope.json" in err
    code, _, err = run(capsys, "simulate", "triangle", "--offset", "2")
    assert code == 2
    assert "--offset" in err and "mujoco" in err
    code, _, err = run(capsys, "simulate", "triangle", "--trials", "0")
    assert code == 2


def test_cli_simulate_guaranteed_plan(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("bayesgrasp.planning.guaranteed")
    code, out, err = run(capsys, "simulate", "rectangle", "--plan", "guaranteed", "--trials",
                         "2000", "--goal", "symmetry", "--json")  # fmt: skip
    assert code == 0, err
    assert json.loads(out)["observed_success"] == 1.0


@pytest.mark.parametrize("seed", [-1, -(2**70), True, 1.5, "3", np.int64(-2)])
def test_a_bad_seed_is_a_simulation_error_naming_rng(seed: object) -> None:
    """Issue 15: ``rng=-1`` raised numpy's ValueError naming no parameter."""
    pb = Problem.build(load("triangle"))
    plan = plan_exact(pb).bayes_plan
    with pytest.raises(SimulationError, match=r"`rng` must be a numpy Generator, None or an"):
        simulate_kinematic(pb, plan, 10, rng=seed)  # type: ignore[arg-type]
    with pytest.raises(SimulationError, match=r"`rng` must be"):
        sample_prior(UniformPrior(), 3, rng=seed)  # type: ignore[arg-type]


def test_good_seeds_give_numpy_s_draws() -> None:
    pb = Problem.build(load("triangle"))
    plan = plan_exact(pb).bayes_plan
    a = simulate_kinematic(pb, plan, 1000, rng=np.int64(7))
    b = simulate_kinematic(pb, plan, 1000, rng=np.random.default_rng(7))
    c = simulate_kinematic(pb, plan, 1000, rng=np.random.SeedSequence(7))
    assert np.array_equal(a.observed, b.observed) and np.array_equal(a.observed, c.observed)


def test_every_sampler_refuses_a_negative_seed_naming_rng() -> None:
    """The noisy-plan and policy simulations and the gripper noise share ``as_generator``."""
    from bayesgrasp.model.noise import NoiseModel, parse_turn_noise
    from bayesgrasp.planning.policy import plan_policy
    from bayesgrasp.sim.noise import GripperNoise
    from bayesgrasp.sim.noisy import simulate_noise
    from bayesgrasp.sim.policy import simulate_policy

    pb = Problem.build(load("triangle"))
    steps = plan_exact(pb).bayes_plan.steps
    with pytest.raises(SimulationError, match=r"`rng` must be"):
        simulate_noise(pb, NoiseModel(parse_turn_noise("normal:2")), steps, 10, rng=-1)
    with pytest.raises(SimulationError, match=r"`rng` must be"):
        simulate_policy(pb, plan_policy(pb, "width", 2), 10, rng=-1)
    with pytest.raises(SimulationError, match=r"`rng` must be"):
        GripperNoise("normal", 0.01).draw((3,), rng=-1)
