"""The sensing study (paper/sensing.py): each mean is the planners' own, in the right order."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.model import Problem
from bayesgrasp.model.actions import PUSH_GRASP, SQUEEZE
from bayesgrasp.model.sensing import WidthSensor
from bayesgrasp.paper.sensing import run_sensing_study, sensing_columns, sensing_json
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning.exact import plan_exact
from bayesgrasp.planning.policy import plan_policy


def test_means_are_the_planners_and_ordered() -> None:
    res = run_sensing_study(polygons=6, seed=3, max_actions=2, parts=["rectangle"])
    rng = np.random.default_rng(3)
    polys = [random_polygon(rng) for _ in range(6)]
    for name, acts in (
        ("squeezes", (SQUEEZE,)),
        ("squeezes and push-grasps", (SQUEEZE, PUSH_GRASP)),
    ):
        pbs = [Problem.build(p, actions=acts) for p in polys]
        none = np.mean([plan_exact(pb, max_actions=2).bayes_plan.expected_cost for pb in pbs])
        five = np.mean(
            [
                plan_policy(
                    pb, WidthSensor(0.05 * pb.widths.max(), 0.025 * pb.widths.max()), 2
                ).expected_cost
                for pb in pbs
            ]
        )
        row = res.polygon_cost[name]
        assert row["none"] == pytest.approx(none, rel=1e-12)
        assert row["SIGMA 5%"] == pytest.approx(five, rel=1e-12)
        # More information never costs more: exact <= 1% <= 5% <= none (within rounding).
        assert (
            row["exact"] <= row["SIGMA 1%"] + 1e-9 <= row["SIGMA 5%"] + 2e-9 <= row["none"] + 3e-9
        )
    # Random polygons have distinct widths (apart from the pi pairs): exact readings with
    # squeezes give (1 + verify) / 0.5 = 4.
    assert res.polygon_cost["squeezes"]["exact"] == pytest.approx(4.0, abs=1e-9)
    assert res.parts["rectangle"]["squeezes"]["exact"] == pytest.approx(4.0, abs=1e-9)
    doc = json.loads(json.dumps(sensing_json(res)))
    assert doc["schema"] == "bayesgrasp.sensing-study/1"


def test_columns_from_a_given_sensor() -> None:
    cols = sensing_columns("width:0.02,0.01")
    assert [c.kind for c in cols] == ["none", "exact", "relative"]
    assert cols[2].sigma == 0.02 and cols[2].resolution == 0.01


def test_cli_study_sense(capsys: pytest.CaptureFixture[str]) -> None:
    assert (
        main(
            [
                "study",
                "--sense",
                "width:0.05,0.025",
                "--polygons",
                "2",
                "--max-actions",
                "1",
                "--json",
            ]
        )
        == 0
    )
    doc = json.loads(capsys.readouterr().out)
    assert [c["label"] for c in doc["columns"]] == ["none", "exact", "SIGMA 5%, RES 2.5%"]
    assert set(doc["parts"]) >= {"triangle", "house", "key"}
    assert main(["study", "--sense", "width:-1,1", "--polygons", "2"]) == 2
    assert "sigma" in capsys.readouterr().err


def test_a_malformed_study_sensor_is_worded_in_relative_units(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["study", "--sense", "width:1", "--polygons", "2"]) == 2
    err = capsys.readouterr().err
    assert "fractions of each part's largest diameter" in err and "part units" not in err
    assert err.count("\n") == 1
