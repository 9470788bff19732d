"""Figure (a), bayesgrasp.figures.part: the jaws touch the chord; the legend hides nothing."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import MissingExtraError
from bayesgrasp.figures import part_figure
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


def test_missing_matplotlib_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'bayesgrasp\[plot\]'"):
        part_figure(PENTAGON)
