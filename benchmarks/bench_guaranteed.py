"""Guaranteed and mixed-action planning speed on the seed's 2000-polygon set.

Target (issue 4): guaranteed squeeze plans and mixed squeeze / push-grasp Bayes plans for the
2000 polygons (10 uniform points in the unit square, fixed seed) in under 3 s on one core,
set-up included (hull, diameter, radius, squeeze and push-grasp functions). Prints wall and
CPU times (best of several repeats: the machine may be shared) and what the plans are like.

Run: ``.venv/bin/python benchmarks/bench_guaranteed.py [--polygons 2000] [--seed 1]
[--repeat 3]``
"""

from __future__ import annotations

import argparse
import math
import time
from collections import Counter
from collections.abc import Callable
from typing import Any

import numpy as np

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import CostModel, Problem
from bayesgrasp.paper.study import random_polygon
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.guaranteed import plan_guaranteed


def timed(fn: Callable[[], Any], repeat: int) -> tuple[float, float, Any]:
    """Best wall time and best CPU time over ``repeat`` calls, and the last result."""
    best_wall = best_cpu = math.inf
    out = None
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        best_wall = min(best_wall, time.perf_counter() - w)
        best_cpu = min(best_cpu, time.process_time() - c)
    return best_wall, best_cpu, out


def guaranteed_all(parts: list[Part]) -> list[tuple[int, int]]:
    """(sides, guaranteed squeeze-plan length) of every part, set-up included."""
    return [(p.hull.n_sides, plan_guaranteed(Problem.build(p)).n_actions) for p in parts]


def mixed_all(parts: list[Part], push_cost: float) -> list[tuple[float, float, int, float]]:
    """(Bayes cost, most-certain probability, most-certain length, its cost) per part."""
    out = []
    cost = CostModel({"push-grasp": push_cost})
    for p in parts:
        rep = plan_exact(Problem.build(p, cost=cost, actions=("squeeze", "push-grasp")))
        mc = rep.most_certain_plan
        out.append(
            (rep.bayes_plan.expected_cost, mc.success_probability, mc.n_actions, mc.expected_cost)
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--polygons", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    parts = [random_polygon(rng) for _ in range(args.polygons)]
    n = len(parts)
    print(f"{n} polygons (10 uniform points in the unit square, seed {args.seed})")

    w1, c1, g = timed(lambda: guaranteed_all(parts), args.repeat)
    lengths = Counter(k for _, k in g)
    worst = max(k - (2 * s - 1) for s, k in g)
    print(f"guaranteed squeeze plans: wall {w1:.3f} s, cpu {c1:.3f} s")
    print(f"  lengths {dict(sorted(lengths.items()))}; max (length - (2n - 1)) = {worst}")

    w2, c2, m = timed(lambda: mixed_all(parts, 1.0), args.repeat)
    print(
        f"mixed squeeze + push-grasp Bayes plans (push-grasp cost 1): wall {w2:.3f} s, "
        f"cpu {c2:.3f} s"
    )
    sure = sum(1 for _, p, _, _ in m if p >= 1.0 - 1e-12)
    print(
        f"  most certain plan reaches probability 1 for {sure}/{n}; its length "
        f"{dict(sorted(Counter(k for _, _, k, _ in m).items()))}"
    )
    print(f"total (guaranteed + mixed): wall {w1 + w2:.3f} s, cpu {c1 + c2:.3f} s")

    sq = [plan_exact(Problem.build(p)).bayes_plan.expected_cost for p in parts]
    mixed_cost = np.array([b for b, _, _, _ in m])
    squeeze_cost = np.array(sq)
    print(
        f"mean Bayes expected cost: squeeze only {squeeze_cost.mean():.4f}, with push-grasps "
        f"{mixed_cost.mean():.4f} (lower for {int(np.sum(mixed_cost < squeeze_cost - 1e-12))}/{n})"
    )
    w4, c4, m2 = timed(lambda: mixed_all(parts, 2.0), 1)
    print(
        f"push-grasp cost 2: wall {w4:.3f} s, cpu {c4:.3f} s; mean Bayes cost "
        f"{np.mean([b for b, _, _, _ in m2]):.4f}"
    )


if __name__ == "__main__":
    main()
