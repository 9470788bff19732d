"""Curved parts: exact hulls of segments and arcs, their diameter function and states.

Independent checks: closed forms (disc, slot, rounded rectangle, four-centre oval, D-shape,
filleted polygon vs the sharp one) and the exact support and diameter functions against a
brute force over a very dense sampling of the true outline (hypothesis, random outlines of
arcs and segments).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.errors import PartError, PlanningError
from bayesgrasp.geometry import Part
from bayesgrasp.geometry.curved import (
    CurvedPart,
    CurvedRing,
    curved_diameter,
    curved_hull,
    curved_part,
    resting_states,
    squeeze_model,
    with_shape_tol,
)
from bayesgrasp.geometry.transfer import squeeze_function
from bayesgrasp.model.problem import Problem

QUARTER = math.tan(math.pi / 8)  # the bulge of a quarter turn


def rounded_rectangle(a: float, b: float, rho: float) -> CurvedRing:
    """An a x b rectangle centred at the origin, corners filleted with radius rho."""
    x, y = a / 2, b / 2
    pts = [
        (-x + rho, -y),
        (x - rho, -y),
        (x, -y + rho),
        (x, y - rho),
        (x - rho, y),
        (-x + rho, y),
        (-x, y - rho),
        (-x, -y + rho),
    ]
    return CurvedRing(pts, [0.0, QUARTER] * 4)


def slot(length: float, rho: float) -> CurvedRing:
    """A stadium: two half circles of radius rho whose centres are ``length`` apart."""
    return CurvedRing([(0, -rho), (length, -rho), (length, rho), (0, rho)], [0, 1, 0, 1])


DISC = CurvedRing([(1.0, 0.0), (-1.0, 0.0)], [1.0, 1.0])


def test_disc_has_no_state_and_every_plan_is_refused() -> None:
    part = curved_part(DISC, name="disc")
    d = part.diameter_function
    assert d.minima.size == 0 and d.maxima.size == 0
    assert_allclose(d(np.linspace(0, 7, 50)), 2.0, atol=1e-12)
    with pytest.raises(PlanningError, match=r"no stable orientation.*disc"):
        Problem.build(part)


@pytest.mark.parametrize(("length", "rho"), [(2.0, 1.0), (10.0, 0.5), (0.1, 3.0)])
def test_slot_has_two_states_half_a_turn_apart(length: float, rho: float) -> None:
    _, s = squeeze_model(curved_part(slot(length, rho)))
    assert s.n_states == 2
    assert_allclose(np.degrees(s.stable), [90.0, 270.0], atol=1e-9)
    assert_allclose(s.widths, [math.pi, math.pi], atol=1e-12)
    d = curved_part(slot(length, rho)).diameter_function
    assert_allclose(d([0.0, math.pi / 2]), [length + 2 * rho, 2 * rho], rtol=1e-12)


@pytest.mark.parametrize(("a", "b", "rho"), [(4.0, 3.0, 1.0), (10.0, 2.0, 0.3), (5.0, 5.0, 2.0)])
def test_rounded_rectangle_closed_form(a: float, b: float, rho: float) -> None:
    # Between the flats both jaws touch opposite fillets: d = L cos(theta - phase) + 2 rho,
    # L the distance between the fillets' centres, so the maxima (basin boundaries) are where
    # that chord lies along the squeeze axis: atan((b - 2 rho) / (a - 2 rho)).
    part = curved_part(rounded_rectangle(a, b, rho))
    _, s = squeeze_model(part)
    assert s.n_states == 4
    assert_allclose(np.degrees(s.stable), [0.0, 90.0, 180.0, 270.0], atol=1e-9)
    beta = math.atan2(b - 2 * rho, a - 2 * rho)
    p0 = 2 * beta / (2 * math.pi)
    p1 = (math.pi - 2 * beta) / (2 * math.pi)
    pb = Problem.build(part)
    assert_allclose(pb.state_distribution(), [p0, p1, p0, p1], atol=1e-12)
    assert_allclose(pb.widths, [a, b, a, b], rtol=1e-12)
    d = part.diameter_function
    assert_allclose(d(beta), math.hypot(a - 2 * rho, b - 2 * rho) + 2 * rho, rtol=1e-12)


def test_filleted_polygon_keeps_the_sharp_polygons_states() -> None:
    # An L-free convex pentagon-like plate: a 6 x 4 rectangle with two corners cut, filleted.
    a, b, rho = 6.0, 4.0, 0.5
    sharp = Part.from_points([(-3, -2), (3, -2), (3, 2), (-3, 2)])
    fillet = curved_part(rounded_rectangle(a, b, rho))
    s_sharp = squeeze_function(sharp.hull)
    _, s_round = squeeze_model(fillet)
    assert_allclose(s_round.stable, s_sharp.stable, atol=1e-12)
    # The jaw widths at the states agree (the flats set them); the basins differ by the
    # fillets: boundaries at atan(b / a) for the sharp one, atan((b - 2 rho)/(a - 2 rho)).
    assert_allclose(Problem.build(fillet).widths, Problem.build(sharp).widths, rtol=1e-12)
    assert_allclose(s_sharp.basin_hi[0], math.atan2(b, a), atol=1e-12)
    assert_allclose(s_round.basin_hi[0], math.atan2(b - 2 * rho, a - 2 * rho), atol=1e-12)
    # And the diameter at the diagonal differs by exactly the fillets' geometry.
    d_round = fillet.diameter_function
    t = math.atan2(b, a)
    sharp_width = math.hypot(a, b)
    chord = math.hypot(a - 2 * rho, b - 2 * rho)
    expected = chord * math.cos(t - math.atan2(b - 2 * rho, a - 2 * rho)) + 2 * rho
    assert_allclose(d_round(t), expected, rtol=1e-12)
    assert d_round(t) < sharp_width


def four_centre_oval(big: float, small: float, k: float) -> CurvedRing:
    """An oval of two big arcs (centres (0, -+k)) and two small end arcs (radius small)."""
    # The end arcs have centres (+-m, 0), tangent to the big arcs of radius `big` centred
    # at (0, -k) and (0, k): |(m, k)| = big - small.
    m = math.sqrt((big - small) ** 2 - k**2)
    phi = math.atan2(k, m)  # where the end arc meets the big arc, seen from the end centre
    ends = []
    for sx in (1.0, -1.0):
        c = np.array([sx * m, 0.0])
        ends.append((c, sx))
    p = []
    # Counter-clockwise from the right end arc's bottom.
    p.append((m + small * math.cos(-phi), small * math.sin(-phi)))
    p.append((m + small * math.cos(phi), small * math.sin(phi)))
    p.append((-m - small * math.cos(phi), small * math.sin(phi)))
    p.append((-m - small * math.cos(phi), -small * math.sin(phi)))
    end_sweep = 2 * phi
    big_sweep = math.pi - 2 * phi
    return CurvedRing(p, [math.tan(end_sweep / 4), math.tan(big_sweep / 4)] * 2)


def test_oval_has_smooth_minima_at_its_minor_axis() -> None:
    ring = four_centre_oval(big=10.0, small=2.0, k=5.0)
    part = curved_part(ring)
    d = part.diameter_function
    mins = [e for e in d.kept if not e.is_max]
    assert len(mins) == 1 and not mins[0].kink  # a smooth minimum, not a flush edge
    assert_allclose(mins[0].theta, math.pi / 2, atol=1e-12)
    assert_allclose(mins[0].value, 2 * (10.0 - 5.0), rtol=1e-12)  # 2 (big - k)
    assert resting_states(d)[0].edges == ()


def test_d_shape_rests_on_its_flat() -> None:
    d_shape = CurvedRing([(0.0, -1.0), (0.0, 1.0)], [0.0, 1.0])  # diameter, then half circle
    part = curved_part(d_shape)
    d = part.diameter_function
    assert_allclose(np.degrees(d.minima), [0.0], atol=1e-9)
    assert_allclose(np.degrees(d.maxima), [90.0], atol=1e-9)
    th = np.linspace(0, math.pi, 101)
    assert_allclose(d(th), 1 + np.abs(np.sin(th)), atol=1e-12)  # closed form
    (rest,) = resting_states(d)
    assert len(rest.edges) == 1
    ends = sorted(map(tuple, np.round(rest.edges[0], 12).tolist()))
    assert ends == [(0.0, -1.0), (0.0, 1.0)]
    # The centre of mass of a half disc: 4 r / (3 pi) from the flat.
    assert_allclose(part.center_of_mass, [-4 / (3 * math.pi), 0.0], atol=1e-12)


def test_shape_tolerance_removes_minima_it_could_erase() -> None:
    # A rectangle with a slightly tilted side: its extra minimum is shallow.
    part = Part.from_points([(0, 0), (10, 0), (10, 1), (0, 1.05)])
    plain = Problem.build(part)
    tol = with_shape_tol(part, 0.2)
    assert isinstance(tol, CurvedPart)
    loose = Problem.build(tol)
    assert loose.n_states < plain.n_states
    assert with_shape_tol(part, 0.0) is part
    with pytest.raises(PartError, match="shape_tol"):
        with_shape_tol(part, -1.0)


def test_coincident_points_are_refused() -> None:
    with pytest.raises(PartError, match="coincide"):
        CurvedRing([(0, 0), (1, 0), (1, 0), (0, 1)], [0, 0, 0, 0])
    with pytest.raises(PartError, match="across"):
        CurvedRing([(1.0, 0.0), (1.0, 1e-300)], [1.0, 1.0])


def test_polygon_through_the_curved_model_agrees_with_the_polygon_code() -> None:
    part = Part.from_points([(0, 0), (40, 0), (10, 20)])
    curved = with_shape_tol(part, 1e-300)  # the curved code path, no tolerance to speak of
    assert isinstance(curved, CurvedPart)
    s_poly = squeeze_function(part.hull)
    _, s_curved = squeeze_model(curved)
    assert_allclose(s_curved.stable, s_poly.stable, atol=1e-12)
    assert_allclose(s_curved.basin_hi, s_poly.basin_hi, atol=1e-12)


# ------------------------------------------------------------------------------------
# Brute force: the support and diameter functions of a dense sampling of the outline


def dense_outline(ring: CurvedRing, per_turn: int = 20_000, sag: float = 2e-11) -> np.ndarray:
    """Points on the true outline: every segment end and arcs sampled very finely.

    Each arc is sampled at least ``per_turn`` times a turn and so that its sagitta between
    samples (``r step^2 / 8``) is at most ``sag`` times the part's extent.
    """
    out = [ring.points]
    centers, radii, starts, sweeps, _ = ring.arcs()
    extent = float(np.ptp(ring.points)) or 1.0
    for c, r, a, s in zip(centers, radii, starts, sweeps, strict=True):
        step = math.sqrt(8.0 * sag * extent / r)
        n = max(
            16, int(per_turn * abs(s) / (2 * math.pi)), min(2_000_000, math.ceil(abs(s) / step))
        )
        t = a + s * np.linspace(0.0, 1.0, n)
        out.append(c + r * np.column_stack([np.cos(t), np.sin(t)]))
    return np.concatenate(out)


@st.composite
def arc_outlines(draw: st.DrawFn) -> CurvedRing:
    n = draw(st.integers(2, 7))
    angles = np.sort(draw(st.lists(st.floats(0, 2 * math.pi), min_size=n, max_size=n, unique=True)))
    radii = draw(st.lists(st.floats(0.3, 2.0), min_size=n, max_size=n))
    pts = np.column_stack([np.cos(angles), np.sin(angles)]) * np.array(radii)[:, None]
    bulges = draw(
        st.lists(
            st.one_of(st.just(0.0), st.floats(-0.6, 1.2).filter(lambda b: abs(b) > 1e-3)),
            min_size=n,
            max_size=n,
        )
    )
    if n == 2:
        bulges[0] = 1.0
    step = np.roll(pts, -1, axis=0) - pts
    assume(np.min(np.hypot(step[:, 0], step[:, 1])) > 1e-2)
    return CurvedRing(pts, bulges)


@settings(max_examples=30, deadline=None)
@given(arc_outlines())
def test_exact_support_and_diameter_match_a_dense_sampling(ring: CurvedRing) -> None:
    try:
        hull = curved_hull(ring)
    except PartError:
        return
    pts = dense_outline(ring)
    size = float(np.max(np.hypot(*(pts - pts.mean(axis=0)).T)))
    phi = np.linspace(0.0, 2 * math.pi, 61, endpoint=False) + 0.0123
    brute = (np.cos(phi)[:, None] * pts[:, 0] + np.sin(phi)[:, None] * pts[:, 1]).max(axis=1)
    assert_allclose(hull.support(phi), brute, rtol=0, atol=1e-9 * size)
    d = curved_diameter(hull)
    th = np.linspace(0.0, math.pi, 37) + 0.0071
    brute_d = np.array(
        [
            np.ptp(np.cos(t) * pts[:, 0] - np.sin(t) * pts[:, 1])  # width along the squeeze axis
            for t in th
        ]
    )
    assert_allclose(d(th), brute_d, rtol=0, atol=1e-9 * size)
    # Extrema alternate, and every kept minimum is a local minimum of the sampled width.
    kinds = [e.is_max for e in d.kept]
    assert all(a != b for a, b in zip(kinds, kinds[1:] + kinds[:1], strict=True))
    others = np.array([x.theta for x in d.extrema])
    for e in d.kept:
        gap = np.abs(np.remainder(others - e.theta + math.pi / 2, math.pi) - math.pi / 2)
        step = min(1e-4, 0.25 * float(np.min(gap[gap > 1e-12], initial=1.0)))
        near = np.array(
            [
                np.ptp(np.cos(t) * pts[:, 0] - np.sin(t) * pts[:, 1])
                for t in (e.theta - step, e.theta + step)
            ]
        )
        if e.is_max:
            assert np.all(near <= e.value + 1e-9 * size)
        else:
            assert np.all(near >= e.value - 1e-9 * size)


def test_hull_edges_and_arcs_of_a_slot() -> None:
    hull = curved_hull(slot(2.0, 1.0))
    assert hull.n_pieces == 2
    assert_allclose(sorted(hull.edges), [2.0, 2.0], atol=1e-12)
    assert_allclose(hull.radii, [1.0, 1.0])
    poly = hull.polygon(1e-4)
    assert poly.n_sides > 100
    assert_allclose(poly.area, 4 + math.pi, rtol=1e-4)


def test_exact_area_and_centroid_of_arcs() -> None:
    a, c = rounded_rectangle(4.0, 3.0, 1.0).area_centroid()
    assert_allclose(a, 12.0 - (4 - math.pi), rtol=1e-12)
    assert_allclose(c, [0.0, 0.0], atol=1e-12)
    a, c = CurvedRing([(0.0, 1.0), (0.0, -1.0)], [0.0, 1.0]).area_centroid()  # right half disc
    assert_allclose(a, math.pi / 2, rtol=1e-12)
    assert_allclose(c, [4 / (3 * math.pi), 0.0], atol=1e-12)


def cog(pieces: int = 400, seed: int = 3) -> CurvedRing:
    """A detailed ring of alternating segments and arcs (enough sites to be pruned)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2 * math.pi, pieces, endpoint=False)
    r = 50.0 + 1.5 * np.sin(7 * t) + rng.uniform(-0.3, 0.3, pieces)
    bulges = np.where(np.arange(pieces) % 2 == 1, rng.uniform(-0.3, 0.3, pieces), 0.0)
    return CurvedRing(np.column_stack([r * np.cos(t), r * np.sin(t)]), bulges)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1])
def test_pruned_hull_of_a_detailed_outline_matches_a_dense_sampling(seed: int) -> None:
    from scipy.spatial import ConvexHull

    ring = cog(seed=seed)
    hull = curved_hull(ring)
    pts = dense_outline(ring, 200_000)
    pts = pts[ConvexHull(pts).vertices]
    phi = np.linspace(0.0, 2 * math.pi, 601)
    brute = (np.cos(phi)[:, None] * pts[:, 0] + np.sin(phi)[:, None] * pts[:, 1]).max(axis=1)
    assert_allclose(hull.support(phi), brute, rtol=0, atol=1e-9 * 50)


@pytest.mark.slow
def test_push_of_a_half_disc() -> None:
    from bayesgrasp.geometry.curved import curved_push, curved_push_grasp, curved_radius

    # A half disc rests on its flat (the foot from the centre of mass is inside it) and on
    # its arc like a rocker (a smooth minimum: the centre of mass as near the jaw as it gets).
    part = curved_part(CurvedRing([(0.0, -1.0), (0.0, 1.0)], [0.0, 1.0]))
    r = curved_radius(part)
    c = 4 / (3 * math.pi)
    th = np.linspace(0, 2 * math.pi, 721)
    pts = dense_outline(part.ring, 100_000) - part.center_of_mass  # type: ignore[arg-type]
    brute = (-np.cos(th)[:, None] * pts[:, 0] + np.sin(th)[:, None] * pts[:, 1]).max(axis=1)
    assert_allclose(r(th), brute, atol=1e-8)
    p = curved_push(part)
    assert_allclose(np.degrees(p.stable), [0.0, 180.0], atol=1e-9)  # the arc; the flat
    assert_allclose(r([0.0, math.pi]), [1 - c, c], rtol=1e-12)
    g = curved_push_grasp(part)
    assert set(np.round(g.stable, 12)) <= set(np.round(squeeze_model(part)[1].stable, 12))
