"""``plan --sense`` and ``simulate --sense`` with noisy actions (--turn-noise, --contact-noise)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning.noisy_policy import plan_noisy_policy
from bayesgrasp.shapes import load

SENSE = ["--sense", "width:0.5,0.25", "--max-actions", "2"]


def test_plan_json_equals_the_library(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["plan", "house", *SENSE, "--turn-noise", "normal:2", "--contact-noise", "0.1"]
    assert main([*argv, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    noise = NoiseModel(TurnNoise("normal", math.radians(2)), 0.1)
    pol = plan_noisy_policy(Problem.build(load("house")), "width:0.5,0.25", 2, noise)
    assert doc["schema"] == "bayesgrasp.policy/1"
    turn = {"kind": "normal", "scale_rad": math.radians(2)}
    assert doc["noise"] == {"turn": turn, "contact": 0.1}
    assert_allclose(doc["expected_cost"], pol.expected_cost, rtol=1e-12)
    assert_allclose(doc["refinement_bound"], pol.refinement_bound, rtol=1e-12)
    assert doc["expected_cost"] <= doc["sensorless_cost"]
    # the text tells the same figures and the noise
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert f"expected cost {pol.expected_cost:.4f}" in out
    assert "noise: turn error normal:2 deg, contact asynchrony q=0.1" in out


def test_plan_without_noise_has_no_noise_field(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", "house", *SENSE, "--json"]) == 0
    assert "noise" not in json.loads(capsys.readouterr().out)


def test_simulate_replays_the_noisy_policy(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["simulate", "house", *SENSE, "--turn-noise", "normal:3", "--trials", "40000"]
    assert main([*argv, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["agrees"] is True
    assert doc["noise"]["turn"] == {"kind": "normal", "scale_rad": math.radians(3)}
    noise = NoiseModel(TurnNoise("normal", math.radians(3)))
    pol = plan_noisy_policy(Problem.build(load("house")), "width:0.5,0.25", 2, noise)
    assert_allclose(doc["expected_cost"]["predicted"], pol.expected_cost, rtol=1e-12)
    assert main(argv) == 0
    assert "planned and predicted under turn error normal:3 deg" in capsys.readouterr().out


def test_plan_sense_with_a_payoff(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "u.csv"
    f.write_text("orientation_deg,value\n0,1\n46.99,0.5\n")
    argv = ["plan", "house", *SENSE, "--payoff", str(f), "--turn-noise", "uniform:2"]
    assert main([*argv, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    u = [1.0, 0.5] + [0.0] * 6
    assert doc["payoff"] == u
    noise = NoiseModel(TurnNoise("uniform", math.radians(2)))
    pol = plan_noisy_policy(Problem.build(load("house")), "width:0.5,0.25", 2, noise, payoff=u)
    assert_allclose(doc["expected_cost"], pol.expected_cost, rtol=1e-12)
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "stop, verify (expected payoff" in out and "per unit payoff" in out
    assert (
        main(["plan", "house", "--sense", "width", "--also", "triangle", "--payoff", str(f)]) == 2
    )
    assert "a payoff is for one part" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["plan", "house", "--sense", "width", "--payoff", "x.json"], "x.json"),
        (["plan", "house", "--sense", "width", "--turn-noise", "normal:x"], "normal:SIGMA_DEG"),
        (["plan", "house", "--sense", "width", "--turn-noise", "normal:1", "--guaranteed"],
         "takes no --guaranteed"),
        (["simulate", "house", "--sense", "width", "--turn-noise", "normal:1", "--noise", "1"],
         "not both"),
    ],
)  # fmt: skip
def test_bad_input(argv: list[str], match: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert match in err and len(err.strip().splitlines()) == 1
