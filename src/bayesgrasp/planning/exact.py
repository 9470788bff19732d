"""The exact Bayesian planner: backchaining arc lengths (Goldberg 1993, made Bayesian).

See design.md, "The fact that makes exact planning fast".

Every transfer function here is a non-decreasing step function with
``F(theta + 2 pi) = F(theta) + 2 pi``, and so is every composition of them. Hence the initial
orientations that a plan sends to one final orientation form an arc, and because the gripper
may be turned freely before each action, whether an arc can be collapsed to a point by a
given sequence of action types depends only on its length. Let ``L(seq)`` be the supremum of
those lengths. For a sequence whose first action has transfer function ``F`` and whose rest
is ``seq'``:

    L(F, seq') = the widest open arc (B_i, B_j) between basin boundaries of F whose stable
                 orientations S_{i+1} .. S_j span strictly less than L(seq')

(the image of the arc is the closed arc [S_{i+1}, S_j]; it must fit inside an open arc of
length ``L(seq')``; an arc reaching past a basin boundary takes the next stable orientation
along, and the boundary itself, an unstable equilibrium, stays where it is). The last action
alone collapses exactly one basin. ``L`` grows with the allowed arc, so for a fixed count of
each action type only the type of the *first* action matters for cost; the rest take the
order that gives the widest arc. Comparisons keep a margin of the angle tolerance: an image
must span less than ``L(seq') - 2 tol``, so no plan relies on hitting an unstable equilibrium.

Only arcs on the *front* matter: an arc is useless if another is at least as wide and spans
no more. The front of a transfer function (at most one arc for each span, sorted by span,
widths increasing) is computed once; the widest arc under a span limit is then a binary
search.

Success probability: the plan collapses an open arc of length ``L`` placed anywhere by the
gripper angle of the first action, so ``p = max over placements of the prior mass of that
arc`` (with a symmetry goal, of the arc and its copies ``2 pi / r`` apart). Under the uniform
prior ``p = L / (2 pi)`` (times ``r``). Expected cost is ``CostModel.expected_cost``. The
search stops at the first length whose probability reaches the largest prior mass of an arc
as long as the period (or ``2 pi / r``), which no plan can beat.

Angles come from a chain of *witness* arcs ``a_1, ..., a_k``, one per action, each an open arc
between basin boundaries of that action's transfer function: ``a_1`` is the success arc (of
length ``L``), ``a_k`` a single basin, and the image of ``a_m`` (its stable orientations, of
span ``x_m``) is placed in the middle of ``a_{m+1}`` (of length ``W_{m+1}``). Relative rotation
``m + 1`` may then err by ``(W_{m+1} - x_m) / 2`` and every orientation of the success arc still
ends at the goal; the plan's tolerance is the least of these margins.

The witnesses are not simply the widest arcs of each count: a wider ``a_{m+1}`` gives more
margin before action ``m + 1`` but may have a larger image, leaving less before action
``m + 2``. The chain is chosen to maximise the least margin (a bottleneck dynamic programme
from the last action back): ``tau_m(x)``, the best least margin of actions ``m..k`` when an
image of span ``x`` arrives before action ``m``, is
``max over front arcs a of min((W(a) - x) / 2, tau_{m+1}(span(a)))``, a non-increasing
staircase in ``x`` kept as the Pareto front of its (width, later margin) pairs. Under errors of
at most ``t`` on every turn, the orientations that can arrive before an action fill the
basins of an arc whose width exceeds the arriving span by ``2 t``; so no plan with this
success arc has a larger tolerance than the chain's.

Gripper accuracy (``Problem.accuracy``, ``A``): the same argument with margin ``A``. An
image must span less than ``L(seq') - 2 max(tol, A)``, so that it fits the next witness with
more than ``A`` to spare on each side, and the staircases admit only margins of at least
``A``: every plan of two or more actions then has tolerance at least ``A``, and since under
errors up to ``A`` the arriving orientations fill an arc ``2 A`` wider than the image, no
plan robust to such errors collapses more. The widest arc of ``k + 1`` actions is
``G(W_k)`` with ``G`` non-decreasing (the widest arc of any action type whose image fits an
arc ``W_k`` wide), so ``W_k`` is monotone; with ``A > 0`` it may stop short of the period,
and the search then stops at the fixed point: the highest attainable probability is that of
the widest arc reached (``_Planner.widest_reachable``, computed before the search).

Cost: O(K^2) once per action type for the front (K stable orientations; usually far fewer
arcs survive), then O(log K) per (count, type) for the lengths and O(F log F) per action of
each reported plan for its witnesses (F arcs on the front).
"""

from __future__ import annotations

import bisect
import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import PlanningError
from ..geometry.transfer import TransferFunction
from ..model.problem import Problem
from .result import PlanOption, PlanReport, PlanStep, choose_indices

__all__ = ["plan_exact"]

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]
Counts = tuple[int, ...]  # how many actions of each type, in ``problem.action_kinds`` order
_CHUNK = 1 << 20  # arcs enumerated at once (bounds memory for parts with many states)
# The lengths admit a margin above ``accuracy`` by ``span < L - 2 accuracy``, the staircases
# compute it as ``(L - span) / 2``: these may differ by rounding, and the witness chain must
# exist whenever the lengths allow it.
_ROUNDING = 1e-13


@dataclass(frozen=True, slots=True)
class Arc:
    """An open arc ``(lo, hi)`` of one action's frame and its image ``[s_first, s_last]``.

    ``s_first .. s_last`` are the stable orientations of the basins the arc covers.
    """

    kind: str
    lo: float
    hi: float
    s_first: float
    s_last: float

    @property
    def width(self) -> float:
        """Length of the arc."""
        return self.hi - self.lo

    @property
    def span(self) -> float:
        """Length of its image."""
        return self.s_last - self.s_first


@dataclass(frozen=True, slots=True, eq=False)
class _Front:
    """The arcs of one transfer function that no other arc beats.

    Sorted by ``span`` (of the image) increasing, with ``width`` strictly increasing: an
    arc is dropped when another is at least as wide and spans no more. Arc ``n`` is the
    open arc ``(lo[n], lo[n] + width[n])`` with image ``[s_first[n], s_first[n] + span[n]]``.
    The lists repeat the arrays for the scalar binary searches of the planner.
    """

    kind: str
    lo: FloatArray
    width: FloatArray
    s_first: FloatArray
    span: FloatArray
    span_list: list[float]
    width_list: list[float]

    def arc(self, n: int) -> Arc:
        """Arc ``n`` as plain floats."""
        lo, s = float(self.lo[n]), float(self.s_first[n])
        return Arc(self.kind, lo, lo + self.width_list[n], s, s + self.span_list[n])


def _arc_front(f: TransferFunction, max_span: float) -> _Front:
    """The front of the arcs of ``f`` whose image spans less than ``max_span``.

    Single basins (span 0) are always arcs, even when ``max_span <= 0``. Of arcs equal in
    width and span the one of the first basin is kept.
    """
    k = f.n_states
    s2 = np.concatenate([f.stable, f.stable + TWO_PI])  # (2K,)
    hi2 = np.concatenate([f.basin_hi, f.basin_hi + TWO_PI])
    i_all = np.arange(k)
    # Last basin j of an arc starting at basin i: at most K basins, image span < max_span,
    # at least basin i itself.
    last = np.clip(np.searchsorted(s2, f.stable + max_span, side="left") - 1, i_all, i_all + k - 1)
    n_off = int(np.max(last - i_all)) + 1
    rows = max(1, _CHUNK // n_off)
    parts: list[tuple[FloatArray, ...]] = []
    for start in range(0, k, rows):
        i = i_all[start : start + rows]
        j = i[:, None] + np.arange(n_off)[None, :]  # (R, J) candidate last basins
        ok = j <= last[i, None]
        ii = np.broadcast_to(i[:, None], j.shape)[ok]
        jj = j[ok]
        lo = f.basin_lo[ii]
        width = hi2[jj] - lo
        span = s2[jj] - f.stable[ii]
        keep = _front_index(span, width)
        parts.append((lo[keep], width[keep], f.stable[ii][keep], span[keep]))
    lo, width, first, span = (np.concatenate(x) for x in zip(*parts, strict=True))
    keep = _front_index(span, width)
    lo, width, first, span = lo[keep], width[keep], first[keep], span[keep]
    return _Front(f.kind, lo, width, first, span, span.tolist(), width.tolist())


def _front_index(cost: FloatArray, value: FloatArray) -> NDArray[np.intp]:
    """Indices of the Pareto front (least ``cost``, most ``value``), by cost increasing.

    On the front ``value`` strictly increases; of equal pairs the first index is kept.
    """
    order = np.argsort(cost, kind="stable")
    v = value[order]
    best_before = np.maximum.accumulate(np.concatenate([[-np.inf], v[:-1]]))
    kept = order[v > best_before]  # value increases; cost non-decreasing
    # Of entries with equal cost only the last (the most value) is on the front.
    c = cost[kept]
    return np.asarray(kept[np.append(c[1:] != c[:-1], True)], dtype=np.intp)


def _widest(front: _Front, max_span: float) -> float:
    """Width of the widest arc whose image spans less than ``max_span`` (0 if none does).

    Every front holds a single basin (span 0), so only ``max_span <= 0`` gives 0: the arc
    after this action is too narrow to take even one point with the margin asked for.
    """
    n = bisect.bisect_left(front.span_list, max_span) - 1
    return front.width_list[n] if n >= 0 else 0.0


@dataclass(frozen=True, slots=True, eq=False)
class _Staircase:
    """``tau(x)`` of one action: the best least margin of it and the actions after it.

    Entry ``r`` is arc ``index[r]`` of ``front``, with ``rest[r]`` the least margin of the
    later actions after that arc. Entries are sorted by ``rest`` decreasing, with widths
    strictly increasing: the Pareto front of (width, rest). With ``c = width - 2 rest``
    (non-decreasing), ``tau(x)`` is attained at the first entry with ``c >= x`` (value
    ``rest``) or at the one before it (value ``(width - x) / 2``).
    """

    front: _Front
    index: NDArray[np.intp]
    rest: FloatArray
    width: FloatArray
    c: FloatArray
    c_list: list[float]
    tol: float
    accuracy: float

    def tau(self, x: FloatArray) -> FloatArray:
        """Best least margin for images of spans ``x`` (``-inf`` where none fits)."""
        n = len(self.rest)
        r = np.searchsorted(self.c, x, side="left")  # (M,) first entry with c >= x
        at = np.where(r < n, self.rest[np.minimum(r, n - 1)], -np.inf)
        before = np.where(r > 0, 0.5 * (self.width[np.maximum(r - 1, 0)] - x), -np.inf)
        value = np.maximum(at, before)
        ok = (value > self.tol) & (value >= self.accuracy - _ROUNDING)
        return np.asarray(np.where(ok, value, -np.inf), dtype=np.float64)

    def pick(self, x: float) -> Arc:
        """The arc that attains ``tau(x)`` for one span ``x``."""
        r = bisect.bisect_left(self.c_list, x)
        at = float(self.rest[r]) if r < len(self.c_list) else -math.inf
        before = 0.5 * (float(self.width[r - 1]) - x) if r > 0 else -math.inf
        return self.front.arc(int(self.index[r if at >= before else r - 1]))


def _staircase(
    front: _Front, after: _Staircase | None, tol: float, accuracy: float = 0.0
) -> _Staircase:
    """The staircase of an action whose arcs are ``front``, given the one of the next action.

    Only margins above ``tol`` and at least ``accuracy`` count (``tau`` is ``-inf`` below).
    """
    if after is None:  # the last action collapses one basin: only single basins count
        index = np.flatnonzero(front.span <= 0.0)
        rest = np.full(len(index), np.inf)
    else:
        rest = after.tau(front.span)
        index = np.flatnonzero(rest > tol)
        rest = rest[index]
    keep = _front_index(-rest, front.width[index])  # most rest first, widths increasing
    index, rest = index[keep], rest[keep]
    width = front.width[index]
    c = width - 2.0 * rest
    return _Staircase(front, index, rest, width, c, c.tolist(), tol, accuracy)


@dataclass(slots=True)
class _Planner:
    """The fronts, widest arcs and staircases of one problem, computed on first use.

    ``best[counts]`` is the widest arc that actions of those counts collapse (their best
    order) and the type of the first action of that order.
    """

    problem: Problem
    tol: float
    max_span: float
    fronts: dict[str, _Front] = field(default_factory=dict)
    # Staircase of an action type followed by the actions of staircase ``next_id`` (-1:
    # none), with its own id: a suffix of a plan is found in O(1) from the next one.
    stairs: dict[tuple[str, int], tuple[int, _Staircase]] = field(default_factory=dict)
    best: dict[Counts, tuple[float, str]] = field(default_factory=dict)
    index: dict[str, int] = field(init=False)  # position of each action type in a Counts

    def __post_init__(self) -> None:
        self.index = {t: i for i, t in enumerate(self.problem.action_kinds)}

    def front(self, kind: str) -> _Front:
        """The arc front of one action type."""
        if kind not in self.fronts:
            self.fronts[kind] = _arc_front(self.problem.transfers[kind], self.max_span)
        return self.fronts[kind]

    def extend(self, level: list[Counts]) -> tuple[list[tuple[Counts, str, float]], list[Counts]]:
        """The plans one action longer than those of ``level`` (all zeros: no action yet).

        For each counts in ``level`` and each action type put before them: the new counts,
        that type, and the widest arc the plan collapses (the later actions in their best
        order). Updates ``best``. Returns these candidates and the next level (the new
        counts, in order of first appearance).
        """
        kinds = self.problem.action_kinds
        tol = self.tol
        margin = max(tol, self.problem.accuracy)
        candidates: list[tuple[Counts, str, float]] = []
        nxt: dict[Counts, None] = {}
        for rest in level:
            # The last action must leave a single stable orientation: an image under tol.
            # Before it, the image must fit the next arc with ``margin`` to spare each side.
            max_span = self.best[rest][0] - 2.0 * margin if any(rest) else tol
            for i, t in enumerate(kinds):
                key = (*rest[:i], rest[i] + 1, *rest[i + 1 :])
                width = _widest(self.front(t), max_span)
                candidates.append((key, t, width))
                nxt[key] = None
                if key not in self.best or width > self.best[key][0] + tol:
                    self.best[key] = (width, t)
        return candidates, list(nxt)

    def widest_reachable(self, cap: float, max_actions: int) -> float:
        """The widest arc any plan collapses, up to ``cap`` (at most ``max_actions`` actions).

        The widest arc of ``k + 1`` actions is ``G(W_k)``, with ``G(L)`` the widest arc of any
        action type whose image fits an arc ``L`` wide (the best counts of each length keep
        the widest arc, and ``G`` is non-decreasing). So the widths ``W_k`` are monotone from
        the first step on: once ``W_{k+1} <= W_k`` no longer plan collapses more. Without
        accuracy they grow to the period (Goldberg 1993); with it they may stop short.
        """
        margin = max(self.tol, self.problem.accuracy)
        fronts = [self.front(t) for t in self.problem.action_kinds]
        width = max(_widest(f, self.tol) for f in fronts)
        for _ in range(max_actions - 1):
            if width >= cap:
                break
            wider = max(_widest(f, width - 2.0 * margin) for f in fronts)
            if wider <= width + self.tol:
                break
            width = wider
        return width

    def order(self, counts: Counts, first: str) -> tuple[str, ...]:
        """Action types of a plan in order: ``first``, then the best order of the rest."""
        kinds = [first]
        left = list(counts)
        left[self.index[first]] -= 1
        while any(left):
            kind = self.best[tuple(left)][1]
            kinds.append(kind)
            left[self.index[kind]] -= 1
        return tuple(kinds)

    def staircases(self, kinds: tuple[str, ...]) -> list[_Staircase]:
        """The staircase of ``kinds[m:]`` for each ``m``."""
        out: list[_Staircase] = []
        next_id, after = -1, None
        for kind in reversed(kinds):
            key = (kind, next_id)
            if key not in self.stairs:
                stair = _staircase(self.front(kind), after, self.tol, self.problem.accuracy)
                self.stairs[key] = (len(self.stairs), stair)
            next_id, after = self.stairs[key]
            out.append(after)
        return out[::-1]

    def witnesses(self, kinds: tuple[str, ...], length: float) -> tuple[list[Arc], float | None]:
        """The chain of witness arcs of largest least margin, and that margin.

        ``length`` is the success arc's length; the first witness is an arc that wide.
        """
        front = self.front(kinds[0])
        wide = bisect.bisect_left(front.width_list, length - self.tol)  # arcs wide..end
        if len(kinds) == 1:
            return [front.arc(wide + int(np.flatnonzero(front.span[wide:] <= 0.0)[0]))], None
        stairs = self.staircases(kinds[1:])
        rest = stairs[0].tau(front.span[wide:])
        best = float(rest.max())
        if not math.isfinite(best):  # pragma: no cover - the lengths guarantee a chain
            raise PlanningError("internal error: no witness chain for a plan the lengths allow")
        chain = [front.arc(wide + int(np.flatnonzero(rest >= best - self.tol)[0]))]
        for stair in stairs:
            chain.append(stair.pick(chain[-1].span))
        return chain, best


def plan_exact(problem: Problem, max_actions: int | None = None) -> PlanReport:
    """Best plans of every length, exactly, for any prior, cost model and goal.

    Parameters
    ----------
    problem : Problem
    max_actions : int, optional
        Stop after plans of this many actions even if more would raise the success
        probability (default: go on until the highest attainable probability).

    Honours the problem's gripper ``accuracy``: every plan of two or more actions has
    tolerance at least ``accuracy``, and is the best of those that do.

    Returns
    -------
    PlanReport
        ``options[k - 1]`` is the best plan of ``k`` actions: the least expected cost of
        those with ``k`` actions, except the last, the most certain one. When action types
        cost differently (squeezes and push-grasps), one more option may follow: the
        cheapest plan with at least as many actions as the most certain one, if it costs
        less than every other option (it is then the Bayes plan).

    Raises
    ------
    PlanningError
        If ``max_actions`` is less than 1.

    Examples
    --------
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
    """
    if max_actions is not None and max_actions < 1:
        raise PlanningError(f"`max_actions` must be at least 1; got {max_actions}")
    tol = problem.states.angle_tol
    group = problem.goal_group
    prior = problem.prior
    kinds = problem.action_kinds
    periods = [problem.transfers[t].period for t in kinds]
    cap = min(max(periods), TWO_PI / group)  # no plan orients beyond the period
    planner = _Planner(problem, tol, max(periods) + tol)
    limit_hard = 4 * problem.part.hull.n_sides + 8
    # With an accuracy the widths may stop growing short of the period: the highest
    # attainable probability is that of the widest arc any plan collapses.
    reach = planner.widest_reachable(cap, limit_hard)
    p_best, _ = prior.max_arc_mass(min(reach, cap), group)

    options: list[PlanOption] = []
    level: list[Counts] = [(0,) * len(kinds)]
    first_kind = min(kinds, key=lambda t: problem.cost.action_cost(t, first=True))
    next_kind = min(kinds, key=lambda t: problem.cost.action_cost(t))

    def cheap_kinds(n: int) -> tuple[str, ...]:
        """The action types of the cheapest attempt of ``n`` actions."""
        return (first_kind,) + (next_kind,) * (n - 1)

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
            scored.append((p, problem.cost.expected_cost(order, p), order, width))
        cheapest = min(scored, key=lambda s: (s[1], -s[0]))
        if certain_at is None:
            top_p = max(s[0] for s in scored)
            done = top_p >= p_best - 1e-12 or (max_actions is not None and k >= max_actions)
            # The last level shows its most certain plan.
            pick = min(scored, key=lambda s: (-round(s[0], 12), s[1])) if done else cheapest
            p, cost, order, width = pick
            options.append(_option(planner, order, width, min(width, cap), p, cost))
            if done:
                certain_at = k
        if certain_at is not None:
            # With action types of different costs a plan as long as the most certain one,
            # or longer, may cost less (less certain, or cheaper actions): keep the cheapest
            # such plan, and search on while the cheapest attempt of one more action at the
            # highest probability could still beat the best so far.
            bound = min(o.expected_cost for o in options)
            if extra is not None:
                bound = min(bound, extra[1])
            if cheapest[1] < bound * (1.0 - 1e-12):
                extra = cheapest
                bound = cheapest[1]
            if (
                len(kinds) == 1
                or (max_actions is not None and k >= max_actions)
                or problem.cost.expected_cost(cheap_kinds(k + 1), p_best) >= bound * (1 - 1e-12)
            ):
                break
        if k >= limit_hard:  # pragma: no cover - Goldberg 1993 bounds plans by O(n)
            raise PlanningError(f"no plan reached probability {p_best:.6f} in {k} actions")
        level = nxt
    if extra is not None:
        p, cost, order, width = extra
        options.append(_option(planner, order, width, min(width, cap), p, cost))
    bayes, most = choose_indices(tuple(options))
    return PlanReport(problem, tuple(options), bayes, most, "exact")


def _option(
    planner: _Planner,
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
    return _chain_option(planner.problem, chain, tolerance, placed, p, cost, chain[0].width)


def _chain_option(
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
    length ``placed`` is largest; the success arc is reported ``arc`` long from there.
    """
    _, start = problem.prior.max_arc_mass(placed, problem.goal_group, prefer=chain[0].lo)
    angles = [start - chain[0].lo]
    for prev, w in itertools.pairwise(chain):
        # Centre the image [s_first, s_last] of the previous arc inside this witness.
        angles.append(0.5 * (prev.s_first + prev.s_last) - 0.5 * (w.lo + w.hi))
    steps, turned = _short_turns(tuple(a.kind for a in chain), angles)
    final = math.fmod(chain[-1].s_first + turned + TWO_PI, TWO_PI)
    return PlanOption(tuple(steps), final, p, cost, tolerance, (start, start + arc))


def _short_turns(kinds: tuple[str, ...], angles: list[float]) -> tuple[list[PlanStep], float]:
    """Steps with each squeeze's gripper angle in ``(-pi/2, pi/2]``, and the final frame's turn.

    A squeeze gripper turned by pi is the same gripper with its jaws swapped: the part then
    lies pi further round in its frame, and stays pi further round after the squeeze
    (``s(theta + pi) = s(theta) + pi``). So a squeeze angle may change by pi if the next
    angle changes by pi too (or, after the last action, the final orientation). A push-grasp
    has a pushing side, so its angle keeps whatever it receives.
    """
    steps = []
    carry = 0.0  # how much further round the part lies in the current frame
    for kind, angle in zip(kinds, angles, strict=True):
        a = _wrap(angle + carry)
        carry = 0.0
        if kind == "squeeze":
            short = _wrap(2.0 * a) / 2.0  # in (-pi/2, pi/2]
            carry = a - short  # 0 or +-pi
            a = short
        steps.append(PlanStep(kind, a))
    return steps, carry


def _wrap(a: float) -> float:
    """Angle in (-pi, pi]."""
    r = math.remainder(a, TWO_PI)
    return math.pi if r == -math.pi else r
