"""Bad values given to the library raise a BayesGraspError that names them, never a bare
TypeError, AttributeError or OverflowError."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest

from bayesgrasp import shapes
from bayesgrasp.errors import BayesGraspError
from bayesgrasp.model import Problem
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.prior import DensityPrior, parse_prior, von_mises
from bayesgrasp.planning import plan_exact

KEY = Problem.build(shapes.load("key"))


def _flat(t: Any) -> Any:
    return 1.0 + 0.0 * t


CASES: list[tuple[str, Callable[[], object], str]] = [
    ("von_mises mean text", lambda: von_mises(mean="1", kappa=2.0), "`mean` must be a number"),  # type: ignore[arg-type]
    ("von_mises kappa None", lambda: von_mises(0.0, None), "`kappa` must be a number"),  # type: ignore[arg-type]
    ("density bins 1.5", lambda: DensityPrior(_flat, bins=1.5), "integer >= 1"),  # type: ignore[arg-type]
    ("density bins True", lambda: DensityPrior(_flat, bins=True), "integer >= 1"),
    ("prior nan", lambda: parse_prior(math.nan), "written as text"),  # type: ignore[arg-type]
    ("prior empty", lambda: parse_prior(""), "the prior is empty"),
    ("prior blank", lambda: parse_prior("  "), "the prior is empty"),
    ("max_actions text", lambda: plan_exact(KEY, max_actions="1"), "integer >= 1"),  # type: ignore[arg-type]
    ("max_actions 1.0", lambda: plan_exact(KEY, max_actions=1.0), "integer >= 1"),  # type: ignore[arg-type]
    ("cost 10**400", lambda: CostModel({"squeeze": 10**400}), "at most"),
    ("verify 10**400", lambda: CostModel(verify=10**400), "at most"),
    ("accuracy 10**400", lambda: Problem.build(shapes.load("key"), accuracy=10**400), "finite"),
]


@pytest.mark.parametrize(("what", "call", "match"), CASES, ids=[c[0] for c in CASES])
def test_bad_library_input_is_a_bayesgrasp_error(
    what: str, call: Callable[[], object], match: str
) -> None:
    with pytest.raises(BayesGraspError, match=match) as info:
        call()
    assert "\n" not in str(info.value)
