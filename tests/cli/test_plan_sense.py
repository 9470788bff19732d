"""``plan --sense``: policies from the command line equal the library's."""

from __future__ import annotations

import json

import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning.policy import plan_policy
from bayesgrasp.shapes import load


def test_plan_sense_json_equals_the_library(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", "house", "--sense", "width", "--max-actions", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    pol = plan_policy([Problem.build(load("house"))], sensor="width", max_actions=2)
    assert doc["schema"] == "bayesgrasp.policy/1"
    assert doc["parts"] == ["house"]
    assert_allclose(doc["expected_cost"], pol.expected_cost, rtol=1e-12)
    assert doc["expected_cost"] < doc["sensorless_cost"]


def test_plan_sense_recognition_and_text(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["plan", "rectangle", "--also", "ic-chip", "--sense", "width", "--part-prior", "1,3"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "declare part 'ic-chip'" in out and "declare part 'rectangle'" in out
    assert "expected cost" in out


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--sense", "width:1"], "sensor must be written `width` or `width:SIGMA,RES`"),
        (["--sense", "width:-1,1"], "sensor `sigma` must be >= 0; got -1.0"),
        (["--sense", "width", "--part-prior", "1,2,3"], "part prior"),
        (["--also", "triangle"], "--also and --part-prior need --sense"),
    ],
)
def test_plan_sense_bad_input(
    argv: list[str], match: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", "house", *argv]) == 2
    err = capsys.readouterr().err
    assert match in err and len(err.strip().splitlines()) == 1
