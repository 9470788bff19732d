"""A mesh in a sweep: one row per resting pose, each the CLI's ``plan MESH --pose K --json``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from bayesgrasp.sweep import PartSource, SweepOptions, find_parts, plan_part
from bayesgrasp.sweep.tasks import plan_part_rows, run_chunk

from .conftest import run_cli


@pytest.fixture
def wedge(tmp_path: Path) -> Path:
    """A wedge: a right triangle (legs 3 and 1.5) extruded by 1: poses of distinct widths."""
    tri = np.array([[0, 0], [3, 0], [0, 1.5]], dtype=float)
    pts = np.array([[x, y, z] for x, z in tri for y in (0, 1)], dtype=float)
    f = tmp_path / "wedge.stl"
    trimesh.convex.convex_hull(pts).export(f)
    return f


def test_a_row_per_pose_as_plan_mesh_pose_k(wedge: Path) -> None:
    options = SweepOptions(max_actions=2)
    rows = plan_part_rows(str(wedge), options)
    code, out, _ = run_cli(["poses", str(wedge), "--json"])
    poses = json.loads(out)["poses"]
    assert code == 0 and len(rows) == len(poses) > 1
    for k, row in enumerate(rows):
        assert row["status"] == "ok"
        assert row["pose"] == k and row["part_id"].endswith(f"#pose-{k}")
        assert row["part_id"].startswith(f"{wedge}#{row['sha256'][:16]}")
        assert_allclose(row["pose_probability"], poses[k]["probability"], rtol=1e-12)
        code, out, _ = run_cli(["plan", str(wedge), "--pose", str(k), *options.plan_args()])
        assert code == 0
        assert json.loads(row["plan_json"]) == json.loads(out)
    assert len({r["part_id"] for r in rows}) == len(rows)
    first = plan_part(str(wedge), options)  # one row: the most probable pose's
    assert first["part_id"] == rows[0]["part_id"] and first["plan_json"] == rows[0]["plan_json"]


def test_bytes_give_the_same_rows(wedge: Path) -> None:
    import hashlib

    data = wedge.read_bytes()
    by_path = plan_part_rows(str(wedge), SweepOptions())
    by_bytes = plan_part_rows(
        PartSource(str(wedge), hashlib.sha256(data).hexdigest(), data), SweepOptions()
    )
    keep = ("part_id", "pose", "pose_probability", "plan_json", "status")
    assert [{k: r[k] for k in keep} for r in by_bytes] == [{k: r[k] for k in keep} for r in by_path]


def test_a_chunk_holds_every_pose_and_the_planar_parts(wedge: Path, tmp_path: Path) -> None:
    plate = tmp_path / "plate.wkt"
    plate.write_text("POLYGON ((0 0, 4 0, 4 1, 1 1, 1 3, 0 3, 0 0))")
    assert set(find_parts([str(tmp_path)])) >= {str(wedge), str(plate)}
    res = run_chunk([PartSource(str(wedge)), PartSource(str(plate))], SweepOptions())
    n = len(plan_part_rows(str(wedge), SweepOptions()))
    assert len(res.rows) == n + 1
    assert [r["pose"] for r in res.rows] == [*range(n), None]


def test_mujoco_refused_for_a_mesh_with_the_reason(wedge: Path) -> None:
    rows = plan_part_rows(str(wedge), SweepOptions(simulate="mujoco", trials=1))
    assert rows and all(r["status"] == "error" for r in rows)
    assert all("not the solid" in r["error_message"] for r in rows)


def test_an_unreadable_mesh_is_one_error_row(tmp_path: Path) -> None:
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"solid nothing\nendsolid nothing\n")
    rows = plan_part_rows(str(bad), SweepOptions())
    assert len(rows) == 1 and rows[0]["status"] == "error"
    code, _, err = run_cli(["plan", str(bad), "--json"])
    assert code == 2 and rows[0]["error_message"] in err


@pytest.mark.dask
def test_a_sweep_writes_every_pose_once_and_resumes(wedge: Path, tmp_path: Path) -> None:
    """Rows are told apart by part_id (a mesh's poses share a path); resuming skips the mesh."""
    from bayesgrasp.sweep import read_results, run_sweep

    plate = tmp_path / "plate.wkt"
    plate.write_text("POLYGON ((0 0, 4 0, 4 1, 1 1, 1 3, 0 3, 0 0))")
    out = tmp_path / "out.csv"
    options = SweepOptions(max_actions=2)
    run_sweep([str(wedge), str(plate)], out, options, workers=1, fmt="csv")
    rows = read_results(out)
    n = len(plan_part_rows(str(wedge), options))
    assert len(rows) == n + 1 and len({r["part_id"] for r in rows}) == n + 1
    assert sorted(r["pose"] for r in rows if r["pose"] is not None) == list(range(n))
    again = run_sweep([str(wedge), str(plate)], out, options, workers=1, fmt="csv", resume=True)
    assert again.written == 0 and len(read_results(out)) == n + 1


def test_the_report_names_each_pose(wedge: Path) -> None:
    from bayesgrasp.sweep.report import report_html

    rows = plan_part_rows(str(wedge), SweepOptions(max_actions=2))
    text = report_html(rows)
    for r in rows:
        assert f"(pose {r['pose']}, p = {r['pose_probability']:.3g})" in text
