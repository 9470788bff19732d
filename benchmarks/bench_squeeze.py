"""Speed of the foundation: convex hull, exact diameter function and squeeze function.

Two workloads (issue 2):

* the seed's study: 2000 random polygons, each the hull of 10 uniform points in the unit
  square, built one after the other in a single process (target: under 0.6 s in all);
* one large part: 100,000 points evenly spaced on an ellipse of aspect 2 (target: under
  0.5 s).

Each workload runs ``--repeat`` times; the script prints the best wall-clock time and the
process CPU time of that run, split into hull (``ConvexPolygon.from_points``), diameter
function and squeeze function. On a loaded machine the CPU time is the fairer figure.

Run: ``.venv/bin/python benchmarks/bench_squeeze.py [--repeat 5]``.
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import ConvexPolygon
from bayesgrasp.geometry.transfer import squeeze_function

Timing = dict[str, tuple[float, float]]  # stage -> (wall seconds, cpu seconds)


def timed(fn: Callable[[], Any]) -> tuple[Any, float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def run_polygons(points: np.ndarray) -> Timing:
    polys, w1, c1 = timed(lambda: [ConvexPolygon.from_points(p) for p in points])
    diams, w2, c2 = timed(lambda: [diameter_function(p) for p in polys])
    squeezes, w3, c3 = timed(lambda: [squeeze_function(d) for d in diams])
    assert all(s.n_states >= 2 for s in squeezes)
    return {"hull": (w1, c1), "diameter": (w2, c2), "squeeze": (w3, c3)}


def best(runs: list[Timing]) -> Timing:
    """The run with the least total wall-clock time."""
    return min(runs, key=lambda r: sum(w for w, _ in r.values()))


def report(title: str, timing: Timing, target: float) -> None:
    print(title)
    print(f"  {'stage':<10} {'wall s':>8} {'CPU s':>8}")
    for stage, (wall, cpu) in timing.items():
        print(f"  {stage:<10} {wall:8.3f} {cpu:8.3f}")
    wall = sum(w for w, _ in timing.values())
    cpu = sum(c for _, c in timing.values())
    verdict = "met" if wall < target else "MISSED (see the CPU time if the machine is busy)"
    print(f"  {'total':<10} {wall:8.3f} {cpu:8.3f}   target {target} s: {verdict}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--polygons", type=int, default=2000)
    parser.add_argument("--vertices", type=int, default=100_000)
    args = parser.parse_args()
    rng = np.random.default_rng(1990)
    print(f"python {platform.python_version()}, numpy {np.__version__}, {platform.machine()}")

    points = rng.random((args.polygons, 10, 2))
    runs = [run_polygons(points) for _ in range(args.repeat)]
    sides = np.mean([ConvexPolygon.from_points(p).n_sides for p in points])
    title = f"{args.polygons} random 10-point polygons (mean {sides:.2f} sides)"
    report(f"{title}, best of {args.repeat}:", best(runs), 0.6)

    t = np.arange(args.vertices) * (2.0 * math.pi / args.vertices)
    ellipse = np.column_stack([2.0 * np.cos(t), np.sin(t)])
    runs = [run_polygons(ellipse[None]) for _ in range(args.repeat)]
    poly = ConvexPolygon.from_points(ellipse)
    n_states = squeeze_function(poly).n_states
    title = f"{args.vertices}-point ellipse, aspect 2 ({poly.n_sides} sides, {n_states} states)"
    report(f"{title}, best of {args.repeat}:", best(runs), 0.5)


if __name__ == "__main__":
    main()
