"""Sweeps under turn noise, contact noise and a payoff: each row is ``plan PATH --turn-noise``."""

from __future__ import annotations

import json
import math
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from bayesgrasp.errors import PlanningError
from bayesgrasp.sweep import SweepError, SweepOptions, plan_part, read_results
from bayesgrasp.sweep.results import open_results
from bayesgrasp.sweep.tasks import ROW_COLUMNS, run_chunk

Check = Callable[[list[dict[str, Any]], list[str], SweepOptions], None]
CliRun = Callable[[list[str]], tuple[int, str, str]]
NOISY = [
    {"turn_noise": "normal:2"},
    {"turn_noise": "uniform:3", "contact_noise": 0.1},
    {"contact_noise": 0.2, "max_actions": 3},
    {"turn_noise": "normal:1", "prior": "vonmises:30,2", "retry_cost": 0.5},
]


def noisy(**kwargs: Any) -> SweepOptions:
    return SweepOptions(guaranteed=False, **kwargs)


@pytest.mark.parametrize("kwargs", NOISY)
def test_rows_equal_the_cli_noisy_plan(
    parts: list[str], rows_check: Check, kwargs: dict[str, Any]
) -> None:
    options = noisy(**kwargs)
    rows = run_chunk([*map(_source, parts)], options).rows
    rows_check(rows, parts, options)  # plan_json == `plan PATH --turn-noise ... --json`
    for r in rows:
        doc = json.loads(r["plan_json"])
        assert doc["method"] == r["method"] == "noisy"
        assert r["turn_noise"] == kwargs.get("turn_noise")
        assert r["contact_noise"] == kwargs.get("contact_noise")
        assert r["bayes_payoff"] == doc["expected_payoff"]
        assert r["guaranteed_actions"] is None


def _source(path: str) -> Any:
    from bayesgrasp.sweep import PartSource

    return PartSource(path)


def test_rows_with_a_payoff_file(
    parts: list[str], rows_check: Check, tmp_path: Path, cli_run: CliRun
) -> None:
    # the rectangle's stable orientations are 0, 90, 180, 270 deg
    u = tmp_path / "u.csv"
    u.write_text("orientation_deg,value\n0,1\n90,0.5\n")
    options = noisy(turn_noise="normal:2", payoff=str(u))
    (row,) = run_chunk([_source(parts[1])], options).rows
    rows_check([row], [parts[1]], options)
    doc = json.loads(row["plan_json"])
    assert doc["payoff"] == [1.0, 0.5, 0.0, 0.0]
    assert row["payoff"] == str(u)
    # a part without those orientations: the CLI's message, in an error row
    (bad,) = run_chunk([_source(parts[0])], options).rows
    rows_check([bad], [parts[0]], options)
    assert bad["status"] == "error" and "not a stable orientation" in bad["error_message"]
    assert bad["turn_noise"] == "normal:2"  # an error row records its noise too


def test_noise_keys_and_arguments() -> None:
    assert not any(k in SweepOptions().to_json() for k in ("turn_noise", "contact_noise"))
    # the key of a sweep without noise is the key it had before the noise options existed
    assert SweepOptions().key == "3e1599e3d94477b8"
    o = noisy(turn_noise="uniform:2", contact_noise=0.25, payoff="u.json")
    assert SweepOptions.from_json(json.loads(json.dumps(o.to_json()))) == o
    assert o.key != noisy(turn_noise="uniform:2", contact_noise=0.25).key
    assert o.plan_args()[-6:] == [
        "--turn-noise",
        "uniform:2",
        "--contact-noise",
        "0.25",
        "--payoff",
        "u.json",
    ]
    assert "--guaranteed" not in o.plan_args()


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"turn_noise": "gauss:1", "guaranteed": False}, PlanningError, "normal:SIGMA_DEG"),
        ({"contact_noise": 1.5, "guaranteed": False}, SweepError, "contact_noise"),
        ({"contact_noise": math.nan, "guaranteed": False}, SweepError, "contact_noise"),
        ({"turn_noise": "normal:1"}, SweepError, "`guaranteed`: no plan of two or more"),
        (
            {"turn_noise": "normal:1", "guaranteed": False, "method": "bfs"},
            SweepError,
            "seeds from the exact planner; drop method='bfs'",
        ),
        (
            {"contact_noise": 0.1, "guaranteed": False, "simulate": "mujoco"},
            SweepError,
            "`contact_noise` applies to simulate='kinematic' only",
        ),
        (
            {
                "turn_noise": "normal:1",
                "guaranteed": False,
                "simulate": "kinematic",
                "noise_deg": 1.0,
            },
            SweepError,
            "simulated under its own turn_noise",
        ),
    ],
)
def test_bad_noise_options_are_refused(kwargs: dict[str, Any], error: type, match: str) -> None:
    with pytest.raises(error, match=match):
        SweepOptions(**kwargs)


def test_missing_payoff_file_is_one_row_error(parts: list[str], tmp_path: Path) -> None:
    row = plan_part(parts[0], noisy(payoff=str(tmp_path / "none.json")))
    assert row["status"] == "error" and row["error_class"] == "PayoffError"
    assert row["error_message"].endswith("none.json: no such file")


# -- resume ----------------------------------------------------------------------------------

ROW = {"path": "a.json", "sha256": "00", "options_key": "k", "sides": 4}


@pytest.mark.parametrize("name", ["r.csv", "r.parquet"])
def test_resume_with_other_options_is_refused(tmp_path: Path, name: str) -> None:
    out = tmp_path / name
    open_results(out, SweepOptions()).write([ROW])
    open_results(out, SweepOptions(), resume=True)  # the same options: fine
    with pytest.raises(SweepError, match=r"cannot resume: .*turn_noise None -> 'normal:2'"):
        open_results(out, noisy(turn_noise="normal:2"), resume=True)
    with pytest.raises(SweepError, match=r"verify_cost 1\.0 -> 2\.0.*--force to replace"):
        open_results(out, SweepOptions(verify_cost=2.0), resume=True)
    open_results(out, SweepOptions(verify_cost=2.0), force=True)  # --force still replaces


def test_a_csv_written_before_the_noise_columns_still_resumes(tmp_path: Path) -> None:
    out = tmp_path / "old.csv"
    open_results(out, SweepOptions()).write([ROW])
    old = [name for name, _ in ROW_COLUMNS][:-4]  # the header before the noise columns
    lines = out.read_text().splitlines()
    out.write_text(",".join(old) + "\n" + ",".join(lines[1].split(",")[: len(old)]) + "\n")
    w = open_results(out, SweepOptions(), resume=True)
    w.write([{**ROW, "path": "b.json"}])
    rows = read_results(out)
    assert [r["path"] for r in rows] == ["a.json", "b.json"]
    assert out.read_text().splitlines()[0] == ",".join(old)


# -- the command -----------------------------------------------------------------------------


@pytest.mark.dask
def test_sweep_command_with_noise_equals_plan(
    parts: list[str], tmp_path: Path, cli_run: CliRun
) -> None:
    folder = tmp_path / "parts"
    folder.mkdir()
    for p in parts[:3]:
        shutil.copy(p, folder)
    out = tmp_path / "rows.csv"
    noise = ["--turn-noise", "normal:1.5", "--contact-noise", "0.05"]
    base = ["sweep", str(folder), "--out", str(out), "--workers", "1"]
    code, text, err = cli_run([*base, *noise, "--json"])
    assert code == 0, err
    assert json.loads(text)["ok"] == 3
    rows = read_results(out)  # a .csv path: CSV without --output-format
    for r in rows:
        code, doc, _ = cli_run(["plan", r["path"], *noise, "--json"])
        assert code == 0
        assert json.loads(r["plan_json"]) == json.loads(doc)
        assert (r["turn_noise"], r["contact_noise"]) == ("normal:1.5", 0.05)
    # resuming with the same options has nothing to do; with others it is refused
    code, text, _ = cli_run([*base, *noise, "--resume", "--json"])
    assert code == 0 and json.loads(text)["skipped"] == 3
    code, _, err = cli_run([*base, "--turn-noise", "normal:2", "--resume"])
    assert code == 2
    assert "cannot resume: its rows were planned with other options" in err
    assert "contact_noise 0.05 -> None; turn_noise 'normal:1.5' -> 'normal:2'" in err
    assert len(read_results(out)) == 3


@pytest.mark.dask
def test_local_cluster_sweep_with_a_payoff_equals_plan(
    parts: list[str], tmp_path: Path, rows_check: Check
) -> None:
    from bayesgrasp.sweep import run_sweep

    u = tmp_path / "u.json"
    u.write_text(json.dumps({"payoff": {"0": 1.0, "90": 0.25}, "default": 0.1}))
    options = noisy(turn_noise="uniform:2", payoff=str(u))
    out = tmp_path / "r.parquet"
    s = run_sweep([parts[1]], out, options, workers=1, send="bytes")
    assert s.ok == 1
    (row,) = read_results(out)
    rows_check([row], [parts[1]], options)
    assert json.loads(row["plan_json"])["payoff"] == [1.0, 0.25, 0.1, 0.1]
    assert (row["turn_noise"], row["payoff"]) == ("uniform:2", str(u))


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--turn-noise", "gauss:1"], "normal:SIGMA_DEG or uniform:A_DEG"),
        (["--contact-noise", "2"], "--contact-noise"),
        (["--turn-noise", "normal:1", "--guaranteed"], "no plan of two or more actions can"),
        (["--contact-noise", "0.1", "--method", "bfs"], "seeds from the exact planner"),
        (["--contact-noise", "0.1", "--simulate", "mujoco"], "the physics' own"),
        (["--payoff", "missing.json"], "missing.json: no such file"),
        (["--output-format", "csv", "--format", "parquet"], "give --output-format only"),
    ],
)
def test_sweep_command_refuses(
    parts: list[str],
    tmp_path: Path,
    cli_run: CliRun,
    monkeypatch: pytest.MonkeyPatch,
    extra: list[str],
    match: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = cli_run(["sweep", parts[0], "--out", "rows.csv", *extra])
    assert code == 2, err
    assert match in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "rows.csv").exists()


@pytest.mark.dask
@pytest.mark.parametrize("flag", ["--output-format", "--format"])
def test_output_format_and_its_old_name(
    parts: list[str], tmp_path: Path, cli_run: CliRun, flag: str
) -> None:
    out = tmp_path / "rows"
    code, _, err = cli_run(["sweep", parts[0], "--out", str(out), flag, "csv", "--workers", "1"])
    assert code == 0, err
    assert out.is_file() and out.read_text().startswith("part_id,")


def test_sweep_help_names_only_its_own_options(cli_run: CliRun) -> None:
    code, text, _ = cli_run(["sweep", "--help"])
    assert code == 0
    flat = " ".join(text.split())
    assert "--output-format" in flat and "--turn-noise" in flat and "--payoff" in flat
    assert "--format" not in flat.replace("--output-format", "")  # the old name is hidden
    assert "--plan FILE" not in flat  # sweep has no --plan
    code, text, _ = cli_run(["simulate", "--help"])
    assert "--plan FILE" in " ".join(text.split())  # simulate has it


def test_report_of_noisy_rows(parts: list[str]) -> None:
    import statistics

    from bayesgrasp.sweep.report import report_html

    options = noisy(turn_noise="normal:2", contact_noise=0.1)
    rows = run_chunk([*map(_source, parts)], options).rows
    page = report_html(rows)
    assert f"<td>noise: turn_noise normal:2, contact_noise 0.1</td><td>{len(parts)}</td>" in page
    mean = statistics.fmean(r["bayes_payoff"] for r in rows)
    assert f"<td>Bayes plan expected payoff: mean</td><td>{mean:.4g}</td>" in page
    assert "expected payoff" not in report_html(run_chunk([_source(parts[0])], SweepOptions()).rows)
