"""Payoffs (model/payoff.py): files, validation, and what they do to the Bayes plan.

- A payoff of 1 on the state today's Bayes plan ends in, 0 elsewhere, gives today's plan: the
  same probability and expected cost, with or without noise.
- A payoff that favours another state moves the chosen final orientation there, and the
  cost per unit payoff is then below that of today's plan under the same payoff.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from bayesgrasp import shapes
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.payoff import Payoff, PayoffError, read_payoff
from bayesgrasp.model.problem import Problem
from bayesgrasp.model.states import nearest_state
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.noisy import evaluate_plan, plan_noisy

DEG = math.pi / 180
NOISES = [NoiseModel(), NoiseModel(TurnNoise("normal", 2 * DEG))]


def _state(pb: Problem, theta: float) -> int:
    return int(nearest_state(pb.states, np.array([theta]))[0])


@pytest.mark.parametrize("name", shapes.names())
def test_payoff_one_on_the_goal_state_is_todays_goal(name: str) -> None:
    pb = Problem.build(shapes.load(name))
    exact = plan_exact(pb)
    bayes = exact.bayes_plan
    res = plan_noisy(pb, NoiseModel(), Payoff.one_state(bayes.final_orientation))
    got = res.bayes_plan.option
    assert got.success_probability == pytest.approx(bayes.success_probability, abs=1e-12)
    assert got.expected_cost == pytest.approx(bayes.expected_cost, rel=1e-12)
    assert got.final_orientation == pytest.approx(bayes.final_orientation, abs=1e-12)


@pytest.mark.parametrize("noise", NOISES, ids=lambda n: n.describe())
@pytest.mark.parametrize("name", ["key", "house", "tuning-fork"])
def test_evaluation_with_the_one_state_payoff_is_the_goals(name: str, noise: NoiseModel) -> None:
    pb = Problem.build(shapes.load(name))
    for o in plan_exact(pb).options:
        goal = evaluate_plan(pb, noise, o.steps)
        u = np.zeros(pb.n_states)
        u[goal.final_state] = 1.0
        pay = evaluate_plan(pb, noise, o.steps, u)
        assert pay.expected_payoff == pytest.approx(goal.success_probability, abs=1e-15)
        assert pay.expected_cost == pytest.approx(goal.expected_cost, rel=1e-12)


@pytest.mark.parametrize("noise", NOISES, ids=lambda n: n.describe())
@pytest.mark.parametrize("name", ["key", "example", "house"])
def test_a_payoff_favouring_a_state_moves_the_final_orientation(
    name: str, noise: NoiseModel
) -> None:
    pb = Problem.build(shapes.load(name))
    today = plan_exact(pb).bayes_plan
    j0 = _state(pb, today.final_orientation)
    half = _state(pb, today.final_orientation + math.pi)
    # The best other state a single squeeze reaches (not the goal nor its pi copy).
    mass = pb.state_distribution(0.0)
    mass[[j0, half]] = -1.0
    j1 = int(np.argmax(mass))
    u = np.zeros(pb.n_states)
    u[j0], u[j1] = 0.1, 1.0
    res = plan_noisy(pb, noise, u)
    chosen = res.bayes_plan
    assert _state(pb, chosen.option.final_orientation) == j1
    before = evaluate_plan(pb, noise, today.steps, u)
    assert chosen.evaluation.expected_cost < before.expected_cost
    assert res.payoff is not None and res.payoff.tolist() == u.tolist()


def test_read_json_and_csv(tmp_path: Path) -> None:
    pb = Problem.build(shapes.load("key"))
    s = np.degrees(pb.states.stable)
    a, b = float(s[1]), float(s[5])
    (tmp_path / "u.json").write_text(
        json.dumps({"payoff": {f"{a:.2f}": 1.0, f"{b:.2f}": 0.5}, "default": 0.1})
    )
    (tmp_path / "l.json").write_text(
        json.dumps(
            {"payoff": [{"orientation_deg": a, "value": 1}, {"orientation_deg": b, "value": 0.5}]}
        )
    )
    (tmp_path / "u.csv").write_text(f"orientation_deg,value\n{a:.3f},1\n{b:.3f},0.5\n")
    (tmp_path / "n.csv").write_text(f"{a},1\n\n{b},0.5\n")
    want = np.zeros(pb.n_states)
    want[1], want[5] = 1.0, 0.5
    for f in ["l.json", "u.csv", "n.csv"]:
        np.testing.assert_array_equal(read_payoff(tmp_path / f).vector(pb.states), want)
    with_default = read_payoff(tmp_path / "u.json").vector(pb.states)
    np.testing.assert_array_equal(with_default, np.where(want > 0, want, 0.1))
    assert read_payoff(tmp_path / "u.json").to_json(pb.states)["state_values"][1] == 1.0


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("a.json", "{", "not valid JSON"),
        ("a.json", "[1, 2]", "'payoff' member"),
        ("a.json", '{"payoff": {"x": 1}}', "orientation in degrees"),
        ("a.json", '{"payoff": {"0": 1.5}}', r"in \[0, 1\]"),
        ("a.json", '{"payoff": {"0": true}}', "must be a number"),
        ("a.json", '{"payoff": {"0": 0}}', "positive somewhere"),
        ("a.json", '{"payoff": {"0": 1}, "scale": 2}', "unknown member"),
        ("a.json", '{"payoff": [{"deg": 0, "value": 1}]}', "entry #1"),
        ("a.json", '{"payoff": 3}', "object or a list"),
        ("a.csv", "orientation_deg,value\n0,1,2\n", "line 1"),
        ("a.csv", "orientation_deg,value\n", "no orientation"),
        ("a.csv", "0,-0.5\n", r"in \[0, 1\]"),
        ("a.txt", "0,1\n", r"\.json or \.csv"),
    ],
)
def test_bad_files_are_refused(tmp_path: Path, name: str, text: str, match: str) -> None:
    (tmp_path / name).write_text(text)
    with pytest.raises(PayoffError, match=match):
        read_payoff(tmp_path / name)


def test_orientations_must_be_states(tmp_path: Path) -> None:
    pb = Problem.build(shapes.load("key"))
    with pytest.raises(PayoffError, match="not a stable orientation"):
        Payoff(np.array([0.5]), np.array([1.0])).vector(pb.states)
    s = float(pb.states.stable[2])
    with pytest.raises(PayoffError, match="twice"):
        Payoff(np.array([s, s + 1e-5]), np.array([1.0, 0.5])).vector(pb.states)
    with pytest.raises(PayoffError, match="no such file"):
        read_payoff(tmp_path / "missing.json")
    with pytest.raises(PayoffError, match="needs 8 values"):
        plan_noisy(pb, NoiseModel(), np.ones(3))


@pytest.mark.parametrize(
    ("name", "body", "match"),
    [
        ("big.json", '{"payoff": {"80.63": 1' + "0" * 400 + "}}", "401 digits .* beyond"),
        ("deep.json", "[" * 100_000 + "]" * 100_000, "nested deeper than the limit"),
        ("field.csv", "orientation_deg,value\n80.63," + "1" * 200_000, "not valid CSV"),
        ("latin.csv", "orientation_deg,value\n80.63,1 \xe9\n", "not UTF-8"),
        ("empty.json", "  \n", "the file is empty"),
    ],
)
def test_bad_payoff_files_are_one_clear_error(
    tmp_path: Path, name: str, body: str, match: str
) -> None:
    p = tmp_path / name
    p.write_bytes(body.encode("latin-1"))
    with pytest.raises(PayoffError, match=match) as info:
        read_payoff(p)
    assert "\n" not in str(info.value)


def test_a_fifo_payoff_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    with pytest.raises(PayoffError, match="FIFO"):
        read_payoff(fifo)
