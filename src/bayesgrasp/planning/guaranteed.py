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
argument of :mod:`bayesgrasp.planning.exact`).

This is the exact planner's machinery run to a different stop: the widths ``W_k`` come from
its arc fronts (the widest arc under a span limit is a binary search on the front of each
action type), and the plan's angles from its witness chain, the arcs that maximise the least
margin (see :mod:`bayesgrasp.planning.exact`); each image is centred in the next witness, so
each turn after the first may err by the plan's tolerance, the largest of any plan with
these action types in this order that collapses an arc this wide. Among equally cheap
shortest plans the one of largest tolerance is returned.

With a gripper accuracy (``Problem.accuracy``) every image must fit the next arc with that
margin to spare on each side, as in the exact planner; the widths may then stop growing
short of the period, and no guaranteed plan exists (:class:`~bayesgrasp.errors.NoPlanError`,
raised as soon as the widths stop growing).

Cost: O(K^2) once per action type for its front (K stable orientations), O(log K) per
(count of each type, first type), and O(F log F) per action for the witnesses (F arcs on a
front). Sharing the code, the lengths agree with the exact planner's by construction; the
tests check them against a search over sets of states, and the plans (tolerance included)
by executing them.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from ..errors import NoPlanError, PlanningError
from ..geometry.transfer import TransferFunction
from ..model.problem import Problem
from .exact import Arc, _arc_front, _chain_option, _Planner
from .result import PlanOption

__all__ = ["GuaranteedPlan", "plan_guaranteed", "widest_arc"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class GuaranteedPlan:
    """The shortest plan that orients every initial orientation up to ``period``.

    Attributes
    ----------
    option : PlanOption
        Its steps, final orientation, tolerance, and (for the problem's single or symmetry
        goal and prior) success probability and expected cost.
    period : float
        The plan sends every orientation to ``final_orientation + j * period``.
    widths : tuple of float
        ``W_1 .. W_k``: the widest collapsible arc with 1 .. k actions.
    """

    option: PlanOption
    period: float
    widths: tuple[float, ...]

    @property
    def n_actions(self) -> int:
        """Number of actions."""
        return self.option.n_actions


def widest_arc(f: TransferFunction, limit: float, tol: float) -> Arc:
    """Widest boundary-to-boundary arc of ``f`` whose image spans less than ``limit``.

    The last arc of the front of ``f`` under that span limit (the exact planner's
    ``_arc_front``); among the arcs as wide within ``tol`` the one of least span is returned
    (it leaves the most room to the next action). O(K^2) for K stable orientations.

    Parameters
    ----------
    f : TransferFunction
    limit : float
        The image must fit in an open arc of this length (``span < limit - 2 tol``); a
        limit at most ``2 tol`` admits a single basin (its image is one point).
    tol : float
        Angle tolerance.

    Returns
    -------
    Arc
        ``kind``, ``lo``, ``hi`` (the open arc), ``s_first``, ``s_last`` (its image), with
        ``width`` and ``span``.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> one = widest_arc(s, 0.0, 1e-9)  # a single basin
    >>> two = widest_arc(s, one.width, 1e-9)
    >>> [round(math.degrees(a.width), 6) for a in (one, two)]
    [126.869898, 180.0]
    """
    front = _arc_front(f, limit - 2.0 * tol)
    widths = front.width_list  # increasing with the span
    return front.arc(bisect.bisect_left(widths, widths[-1] - tol))


def plan_guaranteed(problem: Problem) -> GuaranteedPlan:
    """The shortest plan (then the cheapest) that orients the part up to the period.

    Uses the problem's action types, cost model (to break ties between plans of the same
    length), goal (its symmetry group may shorten the period) and prior (only to place the
    first action and report the success probability of the single goal). The first action
    may be made at any gripper angle: the plan is guaranteed from every orientation.

    Parameters
    ----------
    problem : Problem

    Returns
    -------
    GuaranteedPlan

    Raises
    ------
    NoPlanError
        If the widest collapsible arc stops growing short of the period: no plan honours the
        problem's gripper accuracy (without one, Goldberg 1993 proves a plan exists).
    PlanningError
        If no plan is found within ``4 n + 8`` actions (a degenerate part; Goldberg 1993
        bounds plans by O(n)).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)])
    >>> g = plan_guaranteed(Problem.build(rect))
    >>> g.n_actions, round(math.degrees(g.period), 6), g.option.success_probability
    (2, 180.0, 0.5)
    """
    tol = problem.states.angle_tol
    poly = problem.part.hull
    periods = [problem.transfers[t].period for t in problem.action_kinds]
    period = min(max(periods), TWO_PI / problem.goal_group)
    reach = period - max(tol, poly.tol.symmetry)
    planner = _Planner(problem, tol, max(periods) + tol)
    widths: list[float] = []
    level = [(0,) * len(problem.action_kinds)]
    for _ in range(4 * poly.n_sides + 8):
        candidates, level = planner.extend(level)
        widths.append(max(planner.best[key][0] for key in level))
        found = []
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
            option = _chain_option(problem, chain, margin, placed, p, cost, placed)
            return GuaranteedPlan(option, period, tuple(widths))
        # The widest arc of k + 1 actions is a non-decreasing function of that of k (see
        # exact.py): once it stops growing it never grows again.
        if len(widths) > 1 and widths[-1] <= widths[-2] + tol:
            raise NoPlanError(
                f"no guaranteed plan for part {problem.part.name!r} with gripper accuracy "
                f"{math.degrees(problem.accuracy):.6g} deg: the widest arc any plan collapses "
                f"stops at {math.degrees(max(widths)):.6f} deg, short of the period "
                f"{math.degrees(period):.6f} deg"
            )
    raise PlanningError(
        f"no guaranteed plan within {4 * poly.n_sides + 8} actions for part "
        f"{problem.part.name!r} (widest collapsible arc {math.degrees(widths[-1]):.6f} deg, "
        f"period {math.degrees(period):.6f} deg)"
    )
