"""The HTML report of a results file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("pyarrow")
pytest.importorskip("matplotlib")

from bayesgrasp.sweep import SweepOptions, plan_part, write_report
from bayesgrasp.sweep.report import disagreements, report_html
from bayesgrasp.sweep.results import open_results


def test_report_has_every_section(tmp_path: Path) -> None:
    options = SweepOptions(simulate="kinematic", trials=2000, seed=1)
    rows = []
    for i in range(6):
        f = tmp_path / f"p{i}.json"
        f.write_text(json.dumps({"vertices": [[0, 0], [3 + i, 0], [1, 2 + i % 3]]}))
        rows.append(plan_part(str(f), options))
    rows[0] = {**rows[0], "sim_observed": 0.01, "sim_ci_low": 0.0, "sim_ci_high": 0.02}
    rows.append(plan_part(str(tmp_path / "missing.json"), options))
    out = tmp_path / "r.parquet"
    open_results(out, options).write(rows)
    page = tmp_path / "report.html"
    write_report(out, page)
    text = page.read_text()
    for heading in (
        "Summary",
        "Bayes plans",
        "Predicted against observed success",
        "Parts where the kinematic simulation misses the prediction",
        "Every part",
        "Parts that failed",
    ):
        assert f"<h2>{heading}</h2>" in text
    # a kinematic mismatch is not called physics
    assert "physics disagrees" not in text and "kinematic mismatch" in text
    assert "<table class='sortable'>" in text and "querySelectorAll('table.sortable th')" in text
    assert text.count("<svg") >= 4  # two histograms, the scatter, one outline
    assert "missing.json: no such file" in text
    assert disagreements(rows)[0]["path"] == rows[0]["path"]


def test_report_without_simulation_or_rows() -> None:
    text = report_html([])
    assert "<h2>Summary</h2>" in text and "<svg" not in text


def test_parts_table_gives_each_part_its_interval_and_verdict() -> None:
    base = {"status": "ok", "sides": 4, "states": 4, "bayes_actions": 1, "bayes_cost": 1.0,
            "bayes_probability": 0.5, "sim_engine": "mujoco", "sim_trials": 100,
            "sim_p_value": 0.5, "sim_jams": 3, "outline": "[[0,0],[1,0],[0,1]]"}  # fmt: skip
    rows = [
        {**base, "path": "good.json", "sim_predicted": 0.5, "sim_observed": 0.48,
         "sim_ci_low": 0.38, "sim_ci_high": 0.58},
        {**base, "path": "jams.json", "sim_predicted": 0.5, "sim_observed": 0.2,
         "sim_ci_low": 0.13, "sim_ci_high": 0.29},
    ]  # fmt: skip
    text = report_html(rows)
    table = text[text.index("<h2>Every part</h2>") :]
    assert "[0.38, 0.58]" in table and "agrees" in table and "observed below" in table
    assert "<h2>Parts where physics disagrees with the model</h2>" in text
    assert "physics disagrees (predicted outside the observed 95% interval)" in text
