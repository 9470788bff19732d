"""Plans keep every state they may meet off the squeeze's unstable equilibria.

A state whose orientation, turned by a plan's ``alpha``, lies exactly on a basin boundary of
the next action (a maximum of the diameter function, or of the push-grasp's radius function
under contact asynchrony) is an unstable equilibrium: the transition matrices send it to one
side (their intervals are half-open), a squeeze to either side or nowhere (it jams). So a
plan whose claim rests on such a state claims what no gripper does.

Checked here, with the reachable states and boundaries computed from the transfer functions
(not from the planner's matrices):

- every plan of the exact planner (the catalogue and random polygons) and of the noise-aware
  planner under contact noise (random polygons, several ``q``) keeps a positive margin from
  every boundary of every state of positive probability; the noise-aware plan reports that
  margin as its ``tolerance``;
- the house under contact noise 0.3 (whose Bayes plan once turned by exactly -45 deg, four
  states on equilibria) and every catalogue part: the claimed success agrees with the
  kinematic simulation within binomial bounds, and no trial jams;
- a candidate with a turn on an equilibrium is moved to the better side of it;
- under a sample prior (atoms) the first angle keeps every atom off the first action's
  boundaries too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from bayesgrasp import shapes
from bayesgrasp.angles import TWO_PI
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.geometry.transfer import TransferFunction
from bayesgrasp.model.noise import NoiseModel, NoisyTransitions
from bayesgrasp.model.prior import SamplePrior
from bayesgrasp.model.problem import Problem
from bayesgrasp.model.states import nearest_state
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import PlanStep, plan_exact
from bayesgrasp.planning.noisy import _Cand, _Planner, evaluate_plan, plan_noisy
from bayesgrasp.planning.robust import plan_guaranteed_noisy
from bayesgrasp.sim.kinematic import simulate_kinematic

DEG = math.pi / 180


def _ways(pb: Problem, kind: str, q: float) -> list[tuple[TransferFunction, float]]:
    """The transfer functions an action may apply, each with its extra turn (0 or pi)."""
    f = pb.transfer(kind)
    if kind != "squeeze" or q == 0:
        return [(f, 0.0)]
    g = push_grasp_function(pb.part, pb.states)
    ways = [(g, 0.0), (g, math.pi)]
    return ways if q == 1 else [(f, 0.0), *ways]


def _distance(x: np.ndarray, f: TransferFunction) -> np.ndarray:
    """Distance of each orientation ``x`` to the nearest basin boundary of ``f`` (radians)."""
    b = np.concatenate([f.basin_lo, f.basin_hi])
    d = np.mod(x[:, None] - b[None, :] + math.pi, TWO_PI) - math.pi
    return np.asarray(np.abs(d).min(axis=1))


def margins(pb: Problem, steps: tuple[PlanStep, ...], q: float = 0.0) -> list[float]:
    """Each turn's least distance to a boundary of a state the plan may reach before it.

    The states reached are followed through the transfer functions themselves: after the
    first action (uniform prior: every basin has mass), each state turned by ``alpha`` and
    sent by each way the action may go.
    """
    reach = set()
    for f, o in _ways(pb, steps[0].kind, q):
        reach |= set(nearest_state(pb.states, np.mod(f.stable + o, TWO_PI)).tolist())
    out = []
    for s in steps[1:]:
        x = pb.states.stable[sorted(reach)] - s.alpha
        out.append(min(float(_distance(x - o, f).min()) for f, o in _ways(pb, s.kind, q)))
        nxt: set[int] = set()
        for f, o in _ways(pb, s.kind, q):
            ends = np.mod(f(x - o) + o, TWO_PI)
            nxt |= set(nearest_state(pb.states, ends).tolist())
        reach = nxt
    return out


# -- the exact planner ---------------------------------------------------------------------------


def _exact_ok(pb: Problem) -> None:
    tol = pb.states.angle_tol
    for o in plan_exact(pb).options:
        m = margins(pb, o.steps)
        assert all(x > tol for x in m), (pb.part.name, o.n_actions, np.degrees(m))


@pytest.mark.parametrize("name", shapes.names())
def test_exact_plans_keep_off_the_equilibria_catalogue(name: str) -> None:
    _exact_ok(Problem.build(shapes.load(name)))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), points=st.integers(3, 12))
def test_exact_plans_keep_off_the_equilibria(seed: int, points: int) -> None:
    _exact_ok(Problem.build(random_polygon(seed, points)))


# -- the noise-aware planner under contact noise -----------------------------------------------


def _noisy_ok(pb: Problem, q: float) -> None:
    res = plan_noisy(pb, NoiseModel(contact=q))
    tol = pb.states.angle_tol
    for o in res.options:
        m = margins(pb, o.option.steps, q)
        assert all(x > tol for x in m), (pb.part.name, q, o.option.n_actions, np.degrees(m))
        if m:  # the reported tolerance is that margin
            assert o.option.tolerance == pytest.approx(min(m), abs=1e-9)
        else:
            assert o.option.tolerance is None


@pytest.mark.parametrize("name", shapes.names())
def test_contact_plans_keep_off_the_equilibria_catalogue(name: str) -> None:
    _noisy_ok(Problem.build(shapes.load(name)), 0.3)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    points=st.integers(3, 12),
    q=st.sampled_from([0.05, 0.3, 0.7, 1.0]),
)
def test_contact_plans_keep_off_the_equilibria(seed: int, points: int, q: float) -> None:
    _noisy_ok(Problem.build(random_polygon(seed, points)), q)


@settings(max_examples=15, deadline=None)
@given(
    name=st.sampled_from(["key", "house", "example", "triangle"]),
    atoms=st.lists(st.floats(0.0, TWO_PI, exclude_max=True), min_size=1, max_size=8),
)
@example(name="triangle", atoms=[0.0, 2.0])  # the first squeeze once put the atom 0 on a boundary
def test_the_first_angle_keeps_atoms_off_the_boundaries(name: str, atoms: list[float]) -> None:
    """Under a sample prior an atom on a first-action boundary would be an equilibrium too."""
    pb = Problem.build(shapes.load(name), prior=SamplePrior(atoms))
    q = 0.3
    for o in plan_noisy(pb, NoiseModel(contact=q)).options:
        a = o.option.steps[0].alpha
        x = pb.prior.angles - a  # type: ignore[attr-defined]
        d = min(float(_distance(x - off, f).min()) for f, off in _ways(pb, "squeeze", q))
        assert d > pb.states.angle_tol, (name, atoms, o.option.n_actions)


# -- against the kinematic simulation -----------------------------------------------------------


def _agrees(pb: Problem, noise: NoiseModel, n: int, seed: int) -> None:
    res = plan_noisy(pb, noise)
    for i in range(len(res.options)):  # every length, the Bayes and most certain plans among them
        o = res.options[i]
        sim = simulate_kinematic(pb, o.option, n, noise, rng=seed + i)
        assert sim.jams == 0
        p = o.evaluation.success_probability
        assert sim.predicted_success == pytest.approx(p, abs=1e-12)
        sd = math.sqrt(p * (1 - p) / n)
        assert abs(sim.observed_success - p) < 5 * sd + 3 / n, (pb.part.name, i)
        assert sim.agrees


def test_the_house_under_contact_noise() -> None:
    """Its Bayes plan once turned by -45 deg: four states on equilibria, half the trials jammed."""
    pb = Problem.build(shapes.load("house"))
    noise = NoiseModel(contact=0.3)
    res = plan_noisy(pb, noise)
    for o in res.options[1:]:
        assert all(abs(s.alpha + 45 * DEG) > 1e-6 for s in o.option.steps[1:])
        assert min(margins(pb, o.option.steps, 0.3)) > 0.1 * DEG
    _agrees(pb, noise, 100_000, 7)


@pytest.mark.parametrize("name", shapes.names())
def test_contact_plans_agree_with_the_kinematic_simulation(name: str) -> None:
    _agrees(Problem.build(shapes.load(name)), NoiseModel(contact=0.3), 40_000, 3)


# -- moving a turn off an equilibrium -------------------------------------------------------------


def test_a_turn_on_an_equilibrium_is_moved_to_its_better_side() -> None:
    pb = Problem.build(shapes.load("house"))
    noise = NoiseModel(contact=0.3)
    pl = _Planner(pb, noise, None)
    kinds = ("squeeze", "squeeze")
    on_edge = [0.0, -45 * DEG]
    assert min(margins(pb, (PlanStep("squeeze", 0.0), PlanStep("squeeze", -45 * DEG)), 0.3)) < 1e-9
    angles, moved, q_end = pl.off_edges(kinds, on_edge)
    assert moved and angles[0] == 0.0
    steps = tuple(PlanStep(t, a) for t, a in zip(kinds, angles, strict=True))
    assert min(margins(pb, steps, 0.3)) > 1e-6
    # Its value is the better side's: a turn just beside -45 deg either way (same target).
    got = evaluate_plan(pb, noise, steps)
    np.testing.assert_allclose(q_end, got.distribution, atol=1e-15)
    sides = [
        evaluate_plan(pb, noise, [PlanStep("squeeze", 0.0), PlanStep("squeeze", -45 * DEG + e)])
        for e in (-1e-6, 1e-6)
    ]
    assert got.expected_payoff == pytest.approx(max(s.expected_payoff for s in sides), abs=1e-12)
    # A turn already off every equilibrium is left alone.
    again, moved, _ = pl.off_edges(kinds, angles)
    assert not moved and again == angles
    # And the refinement does not put it back.
    cand = _Cand(kinds, angles, "test")
    refined = pl.refine(cand)
    rsteps = tuple(PlanStep(t, a) for t, a in zip(kinds, refined.angles, strict=True))
    assert min(margins(pb, rsteps, 0.3)) > 1e-6


# -- the best two-action plan, against a grid of turns off the equilibria ------------------------


@pytest.mark.parametrize("name", shapes.names())
def test_two_actions_under_contact_noise_beat_every_turn_of_a_grid(name: str) -> None:
    """Exact turns: the refined plan of 2 squeezes is at least the best turn of a fine grid.

    The grid's turns within 1e-7 rad of a boundary of a state they meet are left out (their
    matrices' value is one side's); with the rest fixed, the plan's payoff is constant
    between boundaries, so the grid cannot beat the planner, whose payoff is a real one (its
    turn keeps a margin).
    """
    pb = Problem.build(shapes.load(name))
    q = 0.3
    noise = NoiseModel(contact=q)
    res = plan_noisy(pb, noise, max_actions=2, all_lengths=True)
    o = res.options[1]
    a0 = o.option.steps[0].alpha
    grid = np.linspace(-math.pi / 2, math.pi / 2, 3601, endpoint=False)
    q1 = evaluate_plan(pb, noise, [PlanStep("squeeze", a0)]).distribution
    reach = pb.states.stable[q1 > 0]
    x = (reach[None, :] - grid[:, None]).ravel()  # (N R,) each state turned by each turn
    near = np.zeros(len(grid), dtype=bool)
    for f, off in _ways(pb, "squeeze", q):
        near |= (_distance(x - off, f).reshape(len(grid), -1) < 1e-7).any(axis=1)
    qs = np.einsum("k,nkj->nj", q1, NoisyTransitions(pb, noise).matrices("squeeze", grid))
    assert pb.goal_group == 1  # the payoff of a plan: its most likely final state
    best = float(qs[~near].max(axis=1).max())
    assert o.expected_payoff >= best - 1e-12
    assert min(margins(pb, o.option.steps, q)) > pb.states.angle_tol


@pytest.mark.parametrize("name", shapes.names())
def test_guaranteed_plans_under_contact_noise_keep_off_the_equilibria(name: str) -> None:
    """The set search's turns are middles between every boundary of every state it may meet."""
    pb = Problem.build(shapes.load(name))
    g = plan_guaranteed_noisy(pb, NoiseModel(contact=0.3), max_actions=6)
    if g.status != "ok":
        pytest.skip(g.reason or "no plan")
    assert g.option is not None
    m = margins(pb, g.option.steps, 0.3)
    assert all(x > pb.states.angle_tol for x in m), np.degrees(m)
    if m:
        assert g.option.tolerance is not None and g.option.tolerance <= min(m) + 1e-12
