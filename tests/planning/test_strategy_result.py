"""One result type for every planner: :func:`~bayesgrasp.planning.strategy.solve`.

Each planner's front-door result is held against its planner called directly (the same
plans and documents) and against the one evaluator (its claimed figures); the documents are
read back and re-evaluated; the noisy linear evaluation is the evaluator's; the noisy
policy's candidate turns are each one action once.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import PlanningError, SimulationError
from bayesgrasp.io import resolve_part
from bayesgrasp.io.plans import (
    PlanSource,
    PolicySource,
    noisy_plan_document,
    plan_document,
    policy_document,
    read_policy_document,
    read_strategy,
    strategy_document,
    strategy_document_json,
)
from bayesgrasp.model import Problem
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.payoff import read_payoff
from bayesgrasp.model.sensing import StateSpace, parse_sensor
from bayesgrasp.planning import (
    StrategyResult,
    noisy_model,
    plan_bfs,
    plan_exact,
    plan_guaranteed,
    solve,
)
from bayesgrasp.planning.noisy import PlanEvaluator, evaluate_plan, plan_noisy
from bayesgrasp.planning.policy import DEFAULT_PRUNE, make_solver, plan_policy
from bayesgrasp.planning.result import PlanStep
from bayesgrasp.planning.robust import plan_guaranteed_noisy
from bayesgrasp.planning.strategy import evaluate

RTOL = 1e-9
PARTS = ["rectangle", "key", "triangle", "house"]
NOISES = {
    "normal 2": NoiseModel(TurnNoise("normal", math.radians(2.0))),
    "uniform 3": NoiseModel(TurnNoise("uniform", math.radians(3.0))),
    "contact 0.3": NoiseModel(contact=0.3),
    "uniform 2 + contact 0.1": NoiseModel(TurnNoise("uniform", math.radians(2.0)), 0.1),
}
PAYOFF = "tests/snapshots/parts/payoff-key.json"


def _pb(name: str) -> Problem:
    return Problem.build(resolve_part(name))


def _same_json(a: object, b: object) -> None:
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def _claimed_agree(res: StrategyResult) -> None:
    """The result's claimed figures are the evaluator's (every alternative's too)."""
    ev = res.evaluation
    assert_allclose(ev.success_probability, res.success_probability, rtol=RTOL, atol=1e-12)
    if math.isinf(res.expected_cost):
        assert math.isinf(ev.expected_cost)
    else:
        assert_allclose(ev.expected_cost, res.expected_cost, rtol=RTOL)
    for alt in res.alternatives:
        got = res.evaluate(alt.strategy)
        assert_allclose(got.success_probability, alt.success_probability, rtol=RTOL, atol=1e-12)


@pytest.mark.parametrize("name", PARTS)
@pytest.mark.parametrize("method", ["exact", "bfs", "guaranteed"])
def test_noise_free_planners_through_the_front_door(name: str, method: str) -> None:
    pb = _pb(name)
    res = solve(pb, method=method)
    direct = {"exact": plan_exact, "bfs": plan_bfs, "guaranteed": plan_guaranteed}[method](pb)
    assert res.kind == "plan" and res.method == method and res.ok
    assert res.plans is direct or res.plans.options == direct.options  # type: ignore[union-attr]
    assert [a.option for a in res.alternatives] == list(direct.options)
    assert [a.tolerance for a in res.alternatives] == [o.tolerance for o in direct.options]
    assert (res.bayes, res.most_certain) == (direct.bayes, direct.most_certain)
    _same_json(strategy_document(res), plan_document(direct))
    _claimed_agree(res)
    # a linear plan never branches, and the evaluation has an entropy for each level
    node, depth = res.strategy, 0
    while True:
        depth += 1
        assert len(node.branches) == 1
        if not hasattr(node.branches[0].next, "branches"):
            break
        node = node.branches[0].next  # type: ignore[assignment]
    assert depth == res.bayes_plan.n_actions == len(res.evaluation.expected_entropy)


@pytest.mark.parametrize("name", PARTS)
@pytest.mark.parametrize("noise", list(NOISES))
def test_noise_aware_plans_through_the_front_door(name: str, noise: str) -> None:
    pb, model = _pb(name), NOISES[noise]
    res = solve(pb, noise=model)
    direct = plan_noisy(pb, model)
    assert res.method == "noisy" and res.noise == model
    _same_json(strategy_document(res), noisy_plan_document(direct))
    _claimed_agree(res)


def test_a_payoff_plan_and_its_guarantee() -> None:
    pb = _pb("key")
    payoff = read_payoff(PAYOFF)
    model = NOISES["uniform 3"]
    res = solve(pb, noise=model, payoff=payoff, guaranteed=True, best_only=True)
    direct = plan_noisy(pb, model, payoff).best_only()
    _same_json(
        strategy_document(res),
        noisy_plan_document(direct, guaranteed=plan_guaranteed_noisy(pb, model)),
    )
    assert res.payoff is not None and res.provenance["payoff"] == res.payoff.tolist()
    _claimed_agree(res)  # the payoff earned, per the evaluator


@pytest.mark.parametrize("name", ["rectangle", "key"])
def test_policies_through_the_front_door(name: str) -> None:
    pb = _pb(name)
    res = solve(pb, sensor="width:0.5,0.1", max_actions=2)
    direct = plan_policy(pb, "width:0.5,0.1", 2)
    assert res.kind == "policy" and res.method == "policy" and res.sensor == direct.sensor
    _same_json(strategy_document(res), policy_document(direct))
    assert_allclose(res.evaluation.expected_entropy, direct.expected_entropy, rtol=RTOL)
    _claimed_agree(res)
    noisy = solve(pb, sensor="width", max_actions=2, noise=NOISES["contact 0.3"])
    assert noisy.method == "noisy-policy"
    _claimed_agree(noisy)


def test_several_candidate_parts_are_one_policy() -> None:
    pbs = [_pb("key"), _pb("rectangle")]
    res = solve(pbs, sensor="width", max_actions=2, part_prior=[0.3, 0.7])
    assert res.problems == tuple(pbs) and res.provenance["part_prior"] == [0.3, 0.7]
    _claimed_agree(res)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"sensor": "width", "guaranteed": True}, "takes no guaranteed"),
        ({"sensor": "width", "best_only": True}, "takes no best_only"),
        ({"sensor": "width", "method": "bfs"}, "method 'bfs'"),
        ({"noise": NOISES["contact 0.3"], "method": "bfs"}, "seeds from the exact"),
        ({"noise": NOISES["normal 2"], "guaranteed": True}, "normal"),
        ({"part_prior": [1.0]}, "policies"),
    ],
)
def test_combinations_that_mean_nothing_are_refused(kwargs: dict, words: str) -> None:
    with pytest.raises(PlanningError, match=words):
        solve(_pb("rectangle"), **kwargs)


def test_several_parts_need_a_sensor() -> None:
    with pytest.raises(PlanningError, match="sensor"):
        solve([_pb("rectangle"), _pb("key")])


def test_a_policy_is_not_a_linear_plan() -> None:
    res = solve(_pb("rectangle"), sensor="width", max_actions=1)
    with pytest.raises(PlanningError, match="not a linear plan"):
        res.bayes_plan  # noqa: B018
    assert res.best_only() is res and res.plans is None


def test_the_one_line_document_is_the_document() -> None:
    res = solve(_pb("key"), guaranteed=True)
    assert json.loads(strategy_document_json(res)) == strategy_document(res)


# --- reading documents back ------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs",
    [
        {"sensor": "width:0.5,0.1", "max_actions": 2},
        {"sensor": "width", "max_actions": 2, "noise": NOISES["uniform 2 + contact 0.1"]},
        {"sensor": "width", "max_actions": 2, "payoff": read_payoff(PAYOFF)},
    ],
)
def test_a_policy_document_read_back_evaluates_to_its_figures(kwargs: dict, tmp_path) -> None:
    """The reader (tree, sensor, noise, payoff) and the evaluator reproduce what was written."""
    pb = _pb("key")
    doc = strategy_document(solve(pb, **kwargs))
    path = tmp_path / "policy.json"
    path.write_text(json.dumps(doc))
    src = read_strategy(path)
    assert isinstance(src, PolicySource)
    ev = evaluate(
        pb,
        src.root,
        sensor=src.sensor,
        noise=src.noise,
        payoff=None if src.payoff is None else np.array(src.payoff),
        part_prior=list(src.part_prior),
    )
    assert_allclose(ev.success_probability, doc["success_probability"], rtol=RTOL)
    assert_allclose(ev.expected_cost, doc["expected_cost"], rtol=RTOL)
    assert_allclose(ev.expected_entropy, doc["expected_entropy_bits"], rtol=RTOL, atol=1e-12)
    assert src.figures["expected_cost"] == doc["expected_cost"]


def test_a_plan_document_reads_as_a_plan() -> None:
    res = solve(_pb("key"))
    src = read_strategy(strategy_document(res), "most-certain")
    assert isinstance(src, PlanSource)
    assert src.option.steps == res.plans.most_certain_plan.steps  # type: ignore[union-attr]


@pytest.mark.parametrize(
    ("doc", "words"),
    [
        ({"schema": "bayesgrasp.plan/1"}, "expected a bayesgrasp.policy/1"),
        ({"schema": "bayesgrasp.policy/1", "parts": ["a"]}, "malformed"),
    ],
)
def test_a_malformed_policy_document_is_one_clear_error(doc: dict, words: str) -> None:
    with pytest.raises(SimulationError, match=words):
        read_policy_document(doc)


def test_a_malformed_node_names_where_it_is() -> None:
    doc = strategy_document(solve(_pb("rectangle"), sensor="width", max_actions=2))
    bad = {"action": {"type": "fling", "alpha_rad": 0.0}, "branches": []}
    doc["root"]["branches"][0]["next"] = bad
    with pytest.raises(SimulationError, match=r"root\.branches\[0\]\.next: unknown action"):
        read_policy_document(doc)


# --- the noisy linear evaluation is the one evaluator's ---------------------------------


@pytest.mark.parametrize("name", PARTS)
@pytest.mark.parametrize("noise", list(NOISES))
def test_evaluate_plan_is_the_planners_propagation(name: str, noise: str) -> None:
    """evaluate_plan (by evaluate_tree) against the planner's batched propagation."""
    pb, model = _pb(name), NOISES[noise]
    rng = np.random.default_rng(7)
    ev = PlanEvaluator(pb, model, None)
    for k in (1, 2, 3):
        for _ in range(4):
            angles = rng.uniform(-math.pi, math.pi, k).tolist()
            steps = [PlanStep("squeeze", a) for a in angles]
            got = evaluate_plan(pb, model, steps)
            want = ev.forward(["squeeze"] * k, angles)[-1]
            assert_allclose(got.distribution, want, rtol=1e-12, atol=1e-15)
            # the value aimed at (a tie between symmetric states may go either way)
            assert_allclose(got.expected_payoff, float(ev.value(want)), rtol=1e-12)


# --- the noisy policy's candidate turns --------------------------------------------------


@pytest.mark.parametrize("name", PARTS)
@pytest.mark.parametrize("noise", ["contact 0.3", "uniform 2 + contact 0.1"])
def test_each_candidate_turn_is_one_action_once(name: str, noise: str) -> None:
    """No two candidates share a matrix, and no matrix of the raw candidates is lost."""
    pb = _pb(name)
    space = StateSpace.build(pb)
    sensor = parse_sensor("width")
    model = noisy_model.NoisyModel(space, sensor, NOISES[noise])
    for k in make_solver(space, sensor, DEFAULT_PRUNE).kinds:
        mid, _ = model.candidates(k.name, np.asarray(k.mid), np.asarray(k.half_width))
        mats = model.matrices(k.name, mid)
        kept = mats[noisy_model.first_of_each_matrix(mats)]
        flat = {m.tobytes() for m in kept}
        assert len(flat) == len(kept)
        turns = np.mod(mid, 2 * math.pi)
        gaps = np.abs(turns[:, None] - turns[None, :])
        gaps = np.minimum(gaps, 2 * math.pi - gaps) + np.eye(len(mid))
        assert gaps.min() > 1e-9  # no turn twice (pi and -pi are one turn)
        # the raw set: the noise-free middles and a fine grid of turns; each matrix is kept
        # (the grid shifted off the round turns, which may put a state on a boundary)
        grid = np.linspace(-math.pi, math.pi, 721) + 1e-3 * math.sqrt(2)
        probe = np.concatenate([np.asarray(k.mid), grid])
        for m in model.matrices(k.name, probe):
            if NOISES[noise].turn.exact:
                assert m.tobytes() in flat or any(np.allclose(m, x, atol=1e-12) for x in kept)
