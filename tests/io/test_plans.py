"""Plan documents (bayesgrasp.io.plans): written and read back, plan/1 and plan/2, errors."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from bayesgrasp import Goal, PlanOption, PlanStep, Problem, plan_exact, plan_guaranteed
from bayesgrasp.errors import SimulationError
from bayesgrasp.io.plans import (
    PLAN_SCHEMA_1,
    PLAN_SCHEMA_2,
    PLAN_SCHEMAS,
    guaranteed_document,
    option_document,
    plan_document,
    plan_schema,
    read_plan_document,
)
from bayesgrasp.model.actions import ACTIONS
from bayesgrasp.shapes import load

MIXED = ("squeeze", "push-grasp")
PROBLEMS = [
    ("triangle", {}),
    ("house", {"actions": MIXED}),
    ("key", {"accuracy": math.radians(2)}),
    ("rectangle", {"goal": Goal("symmetry")}),
    ("house", {"actions": ("push-grasp",)}),
]


def through_json(doc: dict[str, Any]) -> Any:
    """What a reader of the printed document gets (strict JSON: no NaN)."""
    return json.loads(json.dumps(doc, allow_nan=False))


def same_plan(back: PlanOption, o: PlanOption) -> None:
    assert back.steps == o.steps  # exact: JSON keeps every float
    assert back.final_orientation == o.final_orientation
    assert back.success_probability == o.success_probability
    assert back.expected_cost == o.expected_cost
    assert back.tolerance == o.tolerance


@pytest.mark.parametrize(("name", "kw"), PROBLEMS, ids=[f"{n}-{k}" for n, k in PROBLEMS])
def test_every_option_round_trips(name: str, kw: dict[str, Any]) -> None:
    rep = plan_exact(Problem.build(load(name), **kw))
    for o in rep.options:
        same_plan(read_plan_document(through_json(option_document(o))), o)
    doc = through_json(plan_document(rep))
    same_plan(read_plan_document(doc), rep.bayes_plan)
    same_plan(read_plan_document(doc, "most-certain"), rep.most_certain_plan)


@pytest.mark.parametrize(("name", "kw"), PROBLEMS, ids=[f"{n}-{k}" for n, k in PROBLEMS])
def test_schema_follows_the_actions(name: str, kw: dict[str, Any]) -> None:
    pb = Problem.build(load(name), **kw)
    squeezes_only = pb.action_kinds == ("squeeze",)
    assert plan_schema(pb) == (PLAN_SCHEMA_1 if squeezes_only else PLAN_SCHEMA_2)
    assert plan_schema(pb, guaranteed=True) == PLAN_SCHEMA_2
    assert plan_document(plan_exact(pb))["schema"] == plan_schema(pb)


@pytest.mark.parametrize("actions", [("squeeze",), MIXED])
def test_guaranteed_plan_round_trips(actions: tuple[str, ...]) -> None:
    pb = Problem.build(load("house"), actions=actions)
    rep, sure = plan_exact(pb), plan_guaranteed(pb)
    doc = through_json(plan_document(rep, guaranteed=sure))
    assert doc["schema"] == PLAN_SCHEMA_2
    assert doc["guaranteed"] == through_json(guaranteed_document(sure))
    assert doc["guaranteed"]["period_rad"] == sure.period
    same_plan(read_plan_document(doc, "guaranteed"), sure.option)
    same_plan(read_plan_document(doc), rep.bayes_plan)


def test_missing_guaranteed_plan_is_written_with_its_reason() -> None:
    rep = plan_exact(Problem.build(load("triangle")))
    doc = plan_document(rep, guaranteed_missing="none honours the accuracy")
    assert doc["schema"] == PLAN_SCHEMA_2
    assert doc["guaranteed"] is None and doc["guaranteed_missing"] == "none honours the accuracy"
    with pytest.raises(SimulationError, match="holds no guaranteed plan"):
        read_plan_document(doc, "guaranteed")


def test_plan_1_documents_without_steps_are_read() -> None:
    """plan/1 as first written: options of first_squeeze_rad and actions_rad only."""
    rep = plan_exact(Problem.build(load("triangle")))
    doc = through_json(plan_document(rep))
    assert doc["schema"] == PLAN_SCHEMA_1
    for option in doc["options"]:
        del option["steps"]
    same_plan(read_plan_document(doc), rep.bayes_plan)
    legacy = {"first_squeeze_rad": 0.1, "actions_rad": [0.5], "final_orientation_rad": 1.0}
    back = read_plan_document(legacy)
    assert back.steps == (PlanStep("squeeze", 0.1), PlanStep("squeeze", 0.5))
    assert math.isnan(back.success_probability) and back.tolerance is None


def test_plan_2_document_with_push_grasps_is_read() -> None:
    rep = plan_exact(Problem.build(load("house"), actions=MIXED))
    doc = through_json(plan_document(rep))
    assert doc["schema"] == PLAN_SCHEMA_2
    back = read_plan_document(doc)
    assert "push-grasp" in back.kinds
    same_plan(back, rep.bayes_plan)


def test_files_are_read(tmp_path: Path) -> None:
    rep = plan_exact(Problem.build(load("house"), actions=MIXED))
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(plan_document(rep)), encoding="utf-8")
    same_plan(read_plan_document(path), rep.bayes_plan)
    same_plan(read_plan_document(str(path), "most-certain"), rep.most_certain_plan)


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        ([1, 2], "a plan must be a JSON object; got list"),
        ({"schema": "bayesgrasp.simulate/1", "plan": {}}, "needs `steps` or `first_squeeze_rad`"),
        ({"schema": "bayesgrasp.plan/3", "options": []}, "expected one of bayesgrasp.plan/1"),
        ({"options": [], "bayes": 0}, "needs `options` and a valid `bayes` index"),
        ({"options": [{}, {}], "bayes": True}, "valid `bayes` index"),
        ({"options": [{}], "most_certain": 0, "bayes": 0}, "a plan needs `steps`"),
        ({"x": 1}, "a plan needs `steps` or `first_squeeze_rad`"),
        ({"steps": []}, "`steps` must be a non-empty list"),
        ({"steps": [{"type": "squeeze"}]}, r"step 1 must be .* got \{'type': 'squeeze'\}"),
        ({"steps": [{"type": "teleport", "alpha_rad": 0}]}, '"squeeze" | "push-grasp"'),
        ({"steps": [{"type": ["squeeze"], "alpha_rad": 0}]}, "step 1 must be"),
        ({"steps": [{"alpha_rad": True}]}, "step 1 must be"),
        ({"steps": [{"alpha_rad": 0.0}]}, "finite `final_orientation_rad`"),
        ({"first_squeeze_rad": "a", "final_orientation_rad": 0}, "must be numbers"),
        ({"first_squeeze_rad": 1e999, "final_orientation_rad": 0}, "angles must be finite"),
    ],
)
def test_bad_documents(doc: Any, message: str) -> None:
    with pytest.raises(SimulationError, match=message):
        read_plan_document(doc)


def test_bad_which_and_bad_files(tmp_path: Path) -> None:
    doc = plan_document(plan_exact(Problem.build(load("triangle"))))
    with pytest.raises(SimulationError, match="`which` must be bayes, most-certain or guaranteed"):
        read_plan_document(doc, "cheapest")
    with pytest.raises(SimulationError, match=r"plan file '.*missing\.json' cannot be read"):
        read_plan_document(tmp_path / "missing.json")
    broken = tmp_path / "broken.json"
    broken.write_text('{"steps": [', encoding="utf-8")
    with pytest.raises(SimulationError, match=r"broken\.json': not valid JSON"):
        read_plan_document(broken)
    binary = tmp_path / "binary.json"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(SimulationError, match="not UTF-8"):
        read_plan_document(binary)
    empty = tmp_path / "empty-plan.json"
    empty.write_text('{"x": 1}', encoding="utf-8")
    with pytest.raises(SimulationError, match=r"empty-plan\.json': a plan needs `steps`"):
        read_plan_document(empty)


def test_every_schema_written_is_readable() -> None:
    assert PLAN_SCHEMAS == (PLAN_SCHEMA_1, PLAN_SCHEMA_2)


angles = st.floats(-10.0, 10.0, allow_nan=False)


@given(
    steps=st.lists(st.tuples(st.sampled_from(sorted(ACTIONS)), angles), min_size=1, max_size=8),
    final=st.floats(0.0, 2 * math.pi, allow_nan=False, exclude_max=True),
    p=st.floats(0.0, 1.0),
    cost=st.floats(0.0, 1e6) | st.just(math.inf),
    tol=st.none() | st.floats(0.0, 1.0),
)
def test_any_option_round_trips(
    steps: list[tuple[str, float]], final: float, p: float, cost: float, tol: float | None
) -> None:
    o = PlanOption(tuple(PlanStep(k, a) for k, a in steps), final, p, cost, tol, (0.0, 1.0))
    back = read_plan_document(through_json(option_document(o)))
    assert back.steps == o.steps and back.final_orientation == final
    assert back.success_probability == p and back.tolerance == tol
    assert back.expected_cost == cost or (math.isinf(cost) and math.isnan(back.expected_cost))


def test_a_memo_shares_the_provenance_only_of_alike_problems() -> None:
    """``memo`` (plan --batch): the same document, the provenance made once per run of alike
    problems; another prior, goal, accuracy or inputs makes a new one."""
    from bayesgrasp.model.cost import CostModel
    from bayesgrasp.model.prior import UniformPrior, von_mises

    shared = {"prior": UniformPrior(), "cost": CostModel(), "goal": Goal()}
    inputs = {"max_actions": None, "format": "json"}
    other = {**inputs, "format": None}
    runs = [
        ("triangle", shared, inputs),
        ("key", shared, inputs),  # alike: shared
        ("key", {**shared, "prior": von_mises(0.3, 2.0)}, inputs),
        ("key", {**shared, "prior": von_mises(0.3, 2.0)}, inputs),  # an equal, new prior
        ("key", {**shared, "goal": Goal("symmetry")}, inputs),
        ("key", {**shared, "accuracy": 0.01}, inputs),
        ("key", {**shared, "actions": MIXED}, inputs),
        ("key", shared, other),
        ("house", shared, other),
    ]
    memo: dict[str, Any] = {}
    seen: list[object] = []
    for name, kw, extra in runs:
        result = plan_exact(Problem.build(load(name), **kw))
        doc = plan_document(result, inputs=extra, memo=memo)
        assert doc == plan_document(result, inputs=extra)
        seen.append(doc["provenance"])
    shared_with_previous = [a is b for a, b in itertools.pairwise(seen)]
    assert shared_with_previous == [True, False, False, False, False, False, False, True]
