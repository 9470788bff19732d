"""Numerical robustness of the geometry layer (issue 15, item 13: what a fuzzer found).

* Odd inputs to :func:`as_points` and :meth:`Part.from_points` (Python ints beyond the float
  range, ragged or nested lists, None, dicts, object arrays ...) raise :class:`PartError`
  naming the parameter, never anything else.
* Near-regular polygons: the extrema of the diameter function alternate and pair up, in the
  numpy and the plain-Python paths alike (the same decisions), and agree with the brute-force
  grid descent of ``tests/reference.py``.
* Near-symmetric parts are symmetric within ``Tolerance.symmetry`` and everything downstream
  agrees: the squeeze, push and push-grasp periods follow ``symmetry_order``, and
  ``F(theta + T) = F(theta) + T`` holds to the angle tolerance.
"""

from __future__ import annotations

import decimal
import fractions
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from numpy.typing import NDArray

from bayesgrasp.errors import PartError
from bayesgrasp.geometry import diameter_pieces, symmetry
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import ConvexPolygon, Part, as_points
from bayesgrasp.geometry.push import push_function, push_grasp_function
from bayesgrasp.geometry.transfer import TransferFunction, squeeze_function
from bayesgrasp.model.problem import Problem
from bayesgrasp.tolerance import DEFAULT_TOLERANCE, MIN_ANGLE, Tolerance
from reference import TWO_PI, circle_distance, descend, local_minima, regular_polygon

FloatArray = NDArray[np.float64]

# The symmetry test switched off: every part is taken as it is (no symmetrization), so the
# extrema come from the noisy polygon itself.
EXACT = Tolerance(symmetry=0.0)


def period_formula(r: int) -> float:
    """Goldberg (1993): the squeeze period of an r-fold symmetric part."""
    return TWO_PI / (r * (1 + r % 2))


def near_regular(
    n: int, noise: float, rng: np.random.Generator, radius: float = 1.0, phase: float = 0.0
) -> FloatArray:
    """A regular n-gon with normal noise of ``noise * radius`` on every coordinate."""
    center = tuple(rng.uniform(-2, 2, size=2) * radius)
    pts = regular_polygon(n, radius, phase, center)  # type: ignore[arg-type]
    return pts + rng.normal(scale=noise * radius, size=pts.shape)


@st.composite
def near_regular_points(draw: st.DrawFn, max_n: int = 60) -> FloatArray:
    """Near-regular polygons: 3 to 60 sides, noise 1e-12 to 1e-6 of the radius, any size."""
    n = draw(st.integers(3, max_n))
    noise = 10.0 ** draw(st.floats(-12, -6))
    radius = 10.0 ** draw(st.floats(-3, 3))
    phase = draw(st.floats(0, TWO_PI))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    return near_regular(n, noise, rng, radius, phase)


def shift_error(f: TransferFunction, theta: FloatArray) -> float:
    """Largest ``|F(theta + T) - F(theta) - T|`` on the circle."""
    return float(np.max(circle_distance(f(theta + f.period), f(theta) + f.period)))


def alternate(minima: FloatArray, maxima: FloatArray) -> bool:
    """Whether minima and maxima pair up and alternate around the circle."""
    if len(minima) != len(maxima) or len(minima) == 0:
        return False
    both = np.concatenate([minima, maxima])
    kinds = np.concatenate([np.zeros(len(minima)), np.ones(len(maxima))])[np.argsort(both)]
    return bool(np.all(np.diff(kinds) != 0))


# --------------------------------------------------------------------------- odd inputs


@pytest.mark.parametrize(
    "points",
    [
        [[0, 0], [10**400, 0], [0, 1]],
        [[0, 0], [1, 0], [0, -(10**5000)]],  # 5001 digits
        [[fractions.Fraction(10**400), 0], [0, 0], [0, 1]],
        np.array([[0, 0], [1, 0], [0, 10**400]], dtype=object),
        [[0, 0], [np.int64(5), 0], [0, 10**309]],
    ],
)
def test_numbers_beyond_the_float_range_are_a_part_error(points: object) -> None:
    with pytest.raises(PartError, match="`vertices` must be finite numbers within the range"):
        Part.from_points(points)  # type: ignore[arg-type]
    with pytest.raises(PartError, match="`outline` must be finite"):
        as_points(points, "outline")  # type: ignore[arg-type]


def test_a_huge_centre_of_mass_is_a_part_error() -> None:
    with pytest.raises(PartError, match="`center_of_mass` must be finite"):
        Part.from_points([[0, 0], [1, 0], [0, 1]], center_of_mass=[0.1, 10**400])


class _Unreadable:
    """An object whose conversion to an array fails."""

    def __len__(self) -> int:
        raise TypeError("no length")

    def __getitem__(self, i: int) -> int:
        raise TypeError("no items")


class _BadFloat(fractions.Fraction):
    """A real number whose conversion to float fails."""

    def __float__(self) -> float:
        raise ValueError("no float")


@pytest.mark.parametrize(
    "points",
    [
        None,
        {},
        {"x": 1},
        {1, 2},
        "abc",
        b"abc",
        3,
        [[0, 0], [1], [0, 1]],
        [[0, 0], [1, 0], [0, None]],
        [[0, 0], [1, 0], [0, (1,)]],
        eval("[" * 70 + "1" + "]" * 70),  # deeper than numpy's 64 dimensions
        np.array([[0, [1]], [1, 0], [0, 1]], dtype=object),
        np.zeros((3, 2), dtype="m8"),
        np.array([(0, 0), (1, 0)], dtype=[("x", "f8"), ("y", "f8")]),
        [[decimal.Decimal(1), 0], [0, 0], [0, 1]],
        [[_BadFloat(1), 0], [0, 0], [0, 1]],
        [[1 + 2j, 0], [0, 0], [0, 1]],
        _Unreadable(),
        "OBJECT-ARRAY-OF-A-HUGE-INT",
    ],
)
def test_odd_inputs_are_a_part_error(points: object) -> None:
    # An int of 5001 digits inside an object array: its repr fails (over 4300 digits).
    if isinstance(points, str) and points == "OBJECT-ARRAY-OF-A-HUGE-INT":
        points = _object_array([[10**5000, "x"], (0, 0), (0, 1)], rows=False)
    with pytest.raises(PartError, match="`vertices`"):
        Part.from_points(points)  # type: ignore[arg-type]


_LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-5, 5),
    st.integers(),
    st.integers(10**300, 10**4000) | st.integers(-(10**4000), -(10**300)),  # repr < 4300 digits
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=3),
    st.binary(max_size=3),
    st.fractions(),
    st.decimals(allow_nan=True),
    st.complex_numbers(),
)
_TREES = st.recursive(
    _LEAVES,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.tuples(inner, inner),
        st.dictionaries(st.text(max_size=2), inner, max_size=2),
    ),
    max_leaves=12,
)
_POINT_LISTS = st.lists(
    st.one_of(st.tuples(_LEAVES, _LEAVES), st.lists(_LEAVES, max_size=3), _LEAVES),
    max_size=6,
)


def _object_array(items: list[Any], rows: bool) -> NDArray[Any]:
    """Items in a numpy object array (1-D, or 2-D when every item is a pair)."""
    if rows and items and all(isinstance(x, tuple) and len(x) == 2 for x in items):
        out = np.empty((len(items), 2), dtype=object)
        for i, (a, b) in enumerate(items):
            out[i, 0], out[i, 1] = a, b
        return out
    out = np.empty(len(items), dtype=object)
    for i, x in enumerate(items):
        out[i] = x
    return out


@settings(max_examples=300)
@given(
    points=st.one_of(_TREES, _POINT_LISTS, _POINT_LISTS.map(lambda x: _object_array(x, True))),
    wrap=st.booleans(),
)
def test_only_part_errors_escape_from_odd_inputs(points: Any, wrap: bool) -> None:
    if wrap and isinstance(points, list):
        points = _object_array(points, False)
    try:
        arr = as_points(points)
    except PartError as exc:
        assert "`vertices`" in str(exc)
    else:
        assert arr.dtype == np.float64
        assert arr.ndim == 2
        assert arr.shape[1] == 2
        assert np.all(np.isfinite(arr))
    try:
        Part.from_points(points)
    except PartError:
        pass


# --------------------------------------------------------------------------- the extrema


def test_near_regular_12_gons_build_a_problem() -> None:
    # The fuzzer's reproducer: 13 of these 200 failed with "internal error: 5 minima and 6
    # maxima of the diameter" (opposite edges parallel to about 1e-9 rad).
    rng = np.random.default_rng(0)
    n = 12
    a = 2 * np.pi * np.arange(n) / n
    for _ in range(200):
        pts = np.c_[np.cos(a), np.sin(a)] + rng.normal(scale=1e-10, size=(n, 2))
        problem = Problem.build(Part.from_points(pts))
        assert problem.n_states == 12


def _check_paths(v: FloatArray, tol: float, period: float) -> None:
    """Both paths find alternating, paired extrema, and the same ones."""
    a = diameter_pieces.pieces_numpy(v, tol, period)
    b = diameter_pieces.pieces_python(*v.T.tolist(), tol, period)
    scale = max(1.0, float(np.max(np.abs(v))))  # lengths scale with the part, angles do not
    for x, y in zip(a[:5], b[:5], strict=True):
        assert_allclose(x, y, atol=1e-13 * scale, rtol=0)
    for ext in (a[5], b[5]):
        min_at, _, max_at, _ = ext
        lo = a[0][0]
        wrapped = [np.mod(np.asarray(x) - lo, period) for x in (min_at, max_at)]
        assert alternate(*wrapped), (len(min_at), len(max_at))
    for x, y in zip(a[5], b[5], strict=True):
        assert len(x) == len(y)
        assert_allclose(sorted(x), sorted(y), atol=1e-12 * scale, rtol=0)


@pytest.mark.parametrize("n", range(3, 61))
def test_near_regular_polygons_have_paired_extrema(n: int) -> None:
    rng = np.random.default_rng(n)
    for noise in (1e-12, 1e-11, 1e-10, 3e-10, 1e-9, 1e-8, 1e-7, 1e-6):
        for _ in range(4):
            pts = near_regular(n, noise, rng, phase=float(rng.uniform(0, TWO_PI)))
            # The noisy polygon itself (what the earlier code classified) ...
            poly = ConvexPolygon.from_points(pts, EXACT)
            _check_paths(poly.vertices, poly.tol.angle, math.pi)
            d = diameter_function(poly)
            assert alternate(d.minima, d.maxima)
            # ... and the default, where a symmetric part uses one period of its
            # symmetrized vertices.
            sym = ConvexPolygon.from_points(pts)
            r = sym.symmetry_order
            if r > 2:
                _check_paths(sym.symmetrized(), sym.tol.angle, period_formula(r))
            d = diameter_function(sym)
            assert alternate(d.minima, d.maxima)


@settings(max_examples=200)
@given(pts=near_regular_points())
def test_both_paths_decide_alike_on_near_regular_polygons(pts: FloatArray) -> None:
    poly = ConvexPolygon.from_points(pts, EXACT)
    _check_paths(poly.vertices, poly.tol.angle, math.pi)


def _check_against_descent(f: TransferFunction, points: FloatArray, slack: float) -> None:
    """The squeeze function agrees with a grid descent of the width of ``points``.

    Every grid angle farther than ``slack`` plus two grid steps from a basin boundary ends
    where the descent ends, within ``slack`` plus a grid step; the local minima of the width
    on the grid are the stable orientations.
    """
    m = 1 << 15
    theta, d, end = descend(points, m)
    step = TWO_PI / m
    margin = slack + 2 * step
    away = np.min(circle_distance(theta[:, None], f.boundaries[None, :]), axis=1) > margin
    got = f(theta[away])
    assert np.max(circle_distance(got, theta[end[away]])) <= slack + step
    grid_minima = theta[local_minima(d)]
    assert len(grid_minima) == f.n_states
    assert np.max(np.min(circle_distance(grid_minima[:, None], f.stable[None, :]), axis=1)) <= (
        slack + step
    )


@pytest.mark.parametrize("n", [3, 4, 5, 6, 7, 8, 9, 12, 16, 24, 31, 40, 41, 60])
@pytest.mark.parametrize("noise", [1e-12, 1e-10, 1e-8, 1e-6])
def test_near_regular_squeeze_agrees_with_the_grid_descent(n: int, noise: float) -> None:
    rng = np.random.default_rng(1000 * n + int(-math.log10(noise)))
    for _ in range(2):
        pts = near_regular(n, noise, rng, phase=float(rng.uniform(0, TWO_PI)))
        # How far the noise can move an edge alignment (an edge is 2 sin(pi / n) long).
        slack = 40 * noise / math.sin(math.pi / n) + 1e-9
        for tol in (DEFAULT_TOLERANCE, EXACT):
            poly = ConvexPolygon.from_points(pts, tol)
            _check_against_descent(squeeze_function(poly), poly.vertices, slack)


# --------------------------------------------------------------------------- the barrier


def _drop_shallow_reference(ext: list[Any], depth: float) -> list[Any]:
    """Cancel the shallowest neighbouring pair (first in angle on ties) until none is left."""
    ext = list(ext)
    while len(ext) > 2:
        m = len(ext)
        rise = [abs(ext[(i + 1) % m][1] - ext[i][1]) for i in range(m)]
        i = min(range(m), key=lambda k: (rise[k], k))
        if rise[i] > depth:
            break
        drop = {i, (i + 1) % m}
        ext = [x for k, x in enumerate(ext) if k not in drop]
    return ext


@given(
    values=st.lists(st.integers(0, 6), min_size=1, max_size=30),
    depth=st.integers(0, 4),
)
def test_drop_shallow_cancels_the_shallowest_pair_first(values: list[int], depth: int) -> None:
    # Alternating minima and maxima with small integer depths: many ties.
    ext = []
    level = 0.0
    for i, x in enumerate(values):
        level += x if i % 2 == 0 else -x
        ext.append((float(i), level, i % 2 == 0))
    if len(ext) % 2:
        ext.pop()
    if not ext:
        return
    got = diameter_pieces.drop_shallow(ext, float(depth))
    assert got == _drop_shallow_reference(ext, float(depth))
    assert len(got) >= 2
    assert all(a[2] != b[2] for a, b in zip(got, got[1:] + got[:1], strict=True))


# --------------------------------------------------------------------------- symmetry


@settings(max_examples=150)
@given(pts=near_regular_points(), data=st.data())
def test_near_symmetric_parts_agree_downstream(pts: FloatArray, data: st.DataObject) -> None:
    part = Part.from_points(pts)
    poly = part.hull
    r = poly.symmetry_order
    s = squeeze_function(poly)
    theta = np.array(data.draw(st.lists(st.floats(0, TWO_PI), min_size=1, max_size=50)))
    tol = poly.tol.angle
    if r > 1:
        assert_allclose(s.period, period_formula(r), rtol=1e-12)
    else:
        assert_allclose(s.period, math.pi, rtol=1e-12)
    assert shift_error(s, theta) <= tol
    # The diameter function's extrema carry the same period.
    d = diameter_function(poly)
    both = np.concatenate([d.minima, d.maxima])
    turned = np.mod(both + s.period, math.pi)
    assert np.max(np.min(circle_distance(turned[:, None], both[None, :], math.pi), axis=1)) <= tol
    # The centre of mass is the centroid: pushing has the period 2 pi / r, and so has the
    # push-grasp g = s o p.
    for f in (push_function(part), push_grasp_function(part, s)):
        assert_allclose(f.period, TWO_PI / r, rtol=1e-12)
        assert shift_error(f, theta) <= tol


@given(pts=near_regular_points(max_n=24), data=st.data())
def test_symmetrized_extrema_stay_near_the_part(pts: FloatArray, data: st.DataObject) -> None:
    poly = ConvexPolygon.from_points(pts)
    d = diameter_function(poly)
    v = poly.vertices
    e = np.roll(v, -1, axis=0) - v
    alignments = np.mod(-np.arctan2(e[:, 1], e[:, 0]) + math.pi / 2, math.pi)
    shortest = float(np.min(np.hypot(e[:, 0], e[:, 1])))
    # A minimum is at an edge alignment of the part, up to how far the symmetrization moved
    # a vertex (at most tol.symmetry * size) over an edge's length.
    moved = float(np.max(np.abs(poly.symmetrized() - v)))
    bound = 4 * moved / shortest + 1e-9
    dist = circle_distance(d.minima[:, None], alignments[None, :], math.pi)
    assert np.max(np.min(dist, axis=1)) <= bound
    assert moved <= poly.tol.symmetry_for(poly.size)


def test_a_noisy_1000_gon_has_an_exact_period() -> None:
    # The fuzzer's reproducer: s(t + T) = s(t) + T was broken by 6e-4 deg.
    rng = np.random.default_rng(0)
    pts = regular_polygon(1000) + rng.normal(scale=1e-8, size=(1000, 2))
    poly = ConvexPolygon.from_points(pts)
    s = squeeze_function(poly)
    assert poly.symmetry_order == 1000
    assert_allclose(s.period, TWO_PI / 1000, rtol=1e-12)
    assert s.n_states == 1000
    assert shift_error(s, rng.uniform(0, TWO_PI, 20000)) <= poly.tol.angle


def test_a_regular_99999_gon_has_the_period_of_its_symmetry() -> None:
    # The fuzzer's reproducer: symmetry order 99,999 but a squeeze period of 180 deg (every
    # minimum of d lies less than the barrier below its maxima; the barrier dropped all but
    # one pair, in 13 s).
    poly = ConvexPolygon.from_points(regular_polygon(99_999))
    s = squeeze_function(poly)
    assert poly.symmetry_order == 99_999
    assert s.n_states == 199_998
    assert_allclose(s.period, period_formula(99_999), rtol=1e-12)
    theta = np.random.default_rng(1).uniform(0, TWO_PI, 5000)
    assert shift_error(s, theta) <= poly.tol.angle


@pytest.mark.parametrize("n", [3, 4, 6, 8, 12])
@pytest.mark.parametrize("angle", [MIN_ANGLE, DEFAULT_TOLERANCE.angle])
def test_symmetric_parts_far_from_the_origin_keep_their_period(n: int, angle: float) -> None:
    # Reproducers: a square of size 0.007 at 5e5 from the origin (default tolerance), and a
    # triangle under the smallest angle tolerance, failed with "internal error: ... do not
    # alternate / differ": the symmetrized vertices were rounded to the coordinates' ulp.
    rng = np.random.default_rng(n)
    tol = Tolerance(angle=angle)
    for offset, size in ((0.0, 1.0), (1e4, 0.1), (5e5, 0.007), (1e8, 1.0)):
        pts = regular_polygon(n, size, rng.uniform(0, TWO_PI), (offset, offset))
        part = Part.from_points(pts, tol=tol)
        poly = part.hull
        assert poly.symmetry_order == n
        s = squeeze_function(poly)
        assert_allclose(s.period, period_formula(n), rtol=1e-12)
        assert shift_error(s, rng.uniform(0, TWO_PI, 500)) <= angle
        assert_allclose(push_function(part).period, TWO_PI / n, rtol=1e-12)


def test_not_quite_symmetric_parts_have_the_period_pi() -> None:
    # Beyond the symmetry tolerance the part is not symmetric, however periodic its extrema
    # look: the period is the one the extrema have to the angle tolerance (pi here).
    rng = np.random.default_rng(5)
    for n in (3, 4, 6, 9, 12):
        pts = near_regular(n, 1e-3, rng)
        poly = ConvexPolygon.from_points(pts)
        assert poly.symmetry_order == 1
        s = squeeze_function(poly)
        assert_allclose(s.period, math.pi, rtol=1e-12)
        assert shift_error(s, rng.uniform(0, TWO_PI, 1000)) <= poly.tol.angle


@pytest.mark.parametrize("n", [5, 6, 9, 12, 15, 24, 60, 66, 96, 120, 1000])
def test_symmetry_order_python_and_numpy_agree(n: int) -> None:
    rng = np.random.default_rng(n)
    for noise in (1e-9, 3e-6, 1e-5, 1e-3):
        poly = ConvexPolygon.from_points(near_regular(n, noise, rng))
        eps = poly.tol.symmetry_for(poly.size)
        orders = [r for r in range(2, n + 1) if n % r == 0][::-1]
        xs, ys = poly.vertices.T.tolist()
        expected = symmetry.symmetry_order_python(xs, ys, poly.centroid, orders, eps)
        assert poly.symmetry_order == expected
        # Asking for the orders from 3 up first, then for all, gives the same answers.
        fresh = ConvexPolygon.from_points(poly.vertices)
        low = fresh.symmetry_order_from(3)
        assert low == (expected if expected >= 3 else 1)
        assert fresh.symmetry_order == expected
        assert fresh.symmetry_order_from(3) == low


def test_symmetry_order_from_skips_the_lower_orders() -> None:
    rect = ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    assert rect.symmetry_order_from(3) == 1
    assert rect.symmetry_order == 2
    assert rect.symmetry_order_from(2) == 2
    square = ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)])
    assert square.symmetry_order_from(3) == 4
    assert square.symmetry_order_from(5) == 1


# --------------------------------------------------------------------------- tolerances


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"angle": -1e-9}, "`angle` must be a finite number >= 0; got -1e-09"),
        ({"length": float("nan")}, "`length` must be a finite number >= 0; got nan"),
        ({"symmetry": float("inf")}, "`symmetry` must be a finite number >= 0"),
        ({"barrier": "1e-9"}, "`barrier` must be a finite number >= 0; got '1e-9'"),
        ({"probability": True}, "`probability` must be a finite number >= 0; got True"),
        ({"angle": 0.0}, "`angle` must be at least 1e-12 rad .*; got 0.0"),
        ({"angle": 1e-13}, "`angle` must be at least 1e-12 rad"),
    ],
)
def test_tolerances_are_validated(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(PartError, match=match):
        Tolerance(**kwargs)


def test_a_tolerance_must_be_a_tolerance() -> None:
    with pytest.raises(PartError, match="`tol` must be a Tolerance; got float"):
        ConvexPolygon.from_points([(0, 0), (1, 0), (0, 1)], 1e-9)  # type: ignore[arg-type]
