"""What the plain-Python paths for small parts earn: the study with and without them, in one run.

Below :data:`bayesgrasp.sizes.SMALL` vertices or states, the hull, the diameter function's
pieces, the symmetry test, the arc fronts and the part reader run on Python floats; above
it, on numpy arrays. Both paths make the same decisions (the tests hold them together). A
second implementation must earn at least 2x on a user-facing benchmark to stay; this script
measures that gain on the user-facing runs of small parts: the seed's 2000-polygon study
(``run_study(2000, seed=1)``) and ``plan`` of 200 catalogue-sized parts one after another.

Each case runs in a fresh subprocess, with the cut-off as shipped and with every module's
cut-off set to 0 (numpy only), alternately; each figure is the best CPU time of
``--repeat`` runs, imports excluded.

Run: ``.venv/bin/python benchmarks/bench_small_paths.py [--repeat 5]``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

_SCRIPT = r"""
import importlib, json, pkgutil, sys, time
import bayesgrasp
from bayesgrasp.paper.study import random_polygon, run_study
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact

if sys.argv[1] == "numpy":
    for info in pkgutil.walk_packages(bayesgrasp.__path__, "bayesgrasp."):
        if info.name.startswith(("bayesgrasp.web", "bayesgrasp.cli", "bayesgrasp.sweep")):
            continue
        try:
            module = importlib.import_module(info.name)
        except Exception:
            continue
        for name in ("SMALL", "_SMALL"):
            if isinstance(getattr(module, name, None), int):
                setattr(module, name, 0)
parts = [random_polygon(s) for s in range(200)]
t = time.process_time(); run_study(2000, seed=1); study = time.process_time() - t
t = time.process_time()
for p in parts:
    plan_exact(Problem.build(p))
plans = time.process_time() - t
print(json.dumps({"study": study, "plans": plans}))
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    best: dict[str, dict[str, float]] = {"python": {}, "numpy": {}}
    for _ in range(args.repeat):
        for mode in ("python", "numpy"):
            out = subprocess.run(
                [sys.executable, "-c", _SCRIPT, mode],
                capture_output=True,
                text=True,
                check=True,
                cwd=ROOT,
            ).stdout
            for case, seconds in json.loads(out).items():
                best[mode][case] = min(best[mode].get(case, float("inf")), seconds)
    print(f"{'case':<8} {'small paths (s)':>16} {'numpy only (s)':>15} {'gain':>6}")
    for case in best["python"]:
        a, b = best["python"][case], best["numpy"][case]
        print(f"{case:<8} {a:>16.4f} {b:>15.4f} {b / a:>5.2f}x")


if __name__ == "__main__":
    main()
