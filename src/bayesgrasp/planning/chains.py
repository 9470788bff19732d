"""Witness chains turned into plans: gripper angles, final orientation, success arc.

A chain of witness arcs (see :mod:`bayesgrasp.planning.arcs`) becomes a plan option
(:func:`chain_option`; :func:`small_options` for every plan of a few-state problem at once,
on the fronts' lists); :func:`widest_reachable` is the widest arc any plan collapses;
:func:`period_cap` and :func:`one_period_arcs` are what the planners take from the problem.
"""

from __future__ import annotations

import bisect
import itertools
import math

from ..angles import TWO_PI
from ..errors import PlanningError
from ..geometry.curved import CurvedPart
from ..model.actions import Action
from ..model.problem import Problem
from .fronts import Arc, ArcFront
from .result import PlanOption, new_option, plan_actions, short_turns
from .staircases import pick_entry, stair_lists, tau_lists

__all__ = [
    "Counts",
    "Plans",
    "Scored",
    "chain_option",
    "one_period_arcs",
    "period_cap",
    "small_options",
    "widest_reachable",
]

Counts = tuple[int, ...]
"""How many actions of each type, in ``problem.action_kinds`` order."""
Scored = tuple[float, float, tuple[str, ...], float]
"""``(p, cost, action types, success-arc length)`` of a plan, as the exact planner finds it."""
Plans = list[Scored]


def one_period_arcs(problem: Problem) -> bool:
    """Whether the planners take the arcs of one period only (:func:`period_rows`).

    For curved parts (and parts with a shape tolerance), whose transfer functions are
    computed anew at each flattening: ties between copies of a plan are then broken the
    same way at every chordal tolerance.
    """
    return isinstance(problem.part, CurvedPart)


def period_cap(problem: Problem) -> float:
    """The angle no plan orients beyond: the largest period of the action types, or less.

    ``2 pi / g`` when that is smaller (``g`` the goal's group order).
    """
    period = 0.0
    for t in problem.action_kinds:
        if problem.transfers[t].period > period:
            period = problem.transfers[t].period
    cap = TWO_PI / problem.goal_group
    return period if period < cap else cap


def widest_reachable(
    fronts: list[ArcFront], tol: float, margin: float, cap: float, max_actions: int
) -> float:
    """The widest arc any plan collapses, up to ``cap`` (at most ``max_actions`` actions).

    ``fronts`` are those of the action types; each image must fit the next arc with
    ``margin`` to spare on each side. The widest arc of ``k + 1`` actions is ``G(W_k)``,
    with ``G(L)`` the widest arc of any action type whose image fits an arc ``L`` wide (the
    best counts of each length keep the widest arc, and ``G`` is non-decreasing). So the
    widths ``W_k`` are monotone from the first step on: once ``W_{k+1} <= W_k`` no longer
    plan collapses more. Without accuracy they grow to the period (Goldberg 1993); with it
    they may stop short.
    """
    width = max(f.widest(tol) for f in fronts)
    for _ in range(max_actions - 1):
        if width >= cap:
            break
        wider = max(f.widest(width - 2.0 * margin) for f in fronts)
        if wider <= width + tol:
            break
        width = wider
    return width


def small_options(
    problem: Problem, fronts: dict[str, ArcFront], tol: float, plans: Plans
) -> list[PlanOption]:
    """:meth:`ArcPlanner.plan_options` on the fronts' lists: no :class:`Staircase` nor :class:`Arc`.

    The staircase of each suffix of action types (keyed, as in :meth:`ArcPlanner.staircases`,
    by its first action and the staircase after it), and its ``tau`` at every arc of the
    front of the action before it, are computed once for all the plans (a plan of ``k``
    actions needs the ``tau`` that makes the staircase of ``k`` actions); the witnesses are
    front indices. Every float operation is the one of :meth:`ArcPlanner.witnesses`,
    :meth:`Staircase.pick` and :func:`chain_option`, so the options are the same, bit for bit
    (the planner checks that no chain would need more than
    :data:`~bayesgrasp.planning.arcs.STAIR_CELLS` entries).
    """
    accuracy = problem.accuracy
    prior, group = problem.prior, problem.goal_group
    cap = period_cap(problem)
    actions: dict[str, Action] = {}
    for a in problem.actions:  # (a loop: a comprehension costs more on few actions)
        actions[a.name] = a
    inf = math.inf
    # (kind, id of the staircase after it, or -1) -> (id, front index, rest, width, c)
    stairs: dict[tuple[str, int], tuple[int, list[int], list[float], list[float], list[float]]]
    stairs = {}
    taus: dict[tuple[str, int], list[float]] = {}  # (kind, staircase id) -> tau at its front

    out = []
    for p, cost, kinds, length in plans:
        k = len(kinds)
        chain_stairs = []  # the staircases of kinds[k-1:], kinds[k-2:], ..., kinds[1:]
        after = None
        for m in range(k - 1, 0, -1):
            t = kinds[m]
            key = (t, -1 if after is None else after[0])
            st = stairs.get(key)
            if st is None:
                g = fronts[t]
                later: list[float] | None = None
                if after is not None:
                    later = _tau_at(taus, t, g, after, tol, accuracy)
                st = (len(stairs), *stair_lists(g.span_list, g.width_list, later, tol))
                stairs[key] = st
            chain_stairs.append(st)
            after = st
        f = fronts[kinds[0]]
        spans = f.span_list
        at = bisect.bisect_left(f.width_list, length - tol)  # the arcs at..end are wide enough
        if after is None:  # one action: a single basin
            tolerance = None
            while spans[at] > 0.0:
                at += 1
        else:
            values = _tau_at(taus, kinds[0], f, after, tol, accuracy)
            best = -inf
            for n in range(at, len(values)):
                if values[n] > best:
                    best = values[n]
            if not math.isfinite(best):  # pragma: no cover - the lengths guarantee a chain
                raise PlanningError("internal error: no witness chain for a plan the lengths allow")
            while values[at] < best - tol:
                at += 1
            tolerance = best
        # chain_option, witness by witness: the first placed by the prior, each later one
        # picked by its staircase for the span of the one before (Arc.span: s_last - s),
        # the turn centring that image in it.
        lo = f.lo_list[at]
        _, start = prior.max_arc_mass(length if length < cap else cap, group, prefer=lo)
        angles = [start - lo]
        arc = (lo + f.width_list[at]) - lo  # Arc.width
        for m in range(1, k):
            s = f.s_first_list[at]
            s_last = s + f.span_list[at]
            _, idx, rest, width, c = chain_stairs[k - 1 - m]
            at = idx[pick_entry(c, rest, width, s_last - s)]
            f = fronts[kinds[m]]
            lo = f.lo_list[at]
            angles.append(0.5 * (s + s_last) - 0.5 * (lo + (lo + f.width_list[at])))
        steps, turned = short_turns(list(map(actions.__getitem__, kinds)), angles)
        final = math.fmod(f.s_first_list[at] + turned + TWO_PI, TWO_PI)
        out.append(new_option(tuple(steps), final, p, cost, tolerance, (start, start + arc)))
    return out


def _tau_at(
    taus: dict[tuple[str, int], list[float]],
    kind: str,
    front: ArcFront,
    stair: tuple[int, list[int], list[float], list[float], list[float]],
    tol: float,
    accuracy: float,
) -> list[float]:
    """``tau`` of ``stair`` at every arc of ``front`` (of action ``kind``), memoised."""
    key = (kind, stair[0])
    values = taus.get(key)
    if values is None:
        _, _, rest, width, c = stair
        values = taus[key] = tau_lists(c, rest, width, tol, accuracy, front.span_list)
    return values


def chain_option(
    problem: Problem,
    chain: list[Arc],
    tolerance: float | None,
    placed: float,
    p: float,
    cost: float,
    arc: float,
) -> PlanOption:
    """The plan option of a chain of witness arcs: gripper angles and final orientation.

    The first action's world angle puts ``chain[0]`` where the prior's mass on an arc of
    length ``placed`` is largest; each later turn centres the image of the previous witness
    in the next one. The success arc is reported ``arc`` long from the placement;
    ``tolerance``, ``p`` and ``cost`` are reported as given.
    """
    _, start = problem.prior.max_arc_mass(placed, problem.goal_group, prefer=chain[0].lo)
    angles = [start - chain[0].lo]
    for prev, w in itertools.pairwise(chain):
        # Centre the image [s_first, s_last] of the previous arc inside this witness.
        angles.append(0.5 * (prev.s_first + prev.s_last) - 0.5 * (w.lo + w.hi))
    steps, turned = short_turns(plan_actions(problem, [a.kind for a in chain]), angles)
    final = math.fmod(chain[-1].s_first + turned + TWO_PI, TWO_PI)
    return PlanOption(tuple(steps), final, p, cost, tolerance, (start, start + arc))
