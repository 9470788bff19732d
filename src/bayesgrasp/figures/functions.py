"""Figures (b) and (c): the diameter function and the transfer functions of the actions.

Both read the model the problem holds (its diameter function, its squeeze function and the
transfer function of each of its actions); nothing here rebuilds them.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, circle_distance
from ..geometry.curved import CurvedDiameter
from ..geometry.diameter import DiameterFunction
from ..geometry.polygon import Part
from ..geometry.transfer import TransferFunction
from ..model.actions import PUSH_GRASP, SQUEEZE, Action
from ..model.problem import Problem
from .canvas import BAR_COLOR, GOAL_COLOR, HULL_COLOR, as_problem, degree_axis, new_figure, units

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "diameter_figure",
    "diameter_samples",
    "draw_diameter",
    "draw_transfer",
    "first_action_histogram",
    "nearest_state_mod_pi",
    "stable_marks",
    "step_pieces",
    "transfer_figure",
    "transfer_functions",
]

FloatArray = NDArray[np.float64]


def nearest_state_mod_pi(minima: FloatArray, stable: FloatArray) -> NDArray[np.intp]:
    """Index of the minimum (over ``[0, pi)``) nearest to each stable orientation mod pi.

    Distance mod pi is half the circle distance of the doubled angles.

    Examples
    --------
    >>> nearest_state_mod_pi(np.radians([0.0, 90.0]), np.radians([1.0, 92.0, 181.0])).tolist()
    [0, 1, 0]
    """
    dist = circle_distance(2.0 * stable[:, None], 2.0 * minima[None, :])  # (K, M)
    return np.asarray(np.argmin(dist, axis=1), dtype=np.intp)


def first_action_histogram(
    problem: Problem, first_angle: float, action: str | Action = SQUEEZE.name
) -> tuple[FloatArray, FloatArray]:
    """Stable orientations mod pi (degrees) and the probability of each after the first action.

    A squeeze cannot tell ``theta`` from ``theta + pi``; the histogram over ``[0, 180)``
    adds the masses of both.
    """
    d = problem.diameter
    probs = problem.state_distribution(first_angle, action)  # (K,) over [0, 2 pi)
    idx = nearest_state_mod_pi(d.minima, problem.states.stable)
    heights = np.bincount(idx, weights=probs, minlength=len(d.minima)).astype(np.float64)
    return np.degrees(d.minima), heights


def diameter_samples(
    d: DiameterFunction | CurvedDiameter, n: int = 1441
) -> tuple[FloatArray, FloatArray]:
    """Angles over [0, pi] (the breakpoints and extrema included) and ``d`` at them."""
    th = np.unique(
        np.concatenate([np.linspace(0.0, math.pi, n), d.breaks, d.minima, d.maxima, [math.pi]])
    )
    return th, d(th)


def draw_diameter(
    ax: Axes, problem: Problem, first_angle: float, action: str | Action = SQUEEZE.name
) -> None:
    """Panel (b): the diameter function, its extrema, and the first action's histogram."""
    part = problem.part
    first = problem.action(action)
    d = problem.diameter
    th, dv = diameter_samples(d)
    ax.plot(np.degrees(th), dv, color="k", lw=1.5, label="diameter d(θ)", gid="diameter")
    ax.plot(
        np.degrees(d.minima),
        d(d.minima),
        "o",
        color=GOAL_COLOR,
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
    degree_axis(ax, "x", 180.0, margin=3.0)  # a minimum at 0 shows whole
    ax.set_xlabel("orientation θ of the part (deg)")
    ax.set_ylabel(f"jaw separation d(θ){units(part)}")
    lo = float(dv.min())
    ax.set_ylim(lo - 0.35 * (float(dv.max()) - lo) - 1e-12, float(dv.max()) * 1.02 + 1e-12)
    twin = ax.twinx()
    x, heights = first_action_histogram(problem, first_angle, first)
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
        label=f"P(after the first {first.name})",
        gid="histogram",
    )
    twin.set_ylim(0, 1)
    twin.set_ylabel(f"probability after the first {first.name}\n(θ and θ + 180° together)")
    handles, labels = ax.get_legend_handles_labels()
    more, more_labels = twin.get_legend_handles_labels()
    # Below the axes: inside, the legend hid histogram bars and extrema.
    ax.legend(
        handles + more,
        labels + more_labels,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.14),
        ncols=2,
        fontsize="small",
        frameon=False,
    )
    ax.set_title(f"{part.name}: diameter function and the distribution after one {first.name}")


def diameter_figure(
    problem: Problem | Part, first_angle: float = 0.0, first_action: str | Action = SQUEEZE.name
) -> Figure:
    """(b) The diameter function over ``[0, 180)`` degrees, and the first action (Fig. 3).

    Minima (stable orientations) and maxima (unstable equilibria) are marked; the dotted
    histogram is the probability of each stable orientation after a first action (a squeeze
    by default) made at gripper angle ``first_angle`` under the problem's prior
    (orientations ``theta`` and ``theta + 180`` degrees added together, as a squeeze cannot
    tell them apart).

    Parameters
    ----------
    problem : Problem or Part
        A part is built into a problem with a uniform prior.
    first_angle : float, optional
        World gripper angle of the first action (radians).
    first_action : str or Action, optional
        The first action of the plan (one of the problem's actions); default a squeeze.

    Returns
    -------
    Figure

    Examples
    --------
    >>> fig = diameter_figure(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> [ln for ln in fig.axes[0].lines if ln.get_gid() == "minima"][0].get_xdata().tolist()
    [0.0, 90.0]
    """
    fig = new_figure(7.5, 5.0)
    draw_diameter(fig.add_subplot(), as_problem(problem), first_angle, first_action)
    return fig


def step_pieces(f: TransferFunction) -> tuple[FloatArray, FloatArray, FloatArray]:
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


def stable_marks(f: TransferFunction) -> tuple[FloatArray, FloatArray]:
    """Where to mark each stable orientation: on its own step, nearest the identity (degrees).

    For a squeeze a stable orientation lies in its basin, so the mark is the fixed point
    ``(s, s)``. A push-grasp's stable orientation is where the squeeze after the push ends,
    which need not lie in the push-grasp's basin: the mark then sits at the end of the step
    nearest ``s`` (a little inside, off the basin edge), so that it shows where that step
    goes rather than floating on the identity beside another step.

    Returns
    -------
    x, y : ndarray of shape (K,)
        Degrees over ``[0, 360)``; ``y`` is ``f.stable``.
    """
    xs = np.empty(f.n_states)
    for i, (s, lo, hi) in enumerate(zip(f.stable, f.basin_lo, f.basin_hi, strict=True)):
        inset = min(0.02 * (hi - lo), math.radians(1.0))
        best = math.inf
        for shift in (-TWO_PI, 0.0, TWO_PI):
            x = min(max(s, lo + shift + inset), hi + shift - inset)
            if lo + shift <= s <= hi + shift:
                x = s
            if abs(x - s) < best:
                best, xs[i] = abs(x - s), x
    return np.degrees(np.mod(xs, TWO_PI)), np.degrees(f.stable)


def draw_transfer(ax: Axes, f: TransferFunction, name: str, action: Action) -> None:
    """Panel (c): the transfer function of one action as steps over [0, 360) degrees."""
    ys, x0, x1 = step_pieces(f)
    symbol = f"{action.tag}(θ)"
    ax.hlines(ys, x0, x1, colors="k", lw=2.0, label=f"{action.name} function {symbol}", gid="steps")
    ax.plot([0, 360], [0, 360], ":", color="0.6", lw=1, label="identity", gid="identity")
    mx, my = stable_marks(f)
    ax.plot(mx, my, "o", color=GOAL_COLOR, ms=6, label="stable orientations", gid="stable")
    for k, b in enumerate(np.degrees(f.boundaries)):
        ax.axvline(
            b,
            color=HULL_COLOR,
            lw=0.8,
            ls="--",
            gid="boundaries",
            label="unstable (basin edges)" if k == 0 else None,
        )
    degree_axis(ax, "x", 360.0, margin=6.0)  # the step at 0 shows whole
    degree_axis(ax, "y", 360.0, margin=6.0)
    ax.set_aspect("equal")
    ax.set_xlabel("orientation before the action θ (deg)")
    ax.set_ylabel("orientation after (deg)")
    ax.set_title(
        f"{name}: {action.name} function "
        f"({len(np.unique(f.stable))} stable, period {math.degrees(f.period):.4g}°)"
    )
    ax.legend(loc="upper left", fontsize="small")


def transfer_functions(
    problem: Problem, push_grasp: bool | None = None
) -> list[tuple[Action, TransferFunction]]:
    """The squeeze function (the states) then the transfer function of each other action.

    ``push_grasp`` is the deprecated switch of :func:`transfer_figure`.
    """
    drawn = [(SQUEEZE, problem.states)]
    drawn += [(a, problem.transfer(a)) for a in problem.actions if a.name != SQUEEZE.name]
    if push_grasp is None:
        return drawn
    has = any(a.name == PUSH_GRASP.name for a, _ in drawn)
    if push_grasp != has:
        warnings.warn(
            "`push_grasp` is deprecated: transfer_figure draws the problem's actions "
            "(Problem.build(part, actions=('squeeze', 'push-grasp')))",
            DeprecationWarning,
            stacklevel=3,
        )
    if push_grasp and not has:
        drawn.append((PUSH_GRASP, PUSH_GRASP.build(problem.part, problem.states)))
    elif not push_grasp:
        drawn = [(a, f) for a, f in drawn if a.name != PUSH_GRASP.name]
    return drawn


def transfer_figure(problem: Problem | Part, push_grasp: bool | None = None) -> Figure:
    """(c) The transfer function of every action of the problem over ``[0, 360)`` degrees.

    The squeeze function comes first (its stable orientations are the problem's states),
    then one panel for each other action of the problem (a push-grasp, ...). Each step is a
    basin: every orientation in it ends at the step's stable orientation (marked on the
    step); dashed lines are the unstable equilibria between basins.

    Parameters
    ----------
    problem : Problem or Part
        A part is built into a problem with squeezes only (and push-grasps when
        ``push_grasp`` is true).
    push_grasp : bool, optional
        Deprecated: the actions drawn are the problem's. When given and it disagrees with
        them, a :class:`DeprecationWarning` is issued and the push-grasp panel is added
        (``True``) or left out (``False``) as before.

    Returns
    -------
    Figure

    Examples
    --------
    >>> fig = transfer_figure(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> sorted(set(fig.axes[0].collections[0].get_segments()[0][:, 1].tolist()))
    [0.0]
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1)]), actions="squeeze,push-grasp")
    >>> [ax.get_title().split(":")[1].split()[0] for ax in transfer_figure(pb).axes]
    ['squeeze', 'push-grasp']
    """
    pb = as_problem(problem, (SQUEEZE.name, PUSH_GRASP.name) if push_grasp else (SQUEEZE.name,))
    drawn = transfer_functions(pb, push_grasp)
    fig = new_figure(5.2 * len(drawn), 5.4)
    for k, (action, f) in enumerate(drawn):
        draw_transfer(fig.add_subplot(1, len(drawn), k + 1), f, pb.part.name, action)
    return fig
