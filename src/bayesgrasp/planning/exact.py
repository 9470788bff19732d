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
each reported plan for its witnesses (F arcs on the front). Parts whose every action has at
most :data:`~bayesgrasp.sizes.SMALL` states (the seed's study: about 6) are planned on plain
Python lists end to end (one action type: :func:`_plan_one_small`, with exact prunings of
the front and the staircases; the angles of any: :func:`~bayesgrasp.planning.arcs.small_options`),
with the same plans bit for bit.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from typing import Literal

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.cost import CostModel
from ..model.prior import Prior, UniformPrior
from ..model.problem import Problem
from . import arcs, result
from .arcs import ROUNDING, SPAN_SLACK, ArcPlanner, Counts, Scored
from .result import (
    COST_RTOL,
    PlanOption,
    PlanResult,
    PlanStep,
    check_max_actions,
    choose_among,
    max_plan_length,
    new_result,
    short_turns,
)

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
    check_max_actions(max_actions)
    if report not in ("all", "best"):
        raise PlanningError(f"`report` must be 'all' or 'best'; got {report!r}")
    if len(problem.actions) == 1 and arcs.FUSED and arcs.few_states(problem.transfers.values()):
        return _plan_one_small(problem, max_actions, report)
    p_tol = problem.part.hull.tol.probability
    planner = ArcPlanner.for_problem(problem)
    cap = planner.period  # no plan orients beyond the period
    limit_hard = max_plan_length(problem)
    mass = _masses(problem.prior, problem.goal_group, cap)
    # With an accuracy the widths may stop growing short of the period: the highest
    # attainable probability is that of the widest arc any plan collapses.
    p_best = mass(planner.widest_reachable(cap, limit_hard))
    attempt = _attempts(problem.cost)
    args = (problem, planner.tol, mass, attempt, p_best, p_tol, max_actions, limit_hard)
    options = _search(planner, *args)
    options, bayes, most = _choose(options, p_tol, report)
    return PlanResult(problem, tuple(planner.plan_options(options)), bayes, most, "exact")


_Stair = tuple[list[int], list[float], list[float], list[float]]
"""A staircase of :func:`_plan_one_small`: front index, rest, width and ``c`` of each entry."""

# Scored (arcs.py): (p, cost, action types, width) of the best plan of a length; angles last.


def _plan_one_small(problem: Problem, max_actions: int | None, report: Report) -> PlanResult:
    """:func:`plan_exact` for one action type of at most :data:`~bayesgrasp.sizes.SMALL` states.

    The same steps on plain lists, without an :class:`~bayesgrasp.planning.arcs.ArcPlanner`
    nor any :class:`~bayesgrasp.planning.arcs.ArcFront`, staircase or arc object, and the
    same plans, bit for bit (the tests run both):

    - the front (:class:`~bayesgrasp.planning.arcs.SpanFront`), taken in order of span only
      as far as the widths and the staircases below ask;
    - the widths ``W_k`` of each length, which for one action type are one sequence: ``W_1``
      the widest single basin, ``W_k`` the front's widest under ``W_{k-1}`` less twice the
      margin (:func:`~bayesgrasp.planning.arcs.widest_reachable` runs it to its end, the
      search to the first length that reaches its probability, as :func:`_search` does with
      one type); they ask for arcs of spans below ``cap - 2 max(tol, accuracy)`` only
      (``W < cap`` before each step);
    - the attempt costs as :meth:`CostModel.attempt_cost` sums them (left to right), the
      expected costs as :meth:`CostModel.expected_from_attempt` makes them, and the Bayes
      and the most certain plans (:func:`~bayesgrasp.planning.result.choose_among`, as
      :func:`_choose`);
    - the angles of the reported plans (:meth:`~bayesgrasp.planning.arcs.ArcPlanner.witnesses`,
      :meth:`~bayesgrasp.planning.arcs.Staircase.pick` and
      :func:`~bayesgrasp.planning.arcs.chain_option`, as
      :func:`~bayesgrasp.planning.arcs.small_options` runs them for any action set): the
      staircase of the last ``m`` actions, ``m = 1, 2, ..`` (for one action type it depends
      on ``m`` only), and its ``tau`` at the front's arcs, up to the longest reported plan.

    Exact prunings (each keeps every float operation that decides a plan):

    - *The front as far as asked.* The widths ask for the front's arcs of spans below
      ``W - 2 max(tol, accuracy) < cap - 2 T`` (``T`` below), so the front is taken up to
      ``cap - 2 T + slack`` at once, in one pass before the widths (each width is then the
      widest arc under its bound, a binary search); each staircase asks for those below
      ``Wmax - 2 T + slack`` (next item), which may reach further.
      :class:`~bayesgrasp.planning.arcs.SpanFront` takes its arcs in order of span up to
      there and no further, the same arcs the whole front holds below that span. A loop
      over the front's arcs that ends at the first ``-inf`` (next two items) ends at the
      same arc however far beyond its bound the front was taken.
    - *tau where it can be finite.* Let ``T`` be ``max(tol, accuracy - ROUNDING)``: a
      ``tau`` is ``-inf`` unless above ``tol`` and at least ``accuracy - ROUNDING``, so
      every entry of a staircase has a rest of at least ``T`` (or ``inf``), and let
      ``Wmax`` be its widest entry. An entry ``r`` with ``c_r = fl(w_r - 2 rest_r) >= x``
      needs ``x <= Wmax - 2 T`` but for a rounding; so for ``x >= Wmax - 2 T + slack`` the
      first entry with ``c >= x`` is past the last and ``tau(x) = (Wmax - x) / 2 < T``
      (again but for a rounding, far below the slack) is ``-inf``.
    - *tau only falls.* ``tau`` is non-increasing in ``x``, exactly in floats: for
      ``x < x'`` with the same first entry ``r`` (``c_r >= x``) both terms fall (rounding
      is monotone); with a later one ``r' > r``, ``rest_{r'} < rest_r`` and the entry
      ``e = r' - 1 >= r`` has ``fl(w_e - 2 rest_e) < x'``, hence ``w_e - 2 rest_e < x'``
      exactly (``x'`` is a float), ``fl(w_e - x') <= 2 rest_e`` and
      ``0.5 fl(w_e - x') <= rest_e <= rest_r``. So along the front (spans increasing) the
      first ``-inf`` ends the ``tau`` of a staircase; and the first witness of a plan of
      ``k`` actions, the first arc whose ``tau`` is within ``tol`` of the best among the
      arcs at least ``W_k - tol`` wide, is the first of those arcs.
    - *The last action.* Its staircase is the widest single basin, front arc 0 (span 0,
      rest ``inf``, ``c = -inf``): its ``tau`` is ``(W_0 - x) / 2`` where that passes, and
      it picks arc 0 for every span.
    - *The angles of the reported plans only* (``report="best"``: the Bayes and the most
      certain), and the staircases up to the longest of them.
    """
    (action,) = problem.actions
    kind = action.name
    f = problem.transfers[kind]
    tol = problem.states.angle_tol
    group = problem.goal_group
    accuracy = problem.accuracy
    cap = TWO_PI / group  # arcs.period_cap for one action type
    if f.period < cap:
        cap = f.period
    margin2 = 2.0 * (tol if tol >= accuracy else accuracy)  # max(tol, accuracy)
    floor = accuracy - ROUNDING  # Staircase.tau: margins from accuracy (less the rounding)
    low = tol if tol >= floor else floor  # T: every finite tau is at least this
    stable, lo, hi = f.values
    # ArcPlanner.max_span; the widths ask for spans below cap - margin2 <= cap - 2 T only.
    first = cap - 2.0 * low + 2.0 * SPAN_SLACK
    if arcs.one_period_arcs(problem):  # ties between copies broken alike at every flattening
        one = arcs.period_rows(f, tol)
        front = arcs.SpanFront(stable, lo, hi, f.period + tol, first, rows=one)
    else:
        front = arcs.SpanFront(stable, lo, hi, f.period + tol, first)
    spans, widths, rows = front.spans, front.widths, front.rows
    cover = front.cover
    left = bisect.bisect_left
    limit_hard = max_plan_length(problem)
    prior, cost = problem.prior, problem.cost
    uniform = type(prior) is UniformPrior  # its max_arc_mass: group * length / (2 pi)

    # Every bound the widths ask, at once (one pass over the arcs; see the docstring).
    bound = cap - 2.0 * low + SPAN_SLACK
    cover(bound if bound > tol else tol)
    n = left(spans, tol) - 1
    grown = [widths[n] if n >= 0 else 0.0]  # W_1, W_2, ...
    width = grown[0]
    for _ in range(limit_hard - 1):  # widest_reachable
        if width >= cap:
            break
        bound = width - margin2
        if bound > front.covered:  # pragma: no cover - not past the bound above (W < cap)
            cover(bound)
        n = left(spans, bound) - 1
        wider = widths[n] if n >= 0 else 0.0
        grown.append(wider)
        if wider <= width + tol:
            break
        width = wider
    # The prior mass of the success arc, placed best (capped at the period; memoised).
    masses: dict[float, float] = {}
    x = width if width <= cap else cap  # min(width, cap)
    if uniform:
        p_best = group * x / TWO_PI
    else:
        p_best = masses[x] = prior.max_arc_mass(x, group)[0]
    p_tol = problem.part.hull.tol.probability
    stop = p_best - p_tol
    cut = limit_hard if max_actions is None else max_actions
    step = cost.action_cost(kind)
    run = 0 + cost.action_cost(kind, True)  # the actions' costs summed left to right
    verify, retry = cost.verify, cost.retry
    costs: list[float] = []
    probs: list[float] = []
    k = 0
    # The widths reach p_best within `grown` (p_best is the mass of one of them), and
    # Goldberg 1993 bounds plans by O(n).
    for width in grown:
        k += 1
        x = width if width <= cap else cap
        if uniform:
            p = group * x / TWO_PI
        else:
            known = masses.get(x)
            p = masses[x] = prior.max_arc_mass(x, group)[0] if known is None else known
        # CostModel.expected_from_attempt
        costs.append((verify + run) / p + retry * (1.0 / p - 1.0) if p > 0.0 else math.inf)
        probs.append(p)
        if p >= stop or k >= cut:
            break
        run = run + step
    else:  # pragma: no cover - see above
        raise PlanningError(f"no plan reached probability {p_best:.6f} in {k} actions")
    bayes, most = choose_among(costs, probs, p_tol)
    if report == "best":  # as PlanResult.best_only, before the angles are computed
        keep = [bayes] if bayes == most else sorted((bayes, most))
        bayes, most = keep.index(bayes), keep.index(most)
    else:
        keep = list(range(k))
    longest = keep[-1] + 1
    if longest * len(widths) > arcs.STAIR_CELLS:  # pragma: no cover - not with few states
        options = [(probs[n], costs[n], (kind,) * (n + 1), grown[n]) for n in keep]
        plans = ArcPlanner.for_problem(problem).plan_options(options)
        return new_result(problem, tuple(plans), bayes, most, "exact")

    # The staircases of the last m = 1, 2, .. actions and their tau at the front's arcs (as
    # far as it is finite; -inf after). A staircase is its entries' front index, rest
    # (then -inf), width (after -inf) and c: rest[r] and 0.5 * (width[r] - x) are then
    # Staircase.tau's rest[r] (-inf past the last) and 0.5 * (width[r - 1] - x) (-inf
    # before the first). "v > tol and v >= floor" is v >= passing. The tau of the longest
    # plan's staircase is asked at one arc only (its first witness), so not made here.
    last = longest - 1
    inf = math.inf
    passing = math.nextafter(tol, inf)
    if floor > passing:
        passing = floor
    w0 = widths[0]
    bound = w0 - 2.0 * low + SPAN_SLACK
    if bound > front.covered:
        cover(bound)
    tau = []
    for x in spans if last > 1 else ():  # the last action's staircase: (W_0 - x) / 2
        v = 0.5 * (w0 - x)
        if v >= passing:
            tau.append(v)
        else:
            break
    taus = [[], tau]  # by m (none for m = 0)
    top_tau = tau  # the tau the longest plan's staircase is made from
    # by m; none for m = 0, and the last action's (arc 0) is never looked up
    stairs: list[_Stair] = [([], [], [], [])] * 2
    for m in range(2, longest):
        if m == last:  # the longest plan's staircase: asked at two spans only, _stair_top
            if tau:
                bound = widths[len(tau) - 1] - 2.0 * low + SPAN_SLACK
                if bound > front.covered:
                    cover(bound)
            top_tau = tau
            break
        # The staircase of m actions from the tau of m - 1 (arcs.staircase: every arc whose
        # rest exceeds the rest of each wider arc, one scan from the widest down; a finite
        # tau is above tol), then its tau.
        idx: list[int] = []
        rest = [-inf]
        wid: list[float] = []
        c: list[float] = []
        best = -inf
        for n in range(len(tau) - 1, -1, -1):
            v = tau[n]
            if v > best:
                best = v
                w = widths[n]
                idx.append(n)
                rest.append(v)
                wid.append(w)
                c.append(w - 2.0 * v)
        wid.append(-inf)
        idx.reverse()
        rest.reverse()
        wid.reverse()
        c.reverse()
        stairs.append((idx, rest, wid, c))
        tau = []
        if c:
            bound = wid[-1] - 2.0 * low + SPAN_SLACK
            if bound > front.covered:
                cover(bound)
            for x in spans:  # Staircase.tau, as far as it passes
                r = left(c, x)
                at = rest[r]
                before = 0.5 * (wid[r] - x)
                value = at if at >= before else before
                if value >= passing:
                    tau.append(value)
                else:
                    break
        taus.append(tau)

    remainder, pi, two_pi = math.remainder, math.pi, TWO_PI
    g = action.gripper_period
    half = g / 2.0
    neg_pi, neg_half = -pi, -half
    new = object.__new__  # PlanStep and PlanOption made as short_turns and new_option do
    set_kind, set_alpha = result.slot_setters(PlanStep)
    set_steps, set_final, set_p, set_cost, set_tolerance, set_arc = result.slot_setters(PlanOption)
    zero = new(PlanStep)  # the first step of every plan under the uniform prior
    set_kind(zero, kind)
    set_alpha(zero, 0.0)
    top_x, top_at = math.nan, -1  # the longest plan's first witness: its span, the next one
    out = []
    for n in keep:
        length = grown[n]
        at = left(widths, length - tol)  # the arcs at..end are wide enough
        if n == 0:  # one action: a single basin
            tolerance = None
            while spans[at] > 0.0:
                at += 1
        else:  # the best tau of the arcs at..end (and the first within tol of it): at's
            if n < last:
                vals = taus[n]
                tolerance = vals[at] if at < len(vals) else -inf
            elif n == 1 and at < len(spans):  # the longest plan: its staircase's tau at `at`
                tolerance = 0.5 * (w0 - spans[at])
            elif at < len(spans):  # (and the arc it picks there: the next witness, below)
                top_x = spans[at]
                tolerance, top_at = _stair_top(top_tau, widths, top_x)
            else:
                tolerance = -inf
            if not tolerance >= passing:  # pragma: no cover - the lengths guarantee a chain
                raise PlanningError("internal error: no witness chain for a plan the lengths allow")
        # chain_option, witness by witness: the first placed by the prior, each later one
        # picked by its staircase for the span of the one before (Arc.span: s_last - s),
        # the turn centring that image in it; each turn made short as short_turns makes
        # it (wrap, then wrap_period of the gripper's period, the rest carried on).
        i = rows[at]
        a = lo[i]
        if uniform:  # the first turn, start - a, is a - a = +0.0: already short, carry 0.0
            start = a
            steps = [zero]
            carry = 0.0
        else:
            start = prior.max_arc_mass(length if length < cap else cap, group, prefer=a)[1]
            steps, carry = short_turns((action,), (start - a,))
        arc = (a + widths[at]) - a  # Arc.width
        m = n
        while m:
            s = stable[i]
            s_last = s + spans[at]
            if m == 1:
                at = 0  # the last action's staircase picks arc 0
            elif m == last:  # picked at the span of the first witness (Arc.span)
                x = s_last - s
                at = top_at if x == top_x else _stair_top(top_tau, widths, x)[1]
            else:
                idx, rest, wid, c = stairs[m]
                x = s_last - s
                r = left(c, x)
                at = idx[r if rest[r] >= 0.5 * (wid[r] - x) else r - 1]
            i = rows[at]
            a = lo[i]
            turn = 0.5 * (s + s_last) - 0.5 * (a + (a + widths[at])) + carry
            if neg_half < turn < half:  # as short as it gets: wrap and wrap_period keep it
                short = turn
                carry = 0.0  # turn - turn
            else:
                wrapped = remainder(turn, two_pi)
                if wrapped == neg_pi:
                    wrapped = pi
                short = remainder(wrapped, g)
                if short == neg_half:
                    short = half
                carry = wrapped - short
            made = new(PlanStep)
            set_kind(made, kind)
            set_alpha(made, short)
            steps.append(made)
            m -= 1
        final = math.fmod(stable[i] + carry + two_pi, two_pi)
        option = new(PlanOption)
        set_steps(option, tuple(steps))
        set_final(option, final)
        set_p(option, probs[n])
        set_cost(option, costs[n])
        set_tolerance(option, tolerance)
        set_arc(option, (start, start + arc))
        out.append(option)
    return new_result(problem, tuple(out), bayes, most, "exact")


def _stair_top(tau: list[float], widths: list[float], x: float) -> tuple[float, int]:
    """``tau`` at span ``x`` of the staircase made from ``tau``, and the front arc it picks.

    ``tau`` is the (finite, non-increasing) ``tau`` of the staircase after it at the front's
    arcs ``0, 1, ..``, ``widths`` the front's widths. That staircase's entries are the arcs
    ``n`` with ``tau[n] > tau[n + 1]`` and the last (arcs.staircase's scan from the widest
    down keeps an arc whose rest exceeds every wider arc's), with ``c = w - 2 tau``
    non-decreasing along them; its ``tau(x)`` and pick are decided by the first entry with
    ``c >= x`` and the one before (:meth:`~bayesgrasp.planning.arcs.Staircase.tau`,
    :meth:`~bayesgrasp.planning.arcs.Staircase.pick`). Found from the widest entry down,
    for spans near the widest (the longest plan's first witness and its image) in a few
    steps, without the staircase: the same floats and the same arc.
    """
    n = len(tau) - 1
    if n < 0:  # pragma: no cover - the lengths guarantee a chain
        return -math.inf, -1
    if widths[n] - 2.0 * tau[n] < x:  # past the widest entry: (W - x) / 2 of the widest
        return 0.5 * (widths[n] - x), n
    cur = n  # the least entry so far with c >= x
    m = n - 1
    while m >= 0:
        v = tau[m]
        if v > tau[m + 1]:  # an entry
            if widths[m] - 2.0 * v < x:  # the entry before the first with c >= x
                before = 0.5 * (widths[m] - x)
                value = tau[cur]
                return (value, cur) if value >= before else (before, m)
            cur = m
        m -= 1
    return tau[cur], cur


def _choose(options: list[Scored], p_tol: float, report: Report) -> tuple[list[Scored], int, int]:
    """The options to report, and the indices of the Bayes and the most certain among them."""
    bayes, most = choose_among([o[1] for o in options], [o[0] for o in options], p_tol)
    if report == "best":  # as PlanResult.best_only, before the angles are computed
        keep = sorted({bayes, most})
        return [options[i] for i in keep], keep.index(bayes), keep.index(most)
    return options, bayes, most


def _masses(prior: Prior, group: int, cap: float) -> Callable[[float], float]:
    """The prior mass of the best placed arc of a width capped at ``cap`` (memoised)."""
    masses: dict[float, float] = {}

    def mass(width: float) -> float:
        x = min(width, cap)
        if x not in masses:
            masses[x] = prior.max_arc_mass(x, group)[0]
        return masses[x]

    return mass


def _attempts(cost: CostModel) -> Callable[[tuple[str, ...]], float]:
    """``cost.attempt_cost``, in O(1) amortised for plans of one repeated action.

    Its sum is left to right, so the partial sums of ``first, kind, kind, ...`` are kept and
    extended (the plans of each length are one action longer): bit for bit the same value.
    """
    runs: dict[tuple[str, str], list[float]] = {}

    def attempt(order: tuple[str, ...]) -> float:
        if len(order) < 3 or order.count(order[1]) - (order[0] == order[1]) != len(order) - 1:
            return cost.attempt_cost(order)
        partial = runs.setdefault((order[0], order[1]), [0 + cost.action_cost(order[0], True)])
        step = cost.action_cost(order[1])
        while len(partial) < len(order):
            partial.append(partial[-1] + step)
        return cost.verify + partial[len(order) - 1]

    return attempt


def _search(
    planner: ArcPlanner,
    problem: Problem,
    tol: float,
    mass: Callable[[float], float],
    attempt: Callable[[tuple[str, ...]], float],
    p_best: float,
    p_tol: float,
    max_actions: int | None,
    limit_hard: int,
) -> list[Scored]:
    """The best plan of each length (and perhaps one more, see :func:`plan_exact`)."""
    kinds = problem.action_kinds
    cost = problem.cost
    options: list[Scored] = []
    level: list[Counts] = [(0,) * len(kinds)]
    first_kind = min(kinds, key=lambda t: cost.action_cost(t, first=True))
    next_kind = min(kinds, key=lambda t: cost.action_cost(t))

    def cheap_kinds(n: int) -> tuple[str, ...]:
        """The action types of the cheapest attempt of ``n`` actions."""
        return (first_kind,) + (next_kind,) * (n - 1)

    certain_at: int | None = None  # the length of the most certain plan, once found
    extra: Scored | None = None
    k = 0
    while True:
        k += 1
        candidates, nxt = planner.extend(level)
        scored = []
        for key, t, width in candidates:
            p = mass(width)
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
                or cost.expected_cost(cheap_kinds(k + 1), p_best) >= bound * (1 - COST_RTOL)
            ):
                break
        if k >= limit_hard:  # pragma: no cover - Goldberg 1993 bounds plans by O(n)
            raise PlanningError(f"no plan reached probability {p_best:.6f} in {k} actions")
        level = nxt
    if extra is not None:
        options.append(extra)
    return options
