"""Speed of the Bayes-policy planner (issue 10's targets), printed as figures.

- exact-reading policies for the seed's 2000 random 10-point polygons, squeezes, depth <= 4
  (target: under 5 s on one core);
- noisy readings, SIGMA = 1% of each polygon's largest diameter, RES = SIGMA / 2
  (target: under 60 s);
- a 3-part recognition policy for catalogue parts (target: under 1 s);
- noisy actions too (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`): the 2000
  polygons with SIGMA = 1% of each diameter (RES = SIGMA / 2) and a normal turn error of
  2 deg, depth <= 3 (target: under 120 s on one core); ``--noisy-actions N`` runs only
  this, on the first N polygons.

Run: ``python benchmarks/bench_policy.py [--polygons N] [--depth K] [--noisy-polygons N]``;
``--polygon I`` times the noisy polygon ``I`` of the draw alone (1402 is the slowest).
Times include building each problem; the second figure excludes it.
``plan_policy(..., sensorless=False)`` unless said (the sensorless Bayes plan is then not
computed inside the planner). Each figure is given as wall time and as CPU time of this
process (``time.process_time``): on a shared, loaded machine the CPU time is the one-core
figure the targets speak of.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from bayesgrasp import shapes
from bayesgrasp.model import Problem
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.model.sensing import WidthSensor
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning.policy import plan_policy


def polygons(n: int, seed: int = 0) -> list[Problem]:
    rng = np.random.default_rng(seed)
    return [Problem.build(random_polygon(rng)) for _ in range(n)]


def bench_one(index: int, depth: int, noisy: float) -> None:
    """Polygon ``index`` of the benchmark's draw alone (1402: the noisy run's slowest)."""
    rng = np.random.default_rng(0)
    for _ in range(index + 1):
        part = random_polygon(rng)
    pb = Problem.build(part)
    sigma = noisy * float(pb.diameter.lengths.max())
    c0 = time.process_time()
    pol = plan_policy(pb, WidthSensor(sigma, sigma / 2), depth, sensorless=False)
    cpu = time.process_time() - c0
    print(
        f"polygon {index} alone, SIGMA {noisy:.0%} of diameter, depth <= {depth}: "
        f"{cpu:.2f} s CPU; cost {pol.expected_cost:.6f}, {pol.searched} beliefs searched, "
        f"{pol.iterations} parametric steps"
    )


def bench_random(n: int, depth: int, noisy: float | None, with_sensorless: bool) -> None:
    t0 = time.perf_counter()
    c0 = time.process_time()
    pbs = polygons(n)
    t1 = time.perf_counter()
    costs, sensorless, beliefs, iters = [], [], [], []
    for pb in pbs:
        if noisy is None:
            sensor = WidthSensor()
        else:
            sigma = noisy * float(pb.diameter.lengths.max())
            sensor = WidthSensor(sigma, sigma / 2)
        pol = plan_policy(pb, sensor, depth, sensorless=with_sensorless)
        costs.append(pol.expected_cost)
        sensorless.append(math.nan if pol.sensorless_cost is None else pol.sensorless_cost)
        beliefs.append(pol.beliefs)
        iters.append(pol.iterations)
    t2 = time.perf_counter()
    cpu = time.process_time() - c0
    label = "exact readings" if noisy is None else f"SIGMA {noisy:.0%} of diameter, RES SIGMA/2"
    label += ", with the sensorless plan" if with_sensorless else ""
    print(
        f"{n} polygons, {label}, depth <= {depth}: {t2 - t0:.2f} s wall, {cpu:.2f} s CPU "
        f"({t2 - t1:.2f} s planning, {t1 - t0:.2f} s building problems); "
        f"mean cost {np.mean(costs):.4f} (sensorless {np.mean(sensorless):.4f}); "
        f"beliefs/polygon mean {np.mean(beliefs):.1f} max {max(beliefs)}; "
        f"parametric steps mean {np.mean(iters):.2f}"
    )


def bench_noisy_actions(n: int, depth: int = 3, turn_deg: float = 2.0) -> None:
    """Noisy readings (SIGMA 1% of the diameter, RES SIGMA/2) and a normal turn error."""
    from bayesgrasp.planning.noisy_policy import plan_noisy_policy

    noise = NoiseModel(TurnNoise("normal", math.radians(turn_deg)))
    t0 = time.perf_counter()
    c0 = time.process_time()
    pbs = polygons(n)
    t1 = time.perf_counter()
    c1 = time.process_time()
    costs, searched, bounds, times = [], [], [], []
    for pb in pbs:
        sigma = 0.01 * float(pb.diameter.lengths.max())
        p0 = time.process_time()
        pol = plan_noisy_policy(pb, WidthSensor(sigma, sigma / 2), depth, noise, sensorless=False)
        times.append(time.process_time() - p0)
        costs.append(pol.expected_cost)
        searched.append(pol.searched)
        bounds.append(pol.refinement_bound)
    t2 = time.perf_counter()
    cpu = time.process_time() - c0
    worst = int(np.argmax(times))
    print(
        f"{n} polygons, noisy actions (normal {turn_deg:g} deg) and readings (SIGMA 1% of "
        f"diameter, RES SIGMA/2), depth <= {depth}: {t2 - t0:.2f} s wall, {cpu:.2f} s CPU "
        f"({time.process_time() - c1:.2f} s CPU planning, {t1 - t0:.2f} s building problems); "
        f"mean cost {np.mean(costs):.4f}; beliefs searched/polygon mean "
        f"{np.mean(searched):.1f} max {max(searched)}; refinement bound max {max(bounds):.2g}; "
        f"slowest polygon {worst} ({times[worst]:.3f} s CPU)"
    )


def bench_recognition(names: tuple[str, ...], depth: int, sensor: str) -> None:
    t0 = time.perf_counter()
    c0 = time.process_time()
    pbs = [Problem.build(shapes.load(n)) for n in names]
    pol = plan_policy(pbs, sensor, depth)
    t1 = time.perf_counter()
    cpu = time.process_time() - c0
    print(
        f"recognition {'+'.join(names)}, {sensor}, depth <= {depth}: {t1 - t0:.3f} s wall, "
        f"{cpu:.3f} s CPU; "
        f"cost {pol.expected_cost:.4f}, success {pol.success_probability:.4f}, "
        f"actions {pol.expected_actions:.3f}, beliefs {pol.beliefs}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--polygons", type=int, default=2000)
    ap.add_argument("--depth", type=int, default=4)
    ap.add_argument("--noisy-polygons", type=int, default=None)
    ap.add_argument("--polygon", type=int, default=None, help="only this noisy polygon")
    ap.add_argument(
        "--noisy-actions", type=int, default=None, help="only noisy actions, N polygons"
    )
    args = ap.parse_args()
    if args.noisy_actions is not None:
        bench_noisy_actions(args.noisy_actions)
        return
    if args.polygon is not None:
        bench_one(args.polygon, args.depth, 0.01)
        return
    for with_sensorless in (False, True):
        bench_random(args.polygons, args.depth, None, with_sensorless)
    bench_random(args.noisy_polygons or args.polygons, args.depth, 0.01, False)
    parts = ("rectangle", "tuning-fork", "ic-chip")
    for sensor in ("width", "width:0.5,0.1"):
        bench_recognition(parts, 3, sensor)
        bench_recognition(parts, 4, sensor)
    bench_recognition(("triangle", "example", "allen-wrench"), 3, "width:0.5,0.1")
    bench_noisy_actions(args.noisy_polygons or args.polygons)


if __name__ == "__main__":
    main()
