"""Tests of bayesgrasp.geometry.transfer: the squeeze function, basins, period, probabilities."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from bayesgrasp.errors import BayesGraspError
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import ConvexPolygon
from bayesgrasp.geometry.transfer import (
    TransferFunction,
    detect_period,
    squeeze_function,
    transfer_from_extrema,
)
from bayesgrasp.model.prior import HistogramPrior, SamplePrior, UniformPrior, von_mises
from reference import (
    TWO_PI,
    circle_distance,
    descend,
    regular_polygon,
    rotate,
    round_significant,
    width,
    wrap,
)
from strategies import angles, convex_points, lattice_points, uniform_points

SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
RIGHT_TRIANGLE = [(0.0, 0.0), (2.0, 0.0), (0.0, 1.0)]
PARALLELOGRAM = [(0.0, 0.0), (3.0, 0.0), (4.0, 1.5), (1.0, 1.5)]


def squeeze(points: object) -> TransferFunction:
    return squeeze_function(ConvexPolygon.from_points(points))  # type: ignore[arg-type]


def period_formula(r: int) -> float:
    """Goldberg (1993): the squeeze period of an r-fold symmetric part."""
    return TWO_PI / (r * (1 + r % 2))


def same_circle_set(a: np.ndarray, b: np.ndarray, atol: float) -> bool:
    if len(a) != len(b):
        return False
    dist = circle_distance(np.asarray(a)[:, None], np.asarray(b)[None, :])
    return bool(np.all(dist.min(axis=1) <= atol) and np.all(dist.min(axis=0) <= atol))


def check_structure(s: TransferFunction) -> None:
    """Invariants every squeeze function has."""
    k = s.n_states
    assert k >= 2
    assert s.stable.shape == s.basin_lo.shape == s.basin_hi.shape == (k,)
    assert np.all(np.diff(s.stable) > 0)
    assert np.all((s.stable >= 0) & (s.stable < TWO_PI))
    assert np.all(s.basin_lo < s.stable) and np.all(s.stable < s.basin_hi)
    # Basins tile the circle: each ends where the next begins.
    assert_allclose(s.basin_lo[1:], s.basin_hi[:-1], atol=0)
    assert_allclose(s.basin_hi[-1] - s.basin_lo[0], TWO_PI, atol=1e-12)
    assert_allclose(s.widths.sum(), TWO_PI, atol=1e-12)
    # s(theta + pi) = s(theta) + pi: the states come in pairs half a turn apart.
    assert k % 2 == 0
    assert_allclose(wrap(s.stable[k // 2 :] - s.stable[: k // 2] - math.pi), 0.0, atol=1e-9)
    # The period divides pi, and 2 pi / period divides the number of states.
    m = TWO_PI / s.period
    assert abs(m - round(m)) < 1e-9
    assert round(m) >= 2
    assert k % round(m) == 0


# --------------------------------------------------------------------------- closed forms


def test_square() -> None:
    s = squeeze(SQUARE)
    assert_allclose(s.stable, [0, math.pi / 2, math.pi, 3 * math.pi / 2], atol=1e-15)
    assert_allclose(s.widths, math.pi / 2, atol=1e-14)
    assert_allclose(UniformPrior().mass(s.basin_lo, s.basin_hi), 0.25, atol=1e-15)
    assert_allclose(s.period, math.pi / 2, atol=1e-15)
    assert_allclose(s.boundaries, math.pi / 4 + np.arange(4) * math.pi / 2, atol=1e-14)


@pytest.mark.parametrize(
    ("a", "b"), [(2.0, 1.0), (1.55, 1.0), (1.0, 1.55), (3.0, 0.2), (100.0, 1.0), (1.01, 1.0)]
)
def test_rectangle(a: float, b: float) -> None:
    s = squeeze([(0, 0), (a, 0), (a, b), (0, b)])
    assert_allclose(s.stable, np.arange(4) * math.pi / 2, atol=1e-15)
    # At theta = 0 the sides of length b lie on the jaws; the diagonals bound that basin.
    width_0 = 2 * math.atan(b / a)
    expected = [width_0, math.pi - width_0, width_0, math.pi - width_0]
    assert_allclose(s.widths, expected, atol=1e-14)
    assert_allclose(UniformPrior().mass(s.basin_lo, s.basin_hi), np.array(expected) / TWO_PI)
    assert_allclose(s.period, math.pi, atol=1e-15)


def test_equilateral_triangle() -> None:
    s = squeeze(regular_polygon(3, phase=0.4))
    assert s.n_states == 6
    assert_allclose(s.widths, math.pi / 3, atol=1e-14)
    assert_allclose(UniformPrior().mass(s.basin_lo, s.basin_hi), 1 / 6, atol=1e-14)
    assert_allclose(s.period, math.pi / 3, atol=1e-15)


def test_right_triangle_has_two_states() -> None:
    # Only the hypotenuse alignments are stable (the legs are kinks, not minima).
    s = squeeze(RIGHT_TRIANGLE)
    assert s.n_states == 2
    assert_allclose(s.stable, [math.pi / 2 + math.atan(0.5), 3 * math.pi / 2 + math.atan(0.5)])
    assert_allclose(s.widths, math.pi, atol=1e-14)
    assert_allclose(s.period, math.pi, atol=1e-15)


def test_parallelogram() -> None:
    s = squeeze(PARALLELOGRAM)
    # The basins are bounded by the diagonals: the angle between them, and pi minus it.
    d1, d2 = np.array([4.0, 1.5]), np.array([-2.0, 1.5])
    between = math.acos(d1 @ d2 / (np.hypot(*d1) * np.hypot(*d2)))
    assert s.n_states == 4
    assert_allclose(np.sort(s.widths), sorted([math.pi - between, between] * 2), atol=1e-14)
    assert_allclose(s.period, math.pi, atol=1e-15)


@pytest.mark.parametrize("r", [*range(3, 13), 13, 15, 17, 21, 25, 31, 36, 48])
def test_regular_polygons(r: int, rng: np.random.Generator) -> None:
    for _ in range(4):
        radius = float(10.0 ** rng.uniform(-3, 3))
        center = tuple(rng.uniform(-2, 2, size=2) * radius)
        pts = regular_polygon(r, radius, float(rng.uniform(0, TWO_PI)), center)  # type: ignore[arg-type]
        poly = ConvexPolygon.from_points(pts)
        s = squeeze_function(poly)
        assert poly.symmetry_order == r
        assert s.n_states == (2 * r if r % 2 else r)
        assert_allclose(s.period, period_formula(r), rtol=1e-12)
        assert_allclose(s.widths, TWO_PI / s.n_states, rtol=1e-9)
        check_structure(s)


@pytest.mark.parametrize("r", [*range(3, 13), 15, 21, 48])
def test_regular_polygons_from_rounded_coordinates(r: int, rng: np.random.Generator) -> None:
    for _ in range(4):
        radius = float(10.0 ** rng.uniform(-3, 3))
        center = tuple(rng.uniform(-2, 2, size=2) * radius)
        pts = regular_polygon(r, radius, float(rng.uniform(0, TWO_PI)), center)  # type: ignore[arg-type]
        poly = ConvexPolygon.from_points(round_significant(pts, 7))
        s = squeeze_function(poly)
        assert poly.symmetry_order == r
        assert s.n_states == (2 * r if r % 2 else r)
        assert_allclose(s.period, period_formula(r), rtol=1e-12)
        assert_allclose(s.widths, TWO_PI / s.n_states, atol=1e-4)
        check_structure(s)


def test_nearly_symmetric_parts_keep_the_period_pi() -> None:
    # One vertex moved by 1% of the size: the extrema stay nearly periodic, but the part
    # is not symmetric, so the period stays pi.
    for r in (3, 4, 6, 8):
        pts = regular_polygon(r, phase=0.2)
        pts[0] *= 1.01
        poly = ConvexPolygon.from_points(pts)
        assert poly.symmetry_order == 1
        assert_allclose(squeeze_function(poly).period, math.pi)


def test_period_of_shapes_with_a_smaller_symmetry() -> None:
    assert_allclose(squeeze([(0, 0), (2, 0), (3, 1), (2, 2), (0, 2), (-1, 1)]).period, math.pi)
    cut_square = [(1, 0), (2, 0), (3, 1), (3, 2), (2, 3), (1, 3), (0, 2), (0, 1)]
    assert_allclose(squeeze(cut_square).period, math.pi / 2)


# --------------------------------------------------------------------------- brute force


def check_against_descent(points: np.ndarray, m: int = 1 << 14) -> float:
    """s agrees with walking downhill on the sampled width, where the grid resolves it.

    A walk with steps of ``h = 2 pi / m`` steps over a barrier narrower than ``h``, so the
    comparison is made in the basins whose stable orientation lies more than ``3 h`` from
    both ends, and away from the basin ends. Returns the fraction of the grid compared.
    """
    poly = ConvexPolygon.from_points(points)
    s = squeeze_function(poly)
    theta, d, end = descend(poly.vertices, m)
    h = TWO_PI / m
    assert_allclose(diameter_function(poly)(theta), d, atol=1e-12 * poly.size, rtol=0)
    resolved = np.minimum(s.stable - s.basin_lo, s.basin_hi - s.stable) > 3 * h  # (K,)
    near_boundary = circle_distance(theta[:, None], s.boundaries[None, :]).min(axis=1) <= 3 * h
    check = resolved[s.state_index(theta)] & ~near_boundary
    err = circle_distance(s(theta), theta[end])
    assert np.all(err[check] <= 1.01 * h)
    # The walks stop near the stable orientations and nowhere else; each resolved stable
    # orientation is reached.
    stops = np.unique(end)
    assert np.all(circle_distance(theta[stops][:, None], s.stable[None, :]).min(axis=1) <= 2 * h)
    reached = circle_distance(s.stable[:, None], theta[stops][None, :]).min(axis=1) <= h
    assert np.all(reached[resolved])
    # The fraction of starts reaching each state is its uniform-prior probability.
    if np.all(resolved):
        share = np.array([np.mean(circle_distance(theta[end], st) <= 1.01 * h) for st in s.stable])
        assert_allclose(share, s.widths / TWO_PI, atol=8.0 / m)
    return float(np.mean(check))


def test_random_polygons_agree_with_descent(rng: np.random.Generator) -> None:
    # The seed's random polygons: 10 uniform points in the unit square.
    compared = [check_against_descent(rng.random((10, 2))) for _ in range(150)]
    assert np.mean(compared) > 0.97


def test_polygons_with_many_vertices_agree_with_descent(rng: np.random.Generator) -> None:
    for n in (41, 60, 200):
        t = np.sort(rng.uniform(0, 2 * math.pi, n))
        radius = 1 + 0.3 * rng.random(n) * (rng.random(n) < 0.1)
        pts = np.column_stack([radius * np.cos(t), 0.7 * radius * np.sin(t)])
        assert check_against_descent(pts) > 0.5


@given(pts=uniform_points())
def test_uniform_polygons_agree_with_descent(pts: np.ndarray) -> None:
    assert check_against_descent(pts, m=1 << 12) > 0.0


@pytest.mark.parametrize(
    "points",
    [
        SQUARE,
        RIGHT_TRIANGLE,
        PARALLELOGRAM,
        [(0.0, 0.0), (2.0, 0.0), (2.0, 1.5), (1.0, 2.5), (0.0, 1.5)],
        [(0, 0), (10, 0), (10, 0.1), (5, 0.1 + 1e-6), (0, 0.1)],
        [*SQUARE, (0.5, -1e-6)],
        regular_polygon(7),
        regular_polygon(12),
    ],
)
def test_degenerate_shapes_agree_with_descent(points: object) -> None:
    pts = np.asarray(points, dtype=np.float64)
    for beta in (0.0, 0.3, math.pi / 2, 2.0):
        assert check_against_descent(rotate(pts, beta)) > 0.9


# --------------------------------------------------------------------------- properties


@given(pts=convex_points())
def test_structure(pts: np.ndarray) -> None:
    check_structure(squeeze(pts))


@given(pts=convex_points())
def test_stable_orientations_are_fixed_points(pts: np.ndarray) -> None:
    s = squeeze(pts)
    assert_allclose(wrap(s(s.stable) - s.stable), 0.0, atol=0)
    assert_allclose(wrap(s(s.stable + TWO_PI) - s.stable), 0.0, atol=1e-12)
    assert_array_equal(s.state_index(s.stable), np.arange(s.n_states))


@given(pts=convex_points())
def test_basin_ends_are_local_maxima_of_d(pts: np.ndarray) -> None:
    poly = ConvexPolygon.from_points(pts)
    s = squeeze_function(poly)
    v = poly.vertices
    for i in range(s.n_states):
        for end, inner in ((s.basin_lo[i], 1.0), (s.basin_hi[i], -1.0)):
            # Step inward up to a quarter of the way to the stable orientation, and outward
            # as far into the neighbouring basin.
            nxt = s.stable[(i + 1) % s.n_states] + (TWO_PI if i + 1 == s.n_states else 0.0)
            prv = s.stable[i - 1] - (TWO_PI if i == 0 else 0.0)
            room_in = abs(s.stable[i] - end)
            room_out = abs((nxt if inner < 0 else prv) - end)
            step = min(1e-3, 0.25 * room_in, 0.25 * room_out)
            here = float(width(v, end))
            assert width(v, end + inner * step) < here
            assert width(v, end - inner * step) < here
        # Stable orientations are local minima.
        step = min(1e-3, 0.25 * (s.stable[i] - s.basin_lo[i]), 0.25 * (s.basin_hi[i] - s.stable[i]))
        here = float(width(v, s.stable[i]))
        assert width(v, s.stable[i] - step) > here
        assert width(v, s.stable[i] + step) > here


@given(pts=convex_points(), theta=st.lists(angles(), min_size=1, max_size=30))
def test_s_is_monotone_with_the_pi_shift(pts: np.ndarray, theta: list[float]) -> None:
    s = squeeze(pts)
    th = np.array(theta)
    # Away from the unstable equilibria (which stay put).
    keep = circle_distance(th[:, None], s.boundaries[None, :]).min(axis=1) > 1e-9
    th = th[keep]
    out = s(th)
    assert np.all((out >= 0) & (out < TWO_PI))
    assert_allclose(wrap(s(th + math.pi) - out - math.pi), 0.0, atol=1e-12)
    assert_allclose(wrap(s(th + s.period) - out - s.period), 0.0, atol=1e-9)
    # Lifted to the real line, s is non-decreasing and moves theta by less than a basin.
    base = np.sort(np.mod(th, TWO_PI))
    lifted = base + wrap(s(base) - base)
    assert np.all(np.diff(lifted) >= -1e-12)
    assert np.all(np.abs(wrap(s(base) - base)) < s.widths.max())


@given(pts=convex_points())
def test_unstable_equilibria_stay_put(pts: np.ndarray) -> None:
    s = squeeze(pts)
    assert_allclose(wrap(s(s.boundaries) - s.boundaries), 0.0, atol=1e-12)


@given(pts=convex_points(), seed=st.integers(0, 2**32 - 1))
def test_probabilities_sum_to_one(pts: np.ndarray, seed: int) -> None:
    s = squeeze(pts)
    rng = np.random.default_rng(seed)
    priors = [
        UniformPrior(),
        HistogramPrior(rng.random(int(rng.integers(1, 50)))),
        von_mises(float(rng.uniform(0, TWO_PI)), float(rng.uniform(0, 20)), bins=360),
        SamplePrior(rng.uniform(-10, 10, size=int(rng.integers(1, 30)))),
    ]
    for prior in priors:
        for shift in (0.0, float(rng.uniform(-10, 10))):
            p = prior.mass(s.basin_lo + shift, s.basin_hi + shift)
            assert np.all(p >= -1e-15)
            assert_allclose(p.sum(), 1.0, atol=1e-12)


@given(pts=lattice_points(), beta=st.floats(0, TWO_PI))
def test_rotating_the_input_shifts_the_stable_orientations(pts: np.ndarray, beta: float) -> None:
    a = squeeze(pts)
    b = squeeze(rotate(pts, beta))
    assert same_circle_set(a.stable - beta, b.stable, 1e-9)
    assert same_circle_set(a.boundaries - beta, b.boundaries, 1e-9)
    assert_allclose(np.sort(a.widths), np.sort(b.widths), atol=1e-9)
    assert_allclose(a.period, b.period, atol=1e-12)


@given(
    pts=lattice_points(),
    shift=st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
    scale=st.floats(1e-3, 1e3),
)
def test_translation_and_scaling_change_nothing(
    pts: np.ndarray, shift: tuple[float, float], scale: float
) -> None:
    a = squeeze(pts)
    b = squeeze(pts * scale + np.array(shift) * scale)
    assert same_circle_set(b.stable, a.stable, 1e-9)
    assert same_circle_set(b.boundaries, a.boundaries, 1e-9)
    assert_allclose(np.sort(b.widths), np.sort(a.widths), atol=1e-9)
    assert b.period == a.period


@given(pts=convex_points(), data=st.data())
def test_vertex_order_interior_and_duplicate_points_change_nothing(
    pts: np.ndarray, data: st.DataObject
) -> None:
    a = squeeze(pts)
    poly = ConvexPolygon.from_points(pts)
    perm = list(data.draw(st.permutations(range(len(pts)))))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    w = rng.dirichlet(np.ones(poly.n_sides), size=5)
    inside = poly.centroid + 0.5 * (w @ poly.vertices - poly.centroid)
    more = np.vstack([pts[perm], inside, pts[perm[:3]]])
    b = squeeze(more)
    assert_array_equal(b.stable, a.stable)
    assert_array_equal(b.basin_lo, a.basin_lo)
    assert_array_equal(b.basin_hi, a.basin_hi)


@given(pts=convex_points())
def test_period_divides_the_symmetry_formula(pts: np.ndarray) -> None:
    poly = ConvexPolygon.from_points(pts)
    s = squeeze_function(poly)
    ratio = period_formula(poly.symmetry_order) / s.period if poly.symmetry_order > 1 else 1.0
    if poly.symmetry_order > 1:
        assert abs(ratio - round(ratio)) < 1e-9
    else:
        assert s.period <= math.pi + 1e-12


# --------------------------------------------------------------------------- API details


def test_call_and_state_index_shapes() -> None:
    s = squeeze(SQUARE)
    assert s(0.3).shape == ()
    assert s(np.zeros((2, 3))).shape == (2, 3)
    assert_array_equal(s.state_index([0.1, 1.6, 3.2, 4.8, 6.2]), [0, 1, 2, 3, 0])
    assert_allclose(s([-0.1, 0.1, 2.0, 7.0]), [0.0, 0.0, math.pi / 2, 0.0], atol=1e-15)


def test_arrays_are_read_only_and_frozen() -> None:
    s = squeeze(PARALLELOGRAM)
    for arr in (s.stable, s.basin_lo, s.basin_hi):
        assert not arr.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.period = 1.0  # type: ignore[misc]


def test_squeeze_function_accepts_a_diameter_function() -> None:
    poly = ConvexPolygon.from_points(PARALLELOGRAM)
    a = squeeze_function(poly)
    b = squeeze_function(diameter_function(poly))
    assert_array_equal(a.stable, b.stable)
    assert a.kind == b.kind == "squeeze"


def test_detect_period() -> None:
    k = np.arange(6)
    assert_allclose(detect_period(k * math.pi / 3, k * math.pi / 3 + 0.5, 1e-9), math.pi / 3)
    stable = np.array([0.0, 1.0, math.pi, math.pi + 1.0])
    assert_allclose(detect_period(stable, stable + 0.5, 1e-9), math.pi)
    lop = np.array([0.0, 2.0])  # no shift of the pair maps it onto itself but 2 pi
    assert_allclose(detect_period(lop, lop + 0.5, 1e-9), TWO_PI)
    # A shift that maps the stable orientations but not the boundaries is no period.
    assert_allclose(detect_period(k * math.pi / 3, k * math.pi / 3 + 0.01 * k, 1e-9), TWO_PI)


def test_transfer_from_extrema() -> None:
    f = transfer_from_extrema("push", np.array([1.0, 4.0]), np.array([6.0, 2.0]), 1e-9, 1e-6)
    assert f.kind == "push"
    assert_allclose(f.stable, [1.0, 4.0])
    assert_allclose(f.basin_lo, [6.0 - TWO_PI, 2.0])
    assert_allclose(f.basin_hi, [2.0, 6.0])
    assert f.period == TWO_PI
    with pytest.raises(BayesGraspError, match=r"alternate|differ"):
        transfer_from_extrema("push", np.array([1.0, 1.5]), np.array([2.0, 3.0]), 1e-9, 1e-6)
