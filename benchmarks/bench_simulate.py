"""Speed of plan execution: kinematic Monte Carlo and MuJoCo physics.

Prints:
- kinematic plan executions per second (one core; numpy), for plans of 1 to 3 squeezes;
- MuJoCo squeezes per second in one process (and simulated seconds per squeeze);
- wall time of 500 trials of a 3-squeeze plan with 2 worker processes (target: < 60 s).

The machine's load average is printed too: on a shared machine the figures move with it.

Usage: ``.venv/bin/python benchmarks/bench_simulate.py [--quick] [--study | --agreement]``;
``--study`` prints the README's table of predicted against MuJoCo success for the catalogue
instead, ``--agreement`` the README's table of single squeezes against the model.
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact
from bayesgrasp.shapes import load
from bayesgrasp.sim.kinematic import simulate_kinematic


def load_note() -> str:
    try:
        one, five, _ = os.getloadavg()
    except OSError:  # pragma: no cover - not on every platform
        return "load average unknown"
    return f"load average {one:.2f} (1 min), {five:.2f} (5 min) on {os.cpu_count()} cores"


def bench_kinematic(trials: int) -> None:
    print(f"kinematic Monte Carlo, {trials:,} executions a run, best of 3 ({load_note()})")
    pb = Problem.build(load("triangle"))
    for opt in plan_exact(pb).options:
        best = math.inf
        for rep in range(3):
            t0 = time.perf_counter()
            simulate_kinematic(pb, opt, trials, rng=rep)
            best = min(best, time.perf_counter() - t0)
        print(
            f"  triangle, {opt.n_actions} squeeze(s): {trials / best:,.0f} executions/s "
            f"({best:.3f} s, including sampling and the summary)"
        )


def bench_mujoco(squeezes: int, trials: int) -> None:
    try:
        from bayesgrasp.sim import Squeezer, simulate_mujoco
    except ImportError:  # pragma: no cover
        print("MuJoCo not installed (extra `sim`): skipped")
        return
    part = load("triangle")
    sq = Squeezer(part, 0.001)
    rng = np.random.default_rng(0)
    starts = rng.uniform(0, 2 * math.pi, squeezes)
    t0 = time.perf_counter()
    sim_time = 0.0
    for th in starts:
        sim_time += sq.act(float(th)).sim_time
    dt = time.perf_counter() - t0
    print(f"MuJoCo, one process ({load_note()})")
    print(
        f"  {squeezes} squeezes of the triangle: {squeezes / dt:.1f} squeezes/s "
        f"({1000 * dt / squeezes:.1f} ms each, {sim_time / squeezes:.2f} s simulated each, "
        f"timestep {sq.params.timestep * 1000:g} ms)"
    )
    pb = Problem.build(part)
    plan = next(o for o in plan_exact(pb).options if o.n_actions == 3)
    t0 = time.perf_counter()
    res = simulate_mujoco(pb, plan, trials, rng=1, workers=2)
    dt = time.perf_counter() - t0
    print(f"  {trials} trials of a 3-squeeze plan, 2 workers: {dt:.1f} s wall ({load_note()})")
    print(
        f"    predicted success {res.predicted_success:.3f}, observed "
        f"{res.observed_success:.3f}, jams {res.jams}, near-boundary {res.near_boundary}"
    )


def study(trials: int, push_trials: int, offset_mm: float = 5.0, workers: int = 2) -> None:
    """The README's table: predicted against MuJoCo success of the catalogue's Bayes plans."""
    from bayesgrasp.shapes import names
    from bayesgrasp.sim import simulate_mujoco
    from bayesgrasp.sim.kinematic import SimulationResult

    def cell(r: SimulationResult) -> str:
        lo, hi = r.ci95
        return f"{r.observed_success:.3f} [{lo:.3f}, {hi:.3f}] ({r.jams}/{r.near_boundary})"

    print(
        f"Study: {trials} trials a cell ({push_trials} with push-grasps), seed 1, "
        f"{workers} workers ({load_note()})"
    )
    print(
        "| part | plan | predicted | MuJoCo, centred | "
        f"MuJoCo, {offset_mm:g} mm off centre |\n|---|---|---|---|---|"
    )
    t_all = time.perf_counter()
    for name in names():
        part = load(name)
        for actions, label in ((("squeeze",), "squeezes"), (("squeeze", "push-grasp"), "push")):
            pb = Problem.build(part, actions=actions)
            plan = plan_exact(pb).bayes_plan
            if label == "push" and "push-grasp" not in plan.kinds:
                print(f"| {name} | push-grasps | (the Bayes plan uses squeezes only) | | |")
                continue
            kinds = "+".join("P" if k == "push-grasp" else "S" for k in plan.kinds)
            row = [name, f"Bayes, {kinds}", f"{plan.success_probability:.3f}"]
            for off in (0.0, offset_mm / 1000.0):
                n = push_trials if label == "push" else trials
                r = simulate_mujoco(pb, plan, n, offset=off, rng=1, workers=workers)
                row.append(cell(r))
            print("| " + " | ".join(row) + " |", flush=True)
    print(
        f"({time.perf_counter() - t_all:.0f} s; cells: observed success [95% Wilson interval]"
        " (jams/near-boundary trials))"
    )


def agreement(n: int) -> None:
    """Single actions from random yaws away from basin boundaries: model against MuJoCo."""
    from bayesgrasp.geometry.polygon import Part
    from bayesgrasp.geometry.transfer import TransferFunction, squeeze_function
    from bayesgrasp.sim import Squeezer
    from bayesgrasp.sim.kinematic import boundary_distance

    try:
        from bayesgrasp.geometry.push import push_function, push_grasp_function
    except ImportError:  # pragma: no cover
        push_function = push_grasp_function = None  # type: ignore[assignment]

    margin = math.radians(2.5)
    rng0 = np.random.default_rng(5)
    randoms = [Part.from_points(rng0.random((10, 2)) * 0.05, name=f"r{i}") for i in range(8)]
    quad = Part.from_points([(0, 0), (50, 0), (40, 30), (5, 35)], name="quad", units="mm")

    def run(
        parts: list[Part], f_of: object, offset: float = 0.0, push: bool = False, count: int = n
    ) -> str:
        agree = total = stalls = 0
        errs: list[float] = []
        for part in parts:
            fs: list[TransferFunction] = f_of(part)  # type: ignore[operator]
            starts = np.random.default_rng(4).uniform(0, 2 * math.pi, 4 * count)
            away = np.ones(len(starts), bool)
            for f in fs:
                away &= boundary_distance(f.boundaries, starts) >= margin
            starts = starts[away][:count]
            sq = Squeezer(part, 0.001 if part.units == "mm" else 1.0)
            stable = squeeze_function(part.hull).stable
            for th in starts:
                out = sq.act(float(th), offset, push)
                err = abs(math.remainder(out.end - float(fs[0](th)), 2 * math.pi))
                off_stable = np.min(np.abs(np.remainder(out.end - stable + math.pi, 2 * math.pi)
                                           - math.pi))  # fmt: skip
                total += 1
                if err < math.radians(1.0) and out.settled:
                    agree += 1
                    errs.append(err)
                elif off_stable > math.radians(1.0) or not out.settled:
                    stalls += 1
        med = f"{math.degrees(float(np.median(errs))):.3f} deg" if errs else "-"
        return f"{agree}/{total} (median error {med}; of the rest, {stalls} stalled)"

    def sq_f(p: Part) -> list[TransferFunction]:
        return [squeeze_function(p.hull)]

    print(f"single actions, starts >= 2.5 deg from basin boundaries ({load_note()})")
    from bayesgrasp.shapes import names

    tri, rect = load("triangle"), load("rectangle")
    for name in names():
        print(f"  {name}, centred:", run([load(name)], sq_f), flush=True)
    print("  8 random 10-gons, 5 cm:", run(randoms, sq_f, count=max(10, n // 3)))
    print("  quadrilateral (0,0),(50,0),(40,30),(5,35) mm:", run([quad], sq_f))
    for off in (0.005, 0.010):
        print(f"  triangle, {off * 1000:g} mm off centre:", run([tri], sq_f, off))
        print(f"  rectangle, {off * 1000:g} mm off centre:", run([rect], sq_f, off))
    if push_grasp_function is not None:

        def pg_f(p: Part) -> list[TransferFunction]:
            return [push_grasp_function(p), push_function(p)]

        print(
            "  push-grasps, triangle and 4 random 10-gons:",
            run([tri, *randoms[:4]], pg_f, push=True, count=max(10, n // 4)),
        )


def main() -> None:
    quick = "--quick" in sys.argv
    if "--study" in sys.argv:
        study(60 if quick else 300, 30 if quick else 150)
        return
    if "--agreement" in sys.argv:
        agreement(20 if quick else 100)
        return
    bench_kinematic(200_000 if quick else 2_000_000)
    bench_mujoco(20 if quick else 100, 50 if quick else 500)


if __name__ == "__main__":
    main()
