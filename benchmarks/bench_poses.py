"""Speed of the resting-pose estimator and of pose-recognition policies.

- the quasi-static poses of a 100,000-triangle mesh (target: under 1 s): an ellipsoid of
  semi-axes 1, 1.5, 2.5 (every triangle a hull face, so nothing is merged and every face is
  walked) with its centre of mass moved off centre, and a faceted solid of the same size (a
  box whose faces are split into 100,000 coplanar triangles: the merging is the work);
- a pose-recognition policy, depth 3, exact widths, for example solids (a wedge, an
  L-bracket, a die-like block with a chamfered corner, a hex prism with an off-centre mass;
  target: under 1 s), for ``--goal-pose 0`` and ``any``.

Each figure is wall time and CPU time of this process (``time.process_time``): on a shared,
loaded machine the CPU time is the one-core figure the targets speak of.

Run: ``python benchmarks/bench_poses.py``.
"""

from __future__ import annotations

import time

import numpy as np
import trimesh
from scipy.spatial import ConvexHull

from bayesgrasp.solid.mesh import solid_from_arrays
from bayesgrasp.solid.policy import plan_pose_policy
from bayesgrasp.solid.poses import resting_poses


def timed(label: str, work):  # type: ignore[no-untyped-def]
    w0, c0 = time.perf_counter(), time.process_time()
    out = work()
    print(f"{label}: {time.perf_counter() - w0:.3f} s wall, {time.process_time() - c0:.3f} s CPU")
    return out


def ellipsoid(n_triangles: int) -> trimesh.Trimesh:
    # An icosphere has 20 * 4^k triangles; a UV sphere gets closer to the count asked.
    rows = round(np.sqrt(n_triangles / 4))
    m = trimesh.creation.uv_sphere(count=[rows, rows])
    m.apply_scale([1.0, 1.5, 2.5])
    return m


def split_box(n_triangles: int, rng: np.random.Generator) -> np.ndarray:
    """Points of a 1 x 2 x 4 box: corners plus points on its faces (coplanar hull triangles)."""
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 4)], float)
    n = n_triangles // 2
    face = rng.integers(0, 6, size=n)
    uv = rng.random((n, 2))
    pts = np.empty((n, 3))
    axis, side = face // 2, face % 2
    dims = np.array([1.0, 2.0, 4.0])
    for a in range(3):
        others = [i for i in range(3) if i != a]
        sel = axis == a
        pts[sel, a] = side[sel] * dims[a]
        pts[sel, others[0]] = uv[sel, 0] * dims[others[0]]
        pts[sel, others[1]] = uv[sel, 1] * dims[others[1]]
    return np.vstack([corners, pts])


def examples() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Example solids (vertices) and centres of mass."""
    wedge = np.array([[x, y, z] for x, z in ((0, 0), (3, 0), (0, 1.5)) for y in (0, 1)], float)
    bar = [[x, y, z] for x in (0, 3) for y in (0, 1) for z in (0, 0.5)]
    post = [[x, y, z] for x in (0, 0.5) for y in (0, 1) for z in (0.5, 2)]
    bracket = np.array(bar + post, float)
    bracket_com = (1.5 * np.array([1.5, 0.5, 0.25]) + 0.75 * np.array([0.25, 0.5, 1.25])) / 2.25
    die = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1.1)], float)
    die = np.vstack([die[:-1], [[1, 0.8, 1.1], [0.8, 1, 1.1], [1, 1, 0.9]]])  # one chamfer
    hexp = np.array(
        [[np.cos(a), np.sin(a), z] for a in np.arange(6) * np.pi / 3 for z in (0, 0.8)], float
    )
    return {
        "wedge": (wedge, wedge[ConvexHull(wedge).vertices].mean(axis=0) * 0 + [1, 0.5, 0.5]),
        "L-bracket": (bracket, bracket_com),
        "die": (die, np.array([0.5, 0.5, 0.55])),
        "hex nut (off-centre mass)": (hexp, np.array([0.25, 0.1, 0.4])),
    }


def main() -> None:
    rng = np.random.default_rng(0)
    m = ellipsoid(100_000)
    print(f"ellipsoid: {len(m.faces)} triangles, {len(m.vertices)} vertices")
    solid = timed(
        "  checks and centre of mass (solid_from_arrays)",
        lambda: solid_from_arrays(m.vertices, m.faces),
    )
    com = solid.center_of_mass + np.array([0.1, -0.2, 0.3])
    study = timed("  quasi-static poses", lambda: resting_poses(solid.vertices, com))
    print(f"  {len(study.poses)} stable poses, most probable {study.poses[0].probability:.4f}")
    pts = split_box(100_000, rng)
    h = ConvexHull(pts)
    print(f"split box: {len(pts)} points, {len(h.simplices)} hull triangles")
    study = timed("  quasi-static poses", lambda: resting_poses(pts, [0.6, 0.9, 1.7]))
    print(
        f"  {len(study.poses)} stable poses: "
        + ", ".join(f"{p.probability:.4f}" for p in study.poses)
    )
    for name, (verts, c) in examples().items():
        study = resting_poses(verts, c)
        for goal in (0, None):
            pol = timed(
                f"{name}: {len(study.poses)} poses, policy depth 3, exact widths, goal pose "
                f"{'any' if goal is None else goal}",
                lambda study=study, goal=goal: plan_pose_policy(study, "width", goal_pose=goal),
            )
            print(
                f"  expected cost {pol.expected_cost:.4f}, success {pol.success_probability:.4f}"
                " a cycle"
            )


if __name__ == "__main__":
    main()
