"""Throughput of catalogue sweeps on a local Dask cluster.

Random parts (the seed's hulls of 10 points in the unit square) are written as JSON files
and planned (exact planner, guaranteed plan too: the sweep's defaults) by

- a plain loop in this process (``plan_part``, the baseline: no Dask at all),
- ``run_sweep`` with 1 and with 2 worker processes,

and a few parts are checked in MuJoCo (``--mujoco-parts``, 100 trials each) to measure parts
a minute and extrapolate a 10^5-part check. The machine's load average is printed before
and after each run: on a shared machine the figures are only as good as the load allows.

``--turn-noise SPEC`` (and ``--contact-noise Q``) plans every part with the noise-aware
planner instead (no guaranteed plan), as ``sweep --turn-noise``.

Usage::

    .venv/bin/python benchmarks/bench_sweep.py --parts 10000 --mujoco-parts 10
    .venv/bin/python benchmarks/bench_sweep.py --parts 500 --mujoco-parts 0 --turn-noise normal:2
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial import ConvexHull

from bayesgrasp.sweep import SweepOptions, SweepProgress, plan_part, read_results, run_sweep


def write_parts(folder: Path, n: int, seed: int = 1, units: str | None = None) -> list[str]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        pts = rng.random((10, 2))
        f = folder / f"{i // 1000:03d}" / f"r{i:06d}.json"
        f.parent.mkdir(exist_ok=True)
        doc: dict[str, object] = {"vertices": pts[ConvexHull(pts).vertices].tolist()}
        if units:
            doc["units"] = units  # MuJoCo's settings suit parts of 10 mm to 50 cm
        f.write_text(json.dumps(doc))
        out.append(str(f))
    return out


def load() -> str:
    return "load {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def sweep(folder: Path, out: Path, options: SweepOptions, workers: int) -> tuple[float, float]:
    """Wall seconds of the whole call, and of the work (first task sent to last row)."""
    last: list[SweepProgress] = []
    t = time.perf_counter()
    s = run_sweep([folder], out, options, workers=workers, force=True, progress=last.append)
    wall = time.perf_counter() - t
    assert s.written == s.found and s.errors == 0, s
    return wall, last[-1].elapsed


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--parts", type=int, default=10_000)
    ap.add_argument("--mujoco-parts", type=int, default=10)
    ap.add_argument("--mujoco-trials", type=int, default=100)
    ap.add_argument("--turn-noise", default=None, metavar="normal:SIGMA_DEG|uniform:A_DEG")
    ap.add_argument("--contact-noise", type=float, default=None, metavar="Q")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    folder = tmp / "parts"
    folder.mkdir()
    files = write_parts(folder, args.parts)
    if args.turn_noise is None and args.contact_noise is None:
        options = SweepOptions()
        how = "exact planner"
    else:
        options = SweepOptions(
            guaranteed=False, turn_noise=args.turn_noise, contact_noise=args.contact_noise
        )
        how = f"noise-aware planner, turn {args.turn_noise}, contact {args.contact_noise}"
    print(f"{args.parts} random parts ({how}); cores {os.cpu_count()}; {load()}")

    t = time.perf_counter()
    for f in files:
        plan_part(f, options)
    serial = time.perf_counter() - t
    print(
        f"plain loop, 1 process : {serial:7.1f} s  {args.parts / serial:7.0f} parts/s  ({load()})"
    )
    work: dict[int, float] = {}
    for w in (1, 2):
        wall, busy = sweep(folder, tmp / f"r{w}.parquet", options, w)
        work[w] = busy
        print(
            f"run_sweep, {w} worker(s): {wall:7.1f} s wall ({busy:6.1f} s of tasks)  "
            f"{args.parts / busy:7.0f} parts/s  ({load()})"
        )
    print(
        f"parallel efficiency (2 workers): {work[1] / (2 * work[2]):.2f}; "
        f"sweep overhead vs the plain loop (1 worker): {work[1] / serial - 1:+.0%}"
    )
    rows = read_results(tmp / "r2.parquet")
    plan = np.array([r["plan_seconds"] for r in rows])
    print(
        f"per-part planning on the workers: median {np.median(plan) * 1e3:.2f} ms, "
        f"p99 {np.quantile(plan, 0.99) * 1e3:.2f} ms"
    )

    if args.mujoco_parts:
        try:
            from bayesgrasp.sim import require_mujoco

            require_mujoco()
        except ImportError:
            print("MuJoCo: not installed (extra `sim`), skipped")
            return
        mj = tmp / "mujoco"
        mj.mkdir()
        write_parts(mj, args.mujoco_parts, seed=2, units="cm")
        sim = SweepOptions(simulate="mujoco", trials=args.mujoco_trials)
        wall, busy = sweep(mj, tmp / "mj.parquet", sim, 2)
        rows = read_results(tmp / "mj.parquet")
        per_part = float(np.mean([r["sim_seconds"] + r["plan_seconds"] for r in rows]))
        ppm = args.mujoco_parts / busy * 60
        print(
            f"MuJoCo, {args.mujoco_parts} parts x {args.mujoco_trials} trials, 2 workers: "
            f"{busy:.1f} s of tasks, {ppm:.1f} parts/min; {per_part:.2f} s a part on one "
            f"worker ({load()})"
        )
        for n in (2, 16, 64, 256):
            days = 1e5 * per_part / n / 86400
            print(
                f"  10^5 parts x {args.mujoco_trials} trials on {n:3d} workers: "
                f"{days * 24:8.1f} h ({days:.2f} days), at 100% efficiency"
            )


if __name__ == "__main__":
    main()
