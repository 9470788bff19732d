"""The exact Bayesian planner: backchaining arc lengths (Goldberg 1993, made Bayesian).

See design.md, "The fact that makes exact planning fast". The arc machinery (arc lengths,
fronts, witness chains and their staircases, the gripper accuracy) is
:mod:`bayesgrasp.planning.arcs`, shared with the guaranteed planner; this module runs it to
the Bayes plans.

For each number of actions ``k`` the planner extends the best counts of each action type by
one action (:meth:`~bayesgrasp.planning.arcs.ArcPlanner.extend`): the widest arc ``L`` that
each (counts, first type) collapses, the later actions in the order that gives the widest
arc. Only the type of the first action matters for cost (``CostModel.first``), and the
counts for the rest.

Success probability: the plan collapses an open arc of length ``L`` placed anywhere by the
gripper angle of the first action, so ``p = max over placements of the prior mass of that
arc`` (with a symmetry goal, of the arc and its copies ``2 pi / r`` apart). Under the uniform
prior ``p = L / (2 pi)`` (times ``r``). Expected cost is ``CostModel.expected_cost``. The
search stops at the first length whose probability reaches the largest prior mass of an arc
as long as the period (or ``2 pi / r``), which no plan can beat. With a gripper accuracy the
widths may stop growing short of the period: the highest attainable probability is then that
of the widest arc any plan collapses
(:meth:`~bayesgrasp.planning.arcs.ArcPlanner.widest_reachable`, computed before the search).

The angles of each reported plan come from its chain of witness arcs of largest least margin
(:meth:`~bayesgrasp.planning.arcs.ArcPlanner.witnesses`, turned into gripper angles by
:func:`~bayesgrasp.planning.arcs.chain_option`): its tolerance is the largest of any plan with
this success arc.

Cost: O(K^2) once per action type for the front (K stable orientations; usually far fewer
arcs survive), then O(log K) per (count, type) for the lengths and O(F log F) per action of
each reported plan for its witnesses (F arcs on the front).
"""

from __future__ import annotations

from typing import Literal

from ..errors import PlanningError
from ..model.problem import Problem
from .arcs import ArcPlanner, Counts, chain_option
from .result import COST_RTOL, PlanOption, PlanResult, choose_among, max_plan_length

__all__ = ["Report", "plan_exact"]

Report = Literal["all", "best"]
"""What :func:`plan_exact` reports: the best plan of every length, or only the Bayes and the
most certain plans."""


def plan_exact(
    problem: Problem, max_actions: int | None = None, report: Report = "all"
) -> PlanResult:
    """Best plans of every length, exactly, for any prior, cost model and goal.

    Parameters
    ----------
    problem : Problem
    max_actions : int, optional
        Stop after plans of this many actions even if more would raise the success
        probability (default: go on until the highest attainable probability).
    report : {"all", "best"}
        ``"all"``: the best plan of every length (below). ``"best"``: only the Bayes plan
        and the most certain plan (one option when they are the same), the same plans as
        in ``"all"``; the angles of the others are never computed, which for parts of
        thousands of states is most of the work (``k`` angles for each length ``k``).

    Honours the problem's gripper ``accuracy``: every plan of two or more actions has
    tolerance at least ``accuracy``, and is the best of those that do.

    Returns
    -------
    PlanResult
        ``options[k - 1]`` is the best plan of ``k`` actions: the least expected cost of
        those with ``k`` actions, except the last, the most certain one. When action types
        cost differently (squeezes and push-grasps), one more option may follow: the
        cheapest plan with at least as many actions as the most certain one, if it costs
        less than every other option (it is then the Bayes plan).

    Raises
    ------
    PlanningError
        If ``max_actions`` is less than 1, or ``report`` is neither ``"all"`` nor ``"best"``.

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry.polygon import Part
    >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
    >>> rep = plan_exact(Problem.build(rect))
    >>> [round(o.expected_cost, 1) for o in rep.options], rep.bayes
    ([6.3, 6.0], 1)
    >>> [round(math.degrees(a), 2) for a in rep.options[1].alphas]
    [-45.0]

    >>> round(math.degrees(rep.options[1].tolerance), 3)
    12.171

    With turns that err by up to 20 degrees no 2-squeeze plan collapses more than the
    widest basin, which one squeeze collapses already:

    >>> rep = plan_exact(Problem.build(rect, accuracy=math.radians(20)))
    >>> [o.n_actions for o in rep.options]
    [1]

    Only the Bayes and the most certain plans:

    >>> rep = plan_exact(Problem.build(rect), report="best")
    >>> [o.n_actions for o in rep.options], rep.bayes, rep.most_certain
    ([2], 0, 0)
    """
    if max_actions is not None and max_actions < 1:
        raise PlanningError(f"`max_actions` must be at least 1; got {max_actions}")
    if report not in ("all", "best"):
        raise PlanningError(f"`report` must be 'all' or 'best'; got {report!r}")
    group = problem.goal_group
    prior = problem.prior
    kinds = problem.action_kinds
    p_tol = problem.part.hull.tol.probability
    planner = ArcPlanner.for_problem(problem)
    cap = planner.period  # no plan orients beyond the period
    limit_hard = max_plan_length(problem)
    # With an accuracy the widths may stop growing short of the period: the highest
    # attainable probability is that of the widest arc any plan collapses.
    reach = planner.widest_reachable(cap, limit_hard)
    p_best, _ = prior.max_arc_mass(min(reach, cap), group)

    # (p, cost, kinds, width) of the best plan of each length; angles come last.
    options: list[tuple[float, float, tuple[str, ...], float]] = []
    level: list[Counts] = [(0,) * len(kinds)]
    first_kind = min(kinds, key=lambda t: problem.cost.action_cost(t, first=True))
    next_kind = min(kinds, key=lambda t: problem.cost.action_cost(t))

    def cheap_kinds(n: int) -> tuple[str, ...]:
        """The action types of the cheapest attempt of ``n`` actions."""
        return (first_kind,) + (next_kind,) * (n - 1)

    cost = problem.cost
    runs: dict[tuple[str, str], list[float]] = {}

    def attempt(order: tuple[str, ...]) -> float:
        """``cost.attempt_cost(order)``, in O(1) amortised for plans of one repeated action.

        Its sum is left to right, so the partial sums of ``first, kind, kind, ...`` are
        kept and extended (the plans of each length are one action longer): bit for bit
        the same value.
        """
        if len(order) < 3 or order.count(order[1]) - (order[0] == order[1]) != len(order) - 1:
            return cost.attempt_cost(order)
        partial = runs.setdefault((order[0], order[1]), [0 + cost.action_cost(order[0], True)])
        step = cost.action_cost(order[1])
        while len(partial) < len(order):
            partial.append(partial[-1] + step)
        return cost.verify + partial[len(order) - 1]

    certain_at: int | None = None  # the length of the most certain plan, once found
    extra: tuple[float, float, tuple[str, ...], float] | None = None
    k = 0
    while True:
        k += 1
        candidates, nxt = planner.extend(level)
        scored = []
        for key, t, width in candidates:
            p, _ = prior.max_arc_mass(min(width, cap), group)
            order = planner.order(key, t)
            scored.append((p, cost.expected_from_attempt(attempt(order), p), order, width))
        cheapest = min(scored, key=lambda s: (s[1], -s[0]))
        if certain_at is None:
            top_p = max(s[0] for s in scored)
            done = top_p >= p_best - p_tol or (max_actions is not None and k >= max_actions)
            # The last level shows its most certain plan.
            pick = min(scored, key=lambda s: (-round(s[0], 12), s[1])) if done else cheapest
            options.append(pick)
            if done:
                certain_at = k
        if certain_at is not None:
            # With action types of different costs a plan as long as the most certain one,
            # or longer, may cost less (less certain, or cheaper actions): keep the cheapest
            # such plan, and search on while the cheapest attempt of one more action at the
            # highest probability could still beat the best so far.
            bound = min(o[1] for o in options)
            if extra is not None:
                bound = min(bound, extra[1])
            if cheapest[1] < bound * (1.0 - COST_RTOL):
                extra = cheapest
                bound = cheapest[1]
            if (
                len(kinds) == 1
                or (max_actions is not None and k >= max_actions)
                or problem.cost.expected_cost(cheap_kinds(k + 1), p_best) >= bound * (1 - COST_RTOL)
            ):
                break
        if k >= limit_hard:  # pragma: no cover - Goldberg 1993 bounds plans by O(n)
            raise PlanningError(f"no plan reached probability {p_best:.6f} in {k} actions")
        level = nxt
    if extra is not None:
        options.append(extra)
    bayes, most = choose_among([o[1] for o in options], [o[0] for o in options], p_tol)
    if report == "best":  # as PlanResult.best_only, before the angles are computed
        keep = sorted({bayes, most})
        options = [options[i] for i in keep]
        bayes, most = keep.index(bayes), keep.index(most)
    planner.prepare_margins([(order, width) for _, _, order, width in options])
    plans = tuple(
        _option(planner, order, width, min(width, cap), p, cost)
        for p, cost, order, width in options
    )
    return PlanResult(problem, plans, bayes, most, "exact")


def _option(
    planner: ArcPlanner,
    kinds: tuple[str, ...],
    width: float,
    placed: float,
    p: float,
    cost: float,
) -> PlanOption:
    """Turn a plan's action types and success-arc width into angles, margin and goal.

    ``placed`` is the length of arc the prior is placed on (``width`` capped at the period).
    """
    chain, tolerance = planner.witnesses(kinds, width)
    return chain_option(planner.problem, chain, tolerance, placed, p, cost, chain[0].width)
