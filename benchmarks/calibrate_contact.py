"""Calibrate contact asynchrony: the ``q`` a jaw lag produces in MuJoCo (issue 14).

For each part and jaw lag, ``--trials`` squeezes with one jaw (drawn at random) starting
``lag`` seconds early, all from uniform starts where the pure squeeze and the push-grasp from
the leading side predict different orientations
(:func:`bayesgrasp.sim.asynchrony.measure_asynchrony`). Prints a Markdown table: the push the
leading jaw makes before the other meets the part (``jaw_speed * lag / 2``), outcomes matching
the push-grasp, the squeeze or neither, and ``q = push / (push + squeeze)`` with its 95%
Wilson interval.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/calibrate_contact.py [--trials 40]
[--lags 0,0.05,0.5,1,2,4,8] [--parts key,triangle,house] [--seed 0]``
"""

from __future__ import annotations

import argparse
import time

from bayesgrasp import shapes
from bayesgrasp.sim.asynchrony import measure_asynchrony
from bayesgrasp.sim.params import SimParams
from bayesgrasp.sim.scene import units_scale


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=40, help="squeezes per part and lag")
    ap.add_argument("--lags", default="0,0.05,0.5,1,2,4,8", help="jaw lags, seconds")
    ap.add_argument("--parts", default="key,triangle,house", help="catalogue parts")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    lags = [float(x) for x in args.lags.split(",")]
    sp = SimParams()
    print(
        f"jaw speed {sp.jaw_speed * 1000:g} mm/s; {args.trials} squeezes per row from starts "
        "where squeeze and push-grasp differ\n"
    )
    print("| part | across (mm) | lag (s) | push (mm) | push-grasp | squeeze | neither | q | 95% |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
    cpu0 = time.process_time()
    for name in args.parts.split(","):
        part = shapes.load(name)
        scale = units_scale(part.units)
        across = 2.0 * part.hull.size * scale * 1000.0
        for i, lag in enumerate(lags):
            r = measure_asynchrony(part, scale, lag, args.trials, sp, rng=args.seed + i)
            lo, hi = r.interval()
            print(
                f"| {name} | {across:.0f} | {lag:g} | {r.push_mm:.3g} | {r.push} | {r.squeeze} "
                f"| {r.other} | {r.q:.2f} | {lo:.2f}-{hi:.2f} |",
                flush=True,
            )
    print(f"\nCPU {time.process_time() - cpu0:.0f} s")


if __name__ == "__main__":
    main()
