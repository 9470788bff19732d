"""Tests of bayesgrasp.geometry.polygon: validation, the convex hull, symmetry, the part."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from bayesgrasp.errors import BayesGraspError, PartError
from bayesgrasp.geometry.polygon import ConvexPolygon, Part, as_points, polygon_area_centroid
from bayesgrasp.tolerance import Tolerance
from reference import max_pair_distance, regular_polygon, rotate, round_significant
from strategies import convex_points, lattice_points

SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
RECTANGLE = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]
TRIANGLE = [(0.0, 0.0), (1.0, 0.0), (0.5, math.sqrt(3.0) / 2.0)]
RIGHT_TRIANGLE = [(0.0, 0.0), (3.0, 0.0), (0.0, 1.0)]
PARALLELOGRAM = [(0.0, 0.0), (3.0, 0.0), (4.0, 1.5), (1.0, 1.5)]


def cyclic_equal(a: np.ndarray, b: np.ndarray, atol: float) -> bool:
    """Whether two vertex lists are the same cycle (any starting vertex)."""
    if a.shape != b.shape:
        return False
    return any(np.allclose(np.roll(a, k, axis=0), b, atol=atol, rtol=0) for k in range(len(a)))


# --------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    ("points", "match"),
    [
        ([], r"must have shape \(N, 2\); got shape \(0,\)"),
        ([(0, 0)], "at least 3 distinct points; got 1 point"),
        ([(0, 0), (1, 1)], "at least 3 distinct points; got 2 point"),
        ([(0, 0), (0, 0), (1, 1), (1, 1)], "at least 3 distinct points; got 4 point.* 2 distinct"),
        ([(2, 3)] * 5, "at least 3 distinct points"),
        ([(0, 0), (1, 1), (2, 2), (3, 3)], "collinear"),
        ([(0, 0), (1, 0), (5, 0), (-2, 0), (1, 0)], "collinear"),
        ([(0, 0), (1, 1e-13), (2, 0)], "collinear"),
        ([(0, 0), (1, 0), (math.nan, 1)], r"must be finite; point 2 is \[nan, 1.0\]"),
        ([(0, 0), (math.inf, 0), (0, 1)], r"must be finite; point 1 is \[inf, 0.0\]"),
        ([(0, 0), (1, 0), (0, -math.inf)], "must be finite; point 2"),
        ([(0, 0, 0), (1, 0, 0), (0, 1, 0)], r"must have shape \(N, 2\); got shape \(3, 3\)"),
        ([0, 1, 2, 3], r"must have shape \(N, 2\); got shape \(4,\)"),
        ([[[0, 0], [1, 0], [0, 1]]], r"must have shape \(N, 2\); got shape \(1, 3, 2\)"),
        (None, "must be numbers of shape \\(N, 2\\); got a NoneType"),
        (5.0, r"must have shape \(N, 2\)"),
        ([(0, 0), (1,), (0, 1)], "must be numbers"),
        ([("a", "b"), (1, 0), (0, 1)], "must be numbers"),
        ([("0", "0"), ("1", "0"), ("0", "1")], "must be numbers"),
        ([(0, 0), (1, 0), (0, 1j)], "must be numbers"),
        ([(True, False), (False, True), (True, True)], "must be numbers"),
        ([(None, 0), (1, 0), (0, 1)], "must be numbers"),
        ([({}, 0), (1, 0), (0, 1)], "must be numbers"),
    ],
)
def test_from_points_rejects_bad_input(points: object, match: str) -> None:
    with pytest.raises(PartError, match=match):
        ConvexPolygon.from_points(points)  # type: ignore[arg-type]


def test_part_error_is_a_value_error_and_a_bayesgrasp_error() -> None:
    with pytest.raises(ValueError, match="collinear"):
        ConvexPolygon.from_points([(0, 0), (1, 1), (2, 2)])
    with pytest.raises(BayesGraspError, match="collinear"):
        Part.from_points([(0, 0), (1, 1), (2, 2)])


def test_as_points_names_the_parameter() -> None:
    with pytest.raises(PartError, match=r"`outline` must have shape \(N, 2\)"):
        as_points([1, 2, 3], "outline")
    assert as_points([(1, 2)], "p").dtype == np.float64


def test_numeric_arrays_of_any_real_dtype_are_accepted() -> None:
    for dtype in (np.int8, np.int64, np.uint16, np.float32, np.float64):
        poly = ConvexPolygon.from_points(np.array(SQUARE, dtype=dtype))
        assert poly.vertices.dtype == np.float64
        assert poly.n_sides == 4
    mixed = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=object)
    assert ConvexPolygon.from_points(mixed).n_sides == 4


@pytest.mark.parametrize(
    ("vertices", "match"),
    [
        ([(0, 0), (0, 1), (1, 1), (1, 0)], "counter-clockwise convex polygon"),  # clockwise
        ([(0, 0), (2, 0), (1, 0.2), (1, 2)], "counter-clockwise convex polygon"),  # reflex
        ([(0, 0), (1, 0), (1, 0), (0, 1)], "counter-clockwise convex polygon"),  # zero edge
        (
            [(0, 0), (2, 0), (0, 1), (2, 1), (1, -1), (1, 2)],  # winds twice in places
            "counter-clockwise convex polygon",
        ),
        ([(0, 0), (1, 0)], "counter-clockwise convex polygon"),
        ([(0, 0), (1, math.nan), (0, 1)], "must be finite"),
    ],
)
def test_constructor_validates_convexity(vertices: list[tuple[float, float]], match: str) -> None:
    with pytest.raises(PartError, match=match):
        ConvexPolygon(np.array(vertices, dtype=np.float64))


def test_constructor_accepts_a_convex_ccw_polygon_and_copies_it() -> None:
    v = np.array(SQUARE)
    poly = ConvexPolygon(v)
    v[0, 0] = 99.0
    assert poly.vertices[0, 0] == 0.0
    assert poly.n_sides == 4


# --------------------------------------------------------------------------- immutability


def test_arrays_are_read_only_and_the_polygon_is_frozen() -> None:
    pts = np.array(RECTANGLE)
    poly = ConvexPolygon.from_points(pts)
    for arr in (poly.vertices, poly.centroid):
        assert not arr.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        poly.vertices = pts  # type: ignore[misc]
    pts[0] = (-5.0, -5.0)  # the user's array is not aliased
    assert poly.vertices.min() == 0.0


def test_part_arrays_are_read_only() -> None:
    part = Part.from_points([*RECTANGLE, (1.0, 0.5)], name="r")
    for arr in (part.outline, part.center_of_mass, part.hull.vertices):
        assert not arr.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        part.name = "other"  # type: ignore[misc]


# --------------------------------------------------------------------------- the hull


def test_hull_of_a_square_with_extra_points() -> None:
    pts = [(1, 1), (0, 0), (1, 0), (0, 1), (0.5, 0), (0.5, 0.5), (1, 1), (0, 0.25)]
    poly = ConvexPolygon.from_points(pts)
    assert_array_equal(poly.vertices, np.array(SQUARE))
    assert poly.area == 1.0
    assert_allclose(poly.centroid, [0.5, 0.5], atol=1e-15)
    assert_allclose(poly.size, math.sqrt(0.5), atol=1e-15)


def test_hull_matches_scipy(rng: np.random.Generator) -> None:
    spatial = pytest.importorskip("scipy.spatial")
    for _ in range(200):
        n = int(rng.integers(3, 300))  # both the plain-Python (<= 64) and the numpy path
        pts = rng.normal(size=(n, 2)) * rng.uniform(0.1, 10.0, size=2)
        poly = ConvexPolygon.from_points(pts)
        ref = pts[spatial.ConvexHull(pts).vertices]  # counter-clockwise in 2-D
        assert cyclic_equal(poly.vertices, ref, atol=0.0)


def test_area_and_centroid_match_shapely(rng: np.random.Generator) -> None:
    geometry = pytest.importorskip("shapely.geometry")
    for _ in range(100):
        pts = rng.random((12, 2)) * 7.0 - 3.0
        poly = ConvexPolygon.from_points(pts)
        ref = geometry.Polygon(poly.vertices)
        assert_allclose(poly.area, ref.area, rtol=1e-12)
        assert_allclose(poly.centroid, [ref.centroid.x, ref.centroid.y], atol=1e-12)
        assert_allclose(poly.size, np.hypot(*(poly.vertices - poly.centroid).T).max(), atol=0)


def test_polygon_area_centroid_sign_and_degenerate() -> None:
    area, centroid = polygon_area_centroid(np.array(SQUARE)[::-1].copy())
    assert area == -1.0
    assert_allclose(centroid, [0.5, 0.5], atol=1e-15)
    area, centroid = polygon_area_centroid(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]))
    assert area == 0.0
    assert_allclose(centroid, [1.0, 1.0], atol=1e-15)


def test_vertices_start_at_the_lowest_leftmost_point_and_run_ccw(
    rng: np.random.Generator,
) -> None:
    for _ in range(50):
        poly = ConvexPolygon.from_points(rng.random((10, 2)))
        v = poly.vertices
        first = np.lexsort((v[:, 1], v[:, 0]))[0]
        assert first == 0
        e = np.roll(v, -1, axis=0) - v
        cross = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
        assert np.all(cross > 0)


def test_near_collinear_vertices() -> None:
    # A bump of 1e-13 (far below the 1e-10 relative length tolerance) is dropped ...
    assert ConvexPolygon.from_points([*SQUARE, (0.5, -1e-13)]).n_sides == 4
    # ... a bump of 1e-7 is a real (if short-lived) vertex.
    bumped = ConvexPolygon.from_points([*SQUARE, (0.5, -1e-07)])
    assert bumped.n_sides == 5
    # Many nearly collinear points along one edge: the error never accumulates.
    x = np.linspace(0.0, 1.0, 1001)
    edge = np.column_stack([x, 1e-12 * np.sin(40.0 * x)])
    poly = ConvexPolygon.from_points(np.vstack([edge, [(1.0, 1.0), (0.0, 1.0)]]))
    assert poly.n_sides == 4
    bottom = poly.vertices[poly.vertices[:, 1] < 0.5]
    assert_allclose(bottom, [(0.0, 0.0), (1.0, edge[-1, 1])], atol=0)
    # A custom tolerance merges more.
    loose = ConvexPolygon.from_points([*SQUARE, (0.5, -1e-07)], Tolerance(length=1e-6))
    assert loose.n_sides == 4


def test_tolerance_scales_with_the_part() -> None:
    for scale in (1e-9, 1.0, 1e9):
        pts = np.array([*SQUARE, (0.5, -1e-13)]) * scale
        assert ConvexPolygon.from_points(pts).n_sides == 4
        pts = np.array([*SQUARE, (0.5, -1e-07)]) * scale
        assert ConvexPolygon.from_points(pts).n_sides == 5


@pytest.mark.parametrize("scale", [1e-140, 1e-100, 1e-30, 1e-9, 1e9, 1e30, 1e100, 1e149])
def test_huge_and_tiny_coordinates(scale: float, rng: np.random.Generator) -> None:
    pts = rng.random((10, 2))
    ref = ConvexPolygon.from_points(pts)
    poly = ConvexPolygon.from_points(pts * scale)
    assert_allclose(poly.vertices / scale, ref.vertices, rtol=1e-13, atol=0)
    assert_allclose(poly.area / scale**2, ref.area, rtol=1e-12)
    assert_allclose(poly.centroid / scale, ref.centroid, rtol=1e-12)
    assert_allclose(poly.size / scale, ref.size, rtol=1e-12)
    assert poly.symmetry_order == 1


@pytest.mark.parametrize(
    ("scale", "message"), [(1e200, "at most 1e"), (1e-200, "cannot be resolved")]
)
def test_coordinates_beyond_the_float_range_are_refused(scale: float, message: str) -> None:
    # Areas are products of coordinates: these would overflow or underflow to a wrong answer.
    with pytest.raises(PartError, match=message):
        ConvexPolygon.from_points(np.array(SQUARE) * scale)


def test_booleans_mixed_with_numbers_are_refused() -> None:
    with pytest.raises(PartError, match="got a bool"):
        ConvexPolygon.from_points([[True, 0], [1, 0], [0, 1]])


def test_a_part_far_from_the_origin(rng: np.random.Generator) -> None:
    pts = rng.random((10, 2))
    ref = ConvexPolygon.from_points(pts)
    for offset in (1e3, 1e6):
        poly = ConvexPolygon.from_points(pts + offset)
        assert poly.n_sides == ref.n_sides
        assert_allclose(poly.vertices - offset, ref.vertices, atol=1e-15 * offset * 4)
        assert_allclose(poly.area, ref.area, rtol=1e-15 * offset * 10)
        assert_allclose(poly.centroid - offset, ref.centroid, atol=1e-15 * offset * 4)


# --------------------------------------------------------------------------- invariances


@given(pts=convex_points(), data=st.data())
def test_vertex_order_does_not_matter(pts: np.ndarray, data: st.DataObject) -> None:
    perm = data.draw(st.permutations(range(len(pts))))
    a = ConvexPolygon.from_points(pts)
    b = ConvexPolygon.from_points(pts[list(perm)])
    assert_array_equal(a.vertices, b.vertices)


@given(pts=convex_points(), data=st.data())
def test_duplicate_points_change_nothing(pts: np.ndarray, data: st.DataObject) -> None:
    picks = data.draw(st.lists(st.integers(0, len(pts) - 1), min_size=1, max_size=10))
    a = ConvexPolygon.from_points(pts)
    b = ConvexPolygon.from_points(np.vstack([pts, pts[picks]]))
    assert_array_equal(a.vertices, b.vertices)


@given(pts=convex_points(), data=st.data())
def test_interior_points_change_nothing(pts: np.ndarray, data: st.DataObject) -> None:
    a = ConvexPolygon.from_points(pts)
    k = data.draw(st.integers(1, 10))
    seed = data.draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    # Convex combinations of the vertices pulled halfway to the centroid: well inside.
    w = rng.dirichlet(np.ones(a.n_sides), size=k)
    inside = a.centroid + 0.5 * (w @ a.vertices - a.centroid)
    b = ConvexPolygon.from_points(np.vstack([inside, pts]))
    assert_array_equal(a.vertices, b.vertices)


@given(pts=lattice_points(), shift=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_translation(pts: np.ndarray, shift: tuple[float, float]) -> None:
    a = ConvexPolygon.from_points(pts)
    b = ConvexPolygon.from_points(pts + np.array(shift))
    atol = 1e-13 * (a.size + np.abs(shift).max())
    assert a.n_sides == b.n_sides
    assert_allclose(b.vertices - np.array(shift), a.vertices, atol=atol, rtol=0)
    assert_allclose(b.area, a.area, rtol=1e-9)
    assert b.symmetry_order == a.symmetry_order


@given(pts=convex_points(), scale=st.floats(1e-6, 1e6))
def test_uniform_scaling(pts: np.ndarray, scale: float) -> None:
    a = ConvexPolygon.from_points(pts)
    b = ConvexPolygon.from_points(pts * scale)
    assert a.n_sides == b.n_sides
    assert_allclose(b.vertices / scale, a.vertices, rtol=1e-12, atol=1e-14 * a.size)
    # The shoelace sum's rounding is relative to size^2, not to the area (a sliver's area
    # is a small difference of large products).
    assert_allclose(b.area / scale**2, a.area, rtol=1e-12, atol=1e-13 * a.size**2)
    assert b.symmetry_order == a.symmetry_order


@given(pts=convex_points())
def test_hull_is_convex_contains_all_points_and_has_the_diameter(pts: np.ndarray) -> None:
    poly = ConvexPolygon.from_points(pts)
    v = poly.vertices
    e = np.roll(v, -1, axis=0) - v
    rel = pts[:, None, :] - v[None, :, :]  # (M, N, 2)
    cross = e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0]
    lengths = np.hypot(e[:, 0], e[:, 1])
    # Every input point lies inside or within the length tolerance of the hull.
    assert np.all(cross / lengths >= -1e-9 * poly.size)
    # Every vertex is an input point.
    assert all(np.any(np.all(pts == p, axis=1)) for p in v)
    assert poly.area > 0
    assert_allclose(max_pair_distance(v), max_pair_distance(pts), rtol=1e-12)


# --------------------------------------------------------------------------- symmetry


@pytest.mark.parametrize(
    ("points", "order"),
    [
        (SQUARE, 4),
        (RECTANGLE, 2),
        (TRIANGLE, 3),
        (RIGHT_TRIANGLE, 1),
        (PARALLELOGRAM, 2),
        ([(0, 0), (4, 0), (3, 1), (1, 1)], 1),  # isosceles trapezoid: a mirror, no rotation
        ([(0, 0), (2, 0), (3, 1), (2, 2), (0, 2), (-1, 1)], 2),  # elongated hexagon
        ([(1, 0), (2, 0), (3, 1), (3, 2), (2, 3), (1, 3), (0, 2), (0, 1)], 4),  # cut square
        ([(1, 0), (2, 0), (3, 1), (3, 2), (2, 3), (1, 3), (0, 2), (0, 1.5)], 1),
    ],
)
def test_symmetry_order_of_familiar_shapes(points: list[tuple[float, float]], order: int) -> None:
    assert ConvexPolygon.from_points(points).symmetry_order == order


def test_symmetry_order_of_random_polygons(rng: np.random.Generator) -> None:
    for _ in range(100):
        assert ConvexPolygon.from_points(rng.random((10, 2))).symmetry_order == 1


@pytest.mark.parametrize("r", [*range(3, 13), 15, 17, 21, 25, 31, 48])
def test_symmetry_order_of_regular_polygons(r: int, rng: np.random.Generator) -> None:
    for _ in range(5):
        phase = float(rng.uniform(0, 2 * math.pi))
        radius = float(10.0 ** rng.uniform(-3, 3))
        center = tuple(rng.uniform(-2, 2, size=2) * radius)
        pts = regular_polygon(r, radius, phase, center)  # type: ignore[arg-type]
        assert ConvexPolygon.from_points(pts).symmetry_order == r
        # Exact even from coordinates rounded to 7 significant digits.
        rounded = round_significant(pts, 7)
        assert ConvexPolygon.from_points(rounded).symmetry_order == r
        # A polygon with one vertex moved by 1% of its size is not symmetric.
        moved = pts.copy()
        moved[0] = center + (moved[0] - center) * 0.99
        assert ConvexPolygon.from_points(moved).symmetry_order == 1


@given(pts=lattice_points(), beta=st.floats(0, 2 * math.pi))
def test_symmetry_order_is_invariant_under_rotation(pts: np.ndarray, beta: float) -> None:
    a = ConvexPolygon.from_points(pts)
    b = ConvexPolygon.from_points(rotate(pts, beta))
    assert a.symmetry_order == b.symmetry_order
    assert a.n_sides % a.symmetry_order == 0


# --------------------------------------------------------------------------- rotated, Part


def test_rotated_turns_about_the_origin_and_keeps_the_original() -> None:
    poly = ConvexPolygon.from_points(PARALLELOGRAM)
    turned = poly.rotated(0.7)
    assert cyclic_equal(turned.vertices, rotate(poly.vertices, 0.7), atol=1e-14)
    assert_allclose(turned.area, poly.area, rtol=1e-14)
    assert_array_equal(poly.vertices, np.array(PARALLELOGRAM))


def test_part_keeps_the_outline_and_defaults() -> None:
    outline = [(0, 0), (3, 0), (3, 1), (2, 1), (2, 2), (0, 2)]  # an L: not convex
    part = Part.from_points(outline, name="ell", units="mm")
    assert part.name == "ell"
    assert part.units == "mm"
    assert_array_equal(part.outline, np.array(outline, dtype=np.float64))
    assert part.hull.n_sides == 5
    assert_allclose(part.center_of_mass, part.hull.centroid, atol=0)
    assert Part.from_points(outline).name == "part"
    assert Part.from_points(outline).units is None


def test_part_center_of_mass() -> None:
    part = Part.from_points(SQUARE, center_of_mass=(0.25, 0.75))
    assert_array_equal(part.center_of_mass, [0.25, 0.75])
    with pytest.raises(PartError, match=r"`center_of_mass` \[2.0, 0.5\] must lie inside"):
        Part.from_points(SQUARE, center_of_mass=(2.0, 0.5))
    with pytest.raises(PartError, match="must lie inside"):
        Part.from_points(SQUARE, center_of_mass=(1.0, 0.5))  # on the boundary
    with pytest.raises(PartError, match="`center_of_mass` must be finite"):
        Part.from_points(SQUARE, center_of_mass=(math.nan, 0.5))
    with pytest.raises(PartError, match=r"`center_of_mass` must have shape"):
        Part.from_points(SQUARE, center_of_mass=(0.5, 0.5, 0.5))
    with pytest.raises(PartError, match="`center_of_mass` must be numbers"):
        Part.from_points(SQUARE, center_of_mass=("a", 0.5))


def test_many_points(rng: np.random.Generator) -> None:
    t = rng.uniform(0, 2 * math.pi, 5000)
    ring = np.column_stack([3 * np.cos(t), np.sin(t)])
    inside = rng.uniform(-1, 1, (5000, 2)) * [2.0, 0.6]
    poly = ConvexPolygon.from_points(np.vstack([inside, ring]))
    assert poly.n_sides > 4000
    assert_allclose(poly.area, 3 * math.pi, rtol=1e-4)
    assert_allclose(poly.centroid, [0, 0], atol=1e-3)
