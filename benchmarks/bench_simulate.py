"""Speed of plan execution: kinematic Monte Carlo and MuJoCo physics.

Prints:
- kinematic plan executions per second (one core; numpy), for plans of 1 to 3 squeezes;
- MuJoCo squeezes per second in one process (and simulated seconds per squeeze);
- wall time of 500 trials of a 3-squeeze plan with 2 worker processes (target: < 60 s).

The machine's load average is printed too: on a shared machine the figures move with it.

Usage: ``.venv/bin/python benchmarks/bench_simulate.py [--quick]
[--study | --agreement | --compare | --accuracy]``; ``--study`` prints the README's table of
predicted against MuJoCo success for the catalogue instead, ``--agreement`` the README's
table of single squeezes against the model, ``--compare`` the trials per second per core of
the batched engine (rollout, the settled stop, the default settings) beside the former
engine (one trial at a time from Python, 1 ms steps, jaws at 1 cm/s, 0.1 s settle) on every
catalogue part's Bayes plans, squeezes (200 trials, ``simulate``'s default) and push-grasps
(16) apart, ``--validation`` the guide's validation study (1,000 trials every row), and
``--accuracy`` the study that chose the settings: single actions from random yaws under the
default settings (and the former ones) against a reference of fine steps and slow jaws,
with every disagreement.
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


def legacy_params() -> object:
    """The former engine's settings: 1 ms steps, jaws at 1 cm/s, 3 mm clearance, 0.1 s settle,
    0.1 kg jaws for every part."""
    from bayesgrasp.sim.params import SimParams

    return SimParams(
        timestep=0.001,
        jaw_speed=0.01,
        jaw_damping=20.0,
        clearance=0.003,
        settle_time=0.1,
        check_every=10,
        part_speed=1e3,  # the former test read the jaws only
        part_spin=1e3,
        scale_jaw_mass=False,  # 0.1 kg jaws whatever the part
    )


def reference_params() -> object:
    """The accuracy study's reference: 0.5 ms steps, jaws at 5 mm/s, 0.1 s settle."""
    from bayesgrasp.sim.params import SimParams

    return SimParams(
        timestep=0.0005, jaw_speed=0.005, jaw_damping=20.0, clearance=0.003, settle_time=0.1
    )


def study_parts() -> list[tuple[str, object, float]]:
    """(name, part, metres per unit) of the catalogue and the curved examples."""
    from pathlib import Path

    from bayesgrasp.io import read_part
    from bayesgrasp.shapes import names
    from bayesgrasp.sim.scene import units_scale

    out: list[tuple[str, object, float]] = [(n, load(n), 0.001) for n in names()]
    ex = Path(__file__).resolve().parents[1] / "examples"
    for f in sorted([*ex.glob("*.svg"), *ex.glob("*.dxf")]):
        part = read_part(f)
        sc = units_scale(part.units) if part.units in ("m", "cm", "mm", "in") else 0.001
        out.append((f.stem, part, sc))
    return out


def accuracy(n_squeeze: int, n_push: int, seed: int = 1, cands: dict | None = None) -> None:  # type: ignore[type-arg]
    """Final stable orientation of single actions: candidate settings against the reference.

    ``cands``: name -> SimParams (default: the defaults and the former engine's settings);
    the disagreements of every candidate but ``former`` are listed.
    """
    from bayesgrasp.angles import circle_distance
    from bayesgrasp.sim.params import SimParams
    from bayesgrasp.sim.result import boundary_distance
    from bayesgrasp.sim.rollout import BatchSqueezer

    ref = reference_params()
    cands = cands or {"default": SimParams(), "former": legacy_params()}
    print(
        f"Accuracy study: {n_squeeze} squeezes and {n_push} push-grasps a part from random "
        f"yaws (seed {seed}); reference: 0.5 ms steps, jaws at 5 mm/s ({load_note()})"
    )
    totals = {k: [0, 0, 0.0] for k in cands}
    t_ref = 0.0
    worse: list[str] = []
    for name, part, sc in study_parts():
        pb = Problem.build(part, actions=("squeeze", "push-grasp"))  # type: ignore[arg-type]
        rng = np.random.default_rng(seed)
        for kind, push, n in (("squeeze", False, n_squeeze), ("push-grasp", True, n_push)):
            th = rng.uniform(0, 2 * math.pi, n)
            tf = pb.transfer(kind)

            def classes(end: np.ndarray, ok: np.ndarray, tol: float, tf: object = tf) -> np.ndarray:
                d = circle_distance(end[:, None], tf.stable)  # type: ignore[attr-defined]
                c = d.argmin(axis=1)
                c[d.min(axis=1) > tol] = -1  # jammed away from every stable orientation
                c[~ok] = -2  # did not settle
                return c

            t0 = time.perf_counter()
            r = BatchSqueezer(part, sc, ref).act(th, push=push)  # type: ignore[arg-type]
            t_ref += time.perf_counter() - t0
            cr = classes(r.end, r.settled, ref.jam_tol)  # type: ignore[attr-defined]
            cells = [f"{name} {kind}: reference jams {(cr < 0).sum()}/{n}"]
            for key, sp in cands.items():
                o = BatchSqueezer(part, sc, sp).act(  # type: ignore[arg-type]
                    th, push=push, stable=pb.states.stable
                )  # jammed actions retried with slow jaws, as simulate_mujoco does
                co = classes(o.end, o.settled, sp.jam_tol)  # type: ignore[attr-defined]
                same = co == cr
                totals[key][0] += int(same.sum())
                totals[key][1] += n
                totals[key][2] += float(o.sim_time.sum())
                cells.append(f"{key} {int(same.sum())}/{n}")
                if key != "former":
                    for i in np.flatnonzero(~same):
                        b = math.degrees(float(boundary_distance(tf.boundaries, th[i : i + 1])[0]))
                        worse.append(
                            f"  [{key}] {name} {kind} from {math.degrees(th[i]):.2f} deg "
                            f"({b:.2f} deg from a basin boundary): reference "
                            f"{math.degrees(r.end[i]):.2f} deg (class {cr[i]}), {key} "
                            f"{math.degrees(o.end[i]):.2f} deg (class {co[i]})"
                        )
            print("  " + "; ".join(cells), flush=True)
    for key, (same, n, sim) in totals.items():
        print(
            f"{key}: {same}/{n} = {same / n:.4f} agree with the reference "
            f"({sim / n:.3f} s simulated an action)"
        )
    print(f"reference: {t_ref:.0f} s of wall time")
    print("disagreements (class -1: jammed, -2: did not settle):")
    print("\n".join(worse) or "  none")


def compare(trials: int, push_trials: int) -> None:
    """Trials per second per core: the batched engine beside the former one, in one run."""
    import mujoco
    import mujoco.rollout  # noqa: F401 - imported once here, not inside either engine's time

    from bayesgrasp.shapes import names
    from bayesgrasp.sim import simulate_mujoco

    old = legacy_params()
    print(f"Trials per second per core, one thread each, seed 1 ({load_note()})")
    print("| part | plan | trials | former engine | batched engine | ratio |")
    print("|---|---|---|---|---|---|")
    sums: dict[str, list[float]] = {"squeezes": [0, 0.0, 0.0], "push-grasps": [0, 0.0, 0.0]}
    for name in names():
        part = load(name)
        for actions, label in ((("squeeze",), "squeezes"), (("push-grasp",), "push-grasps")):
            pb = Problem.build(part, actions=actions)
            plan = plan_exact(pb).bayes_plan
            n = trials if label == "squeezes" else push_trials
            t0 = time.process_time()
            simulate_mujoco(pb, plan, n, params=old, rng=1, method="stepped")  # type: ignore[arg-type]
            t_old = time.process_time() - t0
            t0 = time.process_time()
            simulate_mujoco(pb, plan, n, rng=1)
            t_new = time.process_time() - t0
            sums[label][0] += n
            sums[label][1] += t_old
            sums[label][2] += t_new
            print(
                f"| {name} | {label}, {plan.n_actions} action(s) | {n} | {n / t_old:.1f}/s | "
                f"{n / t_new:.1f}/s | {t_old / t_new:.1f}x |",
                flush=True,
            )
    for label, (n, t_old, t_new) in sums.items():
        print(
            f"{label}: former {n / t_old:.1f} trials/s, batched {n / t_new:.1f} trials/s "
            f"per core (CPU time): {t_old / t_new:.1f}x"
        )
    print(f"({load_note()})")


def validation(trials: int, push_trials: int, policy_cycles: int) -> None:
    """The guide's validation study: predicted against MuJoCo success, table and figure.

    Prints a Markdown table (docs/guide/physics-validation.md) and draws
    docs/figures/physics-validation.png: every catalogue part's and curved example's Bayes
    plan, noise-aware plans under their noise, push-grasp plans and a sensing policy.
    """
    from pathlib import Path

    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy import plan_noisy
    from bayesgrasp.planning.policy import plan_policy
    from bayesgrasp.sim import simulate_mujoco
    from bayesgrasp.sim.noise import GripperNoise
    from bayesgrasp.sim.policy import mujoco_sensor, simulate_policy_mujoco
    from bayesgrasp.sim.result import with_prediction
    from bayesgrasp.sim.stats import wilson_interval

    rows: list[tuple[str, str, str, int, float, float, float, float, int, str]] = []
    t_all = time.perf_counter()

    def add(group: str, name: str, plan: str, r: object) -> None:
        lo, hi = r.ci95  # type: ignore[attr-defined]
        flags = r.assumption_flags  # type: ignore[attr-defined]
        rows.append(
            (group, name, plan, r.trials, r.predicted_success, r.observed_success, lo, hi,  # type: ignore[attr-defined]
             r.jams, "; ".join(flags) or "-")  # type: ignore[attr-defined]
        )  # fmt: skip
        print("| " + " | ".join(_cells(rows[-1])) + " |", flush=True)

    print(f"Validation study, seed 1 ({load_note()})")
    print("| group | part | plan | trials | predicted | MuJoCo | 95% interval | jams | flags |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, part, sc in study_parts():
        group = "catalogue" if name in {n for n in _names()} else "curved example"
        pb = Problem.build(part)  # type: ignore[arg-type]
        plan = plan_exact(pb).bayes_plan
        add(group, name, _kinds(plan), simulate_mujoco(pb, plan, trials, rng=1, scale=sc))
    turn = TurnNoise("normal", math.radians(3.0))
    for name in ("triangle", "rectangle", "house"):
        pb = Problem.build(load(name))
        opt = plan_noisy(pb, NoiseModel(turn)).bayes_plan.option
        r = simulate_mujoco(pb, opt, trials, noise=GripperNoise.of(turn), rng=1)
        add("noise-aware, 3 deg turn error", name, _kinds(opt),
            with_prediction(r, pb, NoiseModel(turn)))  # fmt: skip
    for name in ("triangle", "rectangle", "house", "key"):
        pb = Problem.build(load(name), actions=("push-grasp",))
        plan = plan_exact(pb).bayes_plan
        add("push-grasp", name, _kinds(plan), simulate_mujoco(pb, plan, push_trials, rng=1))
    part = load("house")
    pb = Problem.build(part)
    pol = plan_policy(pb, mujoco_sensor(part, 0.001), 3)
    sim = simulate_policy_mujoco(pb, pol, policy_cycles, rng=1)
    lo, hi = wilson_interval(sim.successes, sim.cycles)
    rows.append(
        ("sensing policy", "house", "width sensor, 3 actions", sim.cycles,
         pol.success_probability, sim.observed_success, lo, hi, sim.jams, "-")
    )  # fmt: skip
    print("| " + " | ".join(_cells(rows[-1])) + " |")
    inside = sum(r[6] <= r[4] <= r[7] for r in rows)
    print(
        f"({inside} of {len(rows)} predictions inside the 95% interval; "
        f"{time.perf_counter() - t_all:.0f} s; {load_note()})"
    )
    _figure(rows, Path(__file__).resolve().parents[1] / "docs" / "figures")


def _names() -> list[str]:
    from bayesgrasp.shapes import names

    return list(names())


def _kinds(plan: object) -> str:
    kinds = plan.kinds  # type: ignore[attr-defined]
    return "+".join("P" if k == "push-grasp" else "S" for k in kinds)


def _cells(r: tuple[str, str, str, int, float, float, float, float, int, str]) -> list[str]:
    g, name, plan, n, pred, obs, lo, hi, jams, flags = r
    return [g, name, plan, str(n), f"{pred:.3f}", f"{obs:.3f}", f"[{lo:.3f}, {hi:.3f}]",
            str(jams), flags]  # fmt: skip


def _figure(
    rows: list[tuple[str, str, str, int, float, float, float, float, int, str]], folder: object
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 5.5))
    groups = sorted({r[0] for r in rows})
    for g, marker in zip(groups, "osD^v", strict=False):
        sel = [r for r in rows if r[0] == g]
        x = np.array([r[4] for r in sel])
        y = np.array([r[5] for r in sel])
        err = np.array([[r[5] - r[6] for r in sel], [r[7] - r[5] for r in sel]])
        ax.errorbar(x, y, yerr=err, fmt=marker, ms=5, capsize=2, label=g)
    ax.plot([0, 1], [0, 1], "k--", lw=0.8)
    ax.set(xlim=(0, 1.02), ylim=(0, 1.02), xlabel="predicted success (model)",
           ylabel="observed success (MuJoCo), 95% interval")  # fmt: skip
    ax.set_aspect("equal")
    ax.legend(loc="upper left", fontsize=8)
    path = folder / "physics-validation.png"  # type: ignore[operator]
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    print(f"figure: {path}")


def main() -> None:
    quick = "--quick" in sys.argv
    if "--validation" in sys.argv:
        validation(100 if quick else 1000, 40 if quick else 1000, 60 if quick else 1000)
        return
    if "--accuracy" in sys.argv:
        accuracy(10 if quick else 40, 5 if quick else 20)
        return
    if "--compare" in sys.argv:
        compare(10 if quick else 200, 4 if quick else 16)
        return
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
