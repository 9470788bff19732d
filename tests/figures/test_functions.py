"""Figures (b) and (c), bayesgrasp.figures.functions: the curves are the problem's functions."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.figures import diameter_figure, transfer_figure
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.geometry.transfer import TransferFunction, squeeze_function
from bayesgrasp.model.problem import Problem
from bayesgrasp.shapes import load

ByGid = Callable[[Any, str], list[Any]]

PENTAGON = Part.from_points([(0, 0), (4, 0), (5, 2), (2, 4), (-1, 2)], name="pentagon")
L_PART = Part.from_outline([(0, 0), (6, 0), (6, 2), (2, 2), (2, 5), (0, 5)], name="L", units="mm")


@pytest.mark.parametrize("part", [PENTAGON, L_PART])
def test_diameter_figure_marks_the_extrema_and_the_first_squeeze(part: Part, by_gid: ByGid) -> None:
    pb = Problem.build(part)
    fig = diameter_figure(pb)
    ax, twin = fig.axes
    d = diameter_function(part.hull)
    s = squeeze_function(part.hull)
    minima = np.asarray(by_gid(ax, "minima")[0].get_xdata())
    assert_allclose(minima, np.degrees(np.unique(np.round(np.mod(s.stable, np.pi), 12))), atol=1e-9)
    assert_allclose(by_gid(ax, "minima")[0].get_ydata(), d(d.minima), rtol=1e-12)
    assert_allclose(by_gid(ax, "maxima")[0].get_xdata(), np.degrees(d.maxima), atol=1e-9)
    curve = by_gid(ax, "diameter")[0]
    x, y = np.asarray(curve.get_xdata()), np.asarray(curve.get_ydata())
    assert x.min() == 0 and x.max() == 180
    assert_allclose(y, d(np.radians(x)), rtol=1e-12)
    assert y.min() >= d(d.minima).min() - 1e-12  # the marked minima are the lowest points
    bars = by_gid(twin, "histogram")
    centres = np.array([b.get_x() + b.get_width() / 2 for b in bars])
    heights = np.array([b.get_height() for b in bars])
    assert_allclose(centres, minima, atol=1e-9)
    assert_allclose(heights.sum(), 1.0, atol=1e-12)
    # theta and theta + pi together: basin widths of both over 2 pi
    k = len(d.minima)
    assert_allclose(heights, (s.widths[:k] + s.widths[k:]) / (2 * np.pi), atol=1e-12)
    assert ax.get_xlabel().endswith("(deg)")
    lo, hi = ax.get_xlim()
    assert lo < 0 and hi > 180  # a minimum at 0 (or 180) is drawn whole


def test_diameter_figure_of_a_push_grasp_first(by_gid: ByGid) -> None:
    pb = Problem.build(load("house"), actions="squeeze,push-grasp")
    fig = diameter_figure(pb, 0.4, "push-grasp")
    bars = by_gid(fig.axes[1], "histogram")
    heights = np.array([b.get_height() for b in bars])
    after = pb.state_distribution(0.4, "push-grasp")  # (K,) over [0, 2 pi)
    k = len(pb.diameter.minima)
    assert_allclose(heights, after[:k] + after[k:], atol=1e-12)
    assert "push-grasp" in fig.axes[0].get_title()


def steps_of(ax: Any, by_gid: ByGid) -> np.ndarray:
    """(y, x_from, x_to) of every drawn step, degrees."""
    segs = by_gid(ax, "steps")[0].get_segments()
    return np.array([(s[0][1], s[0][0], s[1][0]) for s in segs])


def test_transfer_figure_steps_are_the_squeeze_function(by_gid: ByGid) -> None:
    pb = Problem.build(PENTAGON)
    fig = transfer_figure(pb)
    ax = fig.axes[0]
    s = pb.states
    assert_allclose(by_gid(ax, "stable")[0].get_xdata(), np.degrees(s.stable), atol=1e-9)
    steps = by_gid(ax, "steps")[0].get_segments()
    for seg in steps:
        (x0, y), (x1, _) = seg
        mid = np.radians((x0 + x1) / 2)
        assert_allclose(np.degrees(s(mid)), y, atol=1e-9)
    covered = sum(seg[1][0] - seg[0][0] for seg in steps)
    assert_allclose(covered, 360.0, atol=1e-9)  # the steps tile [0, 360)
    lines = by_gid(ax, "boundaries")
    assert_allclose(sorted(ln.get_xdata()[0] for ln in lines), np.degrees(s.boundaries), atol=1e-9)
    lo, hi = ax.get_ylim()
    assert lo < 0 and hi > 360  # the step at 0 is not hidden on the frame


def test_transfer_figure_draws_every_action_of_the_problem() -> None:
    pb = Problem.build(L_PART, actions="squeeze,push-grasp")
    fig = transfer_figure(pb)
    assert [ax.get_title().split(": ")[1].split()[0] for ax in fig.axes] == [
        "squeeze",
        "push-grasp",
    ]
    only_push = Problem.build(L_PART, actions="push-grasp")
    assert len(transfer_figure(only_push).axes) == 2  # the squeeze function: the states
    assert len(transfer_figure(Problem.build(L_PART)).axes) == 1


def test_transfer_figure_of_a_part_with_the_deprecated_flag(by_gid: ByGid) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a part is built with the actions the flag asks for
        fig = transfer_figure(L_PART, push_grasp=True)
    assert len(fig.axes) == 2
    g = push_grasp_function(L_PART)
    assert_allclose(by_gid(fig.axes[1], "stable")[0].get_ydata(), np.degrees(g.stable), atol=1e-9)
    assert "push-grasp" in fig.axes[1].get_title()


def test_the_deprecated_flag_warns_when_it_changes_the_figure() -> None:
    pb = Problem.build(L_PART)
    with pytest.warns(DeprecationWarning, match="`push_grasp` is deprecated"):
        assert len(transfer_figure(pb, push_grasp=True).axes) == 2
    both = Problem.build(L_PART, actions="squeeze,push-grasp")
    with pytest.warns(DeprecationWarning, match="draws the problem's actions"):
        assert len(transfer_figure(both, push_grasp=False).axes) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # agreeing with the problem: as before, silently
        assert len(transfer_figure(both, push_grasp=True).axes) == 2


def on_a_step(x: float, y: float, steps: np.ndarray) -> bool:
    ys, x0, x1 = steps.T
    return bool(np.any((np.abs(ys - y) < 1e-9) & (x0 - 1e-9 <= x) & (x <= x1 + 1e-9)))


@pytest.mark.parametrize("name", ["key", "hand", "house", "example", "triangle"])
def test_stable_orientations_are_marked_on_their_steps(name: str, by_gid: ByGid) -> None:
    """Issue 15, item 11: the push-grasp plot showed stable dots off its steps."""
    pb = Problem.build(load(name), actions="squeeze,push-grasp")
    fig = transfer_figure(pb)
    functions: list[TransferFunction] = [pb.states, pb.transfer("push-grasp")]
    for ax, f in zip(fig.axes, functions, strict=True):
        steps = steps_of(ax, by_gid)
        marks = by_gid(ax, "stable")[0]
        xs, ys = np.asarray(marks.get_xdata()), np.asarray(marks.get_ydata())
        assert_allclose(ys, np.degrees(f.stable), atol=1e-9)
        for x, y in zip(xs, ys, strict=True):
            assert on_a_step(x, y, steps), (name, f.kind, x, y)
            # ... the step of that stable orientation: the function sends x there
            assert_allclose(np.degrees(f(math.radians(x))), y, atol=1e-9)
        inside = (f.basin_lo <= f.stable) & (f.stable <= f.basin_hi)
        assert_allclose(xs[inside], ys[inside], atol=1e-9)  # fixed points on the identity
