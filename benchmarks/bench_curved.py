"""Curved parts: a DXF part of 200 arcs and 200 segments, squeezed and planned.

Target (issue 16): the squeeze function in under 50 ms and the plan in under 0.2 s. The part
is a cog-like ring: 400 points around a circle of radius 50 mm with a small radial wobble,
joined alternately by a segment and by an arc (bulges of both signs), written as one
LWPOLYLINE and read back by the DXF reader. Prints the best wall time of several repeats of
each step (the machine may be shared: the numbers are floors), and what the model found.

Run: ``.venv/bin/python benchmarks/bench_curved.py [--pieces 400] [--repeat 5]``
"""

from __future__ import annotations

import argparse
import io
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from bayesgrasp.geometry.curved import CurvedPart, squeeze_model
from bayesgrasp.io import read_part_bytes
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact


def timed(fn: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """Best wall time over ``repeat`` calls, and the last result."""
    best, out = math.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def cog_dxf(pieces: int, seed: int = 1) -> bytes:
    """A closed LWPOLYLINE of ``pieces`` pieces, every other one an arc."""
    import ezdxf

    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2 * math.pi, pieces, endpoint=False)
    r = 50.0 + 1.5 * np.sin(7 * t) + rng.uniform(-0.3, 0.3, pieces)
    bulges = np.where(np.arange(pieces) % 2 == 1, rng.uniform(-0.3, 0.3, pieces), 0.0)
    pts = [
        (float(x), float(y), float(b))
        for x, y, b in zip(r * np.cos(t), r * np.sin(t), bulges, strict=True)
    ]
    doc = ezdxf.new("R2010", units=4)
    doc.modelspace().add_lwpolyline(pts, format="xyb", close=True)
    text = io.StringIO()
    doc.write(text)
    return text.getvalue().encode()


def main() -> None:
    """Time reading, the squeeze function (hull, diameter, states) and planning."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pieces", type=int, default=400)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    data = cog_dxf(args.pieces)
    t_read, part = timed(lambda: read_part_bytes(data, "dxf", "cog.dxf"), args.repeat)
    if not isinstance(part, CurvedPart) or part.ring is None:
        raise SystemExit("the cog was not read as a curved part")

    def squeeze() -> Any:
        part._model.clear()  # the hull and diameter are cached on the part: start afresh
        return squeeze_model(part)

    t_squeeze, (d, s) = timed(squeeze, args.repeat)

    def plan() -> Any:
        part._model.clear()
        return plan_exact(Problem.build(part))

    t_plan, report = timed(plan, args.repeat)
    best = report.options[report.bayes]
    print(f"cog.dxf: {part.ring.n_arcs} arcs, {len(part.ring.points) - part.ring.n_arcs} segments")
    print(f"hull pieces {part.curved_hull.n_pieces}, extrema {len(d.extrema)}, states {s.n_states}")
    print(f"read DXF                 {1e3 * t_read:8.1f} ms")
    print(f"squeeze function         {1e3 * t_squeeze:8.1f} ms   (target < 50 ms)")
    print(f"Problem.build + plan     {1e3 * t_plan:8.1f} ms   (target < 200 ms)")
    print(
        f"Bayes plan: {best.n_actions} squeezes, p = {best.success_probability:.4f}, "
        f"E[cost] = {best.expected_cost:.3f}"
    )


if __name__ == "__main__":
    main()
