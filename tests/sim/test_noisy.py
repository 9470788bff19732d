"""sim/noisy.py (the Monte Carlo of the noise model) and MuJoCo runs with the turn error.

The Monte Carlo against the exact matrices is in tests/planning/test_noisy.py; here: its
plumbing, and (marked ``physics``) the noise-aware plan executed in MuJoCo with the turn
error injected through ``simulate --turn-noise``.
"""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.errors import SimulationError
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning.result import PlanStep
from bayesgrasp.shapes import load
from bayesgrasp.sim.noisy import simulate_noise

HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None


def test_counts_and_errors() -> None:
    pb = Problem.build(load("rectangle"))
    steps = [PlanStep("squeeze", 0.0), PlanStep("squeeze", math.pi / 4)]
    counts = simulate_noise(pb, NoiseModel(TurnNoise("normal", 0.05), 0.5), steps, 5000, 1)
    assert counts.sum() == 5000 and counts.shape == (pb.n_states,)
    same = simulate_noise(pb, NoiseModel(), steps, 5000, 1)
    # No noise: the rectangle's 2-squeeze plan sends half of the starts to each of 2 states.
    assert np.count_nonzero(same) == 2
    with pytest.raises(SimulationError, match="trials"):
        simulate_noise(pb, NoiseModel(), steps, 0)
    with pytest.raises(SimulationError):
        simulate_noise(pb, NoiseModel(), [PlanStep("push-grasp", 0.0)], 10)


@pytest.mark.physics
@pytest.mark.skipif(not HAVE_MUJOCO, reason="MuJoCo is not installed (extra `sim`)")
def test_noise_aware_plan_runs_in_mujoco_with_the_turn_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", "key", "--turn-noise", "normal:2", "--json"]) == 0
    plan = tmp_path / "p.json"
    plan.write_text(capsys.readouterr().out)
    argv = ["simulate", "key", "--engine", "mujoco", "--plan", str(plan)]
    assert main([*argv, "--turn-noise", "normal:2", "--trials", "6", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["trials"] == 6 and doc["engine"] == "mujoco"
    assert sum(r["count"] for r in doc["per_orientation"]) + doc["final_jams"] == 6
