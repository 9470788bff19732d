"""Reports for people, and the JSON documents of squeezes, pushes and simulations.

Everything here turns library values into output; nothing is computed that the library does
not already know. JSON angles are radians (``*_rad``); tables show degrees.

- Text tables: :func:`squeeze_table`, :func:`push_table`, :func:`plan_table`,
  :func:`guaranteed_text`, :func:`simulate_table`.
- JSON documents: ``bayesgrasp.squeeze/1`` (:func:`squeeze_json`), ``bayesgrasp.push/1``
  (:func:`push_json`) and ``bayesgrasp.simulate/1`` (:func:`simulate_json`). Plan documents
  (``bayesgrasp.plan/1`` and ``plan/2``) are written and read by :mod:`bayesgrasp.io.plans`,
  as is the ``part`` object every document embeds.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from ..geometry.polygon import Part
from ..geometry.push import RadiusFunction
from ..geometry.transfer import TransferFunction
from ..io.plans import (
    guaranteed_document,
    json_float,
    option_document,
    part_document,
    plan_document,
)
from ..model.actions import ACTIONS, SQUEEZE, Action, get_action
from ..model.prior import Prior, UniformPrior

if TYPE_CHECKING:  # ``squeeze`` and ``push`` print tables without importing the planners
    from ..model.problem import Problem
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.result import PlanOption, PlanReport
    from ..sim.kinematic import SimulationResult

__all__ = [
    "guaranteed_text",
    "num",
    "plan_steps_text",
    "plan_table",
    "push_json",
    "push_table",
    "simulate_json",
    "simulate_table",
    "squeeze_json",
    "squeeze_table",
    "tagged",
    "transfer_json",
]


def num(x: float, spec: str) -> str:
    """``format(x, spec)`` without a negative zero: a value that rounds to 0 prints as 0.

    Examples
    --------
    >>> num(-1e-12, "9.3f"), num(-1e-12, "+.2f"), num(-0.0, ".4f"), num(-0.5, ".3f")
    ('    0.000', '+0.00', '0.0000', '-0.500')
    """
    text = format(x, spec)
    if text.lstrip().startswith("-") and math.isfinite(x) and float(text) == 0.0:
        return format(0.0, spec)
    return text


# The plan documents moved to bayesgrasp.io.plans; these names are kept for the transition.
part_json = part_document
option_json = option_document
plan_json = plan_document
guaranteed_json = guaranteed_document


def transfer_json(f: TransferFunction, prior: Prior) -> dict[str, Any]:
    """Stable orientations, basins, probabilities (first action at angle 0) and period."""
    probs = prior.mass(f.basin_lo, f.basin_hi)
    return {
        "stable_orientations_rad": f.stable.tolist(),
        "basins_rad": np.stack([f.basin_lo, f.basin_hi], axis=1).tolist(),
        "probabilities": np.asarray(probs).tolist(),
        "period_rad": float(f.period),
    }


def squeeze_json(part: Part, f: TransferFunction, prior: Prior | None = None) -> dict[str, Any]:
    """The ``bayesgrasp.squeeze/1`` document."""
    return {
        "schema": "bayesgrasp.squeeze/1",
        "part": part_document(part),
        **transfer_json(f, prior or UniformPrior()),
    }


def squeeze_table(part: Part, f: TransferFunction, prior: Prior | None = None) -> str:
    """A text table of stable orientations (degrees), basins and probabilities."""
    probs = np.asarray((prior or UniformPrior()).mass(f.basin_lo, f.basin_hi))
    units = f" ({part.units})" if part.units else ""
    lines = [
        f"{part.name}{units}: {part.hull.n_sides} sides, symmetry order "
        f"{part.hull.symmetry_order}, {f.kind} period {math.degrees(f.period):.4g} deg",
        f"{'state':>5}  {'stable (deg)':>12}  {'basin (deg)':>23}  {'probability':>11}",
    ]
    for i, (s, lo, hi, p) in enumerate(zip(f.stable, f.basin_lo, f.basin_hi, probs, strict=True)):
        basin = f"({num(math.degrees(lo), '9.3f')}, {num(math.degrees(hi), '9.3f')})"
        lines.append(f"{i:>5}  {num(math.degrees(s), '12.3f')}  {basin:>23}  {p:11.4f}")
    from .curved import curved_lines

    lines += curved_lines(part) if f.kind == "squeeze" else []
    return "\n".join(lines)


def guaranteed_text(g: GuaranteedPlan) -> str:
    """One paragraph: the guaranteed plan's steps, period, final orientation and tolerance.

    The steps are written as :func:`plan_table` writes a row (:func:`plan_steps_text`): the
    first gripper angle, then the turns (tagged by action when the table tags them).
    """
    o = g.option
    mixed = tagged(g.problem)
    steps = plan_steps_text(o, mixed)
    head = "steps" if mixed else "alphas"
    tol = "-" if o.tolerance is None else f"{math.degrees(o.tolerance):.3f} deg"
    return (
        f"guaranteed plan: {o.n_actions} action(s), first {num(math.degrees(o.first_angle), '.2f')}"
        f" deg, {head} (deg) {steps}\n"
        f"  sends every orientation to {num(math.degrees(o.final_orientation), '.2f')} deg modulo "
        f"{math.degrees(g.period):.4g} deg; tolerance {tol}\n"
        f"  for the goal: P(success) {o.success_probability:.4f}, "
        f"E[cost] {o.expected_cost:.3f}"
    )


def _stable_edges(radius: RadiusFunction, push: TransferFunction) -> list[int]:
    """The hull edge flat against the pushing jaw in each of the push's stable orientations."""
    gap = np.abs(np.mod(push.stable[:, None] - radius.minima[None, :] + math.pi, 2 * math.pi))
    return [int(radius.stable_edges[k]) for k in np.argmin(np.abs(gap - math.pi), axis=1)]


def push_json(
    part: Part,
    radius: RadiusFunction,
    push: TransferFunction,
    push_grasp: TransferFunction,
    prior: Prior | None = None,
) -> dict[str, Any]:
    """The ``bayesgrasp.push/1`` document: the push function and the push-grasp function."""
    pr = prior or UniformPrior()
    n = part.hull.n_sides
    edges = _stable_edges(radius, push)
    return {
        "schema": "bayesgrasp.push/1",
        "part": part_document(part),
        "center_of_mass": radius.center_of_mass.tolist(),
        **transfer_json(push, pr),
        "stable_edges": [[e, (e + 1) % n] for e in edges],
        "push_grasp": transfer_json(push_grasp, pr),
    }


def push_table(
    part: Part,
    radius: RadiusFunction,
    push: TransferFunction,
    push_grasp: TransferFunction,
    prior: Prior | None = None,
) -> str:
    """The push function's table with each stable edge, then the push-grasp function's."""
    v = part.hull.vertices
    n = part.hull.n_sides
    c = radius.center_of_mass
    edges = _stable_edges(radius, push)
    lines = [
        squeeze_table(part, push, prior),
        f"centre of mass ({c[0]:.6g}, {c[1]:.6g}); the pushing jaw is on the gripper's -x side",
        "edge flat against the pushing jaw in each stable orientation:",
    ]
    for i, e in enumerate(edges):
        a, b = v[e], v[(e + 1) % n]
        lines.append(f"{i:>5}  ({a[0]:.6g}, {a[1]:.6g}) - ({b[0]:.6g}, {b[1]:.6g})")
    lines += ["", "push-grasp (push, then squeeze):", squeeze_table(part, push_grasp, prior)]
    return "\n".join(lines)


def _tags(actions: Iterable[Action]) -> str:
    """The legend of step tags: ``S = squeeze, P = push-grasp``."""
    return ", ".join(f"{a.tag} = {a.name}" for a in actions)


def tagged(problem: Problem) -> bool:
    """Whether a problem's plans are written with each step tagged by its action.

    Plans of squeezes only are written as their turns (``[+34.59, -23.49]``); any other
    action kind tags every step (``P S+23.49``).
    """
    return len(problem.action_kinds) > 1 or problem.action_kinds != (SQUEEZE.name,)


def plan_steps_text(o: PlanOption, mixed: bool) -> str:
    """A plan's relative turns in degrees, as :func:`plan_table` writes them.

    Without ``mixed``: the turns before each further squeeze in brackets (``-`` for none);
    with it, each step's action tag (``S`` squeeze, ``P`` push-grasp) followed by its turn,
    the first step's angle left to the table's first column.
    """
    if not mixed:
        alphas = ", ".join(f"{num(math.degrees(a), '+.2f')}" for a in o.alphas)
        return f"[{alphas}]" if alphas else "-"
    first = get_action(o.steps[0].kind).tag
    rest = [f"{get_action(s.kind).tag}{num(math.degrees(s.alpha), '+.2f')}" for s in o.steps[1:]]
    return " ".join([first, *rest])


def plan_table(report: PlanReport, max_actions: int | None = None) -> str:
    """One row per plan length: angles (degrees), success probability, expected cost.

    Plans of one action kind other than the squeeze are tagged as mixed plans are (the
    ``P`` of a push-grasp). ``max_actions``: the longest plan the planner was allowed; when
    it cut the plans short of certainty, the legend says the C plan is the most certain of
    those only.
    """
    pb = report.problem
    mixed = tagged(pb)
    action = "action" if len(pb.action_kinds) > 1 else pb.action_kinds[0]
    texts = [plan_steps_text(o, mixed) for o in report.options]
    width = max(34, *(len(t) for t in texts))
    head = "steps (deg)" if mixed else "alphas (deg)"
    lines = [
        f"{pb.part.name}: {pb.part.hull.n_sides} sides, {pb.n_states} stable orientations, "
        f"prior {pb.prior.name}, goal {pb.goal.kind}, method {report.method}"
        + (f", gripper accuracy {math.degrees(pb.accuracy):g} deg" if pb.accuracy > 0 else ""),
        f"first: gripper angle of the first {action} (world frame); "
        f"alphas: gripper turn before each further {action}",
        f"(relative to the previous {action}); final: the part's orientation in the last "
        "gripper frame",
    ]
    if mixed:
        used = [a for a in ACTIONS.values() if a.name in pb.action_kinds]  # registry order
        lines.append(f"steps: {_tags(used)}, each after its gripper turn")
    lines.append(
        f"{'k':>3} {'first (deg)':>11}  {head:<{width}} {'final (deg)':>11} "
        f"{'P(success)':>10} {'E[cost]':>8} {'tol (deg)':>9}"
    )
    for i, (o, text) in enumerate(zip(report.options, texts, strict=True)):
        marks = ("B" if i == report.bayes else " ") + ("C" if i == report.most_certain else " ")
        tol = "-" if o.tolerance is None else f"{math.degrees(o.tolerance):.3f}"
        lines.append(
            f"{o.n_actions:>3} {num(math.degrees(o.first_angle), '11.2f')}  {text:<{width}} "
            f"{num(math.degrees(o.final_orientation), '11.2f')} {o.success_probability:10.4f} "
            f"{o.expected_cost:8.3f} {tol:>9} {marks}".rstrip()
        )
    sure = report.most_certain_plan.success_probability >= 1.0 - pb.part.hull.tol.probability
    if max_actions is not None and len(report.options) >= max_actions and not sure:
        what = f"the most certain of the plans of at most {max_actions} action(s) considered"
    else:
        what = "most certain plan"
    lines.append(f"B = Bayes plan (least expected cost), C = {what}")
    from .curved import shallow_warnings

    lines += shallow_warnings(pb, _finals(report))
    if report.nodes is not None:
        lines.append(f"breadth-first nodes generated: {report.nodes}")
    return "\n".join(lines)


def _finals(report: PlanReport) -> dict[str, float]:
    """The final orientations of the Bayes and the most certain plan, by label."""
    out = {"Bayes plan": report.options[report.bayes].final_orientation}
    if report.most_certain != report.bayes:
        out["most certain plan"] = report.options[report.most_certain].final_orientation
    return out


def _simulated_rows(res: SimulationResult) -> list[int]:
    """States worth a row: predicted or observed."""
    return [i for i in range(len(res.orientations)) if res.predicted[i] > 0 or res.observed[i]]


def simulate_json(res: SimulationResult, part: Part | None = None) -> dict[str, Any]:
    """The ``bayesgrasp.simulate/1`` document.

    ``observed`` per orientation is the fraction of all trials (jammed trials end in none).
    """
    from ..sim.result import verdict_document

    doc = option_document(res.option)
    plan = {k: (json_float(v) if isinstance(v, float) else v) for k, v in doc.items()}
    lo, hi = res.ci95
    out: dict[str, Any] = {
        "schema": "bayesgrasp.simulate/1",
        "engine": res.engine,
        "plan": plan,
        "trials": res.trials,
        "predicted_success": res.predicted_success,
        "observed_success": res.observed_success,
        "ci95": [lo, hi],
        "p_value": json_float(res.p_value),
        "jams": res.jams,
        "final_jams": res.final_jams,
        "near_boundary": res.near_boundary,
        "boundary_margin_rad": res.boundary_margin,
        "per_orientation": [
            {
                "orientation_rad": float(res.orientations[i]),
                "predicted": float(res.predicted[i]),
                "observed": int(res.observed[i]) / res.trials,
                "count": int(res.observed[i]),
                "goal": bool(res.goal[i]),
            }
            for i in _simulated_rows(res)
        ],
        "seconds": res.seconds,
    }
    why = res.fit_unavailable
    if why is not None:
        out["p_value_unavailable"] = why
    out.update(verdict_document(res))  # the noise, the payoff and the verdict
    if part is not None:
        out["part"] = part_document(part)
    return out


def simulate_table(res: SimulationResult, title: str = "") -> str:
    """Predicted against observed final orientations (degrees), success, jams, wall time."""
    o = res.option
    tol = "-" if o.tolerance is None else f"{math.degrees(o.tolerance):.2f} deg"
    lo, hi = res.ci95
    steps = plan_steps_text(o, len(set(o.kinds)) > 1)
    lines = [
        f"{title}{res.engine} execution, {res.trials} trials",
        f"plan: {steps} (first action at {num(math.degrees(o.first_angle), '.2f')} deg, "
        f"{o.n_actions} action(s), tolerance {tol}); "
        f"goal {num(math.degrees(o.final_orientation), '.2f')} deg",
        f"{'final (deg)':>11}  {'predicted':>9}  {'observed':>9}  {'count':>9}",
    ]
    for i in _simulated_rows(res):
        mark = "  goal" if res.goal[i] else ""
        lines.append(
            f"{num(math.degrees(res.orientations[i]), '11.2f')}  {res.predicted[i]:9.4f}  "
            f"{res.observed[i] / res.trials:9.4f}  {res.observed[i]:9d}{mark}"
        )
    rate = res.trials / res.seconds if res.seconds > 0 else math.inf
    why = res.fit_unavailable
    lines += [
        f"success: predicted {res.predicted_success:.4f}, observed {res.observed_success:.4f}, "
        f"95% interval [{lo:.4f}, {hi:.4f}]",
        "goodness of fit (chi-square over final orientations): "
        + (f"p = {res.p_value:.3g}" if why is None else f"n/a ({why})"),
        f"jams: {res.jams} ({res.final_jams} in the last action); near-boundary starts "
        f"(within {math.degrees(res.boundary_margin):.1f} deg of a basin boundary): "
        f"{res.near_boundary}",
        f"wall time {res.seconds:.2f} s ({rate:.3g} trials/s)",
    ]
    return "\n".join(lines)
