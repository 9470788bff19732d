"""``plan_document_json``: the text of ``json.dumps(plan_document(...))``, byte for byte.

The batch writes each plan document from the result's values (issue 12); every case here
compares it with the encoder's text of the same document, on study polygons, catalogue and
random parts, every option of the problem and planner, guaranteed plans, shared memos, and
the values that send it to the general path (curved parts, non-finite numbers, other types).
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.io import plans as plans_module
from bayesgrasp.io import resolve_part
from bayesgrasp.io.plans import plan_document, plan_document_json
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.goal import Goal
from bayesgrasp.model.prior import parse_prior
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import plan_bfs, plan_exact
from bayesgrasp.planning.guaranteed import plan_guaranteed
from bayesgrasp.shapes import names


def dumps(result: Any, memo: dict[str, Any] | None = None, **kw: Any) -> str:
    return json.dumps(plan_document(result, memo=memo, **kw), allow_nan=False)


def same(result: Any, **kw: Any) -> None:
    assert plan_document_json(result, **kw) == dumps(result, **kw)


def test_the_study_polygons_with_one_memo() -> None:
    rng = np.random.default_rng(1)
    inputs = {"max_actions": None, "format": None}
    memo: dict[str, Any] = {}
    general = 0
    for _ in range(200):
        res = plan_exact(Problem.build(random_polygon(rng)))
        assert plan_document_json(res, inputs=inputs, memo=memo) == dumps(res, inputs=inputs)
        general += plans_module._document_text(res, None, None, inputs, memo) is None
    assert "provenance_text" in memo  # the shared text was used
    # The template, not its fallback, writes them all (a float below 1e-4 too).
    assert general == 0


PROBLEMS = [
    {},
    {"prior": parse_prior("vonmises:30,4")},
    {"goal": Goal("symmetry")},
    {"actions": ("squeeze", "push-grasp"), "cost": CostModel({"push-grasp": 0.7})},
    {"actions": ("push-grasp",)},
    {"accuracy": math.radians(3.0)},
    {"cost": CostModel({"squeeze": 2.0}, 0.5, {"squeeze": 3.0}, 0.25)},
]


@pytest.mark.parametrize("kw", PROBLEMS, ids=range(len(PROBLEMS)))
@pytest.mark.parametrize("name", names())
def test_catalogue_parts_under_every_problem_option(name: str, kw: dict[str, Any]) -> None:
    pb = Problem.build(resolve_part(name), **kw)
    res = plan_exact(pb)
    same(res)
    same(plan_exact(pb, report="best"), inputs={"max_actions": 3, "com": None})
    found = plan_guaranteed(pb)
    if found.status == "ok":
        same(res, guaranteed=found)
    else:
        same(res, guaranteed_missing=str(found.reason))


def test_breadth_first_results_write_their_nodes() -> None:
    res = plan_bfs(Problem.build(resolve_part("house")))
    assert res.nodes is not None
    same(res)
    same(res.best_only())


@pytest.mark.parametrize(
    "name", ['a "quoted" name', "été\nnext", "\u2603 snow", "nan", "infinite part", ""]
)
def test_names_and_units_are_escaped_as_the_encoder(name: str) -> None:
    part = Part.from_points([(0, 0), (3, 0), (3, 1.5), (0, 2)], name=name, units="µm")
    same(plan_exact(Problem.build(part)))


def test_shared_memo_keeps_each_documents_provenance() -> None:
    """Documents of different problems share one memo: each gets its own provenance."""
    part = resolve_part("key")
    memo: dict[str, Any] = {}
    for kw in [*PROBLEMS, PROBLEMS[0]]:
        res = plan_exact(Problem.build(part, **kw))
        for inputs in ({"max_actions": 2}, {"max_actions": 2}, None):
            text = plan_document_json(res, inputs=inputs, memo=memo)
            assert text == dumps(res, inputs=inputs)


def test_a_curved_part_takes_the_general_path() -> None:
    from pathlib import Path

    lever = Path(__file__).resolve().parents[2] / "examples" / "lever.svg"
    part = resolve_part(str(lever))
    assert type(part) is not Part
    same(plan_exact(Problem.build(part)))


def _with_option(res: Any, **changes: Any) -> Any:
    opts = list(res.options)
    opts[res.bayes] = dataclasses.replace(opts[res.bayes], **changes)
    return dataclasses.replace(res, options=tuple(opts))


def test_other_value_types_are_written_as_the_encoder_writes_them() -> None:
    res = plan_exact(Problem.build(resolve_part("house")))
    cases = [
        _with_option(res, success_probability=np.float64(0.25)),  # a float subclass
        _with_option(res, success_probability=1),  # an int: the general path
        _with_option(res, final_orientation=True),  # a bool: the general path
        _with_option(res, expected_cost=math.inf, tolerance=math.nan),  # null, null
        dataclasses.replace(res, nodes=17),
        dataclasses.replace(res, most_certain=True),  # a bool index: the general path
        dataclasses.replace(res, nodes=True),
        _with_option(res, final_orientation=-0.0),  # not the text of 0.0
        _with_option(res, final_orientation=np.float64(res.problem.states.stable[1])),
        _with_option(res, final_orientation=int(res.problem.states.stable[1])),
    ]
    for case in cases:
        same(case)


def test_non_finite_numbers_fail_as_the_encoder_fails() -> None:
    res = plan_exact(Problem.build(resolve_part("house")))
    for bad in (math.nan, math.inf, -math.inf):
        case = _with_option(res, success_probability=bad)
        with pytest.raises(ValueError, match="Out of range float values"):
            dumps(case)
        with pytest.raises(ValueError, match="Out of range float values"):
            plan_document_json(case)


def test_the_template_is_taken_for_plain_parts(monkeypatch: pytest.MonkeyPatch) -> None:
    """The comparisons above test the template, not only its fallback."""
    res = plan_exact(Problem.build(resolve_part("house")))
    expected = dumps(res)

    def refuse(*args: Any, **kw: Any) -> Any:
        raise AssertionError("the general path was taken")

    monkeypatch.setattr(plans_module, "plan_document", refuse)
    assert plan_document_json(res) == expected
    with pytest.raises(AssertionError):  # and the fallback does call it
        plan_document_json(_with_option(res, success_probability=1))


_coordinate = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


@settings(max_examples=150, deadline=None)
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
    same(plan_exact(pb))


def test_stable_orientations_held_as_arrays_or_floats() -> None:
    """The template writes the states' own floats; the general path their array's tolist()."""
    from bayesgrasp.geometry.transfer import TransferFunction

    for made in ("arrays", "float64 scalars"):
        res = plan_exact(Problem.build(resolve_part("house")))
        pb, f = res.problem, res.problem.states
        cols = [f.stable.copy(), f.basin_lo.copy(), f.basin_hi.copy()]
        if made != "arrays":
            cols = [[np.float64(x) for x in c] for c in cols]
        other = TransferFunction(f.kind, *cols, period=f.period, angle_tol=f.angle_tol)
        assert (other._values is None) == (made == "arrays")
        object.__setattr__(pb, "states", other)  # the same values, held another way
        assert pb.states is other
        expected = dumps(res)
        assert plan_document_json(res) == expected
        assert '"stable_orientations_rad": [' + ", ".join(map(repr, f.values[0])) in expected


# Floats of every kind orjson might spell otherwise than repr: tiny, huge, subnormal, the
# exponent boundaries 1e-4 and 1e16, zeros of both signs, and the non-finite values.
_any_float = st.one_of(
    st.floats(),
    st.floats(-1e-3, 1e-3),
    st.floats(-1e17, 1e17),
    st.sampled_from([1e-4, 9.999999999999999e-05, 1e-05, 5e-324, 1e16, 9999999999999998.0, -0.0]),
)


@settings(max_examples=500, deadline=None)
@given(values=st.lists(_any_float, max_size=12))
def test_orjson_float_text_is_repr(values: list[float]) -> None:
    """The float texts the template writes by orjson are each float's repr, as json.dumps.

    Or ``None`` (the general path), only for a value that is not finite. (A value orjson
    may spell otherwise, with an exponent in its repr, below 1e-4 or from 1e16 on, or four
    zeros after a point as 10.00001, has every text written by repr.)
    """
    texts = plans_module._float_texts(values)
    if texts is not None:
        assert texts == [repr(x) for x in values]
    else:
        assert not all(map(math.isfinite, values))


def test_orjson_spellings_unlike_repr_are_written_by_repr() -> None:
    values = [1e-05, 0.5, 1e16, 10.00001, 1.5e-300, -2e-5]
    assert plans_module._float_texts(values) == [repr(x) for x in values]
    assert plans_module._float_texts([0.5, math.nan]) is None
    assert plans_module._float_texts([math.inf, 1e-05]) is None


def test_float_texts_refuse_what_float_repr_refuses() -> None:
    """A value that is not a float sends the document to the general path."""
    for values in ([0.5, 1], [True], [None], [0.5, "0.5"], [np.float64(0.1), 0.2]):
        assert plans_module._float_texts(values) is None
    assert plans_module._float_texts([0.1, 0.2, 0.0, -0.0]) == ["0.1", "0.2", "0.0", "-0.0"]
    assert plans_module._float_texts([]) == []
