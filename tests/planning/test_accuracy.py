"""Plans robust to gripper error: ``Problem.accuracy`` in the exact and guaranteed planners.

- Replay: every plan of two or more actions is executed with ``execute_plan`` with every
  turn perturbed by up to the accuracy (both extremes, random signs, random sizes); the
  fraction of prior draws that end at the goal must match the stated probability (binomial
  bound, fixed seed), and every orientation of the success arc must still end there.
- Brute force, written here from the squeeze function only: after a first squeeze at angle 0
  the part sits at one of the stable orientations (each with its basin's mass); every pair or
  triple of turns on a grid is tried, and a state counts for a final orientation only if it
  ends there under the extreme errors ``-A`` and ``+A`` on every turn (the lifted transfer
  function is non-decreasing, so the final orientation is monotone in each error and the
  two opposite corners of the error box bound every error inside it). Its best probability
  lies between the planner's with accuracy ``A + cell`` (such plans leave every turn a
  window of at least two cells) and with accuracy ``A``.
- Simulation: the kinematic Monte Carlo with uniform gripper noise just under the accuracy
  keeps the predicted success.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from bayesgrasp import (
    NoPlanError,
    Part,
    PlanningError,
    PlanStep,
    Problem,
    execute_plan,
    plan_exact,
)
from bayesgrasp.cli import main
from bayesgrasp.geometry.transfer import TransferFunction
from bayesgrasp.planning.bfs import plan_bfs
from bayesgrasp.planning.guaranteed import plan_guaranteed
from bayesgrasp.planning.result import PlanOption
from bayesgrasp.shapes import load
from bayesgrasp.sim.kinematic import GripperNoise, simulate_kinematic
from strategies import convex_points

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]
RECTANGLE = [(0.0, 0.0), (31.0, 0.0), (31.0, 20.0), (0.0, 20.0)]
ACCURACIES_DEG = [0.5, 2.0, 5.0, 12.0]


def random_part(rng: np.random.Generator, n: int = 8) -> Part:
    """The seed's random polygon: the hull of ``n`` uniform points in the unit square."""
    return Part.from_points(rng.uniform(size=(n, 2)))


def lands(out: FloatArray, final: float) -> NDArray[np.bool_]:
    d = np.abs(np.mod(out - final + math.pi, TWO_PI) - math.pi)
    return np.asarray(d < 1e-6)


def perturbed(option: PlanOption, errors: FloatArray) -> list[PlanStep]:
    return [option.steps[0]] + [
        PlanStep(s.kind, s.alpha + e) for s, e in zip(option.steps[1:], errors, strict=True)
    ]


def error_patterns(m: int, accuracy: float, rng: np.random.Generator) -> list[FloatArray]:
    """Both extremes with one sign, random extreme signs, and random sizes."""
    pats = [np.full(m, accuracy), np.full(m, -accuracy)]
    pats += [accuracy * rng.choice([-1.0, 1.0], size=m) for _ in range(4)]
    pats += [rng.uniform(-accuracy, accuracy, size=m) for _ in range(4)]
    return pats


def binomial_ok(hits: NDArray[np.bool_], p: float) -> bool:
    n = len(hits)
    return abs(float(hits.mean()) - p) <= 5.0 * math.sqrt(p * (1.0 - p) / n) + 1e-12


def check_robust(pb: Problem, rng: np.random.Generator, n: int = 4000) -> None:
    """Every plan of 2+ actions: tolerance >= accuracy, and success under errors <= accuracy."""
    acc = pb.accuracy
    theta = rng.uniform(0.0, TWO_PI, n)  # the uniform prior
    for o in plan_exact(pb).options:
        if o.n_actions < 2:
            continue
        assert o.tolerance is not None
        assert o.tolerance >= acc - 1e-12
        lo, hi = o.success_arc
        arc = np.linspace(lo, hi, 1001)[1:-1]
        for e in error_patterns(o.n_actions - 1, acc, rng):
            steps = perturbed(o, e)
            assert lands(execute_plan(pb, steps, arc), o.final_orientation).all()
            hits = lands(execute_plan(pb, steps, theta), o.final_orientation)
            assert binomial_ok(hits, o.success_probability)


@pytest.mark.parametrize("accuracy_deg", ACCURACIES_DEG)
def test_plans_tolerate_the_accuracy(rng: np.random.Generator, accuracy_deg: float) -> None:
    for _ in range(6):
        for actions in [("squeeze",), ("squeeze", "push-grasp")]:
            part = random_part(rng)
            check_robust(
                Problem.build(part, actions=actions, accuracy=math.radians(accuracy_deg)), rng
            )


@settings(max_examples=30)
@given(convex_points(), st.floats(0.0, 0.3))
def test_tolerance_at_least_accuracy(points: list[tuple[float, float]], accuracy: float) -> None:
    for o in plan_exact(Problem.build(Part.from_points(points), accuracy=accuracy)).options:
        if o.n_actions >= 2:
            assert o.tolerance is not None
            assert o.tolerance >= accuracy - 1e-12


def test_probabilities_never_above_accuracy_zero(rng: np.random.Generator) -> None:
    for _ in range(20):
        part = random_part(rng)
        free = plan_exact(Problem.build(part)).options
        top = max(o.success_probability for o in free)
        for deg in ACCURACIES_DEG:
            tight = plan_exact(Problem.build(part, accuracy=math.radians(deg))).options
            for k, o in enumerate(tight):
                ref = free[k].success_probability if k < len(free) else top
                assert o.success_probability <= ref + 1e-12
                assert o.success_probability <= top + 1e-12


def test_accuracy_below_every_tolerance_changes_nothing(rng: np.random.Generator) -> None:
    changed = 0
    for _ in range(20):
        part = random_part(rng)
        free = plan_exact(Problem.build(part)).options
        tols = [o.tolerance for o in free if o.tolerance is not None]
        if not tols:
            continue
        acc = 0.99 * min(tols)
        tight = plan_exact(Problem.build(part, accuracy=acc)).options
        assert [o.n_actions for o in tight] == [o.n_actions for o in free]
        for a, b in zip(tight, free, strict=True):
            assert a.success_probability == pytest.approx(b.success_probability, abs=1e-12)
            assert a.expected_cost == pytest.approx(b.expected_cost, rel=1e-12)
        # Just above the least tolerance that plan must go: the options change.
        over = plan_exact(Problem.build(part, accuracy=1.01 * min(tols))).options
        changed += [(o.n_actions, o.tolerance) for o in over] != [
            (o.n_actions, o.tolerance) for o in free
        ]
    assert changed > 0


# --------------------------------------------------------------------------------------
# Brute force over gridded turns
# --------------------------------------------------------------------------------------


def brute_best(f: TransferFunction, k: int, accuracy: float, cells: int) -> float:
    """Best probability of ``k`` squeezes whose success survives any errors within +-A.

    The turns run over a grid of ``cells`` angles in ``[0, pi)`` (a squeeze turned by pi
    is the same squeeze).
    """
    w = f.widths / TWO_PI
    turns = np.arange(cells) * (math.pi / cells)
    if k == 1:
        return float(w.max())
    grids = np.meshgrid(*([turns] * (k - 1)), indexing="ij")
    alphas = np.stack([g.ravel() for g in grids], axis=1)  # (P, k - 1)
    corners = []
    for sign in (-1.0, 1.0):
        pos = np.broadcast_to(f.stable, (len(alphas), f.n_states))  # (P, K)
        for m in range(k - 1):
            pos = f(pos - (alphas[:, m : m + 1] + sign * accuracy))
        corners.append(pos)
    lo, hi = corners
    robust = np.abs(lo - hi) < 1e-9  # the same lifted final orientation at both corners
    final = np.round(np.mod(lo, TWO_PI) * 1e6)
    # Mass of the robust states at each one's final orientation, best over plans.
    same = (np.abs(final[:, :, None] - final[:, None, :]) < 0.5) & robust[:, None, :]
    mass = (same @ w) * robust  # (P, K)
    return float(mass.max())


def planner_best(part: Part, k: int, accuracy: float) -> float:
    rep = plan_exact(Problem.build(part, accuracy=accuracy), max_actions=k)
    return max(o.success_probability for o in rep.options)


def test_brute_force_agrees_on_random_polygons(rng: np.random.Generator) -> None:
    cells = 720  # quarter-degree turns
    cell = math.pi / cells
    for _ in range(8):
        part = random_part(rng, 7)
        f = Problem.build(part).states
        for deg in (1.0, 4.0, 10.0):
            acc = math.radians(deg)
            for k in (2, 3):
                found = brute_best(f, k, acc, cells if k == 2 else 240)
                step = cell if k == 2 else math.pi / 240
                assert found <= planner_best(part, k, acc) + 1e-9
                assert found >= planner_best(part, k, acc + step) - 1e-9


# --------------------------------------------------------------------------------------
# The catalogue key, simulation, guaranteed plans, the baseline, the CLI
# --------------------------------------------------------------------------------------


def test_key_with_two_degrees() -> None:
    key = load("key")
    free = plan_exact(Problem.build(key))
    assert free.bayes_plan.tolerance is not None
    assert math.degrees(free.bayes_plan.tolerance) < 1.0  # the fragile plan of the study
    rep = plan_exact(Problem.build(key, accuracy=math.radians(2.0)))
    assert rep.bayes_plan.tolerance is not None
    assert math.degrees(rep.bayes_plan.tolerance) >= 2.0
    assert rep.bayes_plan.expected_cost >= free.bayes_plan.expected_cost


@pytest.mark.parametrize("actions", [("squeeze",), ("squeeze", "push-grasp")])
def test_simulation_under_bounded_noise_keeps_success(actions: tuple[str, ...]) -> None:
    acc = math.radians(2.0)
    pb = Problem.build(load("key"), actions=actions, accuracy=acc)
    noise = GripperNoise("uniform", 0.999 * acc)
    for o in plan_exact(pb).options:
        res = simulate_kinematic(pb, o, 50_000, noise, rng=3)
        assert res.final_jams == 0
        p = o.success_probability
        assert abs(res.observed_success - p) <= 5.0 * math.sqrt(p * (1 - p) / res.trials) + 1e-12


def test_simulation_shows_the_fragile_plan_fail() -> None:
    """The check above can fail: the accuracy-0 plan loses success under the same noise."""
    pb = Problem.build(load("key"))
    o = plan_exact(pb).bayes_plan
    res = simulate_kinematic(pb, o, 50_000, GripperNoise("uniform", math.radians(1.998)), rng=3)
    assert res.observed_success < o.success_probability - 0.05


def test_guaranteed_plan_honours_accuracy(rng: np.random.Generator) -> None:
    for _ in range(10):
        part = random_part(rng)
        for deg in (1.0, 3.0):
            pb = Problem.build(part, accuracy=math.radians(deg))
            g = plan_guaranteed(pb)
            if g.status == "no-plan":
                continue
            assert g.option.tolerance is not None
            assert g.option.tolerance >= pb.accuracy - 1e-12
            theta = np.linspace(0.0, TWO_PI, 3001)[:-1]
            for e in error_patterns(g.n_actions - 1, pb.accuracy, rng):
                out = execute_plan(pb, perturbed(g.option, e), theta)
                d = np.mod(out - g.option.final_orientation + g.period / 2, g.period) - g.period / 2
                near = np.min(np.abs(theta[:, None] - pb.states.boundaries[None, :]), axis=1)
                assert np.all((np.abs(d) < 1e-6) | (near < 1e-6))


def test_no_guaranteed_plan_under_large_accuracy() -> None:
    pb = Problem.build(load("key"), accuracy=math.radians(30.0))
    g = plan_guaranteed(pb)
    assert g.status == "no-plan" and g.options == ()
    assert g.reason is not None and "gripper accuracy 30 deg" in g.reason
    assert "short of the period 180.000000 deg" in g.reason
    # The widths stop growing: the last two are equal, all short of the period.
    assert len(g.widths) >= 2 and g.widths[-1] <= g.widths[-2] + 1e-9
    assert max(g.widths) < g.period
    # Asking for the plan says why there is none.
    with pytest.raises(NoPlanError, match="gripper accuracy 30 deg"):
        _ = g.option
    with pytest.raises(NoPlanError, match="gripper accuracy 30 deg"):
        _ = g.n_actions
    # The exact planner still answers: the single squeeze (no turn to err).
    assert [o.n_actions for o in plan_exact(pb).options] == [1]


@pytest.mark.parametrize("bad", [-0.1, math.nan, math.inf, True])
def test_accuracy_is_validated(bad: float) -> None:
    with pytest.raises(PlanningError, match="`accuracy` must be a finite number"):
        Problem.build(Part.from_points(RECTANGLE), accuracy=bad)


def test_bfs_refuses_accuracy() -> None:
    pb = Problem.build(Part.from_points(RECTANGLE), accuracy=0.01)
    with pytest.raises(PlanningError, match="`accuracy` must be 0"):
        plan_bfs(pb)


def test_cli_accuracy(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    assert main(["plan", "key", "--accuracy", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    bayes = doc["options"][doc["bayes"]]
    assert math.degrees(bayes["tolerance_rad"]) >= 2.0
    assert doc["accuracy_rad"] == pytest.approx(math.radians(2.0))
    assert main(["plan", "key", "--accuracy", "30", "--guaranteed"]) == 1
    out = capsys.readouterr().out
    assert "Guaranteed plan: none" in out and "gripper accuracy 30" in out
    assert main(["plan", "key", "--accuracy", "-1"]) == 2
    assert main(["plan", "key", "--accuracy", "1", "--method", "bfs"]) == 2
    assert "`accuracy` must be 0" in capsys.readouterr().err
