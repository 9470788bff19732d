"""Instructions a unit of issue 12's work, by valgrind: figures the machine's load cannot move.

Times on a shared machine moved the ratios of ``bench_limits.py`` by 30% from run to run;
instruction counts move much less: 1-2% for ``study`` and ``batch`` in repeated runs, but up
to 17% for ``hard`` (184 plans of a few microseconds each, where the heap's layout shows), so
compare ``hard`` within one session only. Each figure is the difference of two runs under
``valgrind --tool=callgrind`` (the work done and not done, the set-up the same, hash seed
0), divided by the units:

- ``study``: one polygon of the seed's study (``run_study(2000, seed=1)``: hull, problem,
  exact plans with angles);
- ``batch``: one line of a warm ``plan --batch`` of the study's 2000 hulls (its second call
  in the process), JSON in and out;
- ``hard``: one exact plan of the study polygons whose breadth-first search needs over 100
  nodes (184 of them; their indices are cached in the temporary directory).

Needs valgrind (``apt-get install valgrind``); about a minute a case (``hard``: three the
first time, for the breadth-first search). Give ``--src`` to count another worktree's code.

Run: ``.venv/bin/python benchmarks/icount.py [study] [batch] [hard] [--src PATH]``
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent / "src"
_HARD = "bayesgrasp-icount-hard.json"  # the hard polygons' indices, in the temporary folder

_CHILD = r"""
import contextlib, io, json, os, sys
import numpy as np
from bayesgrasp.paper.study import random_polygon, run_study
stage, work, tmp, HARD = sys.argv[1], sys.argv[2] == "1", sys.argv[3], sys.argv[4]
if stage == "hard":
    from bayesgrasp.model.problem import Problem
    from bayesgrasp.planning.bfs import search_bfs
    from bayesgrasp.planning.exact import plan_exact
    rng = np.random.default_rng(1)
    pbs = [Problem.build(random_polygon(rng)) for _ in range(2000)]
    cache = os.path.join(tmp, HARD)
    if not os.path.exists(cache):
        with open(cache, "w") as fh:
            json.dump([k for k, pb in enumerate(pbs)
                       if search_bfs(pb, tree_count=False).stats.bfs_nodes > 100], fh)
    with open(cache) as fh:
        hard = [pbs[k] for k in json.load(fh)]
    for pb in hard:  # warm
        plan_exact(pb)
    units = len(hard)
    if work:
        for pb in hard:
            plan_exact(pb)
elif stage == "study":
    run_study(50, 1)  # warm
    units = 2000
    if work:
        run_study(2000, 1)
else:
    from bayesgrasp.cli import main
    path = os.path.join(tmp, "bayesgrasp-icount-parts.jsonl")
    rng = np.random.default_rng(1)
    with open(path, "w") as fh:
        for k in range(2000):
            hull = random_polygon(rng).hull.vertices.tolist()
            fh.write(json.dumps({"name": f"p{k}", "vertices": hull}) + "\n")
    with contextlib.redirect_stdout(io.StringIO()):
        main(["plan", "--batch", path])  # the first call imports the command's modules
    units = 2000
    if work:
        with contextlib.redirect_stdout(io.StringIO()):
            main(["plan", "--batch", path])
print("UNITS", units)
"""


def count(src: Path, stage: str, work: bool) -> tuple[int, int]:
    """(instructions, units) of one run of the case under callgrind."""
    run = subprocess.run(
        [
            "valgrind",
            "--tool=callgrind",
            "--callgrind-out-file=/dev/null",
            sys.executable,
            "-c",
            _CHILD,
            stage,
            "1" if work else "0",
            tempfile.gettempdir(),
            _HARD,
        ],
        env=dict(os.environ, PYTHONPATH=str(src), PYTHONHASHSEED="0"),
        capture_output=True,
        text=True,
        check=False,
    )
    found = re.search(r"Collected : (\d+)", run.stderr)
    units = re.search(r"UNITS (\d+)", run.stdout)
    if run.returncode != 0 or found is None or units is None:
        sys.exit(f"icount: the {stage} case failed:\n{run.stderr[-2000:]}{run.stdout[-2000:]}")
    return int(found.group(1)), int(units.group(1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cases", nargs="*", default=["study", "batch", "hard"])
    ap.add_argument("--src", type=Path, default=HERE, help="the src folder to count")
    args = ap.parse_args()
    if shutil.which("valgrind") is None:
        sys.exit("icount: needs valgrind (apt-get install valgrind)")
    for case in args.cases:
        if case not in ("study", "batch", "hard"):
            sys.exit(f"icount: unknown case {case!r}; expected study, batch or hard")
        if case == "hard" and not (Path(tempfile.gettempdir()) / _HARD).exists():
            count(args.src, case, False)  # finds the polygons, by the breadth-first search
        idle, _ = count(args.src, case, False)
        busy, units = count(args.src, case, True)
        print(f"{case}: {(busy - idle) / units / 1000:.1f}k instructions a unit ({units} units)")


if __name__ == "__main__":
    main()
