"""The one exact evaluator against every planner's own figures and against Monte Carlo runs.

:func:`bayesgrasp.planning.strategy.evaluate` propagates a belief through a strategy tree; every
planner (exact, breadth-first, guaranteed, noisy, policy) reports figures for the strategies it
returns, computed its own way. They must agree to rounding. The evaluator itself is checked
against an independent sampled execution (:func:`_run`): parts drawn from the part prior,
orientations from the orientation prior, the transfer functions applied to the sampled
orientation with a sampled turn error and contact event, the reading drawn by the sensor.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from numpy.testing import assert_allclose

from bayesgrasp.errors import PlanningError
from bayesgrasp.geometry import Part
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.io import resolve_part
from bayesgrasp.model import Problem
from bayesgrasp.model.actions import SQUEEZE
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.payoff import as_vector, read_payoff
from bayesgrasp.model.prior import parse_prior
from bayesgrasp.model.problem import nearest_state
from bayesgrasp.model.sensing import StateSpace, parse_sensor
from bayesgrasp.planning import plan_bfs, plan_exact, plan_guaranteed
from bayesgrasp.planning.noisy import plan_noisy
from bayesgrasp.planning.policy import Declare, PolicyNode, Reject, plan_policy
from bayesgrasp.planning.strategy import evaluate, plan_strategy
from bayesgrasp.shapes import names
from bayesgrasp.sim.kinematic import sample_prior
from strategies import convex_points

RTOL = 1e-9
CATALOGUE = names()
NOISES = {
    "normal 2": NoiseModel(TurnNoise("normal", math.radians(2.0))),
    "uniform 3 + contact 0.1": NoiseModel(TurnNoise("uniform", math.radians(3.0)), 0.1),
    "contact 0.2": NoiseModel(contact=0.2),
}
PAYOFF = "tests/snapshots/parts/payoff-key.json"


def _agree(plan_p: float, plan_cost: float, p: float, cost: float) -> None:
    assert_allclose(p, plan_p, rtol=RTOL, atol=1e-12)
    if math.isinf(plan_cost):
        assert math.isinf(cost)
    else:
        assert_allclose(cost, plan_cost, rtol=RTOL)


@pytest.mark.parametrize("name", CATALOGUE)
@pytest.mark.parametrize("planner", ["exact", "bfs", "guaranteed"])
def test_every_plan_of_the_noise_free_planners(name: str, planner: str) -> None:
    for actions in ("squeeze", "squeeze,push-grasp"):
        pb = Problem.build(resolve_part(name), actions=actions.split(","))
        if planner == "guaranteed":
            found = plan_guaranteed(pb)
            options = list(found.options)
        else:
            res = plan_exact(pb) if planner == "exact" else plan_bfs(pb)
            options = list(res.options)
        for o in options:
            ev = evaluate(pb, plan_strategy(pb, o))
            _agree(o.success_probability, o.expected_cost, ev.success_probability, ev.expected_cost)
            assert ev.expected_actions == pytest.approx(o.n_actions, abs=1e-12)
            assert ev.reject_probability == 0.0
            assert ev.final_distribution.sum() == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(
    ("name", "prior", "cost"),
    [
        ("key", "vonmises:40,4", CostModel(verify=2.0)),
        ("house", "uniform", CostModel({"squeeze": 0.5}, retry=3.0)),
        ("example", "vonmises:200,1", CostModel(first={"squeeze": 4.0}, retry=1.5)),
        ("hand", f"histogram:{'tests/snapshots/parts/histogram.txt'}", CostModel()),
    ],
)
def test_plans_under_priors_and_costs(name: str, prior: str, cost: CostModel) -> None:
    pb = Problem.build(resolve_part(name), prior=parse_prior(prior), cost=cost)
    for o in plan_exact(pb).options:
        ev = evaluate(pb, plan_strategy(pb, o))
        _agree(o.success_probability, o.expected_cost, ev.success_probability, ev.expected_cost)


@pytest.mark.parametrize("noise", list(NOISES), ids=list(NOISES))
@pytest.mark.parametrize("name", ["key", "house", "triangle", "example"])
def test_noisy_plans(name: str, noise: str) -> None:
    pb = Problem.build(resolve_part(name))
    res = plan_noisy(pb, NOISES[noise])
    for o in res.options:
        ev = evaluate(pb, plan_strategy(pb, o.option), noise=NOISES[noise])
        _agree(
            o.evaluation.success_probability,
            o.evaluation.expected_cost,
            ev.success_probability,
            ev.expected_cost,
        )
        assert_allclose(ev.final_distribution, o.evaluation.distribution, atol=1e-12)


@pytest.mark.parametrize("noise", [NoiseModel(), *NOISES.values()])
def test_noisy_plans_with_a_payoff(noise: NoiseModel) -> None:
    pb = Problem.build(resolve_part("key"))
    payoff = read_payoff(PAYOFF)
    u = as_vector(payoff, pb.states)
    for o in plan_noisy(pb, noise, payoff, 4, all_lengths=True).options:
        ev = evaluate(pb, plan_strategy(pb, o.option), noise=noise, payoff=u)
        _agree(
            o.expected_payoff, o.evaluation.expected_cost, ev.success_probability, ev.expected_cost
        )


POLICY_CASES = [
    ("house", (), "width", None),
    ("house", (), "width:0.5,0.1", None),
    ("key", (), "width:0.5,0.1", None),
    ("key", (), "width:0,1", None),
    ("triangle", ("rectangle",), "width", None),
    ("rectangle", ("triangle",), "width:0.2,0.05", "1,3"),
    ("example", (), "width", None),
]


@pytest.mark.parametrize(("name", "also", "sensor", "part_prior"), POLICY_CASES)
def test_policies(name: str, also: tuple[str, ...], sensor: str, part_prior: str | None) -> None:
    pbs = [Problem.build(resolve_part(n)) for n in (name, *also)]
    pol = plan_policy(pbs, sensor, 3, part_prior=part_prior)
    ev = evaluate(pbs, pol.root, sensor=pol.sensor, part_prior=part_prior)
    _agree(pol.success_probability, pol.expected_cost, ev.success_probability, ev.expected_cost)
    assert ev.cycle_cost == pytest.approx(pol.cycle_cost, rel=RTOL)
    assert ev.reject_probability == pytest.approx(pol.reject_probability, abs=1e-12)
    assert ev.expected_actions == pytest.approx(pol.expected_actions, rel=RTOL)
    assert_allclose(ev.expected_entropy, pol.expected_entropy, rtol=1e-9, atol=1e-12)


def test_policy_with_push_grasps() -> None:
    pb = Problem.build(resolve_part("example"), actions=["squeeze", "push-grasp"])
    pol = plan_policy(pb, "width:0.3,0.1", 2)
    ev = evaluate(pb, pol.root, sensor=pol.sensor)
    _agree(pol.success_probability, pol.expected_cost, ev.success_probability, ev.expected_cost)


@settings(max_examples=40, deadline=None)
@given(convex_points())
def test_random_parts(points: np.ndarray) -> None:
    pb = Problem.build(Part.from_points(points))
    for o in plan_exact(pb).options:
        ev = evaluate(pb, plan_strategy(pb, o))
        _agree(o.success_probability, o.expected_cost, ev.success_probability, ev.expected_cost)
        assert 0.0 <= ev.success_probability <= 1.0
        assert ev.final_distribution.sum() == pytest.approx(1.0, abs=1e-9)


# -- the evaluator against sampled executions ------------------------------------------------


def _act(pb: Problem, kind: str, theta: np.ndarray, noise: NoiseModel, rng: np.random.Generator):
    """The part's orientation after acting on it at ``theta`` (gripper frame), with contacts."""
    out = pb.transfer(kind)(theta)
    if kind == SQUEEZE.name and noise.contact > 0:
        g = push_grasp_function(pb.part, pb.states)
        u = rng.random(theta.shape)
        left = u < noise.contact / 2
        right = (u >= noise.contact / 2) & (u < noise.contact)
        out = np.where(left, g(theta), out)
        out = np.where(right, g(theta - math.pi) + math.pi, out)
    return np.mod(out, 2 * math.pi)


def _error(noise: NoiseModel, n: int, rng: np.random.Generator) -> np.ndarray:
    t = noise.turn
    if t.scale == 0:
        return np.zeros(n)
    if t.kind == "normal":
        return rng.normal(0.0, t.scale, n)
    return rng.uniform(-t.scale, t.scale, n)


def _run(pbs, root, sensor, noise, part_prior, n, rng):
    """Sampled cycles: (success, cycle cost without the retry, number of actions) each."""
    space = StateSpace.build(pbs, part_prior)
    sens = None if sensor is None else parse_sensor(sensor)
    part = rng.choice(len(pbs), size=n, p=space.part_prior)
    theta = np.zeros(n)
    for j, pb in enumerate(pbs):
        idx = np.flatnonzero(part == j)
        theta[idx] = sample_prior(pb.prior, len(idx), rng)
    ok = np.zeros(n, dtype=bool)
    cost = np.zeros(n)
    acts = np.zeros(n)
    cm = pbs[0].cost

    def walk(node, idx, first):
        # The gripper turns by the commanded angle plus its error, then acts.
        t = theta[idx] - node.step.alpha - _error(noise, len(idx), rng)
        for j, pb in enumerate(pbs):
            sel = part[idx] == j
            theta[idx[sel]] = _act(pb, node.step.kind, t[sel], noise, rng)
        acts[idx] += 1
        cost[idx] += cm.action_cost(node.step.kind, first)
        width = np.zeros(len(idx))
        for j, pb in enumerate(pbs):
            sel = part[idx] == j
            width[sel] = pb.widths[nearest_state(pb.states, theta[idx[sel]])]
        reading = width if sens is None else sens.read(width, rng)
        his = np.array([b.hi for b in node.branches])
        which = np.searchsorted(his[:-1], reading, side="right")
        for k, br in enumerate(node.branches):
            sub = idx[which == k]
            if len(sub) == 0:
                continue
            if isinstance(br.next, PolicyNode):
                walk(br.next, sub, False)
            elif isinstance(br.next, Declare):
                cost[sub] += cm.verify
                d = br.next
                pb = pbs[d.part]
                good = pb.success_states(d.orientation)
                mine = sub[part[sub] == d.part]
                ok[mine] = good[nearest_state(pb.states, theta[mine])]
            else:
                assert isinstance(br.next, Reject)

    walk(root, np.arange(n), True)
    return ok, cost, acts


# Noise strong enough that its effect on every figure is many standard errors of the runs.
STRONG = {
    "normal 8": NoiseModel(TurnNoise("normal", math.radians(8.0))),
    "uniform 10 + contact 0.3": NoiseModel(TurnNoise("uniform", math.radians(10.0)), 0.3),
    "contact 0.5": NoiseModel(contact=0.5),
}
MC_CASES = [
    ("key", (), None, NoiseModel(), "plan"),
    ("key", (), None, STRONG["normal 8"], "noisy"),
    ("triangle", (), None, STRONG["uniform 10 + contact 0.3"], "noisy"),
    ("house", (), "width:0.5,0.1", NoiseModel(), "policy"),
    ("triangle", ("rectangle",), "width", NoiseModel(), "policy"),
    ("house", (), "width:0.5,0.1", STRONG["normal 8"], "policy"),
    ("key", (), "width", STRONG["contact 0.5"], "policy"),
    # Noise-free strategies run under noise they were not planned for.
    ("key", (), None, STRONG["normal 8"], "plan"),
    ("house", (), None, STRONG["contact 0.5"], "plan"),
    ("example", (), "width", STRONG["uniform 10 + contact 0.3"], "policy"),
]


@pytest.mark.parametrize(("name", "also", "sensor", "noise", "what"), MC_CASES)
def test_evaluation_matches_sampled_cycles(name, also, sensor, noise, what, rng) -> None:
    # A peaked prior where the actions are exact, the uniform one where the noise matters most.
    prior = parse_prior("vonmises:60,2" if noise.exact and noise.contact == 0 else "uniform")
    pbs = [Problem.build(resolve_part(n), prior=prior) for n in (name, *also)]
    pb = pbs[0]
    if what == "plan":
        root = plan_strategy(pb, plan_exact(pb).bayes_plan)
    elif what == "noisy":
        root = plan_strategy(pb, plan_noisy(pb, noise).bayes_plan.option)
    else:  # a noise-free policy, run under the noise as it is
        root = plan_policy(pbs, sensor, 3).root
    ev = evaluate(pbs, root, sensor=sensor, noise=noise)
    n = 40_000
    ok, cost, acts = _run(pbs, root, sensor, noise, None, n, rng)
    p = ev.success_probability
    se = math.sqrt(max(p * (1 - p), 1e-6) / n)
    assert abs(ok.mean() - p) < 4.5 * se
    attempt = ev.cycle_cost - pb.cost.retry * (1 - p)
    assert abs(cost.mean() - attempt) < 4.5 * cost.std() / math.sqrt(n) + 1e-12
    assert abs(acts.mean() - ev.expected_actions) < 4.5 * acts.std() / math.sqrt(n) + 1e-12


def test_a_branching_strategy_needs_its_sensor() -> None:
    pb = Problem.build(resolve_part("house"))
    pol = plan_policy(pb, "width", 2)
    with pytest.raises(PlanningError, match="needs the sensor"):
        evaluate(pb, pol.root)


def test_payoff_must_cover_every_state() -> None:
    pb = Problem.build(resolve_part("key"))
    root = plan_strategy(pb, plan_exact(pb).bayes_plan)
    with pytest.raises(PlanningError, match="one value per state"):
        evaluate(pb, root, payoff=[1.0, 0.0])
