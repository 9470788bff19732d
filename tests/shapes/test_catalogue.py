"""The catalogue of the seed's Table 1 parts: data files, loader, designs."""

from __future__ import annotations

import itertools
import json
import math
from importlib import resources

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import PartError
from bayesgrasp.geometry.polygon import hull_contains
from bayesgrasp.io import resolve_part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import execute_plan, plan_exact
from bayesgrasp.shapes import CatalogueEntry, _parse, describe, entry, load, names

# The seed's Table 1: each part's number of sides (of the convex hull), in the printed order.
SIDES = {
    "triangle": 3,
    "rectangle": 4,
    "ic-chip": 5,
    "house": 5,
    "example": 5,
    "allen-wrench": 6,
    "tuning-fork": 6,
    "key": 11,
    "hand": 13,
}


def brute_hull_count(points: np.ndarray) -> int:
    """Vertices of the convex hull, counted the slow way (independent of geometry.py).

    A point is a hull vertex when some direction makes it the unique farthest point: test
    4096 directions and keep points that are strictly extreme in at least one of them (a
    point in the middle of a hull edge is never strictly extreme).
    """
    a = np.linspace(0.0, 2.0 * math.pi, 4096, endpoint=False)
    u = np.stack([np.cos(a), np.sin(a)], axis=1)  # (D, 2)
    proj = points @ u.T  # (N, D)
    top = proj.max(axis=0)
    extreme = set()
    for d in range(len(a)):
        hits = np.flatnonzero(proj[:, d] >= top[d] - 1e-9 * np.ptp(points))
        if len(hits) == 1:
            extreme.add(int(hits[0]))
    unique = {tuple(np.round(points[i], 9)) for i in extreme}
    return len(unique)


def segments_cross(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> bool:
    """Whether the closed segments pq and rs intersect (orientation test)."""

    def orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    d1, d2 = orient(r, s, p), orient(r, s, q)
    d3, d4 = orient(p, q, r), orient(p, q, s)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0 not in (d1, d2, d3, d4):
        return True

    def on(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> bool:
        return (
            min(a[0], b[0]) <= c[0] <= max(a[0], b[0])
            and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])
            and orient(a, b, c) == 0
        )

    return on(r, s, p) or on(r, s, q) or on(p, q, r) or on(p, q, s)


def is_simple(outline: np.ndarray) -> bool:
    """No two non-adjacent edges of the closed outline touch."""
    n = len(outline)
    edges = [(outline[i], outline[(i + 1) % n]) for i in range(n)]
    for i, j in itertools.combinations(range(n), 2):
        if j == i + 1 or (i == 0 and j == n - 1):
            continue
        if segments_cross(*edges[i], *edges[j]):
            return False
    return True


def test_names_follow_the_seeds_table() -> None:
    assert names() == list(SIDES)


@pytest.mark.parametrize("name", names())
def test_part_loads_with_the_stated_side_count(name: str) -> None:
    part = load(name)
    assert part.name == name
    assert part.units == "mm"
    assert part.hull.n_sides == SIDES[name]
    assert brute_hull_count(np.asarray(part.outline)) == SIDES[name]
    assert part.hull.symmetry_order == (2 if name == "rectangle" else 1)


@pytest.mark.parametrize("name", names())
def test_part_is_documented(name: str) -> None:
    text = describe(name)
    assert len(text) > 100
    assert "placeholder" not in text.lower()
    assert name.split("-")[0] in text.lower() or name == "example"
    assert entry(name).description == text


@pytest.mark.parametrize("name", names())
def test_outline_is_a_simple_counter_clockwise_polygon(name: str) -> None:
    outline = np.asarray(load(name).outline)
    assert is_simple(outline)
    x, y = outline.T
    assert 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)) > 0


@pytest.mark.parametrize("name", names())
def test_centre_of_mass_is_the_outlines_centroid(name: str) -> None:
    part = load(name)
    outline = np.asarray(part.outline)
    # Independent: centroid of a fine raster of the outline (even-odd rule).
    lo, hi = outline.min(axis=0), outline.max(axis=0)
    g = np.stack(np.meshgrid(*(np.linspace(lo[i], hi[i], 801) for i in (0, 1))), -1).reshape(-1, 2)
    inside = np.zeros(len(g), dtype=bool)
    for a, b in zip(outline, np.roll(outline, -1, axis=0), strict=True):
        crosses = (a[1] > g[:, 1]) != (b[1] > g[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = a[0] + (g[:, 1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        inside ^= crosses & (g[:, 0] < xi)
    assert_allclose(part.center_of_mass, g[inside].mean(axis=0), atol=2e-3 * np.ptp(outline))
    assert hull_contains(part.hull, np.asarray(part.center_of_mass))
    if len(outline) == part.hull.n_sides:  # convex outline: the hull's own centroid
        assert_allclose(part.center_of_mass, part.hull.centroid, atol=1e-9)


def test_non_convex_outlines_keep_their_own_centre_of_mass() -> None:
    fork = load("tuning-fork")
    assert len(fork.outline) > fork.hull.n_sides
    # The prongs' gap makes the fork lighter at the top than its hull.
    assert fork.center_of_mass[1] < fork.hull.centroid[1] - 1.0


def test_resolve_part_reaches_the_catalogue() -> None:
    a, b = resolve_part("hand"), load("hand")
    assert a.name == "hand"
    assert_allclose(a.hull.vertices, b.hull.vertices, atol=0)


def test_data_files_hold_exactly_the_documented_keys() -> None:
    files = [f for f in resources.files("bayesgrasp.shapes").iterdir() if f.name.endswith(".json")]
    assert len(files) == len(names())
    for f in files:
        data = json.loads(f.read_text(encoding="utf-8"))
        assert set(data) == {"name", "order", "units", "description", "vertices"}
        assert f.name == f"{data['name']}.json"


def test_entry_is_the_stored_data() -> None:
    e = entry("triangle")
    assert isinstance(e, CatalogueEntry)
    assert (e.order, e.units) == (1, "mm")
    assert e.vertices == ((0.0, 0.0), (40.0, 0.0), (15.55, 36.06))


@pytest.mark.parametrize("func", [load, describe, entry])
def test_unknown_names_raise_part_error(func: object) -> None:
    with pytest.raises(PartError, match=r"no catalogue part 'spoon'; expected one of triangle, "):
        func("spoon")  # type: ignore[operator]
    with pytest.raises(PartError, match="name must be a string; got int"):
        func(3)  # type: ignore[operator]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", "catalogue file 'bad.json' is not valid JSON"),
        ('{"name": "x"}', "must be an object with keys name, order, units, description"),
        ("[1, 2]", r"must be an object with keys .*; got list"),
        (
            '{"name": "x", "order": 1, "units": "mm", "description": "", "vertices": [1, 2]}',
            r"`vertices of catalogue part 'x'` must have shape \(N, 2\)",
        ),
    ],
)
def test_broken_data_files_are_reported(text: str, message: str) -> None:
    with pytest.raises(PartError, match=message):
        _parse("bad.json", text)


def test_example_orientation_counts_as_in_figure_1() -> None:
    """Figure 1: 6 orientations after the first squeeze, 4 after the second, 2 after the third."""
    pb = Problem.build(load("example"))
    plan = plan_exact(pb).most_certain_plan
    rng = np.random.default_rng(5)
    theta = rng.uniform(0.0, 2.0 * math.pi, 20000)
    counts = []
    for k in range(1, len(plan.steps) + 1):
        out = execute_plan(pb, plan.steps[:k], theta)
        counts.append(len(np.unique(np.round(out, 6))))
    assert counts == [6, 4, 2]
