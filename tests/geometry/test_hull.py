"""Tests of bayesgrasp.geometry.hull: Andrew's monotone chain and its vectorised twin.

The reference :func:`monotone_chain` is checked against an independent definition (a
vertex of the hull is a point no other point lies beyond, seen from every edge) and against
Qhull; the vectorised :func:`monotone_chain_vectorised` must give the reference's indices,
one for one; the plain-Python hull of a few points must give the array hull's vertices.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal
from numpy.typing import NDArray

from bayesgrasp.geometry.hull import (
    drop_near_collinear,
    hull_indices,
    hull_of_few,
    monotone_chain,
    monotone_chain_vectorised,
    polygon_area_centroid,
    pruned_half_chain,
)
from bayesgrasp.geometry.polygon import ConvexPolygon, Part
from bayesgrasp.io import points as points_module
from bayesgrasp.tolerance import Tolerance
from strategies import convex_points, lattice_points

FloatArray = NDArray[np.float64]


def sorted_pairs(pts: FloatArray) -> tuple[NDArray[np.intp], list[tuple[float, float]]]:
    """``np.lexsort``'s order of the points and the points in that order, as pairs."""
    order = np.lexsort((pts[:, 1], pts[:, 0]))
    return order, list(zip(pts[order, 0].tolist(), pts[order, 1].tolist(), strict=True))


def sequential_hull(points: FloatArray) -> NDArray[np.intp]:
    """The reference chain's hull indices into ``points``."""
    order, pairs = sorted_pairs(points)
    return order[np.array(monotone_chain(pairs), dtype=np.intp)]


def strict_vertices(points: FloatArray) -> set[tuple[float, float]]:
    """The hull's vertices by definition, in O(N^4): brute force, exact on lattice points.

    A distinct point is a vertex of the hull iff it is not in the convex hull of the other
    points; in the plane (Caratheodory) iff no triangle of three others holds it (closed)
    and it lies strictly inside no segment between two others.
    """
    pts = sorted({(float(x), float(y)) for x, y in points})
    out = set()
    for p in pts:
        others = [q for q in pts if q != p]
        inside = False
        for i, a in enumerate(others):
            for j in range(i + 1, len(others)):
                b = others[j]
                cr = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
                if cr == 0 and min(a, b) < p < max(a, b):
                    inside = True
                    break
                for c in others[j + 1 :]:
                    d1 = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
                    d2 = (c[0] - b[0]) * (p[1] - b[1]) - (c[1] - b[1]) * (p[0] - b[0])
                    d3 = (a[0] - c[0]) * (p[1] - c[1]) - (a[1] - c[1]) * (p[0] - c[0])
                    if (d1 >= 0 and d2 >= 0 and d3 >= 0) or (d1 <= 0 and d2 <= 0 and d3 <= 0):
                        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
                        if area != 0:
                            inside = True
                            break
                if inside:
                    break
            if inside:
                break
        if not inside:
            out.add(p)
    return out


# --------------------------------------------------------------------------- the reference


@settings(max_examples=150, deadline=None)
@given(pts=lattice_points(min_size=3, max_size=16, bound=4))
def test_reference_chain_is_the_hull_by_definition(pts: FloatArray) -> None:
    _, pairs = sorted_pairs(pts)
    chain = monotone_chain(pairs)
    got = [pairs[i] for i in chain]
    assert len(set(got)) == len(got)  # no vertex twice
    assert set(got) == strict_vertices(pts)
    if len(got) >= 3:  # counter-clockwise, every turn strictly left
        for k in range(len(got)):
            a, b, c = got[k - 2], got[k - 1], got[k]
            assert (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0
    assert chain[0] == 0  # from the lexicographically least point


def test_reference_chain_matches_qhull(rng: np.random.Generator) -> None:
    spatial = pytest.importorskip("scipy.spatial")
    for _ in range(100):
        pts = rng.normal(size=(int(rng.integers(3, 400)), 2))
        ref = set(map(tuple, pts[spatial.ConvexHull(pts).vertices].tolist()))
        assert set(map(tuple, pts[sequential_hull(pts)].tolist())) == ref


def test_reference_chain_small_cases() -> None:
    assert monotone_chain([]) == []
    assert monotone_chain([(0.0, 0.0)]) == []  # one point: the ends cancel
    assert monotone_chain([(0.0, 0.0), (1.0, 1.0)]) == [0, 1]
    # collinear points: only the two ends
    assert monotone_chain([(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)]) == [0, 2]
    # repeated points: each vertex once
    square = sorted([(0.0, 0.0), (0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (1.0, 1.0), (0.0, 1.0)])
    assert [square[i] for i in monotone_chain(square)] == [(0, 0), (1, 0), (1, 1), (0, 1)]


# --------------------------------------------------------------------------- vectorised twin


@settings(max_examples=300, deadline=None)
@given(
    pts=st.one_of(
        lattice_points(min_size=1, max_size=300, bound=4),
        lattice_points(min_size=3, max_size=200, bound=1000),
        convex_points(),
    )
)
def test_vectorised_chain_is_the_reference(pts: FloatArray) -> None:
    # Duplicates, collinear runs, vertical edges: the same vertices, the same indices.
    order, pairs = sorted_pairs(pts)
    fast = monotone_chain_vectorised(pts[order, 0], pts[order, 1])
    assert fast is not None
    assert fast.tolist() == monotone_chain(pairs)
    assert_array_equal(hull_indices(pts), sequential_hull(pts))


def test_vectorised_chain_on_large_clouds(rng: np.random.Generator) -> None:
    t = rng.uniform(0, 2 * math.pi, 20_000)
    clouds = [
        rng.random((20_000, 2)),
        np.column_stack([np.cos(t), np.sin(t)]),
        np.round(rng.random((20_000, 2)) * 50) / 50,  # many repeated and collinear points
        np.column_stack([2 * np.cos(np.sort(t)), np.sin(np.sort(t))]),
    ]
    for pts in clouds:
        assert_array_equal(hull_indices(pts), sequential_hull(pts))


def test_vectorised_chain_gives_up_after_its_rounds(rng: np.random.Generator) -> None:
    pts = rng.random((500, 2))
    order, _ = sorted_pairs(pts)
    xs, ys = pts[order, 0], pts[order, 1]
    assert pruned_half_chain(xs, ys, np.arange(len(xs)), rounds=0) is None
    assert monotone_chain_vectorised(xs, ys, rounds=0) is None
    # hull_indices then runs the reference: the same answer
    assert_array_equal(hull_indices(pts), sequential_hull(pts))


# --------------------------------------------------------------------------- a few points


@given(pts=st.one_of(convex_points(), lattice_points(max_size=60, bound=5)))
def test_plain_python_and_array_hulls_agree(pts: FloatArray) -> None:
    extent = float(np.max(np.ptp(pts, axis=0)))
    eps = Tolerance().length_for(extent)
    _, pairs = sorted_pairs(pts)
    xs, ys, area, cx, cy = hull_of_few(pairs, eps)
    hull = pts[hull_indices(pts)]
    if len(hull) > 3:
        hull = drop_near_collinear(hull, eps)
    assert_array_equal(np.array([xs, ys]).T.reshape(-1, 2), hull)
    if len(hull) >= 3:
        ref_area, ref_centroid = polygon_area_centroid(hull)
        assert_allclose(area, ref_area, rtol=1e-12, atol=1e-300)
        assert_allclose([cx, cy], ref_centroid, rtol=1e-12, atol=1e-12 * extent)


def test_drop_near_collinear_keeps_chords_within_eps() -> None:
    # a run of vertices 1e-12 off the bottom edge: all dropped, the square stays
    bottom = [(x / 10, 1e-12 * (x % 2)) for x in range(1, 10)]
    ring = np.array([(0.0, 0.0), *bottom, (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
    assert drop_near_collinear(ring, 1e-9).tolist() == [[0, 0], [1, 0], [1, 1], [0, 1]]
    # beyond eps they stay
    assert len(drop_near_collinear(ring, 1e-13)) == len(ring)


# --------------------------------------------------------------------------- a ring as given


def test_a_convex_ring_read_from_a_file_is_its_points_part() -> None:
    """The reader's part of a convex ring: the points' own ``Part.from_points``, field by field."""
    rng = np.random.default_rng(11)
    for _ in range(50):
        pts = ConvexPolygon.from_points(rng.uniform(-5, 5, size=(9, 2))).vertices.tolist()
        k = int(rng.integers(len(pts)))
        pts = pts[k:] + pts[:k]
        got = points_module.point_list_part(Path("p.json"), pts, "p")
        want = Part.from_points(np.array(pts), name="p")
        assert got.hull.vertices.tolist() == want.hull.vertices.tolist()
        assert (got.hull.area, got.hull.size) == (want.hull.area, want.hull.size)
        assert got.outline.tolist() == pts
        assert got.center_of_mass.tolist() == want.center_of_mass.tolist()
        assert not got.outline.flags.writeable
