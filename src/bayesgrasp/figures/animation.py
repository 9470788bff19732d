"""Animation (e): a plan executed kinematically from several initial orientations.

:func:`plan_animation` computes the part's orientation and the jaw gap at every frame from
the problem's model (its diameter function and the transfer function of each step's
action) and draws one panel per initial orientation, framed green where that start ends at
the goal and red where it does not. :func:`save_animation` writes a GIF (and an MP4 when
ffmpeg is present).
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import wrap_array
from ..errors import MissingExtraError, PlanningError
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption, PlanStep, execute_plan
from .canvas import FAIL_COLOR, GOAL_COLOR, JAW_COLOR, PART_COLOR, PART_EDGE, new_figure
from .part import outline_path, part_patch, place_part

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "PlanAnimation",
    "ends_at_goal",
    "kinematics",
    "plan_animation",
    "render_frames",
    "save_animation",
]

FloatArray = NDArray[np.float64]

#: Resolution of the animation's frames (dots per inch) and the size of one panel (inches).
FRAME_DPI = 100
PANEL_SIZE = (3.0, 3.4)


@dataclass(frozen=True, eq=False)
class PlanAnimation:
    """A plan executed kinematically from several initial orientations.

    Attributes
    ----------
    figure : Figure
    draw : callable
        ``draw(frame)`` updates the figure to frame ``frame`` (0 to ``n_frames - 1``) and
        returns the artists it changed; :func:`save_animation` runs it for every frame.
    initial : ndarray of shape (M,)
        Initial world orientations (radians), one panel each.
    orientation : ndarray of shape (F, M)
        The part's orientation in the current gripper frame at each frame (radians,
        unwrapped).
    gap : ndarray of shape (F, M)
        Distance between the jaws at each frame (the part's width while they touch it).
    step_frames : tuple of range
        The frames of each step of the plan, in order (a final pause follows).
    final : ndarray of shape (M,)
        The orientation reached by each panel (``execute_plan``, in ``[0, 2 pi)``).
    success : ndarray of shape (M,) of bool, optional
        Whether each panel ends at the plan's goal (or, for a symmetry goal, a copy of it).
    """

    figure: Figure
    draw: Callable[[int], Any]
    initial: FloatArray
    orientation: FloatArray
    gap: FloatArray
    step_frames: tuple[range, ...]
    final: FloatArray
    success: NDArray[np.bool_] | None = None

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return len(self.orientation)


def kinematics(
    problem: Problem, steps: Sequence[PlanStep], initial: FloatArray, frames: int
) -> tuple[FloatArray, FloatArray, tuple[range, ...], list[str]]:
    """Orientation and jaw gap per frame: turn the gripper, close, turn the part, open.

    During an action the orientation moves from ``theta`` to the model's final orientation
    ``F(theta)`` linearly (the part descends the diameter function, so the jaws, always
    touching, close monotonically); the jaws then open at the new orientation.

    Returns
    -------
    orientation, gap : ndarray of shape (F, M)
    step_frames : tuple of range
    phases : list of str
        What happens at each frame, for the title.
    """
    d = problem.diameter
    open_gap = 1.25 * d.diameter
    n_turn = max(1, frames // 4)
    n_close = max(1, frames // 4)
    n_act = max(1, frames // 3)
    n_open = max(1, frames - n_turn - n_close - n_act)
    theta = initial.astype(np.float64).copy()
    rows_th: list[FloatArray] = []
    rows_gap: list[FloatArray] = []
    phases: list[str] = []
    spans: list[range] = []
    for k, step in enumerate(steps):
        begin = len(rows_th)
        what = f"step {k + 1}, {problem.action(step.kind).name}"
        target = theta - step.alpha
        for u in np.linspace(0.0, 1.0, n_turn):
            rows_th.append(theta + u * (target - theta))
            rows_gap.append(np.full_like(theta, open_gap))
            phases.append(f"{what}: gripper turns {math.degrees(step.alpha):+.1f}°")
        theta = target
        width = d(theta)
        for u in np.linspace(0.0, 1.0, n_close + 1)[1:]:
            rows_th.append(theta.copy())
            rows_gap.append(open_gap + u * (width - open_gap))
            phases.append(f"{what}: jaws close")
        final = problem.transfer(step.kind)(theta)  # [0, 2 pi)
        end = theta + wrap_array(final - theta)
        for u in np.linspace(0.0, 1.0, n_act + 1)[1:]:
            th = theta + u * (end - theta)
            rows_th.append(th)
            rows_gap.append(d(th))
            phases.append(f"{what}: the part turns")
        theta = end
        width = d(theta)
        for u in np.linspace(0.0, 1.0, n_open + 1)[1:]:
            rows_th.append(theta.copy())
            rows_gap.append(width + u * (open_gap - width))
            phases.append(f"{what}: jaws open")
        spans.append(range(begin, len(rows_th)))
    for _ in range(max(2, frames // 3)):  # a pause on the result
        rows_th.append(theta.copy())
        rows_gap.append(np.full_like(theta, open_gap))
        phases.append("done")
    return np.array(rows_th), np.array(rows_gap), tuple(spans), phases


def ends_at_goal(problem: Problem, option: PlanOption, final: FloatArray) -> NDArray[np.bool_]:
    """Whether each final orientation is a goal state of the plan (see :class:`Goal`)."""
    return np.asarray(
        problem.success_states(option.final_orientation)[nearest_state(problem.states, final)],
        dtype=bool,
    )


def plan_animation(
    problem: Problem,
    option: PlanOption,
    initial: ArrayLike | None = None,
    frames_per_step: int = 24,
    label: str = "chosen",
    note: str | None = None,
) -> PlanAnimation:
    """(e) Animate a plan from several initial orientations: jaws closing, the part turning.

    Each panel starts from one initial world orientation; for each step the gripper turns,
    the jaws close to the part's width, the part turns from its orientation to the one the
    action's transfer function predicts (linearly, the jaws following the diameter
    function) and the jaws open. The part is drawn in the gripper frame. A panel's frame and
    title are green when its start ends at the plan's goal, red when it does not.

    Parameters
    ----------
    problem : Problem
    option : PlanOption
    initial : array_like of shape (M,), optional
        Initial world orientations (radians); default four spread over the circle.
    frames_per_step : int, optional
        Frames of each step (at least 4).
    label : str, optional
        How the title names the plan.
    note : str, optional
        A second line of the caption (below the goal and ``P(success)``), for example the
        noise model the option's probability is exact under.

    Returns
    -------
    PlanAnimation

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> opt = plan_exact(pb).bayes_plan
    >>> anim = plan_animation(pb, opt, frames_per_step=8)
    >>> len(anim.step_frames) == opt.n_actions, anim.success.tolist()
    (True, [True, True, False, False])
    """
    if frames_per_step < 4:
        raise PlanningError(f"`frames_per_step` must be at least 4; got {frames_per_step}")
    try:
        from matplotlib.patches import Rectangle
    except ImportError:
        raise MissingExtraError("matplotlib", "plot") from None
    if initial is None:
        start = np.radians(17.0 + 90.0 * np.arange(4))
    else:
        start = np.atleast_1d(np.asarray(initial, dtype=np.float64))
    steps = option.steps
    orient, gap, spans, phases = kinematics(problem, steps, start, frames_per_step)
    final = execute_plan(problem, steps, start)
    success = ends_at_goal(problem, option, final)

    part = problem.part
    m = len(start)
    fig = new_figure(PANEL_SIZE[0] * m + 0.3, PANEL_SIZE[1] + 0.6)
    fig.set_dpi(FRAME_DPI)
    axes = fig.subplots(1, m, squeeze=False)[0]
    diameter = problem.diameter.diameter
    reach = 0.5 * 1.25 * diameter
    jaw = 0.12 * diameter
    patches = []
    jaws = []
    texts = []
    for j, ax in enumerate(axes):
        patch = part_patch(
            place_part(part, float(orient[0, j])), facecolor=PART_COLOR, edgecolor=PART_EDGE, lw=1.0
        )
        ax.add_patch(patch)
        left = Rectangle((0, -0.7 * diameter), jaw, 1.4 * diameter, color=JAW_COLOR)
        right = Rectangle((0, -0.7 * diameter), jaw, 1.4 * diameter, color=JAW_COLOR)
        ax.add_patch(left)
        ax.add_patch(right)
        patches.append(patch)
        jaws.append((left, right))
        texts.append(ax.text(0.5, 0.02, "", transform=ax.transAxes, ha="center", fontsize=10))
        ax.set_xlim(-reach - jaw * 1.2, reach + jaw * 1.2)
        ax.set_ylim(-0.75 * diameter, 0.75 * diameter)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        color = GOAL_COLOR if success[j] else FAIL_COLOR
        for spine in ax.spines.values():
            spine.set_edgecolor(color)
            spine.set_linewidth(3.0)
        verdict = "✓ ends at the goal" if success[j] else "✗ misses the goal"
        ax.set_title(
            f"start {math.degrees(start[j]) % 360:.0f}° → end {math.degrees(final[j]):.0f}°\n"
            f"{verdict}",
            fontsize=10,
            color=color,
        )
    title = fig.suptitle("", fontsize=12)
    fig.supxlabel(
        f"goal {math.degrees(option.final_orientation):.1f}° in the last gripper frame; "
        f"P(success) = {option.success_probability:.3f} over the prior"
        + ("" if note is None else f"\n{note}"),
        fontsize=10,
    )

    def update(frame: int) -> list[Any]:
        for j in range(m):
            path = outline_path(place_part(part, float(orient[frame, j])))
            patches[j].set_path(path)
            half = gap[frame, j] / 2.0
            jaws[j][0].set_x(-half - jaw)
            jaws[j][1].set_x(half)
            texts[j].set_text(f"θ = {round(math.degrees(orient[frame, j]), 1) % 360:5.1f}°")
        title.set_text(f"{part.name}, {label} plan: {phases[frame]}")
        return [*patches, *(r for pair in jaws for r in pair), *texts, title]

    update(0)
    fig.canvas.draw()  # lay the panels out once; re-running the layout on every frame is slow
    fig.set_layout_engine("none")
    return PlanAnimation(fig, update, start, orient, gap, spans, final, success)


def render_frames(anim: PlanAnimation) -> Iterable[NDArray[np.uint8]]:
    """The RGB pixels of every frame, drawing only what changes (blitting).

    The still parts (panel frames, titles, the caption) are drawn once; each frame restores
    them and draws the artists ``anim.draw`` returns. A ``draw`` that returns nothing gets a
    full redraw per frame.
    """
    canvas = anim.figure.canvas
    changed = anim.draw(0)
    artists = list(changed) if isinstance(changed, Iterable) else []
    for a in artists:
        a.set_animated(True)
    try:
        canvas.draw()
        background = canvas.copy_from_bbox(anim.figure.bbox)  # type: ignore[attr-defined]
        for k in range(anim.n_frames):
            if artists:
                canvas.restore_region(background)  # type: ignore[attr-defined]
                for a in anim.draw(k):
                    (a.axes or anim.figure).draw_artist(a)
            else:
                anim.draw(k)
                canvas.draw()
            rgba = np.asarray(canvas.buffer_rgba())  # type: ignore[attr-defined]
            yield rgba[..., :3]
    finally:
        for a in artists:
            a.set_animated(False)


def save_animation(anim: PlanAnimation, path: str | Path, fps: int = 12) -> list[Path]:
    """Write the animation as a GIF (pillow) and, when ffmpeg is installed, an MP4 beside it.

    Parameters
    ----------
    anim : PlanAnimation
    path : str or Path
        The GIF's path; the MP4 gets the same name with ``.mp4``.
    fps : int, optional
        Frames per second.

    Returns
    -------
    list of Path
        The files written.
    """
    try:
        from PIL import Image
    except ImportError:
        raise MissingExtraError("pillow", "plot") from None
    gif = Path(path)
    frames = []
    palette = None
    for rgb in render_frames(anim):
        image = Image.fromarray(rgb)
        if palette is None:  # the first frame holds every colour (titles, frames, part, jaws)
            palette = image.quantize(colors=255)
        frames.append(image.quantize(palette=palette, dither=Image.Dither.NONE))
    frames[0].save(
        gif,
        save_all=True,
        append_images=frames[1:],
        duration=round(1000 / fps),
        loop=0,
        optimize=False,
    )
    written = [gif]
    if shutil.which("ffmpeg") is not None:
        from matplotlib.animation import FFMpegWriter, FuncAnimation

        mp4 = gif.with_suffix(".mp4")
        movie = FuncAnimation(anim.figure, anim.draw, frames=anim.n_frames, blit=False)
        movie.save(str(mp4), writer=FFMpegWriter(fps=fps))
        written.append(mp4)
    anim.draw(0)
    return written
