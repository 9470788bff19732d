"""How the catalogue's outlines were designed: shape generators, fits, and a check.

The seed prints no coordinates for its Table 1 parts, so each catalogue part is a
recognisable outline drawn by a small generator with a few free parameters (lengths in mm),
fitted so that the exact planner's row comes close to the printed one.

    python benchmarks/fit_catalogue.py               # check: regenerate every stored outline
                                                     # from its recorded parameters, print rows
    python benchmarks/fit_catalogue.py --fit house   # search the parameters again (minutes)

The fit minimises, over the generator's box of parameters (chosen to keep the part
recognisable), a score that is zero when every entry of our row rounds to the printed one
with 0.015 to spare; a part whose hull has the wrong number of sides is heavily penalised, and
so is any stable orientation closer than 2 degrees to an unstable equilibrium (the edge of
its basin): fits without that guard land on degenerate shapes whose row flips under a
hundredth of a millimetre (a stable orientation 0.1 degree from a maximum of the diameter
function is not something a gripper can rely on). Differential evolution, then bounded
Nelder-Mead. Many shapes fit equally well, so a new search may land on another one (the
triangle's finds (23.86, 37.42) as readily as the stored (15.55, 36.06)); the stored
parameters are the ones recorded below. The triangle's apex was solved for the two printed
entries and rounded to 0.01 mm; the tuning fork's dimensions were picked from a small grid
within its box (the first-squeeze cost depends mostly on its length over width). Not part
of the test run.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import resources

import numpy as np

from bayesgrasp.errors import BayesGraspError
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.transfer import squeeze_function
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.table1 import paper_row
from bayesgrasp.planning import execute_plan, plan_exact

Points = list[tuple[float, float]]


def rounded(points: Sequence[Sequence[float]], step: float) -> Points:
    """Move the outline to the first quadrant (touching both axes) and round it."""
    p = np.asarray(points, dtype=np.float64)
    p = np.round((p - p.min(axis=0)) / step) * step
    return [(float(round(x, 6)), float(round(y, 6))) for x, y in p]


def triangle(x: Sequence[float]) -> Points:
    """40 mm base, apex at (x0, x1)."""
    return [(0.0, 0.0), (40.0, 0.0), (round(x[0], 2), round(x[1], 2))]


def ic_chip(x: Sequence[float]) -> Points:
    """Body of a DIP package, 6.35 mm wide, length x0, pin-1 chamfer x1."""
    length, c = round(x[0], 2), round(x[1], 2)
    return [(0.0, 0.0), (length, 0.0), (length, 6.35), (c, 6.35), (0.0, round(6.35 - c, 2))]


def house(x: Sequence[float]) -> Points:
    """40 x 40 mm square, symmetric roof rising x0."""
    return [(0.0, 0.0), (40.0, 0.0), (40.0, 40.0), (20.0, round(40.0 + x[0], 2)), (0.0, 40.0)]


def example(x: Sequence[float]) -> Points:
    """Irregular pentagon: radii x0..x3 and angle offsets x4..x7 of four vertices (first fixed)."""
    r = np.concatenate([[1.0], x[:4]])
    a = 2.0 * np.pi * np.arange(5) / 5 + np.concatenate([[0.0], x[4:8]])
    return rounded(20.0 * np.c_[r * np.cos(a), r * np.sin(a)], 0.1)


def allen_wrench(x: Sequence[float]) -> Points:
    """L of 4 mm hex bar: long arm x0, short arm x1, outer-bend chamfer x2."""
    a, b, c = round(x[0], 2), round(x[1], 2), round(x[2], 2)
    return [(c, 0.0), (a, 0.0), (a, 4.0), (4.0, 4.0), (4.0, b), (0.0, b), (0.0, c)]


def tuning_fork(x: Sequence[float]) -> Points:
    """Stem width x0 and length x1, yoke height x2, prong length x3; 20 mm wide, 3.5 mm prongs."""
    s, ls, yoke, lp = (round(v, 2) for v in x[:4])
    y1, top = ls + yoke, ls + yoke + lp
    return [
        (10 - s / 2, 0.0), (10 + s / 2, 0.0), (10 + s / 2, ls), (20.0, y1), (20.0, top),
        (16.5, top), (16.5, y1 + 2.5), (3.5, y1 + 2.5), (3.5, top), (0.0, top), (0.0, y1),
        (10 - s / 2, ls),
    ]  # fmt: skip


def key(x: Sequence[float]) -> Points:
    """Head: octagon of radius 12 with radii x0..x6 (one corner hidden by the blade);
    blade: spine x7 above and edge x8 below the axis, length x9, tip bevel x10 and tip height
    x11 (fraction), stop height x12, tooth depth x13."""
    rad = x[:7]
    ht, hb, lb, tb, ytf, sh, dc = x[7:14]
    ang = [math.pi / 8 + k * math.pi / 4 for k in range(1, 8)]
    head = [(12 * r * math.cos(a), 12 * r * math.sin(a)) for r, a in zip(rad, ang, strict=True)]
    c = 12 * math.cos(math.pi / 8)
    pts = [(lb, -hb + ytf * (ht + hb)), (lb - tb, ht), (c + 4, ht), (c + 4, ht + sh), (c, ht + sh)]
    pts += [*head[:6], (c, -hb)]
    for i, xx in enumerate(np.linspace(c + 3, lb - tb - 1, 7)):
        pts.append((float(xx), -hb if i % 2 == 0 else -hb - dc))
    pts.append((lb - tb / 2, -hb))
    return rounded(pts, 0.1)


def hand(x: Sequence[float]) -> Points:
    """Palm width x0 and height x1, middle finger x2, finger spread x3 (rad), thumb width x4,
    length x5, angle x6 (rad) and height x7 (fraction of the palm), little finger x8."""
    w, h, fl, spread, tw, tl, ta, th, lit = x
    fw = w / 4.4
    pts: list[tuple[float, float]] = [(w / 2 * 0.8, 0.0), (w / 2, h * 0.45)]
    lengths = [fl * 0.75 * lit, fl * 0.93, fl, fl * 0.92]  # little, ring, middle, index
    for i, (length, a) in enumerate(zip(lengths, (-1.5, -0.5, 0.5, 1.5), strict=True)):
        base = np.array([w * 0.5 - fw * 0.55 - i * fw * 1.02, h])
        d = np.array([-math.sin(a * spread), math.cos(a * spread)])
        n = np.array([d[1], -d[0]])
        tip = base + length * d
        for q in (
            base + n * fw / 2, tip + n * fw / 2 - d * fw * 0.3, tip + n * fw * 0.2,
            tip - n * fw * 0.2, tip - n * fw / 2 - d * fw * 0.3, base - n * fw / 2,
        ):  # fmt: skip
            pts.append((float(q[0]), float(q[1])))
    base = np.array([-w / 2, th * h])
    d = np.array([-math.sin(ta), math.cos(ta)])
    n = np.array([d[1], -d[0]])
    for q in (
        np.array([-w / 2, th * h + tw * 0.8]), base + tl * d + n * tw * 0.5,
        base + tl * d - n * tw * 0.5, base - n * tw * 0.5 + np.array([0.0, -tw * 0.5]),
        np.array([-w / 2, h * 0.2]), np.array([-w / 2 * 0.8, 0.0]),
    ):  # fmt: skip
        pts.append((float(q[0]), float(q[1])))
    return rounded(pts, 0.1)


@dataclass(frozen=True)
class Design:
    """A generator, the box it is fitted in, and the parameters of the stored outline."""

    make: Callable[[Sequence[float]], Points]
    bounds: list[tuple[float, float]]
    params: list[float]
    target: tuple[float, ...] | None = None  # default: the printed row
    counts: tuple[int, ...] | None = None  # orientations after each squeeze (Figure 1)


KEY_HEAD_BOUNDS = [(0.8, 1.2)] * 7
KEY_BLADE_BOUNDS = [(2.2, 4.5), (2.2, 4.5), (26.0, 45.0), (0.8, 5.0), (0.2, 0.9), (0.0, 3.0)]
KEY_BOUNDS = KEY_HEAD_BOUNDS + KEY_BLADE_BOUNDS
KEY_BOUNDS.append((0.5, 2.0))
KEY_PARAMS = [0.8729, 1.0324, 1.0348, 0.8345, 1.193, 1.0414, 0.9763, 4.4314, 3.6805]
KEY_PARAMS.extend([26.8912, 1.2202, 0.4769, 2.7448, 1.739])
HAND_BOUNDS = [(70.0, 95.0), (80.0, 110.0), (60.0, 90.0), (0.0, 0.25), (18.0, 26.0)]
HAND_BOUNDS.extend([(45.0, 70.0), (0.4, 1.1), (0.2, 0.6), (0.8, 1.1)])
HAND_PARAMS = [92.8213, 105.239, 81.6058, 0.1937, 23.6506, 67.6617, 0.7941, 0.391, 1.068]

DESIGNS: dict[str, Design] = {
    "triangle": Design(triangle, [(0, 40), (10, 60)], [15.55, 36.06]),
    "rectangle": Design(
        lambda x: [(0.0, 0.0), (round(x[0], 2), 0.0), (round(x[0], 2), 20.0), (0.0, 20.0)],
        [(20, 60)],
        [31.0],
    ),
    "ic-chip": Design(ic_chip, [(8, 25), (0.1, 1.0)], [19.05, 0.3]),
    "house": Design(house, [(5, 40)], [18.66]),
    "example": Design(
        example,
        [(0.5, 1.5)] * 4 + [(-0.5, 0.5)] * 4,
        [0.7403, 0.7124, 0.7251, 1.2753, 0.4872, -0.4941, 0.014, 0.2098],
        counts=(6, 4, 2),
    ),
    "allen-wrench": Design(allen_wrench, [(48, 80), (16, 28), (0.2, 3.8)], [48.0, 27.8, 0.64]),
    "tuning-fork": Design(tuning_fork, [(4, 6), (5, 30), (1.5, 10), (20, 80)], [6, 10, 3.5, 30]),
    # The printed last entry, 8.2, is below the attainable 1/2; aim at 8.0 (see key.json).
    "key": Design(key, KEY_BOUNDS, KEY_PARAMS, target=(9.1, 6.2, 8.0)),
    "hand": Design(hand, HAND_BOUNDS, HAND_PARAMS),
}


def margin_deg(part: Part) -> float:
    """Least angle between a stable orientation and the edge of its basin (degrees)."""
    f = squeeze_function(part.hull)
    return float(np.degrees(np.min(np.minimum(f.stable - f.basin_lo, f.basin_hi - f.stable))))


def depth(part: Part) -> float:
    """Least depth of a minimum of the diameter function below its lower neighbouring maximum,
    relative to the part's size."""
    f = squeeze_function(part.hull)
    d = diameter_function(part.hull)
    return float(np.min(np.minimum(d(f.basin_lo), d(f.basin_hi)) - d(f.stable)) / part.hull.size)


def orientation_counts(pb: Problem) -> tuple[int, ...]:
    """Distinct orientations after each squeeze of the most certain plan."""
    plan = plan_exact(pb).most_certain_plan
    theta = np.linspace(0, 2 * math.pi, 4001, endpoint=False) + 1e-4
    return tuple(
        len(np.unique(np.round(execute_plan(pb, plan.steps[:k], theta), 6)))
        for k in range(1, plan.n_actions + 1)
    )


def score(design: Design, name: str, x: Sequence[float], spare: float = 0.015) -> float:
    paper = paper_row(name)
    target = design.target or paper.costs
    try:
        part = Part.from_points(design.make(x))
    except BayesGraspError:
        return 1e3
    pb = Problem.build(part)
    costs = [o.expected_cost for o in plan_exact(pb).options]
    m = min(len(costs), len(target))
    s = sum(max(0.0, abs(costs[i] - target[i]) - (0.05 - spare)) ** 2 for i in range(m))
    s += 1e-4 * sum((costs[i] - target[i]) ** 2 for i in range(m))
    s += 4.0 * abs(len(costs) - len(target))
    s += 0.1 * max(0.0, 2.0 - margin_deg(part)) ** 2
    if part.hull.n_sides != paper.sides:
        s += 50 + 10 * abs(part.hull.n_sides - paper.sides)
    if design.counts is not None and orientation_counts(pb) != design.counts:
        s += 2.0
    return s


def fit(name: str, seed: int) -> list[float]:
    from scipy.optimize import differential_evolution, minimize

    design = DESIGNS[name]

    def f(x: np.ndarray) -> float:
        return score(design, name, x)

    res = differential_evolution(f, design.bounds, seed=seed, maxiter=150, popsize=30, polish=False)
    res2 = minimize(f, res.x, method="Nelder-Mead", bounds=design.bounds)
    best = res2.x if res2.fun <= res.fun else res.x
    print(f"{name}: score {min(res.fun, res2.fun):.3g}, parameters {np.round(best, 4).tolist()}")
    print(json.dumps([[round(x, 3), round(y, 3)] for x, y in design.make(best)]))
    return [float(v) for v in best]


def check() -> int:
    bad = 0
    for name, design in DESIGNS.items():
        data = json.loads(
            resources.files("bayesgrasp.shapes").joinpath(f"{name}.json").read_text("utf-8")
        )
        stored = np.asarray(data["vertices"], dtype=np.float64)
        made = np.asarray(design.make(design.params), dtype=np.float64)
        same = made.shape == stored.shape and bool(np.allclose(made, stored, atol=1e-9))
        bad += not same
        part = Part.from_points(stored)
        pb = Problem.build(part)
        costs = [round(o.expected_cost, 3) for o in plan_exact(pb).options]
        print(
            f"{name:<13} regenerated {'yes' if same else 'NO '}  sides {part.hull.n_sides:>2}  "
            f"ours {costs}  printed {list(paper_row(name).costs)}  "
            f"margin {margin_deg(part):5.2f} deg  depth {depth(part):.4f}"
            + (f"  counts {orientation_counts(pb)}" if design.counts else "")
        )
    return bad


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fit", choices=sorted(DESIGNS), help="search this part's parameters")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    if args.fit:
        fit(args.fit, args.seed)
    else:
        raise SystemExit(check())


if __name__ == "__main__":
    main()
