"""Sweeps on real Dask clusters: a local one, one the test starts, and faults."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("distributed")
pytest.importorskip("pyarrow")

from distributed import Client, LocalCluster

from bayesgrasp.sweep import (
    SweepError,
    SweepInterrupted,
    SweepOptions,
    SweepProgress,
    read_metadata,
    read_results,
    run_sweep,
)
from bayesgrasp.sweep.engine import task_parts

pytestmark = pytest.mark.dask

Check = Callable[[list[dict[str, Any]], list[str], SweepOptions], None]
VENV_BIN = Path(sys.executable).parent
# A local cluster as the sweep starts one (the scheduler's HTTP server on any free port:
# on 8787 a second cluster warns).
CLUSTER: dict[str, Any] = {
    "n_workers": 2,
    "threads_per_worker": 1,
    "processes": True,
    "host": "127.0.0.1",
    "dashboard_address": None,
    "scheduler_kwargs": {"dashboard_address": ":0"},
}


def explicit(folder: Path) -> list[str]:
    """Paths named one by one: a missing file and a file of no part format."""
    return [str(folder / "missing.json"), str(folder / "random" / "notes.txt")]


def test_local_cluster_rows_equal_plan_json(
    catalogue: tuple[Path, list[str]], tmp_path: Path, rows_check: Check
) -> None:
    folder, files = catalogue
    options = SweepOptions()
    out = tmp_path / "results.parquet"
    seen: list[SweepProgress] = []
    s = run_sweep([folder, *explicit(folder)], out, options, workers=2, progress=seen.append)
    rows = read_results(out)
    paths = [*files, *explicit(folder)]
    rows_check(rows, paths, options)
    broken = [r for r in rows if r["status"] == "error"]
    # six broken files, a missing one, one of no part format
    assert len(broken) == 8, [r["error_message"] for r in broken]
    assert {r["error_class"] for r in broken} == {"PartFileError"}
    assert s.found == s.written == len(paths) and s.errors == 8 and s.skipped == 0
    assert s.ok + s.no_plan == len(paths) - 8 and s.workers == 2
    assert seen[-1].done == len(paths) and seen[-1].failed == 8
    meta = read_metadata(out)
    assert meta[-1]["options"] == options.to_json() and meta[-1]["seed"] == 0
    assert meta[-1]["bayesgrasp_version"]
    # never overwritten without force
    with pytest.raises(SweepError, match="exists; resume it"):
        run_sweep([folder], out, options, workers=1)


@pytest.fixture(scope="module")
def cluster() -> Iterator[str]:
    """A 2-worker local cluster the module's tests share (its scheduler address)."""
    with LocalCluster(**CLUSTER) as c:
        yield c.scheduler_address


def test_csv_with_other_options_and_simulation(
    catalogue: tuple[Path, list[str]],
    tmp_path: Path,
    rows_check: Check,
    cluster: str,
    cli_run: Callable[[list[str]], tuple[int, str, str]],
) -> None:
    folder, files = catalogue
    options = SweepOptions(
        actions=("squeeze", "push-grasp"),
        accuracy_deg=1.0,
        squeeze_cost=2.0,
        first_squeeze_cost=3.0,
        first_push_grasp_cost=0.5,
        goal="symmetry",
    )
    out = tmp_path / "r.csv"
    run_sweep([folder], out, options, scheduler=cluster, fmt="csv")
    rows_check(read_results(out), files, options)
    # a kinematic check of each Bayes plan equals `bayesgrasp simulate` with that seed
    sim = SweepOptions(simulate="kinematic", trials=3000, seed=11)
    out2 = tmp_path / "sim.parquet"
    run_sweep([folder / "catalogue"], out2, sim, scheduler=cluster, send="path")
    for r in read_results(out2):
        code, text, _ = cli_run(
            ["simulate", r["path"], "--json", "--trials", "3000", "--seed", "11"]
        )
        assert code == 0
        want, got = json.loads(text), json.loads(r["sim_json"])
        want.pop("seconds"), got.pop("seconds")
        assert got == want
        assert r["sim_observed"] == want["observed_success"]


def test_resume_after_interrupt_gives_each_part_once(
    catalogue: tuple[Path, list[str]], tmp_path: Path, rows_check: Check, cluster: str
) -> None:
    folder, files = catalogue
    options = SweepOptions()
    out = tmp_path / "r.parquet"

    def stop(p: SweepProgress) -> None:
        if p.done >= 8:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted) as info:
        run_sweep(
            [folder],
            out,
            options,
            scheduler=cluster,
            progress=stop,
            chunk_parts=2,
            batch_rows=3,
        )
    first = info.value.summary
    assert first.interrupted and 8 <= first.written < len(files)
    assert len(read_results(out)) == first.written
    s = run_sweep([folder], out, options, scheduler=cluster, resume=True)
    assert s.skipped == first.written and s.written == len(files) - first.written
    rows_check(read_results(out), files, options)
    # a third run has nothing left to do; other options would mix rows: refused
    assert run_sweep([folder], out, options, scheduler=cluster, resume=True).written == 0
    other = SweepOptions(verify_cost=2.0)
    with pytest.raises(SweepError, match=r"cannot resume: .*verify_cost 1\.0 -> 2\.0"):
        run_sweep([folder / "catalogue"], out, other, scheduler=cluster, resume=True)
    assert len(read_results(out)) == len(files)


def test_resume_csv_with_a_cut_last_line(
    catalogue: tuple[Path, list[str]], tmp_path: Path, rows_check: Check, cluster: str
) -> None:
    folder, files = catalogue
    options = SweepOptions()
    out = tmp_path / "r.csv"
    run_sweep([folder / "catalogue"], out, options, scheduler=cluster, fmt="csv")
    text = out.read_bytes()
    out.write_bytes(text[: len(text) - 40])  # a crash in the middle of the last row
    s = run_sweep([folder], out, options, scheduler=cluster, fmt="csv", resume=True)
    assert s.skipped == len(list((folder / "catalogue").iterdir())) - 1
    rows_check(read_results(out), files, options)


def test_timeout_gives_error_rows(tmp_path: Path, cluster: str) -> None:
    parts = tmp_path / "parts"
    parts.mkdir()
    for i in range(3):
        (parts / f"p{i}.json").write_text(json.dumps({"vertices": [[0, 0], [3 + i, 0], [0, 2]]}))
    slow = SweepOptions(simulate="kinematic", trials=30_000_000)  # seconds a part
    out = tmp_path / "r.parquet"
    s = run_sweep([parts], out, slow, scheduler=cluster, timeout=0.2)
    rows = read_results(out)
    assert len(rows) == 3 and s.timeouts == 3
    assert {r["error_class"] for r in rows} == {"TimeoutError"}
    assert all("longer than the timeout of 0.2 s" in r["error_message"] for r in rows)


def test_killed_worker_still_gives_every_row_once(
    catalogue: tuple[Path, list[str]], tmp_path: Path, rows_check: Check
) -> None:
    folder, files = catalogue
    options = SweepOptions(simulate="kinematic", trials=150_000)  # ~0.05 s a part
    out = tmp_path / "r.parquet"
    with (
        LocalCluster(**CLUSTER) as c,
        Client(c) as client,
    ):
        pids = list(client.run(os.getpid).values())
        killed: list[int] = []

        def kill(p: SweepProgress) -> None:
            if p.done >= 4 and not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        s = run_sweep(
            [folder], out, options, scheduler=c.scheduler_address, progress=kill, chunk_parts=1
        )
    assert killed and s.written == len(files)
    rows = read_results(out)
    rows_check(rows, files, options)
    workers = {r["worker"] for r in rows if r["status"] != "error"}
    assert len(workers) >= 2


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


def wait_for_workers(address: str, n: int, deadline: float) -> None:
    with Client(address, timeout=deadline) as client:
        client.wait_for_workers(n, timeout=deadline)


def test_scheduler_and_workers_started_by_the_test(
    catalogue: tuple[Path, list[str]], tmp_path: Path, rows_check: Check
) -> None:
    folder, files = catalogue
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = str(VENV_BIN / "dask")
    logs = open(tmp_path / "dask.log", "wb")
    procs: list[subprocess.Popen[bytes]] = []
    try:
        procs.append(
            subprocess.Popen(
                [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                stdout=logs,
                stderr=subprocess.STDOUT,
                cwd=tmp_path,
            )
        )
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [
                        dask,
                        "worker",
                        address,
                        "--nthreads",
                        "1",
                        "--nworkers",
                        "1",
                        "--host",
                        "127.0.0.1",
                        "--no-dashboard",
                    ],
                    stdout=logs,
                    stderr=subprocess.STDOUT,
                    cwd=tmp_path,
                )
            )
        deadline = time.monotonic() + 60
        while True:
            with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), 1):
                break
            assert time.monotonic() < deadline, (tmp_path / "dask.log").read_text()
            time.sleep(0.2)
        wait_for_workers(address, 2, 60)
        options = SweepOptions()
        out = tmp_path / "r.parquet"
        s = run_sweep([folder, *explicit(folder)], out, options, scheduler=address, chunk_parts=2)
        assert s.workers == 2
        rows = read_results(out)
        rows_check(rows, [*files, *explicit(folder)], options)
        assert len({r["worker"] for r in rows}) == 2  # bytes went to both workers
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                os.kill(p.pid, signal.SIGTERM)
        for p in reversed(procs):
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                os.kill(p.pid, signal.SIGKILL)
                p.wait()
        logs.close()


def test_forty_small_parts_use_both_workers(tmp_path: Path, cluster: str) -> None:
    """Small parts go several to a task, but spread over every worker of the cluster."""
    folder = tmp_path / "parts"
    folder.mkdir()
    rng = np.random.default_rng(7)
    for i in range(40):
        pts = rng.random((6, 2)) * 30.0
        doc = {"name": f"p{i}", "units": "mm", "vertices": pts.tolist()}
        (folder / f"p{i:02d}.json").write_text(json.dumps(doc))
    out = tmp_path / "r.csv"
    s = run_sweep([folder], out, SweepOptions(), scheduler=cluster)
    rows = read_results(out)
    assert s.written == 40 and s.workers == 2
    assert len({r["worker"] for r in rows}) == 2


def test_task_parts_spreads_small_sweeps() -> None:
    assert task_parts(40, 2, None) == 5  # 8 tasks: 4 a worker
    assert task_parts(1, 8, None) == 1
    assert task_parts(10**5, 2, None) == 64  # capped: task overhead stays small
    assert task_parts(10**5, 2, "kinematic") == 2 and task_parts(10**5, 2, "mujoco") == 1


@pytest.mark.parametrize(
    ("other", "reason"),
    [
        (SweepOptions(seed=1), r"seed 0 -> 1"),
        (SweepOptions(simulate="kinematic", trials=500), r"trials None -> 500"),
    ],
)
def test_resume_with_another_seed_or_trial_count_is_refused(
    tmp_path: Path, cluster: str, other: SweepOptions, reason: str
) -> None:
    folder = tmp_path / "parts"
    folder.mkdir()
    (folder / "tri.json").write_text(json.dumps({"vertices": [[0, 0], [4, 0], [1, 3]]}))
    out = tmp_path / "r.csv"
    run_sweep([folder], out, SweepOptions(), scheduler=cluster)
    with pytest.raises(SweepError, match=rf"cannot resume: .*{reason}"):
        run_sweep([folder], out, other, scheduler=cluster, resume=True)
    assert len(read_results(out)) == 1
