"""Speed of MuJoCo drops of a solid part (target: 400 drops of a 1,000-triangle part in 60 s).

Two 1,000-triangle parts, each dropped ``--drops`` times (default 400) on one core:

* a pebble: the hull of 502 points on an ellipsoid of semi-axes 3, 2 and 1.5 (1,000
  triangles, all on its hull: the worst case for MuJoCo's collider, and a shape that rolls);
* a hex nut: 20 across flats, 8 thick, a 126-sided hole (1,008 triangles; its hull is small).

Prints the wall and CPU time of each study, the time per drop and how many drops settled.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_drops.py [--drops 400]``.
"""

from __future__ import annotations

import argparse
import math
import platform
import time

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull

from bayesgrasp.sim.drops import drop_poses

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def pebble(n: int = 502, seed: int = 0) -> tuple[FloatArray, IntArray]:
    """Hull of ``n`` points on an ellipsoid: ``2 n - 4`` outward triangles."""
    g = np.random.default_rng(seed)
    u = g.normal(size=(n, 3))
    pts = u / np.linalg.norm(u, axis=1)[:, None] * (3.0, 2.0, 1.5)
    hull = ConvexHull(pts)
    faces = hull.simplices.copy()
    for k, (a, b, c) in enumerate(faces):
        if np.cross(pts[b] - pts[a], pts[c] - pts[a]) @ hull.equations[k, :3] < 0:
            faces[k] = (a, c, b)
    return pts, faces


def nut(per_side: int = 21) -> tuple[FloatArray, IntArray]:
    """A hex nut with a ``6 * per_side``-sided hole (``48 * per_side`` triangles)."""
    r_out = 10.0 / math.cos(math.pi / 6)
    corners = [
        (r_out * math.cos(k * math.pi / 3), r_out * math.sin(k * math.pi / 3)) for k in range(7)
    ]
    outer = np.array(
        [
            np.add(corners[k], np.subtract(corners[k + 1], corners[k]) * t / per_side)
            for k in range(6)
            for t in range(per_side)
        ]
    )
    ang = np.arctan2(outer[:, 1], outer[:, 0])
    inner = 5.0 * np.c_[np.cos(ang), np.sin(ang)]
    n = len(outer)
    z0, z1 = np.zeros(n), np.full(n, 8.0)
    verts = np.vstack([np.c_[outer, z0], np.c_[outer, z1], np.c_[inner, z0], np.c_[inner, z1]])
    o0, o1, i0, i1 = 0, n, 2 * n, 3 * n
    faces = []
    for j in range(n):
        k = (j + 1) % n
        faces += [(o0 + j, o0 + k, o1 + k), (o0 + j, o1 + k, o1 + j)]
        faces += [(i0 + j, i1 + k, i0 + k), (i0 + j, i1 + j, i1 + k)]
        faces += [(o1 + j, o1 + k, i1 + k), (o1 + j, i1 + k, i1 + j)]
        faces += [(o0 + j, i0 + k, o0 + k), (o0 + j, i0 + j, i0 + k)]
    return verts, np.array(faces)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--drops", type=int, default=400)
    args = parser.parse_args()
    print(f"python {platform.python_version()}, {platform.machine()}, {args.drops} drops")
    v, f = pebble()
    normals = [ConvexHull(v).equations[:, :3]]
    hex_normals = np.array(
        [(0, 0, -1.0), (0, 0, 1.0)]
        + [(math.cos(a), math.sin(a), 0.0) for a in np.arange(6) * math.pi / 3 + math.pi / 6]
    )
    nv, nf = nut()
    for name, (verts, faces, com, nrm) in {
        "pebble": (v, f, np.zeros(3), normals[0]),
        "hex nut": (nv, nf, np.array([1.5, 0.0, 2.5]), hex_normals),
    }.items():
        wall, cpu = time.perf_counter(), time.process_time()
        study = drop_poses(verts, faces, com, nrm, args.drops, seed=0)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        print(
            f"{name}: {len(faces)} triangles, {args.drops} drops in {wall:.1f} s wall "
            f"({cpu:.1f} s CPU, {1000 * wall / args.drops:.1f} ms a drop); "
            f"{args.drops - study.unsettled} settled, {study.unmatched} unmatched"
        )


if __name__ == "__main__":
    main()
