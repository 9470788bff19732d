"""Animation (e), bayesgrasp.figures.animation: frames follow the model; starts that succeed
are marked; the GIF is large enough to read."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from numpy.testing import assert_allclose

from bayesgrasp.errors import PlanningError
from bayesgrasp.figures import plan_animation, save_animation
from bayesgrasp.figures.canvas import FAIL_COLOR, GOAL_COLOR
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.problem import Problem, nearest_state
from bayesgrasp.planning import execute_plan, plan_exact
from bayesgrasp.shapes import load

PENTAGON = Part.from_points([(0, 0), (4, 0), (5, 2), (2, 4), (-1, 2)], name="pentagon")


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


@pytest.mark.parametrize("actions", ["squeeze", "squeeze,push-grasp"])
def test_the_panels_say_which_starts_succeed(actions: str) -> None:
    pb = Problem.build(load("house"), actions=actions)
    option = plan_exact(pb).bayes_plan
    start = np.radians(np.arange(5.0, 360.0, 40.0))
    anim = plan_animation(pb, option, initial=start, frames_per_step=4)
    final = execute_plan(pb, option.steps, start)
    goal = nearest_state(pb.states, np.array([option.final_orientation]))[0]
    expect = nearest_state(pb.states, final) == goal
    assert anim.success is not None
    assert anim.success.tolist() == expect.tolist()
    assert expect.any()
    for ax, ok in zip(anim.figure.axes, anim.success, strict=True):
        title = ax.get_title()
        assert ("✓" in title) == ok and ("✗" in title) == (not ok)
        colour = to_rgba(GOAL_COLOR if ok else FAIL_COLOR)
        assert {tuple(s.get_edgecolor()) for s in ax.spines.values()} == {colour}
        assert to_rgba(ax.title.get_color()) == colour
        assert ax.spines["left"].get_linewidth() >= 2


def test_save_animation_writes_a_large_enough_gif(tmp_path: Path) -> None:
    """Issue 15, item 11: four panels made a 777 x 237 GIF."""
    from PIL import Image

    out = tmp_path
    pb = Problem.build(load("house"))
    option = plan_exact(pb).bayes_plan
    anim = plan_animation(pb, option, frames_per_step=4)
    files = save_animation(anim, out / "p.gif")
    assert files[0] == out / "p.gif"
    with Image.open(files[0]) as im:
        assert im.size[0] > 1000 and im.size[1] > 350
        assert 1 < getattr(im, "n_frames", 1) <= anim.n_frames
        first = np.asarray(im.convert("RGB"))
    # The drawn frame is the figure: the part is in it (blitting kept every artist).
    anim.draw(0)
    anim.figure.canvas.draw()
    whole = np.asarray(anim.figure.canvas.buffer_rgba())[..., :3]  # type: ignore[attr-defined]
    assert first.shape == whole.shape
    assert np.mean(np.abs(first.astype(int) - whole.astype(int)) > 40) < 0.01
    if len(files) > 1:  # ffmpeg present
        assert files[1].suffix == ".mp4" and files[1].stat().st_size > 0


def test_save_animation_of_two_starts(tmp_path: Path) -> None:
    from PIL import Image

    pb = Problem.build(PENTAGON)
    option = plan_exact(pb).bayes_plan
    anim = plan_animation(pb, option, initial=[0.3, 2.0], frames_per_step=4)
    files = save_animation(anim, tmp_path / "p.gif")
    with Image.open(files[0]) as im:
        assert 1 < getattr(im, "n_frames", 1) <= anim.n_frames
