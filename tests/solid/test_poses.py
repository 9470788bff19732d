"""The quasi-static pose estimator against closed forms, an independent Monte Carlo of the
same model, trimesh, a brute-force projection and re-triangulations of the same solid."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from bayesgrasp.errors import PartError
from bayesgrasp.solid.poses import (
    footprint,
    hull_faces,
    pose_frame,
    quasi_static,
    resting_poses,
)

CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
BOX = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 4)], dtype=float)
TETRA = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
# An L-block (non-convex; only its hull and centre of mass matter): two boxes.
L_POINTS = np.array(
    [[x, y, z] for x in (0, 3) for y in (0, 1) for z in (0, 1)]
    + [[x, y, z] for x in (0, 1) for y in (0, 1) for z in (1, 3)],
    dtype=float,
)
L_COM = (3 * np.array([1.5, 0.5, 0.5]) + 2 * np.array([0.5, 0.5, 2.0])) / 5


def _by_normal(study) -> dict[tuple[float, ...], float]:
    return {tuple(np.round(p.normal, 6) + 0.0): p.probability for p in study.poses}


# ---------------------------------------------------------------------- closed forms


def test_cube_six_poses_of_one_sixth() -> None:
    study = resting_poses(CUBE, [0.5, 0.5, 0.5])
    assert len(study.poses) == 6
    assert_allclose(study.probabilities, 1 / 6, atol=1e-14)
    assert_allclose([p.com_height for p in study.poses], 0.5, atol=1e-14)


def test_regular_tetrahedron_four_poses_of_one_quarter() -> None:
    study = resting_poses(TETRA, [0, 0, 0])
    assert len(study.poses) == 4
    assert_allclose(study.probabilities, 0.25, atol=1e-14)
    assert_allclose([p.com_height for p in study.poses], 1 / math.sqrt(3), atol=1e-14)


def _rectangle_solid_angle(a: float, b: float, h: float) -> float:
    """Solid angle of an a x b rectangle seen from height h above its centre (closed form)."""
    x, y = a / 2, b / 2
    return 4 * math.asin(x * y / math.sqrt((x * x + h * h) * (y * y + h * h)))


def test_box_1x2x4_from_its_solid_angles() -> None:
    study = resting_poses(BOX, [0.5, 1, 2])
    expect = {
        (1.0, 0.0, 0.0): _rectangle_solid_angle(2, 4, 0.5),
        (0.0, 1.0, 0.0): _rectangle_solid_angle(1, 4, 1.0),
        (0.0, 0.0, 1.0): _rectangle_solid_angle(1, 2, 2.0),
    }
    assert_allclose(sum(expect.values()) * 2, 4 * math.pi, rtol=1e-14)
    got = _by_normal(study)
    assert len(got) == 6
    for n, omega in expect.items():
        for sign in (1, -1):
            key = tuple(sign * np.array(n) + 0.0)
            assert_allclose(got[key], omega / (4 * math.pi), rtol=1e-13)
    probs = study.probabilities
    assert np.all(np.diff(probs) <= 1e-15)  # sorted, most probable first


def test_off_centre_box_topples_to_the_low_side() -> None:
    # Centre of mass at height 0.2 of 4: the +z face's projection is inside every face
    # except none; every face is still stable (a box's projections stay inside).
    study = resting_poses(BOX, [0.5, 1, 0.2])
    assert len(study.poses) == 6
    assert study.poses[0].normal.tolist() == [0.0, 0.0, -1.0]
    assert_allclose(study.probabilities.sum(), 1, atol=1e-14)


def test_centre_of_mass_outside_is_refused() -> None:
    with pytest.raises(PartError, match="not strictly inside the convex hull"):
        resting_poses(CUBE, [0.5, 0.5, 1.0])
    with pytest.raises(PartError, match="span no volume"):
        hull_faces([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])


# ------------------------------------------------- an independent Monte Carlo of the model


def _planes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unique hull planes (n, d) with n . x <= d inside, found from Qhull's equations."""
    eq = ConvexHull(points).equations
    keys = {}
    for row in eq:
        k = tuple(np.round(row, 7))
        keys.setdefault(k, row)
    rows = np.array(list(keys.values()))
    return rows[:, :3] / np.linalg.norm(rows[:, :3], axis=1)[:, None], -rows[:, 3]


def _mc_rest(points: np.ndarray, com: np.ndarray, rng: np.random.Generator, n: int) -> dict:
    """Drop ``n`` times: a uniform random rotation, the face under the lowest point of the
    rotated solid along the ray from the centre of mass, then the topple walk, all by brute
    force in 3-D (face polygons from the points on each plane, edges by segment tests)."""
    normals, d = _planes(points)
    size = np.ptp(points, axis=0).max()
    on = [
        np.flatnonzero(np.abs(points @ nn - dd) < 1e-9 * size)
        for nn, dd in zip(normals, d, strict=True)
    ]

    def rest_of(f: int) -> int:
        for _ in range(len(normals) + 1):
            nn = normals[f]
            p = com + (d[f] - nn @ com) * nn  # projection of the centre of mass
            frame = pose_frame(nn)[:2]
            poly = points[on[f]]
            xy = (poly - p) @ frame.T
            hull2 = ConvexHull(xy)
            ring = xy[hull2.vertices]
            # inside strictly?
            inside = True
            for i in range(len(ring)):
                a, b = ring[i], ring[(i + 1) % len(ring)]
                if (b[0] - a[0]) * (0 - a[1]) - (b[1] - a[1]) * (0 - a[0]) <= 1e-12 * size:
                    inside = False
            if inside:
                return f
            # area centroid of the polygon (shoelace)
            x, y = ring[:, 0], ring[:, 1]
            cr = x * np.roll(y, -1) - np.roll(x, -1) * y
            area = cr.sum() / 2
            g = np.array([((x + np.roll(x, -1)) * cr).sum(), ((y + np.roll(y, -1)) * cr).sum()])
            g /= 6 * area
            # the polygon edge the segment g -> 0 crosses
            best, edge = np.inf, None
            for i in range(len(ring)):
                a, b = ring[i], ring[(i + 1) % len(ring)]
                m = np.array([[-g[0], a[0] - b[0]], [-g[1], a[1] - b[1]]])
                if abs(np.linalg.det(m)) < 1e-15:
                    continue
                t, s = np.linalg.solve(m, a - g)
                if -1e-12 <= s <= 1 + 1e-12 and 0 < t < best:
                    best, edge = t, (a, b)
            assert edge is not None
            ends = [p + e[0] * frame[0] + e[1] * frame[1] for e in edge]
            nxt = [
                k
                for k in range(len(normals))
                if k != f and all(abs(normals[k] @ q - d[k]) < 1e-9 * size for q in ends)
            ]
            assert len(nxt) == 1
            f = nxt[0]
        raise AssertionError("no rest")

    cache: dict[int, int] = {}
    counts: dict[tuple[float, ...], int] = {}
    rots = Rotation.random(n, random_state=rng)
    down = rots.inv().apply(np.array([0.0, 0.0, -1.0]))  # world "down" in body coordinates
    verts = points - com
    for u, r in zip(down, rots, strict=False):
        # the lowest point of the rotated solid lies on the first face the downward ray meets
        low = int(np.argmin(r.apply(verts)[:, 2]))
        hit = normals @ u
        t = np.where(hit > 0, (d - normals @ com) / np.where(hit > 0, hit, 1), np.inf)
        f = int(np.argmin(t))
        assert normals[f] @ (points[low] - com) > -1e-9  # the ray's face holds a lowest side
        if f not in cache:
            cache[f] = rest_of(f)
        key = tuple(np.round(normals[cache[f]], 6) + 0.0)
        counts[key] = counts.get(key, 0) + 1
    return counts


@pytest.mark.parametrize(
    ("points", "com"),
    [
        (BOX, np.array([0.7, 1.3, 1.1])),
        (L_POINTS, L_COM),
        (TETRA * [1, 1.5, 0.7], np.array([0.1, -0.2, 0.05])),
    ],
    ids=["leaning-box", "L-block", "tetra"],
)
def test_quasi_static_equals_monte_carlo_of_the_model(points, com, rng) -> None:
    n = 4000
    counts = _mc_rest(points, com, rng, n)
    got = _by_normal(resting_poses(points, com))
    assert set(counts) <= set(got)
    for key, p in got.items():
        k = counts.get(key, 0)
        sd = math.sqrt(p * (1 - p) / n)
        assert abs(k / n - p) < 4.5 * sd + 1e-3, (key, k / n, p)


def test_random_polytopes_against_monte_carlo(rng) -> None:
    pts = rng.normal(size=(14, 3)) * [1, 2, 3]
    com = pts[ConvexHull(pts).vertices].mean(axis=0) + rng.normal(size=3) * 0.2
    n = 3000
    counts = _mc_rest(pts, com, rng, n)
    for key, p in _by_normal(resting_poses(pts, com)).items():
        sd = math.sqrt(p * (1 - p) / n)
        assert abs(counts.get(key, 0) / n - p) < 4.5 * sd + 1e-3


# ------------------------------------------------------------------------ trimesh


def _trimesh_poses(points: np.ndarray, com: np.ndarray) -> dict:
    import trimesh
    from trimesh.poses import compute_stable_poses

    mesh = trimesh.Trimesh(points, ConvexHull(points).simplices).convex_hull
    tfs, probs = compute_stable_poses(mesh, center_mass=com)
    out: dict = {}
    for tf, p in zip(tfs, probs, strict=False):
        key = tuple(np.round(-tf[2, :3], 6) + 0.0)
        out[key] = out.get(key, 0.0) + float(p)
    return out


@pytest.mark.parametrize("seed", range(6))
def test_agrees_with_trimesh_on_triangular_hulls(seed: int) -> None:
    """Random points in general position: every hull face is a triangle, where trimesh's
    per-triangle walk is the model's."""
    g = np.random.default_rng(seed)
    pts = g.normal(size=(12, 3))
    com = pts[ConvexHull(pts).vertices].mean(axis=0) * 0.5
    ours = _by_normal(resting_poses(pts, com))
    theirs = _trimesh_poses(pts, com)
    assert ours.keys() == theirs.keys()
    for k in ours:
        assert_allclose(ours[k], theirs[k], atol=1e-9)


LEAN = np.array([[x + z, y, z] for x in (0, 2) for y in (0, 1) for z in (0, 1)], dtype=float)


def test_trimesh_is_wrong_on_the_boundary() -> None:
    """Where trimesh is not right: a face whose centre-of-mass projection lies exactly on its
    boundary. The model needs the projection strictly inside (on an edge the part is
    balanced on that edge, and any disturbance topples it); trimesh's barycentric test
    counts the boundary as inside and keeps the face as a pose. A leaning block whose centre
    of mass is exactly above the top edge of its slanted sides: ours (and the brute-force
    Monte Carlo) topple them, trimesh lists them with 0.086 each."""
    com = np.array([1.5, 0.5, 0.5])
    ours = _by_normal(resting_poses(LEAN, com))
    counts = _mc_rest(LEAN, com, np.random.default_rng(3), 4000)
    assert set(counts) == set(ours)
    for key, p in ours.items():
        sd = math.sqrt(p * (1 - p) / 4000)
        assert abs(counts.get(key, 0) / 4000 - p) < 4.5 * sd + 1e-3
    theirs = _trimesh_poses(LEAN, com)
    slanted = (-0.707107, 0.0, 0.707107)
    assert slanted not in ours
    assert_allclose(theirs[slanted], 0.0864, atol=1e-4)
    assert len(theirs) == len(ours) + 2


# --------------------------------------------------------------------- footprints


@pytest.mark.parametrize("seed", range(5))
def test_footprint_is_the_brute_force_projection(seed: int) -> None:
    g = np.random.default_rng(seed)
    pts = g.normal(size=(40, 3)) * [1, 2, 0.5]
    com = pts.mean(axis=0)
    study = resting_poses(pts, com)
    for pose in study.poses:
        # brute force: every point projected on the table plane, in the stated frame
        xs = np.array([[(q - com) @ pose.frame[0], (q - com) @ pose.frame[1]] for q in pts])
        ref = xs[ConvexHull(xs).vertices]
        assert_allclose(ConvexHull(pose.footprint).volume, ConvexHull(xs).volume, rtol=1e-12)
        assert {tuple(np.round(v, 9)) for v in pose.footprint} == {
            tuple(np.round(v, 9)) for v in ref
        }
        # the frame: orthonormal, right-handed, z up = minus the normal
        assert_allclose(pose.frame @ pose.frame.T, np.eye(3), atol=1e-12)
        assert_allclose(np.linalg.det(pose.frame), 1.0, atol=1e-12)
        assert_allclose(pose.frame[2], -pose.normal, atol=1e-12)
        # counter-clockwise
        x, y = pose.footprint.T
        assert (x * np.roll(y, -1) - np.roll(x, -1) * y).sum() > 0


def test_footprint_of_a_box_pose() -> None:
    fp = footprint(BOX, pose_frame([1, 0, 0]), [0.5, 1, 2])
    assert sorted(map(tuple, fp.tolist())) == [(-1, -2), (-1, 2), (1, -2), (1, 2)]


# ----------------------------------------------------------- triangulation independence


def _subdivide(points: np.ndarray, g: np.random.Generator, extra: int) -> np.ndarray:
    """The same solid with ``extra`` more points on its surface (on faces and edges): its
    hull is triangulated differently, its faces are the same."""
    hull = ConvexHull(points)
    tris = points[hull.simplices]
    pick = g.integers(0, len(tris), size=extra)
    w = g.dirichlet([1, 1, 1], size=extra)
    on_edge = g.random(extra) < 0.3
    w[on_edge, 2] = 0
    w[on_edge] /= w[on_edge].sum(axis=1)[:, None]
    new = np.einsum("ij,ijk->ik", w, tris[pick])
    return np.vstack([points, new])


@settings(max_examples=25)
@given(seed=st.integers(0, 2**32 - 1), extra=st.integers(1, 60))
def test_triangulation_does_not_change_the_poses(seed: int, extra: int) -> None:
    g = np.random.default_rng(seed)
    base = [BOX, CUBE * [3, 1, 1], L_POINTS][seed % 3]
    com = [np.array([0.6, 0.9, 1.7]), np.array([1.2, 0.45, 0.5]), L_COM][seed % 3]
    ref = resting_poses(base, com)
    got = resting_poses(_subdivide(base, g, extra), com)
    assert len(got.poses) == len(ref.poses)
    a, b = _by_normal(ref), _by_normal(got)
    assert a.keys() == b.keys()
    for k in a:
        assert_allclose(a[k], b[k], atol=1e-12)
    for p, q in zip(ref.poses, got.poses, strict=False):
        assert_allclose(p.footprint, q.footprint, atol=1e-9)  # same vertices, same start


def test_first_contact_sums_to_one_and_rest_is_stable() -> None:
    hull = hull_faces(L_POINTS)
    first, rest = quasi_static(hull, L_COM)
    assert_allclose(first.sum(), 1.0, atol=1e-14)
    assert np.all(rest[rest] == rest)


def test_perturbed_estimator_is_near_and_smooth() -> None:
    com = np.array([0.5, 1.0, 2.0])
    exact = _by_normal(resting_poses(BOX, com))
    pert = resting_poses(BOX, com, estimator="perturbed", sigma=0.01, samples=50, rng=1)
    assert_allclose(pert.probabilities.sum(), 1, atol=1e-12)
    for k, p in _by_normal(pert).items():
        assert abs(p - exact[k]) < 0.02
    with pytest.raises(PartError, match="sigma"):
        resting_poses(BOX, com, estimator="perturbed", sigma=0)
    with pytest.raises(PartError, match="estimator"):
        resting_poses(BOX, com, estimator="bogus")  # type: ignore[arg-type]


@settings(max_examples=30)
@given(seed=st.integers(0, 2**32 - 1))
def test_rigid_motions_move_the_poses_and_keep_the_probabilities(seed: int) -> None:
    """Rotating and translating the solid rotates the normals; probabilities, heights and
    footprint areas stay; the probabilities sum to one."""
    g = np.random.default_rng(seed)
    pts = g.normal(size=(int(g.integers(6, 30)), 3)) * g.uniform(0.2, 3, size=3)
    hull = ConvexHull(pts)
    w = g.dirichlet(np.ones(len(hull.vertices)))
    com = w @ pts[hull.vertices]  # strictly inside: every weight > 0
    rot = Rotation.random(random_state=g)
    shift = g.normal(size=3) * 10
    a = resting_poses(pts, com)
    b = resting_poses(rot.apply(pts) + shift, rot.apply(com) + shift)
    assert_allclose(a.probabilities.sum(), 1.0, atol=1e-12)
    assert len(a.poses) == len(b.poses)
    moved = {tuple(np.round(rot.apply(p.normal.copy()), 6) + 0.0): p for p in a.poses}
    for q in b.poses:
        key = tuple(np.round(q.normal, 6) + 0.0)
        p = moved[key]
        assert_allclose(q.probability, p.probability, atol=1e-11)
        assert_allclose(q.com_height, p.com_height, rtol=1e-9)
        assert_allclose(ConvexHull(q.footprint).volume, ConvexHull(p.footprint).volume, rtol=1e-9)


def test_perturbed_estimator_is_trimesh_form() -> None:
    """The perturbed estimator is the Monte Carlo average trimesh computes: quasi-static
    probabilities over centres of mass drawn from N(c, s^2 I), s = sigma * size (trimesh's
    ``sigma`` is that covariance, s^2). Two independent samplers of one expectation agree
    within their sampling error; on this wedge (its centre of mass near the edge of the
    slanted face) both move 0.1 away from the quasi-static estimate."""
    import trimesh
    from trimesh.poses import compute_stable_poses

    tri = np.array([[0, 0], [1, 0], [0.3, 1.0]])
    pts = np.array([[x, y, z] for x, z in tri for y in (0, 1)], dtype=float)
    com = np.array([0.14, 0.5, 0.3])
    sigma, n = 0.2, 1000
    ours = resting_poses(pts, com, estimator="perturbed", sigma=sigma, samples=n, rng=1)
    s = sigma * ours.hull.size
    mesh = trimesh.convex.convex_hull(pts)
    tfs, probs = compute_stable_poses(mesh, center_mass=com, sigma=s**2, n_samples=n, seed=2)
    theirs: dict[tuple[float, ...], float] = {}
    for tf, p in zip(tfs, probs, strict=True):
        normal = tf[:3, :3].T @ np.array([0.0, 0.0, -1.0])  # the face that rests on z = 0
        key = tuple(np.round(normal, 6) + 0.0)
        theirs[key] = theirs.get(key, 0.0) + float(p)
    mine, exact = _by_normal(ours), _by_normal(resting_poses(pts, com))
    assert set(theirs) == set(mine)
    for k, p in mine.items():
        assert abs(p - theirs[k]) < 0.02, (k, p, theirs[k])
    assert max(abs(mine[k] - exact[k]) for k in mine) > 0.08
