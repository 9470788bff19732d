"""Figures of parts, diameter and transfer functions, plans, and plan animations.

Every function returns a matplotlib :class:`~matplotlib.figure.Figure` drawn on the Agg
canvas (no window, no global pyplot state), so it is safe in scripts, servers and tests;
save it with ``fig.savefig(path)`` (the format follows the extension). People see degrees on
every angle axis; titles say what the figure shows. Artists that carry data have a ``gid``
(``"hull"``, ``"chord"``, ``"minima"``, ``"histogram"``, ...) so that tests and users can
find them.

- :func:`part_figure` (a): the part, its convex hull, the antipodal chord that touches the
  jaws, and the jaws.
- :func:`diameter_figure` (b): the diameter function over ``[0, 180)`` degrees with its
  maxima and minima, and the distribution after the first squeeze (the seed's Fig. 3).
- :func:`transfer_figure` (c): the squeeze function (and the push-grasp function).
- :func:`evolution_figure` (d): the distribution over orientations before and after each
  step of a plan (the seed's Fig. 1).
- :func:`plan_figure`: (a), (b) and (d) together, for ``bayesgrasp plan --plot``.
- :func:`plan_animation` (e): a plan executed kinematically from several initial
  orientations; :func:`save_animation` writes a GIF (and an MP4 when ffmpeg is present).

matplotlib (and pillow, for GIFs) are the optional extra ``plot``:
``pip install 'bayesgrasp[plot]'``.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import MissingExtraError, PlanningError
from ..geometry.diameter import DiameterFunction, diameter_function
from ..geometry.polygon import Part
from ..geometry.transfer import TransferFunction
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption, PlanReport, PlanStep, execute_plan

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

__all__ = [
    "PlanAnimation",
    "diameter_figure",
    "evolution_figure",
    "part_figure",
    "plan_animation",
    "plan_figure",
    "save_animation",
    "step_distributions",
    "transfer_figure",
    "write_figures",
]

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]

PART_COLOR = "#9fb8d6"
HULL_COLOR = "#d62728"
JAW_COLOR = "#555555"
BAR_COLOR = "#4c72b0"


def _figure(width: float, height: float) -> Figure:
    """A new figure on the Agg canvas; MissingExtraError when matplotlib is absent."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise MissingExtraError("matplotlib", "plot") from None
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _rotation(theta: float) -> FloatArray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def _deg_axis(ax: Axes, which: str, upper: float) -> None:
    """Degree ticks every 45 (or 30) degrees on an axis from 0 to ``upper`` degrees."""
    step = 45 if upper > 180 else 30
    ticks = np.arange(0, upper + 1e-9, step)
    if which == "x":
        ax.set_xlim(0, upper)
        ax.set_xticks(ticks)
    else:
        ax.set_ylim(0, upper)
        ax.set_yticks(ticks)


def _units(part: Part) -> str:
    return f" ({part.units})" if part.units else ""


@dataclass(frozen=True, slots=True)
class _Placed:
    """A part turned to orientation ``theta`` in the gripper frame and centred on the jaws."""

    outline: FloatArray
    holes: tuple[FloatArray, ...]
    hull: FloatArray
    com: FloatArray
    width: float


def _place(part: Part, theta: float) -> _Placed:
    """Rotate the part by ``theta`` (counter-clockwise) and centre it between the jaws.

    Translation does not matter to the gripper, so the rotated part is shifted to put the
    middle of its x-extent at 0 and its centre of mass at y = 0.
    """
    rot = _rotation(theta)
    hull = part.hull.vertices @ rot.T
    lo, hi = hull[:, 0].min(), hull[:, 0].max()
    com = part.center_of_mass @ rot.T
    shift = np.array([-(lo + hi) / 2.0, -com[1]])
    return _Placed(
        part.outline @ rot.T + shift,
        tuple(h @ rot.T + shift for h in part.holes),
        hull + shift,
        com + shift,
        float(hi - lo),
    )


def _part_patch(placed: _Placed, **kwargs: Any) -> Any:
    """A filled patch of the outline with its holes (holes run the other way)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    rings = [placed.outline] + [h[::-1] for h in placed.holes]
    verts = np.concatenate([np.vstack([r, r[:1]]) for r in rings])
    codes = np.concatenate(
        [[MplPath.MOVETO] + [MplPath.LINETO] * (len(r) - 1) + [MplPath.CLOSEPOLY] for r in rings]
    )
    return PathPatch(MplPath(verts, codes), **kwargs)


def _draw_part(ax: Axes, part: Part, theta: float) -> None:
    """Panel (a): outline, hull, antipodal chord, centre of mass and jaws at ``theta``."""
    from matplotlib.patches import Rectangle

    placed = _place(part, theta)
    d = diameter_function(part.hull)
    i_plus, i_minus = d.pairs[int(d.piece_index(theta))]
    ax.add_patch(
        _part_patch(placed, facecolor=PART_COLOR, edgecolor="#1f3b5c", lw=1.2, label="part")
    )
    ax.patches[-1].set_gid("outline")
    ring = np.vstack([placed.hull, placed.hull[:1]])
    ax.plot(ring[:, 0], ring[:, 1], "--", color=HULL_COLOR, lw=1.2, label="convex hull", gid="hull")
    chord = placed.hull[[i_minus, i_plus]]
    ax.plot(
        chord[:, 0],
        chord[:, 1],
        "-o",
        color="#2ca02c",
        lw=1.5,
        ms=4,
        label="antipodal chord",
        gid="chord",
    )
    ax.plot(*placed.com, "k+", ms=10, mew=2, label="centre of mass", gid="com")
    ys = placed.hull[:, 1]
    span = float(ys.max() - ys.min())
    y0, height = float(ys.min()) - 0.15 * span, 1.3 * span
    jaw = 0.08 * max(placed.width, span)
    half = placed.width / 2.0
    left = Rectangle((-half - jaw, y0), jaw, height, color=JAW_COLOR, alpha=0.8, gid="jaw-left")
    right = Rectangle((half, y0), jaw, height, color=JAW_COLOR, alpha=0.8, gid="jaw-right")
    right.set_label("jaws")
    ax.add_patch(left)
    ax.add_patch(right)
    for sign in (-1.0, 1.0):
        ax.annotate(
            "",
            xy=(sign * (half + jaw), y0 + height / 2),
            xytext=(sign * (half + 2.5 * jaw), y0 + height / 2),
            arrowprops={"arrowstyle": "->", "color": JAW_COLOR, "lw": 1.5},
        )
    ax.set_aspect("equal")
    ax.set_xlim(-half - 3 * jaw, half + 3 * jaw)
    ax.set_ylim(y0 - 0.1 * span, y0 + height + 0.1 * span)
    u = _units(part)
    ax.set_xlabel(f"x: squeeze axis{u}")
    ax.set_ylabel(f"y: along the jaws{u}")
    ax.set_title(
        f"{part.name} at {math.degrees(theta):.1f}°: hull, chord, jaws (gap {placed.width:.4g})"
    )
    ax.legend(loc="upper right", fontsize="small", framealpha=0.8)


def part_figure(part: Part, theta: float = 0.0) -> Figure:
    """(a) The part in the gripper frame at orientation ``theta``, as the jaws hold it.

    Shows the outline (with holes), the convex hull the jaws touch, the antipodal chord of
    the diameter function at ``theta`` (its vertices touch the jaws), the centre of mass,
    and the two jaws a diameter ``d(theta)`` apart.

    Parameters
    ----------
    part : Part
    theta : float, optional
        Orientation of the part (radians, counter-clockwise); 0 shows it as given.

    Returns
    -------
    Figure

    Examples
    --------
    >>> part = Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1)], name="bar")
    >>> fig = part_figure(part, theta=0.3)
    >>> [a.get_gid() for a in fig.axes[0].patches][:3]
    ['outline', 'jaw-left', 'jaw-right']
    """
    fig = _figure(6.4, 5.0)
    _draw_part(fig.add_subplot(), part, theta)
    return fig


def _first_squeeze_histogram(problem: Problem, first_angle: float) -> tuple[FloatArray, FloatArray]:
    """Stable orientations mod pi (degrees) and the probability of each after squeeze 1.

    A squeeze cannot tell ``theta`` from ``theta + pi``; the histogram over ``[0, 180)``
    adds the masses of both.
    """
    d = diameter_function(problem.part.hull)
    probs = problem.state_distribution(first_angle)  # (K,) over [0, 2 pi)
    idx = nearest_state_mod_pi(d.minima, problem.states.stable)
    heights = np.bincount(idx, weights=probs, minlength=len(d.minima)).astype(np.float64)
    return np.degrees(d.minima), heights


def nearest_state_mod_pi(minima: FloatArray, stable: FloatArray) -> NDArray[np.intp]:
    """Index of the minimum (over ``[0, pi)``) nearest to each stable orientation mod pi."""
    diff = np.abs(np.mod(stable[:, None] - minima[None, :] + math.pi / 2, math.pi) - math.pi / 2)
    return np.asarray(np.argmin(diff, axis=1), dtype=np.intp)


def _diameter_samples(d: DiameterFunction, n: int = 1441) -> tuple[FloatArray, FloatArray]:
    """Angles over [0, pi] (the breakpoints and extrema included) and ``d`` at them."""
    th = np.unique(
        np.concatenate([np.linspace(0.0, math.pi, n), d.breaks, d.minima, d.maxima, [math.pi]])
    )
    return th, d(th)


def _draw_diameter(ax: Axes, problem: Problem, first_angle: float) -> None:
    """Panel (b): the diameter function, its extrema, and the first-squeeze histogram."""
    part = problem.part
    d = diameter_function(part.hull)
    th, dv = _diameter_samples(d)
    ax.plot(np.degrees(th), dv, color="k", lw=1.5, label="diameter d(θ)", gid="diameter")
    ax.plot(
        np.degrees(d.minima),
        d(d.minima),
        "o",
        color="#2ca02c",
        ms=7,
        label="minima (stable)",
        gid="minima",
    )
    ax.plot(
        np.degrees(d.maxima),
        d(d.maxima),
        "v",
        color=HULL_COLOR,
        ms=7,
        label="maxima (unstable)",
        gid="maxima",
    )
    _deg_axis(ax, "x", 180.0)
    ax.set_xlabel("orientation θ of the part (deg)")
    ax.set_ylabel(f"jaw separation d(θ){_units(part)}")
    lo = float(dv.min())
    ax.set_ylim(lo - 0.35 * (float(dv.max()) - lo) - 1e-12, float(dv.max()) * 1.02 + 1e-12)
    twin = ax.twinx()
    x, heights = _first_squeeze_histogram(problem, first_angle)
    width = max(2.0, 0.06 * 180.0 / max(len(x), 1))
    twin.bar(
        x,
        heights,
        width=width,
        facecolor="none",
        edgecolor=BAR_COLOR,
        linestyle=":",
        lw=1.8,
        hatch="..",
        label="P(after first squeeze)",
        gid="histogram",
    )
    twin.set_ylim(0, 1)
    twin.set_ylabel("probability after the first squeeze\n(θ and θ + 180° together)")
    handles = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax.legend(handles[0] + more[0], handles[1] + more[1], loc="lower right", fontsize="small")
    ax.set_title(f"{part.name}: diameter function and the distribution after one squeeze")


def diameter_figure(problem: Problem | Part, first_angle: float = 0.0) -> Figure:
    """(b) The diameter function over ``[0, 180)`` degrees, and the first squeeze (Fig. 3).

    Minima (stable orientations) and maxima (unstable equilibria) are marked; the dotted
    histogram is the probability of each stable orientation after a first squeeze made at
    gripper angle ``first_angle`` under the problem's prior (orientations ``theta`` and
    ``theta + 180`` degrees added together, as a squeeze cannot tell them apart).

    Parameters
    ----------
    problem : Problem or Part
        A part is planned with a uniform prior.
    first_angle : float, optional
        World gripper angle of the first squeeze (radians).

    Returns
    -------
    Figure

    Examples
    --------
    >>> fig = diameter_figure(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> [ln for ln in fig.axes[0].lines if ln.get_gid() == "minima"][0].get_xdata().tolist()
    [0.0, 90.0]
    """
    pb = problem if isinstance(problem, Problem) else Problem.build(problem)
    fig = _figure(7.5, 4.5)
    _draw_diameter(fig.add_subplot(), pb, first_angle)
    return fig


def _step_pieces(f: TransferFunction) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Horizontal pieces (y, x_from, x_to) of a transfer function over [0, 360) degrees."""
    ys: list[float] = []
    x0: list[float] = []
    x1: list[float] = []
    for s, lo, hi in zip(f.stable, f.basin_lo, f.basin_hi, strict=True):
        for shift in (-TWO_PI, 0.0, TWO_PI):
            a, b = max(lo + shift, 0.0), min(hi + shift, TWO_PI)
            if b > a:
                ys.append(math.degrees(s))
                x0.append(math.degrees(a))
                x1.append(math.degrees(b))
    return np.array(ys), np.array(x0), np.array(x1)


def _draw_transfer(ax: Axes, f: TransferFunction, name: str) -> None:
    """Panel (c): a transfer function as steps over [0, 360) degrees."""
    ys, x0, x1 = _step_pieces(f)
    label = "squeeze function s(θ)" if f.kind == "squeeze" else f"{f.kind} function g(θ)"
    ax.hlines(ys, x0, x1, colors="k", lw=2.0, label=label, gid="steps")
    ax.plot([0, 360], [0, 360], ":", color="0.6", lw=1, label="identity", gid="identity")
    ax.plot(
        np.degrees(f.stable),
        np.degrees(f.stable),
        "o",
        color="#2ca02c",
        ms=6,
        label="stable orientations",
        gid="stable",
    )
    for k, b in enumerate(np.degrees(f.boundaries)):
        ax.axvline(
            b,
            color=HULL_COLOR,
            lw=0.8,
            ls="--",
            gid="boundaries",
            label="unstable (basin edges)" if k == 0 else None,
        )
    _deg_axis(ax, "x", 360.0)
    _deg_axis(ax, "y", 360.0)
    ax.set_aspect("equal")
    ax.set_xlabel("orientation before the action θ (deg)")
    ax.set_ylabel("orientation after (deg)")
    ax.set_title(
        f"{name}: {f.kind} function ({f.n_states} stable, period {math.degrees(f.period):.4g}°)"
    )
    ax.legend(loc="upper left", fontsize="small")


def transfer_figure(problem: Problem | Part, push_grasp: bool = False) -> Figure:
    """(c) The squeeze function over ``[0, 360)`` degrees (and the push-grasp function).

    Each step is a basin: every orientation in it ends at the basin's stable orientation
    (on the identity line); dashed lines are the unstable equilibria between basins.

    Parameters
    ----------
    problem : Problem or Part
    push_grasp : bool, optional
        Add a panel with the push-grasp function (from the problem when it has one, else
        :func:`bayesgrasp.geometry.push.push_grasp_function`).

    Returns
    -------
    Figure

    Raises
    ------
    PlanningError
        ``push_grasp`` is asked but the push-grasp function is not available.

    Examples
    --------
    >>> fig = transfer_figure(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> sorted(set(fig.axes[0].collections[0].get_segments()[0][:, 1].tolist()))
    [0.0]
    """
    pb = problem if isinstance(problem, Problem) else Problem.build(problem)
    functions = [pb.transfers["squeeze"]]
    if push_grasp:
        if "push-grasp" in pb.transfers:
            functions.append(pb.transfers["push-grasp"])
        else:
            try:
                from ..geometry.push import push_grasp_function
            except ImportError:  # pragma: no cover - push.py ships with the package
                raise PlanningError("the push-grasp function is not available") from None
            functions.append(push_grasp_function(pb.part))
    fig = _figure(5.2 * len(functions), 5.4)
    for k, f in enumerate(functions):
        _draw_transfer(fig.add_subplot(1, len(functions), k + 1), f, pb.part.name)
    return fig


def step_distributions(
    problem: Problem, steps: Sequence[PlanStep]
) -> list[tuple[FloatArray, FloatArray]]:
    """Orientations and probabilities of the part after each step of a plan.

    Entry ``k`` is ``(orientations, probabilities)`` after step ``k + 1``: the stable
    orientations (radians, in that step's gripper frame) and their probabilities under the
    problem's prior. Computed from :meth:`Problem.state_distribution` (first step) and
    :func:`~bayesgrasp.planning.execute_plan` (the following steps).

    Examples
    --------
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> [p.round(3).tolist() for _, p in step_distributions(pb, [PlanStep("squeeze", 0.0)])]
    [[0.148, 0.352, 0.148, 0.352]]
    """
    if not steps:
        raise PlanningError("a plan needs at least one step")
    stable = problem.states.stable
    masses = problem.state_distribution(steps[0].alpha, steps[0].kind)  # (K,)
    out = []
    for k in range(1, len(steps) + 1):
        where = execute_plan(problem, tuple(steps[1:k]), stable)  # (K,) after step k
        idx = nearest_state(problem.states, where)
        probs = np.bincount(idx, weights=masses, minlength=problem.n_states).astype(np.float64)
        keep = probs > 0
        out.append((stable[keep], probs[keep]))
    return out


def _action_text(step: PlanStep, k: int) -> str:
    verb = "squeeze" if step.kind == "squeeze" else step.kind
    if k == 0:
        return f"after {verb} 1 (gripper at {math.degrees(step.alpha):.1f}°)"
    return f"after {verb} {k + 1} (gripper turned α = {math.degrees(step.alpha):+.1f}°)"


def _draw_evolution(
    fig: Figure | SubFigure, problem: Problem, option: PlanOption, label: str
) -> list[Axes]:
    """Panels (d): the prior, then the distribution after each step."""
    n = option.n_actions + 1
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    edges = np.linspace(0.0, TWO_PI, 73)  # 5-degree bins
    prior_mass = np.asarray(problem.prior.mass(edges[:-1], edges[1:]), dtype=np.float64)
    ax = axes[0]
    ax.stairs(prior_mass, np.degrees(edges), fill=True, color="0.8", gid="prior")
    ax.stairs(prior_mass, np.degrees(edges), color="0.35", lw=1.0)
    ax.set_title(
        f"prior ({problem.prior.name}): probability per 5° of initial orientation",
        fontsize="medium",
    )
    ax.set_ylim(0, max(float(prior_mass.max()) * 1.3, 1e-9))
    for k, (where, probs) in enumerate(step_distributions(problem, option.steps)):
        ax = axes[k + 1]
        ax.vlines(np.degrees(where), 0, probs, colors=BAR_COLOR, lw=3, gid="distribution")
        ax.plot(np.degrees(where), probs, "o", color=BAR_COLOR, ms=4)
        for x, p in zip(np.degrees(where), probs, strict=True):
            ax.annotate(
                f"{p:.2f}",
                (x, p),
                textcoords="offset points",
                xytext=(0, 4),
                ha="center",
                fontsize="x-small",
                bbox={"boxstyle": "square,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
            )
        ax.set_ylim(0, 1.15)
        ax.set_title(_action_text(option.steps[k], k), fontsize="medium")
    last = axes[-1]
    last.axvline(
        math.degrees(option.final_orientation),
        color="#2ca02c",
        ls="--",
        lw=1.2,
        zorder=0,
        label=f"goal {math.degrees(option.final_orientation):.1f}°",
        gid="goal",
    )
    last.legend(loc="upper right", fontsize="small")
    _deg_axis(last, "x", 360.0)
    last.set_xlabel("orientation of the part in the gripper frame (deg)")
    for ax in axes:
        ax.set_ylabel("P")
    fig.suptitle(
        f"{problem.part.name}: the {label} plan, {option.n_actions} action(s): "
        f"P(success) = {option.success_probability:.3f}, "
        f"E[cost] = {option.expected_cost:.3g}"
    )
    return list(axes)


def evolution_figure(problem: Problem, option: PlanOption, label: str = "chosen") -> Figure:
    """(d) The distribution over orientations before and after each step of a plan (Fig. 1).

    One panel per step, below the prior: stems at the stable orientations (degrees, in the
    gripper frame of that step) with their probabilities. The last panel marks the plan's
    goal orientation.

    Parameters
    ----------
    problem : Problem
    option : PlanOption
        The plan (for example ``report.bayes_plan``).
    label : str, optional
        How the title names the plan ("Bayes", "most certain", ...).

    Returns
    -------
    Figure

    Examples
    --------
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> rep = plan_exact(pb)
    >>> fig = evolution_figure(pb, rep.bayes_plan, "Bayes")
    >>> len(fig.axes) == rep.bayes_plan.n_actions + 1
    True
    """
    fig = _figure(8.0, 1.9 * (option.n_actions + 1) + 0.6)
    _draw_evolution(fig, problem, option, label)
    return fig


_LABELS = {"bayes": "Bayes", "most-certain": "most certain", "guaranteed": "guaranteed"}


def plan_figure(report: PlanReport, which: str = "bayes") -> Figure:
    """The part, its diameter function and the evolution of a plan, in one figure.

    The figure of ``bayesgrasp plan --plot FILE``: (a) and (b) on top, (d) below.

    Parameters
    ----------
    report : PlanReport
    which : str, optional
        ``"bayes"`` (default) or ``"most-certain"``.

    Returns
    -------
    Figure

    Examples
    --------
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> fig = plan_figure(plan_exact(pb))
    >>> len(fig.subfigs)
    2
    """
    if which not in ("bayes", "most-certain"):
        raise PlanningError(f"`which` must be 'bayes' or 'most-certain'; got {which!r}")
    option = report.bayes_plan if which == "bayes" else report.most_certain_plan
    pb = report.problem
    n = option.n_actions + 1
    fig = _figure(13.0, 4.8 + 1.7 * n)
    subs = cast("Sequence[SubFigure]", fig.subfigures(2, 1, height_ratios=[4.8, 1.7 * n]))
    top, bottom = subs[0], subs[1]
    ax_part, ax_d = top.subplots(1, 2, width_ratios=[1.0, 1.5])
    _draw_part(ax_part, pb.part, 0.0)
    _draw_diameter(ax_d, pb, option.first_angle)
    _draw_evolution(bottom, pb, option, _LABELS[which])
    return fig


@dataclass(frozen=True, eq=False)
class PlanAnimation:
    """A plan executed kinematically from several initial orientations.

    Attributes
    ----------
    figure : Figure
    draw : callable
        ``draw(frame)`` updates the figure to frame ``frame`` (0 to ``n_frames - 1``);
        :func:`save_animation` runs it for every frame.
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
    """

    figure: Figure
    draw: Callable[[int], Any]
    initial: FloatArray
    orientation: FloatArray
    gap: FloatArray
    step_frames: tuple[range, ...]
    final: FloatArray

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return len(self.orientation)


def _wrap_pi(x: FloatArray) -> FloatArray:
    out: FloatArray = np.mod(x + math.pi, TWO_PI) - math.pi
    return out


def _kinematics(
    problem: Problem, steps: Sequence[PlanStep], initial: FloatArray, frames: int
) -> tuple[FloatArray, FloatArray, tuple[range, ...], list[str]]:
    """Orientation and jaw gap per frame: turn the gripper, close, turn the part, open.

    During the squeeze the orientation moves from ``theta`` to the model's final orientation
    ``F(theta)`` linearly (the part descends the diameter function, so the jaws, always
    touching, close monotonically); the jaws then open at the new orientation.
    """
    d = diameter_function(problem.part.hull)
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
        verb = "squeeze" if step.kind == "squeeze" else step.kind
        target = theta - step.alpha
        for u in np.linspace(0.0, 1.0, n_turn):
            rows_th.append(theta + u * (target - theta))
            rows_gap.append(np.full_like(theta, open_gap))
            phases.append(f"{verb} {k + 1}: gripper turns {math.degrees(step.alpha):+.1f}°")
        theta = target
        width = d(theta)
        for u in np.linspace(0.0, 1.0, n_close + 1)[1:]:
            rows_th.append(theta.copy())
            rows_gap.append(open_gap + u * (width - open_gap))
            phases.append(f"{verb} {k + 1}: jaws close")
        final = problem.transfers[step.kind](theta)  # [0, 2 pi)
        end = theta + _wrap_pi(final - theta)
        for u in np.linspace(0.0, 1.0, n_act + 1)[1:]:
            th = theta + u * (end - theta)
            rows_th.append(th)
            rows_gap.append(d(th))
            phases.append(f"{verb} {k + 1}: the part turns")
        theta = end
        width = d(theta)
        for u in np.linspace(0.0, 1.0, n_open + 1)[1:]:
            rows_th.append(theta.copy())
            rows_gap.append(width + u * (open_gap - width))
            phases.append(f"{verb} {k + 1}: jaws open")
        spans.append(range(begin, len(rows_th)))
    for _ in range(max(2, frames // 3)):  # a pause on the result
        rows_th.append(theta.copy())
        rows_gap.append(np.full_like(theta, open_gap))
        phases.append("done")
    return np.array(rows_th), np.array(rows_gap), tuple(spans), phases


def plan_animation(
    problem: Problem,
    option: PlanOption,
    initial: ArrayLike | None = None,
    frames_per_step: int = 24,
    label: str = "chosen",
) -> PlanAnimation:
    """(e) Animate a plan from several initial orientations: jaws closing, the part turning.

    Each panel starts from one initial world orientation; for each step the gripper turns,
    the jaws close to the part's width, the part turns from its orientation to the one the
    transfer function predicts (linearly, the jaws following the diameter function) and the
    jaws open. The part is drawn in the gripper frame.

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

    Returns
    -------
    PlanAnimation

    Examples
    --------
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> opt = plan_exact(pb).bayes_plan
    >>> anim = plan_animation(pb, opt, frames_per_step=8)
    >>> len(anim.step_frames) == opt.n_actions
    True
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
    orient, gap, spans, phases = _kinematics(problem, steps, start, frames_per_step)
    final = execute_plan(problem, steps, start)

    part = problem.part
    m = len(start)
    fig = _figure(2.6 * m + 0.4, 3.3)
    fig.set_dpi(72)  # GIF frames: small files, quick to draw
    axes = fig.subplots(1, m, squeeze=False)[0]
    d = diameter_function(part.hull)
    reach = 0.5 * 1.25 * d.diameter
    jaw = 0.12 * d.diameter
    patches = []
    jaws = []
    texts = []
    for j, ax in enumerate(axes):
        placed = _place(part, float(orient[0, j]))
        patch = _part_patch(placed, facecolor=PART_COLOR, edgecolor="#1f3b5c", lw=1.0)
        ax.add_patch(patch)
        left = Rectangle((0, -0.7 * d.diameter), jaw, 1.4 * d.diameter, color=JAW_COLOR)
        right = Rectangle((0, -0.7 * d.diameter), jaw, 1.4 * d.diameter, color=JAW_COLOR)
        ax.add_patch(left)
        ax.add_patch(right)
        patches.append(patch)
        jaws.append((left, right))
        texts.append(ax.text(0.5, 0.02, "", transform=ax.transAxes, ha="center", fontsize=8))
        ax.set_xlim(-reach - jaw * 1.2, reach + jaw * 1.2)
        ax.set_ylim(-0.75 * d.diameter, 0.75 * d.diameter)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(
            f"start {math.degrees(start[j]) % 360:.0f}° → end {math.degrees(final[j]):.0f}°",
            fontsize=9,
        )
    title = fig.suptitle("")

    def update(frame: int) -> list[Any]:
        from matplotlib.path import Path as MplPath

        for j in range(m):
            placed = _place(part, float(orient[frame, j]))
            rings = [placed.outline] + [h[::-1] for h in placed.holes]
            verts = np.concatenate([np.vstack([r, r[:1]]) for r in rings])
            patches[j].set_path(MplPath(verts, patches[j].get_path().codes))
            half = gap[frame, j] / 2.0
            jaws[j][0].set_x(-half - jaw)
            jaws[j][1].set_x(half)
            texts[j].set_text(f"θ = {round(math.degrees(orient[frame, j]), 1) % 360:5.1f}°")
        title.set_text(f"{part.name}, {label} plan: {phases[frame]}")
        return [*patches, *(r for pair in jaws for r in pair), *texts, title]

    update(0)
    fig.canvas.draw()  # lay the panels out once; re-running the layout on every frame is slow
    fig.set_layout_engine("none")
    return PlanAnimation(fig, update, start, orient, gap, spans, final)


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
    for k in range(anim.n_frames):  # one draw per frame, straight from the Agg buffer
        anim.draw(k)
        anim.figure.canvas.draw()
        rgba = np.asarray(anim.figure.canvas.buffer_rgba())  # type: ignore[attr-defined]
        frames.append(Image.fromarray(rgba[..., :3]).convert("P", palette=Image.Palette.ADAPTIVE))
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


def write_figures(
    problem: Problem,
    option: PlanOption,
    out_dir: str | Path,
    label: str = "chosen",
    formats: Sequence[str] = ("png", "svg"),
    push_grasp: bool = False,
    animation: bool = True,
    frames_per_step: int = 24,
) -> list[Path]:
    """Write figures (a) to (d) in each format, and the animation (e), into a folder.

    Files: ``part``, ``diameter``, ``transfer`` and ``plan`` with each extension, and
    ``plan.gif`` (``plan.mp4`` when ffmpeg is present).

    Returns
    -------
    list of Path
        The files written, in order.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {
        "part": part_figure(problem.part),
        "diameter": diameter_figure(problem, option.first_angle),
        "transfer": transfer_figure(problem, push_grasp=push_grasp),
        "plan": evolution_figure(problem, option, label),
    }
    written: list[Path] = []
    for name, fig in figures.items():
        for fmt in formats:
            target = out / f"{name}.{fmt}"
            fig.savefig(target, dpi=110, metadata=_metadata(fmt))
            written.append(target)
    if animation:
        anim = plan_animation(problem, option, frames_per_step=frames_per_step, label=label)
        written += save_animation(anim, out / "plan.gif")
    return written


def _metadata(fmt: str) -> dict[str, Any] | None:
    """Metadata without dates or versions, so regenerated files only change with content."""
    if fmt == "png":
        return {"Software": None}
    if fmt == "svg":
        return {"Date": None, "Creator": None}
    if fmt == "pdf":
        return {"CreationDate": None, "Producer": None, "Creator": None}
    return None
