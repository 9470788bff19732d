"""Planner speed: the seed's 2000-polygon study (exact planner vs the breadth-first baseline,
same polygons, same run), a 10,000-vertex part, and the baseline's memory on large parts.

Targets (issue 3): the study with the exact planner in under 2 s on one core; the exact
planner at least 100x faster than the breadth-first baseline; a 10,000-vertex ellipse of
aspect 2 planned in under 1 s. Prints wall and CPU times; the machine may be shared, so the
exact figures are the best of several repeats.

The breadth-first baseline's memory grows with the number of states K (its action-class
table has about K^3 / 4 entries): ``plan_bfs`` on N random points of the unit circle, each in
a fresh process capped at 6 GB of address space, with its peak RSS and CPU time.

Run: ``.venv/bin/python benchmarks/bench_plan.py [--polygons 2000] [--seed 1] [--repeat 3]
[--circles 65,100,130,200,300] [--circles-only]``
"""

from __future__ import annotations

import argparse
import math
import resource
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon, run_study
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.bfs import search_bfs


def timed(fn: Callable[[], Any], repeat: int = 1) -> tuple[float, float, Any]:
    """Best wall time and best CPU time over ``repeat`` calls, and the last result."""
    best_wall = best_cpu = math.inf
    out = None
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        best_wall = min(best_wall, time.perf_counter() - w)
        best_cpu = min(best_cpu, time.process_time() - c)
    return best_wall, best_cpu, out


# plan_bfs on n random points of the unit circle; prints K, CPU seconds, peak RSS (KiB).
_BFS_CIRCLE = r"""
import resource, sys, time
import numpy as np
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_bfs
n = int(sys.argv[1])
t = np.sort(np.random.default_rng(5).uniform(0, 2 * np.pi, n))
pb = Problem.build(Part.from_points(np.column_stack([np.cos(t), np.sin(t)])))
c0 = time.process_time()
plan_bfs(pb)
cpu = time.process_time() - c0
print(pb.n_states, cpu, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def _cap_memory() -> None:
    """In the child: 6 GB of address space, so a runaway case fails instead of the machine."""
    resource.setrlimit(resource.RLIMIT_AS, (6 << 30, 6 << 30))


def bfs_circles(sizes: list[int]) -> None:
    print("breadth-first baseline, plan_bfs on N random points of the unit circle:")
    for n in sizes:
        proc = subprocess.run(
            [sys.executable, "-c", _BFS_CIRCLE, str(n)],
            capture_output=True,
            text=True,
            preexec_fn=_cap_memory,
            check=False,
        )
        if proc.returncode:
            last = (proc.stderr.strip().splitlines() or ["killed"])[-1]
            print(f"  N = {n}: {last}")
            continue
        k, cpu, rss = proc.stdout.split()
        print(f"  N = {n} (K = {k}): cpu {float(cpu):.2f} s, peak RSS {int(rss) / 1024:.0f} MB")


def ellipse(n: int, aspect: float) -> Part:
    t = 2 * math.pi * np.arange(n) / n
    return Part.from_points(np.column_stack([aspect * np.cos(t), np.sin(t)]), name="ellipse")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--polygons", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--circles", default="65,100,130,200,300", help="sizes N, comma-separated")
    ap.add_argument("--circles-only", action="store_true", help="only the baseline's memory")
    args = ap.parse_args()
    n, seed = args.polygons, args.seed
    sizes = [int(x) for x in args.circles.split(",") if x.strip()]
    if args.circles_only:
        bfs_circles(sizes)
        return

    # 1. The study as the command runs it, exact planner (polygons drawn, built, planned).
    w, c, res = timed(lambda: run_study(n, seed, method="exact"), args.repeat)
    print(f"study, exact planner, {n} polygons (seed {seed}): wall {w:.3f} s, cpu {c:.3f} s")
    print(
        f"  mean sides {res.mean_sides:.4f}; shorter plan better {res.shorter_plan_better}/{n}; "
        f"most certain lengths {res.plan_length_histogram}"
    )

    # 2. Same polygons, same run: each planner timed per polygon (CPU time), best of repeats.
    rng = np.random.default_rng(seed)
    parts = [random_polygon(rng) for _ in range(n)]
    times = np.full((5, args.repeat, n), np.inf)  # build, exact, classes, bfs, unmerged bfs
    nodes = np.zeros(n, dtype=int)
    over = np.zeros(n, dtype=bool)
    fallback = np.zeros(n, dtype=int)
    for rep_i in range(args.repeat):
        for i, p in enumerate(parts):
            c0 = time.process_time()
            pb = Problem.build(p)
            c1 = time.process_time()
            plan_exact(pb)
            c2 = time.process_time()
            pb.classes("squeeze")
            c3 = time.process_time()
            r = search_bfs(pb, tree_count=False)
            c4 = time.process_time()
            search_bfs(pb, merge=False)
            c5 = time.process_time()
            times[:, rep_i, i] = (c1 - c0, c2 - c1, c3 - c2, c4 - c3, c5 - c4)
            nodes[i], over[i], fallback[i] = (
                r.stats.nodes,
                not r.stats.completed,
                r.stats.fallback_nodes,
            )
    best = times.min(axis=1)  # (5, n) best of the repeats, per polygon
    t_build, t_exact, t_classes, t_bfs, t_tree = best.sum(axis=1)
    print(f"same {n} polygons, cpu seconds (per polygon best of {args.repeat}, summed):")
    print(f"  problem set-up (hull, squeeze function)  {t_build:.3f}")
    print(f"  exact planner                            {t_exact:.3f}")
    print(f"  breadth-first: action classes            {t_classes:.3f}")
    print(f"  breadth-first: search, merging           {t_bfs:.3f}")
    print(f"  breadth-first: search, no merging        {t_tree:.3f}")
    bfs_cost = best[2] + best[3]
    print(
        f"  exact vs breadth-first (merging): {bfs_cost.sum() / t_exact:.1f}x faster planning, "
        f"{(t_build + bfs_cost.sum()) / (t_build + t_exact):.1f}x from the part"
    )
    for label, mask in (
        ("with 100 or more nodes", nodes >= 100),
        ("that passed the 1000-node limit", over),
    ):
        if mask.any():
            print(
                f"  on the {mask.sum()} polygons {label}: exact "
                f"{bfs_cost[mask].sum() / best[1][mask].sum():.1f}x faster"
            )
    print(
        f"  breadth-first: {over.sum()} polygons over 1000 nodes; "
        f"most fallback nodes {fallback.max()}; median nodes {np.median(nodes):g}"
    )

    # 3. A 10,000-vertex ellipse of aspect 2.
    part = ellipse(10_000, 2.0)
    _, cbuild, pb = timed(lambda: Problem.build(part), args.repeat)
    _, cplan, rep = timed(lambda: plan_exact(pb), args.repeat)
    wall_total, cpu_total, _ = timed(
        lambda: plan_exact(Problem.build(ellipse(10_000, 2.0))), args.repeat
    )
    print(
        f"ellipse, 10,000 vertices, aspect 2 ({pb.n_states} states): from points to plans "
        f"wall {wall_total:.3f} s, cpu {cpu_total:.3f} s (build {cbuild:.3f} s, "
        f"plan {cplan:.3f} s cpu); {len(rep.options)} options, "
        f"best p {rep.most_certain_plan.success_probability:.4f}"
    )

    # 4. The breadth-first baseline's memory on large parts.
    bfs_circles(sizes)


if __name__ == "__main__":
    main()
