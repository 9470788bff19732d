"""A firmly convex ring taken as its own hull (issue 12): the hull's polygon, bit for bit.

``ConvexPolygon._of_firm_ring`` skips the monotone chains when ``io.points._firm_turn``
found the ring firmly convex; whenever it answers, its vertices, area, centroid and size
must be those of ``ConvexPolygon._hull_of_floats`` of the same points (compared as float
hex), and the reader's part must be ``Part.from_points``'s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp.geometry.polygon import ConvexPolygon, Part
from bayesgrasp.io import points as points_module
from bayesgrasp.tolerance import DEFAULT_TOLERANCE, Tolerance
from strategies import lattice_points

Box = tuple[float, float, float, float]


def _fields(poly: ConvexPolygon) -> list[str]:
    xs, ys = poly._coords()
    return [v.hex() for v in (*xs, *ys, poly.area, *poly._centroid_xy(), poly.size)]


def _ring(pts: list[tuple[float, float]]) -> tuple[list[float], list[float], Box, float]:
    """The ring's coordinates, their least and largest, and ``_firm_turn`` of them."""
    small = points_module._small_floats([list(p) for p in pts])
    assert small is not None
    xs, ys = small
    box = (min(xs), max(xs), min(ys), max(ys))
    return xs, ys, box, points_module._firm_turn(xs, ys, *box)


def _of_firm_ring(
    xs: list[float], ys: list[float], box: Box, least: float, tol: Tolerance = DEFAULT_TOLERANCE
) -> ConvexPolygon | None:
    return ConvexPolygon._of_firm_ring(xs, ys, least, *box, tol)


def _check(pts: list[tuple[float, float]], tol: Tolerance = DEFAULT_TOLERANCE) -> bool:
    """Whether the shortcut answered; when it did, it agrees with the hull."""
    xs, ys, box, least = _ring(pts)
    if not least:
        return False
    fast = _of_firm_ring(xs, ys, box, least, tol)
    if fast is None:
        return False
    arr = np.array(pts, dtype=np.float64)
    px, py = arr.T.tolist()
    assert _fields(fast) == _fields(ConvexPolygon._hull_of_floats(arr, px, py, tol))
    assert xs == [p[0] for p in pts] and ys == [p[1] for p in pts]  # the caller's lists kept
    return True


def _polygon(angles: list[float], radius: float, offset: tuple[float, float], squash: float):
    t = np.sort(np.asarray(angles))
    xs, ys = offset[0] + radius * np.cos(t), offset[1] + squash * radius * np.sin(t)
    return list(zip(xs.tolist(), ys.tolist(), strict=True))


@settings(max_examples=400, deadline=None)
@given(
    angles=st.lists(
        st.floats(0.0, 2 * np.pi, exclude_max=True), min_size=3, max_size=20, unique=True
    ),
    radius=st.sampled_from([1e-9, 1e-3, 1.0, 7.0, 1e6, 1e12]),
    offset=st.sampled_from([(0.0, 0.0), (1.0, -2.0), (1e8, 1e8), (-1e12, 3.0)]),
    squash=st.sampled_from([1.0, 0.3, 1e-4, 1e-9]),
    shift=st.integers(0, 19),
    reverse=st.booleans(),
    loose=st.booleans(),
)
def test_firm_ring_is_the_hull(angles, radius, offset, squash, shift, reverse, loose) -> None:
    pts = _polygon(angles, radius, offset, squash)
    if reverse:
        pts.reverse()
    k = shift % len(pts)
    pts = pts[k:] + pts[:k]
    tol = Tolerance(length=1e-3) if loose else DEFAULT_TOLERANCE
    if len(set(pts)) == len(pts) and points_module._small_floats([list(p) for p in pts]):
        _check(pts, tol)


# Hulls of lattice points: edges along the axes, so often two points of least x (where the
# hull starts at the lower), in every rotation and either way round, and far from the origin.
@settings(max_examples=400, deadline=None)
@given(
    pts=lattice_points(min_size=3, max_size=30, bound=6),
    shift=st.integers(0, 29),
    reverse=st.booleans(),
    offset=st.sampled_from([0.0, 0.5, -1e6, 1e9]),
    swap=st.booleans(),
)
def test_firm_lattice_rings_are_the_hull(pts, shift, reverse, offset, swap) -> None:
    ring = ConvexPolygon.from_points(pts).vertices.tolist()
    if swap:  # vertical edges become horizontal ones
        ring = [[y, x] for x, y in ring]
    ring = [(x + offset, y - offset) for x, y in ring]
    if reverse:
        ring.reverse()
    k = shift % len(ring)
    _check(ring[k:] + ring[:k])


@pytest.mark.parametrize("shift", range(4))
@pytest.mark.parametrize("reverse", [False, True])
def test_two_points_of_least_x_start_at_the_lower(shift: int, reverse: bool) -> None:
    square = [(0.0, 1.0), (0.0, 0.0), (1.0, 0.0), (1.0, 1.0)][:: -1 if reverse else 1]
    ring = square[shift:] + square[:shift]
    assert _check(ring)
    xs, ys, box, least = _ring(ring)
    poly = _of_firm_ring(xs, ys, box, least)
    assert poly is not None and poly.vertices.tolist()[0] == [0.0, 0.0]


def test_the_shortcut_is_taken_for_random_convex_polygons() -> None:
    rng = np.random.default_rng(5)
    taken = 0
    for _ in range(300):
        hull = ConvexPolygon.from_points(rng.uniform(size=(10, 2)))
        pts = [tuple(p) for p in hull.vertices.tolist()]
        k = int(rng.integers(len(pts)))
        pts = pts[k:] + pts[:k]
        taken += _check(pts if rng.random() < 0.5 else pts[::-1])
    assert taken == 300


@pytest.mark.parametrize(
    ("pts", "why"),
    [
        # a vertex 1e-10 off its neighbours' chord: the hull drops it (eps = 1e-9 * size)
        ([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.5, 1.0 + 1e-10), (0.0, 1.0)], "near-collinear"),
        # the same vertex 1e-6 off is kept: answered
        ([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.5, 1.0 + 1e-6), (0.0, 1.0)], None),
        ([(0.0, 0.0), (1e-151, 0.0), (0.0, 1e-151)], "tiny"),  # below _check_magnitude's range
    ],
)
def test_refused_where_the_hull_may_differ(pts, why) -> None:
    xs, ys, box, least = _ring(pts)
    answer = _of_firm_ring(xs, ys, box, least) if least else None
    assert (answer is None) == (why is not None)
    if answer is not None:
        assert _check(pts)


def test_least_cross_must_be_the_rings_own() -> None:
    """A least turn below the margin or of the wrong sign is refused, not trusted."""
    xs, ys, box, least = _ring([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])
    assert least > 0
    assert _of_firm_ring(xs, ys, box, 1e-14) is None
    assert _of_firm_ring(xs, ys, box, -least) is None  # clockwise?
    assert _of_firm_ring(xs, ys, box, least) is not None


def test_reader_part_is_from_points_part() -> None:
    """The reader's part of a firm ring: the points' own ``Part.from_points``, field by field."""
    rng = np.random.default_rng(11)
    for _ in range(50):
        pts = ConvexPolygon.from_points(rng.uniform(-5, 5, size=(9, 2))).vertices.tolist()
        got = points_module.point_list_part(Path("p.json"), pts, "p")
        want = Part.from_points(np.array(pts), name="p")
        assert _fields(got.hull) == _fields(want.hull)
        assert got.outline.tolist() == want.outline.tolist()
        assert got.center_of_mass.tolist() == want.center_of_mass.tolist()
        assert not got.outline.flags.writeable
        assert got.outline.base is None or not got.outline.base.flags.writeable
