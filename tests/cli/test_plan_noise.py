"""``plan --turn-noise / --contact-noise / --payoff`` and ``simulate --turn-noise``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning.noisy import plan_noisy
from bayesgrasp.shapes import load


def test_plan_json_equals_the_library(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["plan", "key", "--turn-noise", "normal:2", "--contact-noise", "0.1", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    noise = NoiseModel(TurnNoise("normal", math.radians(2)), 0.1)
    res = plan_noisy(Problem.build(load("key")), noise)
    assert doc["method"] == "noisy"
    assert doc["noise"] == {
        "turn": {"kind": "normal", "scale_rad": math.radians(2)},
        "contact": 0.1,
    }
    assert doc["bayes"] == res.bayes
    bayes = res.bayes_plan
    assert_allclose(
        doc["expected_cost_per_unit_payoff"], bayes.evaluation.expected_cost, rtol=1e-12
    )
    assert_allclose(doc["expected_payoff"], bayes.expected_payoff, rtol=1e-12)
    assert doc["payoff"] is None
    assert len(doc["noisy_options"]) == len(doc["options"])


def test_plan_with_a_payoff_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "u.csv"
    f.write_text("orientation_deg,value\n80.63,1\n260.63,0.5\n")
    assert main(["plan", "key", "--payoff", str(f), "--turn-noise", "uniform:1"]) == 0
    out = capsys.readouterr().out
    assert "E[cost] is per unit payoff" in out and "E[payoff]" in out
    assert main(["plan", "key", "--payoff", str(f), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["payoff"][1] == 1.0 and doc["payoff"][5] == 0.5
    assert doc["expected_payoff"] <= 1.0


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--turn-noise", "normal:x"], "must be normal:SIGMA_DEG or uniform:A_DEG"),
        (["--turn-noise", "normal:50"], "scale"),
        (["--contact-noise", "1.5"], "contact-noise"),
        (["--turn-noise", "normal:1", "--method", "bfs"], "drop --method"),
        (["--turn-noise", "normal:1", "--guaranteed"], "do not take noise"),
        (["--payoff", "missing.csv"], "no such file"),
    ],
)
def test_bad_options_exit_2(
    argv: list[str], match: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", "key", *argv]) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_simulate_takes_the_turn_noise(capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        main(["simulate", "key", "--turn-noise", "uniform:2", "--trials", "20000", "--json"]) == 0
    )
    doc = json.loads(capsys.readouterr().out)
    assert doc["trials"] == 20000
    assert main(["simulate", "key", "--turn-noise", "uniform:2", "--noise", "1"]) == 2
    assert "not both" in capsys.readouterr().err


def test_simulate_turn_noise_predicts_under_the_noise(capsys: pytest.CaptureFixture[str]) -> None:
    """The plan is the noise-aware Bayes plan; the predicted column its exact evaluation."""
    from bayesgrasp.planning import plan_exact
    from bayesgrasp.planning.noisy import evaluate_plan
    from bayesgrasp.sim.stats import wilson_interval

    argv = ["simulate", "key", "--turn-noise", "uniform:2", "--trials", "40000", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    pb = Problem.build(load("key"))
    noise = NoiseModel(TurnNoise("uniform", math.radians(2)))
    plan = plan_noisy(pb, noise).bayes_plan.option
    assert [s["alpha_rad"] for s in doc["plan"]["steps"]] == [s.alpha for s in plan.steps]
    ev = evaluate_plan(pb, noise, plan.steps)
    assert_allclose(doc["predicted_success"], ev.success_probability, atol=1e-12)
    noise_free = plan_exact(pb).bayes_plan.success_probability
    assert abs(ev.success_probability - noise_free) > 0.05  # not the noise-free claim
    lo, hi = wilson_interval(round(doc["observed_success"] * 40000), 40000, confidence=0.999)
    assert lo <= doc["predicted_success"] <= hi
    assert_allclose(sum(r["predicted"] for r in doc["per_orientation"]), 1.0, atol=1e-9)
    assert main(["simulate", "key", "--turn-noise", "uniform:2", "--trials", "1000"]) == 0
    assert "predicted under turn error uniform:2 deg" in capsys.readouterr().out
