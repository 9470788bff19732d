"""The set-up's plain-Python paths against the general ones (issue 12).

Each shortcut of the hull, the centre-of-mass check, the diameter and squeeze functions and
their lazily made arrays is compared with the path it replaces: the numpy path (the cut-off
``sizes.SMALL`` forced to 0), the full test it skips, or the arrays it defers. Inputs are
random, near-regular (symmetric within the tolerance or just outside), thin, lattice points
full of repeated and collinear points, and clouds on both sides of the cut-off.
"""

from __future__ import annotations

import dataclasses
import math
import pickle
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from bayesgrasp.angles import TWO_PI
from bayesgrasp.errors import BayesGraspError, PartError, PlanningError
from bayesgrasp.geometry import convex, diameter, diameter_pieces, polygon
from bayesgrasp.geometry import part as part_module
from bayesgrasp.geometry.curved import squeeze_model
from bayesgrasp.geometry.diameter import DiameterFunction, diameter_function
from bayesgrasp.geometry.polygon import ConvexPolygon, Part, hull_contains
from bayesgrasp.geometry.transfer import TransferFunction, _period_count, squeeze_function
from bayesgrasp.tolerance import MIN_ANGLE, Tolerance
from reference import regular_polygon
from strategies import convex_points, lattice_points

FloatArray = np.ndarray


@st.composite
def thin_points(draw: st.DrawFn) -> FloatArray:
    """Slivers: a few points spread along x, at most ``10**-k`` across (k up to 9.5)."""
    n = draw(st.integers(3, 12))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    height = 10.0 ** draw(st.floats(-9.5, -1))
    offset = 10.0 ** draw(st.floats(-2, 6))  # far from the origin too
    pts = np.column_stack([rng.uniform(size=n), rng.uniform(size=n) * height])
    return pts + offset


@st.composite
def near_regular_points(draw: st.DrawFn) -> FloatArray:
    """Regular 3- to 70-gons with noise from none to well past the symmetry tolerance."""
    n = draw(st.integers(3, 70))
    noise = draw(st.sampled_from([0.0, 1e-12, 1e-9, 1e-7, 3e-6, 1e-5, 3e-5, 1e-3]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    pts = regular_polygon(n, 1.0, float(rng.uniform(0, TWO_PI)), (0.3, -0.2))
    return np.asarray(pts + rng.normal(scale=noise, size=pts.shape), dtype=np.float64)


@st.composite
def cloud_points(draw: st.DrawFn) -> FloatArray:
    """Normal clouds of 3 to 150 points: both sides of the cut-off."""
    n = draw(st.integers(3, 150))
    return np.random.default_rng(draw(st.integers(0, 2**32 - 1))).normal(size=(n, 2))


def any_points() -> st.SearchStrategy[FloatArray]:
    return st.one_of(
        convex_points(),
        lattice_points(max_size=40, bound=4),
        thin_points(),
        near_regular_points(),
        cloud_points(),
    )


@pytest.fixture
def numpy_everywhere() -> Iterator[None]:
    """The hull, symmetry test and diameter pieces by numpy for every size."""
    saved = convex._SMALL, part_module._SMALL, diameter._SMALL
    convex._SMALL = part_module._SMALL = diameter._SMALL = 0
    try:
        yield
    finally:
        convex._SMALL, part_module._SMALL, diameter._SMALL = saved


def model(points: FloatArray) -> tuple[Part, DiameterFunction, TransferFunction] | None:
    try:
        part = Part.from_points(points)
        d, s = squeeze_model(part)
    except (PartError, PlanningError):  # refused: the other path must refuse too
        return None
    assert isinstance(d, DiameterFunction)
    return part, d, s


# --------------------------------------------------------------------------- the whole set-up


@settings(max_examples=150, deadline=None)
@given(pts=any_points())
def test_plain_python_set_up_matches_numpy(pts: FloatArray) -> None:
    small = model(pts)
    saved = convex._SMALL, part_module._SMALL, diameter._SMALL
    convex._SMALL = part_module._SMALL = diameter._SMALL = 0
    try:
        general = model(pts)
    finally:
        convex._SMALL, part_module._SMALL, diameter._SMALL = saved
    assert (small is None) == (general is None)
    if small is None or general is None:
        return
    (p1, d1, s1), (p2, d2, s2) = small, general
    # The hull is exact (the same points and decisions); sums may differ in the last bits.
    assert_array_equal(p1.hull.vertices, p2.hull.vertices)
    assert_allclose(p1.center_of_mass, p2.center_of_mass, rtol=1e-12, atol=1e-12 * p1.hull.size)
    assert p1.hull.symmetry_order == p2.hull.symmetry_order
    assert d1.minima.shape == d2.minima.shape and d1.maxima.shape == d2.maxima.shape
    assert_array_equal(d1.pairs, d2.pairs)
    assert_allclose(d1.breaks, d2.breaks, atol=1e-12, rtol=0)
    assert s1.n_states == s2.n_states
    assert_allclose(s1.stable, s2.stable, atol=1e-11, rtol=0)
    assert_allclose(s1.basin_hi, s2.basin_hi, atol=1e-11, rtol=0)
    assert s1.period == pytest.approx(s2.period, abs=1e-12)


def test_the_study_polygons_match_numpy(numpy_everywhere: None) -> None:
    rng = np.random.default_rng(1)
    clouds = [rng.uniform(size=(10, 2)) for _ in range(200)]
    general = [squeeze_model(Part.from_points(c))[1] for c in clouds]
    convex._SMALL, part_module._SMALL, diameter._SMALL = 64, 64, 64
    for c, s2 in zip(clouds, general, strict=True):
        s1 = squeeze_model(Part.from_points(c))[1]
        assert s1.n_states == s2.n_states and s1.period == s2.period
        assert_allclose(s1.stable, s2.stable, atol=1e-12, rtol=0)


# --------------------------------------------------------------------------- the hull


@settings(max_examples=200, deadline=None)
@given(pts=st.one_of(thin_points(), convex_points(), near_regular_points()))
def test_centroid_shortcut_agrees_with_the_full_test(pts: FloatArray) -> None:
    try:
        hull = ConvexPolygon.from_points(pts)
    except PartError:  # a sliver below the tolerance is no part
        return
    assert part_module.holds_centroid(hull) == hull_contains(hull, hull.centroid)


def test_centroid_shortcut_near_its_threshold(monkeypatch: pytest.MonkeyPatch) -> None:
    """Slivers down to the thinnest part: the same answers, the full test run on the thin."""
    full_tests = []

    def counted(hull: ConvexPolygon, point: FloatArray) -> bool:
        full_tests.append(hull)
        return hull_contains(hull, point)

    monkeypatch.setattr(part_module, "hull_contains", counted)
    rng = np.random.default_rng(5)
    tested = 0
    for height in np.geomspace(1e-11, 1e-6, 400):
        pts = np.column_stack([rng.uniform(size=6), rng.uniform(size=6) * height]) + 3.0
        try:
            hull = ConvexPolygon.from_points(pts)
        except PartError:  # too thin to be a part
            continue
        assert part_module.holds_centroid(hull) == hull_contains(hull, hull.centroid)
        tested += 1
    assert 0 < len(full_tests) < tested > 100  # the shortcut and the full test both ran


def test_cached_coordinates_are_the_vertices() -> None:
    hull = ConvexPolygon.from_points(np.random.default_rng(2).uniform(size=(10, 2)))
    xs, ys = hull._coords()
    assert [xs, ys] == hull.vertices.T.tolist()
    big = ConvexPolygon.from_points(np.random.default_rng(2).normal(size=(500, 2)))
    assert list(big._coords()) == big.vertices.T.tolist()  # made on first use


# --------------------------------------------------------------------------- the period


@settings(max_examples=150, deadline=None)
@given(pts=any_points())
def test_half_turn_needs_no_test(pts: FloatArray) -> None:
    """A squeeze function's half turn always passes: skipping it changes no period."""
    built = model(pts)
    if built is None:
        return
    s = built[2]
    stable, _, hi = (list(x) for x in s.values)
    bounds = sorted(x % TWO_PI for x in hi)
    tol = s.angle_tol
    full = _period_count(stable, bounds, len(stable), 1, tol)
    assert _period_count(stable, bounds, len(stable), 1, tol, known=2) == full >= 2
    assert s.period == TWO_PI / full


# --------------------------------------------------------------------------- lazy arrays


def square_ish() -> ConvexPolygon:
    return ConvexPolygon.from_points([(0, 0), (2, 0), (2.2, 1), (0, 1.1)])


def test_transfer_function_values_and_arrays_agree() -> None:
    s = squeeze_function(square_ish())
    values = s.values
    for arr, vals in zip((s.stable, s.basin_lo, s.basin_hi), values, strict=True):
        assert arr.dtype == np.float64 and not arr.flags.writeable
        assert tuple(arr.tolist()) == vals
        assert all(type(x) is float for x in vals)
    assert s.stable is s.stable  # made once
    assert s.n_states == len(values[0])


def test_transfer_function_from_arrays_and_lists() -> None:
    s = squeeze_function(square_ish())
    a = TransferFunction("push", s.stable, s.basin_lo, s.basin_hi, s.period, s.angle_tol)
    assert a.stable is s.stable  # arrays are kept as given
    assert a.values == s.values
    b = TransferFunction("push", *(list(v) for v in s.values), s.period, s.angle_tol)
    assert_array_equal(b.stable, s.stable)
    assert b.values == s.values and not b.basin_hi.flags.writeable


def test_transfer_function_is_frozen_renamable_and_picklable() -> None:
    s = squeeze_function(square_ish())
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.kind = "push"  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del s.period
    r = s.renamed("my-squeeze")
    assert r.kind == "my-squeeze" and s.kind == "squeeze"
    assert r.values == s.values and r.period == s.period
    back = pickle.loads(pickle.dumps(s))
    assert back.values == s.values and back.period == s.period and back.kind == s.kind
    assert_array_equal(back(np.linspace(0, 7, 50)), s(np.linspace(0, 7, 50)))
    assert repr(s).startswith("TransferFunction(kind='squeeze', stable=array(")


def test_diameter_function_lazy_arrays() -> None:
    poly = square_ish()
    d = diameter_function(poly)
    mins, maxs = d.extrema
    assert mins == tuple(d.minima.tolist()) and maxs == tuple(d.maxima.tolist())
    assert d.pairs.shape == (len(d.breaks), 2) and d.pairs.dtype == np.intp
    for arr in (d.breaks, d.lengths, d.phases, d.pairs, d.minima, d.maxima):
        assert not arr.flags.writeable
    big = diameter_pieces.pieces_numpy(poly.vertices, poly.tol.angle)
    assert_array_equal(d.pairs, np.stack([big[3], big[4]], axis=1))
    back = pickle.loads(pickle.dumps(d))
    assert_array_equal(back.minima, d.minima)
    assert_array_equal(back([0.1, 1.0, 2.0]), d([0.1, 1.0, 2.0]))
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.polygon = poly  # type: ignore[misc]
    assert repr(d).startswith("DiameterFunction(polygon=ConvexPolygon(")


def test_symmetric_parts_keep_exact_periods() -> None:
    """The symmetrized extrema on the plain-Python path (a near-regular 12-gon)."""
    rng = np.random.default_rng(0)
    pts = regular_polygon(12, 1.0, 0.1, (0.0, 0.0)) + rng.normal(scale=1e-8, size=(12, 2))
    part = Part.from_points(pts)
    d, s = squeeze_model(part)
    assert part.hull.symmetry_order == 12
    assert s.n_states == 12 and s.period == pytest.approx(math.pi / 6, abs=1e-12)
    assert_allclose(np.diff(s.stable), math.pi / 6, atol=1e-12)
    assert_allclose(np.diff(d.minima), math.pi / 6, atol=1e-12)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("at", [(0, 0), (4, 1), (9, 0)])
def test_small_arrays_refuse_non_finite_points_as_before(bad: float, at: tuple[int, int]) -> None:
    pts = np.random.default_rng(0).uniform(size=(10, 2))
    pts[at] = bad
    with pytest.raises(PartError) as general:
        polygon.as_points(pts)
    with pytest.raises(PartError) as small:
        Part.from_points(pts)
    assert str(small.value) == str(general.value)


def test_small_arrays_whose_sum_overflows_take_the_general_check() -> None:
    pts = np.array([[1e308, 0.0], [1.5e308, 1.0], [1.6e308, -1.0]])  # finite; the sum is not
    with pytest.raises(PartError, match="at most 1e\\+150 in absolute value"):
        Part.from_points(pts)
    big = np.array([[1e140, 0.0], [2e140, 1e140], [0.0, 3e140]])
    part = Part.from_points(big)
    assert_array_equal(part.outline, big)
    assert not part.outline.flags.writeable
    assert part.outline is not big  # a copy, as as_points makes


def test_the_public_constructor_copies_and_reads_pairs_as_rows() -> None:
    """Pairs given as an (N, 2) list keep their rows; the caller's arrays stay writeable."""
    import numpy as np

    from bayesgrasp.geometry import Part
    from bayesgrasp.geometry.diameter import DiameterFunction, diameter_function

    d = diameter_function(Part.from_points([(0, 0), (3, 0), (1, 2)]).hull)
    mine = np.array(d.breaks)
    again = DiameterFunction(
        d.polygon, mine, d.lengths, d.phases, d.pairs.tolist(), d.minima, d.maxima
    )
    assert again.pairs.tolist() == d.pairs.tolist()
    assert again.breaks.tolist() == d.breaks.tolist() and mine.flags.writeable


# --------------------------------------------------------------------------- one-pass extrema


@st.composite
def parallel_points(draw: st.DrawFn) -> FloatArray:
    """Centrally symmetric clouds (parallel edges in pairs), sometimes squashed thin."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    half = rng.normal(size=(draw(st.integers(2, 12)), 2))
    pts = np.concatenate([half, -half]) * [1.0, 10.0 ** draw(st.floats(-6, 0))]
    return np.asarray(pts + rng.normal(size=2), dtype=np.float64)


def general_diameter(poly: ConvexPolygon) -> DiameterFunction:
    """:func:`diameter_function` with the one-pass extrema (``_in_order``) turned off."""
    saved = diameter.in_order
    diameter.in_order = lambda *args: None
    try:
        return diameter_function(poly)
    finally:
        diameter.in_order = saved


TOLERANCES = [
    Tolerance(),
    Tolerance(angle=MIN_ANGLE),
    Tolerance(angle=1e-6),
    Tolerance(barrier=1e-3),
]


@settings(max_examples=300, deadline=None)
@given(
    pts=st.one_of(any_points(), parallel_points()),
    tol=st.sampled_from(TOLERANCES),
)
def test_one_pass_extrema_are_the_general_paths(pts: FloatArray, tol: Tolerance) -> None:
    """Bit for bit: the extrema read in the pieces' loop, and _merged + _drop_shallow."""
    try:
        poly = ConvexPolygon.from_points(pts, tol)
    except PartError:
        return
    fast, general = diameter_function(poly), general_diameter(poly)
    assert fast.extrema == general.extrema  # floats compared exactly
    for a, b in zip(fast._columns(), general._columns(), strict=True):
        assert a.tolist() == b.tolist()
    outcome = []
    for d in (fast, general):
        try:
            s = squeeze_function(d)
            outcome.append((s.values, s.period))
        except BayesGraspError as e:
            outcome.append(str(e))
    assert outcome[0] == outcome[1]


def test_the_study_polygons_take_the_one_pass_extrema() -> None:
    """The common case is the fast one: no flat slope, no shallow pair, no symmetry."""
    calls = []
    saved = diameter.in_order

    def spy(*args: object) -> object:
        calls.append(saved(*args))  # type: ignore[arg-type]
        return calls[-1]

    diameter.in_order = spy  # type: ignore[assignment]
    try:
        for c in np.random.default_rng(1).uniform(size=(200, 10, 2)):
            diameter_function(ConvexPolygon.from_points(c))
    finally:
        diameter.in_order = saved
    assert len(calls) == 200 and all(found is not None for found in calls)


def test_parallel_edges_and_flat_slopes_take_the_general_path() -> None:
    """A rectangle's slopes are flat at its alignments: the general path decides."""
    rect = ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    d = diameter_function(rect)
    assert d.extrema == general_diameter(rect).extrema
    assert_allclose(d.minima, [0.0, math.pi / 2], atol=1e-15)


def test_squeeze_function_sorts_only_what_wraps() -> None:
    """Own extrema lists skip the sort unless a minimum + pi rounds up to 2 pi."""
    poly = square_ish()
    d = diameter_function(poly)
    pieces = (list(d.breaks), list(d.lengths), list(d.phases), *d.pairs.T.tolist())
    below_pi = math.nextafter(math.pi, 0.0)
    assert (below_pi + math.pi) % TWO_PI == 0.0  # wraps to 0
    for lows, highs in [(list(d.minima), list(d.maxima)), ([1.0, below_pi], [0.5, 2.0])]:
        own = DiameterFunction._of_floats(poly, pieces, lows, highs)  # type: ignore[arg-type]
        given_ = DiameterFunction(poly, *pieces[:3], d.pairs, np.array(lows), np.array(highs))
        s1, s2 = squeeze_function(own), squeeze_function(given_)
        assert s1.values == s2.values and s1.period == s2.period
        assert list(s1.values[0]) == sorted(s1.values[0])


def _alternate_reference(stable: list[float], bounds: list[float]) -> bool:
    """The alternation test as it was written before (two all(map(...)) per case)."""
    import bisect
    import operator

    k0 = bisect.bisect_right(bounds, stable[0])
    if k0 == 0:
        ok = all(map(operator.lt, stable, bounds)) and all(map(operator.le, bounds, stable[1:]))
    else:
        ok = all(map(operator.le, bounds, stable)) and all(map(operator.lt, stable, bounds[1:]))
    return k0 <= 1 and ok


@settings(max_examples=300, deadline=None)
@given(
    points=st.lists(
        st.sampled_from([0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0]), min_size=2, max_size=12
    ),
    split=st.integers(0, 2**12 - 1),
)
def test_alternation_loop_is_the_all_map_test(points: list[float], split: int) -> None:
    from bayesgrasp.geometry.transfer import _from_sorted

    half = len(points) // 2
    stable = sorted(points[:half])
    bounds = sorted(points[half : 2 * half])
    if not stable:
        return
    if split % 2:  # both orders of the first two kinds
        stable, bounds = bounds, stable
    expected = _alternate_reference(stable, bounds)
    try:
        _from_sorted("squeeze", stable, bounds, 1e-9, 1e-9)
    except BayesGraspError:
        assert not expected
    else:
        assert expected
