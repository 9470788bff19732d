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
        "Parts where physics disagrees with the model",
        "Parts that failed",
    ):
        assert f"<h2>{heading}</h2>" in text
    assert text.count("<svg") >= 4  # two histograms, the scatter, one outline
    assert "missing.json: no such file" in text
    assert disagreements(rows)[0]["path"] == rows[0]["path"]


def test_report_without_simulation_or_rows() -> None:
    text = report_html([])
    assert "<h2>Summary</h2>" in text and "<svg" not in text
