"""Figures (bayesgrasp.figures.plots): the artists carry the data they claim to show.

Artists are found by their ``gid``. Numbers are compared with the library's functions and,
for the plan's distributions, with a simulation of many initial orientations.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.errors import MissingExtraError, PlanningError
from bayesgrasp.figures.plots import (
    diameter_figure,
    evolution_figure,
    part_figure,
    plan_animation,
    plan_figure,
    save_animation,
    step_distributions,
    transfer_figure,
)
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.geometry.transfer import squeeze_function
from bayesgrasp.io import read_part
from bayesgrasp.model.problem import Problem, nearest_state
from bayesgrasp.planning import PlanStep, execute_plan, plan_exact

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PENTAGON = Part.from_points([(0, 0), (4, 0), (5, 2), (2, 4), (-1, 2)], name="pentagon")
L_PART = Part.from_outline([(0, 0), (6, 0), (6, 2), (2, 2), (2, 5), (0, 5)], name="L", units="mm")


def by_gid(ax: object, gid: str) -> list:
    artists = [*ax.lines, *ax.patches, *ax.collections]  # type: ignore[attr-defined]
    return [a for a in artists if a.get_gid() == gid]


@pytest.fixture(scope="module")
def bracket_problem() -> Problem:
    return Problem.build(read_part(EXAMPLES / "bracket.dxf"))


@pytest.mark.parametrize("theta", [0.0, 0.4, 1.3, 2.9, 4.0])
@pytest.mark.parametrize("part", [PENTAGON, L_PART])
def test_part_figure_jaws_touch_the_antipodal_chord(part: Part, theta: float) -> None:
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


@pytest.mark.parametrize("part", [PENTAGON, L_PART])
def test_diameter_figure_marks_the_extrema_and_the_first_squeeze(part: Part) -> None:
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


def test_transfer_figure_steps_are_the_squeeze_function() -> None:
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


def test_transfer_figure_adds_the_push_grasp_function_when_asked() -> None:
    fig = transfer_figure(L_PART, push_grasp=True)
    assert len(fig.axes) == 2
    g = push_grasp_function(L_PART)
    stable = by_gid(fig.axes[1], "stable")[0].get_xdata()
    assert_allclose(stable, np.degrees(g.stable), atol=1e-9)
    assert "push-grasp" in fig.axes[1].get_title()


def test_step_distributions_agree_with_a_simulation(
    bracket_problem: Problem, rng: np.random.Generator
) -> None:
    pb = bracket_problem
    option = plan_exact(pb).most_certain_plan
    start = rng.uniform(0, 2 * np.pi, 40_000)
    dists = step_distributions(pb, option.steps)
    assert len(dists) == option.n_actions
    for k, (where, probs) in enumerate(dists, start=1):
        final = execute_plan(pb, option.steps[:k], start)
        idx = nearest_state(pb.states, final)
        freq = np.bincount(idx, minlength=pb.n_states) / len(start)
        expected = np.zeros(pb.n_states)
        expected[nearest_state(pb.states, where)] = probs
        sigma = np.sqrt(expected * (1 - expected) / len(start))
        assert np.all(np.abs(freq - expected) <= 5 * sigma + 1e-12)
        assert_allclose(probs.sum(), 1.0, atol=1e-12)


def test_evolution_figure_one_panel_per_step(bracket_problem: Problem) -> None:
    pb = bracket_problem
    rep = plan_exact(pb)
    for option in rep.options:
        fig = evolution_figure(pb, option, "test")
        axes = fig.axes
        assert len(axes) == option.n_actions + 1
        prior = by_gid(axes[0], "prior")[0]
        assert_allclose(np.sum(prior.get_data().values), 1.0, atol=1e-12)
        for ax in axes[1:]:
            stems = by_gid(ax, "distribution")[0].get_segments()
            heights = np.array([seg[1][1] for seg in stems])
            assert_allclose(heights.sum(), 1.0, atol=1e-12)
        last = np.array([seg[1] for seg in by_gid(axes[-1], "distribution")[0].get_segments()])
        goal = math.degrees(option.final_orientation)
        at_goal = last[np.abs(last[:, 0] - goal) < 1e-6, 1]
        assert_allclose(at_goal, [option.success_probability], atol=1e-12)
        assert_allclose(by_gid(axes[-1], "goal")[0].get_xdata(), [goal, goal])


def test_plan_figure_and_its_arguments(bracket_problem: Problem) -> None:
    rep = plan_exact(bracket_problem)
    fig = plan_figure(rep, "most-certain")
    top, bottom = fig.subfigs
    assert len(top.axes) == 3  # part, diameter and its histogram axis
    assert len(bottom.axes) == rep.most_certain_plan.n_actions + 1
    with pytest.raises(PlanningError, match="`which` must be 'bayes' or 'most-certain'"):
        plan_figure(rep, "best")
    with pytest.raises(PlanningError, match="at least one step"):
        step_distributions(bracket_problem, [])


def test_animation_has_one_frame_sequence_per_step(bracket_problem: Problem) -> None:
    pb = bracket_problem
    option = plan_exact(pb).most_certain_plan
    start = np.radians([5.0, 100.0, 200.0])
    anim = plan_animation(pb, option, initial=start, frames_per_step=12)
    assert len(anim.step_frames) == option.n_actions
    assert anim.step_frames[0].start == 0
    for a, b in zip(anim.step_frames, anim.step_frames[1:], strict=False):
        assert a.stop == b.start  # contiguous, in order
    assert anim.step_frames[-1].stop < anim.n_frames  # then a pause on the result
    d = diameter_function(pb.part.hull)
    # The jaws never pass into the part, and they touch it while it turns.
    assert np.all(anim.gap >= d(anim.orientation) - 1e-9)
    for k, frames in enumerate(anim.step_frames, start=1):
        end = frames[-1]
        expect = execute_plan(pb, option.steps[:k], start)
        assert_allclose(np.mod(anim.orientation[end], 2 * np.pi), expect, atol=1e-9)
    assert_allclose(anim.final, execute_plan(pb, option.steps, start))
    assert anim.orientation.shape == anim.gap.shape == (anim.n_frames, 3)
    with pytest.raises(PlanningError, match="at least 4"):
        plan_animation(pb, option, frames_per_step=2)


def test_save_animation_writes_a_gif(tmp_path: Path) -> None:
    from PIL import Image

    pb = Problem.build(PENTAGON)
    option = plan_exact(pb).bayes_plan
    anim = plan_animation(pb, option, initial=[0.3, 2.0], frames_per_step=4)
    files = save_animation(anim, tmp_path / "p.gif")
    assert files[0] == tmp_path / "p.gif"
    with Image.open(files[0]) as im:
        assert 1 < im.n_frames <= anim.n_frames
    if len(files) > 1:  # ffmpeg present
        assert files[1].suffix == ".mp4" and files[1].stat().st_size > 0


def test_missing_matplotlib_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'bayesgrasp\[plot\]'"):
        part_figure(PENTAGON)


def is_png(path: Path) -> bool:
    return path.stat().st_size > 1000 and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_plot_writes_png_and_svg(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "figs"
    code = main(["plot", str(EXAMPLES / "peanut.svg"), "--out", str(out), "--no-animation"])
    printed = capsys.readouterr().out.split()
    assert code == 0
    for name in ("part", "diameter", "transfer", "plan"):
        assert is_png(out / f"{name}.png")
        assert (out / f"{name}.svg").read_text().lstrip().startswith("<?xml")
    assert sorted(printed) == sorted(str(p) for p in out.iterdir())


def test_cli_plot_guaranteed_plan_with_animation(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "plot",
            "rectangle",
            "--plan",
            "guaranteed",
            "--out",
            str(tmp_path),
            "--frames",
            "4",
            "--image-formats",
            "png",
            "--push-grasp",
        ]
    )
    capsys.readouterr()
    assert code == 0
    assert is_png(tmp_path / "plan.png") and is_png(tmp_path / "transfer.png")
    assert (tmp_path / "plan.gif").read_bytes()[:6] == b"GIF89a"
    assert not (tmp_path / "plan.svg").exists()


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["plot", "rectangle", "--image-formats", "jpg"], "--image-formats"),
        (["plan", "rectangle", "--plot", "{tmp}/plan.jpg"], "must end in .png, .svg or .pdf"),
        (["plan", "rectangle", "--plot", "{tmp}/no/such/plan.png"], "no folder"),
        (["plot", "{tmp}/missing.svg", "--out", "{tmp}"], "no such file"),
    ],
)
def test_cli_plot_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], match: str
) -> None:
    code = main([a.format(tmp=tmp_path) for a in argv])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and match in err and "Traceback" not in err


def test_plan_plot_from_a_fresh_process(tmp_path: Path) -> None:
    """The issue's 'done when': `bayesgrasp plan examples/bracket.dxf --plot plan.png`."""
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "bayesgrasp.cli",
            "plan",
            str(EXAMPLES / "bracket.dxf"),
            "--plot",
            "plan.png",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert "Bayes plan" in run.stdout
    assert is_png(tmp_path / "plan.png")


def test_step_distribution_of_a_single_squeeze_is_the_basin_widths() -> None:
    pb = Problem.build(PENTAGON)
    [(where, probs)] = step_distributions(pb, [PlanStep("squeeze", 0.0)])
    assert_allclose(where, pb.states.stable)
    assert_allclose(probs, pb.states.widths / (2 * np.pi), atol=1e-12)
