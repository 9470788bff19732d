"""Write the example meshes the documentation uses (binary STL, millimetres).

Run from the repository root: ``python examples/make_meshes.py``. It writes, in
``examples/meshes/``:

- ``die.stl``: a die-like block, a 16 mm cube whose corners are cut 1.5 mm deep (six faces
  it rests on, eight small corner faces it never rests on);
- ``l_bracket.stl``: an L-bracket, legs 40 mm and 30 mm long, 6 mm thick, 20 mm wide;
- ``wedge.stl``: a wedge, a right triangle of legs 40 mm and 15 mm extruded 20 mm;
- ``hex_nut.stl``: a hex nut, 20 mm across flats, 8 mm thick, a 10 mm hole (24 sides),
  with its centre of mass moved off centre to ``(1.5, 0.0, 2.5)`` mm (an insert on one
  side, below the middle): the solid's centroid is ``(0, 0, 4)``; give it with ``--com``.

The meshes are closed and outward-facing; the others' centres of mass are their solids'.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull

OUT = Path(__file__).resolve().parent / "meshes"
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def hull_mesh(points: FloatArray) -> tuple[FloatArray, IntArray]:
    """Return the convex hull of points as outward-facing triangles."""
    hull = ConvexHull(points)
    faces = hull.simplices.copy()
    for k, (a, b, c) in enumerate(faces):
        n = np.cross(points[b] - points[a], points[c] - points[a])
        if n @ hull.equations[k, :3] < 0:
            faces[k] = (a, c, b)
    used = np.unique(faces)
    remap = np.full(len(points), -1)
    remap[used] = np.arange(len(used))
    return points[used], remap[faces]


def ear_clip(poly: FloatArray) -> list[tuple[int, int, int]]:
    """Triangles of a simple counter-clockwise polygon (ear clipping, O(n^3))."""
    idx = list(range(len(poly)))
    tris = []

    def cross(o: FloatArray, a: FloatArray, b: FloatArray) -> float:
        return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))

    while len(idx) > 3:
        for k in range(len(idx)):
            i, j, m = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            if cross(poly[i], poly[j], poly[m]) <= 0:
                continue
            others = [q for q in idx if q not in (i, j, m)]
            inside = any(
                cross(poly[i], poly[j], poly[q]) >= 0
                and cross(poly[j], poly[m], poly[q]) >= 0
                and cross(poly[m], poly[i], poly[q]) >= 0
                for q in others
            )
            if not inside:
                tris.append((i, j, m))
                idx.pop(k)
                break
    tris.append((idx[0], idx[1], idx[2]))
    return tris


def extrude(poly: FloatArray, depth: float) -> tuple[FloatArray, IntArray]:
    """Extrude a counter-clockwise polygon of the xz-plane along +y, from 0 to ``depth``.

    The polygon is given as (x, z) pairs; the solid spans y in [0, depth].
    """
    n = len(poly)
    front = np.c_[poly[:, 0], np.zeros(n), poly[:, 1]]  # y = 0
    back = np.c_[poly[:, 0], np.full(n, depth), poly[:, 1]]
    verts = np.vstack([front, back])
    faces: list[tuple[int, int, int]] = []
    for a, b, c in ear_clip(poly):
        # (x, z) counter-clockwise seen from -y is clockwise seen from +y: the y = 0 cap
        # faces -y with this order.
        faces.append((a, b, c))
        faces.append((n + a, n + c, n + b))
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, n + i, n + j), (i, n + j, j)]
    return verts, np.array(faces)


def ring(outer: FloatArray, inner: FloatArray, height: float) -> tuple[FloatArray, IntArray]:
    """Return the solid between two counter-clockwise rings of equal length, z in [0, height]."""
    n = len(outer)
    o0, o1 = np.c_[outer, np.zeros(n)], np.c_[outer, np.full(n, height)]
    i0, i1 = np.c_[inner, np.zeros(n)], np.c_[inner, np.full(n, height)]
    verts = np.vstack([o0, o1, i0, i1])
    O0, O1, I0, I1 = 0, n, 2 * n, 3 * n
    faces = []
    for j in range(n):
        k = (j + 1) % n
        faces += [(O0 + j, O0 + k, O1 + k), (O0 + j, O1 + k, O1 + j)]  # outer wall
        faces += [(I0 + j, I1 + k, I0 + k), (I0 + j, I1 + j, I1 + k)]  # hole wall
        faces += [(O1 + j, O1 + k, I1 + k), (O1 + j, I1 + k, I1 + j)]  # top
        faces += [(O0 + j, I0 + k, O0 + k), (O0 + j, I0 + j, I0 + k)]  # bottom
    return verts, np.array(faces)


def oriented(verts: FloatArray, faces: IntArray) -> IntArray:
    """Check the mesh is closed (every edge twice, opposite ways); turn it outward."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    directed = {tuple(e) for e in edges.tolist()}
    if len(directed) != len(edges) or any((b, a) not in directed for a, b in directed):
        raise ValueError("mesh is not closed and consistently oriented")
    tri = verts[faces]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
    return faces if volume > 0 else faces[:, ::-1].copy()


def centroid(verts: FloatArray, faces: IntArray) -> FloatArray:
    """Return the centroid of a closed, outward solid (signed tetrahedra from the origin)."""
    tri = verts[faces]
    det = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    return (det[:, None] * tri.sum(axis=1)).sum(axis=0) / (4.0 * det.sum())


def write_stl(path: Path, verts: FloatArray, faces: IntArray, name: str) -> None:
    """Binary STL: an 80-byte header, a triangle count, 50 bytes a triangle."""
    tri = verts[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    rec = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"], rec["v"] = normal, tri
    header = f"bayesgrasp example {name}, millimetres".encode().ljust(80, b" ")
    path.write_bytes(header + np.uint32(len(faces)).tobytes() + rec.tobytes())


def meshes() -> dict[str, tuple[FloatArray, IntArray, FloatArray]]:
    """Each example's vertices, faces and centre of mass (millimetres)."""
    out = {}
    a, b = 8.0, 6.5  # half side, and where the corner cuts meet the edges
    pts = {
        tuple(np.roll(np.array([sx * a, sy * a, sz * b]), r))
        for r in range(3)
        for sx in (-1, 1)
        for sy in (-1, 1)
        for sz in (-1, 1)
    }
    v, f = hull_mesh(np.array(sorted(pts)) + a)
    out["die"] = (v, f, centroid(v, f))
    lpoly = np.array([(0, 0), (40, 0), (40, 6), (6, 6), (6, 30), (0, 30)], dtype=float)
    v, f = extrude(lpoly, 20.0)
    out["l_bracket"] = (v, f, centroid(v, f))
    v, f = extrude(np.array([(0, 0), (40, 0), (0, 15)], dtype=float), 20.0)
    out["wedge"] = (v, f, centroid(v, f))
    per_side, r_out, r_in = 4, 10.0 / math.cos(math.pi / 6), 5.0
    corners = np.array(
        [(r_out * math.cos(k * math.pi / 3), r_out * math.sin(k * math.pi / 3)) for k in range(7)]
    )
    outer = np.vstack(
        [
            corners[k] + (corners[k + 1] - corners[k]) * t / per_side
            for k in range(6)
            for t in range(per_side)
        ]
    )
    angles = np.arctan2(outer[:, 1], outer[:, 0])
    inner = r_in * np.c_[np.cos(angles), np.sin(angles)]
    v, f = ring(outer, inner, 8.0)
    out["hex_nut"] = (v, f, np.array([1.5, 0.0, 2.5]))
    return out


def main() -> None:
    """Write every example mesh (the centres of mass are in docs/guide/mesh-physics.md)."""
    OUT.mkdir(exist_ok=True)
    for name, (v, f, com) in meshes().items():
        f = oriented(v, f)
        write_stl(OUT / f"{name}.stl", v, f, name)
        where = [round(float(x), 6) for x in com]
        print(f"{name}: {len(f)} triangles, centre of mass {where} mm")  # noqa: T201


if __name__ == "__main__":
    main()
