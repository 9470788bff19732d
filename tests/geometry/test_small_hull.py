"""The parts of a few points, built on plain Python floats, against a reference.

The hull of :data:`~bayesgrasp.sizes.SMALL` points or fewer is taken by
:func:`~bayesgrasp.geometry.hull.hull_of_few`; :meth:`Part.from_points` must give its
vertices, area, centroid and size bit for bit (as float hex), with the size computed here
independently. Inputs: random, near-collinear, duplicates, thin, huge and tiny clouds, under
several tolerances. The lazily made arrays of the polygons and parts are compared with the
eager construction.
"""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal

from bayesgrasp.errors import PartError
from bayesgrasp.geometry import hull
from bayesgrasp.geometry import part as part_module
from bayesgrasp.geometry.polygon import ConvexPolygon, Part
from bayesgrasp.tolerance import DEFAULT_TOLERANCE, Tolerance
from strategies import convex_points, lattice_points

FloatArray = np.ndarray


@st.composite
def near_collinear_points(draw: st.DrawFn) -> FloatArray:
    """A convex polygon with extra points a few tolerances off its edges or its vertices.

    The offsets straddle both the tolerance ``eps`` and the bound ``2 eps extent`` of the
    skipped tests, at the leftmost and rightmost points (where the chains meet) too.
    """
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    k = draw(st.integers(3, 8))
    t = np.sort(rng.uniform(0, 2 * math.pi, k))
    v = np.column_stack([np.cos(t), 0.6 * np.sin(t)])
    offset = 10.0 ** draw(st.floats(-13, -7))  # the default tolerance: 1e-10 of the extent
    extra = []
    for _ in range(draw(st.integers(1, 6))):
        i = int(rng.integers(k))
        a, b = v[i], v[(i + 1) % k]
        normal = np.array([a[1] - b[1], b[0] - a[0]]) / np.hypot(*(b - a))
        where = draw(st.sampled_from([0.0, 1.0, rng.uniform()]))  # on a vertex, or an edge
        extra.append(a + where * (b - a) + offset * rng.normal() * normal)
    pts = np.vstack([v, extra])
    scale = 10.0 ** draw(st.sampled_from([0.0, -120.0, 120.0, float(rng.uniform(-5, 5))]))
    return np.asarray(rng.permutation(pts) * scale + draw(st.sampled_from([0.0, 3.0])) * scale)


@st.composite
def scattered_points(draw: st.DrawFn) -> FloatArray:
    """Clouds of 3 to 64 points: uniform, normal, thin, rounded, huge or tiny."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = draw(st.integers(3, 64))
    kind = draw(st.sampled_from(["uniform", "normal", "thin", "rounded", "scaled"]))
    if kind == "uniform":
        return rng.uniform(size=(n, 2))
    if kind == "normal":
        return rng.normal(size=(n, 2))
    if kind == "thin":
        height = 10.0 ** draw(st.floats(-11, -1))
        return np.column_stack([rng.uniform(size=n), rng.uniform(size=n) * height]) + 5.0
    if kind == "rounded":
        return np.round(rng.uniform(size=(n, 2)) * 8) / 8
    return rng.uniform(size=(n, 2)) * 10.0 ** draw(st.floats(-149, 149))


TOLERANCES = [DEFAULT_TOLERANCE, Tolerance(length=0.0), Tolerance(length=1e-4)]


def any_points() -> st.SearchStrategy[FloatArray]:
    return st.one_of(
        near_collinear_points(),
        scattered_points(),
        convex_points(),
        lattice_points(min_size=3, max_size=40, bound=3),
    )


def hexes(*values: float | list[float]) -> list[object]:
    return [[x.hex() for x in v] if isinstance(v, list) else v.hex() for v in values]


def reference(pts: FloatArray, tol: Tolerance) -> tuple[list[object], float] | None:
    """``hull_of_few`` and the size as the hull had them, or None when refused."""
    px, py = pts.T.tolist()
    x0, x1 = min(px), max(px)
    extent = max(x1 - x0, max(py) - min(py))
    eps = tol.length_for(extent)
    xs, ys, area, cx, cy = hull.hull_of_few(sorted(zip(px, py, strict=True)), eps)
    if len(xs) < 3 or area <= eps * extent:
        return None
    size = math.sqrt(max([(x - cx) ** 2 + (y - cy) ** 2 for x, y in zip(xs, ys, strict=True)]))
    return hexes(xs, ys, area, cx, cy, size), extent


def test_the_bound_covers_the_chord_test() -> None:
    """``|u x w| > 2 eps extent`` implies ``|u x w| > eps |u|`` (``|u|`` <= sqrt(2) extent)."""
    rng = np.random.default_rng(3)
    for _ in range(2000):
        extent = 10.0 ** rng.uniform(-130, 130)
        eps = 10.0 ** rng.uniform(-16, -1) * extent
        bound = 2.0 * eps * extent
        for ux, uy in [rng.choice([-1.0, 1.0], 2) * extent, rng.uniform(-1, 1, 2) * extent]:
            assert eps * math.hypot(ux, uy) < bound  # the longest chords, and any


# --------------------------------------------------------------------------- Part.from_points


@settings(max_examples=300, deadline=None)
@given(pts=any_points(), tol=st.sampled_from(TOLERANCES))
def test_part_from_points_is_the_reference(pts: FloatArray, tol: Tolerance) -> None:
    """The small path's part: the reference hull, the outline copied, the arrays as before."""
    try:
        part = Part.from_points(pts, tol=tol)
    except PartError:
        ref = None if np.max(np.abs(pts)) > 1e150 else reference(pts, tol)
        assert ref is None or np.ptp(pts, axis=0).max() < 1e-150
        return
    hull = part.hull
    ref = reference(pts, tol)
    assert ref is not None
    xs, ys = hull._coords()
    assert hexes(xs, ys, hull.area, *hull.centroid.tolist(), hull.size) == ref[0]
    assert hull.tol is tol
    eager = ConvexPolygon._trusted(
        np.array([xs, ys]).T.copy(), tol, hull.area, np.array(hull.centroid), hull.size
    )
    for lazy, made in ((hull.vertices, eager.vertices), (hull.centroid, eager.centroid)):
        assert lazy.dtype == np.float64 and lazy.shape == made.shape
        assert lazy.flags.c_contiguous and lazy.flags.owndata and not lazy.flags.writeable
        assert_array_equal(lazy, made)
    assert hull.n_sides == len(hull.vertices) == len(xs)
    assert_array_equal(part.outline, pts)
    assert part.outline is not pts and not part.outline.flags.writeable
    assert_array_equal(part.center_of_mass, hull.centroid)
    assert not part.center_of_mass.flags.writeable
    assert part_module.holds_centroid(hull) == part_module.hull_contains(hull, hull.centroid)


def test_lists_and_arrays_give_the_same_part() -> None:
    pts = np.random.default_rng(4).uniform(size=(10, 2))
    a, b = Part.from_points(pts, name="p"), Part.from_points(pts.tolist(), name="p")
    for x, y in ((a.hull.vertices, b.hull.vertices), (a.center_of_mass, b.center_of_mass)):
        assert x.tobytes() == y.tobytes()
    assert (a.hull.area, a.hull.size) == (b.hull.area, b.hull.size)
    assert dataclasses.astuple(a)[0] == "p" and type(a) is Part


# --------------------------------------------------------------------------- lazy arrays


def test_lazy_arrays_are_made_once_read_only_and_frozen() -> None:
    hull = ConvexPolygon.from_points(np.random.default_rng(5).uniform(size=(10, 2)))
    assert hull._v is None and hull._c is None  # nothing asked for yet
    assert hull.n_sides == 6 and hull._v is None
    v, c = hull.vertices, hull.centroid
    assert hull.vertices is v and hull.centroid is c
    for arr in (v, c):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        hull.area = 1.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del hull.size
    assert list(hull._coords()) == v.T.tolist()
    assert hull._centroid_xy() == tuple(c.tolist())


def test_polygon_pickles_and_prints_as_before() -> None:
    hull = Part.from_points(np.random.default_rng(6).uniform(size=(10, 2))).hull
    back = pickle.loads(pickle.dumps(hull))
    assert back.vertices.tobytes() == hull.vertices.tobytes() and back.tol == hull.tol
    assert (back.area, back.size, back.centroid.tolist()) == (
        hull.area,
        hull.size,
        hull.centroid.tolist(),
    )
    assert not back.vertices.flags.writeable and back.symmetry_order == hull.symmetry_order
    assert repr(hull) == (
        f"ConvexPolygon(vertices={hull.vertices!r}, tol={hull.tol!r}, area={hull.area!r}, "
        f"centroid={hull.centroid!r}, size={hull.size!r})"
    )
    built = ConvexPolygon(hull.vertices, hull.tol)  # the checking constructor
    assert_array_equal(built.vertices, hull.vertices)
    assert built.vertices is not hull.vertices
    assert ConvexPolygon(vertices=hull.vertices).tol is DEFAULT_TOLERANCE
