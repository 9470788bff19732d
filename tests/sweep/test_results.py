"""Results files: batches, metadata, overwrite protection, resume of a cut file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pa = pytest.importorskip("pyarrow")
import pyarrow.parquet as pq  # noqa: E402

from bayesgrasp.sweep import SweepError, SweepOptions, plan_part, read_metadata, read_results  # noqa: E402
from bayesgrasp.sweep.results import METADATA_KEY, open_results  # noqa: E402


@pytest.fixture
def rows(tmp_path: Path) -> list[dict[str, object]]:
    out = []
    for i in range(5):
        f = tmp_path / f"p{i}.json"
        f.write_text(json.dumps({"vertices": [[0, 0], [3 + i, 0], [1, 2]]}))
        out.append(plan_part(str(f), SweepOptions()))
    out.append(plan_part(str(tmp_path / "missing.json"), SweepOptions()))
    return out


@pytest.mark.parametrize("name", ["r.parquet", "r.csv"])
def test_batches_round_trip_exactly(
    tmp_path: Path, rows: list[dict[str, object]], name: str
) -> None:
    out = tmp_path / name
    w = open_results(out, SweepOptions(seed=9))
    w.write(rows[:2])
    w.write(rows[2:])
    assert read_results(out) == rows
    meta = read_metadata(out)
    assert meta[0]["seed"] == 9 and meta[0]["options"]["seed"] == 9
    assert len(w.done_keys()) == len(rows)


def test_each_parquet_batch_is_a_complete_file_with_the_run_metadata(
    tmp_path: Path, rows: list[dict[str, object]]
) -> None:
    out = tmp_path / "r.parquet"
    w = open_results(out, SweepOptions())
    w.write(rows[:3])
    (out / ".part-000001.parquet.tmp").write_bytes(b"PAR1 cut short")  # a crash mid-write
    assert len(read_results(out)) == 3
    w2 = open_results(out, SweepOptions(), resume=True)
    assert not list(out.glob(".*.tmp"))
    w2.write(rows[3:])
    files = sorted(out.glob("part-*.parquet"))
    assert [f.name for f in files] == ["part-000000.parquet", "part-000001.parquet"]
    meta = json.loads(pq.read_schema(files[0]).metadata[METADATA_KEY])
    assert meta["options"] == SweepOptions().to_json() and meta["bayesgrasp_version"]
    assert len(read_metadata(out)) == 2
    assert pq.read_table(out).num_rows == len(rows)  # the folder reads as one table


@pytest.mark.parametrize("name", ["r.parquet", "r.csv"])
def test_never_overwritten_without_force(
    tmp_path: Path, rows: list[dict[str, object]], name: str
) -> None:
    out = tmp_path / name
    open_results(out, SweepOptions()).write(rows)
    with pytest.raises(SweepError, match="exists; resume it"):
        open_results(out, SweepOptions())
    open_results(out, SweepOptions(), force=True).write(rows[:1])
    assert len(read_results(out)) == 1


def test_resume_refuses_another_format(tmp_path: Path, rows: list[dict[str, object]]) -> None:
    out = tmp_path / "r.csv"
    open_results(out, SweepOptions()).write(rows)
    with pytest.raises(SweepError, match="not a Parquet results folder"):
        open_results(out, SweepOptions(), "parquet", resume=True)
    with pytest.raises(SweepError, match="cannot tell the results format"):
        open_results(tmp_path / "r.txt", SweepOptions())


def test_csv_cut_last_line_is_dropped_on_resume(
    tmp_path: Path, rows: list[dict[str, object]]
) -> None:
    out = tmp_path / "r.csv"
    open_results(out, SweepOptions()).write(rows)
    data = out.read_bytes()
    out.write_bytes(data[:-25])
    assert len(read_results(out)) == len(rows) - 1  # a reader skips the cut line
    w = open_results(out, SweepOptions(), resume=True)
    assert out.read_bytes().endswith(b"\n")
    w.write(rows[-1:])
    assert read_results(out) == rows
