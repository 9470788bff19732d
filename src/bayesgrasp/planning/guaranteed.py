"""Guaranteed plans: the shortest plan that orients every initial orientation (Goldberg 1993).

A guaranteed plan sends every initial orientation (but the measure-zero unstable
equilibria) to one final orientation, up to the period ``T`` of the transfer functions: a
squeeze cannot tell ``theta`` from ``theta + pi`` (nor from ``theta + T`` for a symmetric
part), so the best any squeeze plan can do is to collapse the circle onto the ``2 pi / T``
orientations ``phi + j T``. Push-grasps have period ``2 pi`` for an asymmetric part; with
them the plan can orient the part uniquely. The goal's symmetry group (a ``"symmetry"``
goal) can only make ``T`` smaller: ``T = min(largest period of the action types,
2 pi / group)``.

Backchaining (Goldberg 1993, section 4): every transfer function commutes with a shift by
``T``, so collapsing one open arc of length ``T`` collapses its copies too, hence the whole
circle up to ``T``. Let ``W_k`` be the widest arc collapsible by ``k`` actions. An arc
``(B_i, B_j)`` between two basin boundaries of the first action's transfer function ``F``
goes to the stable orientations ``S_{i+1} .. S_j``; the remaining actions collapse them iff
their span is strictly less than the arc the remaining actions can collapse. So ``W_1`` is
the widest basin and ``W_{k+1}`` the widest boundary-to-boundary arc of any action type
whose stable orientations span less than ``W_k``; the guaranteed plan has the least ``k``
with ``W_k >= T``. Goldberg proved it exists for every polygon (the widths grow strictly
until they reach ``T``); Chen and Ierardi bounded its length by ``2 n - 1`` for an n-gon.

With several action types and costs, plans with the same number of actions may differ in
cost; the plan returned is the cheapest of the shortest (the width of an arc collapsible
with given counts of each type does not depend on their order after the first action, the
argument of :mod:`bayesgrasp.planning.arcs`).

This is the exact planner's machinery (:mod:`bayesgrasp.planning.arcs`) run to a different
stop: the widths ``W_k`` come from the arc fronts (the widest arc under a span limit is a
binary search on the front of each action type), and the plan's angles from the witness
chain, the arcs that maximise the least margin; each image is centred in the next witness,
so each turn after the first may err by the plan's tolerance, the largest of any plan with
these action types in this order that collapses an arc this wide. Among equally cheap
shortest plans the one of largest tolerance is returned.

With a gripper accuracy (``Problem.accuracy``) every image must fit the next arc with that
margin to spare on each side, as in the exact planner; the widths may then stop growing
short of the period, and no guaranteed plan exists: the result has status ``"no-plan"``
and says why, as soon as the widths stop growing.

Cost: O(K^2) once per action type for its front (K stable orientations), O(log K) per
(count of each type, first type), and O(F log F) per action for the witnesses (F arcs on a
front). Sharing the code, the lengths agree with the exact planner's by construction; the
tests check them against a search over sets of states, and the plans (tolerance included)
by executing them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..model.problem import Problem
from .arcs import Arc, ArcPlanner, chain_option, widest_arc
from .result import PlanOption, PlanResult, check_max_actions, max_plan_length

__all__ = ["GuaranteedPlan", "plan_guaranteed", "widest_arc"]


@dataclass(frozen=True, slots=True, eq=False, kw_only=True)
class GuaranteedPlan(PlanResult):
    """The guaranteed planner's result: the shortest plan that orients every orientation.

    A :class:`~bayesgrasp.planning.result.PlanResult` whose ``options`` hold the one plan
    (``bayes`` and ``most_certain`` are both 0), or none when ``status`` is ``"no-plan"``
    (``reason`` says why), with what the guaranteed planner adds.

    Attributes
    ----------
    period : float
        The plan sends every orientation to ``final_orientation + j * period``.
    widths : tuple of float
        ``W_1 .. W_k``: the widest collapsible arc with 1 .. k actions (with no plan, up to
        where the search stopped).
    """

    period: float
    widths: tuple[float, ...]

    @property
    def option(self) -> PlanOption:
        """The plan (``options[0]``).

        Its steps, final orientation, tolerance, and (for the problem's single or symmetry
        goal and prior) success probability and expected cost.

        Raises
        ------
        NoPlanError
            If ``status`` is ``"no-plan"`` (the message is the ``reason``).
        """
        return self.bayes_plan

    @property
    def n_actions(self) -> int:
        """Number of actions of the plan (raises :class:`NoPlanError` if there is none)."""
        return self.option.n_actions


def plan_guaranteed(problem: Problem, max_actions: int | None = None) -> GuaranteedPlan:
    """The shortest plan (then the cheapest) that orients the part up to the period.

    Uses the problem's action types, cost model (to break ties between plans of the same
    length), goal (its symmetry group may shorten the period) and prior (only to place the
    first action and report the success probability of the single goal). The first action
    may be made at any gripper angle: the plan is guaranteed from every orientation.

    Parameters
    ----------
    problem : Problem
    max_actions : int, optional
        Look no further than plans of this many actions (default ``4 n + 8`` for an n-gon,
        :func:`~bayesgrasp.planning.result.max_plan_length`; Goldberg 1993 bounds plans by
        O(n)).

    Returns
    -------
    GuaranteedPlan
        Status ``"ok"`` with the plan, or ``"no-plan"`` with the reason: the widest
        collapsible arc stops growing short of the period (no plan honours the problem's
        gripper accuracy; without one, Goldberg 1993 proves a plan exists), or no plan
        within ``max_actions``.

    Raises
    ------
    PlanningError
        If ``max_actions`` is less than 1.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)])
    >>> g = plan_guaranteed(Problem.build(rect))
    >>> g.status, g.n_actions, round(math.degrees(g.period), 6), g.option.success_probability
    ('ok', 2, 180.0, 0.5)

    With turns that err by up to 30 degrees the widths stop short of the period:

    >>> g = plan_guaranteed(Problem.build(rect, accuracy=math.radians(30)))
    >>> g.status, g.reason.split(":")[0]
    ('no-plan', "no guaranteed plan for part 'part' with gripper accuracy 30 deg")
    """
    check_max_actions(max_actions)
    planner = ArcPlanner.for_problem(problem)
    tol, period = planner.tol, planner.period
    # An arc reaches the period to the angle tolerance only. (The symmetry tolerance is a
    # length relative to the part's size, not an angle: taken as one it accepted arcs 1e-5
    # rad short, whose plans leave a sliver of starts off the goal.) A part symmetric
    # within its symmetry tolerance is exactly symmetric here, its period exact.
    reach = period - tol
    limit = max_plan_length(problem) if max_actions is None else max_actions
    widths: list[float] = []
    level = [(0,) * len(problem.action_kinds)]

    def result(option: PlanOption | None, reason: str | None = None) -> GuaranteedPlan:
        return GuaranteedPlan(
            problem,
            () if option is None else (option,),
            0,
            0,
            "guaranteed",
            status="no-plan" if option is None else "ok",
            reason=reason,
            period=period,
            widths=tuple(widths),
        )

    for _ in range(limit):
        candidates, level = planner.extend(level)
        widths.append(max(planner.best[key][0] for key in level))
        found: list[tuple[float, float, list[Arc], float | None, float]] = []
        for key, first, width in candidates:
            if width >= reach:
                kinds = planner.order(key, first)
                chain, margin = planner.witnesses(kinds, width)
                sure = math.inf if margin is None else margin
                found.append((problem.cost.attempt_cost(kinds), -sure, chain, margin, width))
        if found:
            _, _, chain, margin, width = min(found, key=lambda x: (x[0], x[1]))
            placed = min(width, period)
            p, _ = problem.prior.max_arc_mass(placed, problem.goal_group)
            cost = problem.cost.expected_cost(tuple(a.kind for a in chain), p)
            return result(chain_option(problem, chain, margin, placed, p, cost, placed))
        # The widest arc of k + 1 actions is a non-decreasing function of that of k (see
        # arcs.py): once it stops growing it never grows again.
        if len(widths) > 1 and widths[-1] <= widths[-2] + tol:
            return result(
                None,
                f"no guaranteed plan for part {problem.part.name!r} with gripper accuracy "
                f"{math.degrees(problem.accuracy):.6g} deg: the widest arc any plan collapses "
                f"stops at {math.degrees(max(widths)):.6f} deg, short of the period "
                f"{math.degrees(period):.6f} deg",
            )
    return result(
        None,
        f"no guaranteed plan within {limit} actions for part "
        f"{problem.part.name!r} (widest collapsible arc {math.degrees(widths[-1]):.6f} deg, "
        f"period {math.degrees(period):.6f} deg)",
    )
