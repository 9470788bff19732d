"""Mixed action sets (squeezes and push-grasps): exact planner vs breadth-first search,
execution of the plans, and the 180-degree ambiguity that only push-grasps break."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import CostModel, Problem
from bayesgrasp.planning import execute_plan, plan_exact
from bayesgrasp.planning.bfs import search_bfs
from bayesgrasp.planning.guaranteed import widest_arc
from bayesgrasp.planning.result import PlanOption

TWO_PI = 2.0 * math.pi
MIXED = ("squeeze", "push-grasp")
GRID = np.linspace(0.0, TWO_PI, 20001)[:-1] + 1.234e-5  # initial world orientations


def random_parts(rng: np.random.Generator, count: int) -> list[Part]:
    """The seed's random polygons: the hull of 10 uniform points in the unit square."""
    return [Part.from_points(rng.random((10, 2))) for _ in range(count)]


def landed(pb: Problem, o: PlanOption, theta: np.ndarray = GRID) -> float:
    """Fraction of initial orientations the plan sends to its final orientation."""
    out = execute_plan(pb, o.steps, theta)
    d = np.abs(np.mod(out - o.final_orientation + math.pi, TWO_PI) - math.pi)
    return float(np.mean(d < 1e-9))


@pytest.mark.slow
@pytest.mark.parametrize("push_cost", [1.0, 2.0])
def test_exact_agrees_with_breadth_first(rng: np.random.Generator, push_cost: float) -> None:
    """Best plan of every length up to 4 actions, exhaustive search (no node limit).

    The breadth-first search stops at the most certain plan; when action types cost
    differently the exact planner may list one more, cheaper plan after it (checked against
    every sequence of action types in :func:`test_every_sequence_of_kinds`).
    """
    depth = 4
    complete = extra = 0
    for part in random_parts(rng, 100):
        pb = Problem.build(part, cost=CostModel({"push-grasp": push_cost}), actions=MIXED)
        exact = plan_exact(pb, max_actions=depth)
        res = search_bfs(pb, max_actions=depth, node_limit=10**7, tree_count=False)
        assert res.stats.completed and res.stats.fallback_nodes == 0
        bfs = res.report
        shared = exact.options[: exact.most_certain + 1]
        assert len(shared) == len(bfs.options)
        for e, b in zip(shared, bfs.options, strict=True):
            assert e.n_actions == b.n_actions
            assert e.success_probability == pytest.approx(b.success_probability, abs=1e-9)
            assert e.expected_cost == pytest.approx(b.expected_cost, rel=1e-9)
        assert exact.most_certain == bfs.most_certain
        if len(exact.options) == len(shared):
            assert exact.bayes == bfs.bayes
        else:
            extra += 1
            assert len(exact.options) == len(shared) + 1
            assert exact.bayes == len(shared)
            assert exact.bayes_plan.expected_cost < bfs.bayes_plan.expected_cost
        complete += exact.most_certain_plan.success_probability > 1 - 1e-12
    # Most of the comparisons cover every plan up to the most certain one.
    assert complete >= 75
    if push_cost == 1.0:  # equal costs: the most certain plan is the cheapest of its length
        assert extra == 0


def sequence_costs(pb: Problem, n_max: int) -> dict[tuple[str, ...], tuple[float, float]]:
    """(success probability, expected cost) of every sequence of action types up to n_max.

    Uniform prior, single goal: p = L / (2 pi), with L by backchaining the widest arcs of
    each sequence in its own order (guaranteed.widest_arc, checked against every pair of
    boundaries in test_guaranteed; not the exact planner's count vectors and best orders).
    """
    tol = pb.states.angle_tol
    cap = min(max(pb.transfers[t].period for t in pb.action_kinds), TWO_PI)
    widths: dict[tuple[str, ...], float] = {(): 0.0}
    out = {}
    for n in range(1, n_max + 1):
        for seq in itertools.product(pb.action_kinds, repeat=n):
            widths[seq] = widest_arc(pb.transfers[seq[0]], widths[seq[1:]], tol).width
            p = min(widths[seq], cap) / TWO_PI
            out[seq] = (p, pb.cost.expected_cost(seq, p))
    return out


@pytest.mark.parametrize("push_cost", [2.0, 5.0])
def test_every_sequence_of_kinds(rng: np.random.Generator, push_cost: float) -> None:
    """Each option against all sequences of its length; the Bayes plan against all
    sequences up to three actions longer than the most certain plan."""
    extra = 0
    for part in random_parts(rng, 60):
        pb = Problem.build(part, cost=CostModel({"push-grasp": push_cost}), actions=MIXED)
        rep = plan_exact(pb)
        mc = rep.most_certain
        seqs = sequence_costs(pb, rep.most_certain_plan.n_actions + 3)
        for i, o in enumerate(rep.options[:mc]):  # below the most certain: least cost
            same = [c for s, (_, c) in seqs.items() if len(s) == i + 1]
            assert o.n_actions == i + 1
            assert o.expected_cost == pytest.approx(min(same), rel=1e-9)
        top = [v for s, v in seqs.items() if len(s) == mc + 1]
        p_max = max(p for p, _ in top)
        o = rep.most_certain_plan
        assert o.success_probability == pytest.approx(p_max, abs=1e-9)
        assert o.expected_cost == pytest.approx(
            min(c for p, c in top if p >= p_max - 1e-9), rel=1e-9
        )
        assert rep.bayes_plan.expected_cost == pytest.approx(
            min(c for _, c in seqs.values()), rel=1e-9
        )
        assert pb.cost.expected_cost(rep.bayes_plan.kinds, rep.bayes_plan.success_probability) == (
            pytest.approx(rep.bayes_plan.expected_cost, rel=1e-12)
        )
        extra += len(rep.options) > mc + 1
    assert extra > 0  # the case this test is for does occur


@pytest.mark.parametrize("push_cost", [1.0, 2.0])
def test_exact_plans_do_what_they_claim(rng: np.random.Generator, push_cost: float) -> None:
    for part in random_parts(rng, 40):
        pb = Problem.build(part, cost=CostModel({"push-grasp": push_cost}), actions=MIXED)
        for o in plan_exact(pb).options:
            assert landed(pb, o) == pytest.approx(o.success_probability, abs=2.0 / len(GRID))
            attempt = pb.cost.attempt_cost(o.kinds)
            assert o.expected_cost == pytest.approx(attempt / o.success_probability, rel=1e-12)


def test_push_grasps_orient_asymmetric_parts_squeezes_stay_at_half(
    rng: np.random.Generator,
) -> None:
    theta = rng.uniform(0.0, TWO_PI, 3000)
    for part in random_parts(rng, 100):
        assert part.hull.symmetry_order == 1
        mixed = Problem.build(part, actions=MIXED)
        sure = plan_exact(mixed).most_certain_plan
        assert sure.success_probability == pytest.approx(1.0, abs=1e-12)
        assert landed(mixed, sure, theta) == 1.0
        squeeze = Problem.build(part)
        best = plan_exact(squeeze).most_certain_plan
        assert best.success_probability == pytest.approx(0.5, abs=1e-12)
        assert landed(squeeze, best, theta) == pytest.approx(0.5, abs=0.05)
        # Push-grasps alone orient the part too (period 2 pi).
        only = plan_exact(Problem.build(part, actions=("push-grasp",))).most_certain_plan
        assert only.success_probability == pytest.approx(1.0, abs=1e-12)
        assert set(only.kinds) == {"push-grasp"}


def test_mixed_never_worse_than_either_kind_alone(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 60):
        for push_cost in (1.0, 2.0, 5.0):
            cost = CostModel({"push-grasp": push_cost})
            mixed = plan_exact(Problem.build(part, cost=cost, actions=MIXED))
            alone = [
                plan_exact(Problem.build(part, cost=cost, actions=(k,)))
                for k in ("squeeze", "push-grasp")
            ]
            best_alone = min(r.bayes_plan.expected_cost for r in alone)
            assert mixed.bayes_plan.expected_cost <= best_alone * (1 + 1e-12)


def test_steps_name_their_kind_and_json_has_them(rng: np.random.Generator) -> None:
    from bayesgrasp.report import plan_json

    part = random_parts(rng, 1)[0]
    rep = plan_exact(Problem.build(part, actions=MIXED))
    doc = plan_json(rep, schema="bayesgrasp.plan/2")
    assert doc["schema"] == "bayesgrasp.plan/2"
    for o, d in zip(rep.options, doc["options"], strict=True):
        assert [s["type"] for s in d["steps"]] == list(o.kinds)
        assert_allclose([s["alpha_rad"] for s in d["steps"]], [s.alpha for s in o.steps])
        assert len(d["steps"]) == o.n_actions


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    from bayesgrasp.cli import main

    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_actions_and_push_grasp_cost(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from bayesgrasp.shapes import load

    args = ("plan", "triangle", "--actions", "squeeze,push-grasp", "--push-grasp-cost", "2")
    code, out, err = run(capsys, *args, "--json")
    assert code == 0 and err == ""
    doc = json.loads(out)
    assert doc["schema"] == "bayesgrasp.plan/2"
    rep = plan_exact(
        Problem.build(load("triangle"), cost=CostModel({"push-grasp": 2.0}), actions=MIXED)
    )
    assert [o["expected_cost"] for o in doc["options"]] == pytest.approx(
        [o.expected_cost for o in rep.options]
    )
    assert [[s["type"] for s in o["steps"]] for o in doc["options"]] == [
        list(o.kinds) for o in rep.options
    ]
    assert (doc["bayes"], doc["most_certain"]) == (rep.bayes, rep.most_certain)
    code, out, err = run(capsys, *args)
    assert code == 0 and " P(" in out


@pytest.mark.parametrize(
    ("actions", "message"),
    [("squeeze,pull", "unknown action 'pull'"), (",", "at least one action type")],
)
def test_cli_bad_actions(capsys: pytest.CaptureFixture[str], actions: str, message: str) -> None:
    code, out, err = run(capsys, "plan", "triangle", "--actions", actions)
    assert code == 2 and out == ""
    assert message in err and len(err.strip().splitlines()) == 1


def test_cli_negative_push_grasp_cost(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plan", "triangle", "--push-grasp-cost", "-1")
    assert code == 2 and out == "" and "push-grasp-cost" in err
