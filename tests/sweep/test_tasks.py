"""The work of one part, without a cluster: options, rows, bytes, timeouts, finding parts."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bayesgrasp.errors import PlanningError
from bayesgrasp.sweep import PartSource, SweepError, SweepOptions, find_parts, plan_part
from bayesgrasp.sweep.tasks import ROW_COLUMNS, run_chunk

Check = Callable[[list[dict[str, Any]], list[str], SweepOptions], None]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"goal": "all"}, "`goal` must be one of single, symmetry; got 'all'"),
        ({"method": "astar"}, "`method` must be one of exact, bfs"),
        ({"squeeze_cost": -1.0}, "`squeeze_cost` must be a finite number >= 0"),
        ({"verify_cost": float("nan")}, "`verify_cost` must be a finite number"),
        ({"trials": 0}, "`trials` must be None or an integer >= 1"),
        ({"simulate": "bullet"}, "`simulate` must be None or one of kinematic, mujoco"),
        ({"actions": "squeeze"}, "`actions` must be a non-empty tuple"),
        ({"offset_mm": 1.0}, "`offset_mm` applies to simulate='mujoco' only"),
    ],
)
def test_options_are_validated(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(SweepError, match=match):
        SweepOptions(**kwargs)


def test_unknown_action_names_the_known_ones() -> None:
    with pytest.raises(PlanningError, match="push-grasp"):
        SweepOptions(actions=("squeeze", "flip"))


def test_options_json_round_trip_and_key() -> None:
    o = SweepOptions(prior="vonmises:30,2", actions=("squeeze", "push-grasp"), seed=4)
    doc = json.loads(json.dumps(o.to_json()))
    assert SweepOptions.from_json(doc) == o
    assert SweepOptions.from_json(doc).key == o.key != SweepOptions().key


def test_every_row_has_every_column(tmp_path: Path) -> None:
    f = tmp_path / "tri.json"
    f.write_text(json.dumps({"vertices": [[0, 0], [3, 0], [0, 2]]}))
    for row in (
        plan_part(str(f), SweepOptions()),
        plan_part(str(tmp_path / "x.json"), SweepOptions()),
    ):
        assert list(row) == [name for name, _ in ROW_COLUMNS]
        for name, kind in ROW_COLUMNS:
            assert row[name] is None or isinstance(row[name], kind), name


def test_rows_equal_the_cli_for_other_options(
    make_catalogue: Callable[[Path, np.random.Generator, int], list[str]],
    tmp_path: Path,
    rows_check: Check,
) -> None:
    files = make_catalogue(tmp_path / "c", np.random.default_rng(3), 4)
    for options in (
        SweepOptions(method="bfs", max_actions=3, guaranteed=False),
        SweepOptions(prior="vonmises:40,3", retry_cost=0.5, accuracy_deg=2.0),
    ):
        rows_check([plan_part(f, options) for f in files], files, options)


def test_shape_tol_rows_equal_the_cli(rows_check: Check) -> None:
    """Issue 16: `--shape-tol` was not a sweep option; with 0.5 mm the bracket has 2 states."""
    bracket = str(Path(__file__).resolve().parents[2] / "examples" / "bracket.dxf")
    options = SweepOptions(shape_tol=0.5)
    assert "--shape-tol" in options.plan_args()
    rows = [plan_part(bracket, options)]
    rows_check(rows, [bracket], options)
    data = Path(bracket).read_bytes()
    assert plan_part(PartSource(bracket, data=data), options)["plan_json"] == rows[0]["plan_json"]
    assert plan_part(bracket, SweepOptions())["plan_json"] != rows[0]["plan_json"]
    assert json.loads(rows[0]["plan_json"])["part"]["curved"]["shape_tol"] == 0.5
    # the key of options without it is the key they had before it existed
    assert "shape_tol" not in SweepOptions().to_json()
    assert SweepOptions.from_json(options.to_json()) == options
    assert options.key != SweepOptions().key
    with pytest.raises(SweepError, match="`shape_tol` must be a finite number >= 0"):
        SweepOptions(shape_tol=-1.0)


def test_bytes_give_the_same_row_and_messages_as_the_path(
    make_catalogue: Callable[[Path, np.random.Generator, int], list[str]], tmp_path: Path
) -> None:
    files = make_catalogue(tmp_path / "c", np.random.default_rng(5), 4)
    options = SweepOptions()
    for f in files:
        data = Path(f).read_bytes()
        a = plan_part(PartSource(f), options)
        b = plan_part(PartSource(f, data=data), options)
        assert a["worker"] == b["worker"]
        for key in ("plan_json", "status", "error_class", "error_message", "sha256", "part_id"):
            assert a[key] == b[key], (f, key)


def test_a_part_over_the_timeout_is_an_error_row_and_the_rest_is_pending(
    tmp_path: Path,
) -> None:
    srcs = []
    for i in range(3):
        f = tmp_path / f"p{i}.json"
        f.write_text(json.dumps({"vertices": [[0, 0], [3 + i, 0], [0, 2]]}))
        srcs.append(PartSource(str(f)))
    slow = SweepOptions(simulate="kinematic", trials=20_000_000)
    res = run_chunk(srcs, slow, timeout=0.05)
    assert res.stuck and res.pending == tuple(srcs[1:])
    assert [r["error_class"] for r in res.rows] == ["TimeoutError"]
    assert res.rows[0]["error_message"] == (
        f"{srcs[0].path}: the part took longer than the timeout of 0.05 s"
    )
    fast = run_chunk(srcs, SweepOptions(), timeout=30)
    assert not fast.stuck and [r["status"] for r in fast.rows] == ["ok"] * 3


def test_find_parts_folders_globs_and_explicit_files(tmp_path: Path) -> None:
    for name in ("a.json", "b/c.wkt", "b/d/e.svg", "b/notes.txt", ".git/x.json", "b/F.DXF"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("x")
    rel = lambda ps: [Path(p).relative_to(tmp_path).as_posix() for p in ps]  # noqa: E731
    assert rel(find_parts([tmp_path])) == ["a.json", "b/F.DXF", "b/c.wkt", "b/d/e.svg"]
    assert rel(find_parts([f"{tmp_path}/b/**/*"])) == ["b/F.DXF", "b/c.wkt", "b/d/e.svg"]
    assert rel(find_parts([f"{tmp_path}/*.json", tmp_path / "a.json"])) == ["a.json"]
    assert rel(find_parts([tmp_path / "b/notes.txt"])) == ["b/notes.txt"]
    assert find_parts([f"{tmp_path}/*.nothing"]) == [f"{tmp_path}/*.nothing"]
