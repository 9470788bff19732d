"""Plan documents as written: the schema's fields in its order, their values, their text.

``plan_document`` builds every document (``plan --json``, each line of ``plan --batch``, the
web service); ``plan_document_json`` is its one-line text, ``json.dumps`` of it. The
checks here: the fields and their order as the module's schema lists them, every value
against the planner's result (the probabilities against numpy's), the text as
``json.dumps`` writes it (``repr`` of each float, ASCII escapes), and NaN refused.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.io import plans as plans_module
from bayesgrasp.io import resolve_part
from bayesgrasp.io.plans import plan_document, plan_document_json, read_plan
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.goal import Goal
from bayesgrasp.model.prior import parse_prior
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import plan_bfs, plan_exact
from bayesgrasp.planning.guaranteed import plan_guaranteed
from bayesgrasp.shapes import names

# The schema, written down again: the fields in the order documents hold them.
TOP = [
    "schema",
    "part",
    "method",
    "stable_orientations_rad",
    "stable_probabilities",
    "period_rad",
    "first_squeeze_rad",
    "options",
    "bayes",
    "most_certain",
    "nodes",
    "accuracy_rad",
    "guaranteed",
    "guaranteed_missing",
    "provenance",
]
PART = ["name", "vertices", "n_sides", "symmetry_order", "units", "center_of_mass", "id", "curved"]
OPTION = [
    "squeezes",
    "actions_rad",
    "steps",
    "first_squeeze_rad",
    "final_orientation_rad",
    "success_probability",
    "expected_cost",
    "tolerance_rad",
]
OPTIONAL = {"nodes", "accuracy_rad", "guaranteed", "guaranteed_missing", "units", "curved"}
LEVER = Path(__file__).resolve().parents[2] / "examples" / "lever.svg"

PROBLEMS = [
    {},
    {"prior": parse_prior("vonmises:30,4")},
    {"goal": Goal("symmetry")},
    {"actions": ("squeeze", "push-grasp"), "cost": CostModel({"push-grasp": 0.7})},
    {"actions": ("push-grasp",)},
    {"accuracy": math.radians(3.0)},
    {"cost": CostModel({"squeeze": 2.0}, 0.5, {"squeeze": 3.0}, 0.25)},
]


def in_order(keys: list[str], schema: list[str]) -> None:
    """``keys`` are the schema's, in its order, with every field that is not optional."""
    assert keys == [k for k in schema if k in keys]
    assert {k for k in schema if k not in keys} <= OPTIONAL


def check(doc: dict[str, Any], result: Any, **kw: Any) -> None:
    """The document's fields in the schema's order, its values the result's.

    ``kw``: what the document was made with (its text is made with them again).
    """
    pb = result.problem
    in_order(list(doc), TOP)
    in_order(list(doc["part"]), PART)
    for option in doc["options"]:
        in_order(list(option), OPTION)
    assert ("nodes" in doc) == (result.nodes is not None)
    assert ("accuracy_rad" in doc) == (pb.accuracy > 0)
    assert doc["schema"] == plans_module.plan_schema(pb, "guaranteed" in doc)
    assert doc["method"] == result.method
    assert doc["stable_orientations_rad"] == list(pb.states.stable)
    first = result.bayes_plan.steps[0]
    # numpy's distribution, the probabilities' reference (the writer may take a faster path)
    assert doc["stable_probabilities"] == list(pb.state_distribution(first.alpha, first.kind))
    assert_allclose(sum(doc["stable_probabilities"]), 1.0, atol=1e-12)
    assert doc["first_squeeze_rad"] == first.alpha
    assert (doc["bayes"], doc["most_certain"]) == (result.bayes, result.most_certain)
    assert len(doc["options"]) == len(result.options)
    for written, option in zip(doc["options"], result.options, strict=True):
        assert [(s["type"], s["alpha_rad"]) for s in written["steps"]] == [
            (s.kind, s.alpha) for s in option.steps
        ]
        assert written["squeezes"] == len(option.steps)
        assert written["actions_rad"] == [s.alpha for s in option.steps[1:]]
        assert written["success_probability"] == option.success_probability
        assert written["final_orientation_rad"] == option.final_orientation
        cost = option.expected_cost
        assert written["expected_cost"] == (cost if math.isfinite(cost) else None)
    part = doc["part"]
    assert part["vertices"] == pb.part.hull.vertices.tolist()
    assert part["id"] == plans_module.part_id(pb.part)
    assert plans_module.same_part(part, pb.part)
    # the text: json.dumps of the document, which reads back to the same values
    text = plan_document_json(result, **kw)
    assert "\n" not in text and text.isascii()
    assert json.loads(text) == json.loads(json.dumps(doc))
    assert read_plan(json.loads(text)).option.steps == result.bayes_plan.steps


@pytest.mark.parametrize("kw", PROBLEMS, ids=range(len(PROBLEMS)))
@pytest.mark.parametrize("name", names())
def test_catalogue_parts_under_every_problem_option(name: str, kw: dict[str, Any]) -> None:
    pb = Problem.build(resolve_part(name), **kw)
    res = plan_exact(pb)
    check(plan_document(res), res)
    best = plan_exact(pb, report="best")
    check(plan_document(best, inputs={"max_actions": 3}), best, inputs={"max_actions": 3})
    found = plan_guaranteed(pb)
    if found.status == "ok":
        asked: dict[str, Any] = {"guaranteed": found}
        doc = plan_document(res, **asked)
        assert doc["guaranteed"]["period_rad"] == found.period
        assert list(doc["guaranteed"]) == [*OPTION, "period_rad"]
    else:
        asked = {"guaranteed_missing": str(found.reason)}
        doc = plan_document(res, **asked)
        assert doc["guaranteed"] is None and doc["guaranteed_missing"] == str(found.reason)
    check(doc, res, **asked)
    assert doc["schema"] == plans_module.PLAN_SCHEMA_2


def test_the_study_polygons_with_one_memo() -> None:
    """The batch's documents: one memo shares the provenance, each document as alone."""
    rng = np.random.default_rng(1)
    inputs = {"max_actions": None, "format": None}
    memo: dict[str, Any] = {}
    for _ in range(100):
        res = plan_exact(Problem.build(random_polygon(rng)))
        text = plan_document_json(res, inputs=inputs, memo=memo)
        assert text == json.dumps(plan_document(res, inputs=inputs), allow_nan=False)
        check(json.loads(text), res, inputs=inputs)


def test_breadth_first_results_write_their_nodes() -> None:
    res = plan_bfs(Problem.build(resolve_part("house")))
    assert res.nodes is not None
    check(plan_document(res), res)
    assert plan_document(res)["nodes"] == res.nodes
    check(plan_document(res.best_only()), res.best_only())


def test_a_curved_part_writes_its_curved_member() -> None:
    part = resolve_part(str(LEVER))
    assert type(part) is not Part
    res = plan_exact(Problem.build(part))
    doc = plan_document(res)
    check(doc, res)
    assert doc["part"]["curved"]["curve_error"] == part.curve_error
    assert doc["provenance"]["flatten_tolerance"] == part.curve_error


@pytest.mark.parametrize(
    "name", ['a "quoted" name', "été\nnext", "\u2603 snow", "nan", "infinite part", ""]
)
def test_names_and_units_are_escaped(name: str) -> None:
    part = Part.from_points([(0, 0), (3, 0), (3, 1.5), (0, 2)], name=name, units="Å")
    res = plan_exact(Problem.build(part))
    text = plan_document_json(res)
    assert text.isascii() and "\n" not in text
    back = json.loads(text)
    assert (back["part"]["name"], back["part"]["units"]) == (name, "Å")
    check(back, res)


def test_floats_are_written_as_their_repr() -> None:
    """The shortest text that reads back to each float, exponents as ``repr``'s (1e-05)."""
    pts = [(0.0, 0.0), (1e-5, 0.0), (1e-5, 3e-6), (0.0, 2e-6)]
    res = plan_exact(Problem.build(Part.from_points(pts)))
    text = plan_document_json(res)
    verts = ", ".join(f"[{x!r}, {y!r}]" for x, y in res.problem.part.hull.vertices.tolist())
    assert f'"vertices": [{verts}]' in text
    assert "1e-05" in text and "0.00001" not in text
    stable = ", ".join(map(repr, res.problem.states.stable.tolist()))
    assert f'"stable_orientations_rad": [{stable}]' in text


def _with_option(res: Any, **changes: Any) -> Any:
    opts = list(res.options)
    opts[res.bayes] = dataclasses.replace(opts[res.bayes], **changes)
    return dataclasses.replace(res, options=tuple(opts))


def test_missing_statistics_are_null_and_nan_is_refused() -> None:
    res = plan_exact(Problem.build(resolve_part("house")))
    doc = json.loads(plan_document_json(_with_option(res, expected_cost=math.inf, tolerance=None)))
    assert doc["options"][res.bayes]["expected_cost"] is None
    assert doc["options"][res.bayes]["tolerance_rad"] is None
    for bad in (math.nan, math.inf, -math.inf):
        case = _with_option(res, success_probability=bad)
        with pytest.raises(ValueError, match="Out of range float values"):
            plan_document_json(case)


def test_the_module_documents_every_field() -> None:
    """The schema in the module's docstring names every field a document may hold."""
    doc = plans_module.__doc__ or ""
    for key in [*TOP, *PART, *OPTION, "period_rad", "type", "alpha_rad"]:
        assert f'"{key}"' in doc, key


_coordinate = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


@settings(max_examples=100, deadline=None)
@given(
    pts=st.lists(st.tuples(_coordinate, _coordinate), min_size=3, max_size=12),
    kw=st.sampled_from(PROBLEMS),
)
def test_random_parts(pts: list[tuple[float, float]], kw: dict[str, Any]) -> None:
    from bayesgrasp.errors import BayesGraspError

    try:
        pb = Problem.build(Part.from_points(pts), **kw)
    except BayesGraspError:
        return
    res = plan_exact(pb)
    check(plan_document(res), res)
