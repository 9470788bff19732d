"""Figure (a), bayesgrasp.figures.part: the jaws touch the chord; the legend hides nothing."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import MissingExtraError
from bayesgrasp.figures import part_figure
from bayesgrasp.figures.part import DRAWING_SAGITTA
from bayesgrasp.geometry.curved import CurvedRing, curved_part
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import Problem
from bayesgrasp.shapes import load

ByGid = Callable[[Any, str], list[Any]]

PENTAGON = Part.from_points([(0, 0), (4, 0), (5, 2), (2, 4), (-1, 2)], name="pentagon")
L_PART = Part.from_outline([(0, 0), (6, 0), (6, 2), (2, 2), (2, 5), (0, 5)], name="L", units="mm")


@pytest.mark.parametrize("theta", [0.0, 0.4, 1.3, 2.9, 4.0])
@pytest.mark.parametrize("part", [PENTAGON, L_PART])
def test_part_figure_jaws_touch_the_antipodal_chord(
    part: Part, theta: float, by_gid: ByGid
) -> None:
    fig = part_figure(part, theta)
    ax = fig.axes[0]
    width = float(diameter_function(part.hull)(theta))
    left, right = by_gid(ax, "jaw-left")[0], by_gid(ax, "jaw-right")[0]
    gap = right.get_x() - (left.get_x() + left.get_width())
    assert_allclose(gap, width, rtol=1e-12)
    chord = by_gid(ax, "chord")[0]
    xs = np.asarray(chord.get_xdata())
    assert_allclose(sorted(xs), [-width / 2, width / 2], atol=1e-9 * width)  # on the jaws
    hull = by_gid(ax, "hull")[0]
    hx, hy = np.asarray(hull.get_xdata()), np.asarray(hull.get_ydata())
    assert len(hx) == part.hull.n_sides + 1  # a closed ring through every hull vertex
    assert_allclose([hx.min(), hx.max()], [-width / 2, width / 2], atol=1e-9 * width)
    # The drawn hull is the part's hull turned by theta (edge lengths are kept).
    edges = np.hypot(np.diff(hx), np.diff(hy))
    v = part.hull.vertices
    assert_allclose(edges, np.hypot(*(np.roll(v, -1, axis=0) - v).T), rtol=1e-12)
    com = by_gid(ax, "com")[0]
    assert_allclose(com.get_ydata(), [0.0], atol=1e-12)
    assert "°" in ax.get_title()


def test_part_figure_of_a_problem_is_the_figure_of_its_part(by_gid: ByGid) -> None:
    pb = Problem.build(L_PART)
    a, b = part_figure(pb, 0.7).axes[0], part_figure(L_PART, 0.7).axes[0]
    for gid in ("hull", "chord", "com"):
        assert_allclose(by_gid(a, gid)[0].get_xydata(), by_gid(b, gid)[0].get_xydata())


@pytest.mark.parametrize("name", ["house", "key", "hand", "triangle"])
def test_the_legend_covers_neither_jaw_nor_the_part(name: str, by_gid: ByGid) -> None:
    """Issue 15, item 11: the legend sat on the right jaw of every part figure."""
    fig = part_figure(load(name))
    fig.canvas.draw()
    ax = fig.axes[0]
    drawn = ax.get_legend()
    assert drawn is not None
    legend = drawn.get_window_extent()
    for gid in ("jaw-left", "jaw-right", "outline"):
        assert not legend.overlaps(by_gid(ax, gid)[0].get_window_extent()), gid
    assert not legend.overlaps(ax.get_window_extent())  # outside the axes, below them
    assert fig.bbox.contains(legend.x0, legend.y0) and fig.bbox.contains(legend.x1, legend.y1)


def _stadium_gap(xy: np.ndarray) -> np.ndarray:
    """Distance of points to the boundary of the stadium of radius 1 about (0, 0)-(2, 0)."""
    t = np.clip(xy[:, 0], 0.0, 2.0)
    return np.abs(np.hypot(xy[:, 0] - t, xy[:, 1]) - 1.0)


def _with_midpoints(ring: np.ndarray) -> np.ndarray:
    closed = np.vstack([ring, ring[:1]])
    return np.vstack([ring, 0.5 * (closed[1:] + closed[:-1])])


@pytest.mark.parametrize("theta", [0.0, 0.7, 2.2])
def test_a_curved_part_is_drawn_with_its_arcs_not_its_file_chords(
    theta: float, by_gid: ByGid
) -> None:
    """Issue 16: the figures drew the chords the part file was flattened to.

    A slot (stadium) with a round hole, built with chords 5% of its size: every drawn point
    and every drawn chord's midpoint must lie within the drawing sagitta of the true arcs.
    """
    slot = CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1])
    hole = CurvedRing([(0.8, 0), (1.2, 0)], [1.0, 1.0])
    part = curved_part(slot, [hole], name="slot", display_tol=0.05 * 2.0)
    size = part.curved_hull.size
    bound = 1.01 * DRAWING_SAGITTA * size
    ax = part_figure(part, theta).axes[0]
    # Undo place_part's turn and shift with the centre of mass, which it puts at y = 0.
    c, s = math.cos(theta), math.sin(theta)
    rot = np.array([[c, -s], [s, c]])
    placed_com = np.asarray(by_gid(ax, "com")[0].get_xydata())[0]
    shift = placed_com - part.center_of_mass @ rot.T

    def unplaced(xy: np.ndarray) -> np.ndarray:
        return np.asarray((xy - shift) @ rot)

    path = by_gid(ax, "outline")[0].get_path()
    rings = [unplaced(r) for r in path.to_polygons(closed_only=False)]
    outer = max(rings, key=len)
    inner = [r for r in rings if r is not outer]
    assert len(inner) == 1
    assert _stadium_gap(_with_midpoints(outer)).max() <= bound
    hole_gap = np.abs(np.hypot(*(_with_midpoints(inner[0]) - (1.0, 0.0)).T) - 0.2)
    assert hole_gap.max() <= bound
    hull = unplaced(np.asarray(by_gid(ax, "hull")[0].get_xydata()))
    assert _stadium_gap(_with_midpoints(hull)).max() <= bound
    left, right = by_gid(ax, "jaw-left")[0], by_gid(ax, "jaw-right")[0]
    gap = right.get_x() - (left.get_x() + left.get_width())
    assert_allclose(gap, 2.0 + 2.0 * abs(math.cos(theta)), atol=2 * bound)


def test_missing_matplotlib_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'bayesgrasp\[plot\]'"):
        part_figure(PENTAGON)
