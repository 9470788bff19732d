"""Sweeps with --sense: each row's policy columns are what ``plan PART --sense --json`` prints."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.model.sensing import SensorError
from bayesgrasp.sweep import SweepError, SweepOptions, plan_part

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def cli_policy(capsys: pytest.CaptureFixture[str], *args: str) -> dict:
    capsys.readouterr()
    assert main(["plan", *args, "--json"]) == 0
    return dict(json.loads(capsys.readouterr().out))


@pytest.mark.parametrize(
    ("options", "args"),
    [
        (SweepOptions(sense="width"), ["--sense", "width"]),
        (
            SweepOptions(sense="width:0.5,0.25", sense_max_actions=2, verify_cost=2.0),
            ["--sense", "width:0.5,0.25", "--max-actions", "2", "--verify-cost", "2.0"],
        ),
        (
            SweepOptions(sense="width:0.5,0.25", accuracy_deg=5.0),
            ["--sense", "width:0.5,0.25", "--accuracy", "5.0"],
        ),
        (
            SweepOptions(sense="width", actions=("squeeze", "push-grasp")),
            ["--sense", "width", "--actions", "squeeze,push-grasp"],
        ),
    ],
)
def test_policy_columns_equal_the_cli(
    make_catalogue: Callable[[Path, np.random.Generator, int], list[str]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    options: SweepOptions,
    args: list[str],
) -> None:
    files = make_catalogue(tmp_path / "c", np.random.default_rng(5), 3)
    for f in [f for f in files if "broken" not in Path(f).parts]:
        row = plan_part(f, options)
        assert row["status"] == "ok", row["error_message"]
        doc = cli_policy(capsys, f, *args)
        assert json.loads(row["policy_json"]) == doc
        assert (row["policy_cost"], row["policy_success"], row["policy_actions"]) == (
            doc["expected_cost"],
            doc["success_probability"],
            doc["expected_actions"],
        )
        # a policy may ignore what it reads: it never costs more than the row's best
        # sensorless plan within its depth
        plans = json.loads(row["plan_json"])["options"]
        depth = options.sense_max_actions
        best = min(o["expected_cost"] for o in plans if o["squeezes"] <= depth)
        assert row["policy_cost"] <= best * (1 + 1e-12)


def test_without_sense_there_are_no_policy_columns_and_the_key_is_unchanged(
    tmp_path: Path,
) -> None:
    f = tmp_path / "tri.json"
    f.write_text(json.dumps({"vertices": [[0, 0], [3, 0], [0, 2]]}))
    row = plan_part(str(f), SweepOptions())
    assert row["policy_cost"] is None and row["policy_json"] is None
    assert "sense" not in SweepOptions().to_json()  # old sweeps' keys still resume
    o = SweepOptions(sense="width:0.1,0.05", sense_max_actions=2)
    assert SweepOptions.from_json(json.loads(json.dumps(o.to_json()))) == o
    assert o.key != SweepOptions().key


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"sense": "width:1"}, SensorError, "width:SIGMA,RES"),
        ({"sense": "width:-1,1"}, SensorError, "sigma"),
        ({"sense": "width", "sense_max_actions": 0}, SweepError, "sense_max_actions"),
    ],
)
def test_bad_sense_options_are_refused(kwargs: dict, error: type, match: str) -> None:
    with pytest.raises(error, match=match):
        SweepOptions(**kwargs)


@pytest.mark.dask
def test_sweep_command_with_sense(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from bayesgrasp.sweep import read_results

    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(EXAMPLES / "plate.geojson", parts)
    out = tmp_path / "rows.csv"
    argv = ["sweep", str(parts), "--out", str(out), "--format", "csv", "--workers", "1"]
    report = tmp_path / "r.html"
    sense = ["--sense", "width:0.5,0.25", "--max-actions", "2"]
    assert main([*argv, *sense, "--report", str(report), "--json"]) == 0
    assert "sensing policy cost: mean" in report.read_text(encoding="utf-8")
    (row,) = read_results(out)
    doc = cli_policy(
        capsys, str(parts / "plate.geojson"), "--sense", "width:0.5,0.25", "--max-actions", "2"
    )
    assert row["policy_cost"] == doc["expected_cost"]
    assert main([*argv, "--sense", "width:1", "--force"]) == 2
    assert "width:SIGMA,RES" in capsys.readouterr().err


@pytest.mark.dask
def test_sweep_command_passes_the_part_file_options(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from bayesgrasp.sweep import read_results

    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(EXAMPLES / "bracket.dxf", parts)
    out = tmp_path / "rows.csv"
    given = ["--shape-tol", "0.2", "--flatten-tol", "0.05"]
    argv = ["sweep", str(parts), "--out", str(out), "--format", "csv", "--workers", "1", *given]
    assert main([*argv, "--json"]) == 0
    (row,) = read_results(out)
    capsys.readouterr()
    assert main(["plan", str(parts / "bracket.dxf"), *given, "--guaranteed", "--json"]) in (0, 1)
    cli = json.loads(capsys.readouterr().out)
    assert json.loads(row["plan_json"])["options"] == cli["options"]
    assert json.loads(row["plan_json"])["part"] == cli["part"]
