"""The planar geometry's price: this worktree beside an earlier version, in one run.

Each case runs in a fresh subprocess with one version's ``src`` first on the path; the runs
of the two versions alternate (so that a change of the machine's load hits both alike) and
each figure is the best CPU time of ``--repeat`` runs, imports excluded.

Cases:

- ``study``: the seed's 2000-polygon study, ``run_study(2000, seed=1)`` (hull, diameter,
  squeeze function, exact Bayes plans);
- ``batch``: ``plan --batch`` of the study's 2000 hulls as JSON lines (each line a convex
  ring read by the point-list reader), a second call in the same process;
- ``read``: the point-list reader alone (``point_list_part``) on the same 2000 convex rings;
- ``hulls``: ``Part.from_points`` of the study's 2000 clouds of 10 points (the hull of a few
  points, on Python floats);
- ``large``: ``Part.from_points`` of 10^5 random points on the unit circle and of a regular
  10^5-gon (the vectorised monotone chain), and ``diameter_function`` of the latter.

Run: ``.venv/bin/python benchmarks/bench_geometry.py [--before REV] [--repeat 5]``; ``REV``
is a git revision (default: where this branch left ``main``) or a ``src`` folder.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
HERE = ROOT / "src"

_SCRIPT = r"""
import contextlib, io, json, math, os, sys, tempfile, time
from pathlib import Path
import numpy as np
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.io.points import point_list_part
from bayesgrasp.paper.study import random_polygon, run_study

case, n = sys.argv[1], int(sys.argv[2])
out = {}
if case == "study":
    c0 = time.process_time()
    res = run_study(n, 1)
    out["cpu"] = time.process_time() - c0
elif case in ("batch", "read"):
    rng = np.random.default_rng(1)
    rings = [random_polygon(rng).hull.vertices.tolist() for _ in range(n)]
    if case == "read":
        c0 = time.process_time()
        parts = [point_list_part(Path("p.json"), r, f"p{k}") for k, r in enumerate(rings)]
        out["cpu"] = time.process_time() - c0
    else:
        from bayesgrasp.cli import main
        path = os.path.join(tempfile.mkdtemp(), "parts.jsonl")
        with open(path, "w") as fh:
            for k, r in enumerate(rings):
                fh.write(json.dumps({"name": f"p{k}", "vertices": r}) + "\n")
        def batch():
            sink = io.StringIO()
            c0 = time.process_time()
            with contextlib.redirect_stdout(sink):
                main(["plan", "--batch", path])
            return time.process_time() - c0, sink.getvalue()
        batch()  # the first call imports the command's modules
        out["cpu"], text = batch()
        out["lines"] = text.count("\n")
elif case == "hulls":
    draws = np.random.default_rng(1).uniform(size=(n, 10, 2))
    c0 = time.process_time()
    for d in draws:
        Part.from_points(d)
    out["cpu"] = time.process_time() - c0
elif case == "large":
    t = np.random.default_rng(0).uniform(0.0, 2 * math.pi, 100_000)
    circle = np.column_stack([np.cos(t), np.sin(t)])
    t = 2 * math.pi * np.arange(100_000) / 100_000
    regular = np.column_stack([np.cos(t), np.sin(t)])
    c0 = time.process_time()
    Part.from_points(circle)
    c1 = time.process_time()
    part = Part.from_points(regular)
    c2 = time.process_time()
    diameter_function(part.hull)
    c3 = time.process_time()
    out.update(cpu=c3 - c0, circle=c1 - c0, regular=c2 - c1, diameter=c3 - c2)
print(json.dumps(out))
"""

CASES = {"study": 2000, "batch": 2000, "read": 2000, "hulls": 2000, "large": 1}


def run(src: Path, case: str, n: int) -> dict[str, Any]:
    """One case in a subprocess with ``src`` first on the path."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT, case, str(n)],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode:
        return {"error": done.stderr.strip().splitlines()[-1] if done.stderr else "failed"}
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def source(before: str) -> Path:
    """The ``src`` of an earlier version: a folder as given, or a revision's, extracted."""
    given = Path(before)
    if (given / "bayesgrasp").is_dir():
        return given
    if (given / "src" / "bayesgrasp").is_dir():
        return given / "src"
    out = Path(tempfile.mkdtemp(prefix="bench-geometry-"))
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", before, "src"], capture_output=True, check=True
    )
    subprocess.run(["tar", "-x", "-C", str(out)], input=archive.stdout, check=True)
    return out / "src"


def default_before() -> str:
    """Where this branch left ``main`` (the version before its changes)."""
    done = subprocess.run(
        ["git", "-C", str(ROOT), "merge-base", "HEAD", "main"],
        capture_output=True,
        text=True,
        check=True,
    )
    return done.stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--before", default=None, help="git revision or src folder to compare")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--only", default="", help="comma-separated cases: " + ", ".join(CASES))
    args = ap.parse_args()
    before = args.before or default_before()
    cases = args.only.split(",") if args.only else list(CASES)
    versions = [("after", HERE), ("before", source(before))]
    for _, src in versions:  # compiled bytecode, as an installed package has it
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(src)], check=True)
    load = os.getloadavg()
    print(f"before = {before}; load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print(f"{'case':<8} {'before (s)':>11} {'after (s)':>10} {'after/before':>13}  detail")
    for case in cases:
        runs: dict[str, list[dict[str, Any]]] = {"after": [], "before": []}
        for _ in range(args.repeat):
            for label, src in versions:
                runs[label].append(run(src, case, CASES[case]))
        best = {}
        for label, found in runs.items():
            ok = [r for r in found if "cpu" in r]
            best[label] = min(ok, key=lambda r: r["cpu"]) if ok else found[0]
        new, old = best["after"], best["before"]
        if "cpu" not in new or "cpu" not in old:
            print(f"{case:<8} {old.get('error', '')} | {new.get('error', '')}")
            continue
        detail = ""
        if case == "large":
            detail = "; ".join(
                f"{k} {old[k]:.3f} -> {new[k]:.3f}" for k in ("circle", "regular", "diameter")
            )
        if case == "batch":
            detail = f"{new['lines']} lines (before {old['lines']})"
        print(
            f"{case:<8} {old['cpu']:>11.4f} {new['cpu']:>10.4f} {new['cpu'] / old['cpu']:>13.3f}"
            f"  {detail}"
        )


if __name__ == "__main__":
    main()
