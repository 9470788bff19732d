"""Figure (d) and the plan figure: how a plan moves the distribution over orientations.

Both take what the planners return (a :class:`~bayesgrasp.planning.PlanOption` and its
problem, or a plan report) and read every number from the problem: the prior, the states,
the transfer function of each step's action (:func:`~bayesgrasp.planning.execute_plan`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption, PlanReport, PlanStep, execute_plan
from .canvas import BAR_COLOR, GOAL_COLOR, degree_axis, new_figure
from .functions import draw_diameter
from .part import draw_part

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

    from ..model.noise import NoiseModel
    from ..planning.noisy import NoisyPlanResult

__all__ = [
    "chosen_option",
    "draw_evolution",
    "draw_probability_labels",
    "evolution_figure",
    "label_levels",
    "noise_note",
    "noisy_plan_figure",
    "plan_figure",
    "step_distributions",
    "step_title",
]

FloatArray = NDArray[np.float64]

#: Font size (points) and padding of the probability labels above the stems.
LABEL_POINTS = 6.94
LABEL_LIFT = 4.0
#: Probabilities below this get a stem but no label (a noisy plan spreads over every state).
LABEL_BELOW = 0.005


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
    >>> from bayesgrasp.geometry import Part
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


def step_title(problem: Problem, step: PlanStep, k: int) -> str:
    """``after step 2: push-grasp (gripper turned α = +45.0°)``, from the step's action."""
    name = problem.action(step.kind).name
    if k == 0:
        return f"after step 1: {name} (gripper at {math.degrees(step.alpha):.1f}°)"
    return f"after step {k + 1}: {name} (gripper turned α = {math.degrees(step.alpha):+.1f}°)"


def label_levels(
    x_pt: FloatArray, y_pt: FloatArray, widths: FloatArray, height: float
) -> NDArray[np.intp]:
    """How many label heights to raise each label so that no two overlap (greedy).

    Label ``i`` is a box ``widths[i]`` wide and ``height`` high centred on ``x_pt[i]``, its
    bottom at ``y_pt[i]`` (all in points). Labels are placed from left to right, each at the
    lowest level where its box meets none placed before.

    Examples
    --------
    >>> label_levels(np.array([0.0, 5.0, 50.0]), np.zeros(3), np.full(3, 20.0), 8.0).tolist()
    [0, 1, 0]
    """
    order = np.argsort(x_pt, kind="stable")
    placed: list[tuple[float, float, float, float]] = []
    levels = np.zeros(len(x_pt), dtype=np.intp)
    for i in order:
        x0, x1 = x_pt[i] - widths[i] / 2.0, x_pt[i] + widths[i] / 2.0
        level = 0
        while True:
            y0 = y_pt[i] + level * height
            y1 = y0 + height
            if not any(x0 < b1 and b0 < x1 and y0 < c1 and c0 < y1 for b0, b1, c0, c1 in placed):
                break
            level += 1
        levels[i] = level
        placed.append((x0, x1, y0, y1))
    return levels


def draw_probability_labels(
    ax: Axes, x_deg: FloatArray, probs: FloatArray, xlim: tuple[float, float], ylim: float
) -> None:
    """Probability labels above the stems, raised where they would overlap."""
    texts = [f"{p:.2f}" for p in probs]
    box = ax.get_window_extent()  # before layout: close enough to space the labels
    dpi = float(ax.figure.dpi)
    width_pt, height_pt = box.width / dpi * 72.0, box.height / dpi * 72.0
    x_pt = (x_deg - xlim[0]) / (xlim[1] - xlim[0]) * width_pt
    y_pt = probs / ylim * height_pt + LABEL_LIFT
    widths = np.array([0.62 * LABEL_POINTS * len(t) + 3.0 for t in texts])
    levels = label_levels(x_pt, y_pt, widths, 1.25 * LABEL_POINTS)
    for x, p, text, level in zip(x_deg, probs, texts, levels, strict=True):
        ax.annotate(
            text,
            (x, p),
            textcoords="offset points",
            xytext=(0, LABEL_LIFT + level * 1.25 * LABEL_POINTS),
            ha="center",
            fontsize=LABEL_POINTS,
            bbox={"boxstyle": "square,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8},
            gid="probability",
        )


def draw_evolution(
    fig: Figure | SubFigure,
    problem: Problem,
    option: PlanOption,
    label: str,
    distributions: Sequence[FloatArray] | None = None,
    note: str | None = None,
) -> list[Axes]:
    """Panels (d): the prior, then the distribution after each step.

    ``distributions``: the (K,) distribution over the states after each step, in place of
    the noise-free ones (:func:`step_distributions`), for example under a noise model;
    ``note`` is then added to the title (what they are). States of probability below
    :data:`LABEL_BELOW` get a stem but no label.
    """
    n = option.n_actions + 1
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    margin = 6.0  # degrees each side: a stem or the goal at 0 shows whole
    xlim = (-margin, 360.0 + margin)
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
    top = 1.22
    if distributions is None:
        dists = step_distributions(problem, option.steps)
    else:
        stable = problem.states.stable
        dists = [(stable[q > 0], np.asarray(q)[q > 0]) for q in distributions]
    for k, (where, probs) in enumerate(dists):
        ax = axes[k + 1]
        ax.vlines(np.degrees(where), 0, probs, colors=BAR_COLOR, lw=3, gid="distribution")
        ax.plot(np.degrees(where), probs, "o", color=BAR_COLOR, ms=4)
        ax.set_ylim(0, top)
        degree_axis(ax, "x", 360.0, margin=margin)
        shown = probs >= LABEL_BELOW
        draw_probability_labels(ax, np.degrees(where[shown]), probs[shown], xlim, top)
        ax.set_title(step_title(problem, option.steps[k], k), fontsize="medium")
    last = axes[-1]
    goal = math.degrees(option.final_orientation)
    # Above the stems (dashed, so the stem at the goal still shows through).
    last.axvline(
        goal, color=GOAL_COLOR, ls="--", lw=1.4, zorder=3, label=f"goal {goal:.1f}°", gid="goal"
    )
    group = problem.goal_group
    if group > 1:
        copies = (goal + 360.0 * np.arange(1, group) / group) % 360.0
        for j, c in enumerate(copies):
            last.axvline(
                c,
                color=GOAL_COLOR,
                ls=":",
                lw=1.2,
                zorder=3,
                gid="goal-copies",
                label="its symmetric copies" if j == 0 else None,
            )
    last.legend(loc="best", fontsize="small")
    degree_axis(last, "x", 360.0, margin=margin)
    last.set_xlabel("orientation of the part in the gripper frame (deg)")
    for ax in axes:
        ax.set_ylabel("P")
    fig.suptitle(
        f"{problem.part.name}: the {label} plan, {option.n_actions} action(s): "
        f"P(success) = {option.success_probability:.3f}, "
        f"E[cost] = {option.expected_cost:.3g}" + ("" if note is None else f"\n{note}")
    )
    return list(axes)


def evolution_figure(
    problem: Problem,
    option: PlanOption,
    label: str = "chosen",
    distributions: Sequence[FloatArray] | None = None,
    note: str | None = None,
) -> Figure:
    """(d) The distribution over orientations before and after each step of a plan (Fig. 1).

    One panel per step, below the prior: stems at the stable orientations (degrees, in the
    gripper frame of that step) with their probabilities. The last panel marks the plan's
    goal orientation (and, for a symmetry goal, its symmetric copies).

    Parameters
    ----------
    problem : Problem
    option : PlanOption
        The plan (for example ``report.bayes_plan``).
    label : str, optional
        How the title names the plan ("Bayes", "most certain", ...).
    distributions, note : optional
        The distributions after each step to draw instead of the noise-free ones, and what
        they are, added to the title (see :func:`draw_evolution`); under a noise model
        :func:`~bayesgrasp.planning.noisy.step_distributions_noisy` and
        :func:`noise_note`, as the bottom half of :func:`noisy_plan_figure` draws them.

    Returns
    -------
    Figure

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> rep = plan_exact(pb)
    >>> fig = evolution_figure(pb, rep.bayes_plan, "Bayes")
    >>> len(fig.axes) == rep.bayes_plan.n_actions + 1
    True
    """
    fig = new_figure(8.0, 1.9 * (option.n_actions + 1) + 0.6)
    draw_evolution(fig, problem, option, label, distributions, note)
    return fig


def noise_note(noise: NoiseModel, payoff: bool = False) -> str:
    """What the distributions of a plan drawn under ``noise`` are: the title's second line.

    ``payoff``: the plan's expected cost is per unit payoff (a payoff was given).

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.model.noise import NoiseModel, TurnNoise
    >>> noise_note(NoiseModel(TurnNoise("normal", math.radians(2))), payoff=True)
    'the distributions below: exact under turn error normal:2 deg; E[cost] per unit payoff'
    """
    note = f"the distributions below: exact under {noise.describe()}"
    return note + ("; E[cost] per unit payoff" if payoff else "")


PLAN_LABELS = {"bayes": "Bayes", "most-certain": "most certain", "guaranteed": "guaranteed"}


def chosen_option(report: PlanReport | Any, which: str) -> PlanOption:
    """The Bayes or the most certain plan of a report (a result without a plan: an error)."""
    if which not in ("bayes", "most-certain"):
        raise PlanningError(f"`which` must be 'bayes' or 'most-certain'; got {which!r}")
    if getattr(report, "status", "ok") != "ok":
        reason = getattr(report, "reason", None) or "no plan reached the goal"
        raise PlanningError(f"there is no plan to draw: {reason}")
    option = report.bayes_plan if which == "bayes" else report.most_certain_plan
    return cast("PlanOption", option)


def plan_figure(
    report: PlanReport,
    which: str = "bayes",
    distributions: Sequence[FloatArray] | None = None,
    note: str | None = None,
) -> Figure:
    """The part, its diameter function and the evolution of a plan, in one figure.

    The figure of ``bayesgrasp plan --plot FILE``: (a) and (b) on top, (d) below.

    Parameters
    ----------
    report : PlanReport
        What a planner returned (its problem and its plans).
    which : str, optional
        ``"bayes"`` (default) or ``"most-certain"``.
    distributions, note : optional
        The distributions after each step to draw instead of the noise-free ones, and what
        they are (see :func:`draw_evolution`; :func:`noisy_plan_figure`).

    Returns
    -------
    Figure

    Raises
    ------
    PlanningError
        If ``which`` is neither, or the result holds no plan.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> fig = plan_figure(plan_exact(pb))
    >>> len(fig.subfigs)
    2
    """
    option = chosen_option(report, which)
    pb = report.problem
    n = option.n_actions + 1
    fig = new_figure(13.0, 5.4 + 1.7 * n)
    subs = cast("Sequence[SubFigure]", fig.subfigures(2, 1, height_ratios=[5.4, 1.7 * n]))
    top, bottom = subs[0], subs[1]
    ax_part, ax_d = top.subplots(1, 2, width_ratios=[1.0, 1.5])
    draw_part(ax_part, pb, 0.0)
    draw_diameter(ax_d, pb, option.first_angle, option.steps[0].kind)
    draw_evolution(bottom, pb, option, PLAN_LABELS[which], distributions, note)
    return fig


def noisy_plan_figure(result: NoisyPlanResult, which: str = "bayes") -> Figure:
    """The plan figure of a noise-aware plan: its distributions under the noise.

    As :func:`plan_figure`, but each panel of (d) draws the exact distribution over the
    stable orientations after that step under the result's noise model
    (:func:`~bayesgrasp.planning.noisy.step_distributions_noisy`), the title the plan's
    success probability and cost under the noise, and the noise model.

    Parameters
    ----------
    result : NoisyPlanResult
        What :func:`~bayesgrasp.planning.noisy.plan_noisy` returned.
    which : str, optional
        ``"bayes"`` (default) or ``"most-certain"``.

    Returns
    -------
    Figure

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model.noise import NoiseModel, TurnNoise
    >>> from bayesgrasp.planning.noisy import plan_noisy
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> res = plan_noisy(pb, NoiseModel(TurnNoise("normal", math.radians(5))))
    >>> fig = noisy_plan_figure(res)
    >>> "exact under turn error normal:5 deg" in fig.subfigs[1].get_suptitle()
    True
    """
    from ..planning.noisy import step_distributions_noisy

    report = result.plan_result()
    option = chosen_option(report, which)
    qs = step_distributions_noisy(result.problem, result.noise, option.steps)
    return plan_figure(report, which, qs, noise_note(result.noise, result.payoff is not None))
