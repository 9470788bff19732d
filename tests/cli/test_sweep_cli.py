"""``bayesgrasp sweep``: the command runs a sweep, refuses to overwrite, writes a report."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from bayesgrasp.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.dask
def test_sweep_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    parts = tmp_path / "parts"
    parts.mkdir()
    shutil.copy(EXAMPLES / "peanut.svg", parts)
    (parts / "bad.json").write_text("{not json", encoding="utf-8")
    out = tmp_path / "rows.csv"
    argv = ["sweep", str(parts), "--out", str(out), "--format", "csv", "--workers", "1"]
    assert main([*argv, "--report", str(tmp_path / "r.html"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["schema"], doc["found"], doc["written"], doc["ok"], doc["errors"]) == (
        "bayesgrasp.sweep/1",
        2,
        2,
        1,
        1,
    )
    assert (tmp_path / "r.html").read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    before = out.read_bytes()
    assert main(argv) == 2
    assert "exists; resume it (--resume) or replace it (--force)" in capsys.readouterr().err
    assert out.read_bytes() == before  # nothing the user had is lost
    assert main([*argv, "--resume", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["skipped"] == 2
    # resumed with another seed, trial count or option: refused with the reason, rows kept
    for extra, reason in (
        (["--seed", "3"], "seed 0 -> 3"),
        (["--simulate", "kinematic", "--trials", "500"], "trials None -> 500"),
        (["--verify-cost", "2"], "verify_cost 1.0 -> 2.0"),
    ):
        assert main([*argv, "--resume", *extra]) == 2
        err = capsys.readouterr().err
        assert "cannot resume" in err and reason in err and "Traceback" not in err
    assert out.read_bytes() == before


def test_outputs_never_land_where_the_sweep_reads_parts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Results or a report inside a swept folder would be read as parts by the next sweep;
    one named like a part file would replace it; a missing PATH is not an empty sweep."""
    parts = tmp_path / "parts"
    parts.mkdir()
    (parts / "a.csv").write_text("0,0\n3,0\n0,2\n", encoding="utf-8")
    for argv in (
        ["--out", str(parts / "rows.csv")],
        ["--out", str(parts / "a.csv"), "--force"],
        ["--out", str(tmp_path / "rows.csv"), "--report", str(parts / "r.html")],
    ):
        assert main(["sweep", str(parts), *argv]) == 2
        err = capsys.readouterr().err
        assert "input" in err and "write it elsewhere" in err and len(err.splitlines()) == 1
    assert main(["sweep", str(parts / "*.csv"), "--out", str(parts / "a.csv"), "--force"]) == 2
    assert "is an input of this sweep" in capsys.readouterr().err
    assert sorted(p.name for p in parts.iterdir()) == ["a.csv"]
    assert main(["sweep", str(tmp_path / "missing"), "--out", str(tmp_path / "r.csv")]) == 2
    assert "no such file or folder" in capsys.readouterr().err
