"""MuJoCo drops of solid parts (bayesgrasp.sim.drops) against the quasi-static model.

The quasi-static prediction here is written independently of the library's estimator:
hull faces (coplanar triangles merged), each face's solid angle seen from the centre of
mass (Van Oosterom and Strackee 1983, summed over its triangles) over 4 pi, and an
unstable face (the centre of mass's projection outside it) handing its share over the edge
that the segment from its area centroid to that projection crosses, until a face holds it.
Drops marked ``physics`` run MuJoCo; the long statistical ones are also ``slow``.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial import ConvexHull

from bayesgrasp.errors import BayesGraspError, SimulationError
from bayesgrasp.sim.drops import DropStudy, drop_poses
from bayesgrasp.sim.mesh_scene import mass_properties, mesh_body

HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None
needs_mujoco = pytest.mark.skipif(not HAVE_MUJOCO, reason="MuJoCo is not installed")
MESHES = Path(__file__).resolve().parents[2] / "examples" / "meshes"


# --- solids -------------------------------------------------------------------------------


def hull_solid(points: list[tuple[float, float, float]]) -> tuple[np.ndarray, np.ndarray]:
    """A convex solid as outward triangles (the hull of its points)."""
    p = np.asarray(points, dtype=float)
    hull = ConvexHull(p)
    faces = hull.simplices.copy()
    for k, (a, b, c) in enumerate(faces):
        if np.cross(p[b] - p[a], p[c] - p[a]) @ hull.equations[k, :3] < 0:
            faces[k] = (a, c, b)
    return p, faces


def box(a: float, b: float, c: float) -> tuple[np.ndarray, np.ndarray]:
    return hull_solid([(x, y, z) for x in (0, a) for y in (0, b) for z in (0, c)])


def read_stl(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Binary STL to (vertices, faces), merging equal corners."""
    raw = path.read_bytes()
    n = int(np.frombuffer(raw, "<u4", 1, 80)[0])
    rec = np.frombuffer(raw, [("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")], n, 84)
    corners = rec["v"].reshape(-1, 3).astype(float)
    verts, inv = np.unique(corners, axis=0, return_inverse=True)
    return verts, inv.reshape(-1, 3)


# --- an independent quasi-static prediction ----------------------------------------------


def triangle_solid_angle(c: np.ndarray, tri: np.ndarray) -> float:
    a, b, d = tri - c
    la, lb, ld = (np.linalg.norm(x) for x in (a, b, d))
    num = abs(a @ np.cross(b, d))
    den = la * lb * ld + (a @ b) * ld + (a @ d) * lb + (b @ d) * la
    return 2.0 * math.atan2(num, den)


def cross2(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def quasi_static(verts: np.ndarray, com: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stable faces' outward normals and probabilities (most probable first)."""
    hull = ConvexHull(verts)
    keys = np.round(hull.equations, 9)
    groups: dict[tuple[float, ...], list[int]] = {}
    for k, key in enumerate(map(tuple, keys)):
        groups.setdefault(key, []).append(k)
    faces = []
    for ks in groups.values():
        normal = hull.equations[ks[0], :3]
        tris = verts[hull.simplices[ks]]
        omega = sum(triangle_solid_angle(com, t) for t in tris)
        ids = set(hull.simplices[ks].ravel().tolist())
        faces.append({"normal": normal, "omega": omega, "ids": ids, "tris": tris})
    total = sum(f["omega"] for f in faces)
    assert abs(total - 4 * math.pi) < 1e-6  # the faces cover the sphere of directions

    def frame(f: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = f["normal"]
        u = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        u /= np.linalg.norm(u)
        return n, u, np.cross(n, u)

    def outcome(i: int, seen: int = 0) -> int:
        f = faces[i]
        n, u, w = frame(f)
        pts = sorted(f["ids"])
        q = np.array([[verts[j] @ u, verts[j] @ w] for j in pts])
        order = ConvexHull(q).vertices  # counter-clockwise in (u, w)
        if np.cross(u, w) @ n < 0:
            order = order[::-1]
        poly = q[order]
        pc = np.array([com @ u, com @ w])
        m = len(poly)
        edge_side = [cross2(poly[(k + 1) % m] - poly[k], pc - poly[k]) for k in range(m)]
        sign = np.sign(sum(cross2(poly[k], poly[(k + 1) % m]) for k in range(m)))
        if all(s * sign > 1e-12 for s in edge_side):
            return i
        area = np.array([np.linalg.norm(np.cross(t[1] - t[0], t[2] - t[0])) for t in f["tris"]])
        cen3 = (area[:, None] * f["tris"].mean(axis=1)).sum(0) / area.sum()
        cen = np.array([cen3 @ u, cen3 @ w])
        for k in range(m):
            a, b = poly[k], poly[(k + 1) % m]
            d1, d2 = pc - cen, b - a
            den = d1[0] * d2[1] - d1[1] * d2[0]
            if abs(den) < 1e-15:
                continue
            t = ((a - cen)[0] * d2[1] - (a - cen)[1] * d2[0]) / den
            s = ((a - cen)[0] * d1[1] - (a - cen)[1] * d1[0]) / den
            if 0 <= t <= 1 and 0 <= s <= 1:
                ends = {pts[order[k]], pts[order[(k + 1) % m]]}
                j = next(g for g, h in enumerate(faces) if g != i and ends <= h["ids"])
                assert seen < len(faces)
                return outcome(j, seen + 1)
        raise AssertionError("no edge crossed")

    prob: dict[int, float] = {}
    for i, f in enumerate(faces):
        j = outcome(i)
        prob[j] = prob.get(j, 0.0) + f["omega"] / (4 * math.pi)
    ranked = sorted(prob, key=lambda j: -prob[j])
    return np.array([faces[j]["normal"] for j in ranked]), np.array([prob[j] for j in ranked])


def total_variation(study: DropStudy, predicted: np.ndarray) -> float:
    """Half the L1 distance, the unmatched drops counted as a pose nobody predicted."""
    freq = study.frequencies()
    return 0.5 * (float(np.abs(freq - predicted).sum()) + study.unmatched / study.trials)


# --- the prediction itself (no MuJoCo) ----------------------------------------------------


def test_quasi_static_closed_forms() -> None:
    """Cube 6 x 1/6; a 1 x 2 x 4 box from the rectangle's solid angle on its axis."""
    _, p = quasi_static(box(1, 1, 1)[0], np.array([0.5, 0.5, 0.5]))
    assert_allclose(p, [1 / 6] * 6, atol=1e-12)
    _, p = quasi_static(box(1, 2, 4)[0], np.array([0.5, 1.0, 2.0]))

    def omega(a: float, b: float, d: float) -> float:  # rectangle 2a x 2b at distance d
        return 4 * math.atan(a * b / (d * math.sqrt(a * a + b * b + d * d)))

    want = sorted([omega(1, 2, 0.5), omega(0.5, 2, 1), omega(0.5, 1, 2)] * 2, reverse=True)
    assert_allclose(p, np.array(want) / (4 * math.pi), atol=1e-12)


def test_quasi_static_topples_a_leaning_block() -> None:
    """A block sheared past its base: it cannot stand on its base or top."""
    v, _ = hull_solid(
        [(0, 0, 0), (3, 0, 0), (0, 2, 0), (3, 2, 0), (4, 0, 3), (7, 0, 3), (4, 2, 3), (7, 2, 3)]
    )
    n, p = quasi_static(v, v.mean(axis=0))
    assert_allclose(p.sum(), 1.0, atol=1e-12)
    assert len(p) == 4 and np.all(np.abs(n[:, 2]) < 0.99)


# --- mass properties and validation -------------------------------------------------------


def test_mass_properties_against_sampling() -> None:
    """Volume, centroid and inertia of the L-bracket against a Monte Carlo of its solid."""
    v, f = read_stl(MESHES / "l_bracket.stl")
    vol, c, inertia = mass_properties(v, f)
    assert_allclose(vol, 40 * 6 * 20 + 6 * 24 * 20, rtol=1e-12)
    g = np.random.default_rng(5)
    pts = g.uniform([0, 0, 0], [40, 20, 30], size=(400_000, 3))
    inside = pts[(pts[:, 2] <= 6) | (pts[:, 0] <= 6)]
    assert_allclose(c, [(240 * 20 + 144 * 3) / 384, 10, (240 * 3 + 144 * 18) / 384], atol=1e-12)
    assert_allclose(c, inside.mean(axis=0), atol=0.15)  # about 5 standard errors
    d = inside - inside.mean(axis=0)
    sampled = (np.eye(3) * (d * d).sum(1).mean() - d.T @ d / len(d)) * vol
    assert_allclose(inertia, sampled, rtol=0.02, atol=0.01 * np.abs(sampled).max())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mass_properties_follow_rigid_motions_and_flips(seed: int) -> None:
    """Rotated and moved: the volume stays, the centroid moves, the inertia turns;
    faces listed inward give the same answer."""
    from scipy.spatial.transform import Rotation

    v, f = read_stl(MESHES / "hex_nut.stl")
    vol, c, inertia = mass_properties(v, f)
    r = Rotation.random(random_state=seed).as_matrix()
    shift = np.array([3.0, -7.0, 11.0])
    vol2, c2, inertia2 = mass_properties(v @ r.T + shift, f[:, ::-1])
    assert_allclose(vol2, vol, rtol=1e-10)
    assert_allclose(c2, r @ c + shift, atol=1e-9)
    assert_allclose(inertia2, r @ inertia @ r.T, atol=1e-8 * np.abs(inertia).max())
    assert_allclose(c, [0, 0, 4], atol=1e-9)  # the nut's solid is symmetric


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"vertices": [[0, 0]]}, r"`vertices` must have shape \(N, 3\); got shape \(1, 2\)"),
        ({"faces": [[0, 1, 2]]}, r"`faces` must have shape \(M, 3\) with M >= 4"),
        ({"faces": [[0, 1, 9]] * 4}, r"`faces` index vertices 0..7; got 0..9"),
        ({"com": [9, 9, 9]}, r"`com` \[9.0, 9.0, 9.0\] lies outside the mesh's hull"),
        ({"com": [np.nan, 0, 0]}, r"`com` must be finite"),
        ({"normals": [[0, 0, 2]]}, r"`normals` must be unit vectors; got lengths \[2.0\]"),
        ({"trials": 0}, r"`trials` must be an integer >= 1; got 0"),
        ({"trials": 2.5}, r"`trials` must be an integer >= 1; got 2.5"),
        ({"seed": -1}, r"`seed` must be an integer >= 0; got -1"),
        ({"height": -0.1}, r"`height` must be a finite number >= 0; got -0.1"),
        ({"restitution": 1.0}, r"`restitution` must be a finite number >= 0 and <= 0.99; got 1.0"),
        ({"friction": 0}, r"`friction` must be a finite number > 0; got 0"),
        ({"size": 0.0}, r"`size` must be a finite number > 0 \(metres\) or None; got 0.0"),
    ],
)
def test_drop_poses_refuses_bad_input(kwargs: dict, message: str) -> None:
    v, f = box(1, 1, 1)
    args = {"vertices": v, "faces": f, "com": [0.5, 0.5, 0.5], "normals": np.eye(3), "trials": 3}
    args.update(kwargs)
    with pytest.raises(SimulationError, match=message) as info:
        drop_poses(**args)
    assert isinstance(info.value, BayesGraspError) and "\n" not in str(info.value)


def test_flat_mesh_is_refused() -> None:
    v = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)], dtype=float)
    f = np.array([(0, 1, 2), (1, 3, 2), (0, 2, 1), (1, 2, 3)])
    with pytest.raises(SimulationError, match=r"the mesh encloses no volume"):
        mesh_body(v, f, (0.5, 0.5, 0))


def test_drop_study_is_read_only_and_adds_up() -> None:
    counts = np.array([2, 1])
    study = DropStudy(counts, 1, 4)
    counts[0] = 9  # the caller's array stays theirs
    assert study.counts.tolist() == [2, 1] and not study.counts.flags.writeable
    with pytest.raises(SimulationError, match=r"must add up to trials \(5\); got 4"):
        DropStudy(np.array([2, 1]), 1, 5)


def test_intervals_are_clopper_pearson() -> None:
    """Against the binomial tails they are defined by (each tail exactly 2.5%)."""
    from scipy.stats import binom

    study = DropStudy(np.array([0, 7, 93]), 0, 100)
    ci = study.intervals(0.95)
    assert ci[0, 0] == 0 and ci[2, 1] <= 1
    assert_allclose(binom.sf(6, 100, ci[1, 0]), 0.025, atol=1e-9)
    assert_allclose(binom.cdf(7, 100, ci[1, 1]), 0.025, atol=1e-9)
    assert_allclose(study.frequencies(), [0, 0.07, 0.93])
    with pytest.raises(SimulationError, match=r"`confidence` must be in \(0, 1\); got 1"):
        study.intervals(1)


# --- MuJoCo -------------------------------------------------------------------------------


@pytest.mark.physics
@needs_mujoco
def test_drops_are_deterministic_and_scale_free() -> None:
    """Same seed, same drops; millimetres and metres give the same poses (scaled to size)."""
    v, f = box(10, 20, 40)
    n, _ = quasi_static(v, v.mean(axis=0))
    a = drop_poses(v, f, v.mean(axis=0), n, 12, seed=3)
    b = drop_poses(v, f, v.mean(axis=0), n, 12, seed=3)
    c = drop_poses(v / 1000, f, v.mean(axis=0) / 1000, n, 12, seed=3)
    assert a.counts.tolist() == b.counts.tolist() == c.counts.tolist()
    assert a.counts.sum() + a.unmatched == 12 and a.unsettled == 0
    assert a.settings["height"] == 0.02 and a.settings["restitution"] == 0.0


@pytest.mark.physics
@needs_mujoco
def test_settled_part_rests_on_the_table() -> None:
    """An off-centre centre of mass is where MuJoCo puts it: the loaded face lands down more."""
    v, f = read_stl(MESHES / "hex_nut.stl")
    study = drop_poses(v, f, [1.5, 0.0, 2.5], [[0, 0, -1], [0, 0, 1]], 100, seed=0)
    assert study.counts.sum() >= 75  # a nut lands flat nearly always
    assert study.counts[0] > study.counts[1]  # quasi-static: 38% and 27%; 1,000 drops: 59%, 25%


@pytest.mark.physics
@needs_mujoco
def test_box_drops_agree_with_solid_angles_quick() -> None:
    v, f = box(10, 20, 40)
    n, p = quasi_static(v, v.mean(axis=0))
    study = drop_poses(v, f, v.mean(axis=0), n, 60, seed=11)
    assert total_variation(study, p) < 0.15  # 60 drops: sampling alone gives about 0.07


AGREEMENT = [  # solid, centre of mass, largest total variation allowed over 400 drops
    ("box 1x2x4", lambda: box(10, 20, 40), 0.05),
    (
        "square pyramid",
        lambda: hull_solid([(0, 0, 0), (4, 0, 0), (0, 4, 0), (4, 4, 0), (2, 2, 3)]),
        0.05,
    ),
]


@pytest.mark.physics
@pytest.mark.slow
@pytest.mark.parametrize(("name", "solid", "bound"), AGREEMENT, ids=[a[0] for a in AGREEMENT])
def test_drops_agree_with_quasi_static_on_simple_solids(name: str, solid, bound: float) -> None:
    v, f = solid()
    com = mass_properties(v, f)[1]
    n, p = quasi_static(v, com)
    study = drop_poses(v, f, com, n, 400, seed=7)
    assert total_variation(study, p) < bound


DIFFERENT = [  # the model is known to miss these by 0.08 to 0.26: the test records by how much
    ("wedge", lambda: read_stl(MESHES / "wedge.stl"), None, 0.35),
    ("L-bracket", lambda: read_stl(MESHES / "l_bracket.stl"), None, 0.35),
    (
        "leaning block",
        lambda: hull_solid(
            [(0, 0, 0), (3, 0, 0), (0, 2, 0), (3, 2, 0), (2, 0, 4), (5, 0, 4), (2, 2, 4), (5, 2, 4)]
        ),
        None,
        0.35,
    ),
    ("hex nut", lambda: read_stl(MESHES / "hex_nut.stl"), (1.5, 0.0, 2.5), 0.35),
    ("die", lambda: read_stl(MESHES / "die.stl"), None, 0.1),
]


@pytest.mark.physics
@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "solid", "com", "bound"), DIFFERENT, ids=[d[0] for d in DIFFERENT]
)
def test_drops_against_quasi_static_on_harder_shapes(name, solid, com, bound) -> None:
    v, f = solid()
    c = mass_properties(v, f)[1] if com is None else np.asarray(com, dtype=float)
    n, p = quasi_static(v, c)
    study = drop_poses(v, f, c, n, 400, seed=7)
    tv = total_variation(study, p)
    print(f"{name}: total variation {tv:.3f}")
    assert tv < bound
    if name == "hex nut":  # a flat part lands flat more often than solid angles say
        assert study.frequencies()[:2].sum() > p[:2].sum() + 0.1
