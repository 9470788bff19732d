"""Tests of bayesgrasp.geometry.diameter: the exact piecewise-sinusoidal diameter function."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.geometry import diameter_pieces
from bayesgrasp.geometry.diameter import DiameterFunction, diameter_function
from bayesgrasp.geometry.polygon import ConvexPolygon
from reference import (
    circle_distance,
    max_pair_distance,
    regular_polygon,
    rotate,
    round_significant,
    width,
)
from strategies import angles, convex_points, lattice_points

SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
RIGHT_TRIANGLE = [(0.0, 0.0), (2.0, 0.0), (0.0, 1.0)]
PARALLELOGRAM = [(0.0, 0.0), (3.0, 0.0), (4.0, 1.5), (1.0, 1.5)]
HOUSE = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.5), (1.0, 2.5), (0.0, 1.5)]  # right angles, parallels


def dfun(points: object) -> DiameterFunction:
    return diameter_function(ConvexPolygon.from_points(points))  # type: ignore[arg-type]


def check_against_brute_force(d: DiameterFunction, m: int = 4096) -> None:
    """Exact d equals the width of the rotated vertices; extrema are extrema of that width.

    The extrema of a part symmetric within the tolerance (order 3 or more) are those of its
    symmetrized vertices (diameter_function's docstring): they are checked against those.
    """
    size = d.polygon.size
    theta = np.linspace(-math.pi, 3 * math.pi, m)
    assert_allclose(d(theta), width(d.polygon.vertices, theta), atol=1e-12 * size, rtol=0)
    v = d.polygon.symmetrized() if d.polygon.symmetry_order > 2 else d.polygon.vertices
    # Minima: d strictly larger a little way off on both sides; an edge is vertical there.
    for lo in d.minima:
        room = min(1e-4, 0.25 * float(circle_distance(lo, d.maxima, math.pi).min()))
        here = width(v, lo)
        assert width(v, lo - room) > here
        assert width(v, lo + room) > here
        rx = rotate(v, float(lo))[:, 0]
        e = np.roll(rx, -1) - rx
        assert np.min(np.abs(e)) <= 1e-9 * size
    # Maxima: d strictly smaller a little way off; the touching chord is along x.
    for hi in d.maxima:
        room = min(1e-4, 0.25 * float(circle_distance(hi, d.minima, math.pi).min()))
        here = width(v, hi)
        assert width(v, hi - room) < here
        assert width(v, hi + room) < here
        r = rotate(v, float(hi))
        top, bottom = np.argmax(r[:, 0]), np.argmin(r[:, 0])
        assert_allclose(r[top, 1], r[bottom, 1], atol=1e-9 * size)


# --------------------------------------------------------------------------- closed forms


def test_square() -> None:
    d = dfun(SQUARE)
    theta = np.linspace(0, 2 * math.pi, 721)
    assert_allclose(d(theta), np.abs(np.cos(theta)) + np.abs(np.sin(theta)), atol=1e-14)
    assert_allclose(d.minima, [0.0, math.pi / 2], atol=1e-15)
    assert_allclose(d.maxima, [math.pi / 4, 3 * math.pi / 4], atol=1e-15)
    assert_allclose(d.diameter, math.sqrt(2.0), atol=1e-15)


@pytest.mark.parametrize(("a", "b"), [(2.0, 1.0), (1.55, 1.0), (10.0, 0.1), (1.0, 3.0)])
def test_rectangle(a: float, b: float) -> None:
    d = dfun([(0, 0), (a, 0), (a, b), (0, b)])
    theta = np.linspace(-1, 7, 1001)
    assert_allclose(d(theta), a * np.abs(np.cos(theta)) + b * np.abs(np.sin(theta)), atol=1e-14)
    assert_allclose(d.minima, [0.0, math.pi / 2], atol=1e-15)
    alpha = math.atan2(b, a)  # the diagonals lie along x at -alpha and +alpha (mod pi)
    assert_allclose(d.maxima, sorted([alpha, math.pi - alpha]), atol=1e-14)
    assert_allclose(d.diameter, math.hypot(a, b), atol=1e-14)


def test_equilateral_triangle() -> None:
    d = dfun(regular_polygon(3))
    h = math.sqrt(3.0) / 2.0  # height of the unit-side triangle is h * side
    side = math.sqrt(3.0)
    assert len(d.minima) == 3
    assert len(d.maxima) == 3
    assert_allclose(d(d.minima), h * side, atol=1e-14)
    assert_allclose(d(d.maxima), side, atol=1e-14)
    assert_allclose(np.diff(d.minima), math.pi / 3, atol=1e-14)


def test_right_triangle_kink_is_not_an_extremum() -> None:
    # At theta = 0 the leg x = 0 is parallel to the jaws and the chord from (2, 0) to (0, 0)
    # is perpendicular to it: d = 2 cos(theta) on one side, a steeper sinusoid on the other.
    # That kink is neither a minimum nor a maximum: only the hypotenuse alignment is stable.
    d = dfun(RIGHT_TRIANGLE)
    assert len(d.minima) == 1
    assert len(d.maxima) == 1
    # The hypotenuse, at angle pi - atan(1/2), is vertical at theta = pi / 2 + atan(1/2)
    # (the minimum) and along x at theta = atan(1/2) (the maximum, the diameter sqrt(5)).
    assert_allclose(d.minima, [math.pi / 2 + math.atan(0.5)], atol=1e-14)
    assert_allclose(d.maxima, [math.atan(0.5)], atol=1e-14)
    assert_allclose(d(d.maxima), [math.sqrt(5.0)], atol=1e-14)
    check_against_brute_force(d)


def test_parallelogram() -> None:
    d = dfun(PARALLELOGRAM)
    check_against_brute_force(d)
    # Each pair of parallel sides is one edge alignment; the maxima are the diagonals.
    assert len(d.minima) == 2
    assert len(d.breaks) == 2
    diag = np.array([[4.0, 1.5], [-2.0, 1.5]])  # the two diagonals
    expected = np.sort(np.mod(-np.arctan2(diag[:, 1], diag[:, 0]), math.pi))
    assert_allclose(d.maxima, expected, atol=1e-14)
    assert_allclose(d.diameter, math.hypot(4.0, 1.5), atol=1e-14)


@pytest.mark.parametrize(
    "points",
    [SQUARE, RIGHT_TRIANGLE, PARALLELOGRAM, HOUSE, regular_polygon(6), regular_polygon(7)],
)
def test_degenerate_shapes_agree_with_brute_force(points: object) -> None:
    d = dfun(points)
    check_against_brute_force(d)
    for beta in (0.1, 1.0, math.pi / 2, math.pi / 3, 2.5):
        check_against_brute_force(dfun(rotate(np.asarray(points, dtype=float), beta)))


def test_nearly_collinear_and_nearly_parallel() -> None:
    # A vertex 1e-6 off an edge: a real vertex, two nearly parallel edges on one side.
    check_against_brute_force(dfun([*SQUARE, (0.5, -1e-6)]))
    # A vertex 1e-6 off the chord of a long thin part.
    check_against_brute_force(dfun([(0, 0), (10, 0), (10, 0.1), (5, 0.1 + 1e-6), (0, 0.1)]))
    # A hexagon whose opposite sides are parallel to 1e-7.
    hexagon = regular_polygon(6)
    hexagon[0] += (0.0, 1e-7)
    check_against_brute_force(dfun(hexagon))


def test_rounded_regular_polygons_keep_their_extrema(rng: np.random.Generator) -> None:
    # Rounding the coordinates to 7 significant digits leaves opposite edges parallel and
    # chords perpendicular only to about 1e-6: d may gain minima and maxima that are
    # closer than that round-off; they are not extrema of the part the user meant.
    for r in [*range(3, 13), 15, 21, 48]:
        for _ in range(3):
            radius = float(10.0 ** rng.uniform(-3, 3))
            center = tuple(rng.uniform(-2, 2, size=2) * radius)
            pts = regular_polygon(r, radius, float(rng.uniform(0, 2 * math.pi)), center)  # type: ignore[arg-type]
            d = dfun(round_significant(pts, 7))
            expected = r if r % 2 else r // 2
            assert len(d.minima) == expected
            assert len(d.maxima) == expected


@pytest.mark.parametrize("scale", [1e-100, 1e-12, 1e12, 1e100])
def test_huge_and_tiny_coordinates(scale: float, rng: np.random.Generator) -> None:
    pts = rng.random((10, 2))
    ref = dfun(pts)
    d = dfun(pts * scale)
    theta = np.linspace(0, math.pi, 100)
    assert_allclose(d(theta) / scale, ref(theta), rtol=1e-13)
    assert_allclose(d.minima, ref.minima, atol=1e-13)
    assert_allclose(d.maxima, ref.maxima, atol=1e-13)


def test_a_part_far_from_the_origin(rng: np.random.Generator) -> None:
    pts = rng.random((10, 2))
    ref = dfun(pts)
    for offset in (1e3, 1e6):
        d = dfun(pts + np.array([offset, -2 * offset]))
        theta = np.linspace(0, math.pi, 100)
        assert_allclose(d(theta), ref(theta), atol=1e-14 * offset * 10)
        assert_allclose(d.minima, ref.minima, atol=1e-14 * offset * 10)
        assert_allclose(d.maxima, ref.maxima, atol=1e-14 * offset * 10)


# --------------------------------------------------------------------------- brute force


def test_random_polygons_agree_with_brute_force(rng: np.random.Generator) -> None:
    for _ in range(200):
        d = dfun(rng.random((10, 2)))
        check_against_brute_force(d, m=2048)
        assert_allclose(d.diameter, max_pair_distance(d.polygon.vertices), rtol=1e-14)


@given(pts=convex_points())
def test_exact_d_equals_the_width_of_the_rotated_vertices(pts: np.ndarray) -> None:
    check_against_brute_force(dfun(pts), m=1024)


# --------------------------------------------------------------------------- structure


@given(pts=convex_points(), theta=st.lists(angles(), min_size=1, max_size=20))
def test_d_has_period_pi(pts: np.ndarray, theta: list[float]) -> None:
    d = dfun(pts)
    th = np.array(theta)
    size = d.polygon.size
    assert_allclose(d(th + math.pi), d(th), atol=1e-12 * size, rtol=0)
    assert_allclose(d(th - 3 * math.pi), d(th), atol=1e-12 * size, rtol=0)
    assert_allclose(d(th), width(d.polygon.vertices, th), atol=1e-12 * size, rtol=0)


@given(pts=convex_points())
def test_pieces_are_consistent(pts: np.ndarray) -> None:
    d = dfun(pts)
    p = len(d.breaks)
    assert d.lengths.shape == d.phases.shape == (p,)
    assert d.pairs.shape == (p, 2)
    assert np.all(np.diff(d.breaks) > 0)
    assert np.all((d.breaks >= 0) & (d.breaks < math.pi))
    ends = np.append(d.breaks[1:], d.breaks[0] + math.pi)
    mids = 0.5 * (d.breaks + ends)
    # The phase is within pi / 2 of the piece, so l cos(theta - phase) is positive on it.
    assert np.all(np.abs(d.phases - mids) < math.pi / 2)
    # The pair touches the jaws: the +x jaw vertex has the largest x at the piece's middle.
    v = d.polygon.vertices
    for k in range(p):
        x = rotate(v, float(mids[k]))[:, 0]
        i_plus, i_minus = d.pairs[k]
        assert_allclose(x[i_plus], x.max(), atol=1e-12 * d.polygon.size)
        assert_allclose(x[i_minus], x.min(), atol=1e-12 * d.polygon.size)
        assert_allclose(d.lengths[k], np.hypot(*(v[i_plus] - v[i_minus])), rtol=1e-14)
    # At most one edge alignment per edge, extrema alternate and lie in [0, pi).
    assert p <= d.polygon.n_sides
    assert len(d.minima) == len(d.maxima) >= 1
    both = np.concatenate([d.minima, d.maxima])
    assert np.all((both >= 0) & (both < math.pi))
    kinds = np.concatenate([np.zeros(len(d.minima)), np.ones(len(d.maxima))])[np.argsort(both)]
    assert np.all(np.diff(kinds) != 0)
    # The diameter is the largest distance between two vertices.
    assert_allclose(d.diameter, max_pair_distance(v), rtol=1e-14)


@given(pts=convex_points())
def test_extrema_are_extrema(pts: np.ndarray) -> None:
    d = dfun(pts)
    check_against_brute_force(d, m=64)


@given(pts=lattice_points(), beta=st.floats(0, 2 * math.pi), theta=angles())
def test_rotating_the_input_shifts_d(pts: np.ndarray, beta: float, theta: float) -> None:
    a = dfun(pts)
    b = dfun(rotate(pts, beta))
    # The rotated part at theta is the original at theta + beta.
    assert_allclose(b(theta), a(theta + beta), atol=1e-12 * a.polygon.size, rtol=0)
    assert _same_circle_set(a.minima - beta, b.minima, math.pi, 1e-9)
    assert _same_circle_set(a.maxima - beta, b.maxima, math.pi, 1e-9)


def _same_circle_set(a: np.ndarray, b: np.ndarray, period: float, atol: float) -> bool:
    if len(a) != len(b):
        return False
    dist = circle_distance(a[:, None], b[None, :], period)
    return bool(np.all(dist.min(axis=1) <= atol) and np.all(dist.min(axis=0) <= atol))


@given(pts=convex_points(), shift=st.tuples(st.floats(-10, 10), st.floats(-10, 10)))
def test_translation_changes_nothing(pts: np.ndarray, shift: tuple[float, float]) -> None:
    a = dfun(pts)
    b = dfun(pts + np.array(shift))
    theta = np.linspace(0, math.pi, 50)
    atol = 1e-12 * (a.polygon.size + max(abs(shift[0]), abs(shift[1])))
    assert_allclose(b(theta), a(theta), atol=atol, rtol=0)
    assert _same_circle_set(a.minima, b.minima, math.pi, 1e-9)
    assert _same_circle_set(a.maxima, b.maxima, math.pi, 1e-9)


# --------------------------------------------------------------------------- API details


def test_evaluation_keeps_shapes() -> None:
    d = dfun(SQUARE)
    assert d(0.3).shape == ()
    assert d([0.1, 0.2]).shape == (2,)
    assert d(np.zeros((3, 4))).shape == (3, 4)
    assert d.piece_index(np.zeros((2, 5))).shape == (2, 5)


def test_arrays_are_read_only_and_frozen() -> None:
    d = dfun(HOUSE)
    for arr in (d.breaks, d.lengths, d.phases, d.pairs, d.minima, d.maxima):
        assert not arr.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        d.minima[0] = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.breaks = d.breaks  # type: ignore[misc]


@given(pts=st.one_of(convex_points(), lattice_points(max_size=60, bound=8)))
def test_plain_python_and_numpy_pieces_agree(pts: np.ndarray) -> None:
    poly = ConvexPolygon.from_points(pts)
    a = diameter_pieces.pieces_numpy(poly.vertices, poly.tol.angle)
    b = diameter_pieces.pieces_python(*poly.vertices.T.tolist(), poly.tol.angle)
    for x, y in zip(a[:5], b[:5], strict=True):
        assert np.shape(x) == np.shape(y)
        # Chord lengths scale with the part; angles and indices do not.
        assert_allclose(x, y, atol=1e-13 * max(1.0, poly.size), rtol=0)
    for x, y in zip(a[5], b[5], strict=True):
        assert_allclose(sorted(x), sorted(y), atol=1e-13 * max(1.0, poly.size), rtol=0)


@pytest.mark.parametrize("n", [41, 100, 1000, 20000])
def test_many_vertices_agree_with_brute_force(n: int, rng: np.random.Generator) -> None:
    t = np.sort(rng.uniform(0, 2 * math.pi, n))
    pts = rotate(np.column_stack([2 * np.cos(t), np.sin(t)]), 0.3) + np.array([5.0, -1.0])
    d = dfun(pts)
    assert d.polygon.n_sides > 0.9 * n
    check_against_brute_force(d, m=512)
    # An ellipse has one minimum and one maximum per half turn (the polygon's own wiggles
    # near the flat minimum are shallower than the tolerance).
    if n >= 1000:
        assert len(d.minima) == len(d.maxima) == 1
        assert_allclose(d.minima, [math.pi / 2 - 0.3], atol=1e-2)
