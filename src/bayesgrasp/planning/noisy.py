"""The Bayes plan under noisy actions and a payoff (the seed, section 6.4).

Under a noise model (:mod:`bayesgrasp.model.noise`: turn error, contact asynchrony) every
action is a row-stochastic (K, K) matrix ``M_t(alpha)`` that depends smoothly (normal error)
or piecewise linearly (uniform error) on the turn, so a plan's outcome is no longer fixed by
finitely many action classes. A plan of actions ``t_1..t_k`` at angles ``a, alpha_2..alpha_k``
ends in the distribution

    q_k = q_1(a) M_{t_2}(alpha_2) ... M_{t_k}(alpha_k)

(``q_1`` the prior convolved with the first action, :meth:`NoisyTransitions.initial`), and
earns ``E[payoff] = q_k . u``: ``u`` the payoff vector (:mod:`bayesgrasp.model.payoff`), or
for today's goal the indicator of the best final state (of its symmetry orbit for a symmetry
goal). The plan's cost is ``E[cycle cost] / E[payoff]``
(:meth:`~bayesgrasp.model.cost.CostModel.expected_cost` with ``E[payoff]`` as ``p``; for a
0/1 payoff the seed's ``C / p``). The Bayes plan minimises it.

How the plan is found, for each length ``k``:

1. *Seeds*: the noise-free exact planner's plans (:func:`~.exact.plan_exact`), and those it
   gives with a gripper accuracy of :data:`ACCURACY_SEEDS` times the error's scale (robust
   plans).
2. *Hyperstate search* (the seed's breadth-first search, section 5, generalised to
   stochastic transfers): a hyperstate is the distribution ``q`` after some actions; its
   children are ``q M_t(alpha)`` for every action kind ``t`` and the middle ``alpha`` of
   every noise-free action class (:meth:`~bayesgrasp.model.problem.Problem.classes`). The
   children no longer collapse onto few distinct distributions, so each level keeps the
   ``beam`` most valuable ones (value: the payoff they would earn if the plan ended there).
3. *Continuous refinement* of the best candidates of each length, one turn at a time:
   ``f(alpha_m) = q_{m-1} M(alpha_m) r_m`` with ``r_m = M(alpha_{m+1}) ... M(alpha_k) u``
   is maximised over the turn's whole range ``(-g/2, g/2]``. Uniform error: ``f`` is
   piecewise linear with kinks at ``S_i - B - o +- A`` (state ``S_i``, basin boundary ``B``,
   contact offset ``o``), so its maximum over the kinks is exact (the middle of a flat top
   is kept). Exact turns (contact noise alone): ``f`` is constant between the critical
   turns ``S_i - B - o``; the middles of the arcs between *all* of them (every boundary of
   every way the action may go, for every state of positive probability, whether or not
   its two sides are worth the same) are tried, and the widest arc of the best value wins
   (exact). Normal error: ``f`` on a
   grid of step ``h = sigma / 6`` within ``8 sigma`` of the critical turns (farther, ``f`` is
   flat to 1e-15: one point a gap) then a grid of step ``h / 32`` around the best point;
   since ``|f''| <= 2 phi(1) / sigma^2``
   (:attr:`~bayesgrasp.model.noise.TurnNoise.curvature_bound`) the grid's best is within
   ``eps = |f''|max h^2 / 8 = 1.7e-3`` of the turn's global maximum. A turn is optimised
   again only after another turn or the target changed, for at most :data:`MAX_SWEEPS`
   sweeps.
4. *Exact evaluation*: every candidate's distribution, payoff and cost are matrix products
   (:func:`evaluate_plan`), nothing is sampled.

Unstable equilibria (exact turns). A turn that puts a state of positive probability exactly
on a basin boundary (a maximum of the diameter function, or of the radius function for a
push-grasp from one jaw) leaves it on an unstable equilibrium: the matrices send it to one
side (their intervals are half-open), a squeeze to either side or nowhere (it jams), so a
plan built on one claims what no gripper does. With exact turns no candidate keeps such a
turn: the search's class middles that fall on a boundary (under contact noise, a
push-grasp's boundary may fall inside a squeeze's action class) are replaced by the middles
of the arcs beside it, a seed's turn on a boundary is moved to the middle of the arc beside
it whose plan earns more, and the refinement chooses among the arcs between all boundaries.
Each plan reports its margin as its ``tolerance``: the least distance of a turn
``alpha_2..alpha_k`` to a boundary turn of a state of positive probability before it, so
that turn errors below it, on every turn at once, change no state's outcome. (With a turn
error a boundary is met with probability 0, and the tolerance is ``None``.)

The guarantee (:attr:`NoisyPlanResult.refinement_bound`):

- every reported probability, payoff and cost is exact for the noise model (to rounding;
  under a non-uniform prior the first action's average over its own error is a
  composite 512-node Gauss-Legendre rule);
- the plan of each length is the best of its candidate set, and each refined plan is
  coordinate-wise optimal: changing any one turn ``alpha_2..alpha_k`` gains at most ``eps``
  in ``E[payoff]`` (0 for the uniform error, whose one-turn maxima are exact; 0 for exact
  turns, among the turns that keep every state off an unstable equilibrium). The first
  angle is not refined: under a non-uniform prior it is one of the exact planner's
  placements of the arc on the prior (with the error, those are seeds, not optima);
- the lengths searched are enough: the search stops at the first length ``k`` where the
  cheapest attempt of ``k + 1`` actions, at the highest attainable payoff (the largest entry
  of ``u``; for today's goal without contact noise, the noise-free bound: averaging over
  errors cannot beat the best deterministic plan, so ``p <= max prior mass of an arc of the
  period``), already costs more than the best plan found, and not before the length of
  the noise-free most certain plan (so the most certain plan under the noise is chosen
  among at least the lengths the exact planner reports);
- not guaranteed: the global maximum over all turns at once (the payoff is a multimodal
  function of the turns). The tests compare the planner with a brute-force grid over the
  turns of every plan of up to 3 actions, within the grid's resolution bound
  ``peak_density * h * (k - 1) / 2`` (``|d f / d alpha_m| <= sup density``).

With no noise at all (and the problem's goal, no payoff) the planner returns the exact
planner's result as it is: the same options (tolerances included), Bayes and most certain
plans, each evaluated by the matrices for the noise-specific fields.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, wrap_period
from ..errors import PlanningError
from ..model.noise import NoiseModel
from ..model.payoff import Payoff, as_vector
from ..model.prior import UniformPrior
from ..model.problem import Problem, nearest_state
from .exact import plan_exact
from .noisy_evaluation import (
    NoisyEvaluation,
    PlanEvaluator,
    evaluate_plan,
    step_distributions_noisy,
)
from .noisy_result import NoisyOption, NoisyPlanResult
from .result import (
    PlanOption,
    PlanStep,
    check_max_actions,
    choose_indices,
    max_plan_length,
    plan_actions,
    short_turns,
)
from .turns import FLAT_SIGMAS, GRID_PER_SIGMA, free_arcs, margin, turn_grid

__all__ = [
    "NoisyEvaluation",
    "NoisyOption",
    "NoisyPlanResult",
    "PlanEvaluator",
    "evaluate_plan",
    "plan_noisy",
    "step_distributions_noisy",
]  # the evaluation and result types are importable from here too

FloatArray = NDArray[np.float64]

ACCURACY_SEEDS = (2.0,)
"""Seeds: the exact planner's plans with a gripper accuracy of these many error scales."""
TIE_RTOL = 1e-9
"""Costs closer than this (relative) tie: the earlier candidate (an exact seed) is kept."""
MAX_SWEEPS = 4
"""Most sweeps over the turns in the refinement of one plan."""
_GAIN_TOL = 1e-12


@dataclass(slots=True)
class _Cand:
    kinds: tuple[str, ...]
    angles: list[float]
    source: str
    ev: NoisyEvaluation | None = None
    prefer: int | None = None  # the final state of an exact seed (kept on ties)


def _periods(problem: Problem, kinds: Sequence[str]) -> list[float]:
    return [a.gripper_period for a in plan_actions(problem, kinds)]


def _short(problem: Problem, kinds: Sequence[str], angles: Sequence[float]) -> list[float]:
    """Angles in their reported ranges, with any carry absorbed (see :func:`short_turns`)."""
    steps, carry = short_turns(plan_actions(problem, kinds), angles)
    if carry != 0.0:  # the last frame is turned by pi: not the same plan for a payoff
        return [float(a) for a in angles]
    return [s.alpha for s in steps]


class _Planner:
    def __init__(self, problem: Problem, noise: NoiseModel, payoff: FloatArray | None) -> None:
        self.problem = problem
        self.noise = noise
        self.ev = PlanEvaluator(problem, noise, payoff)
        self.turn = noise.turn
        self.p_tol = problem.part.hull.tol.probability
        self.a_tol = problem.states.angle_tol

    # -- unstable equilibria ---------------------------------------------------------------
    def margins(self, kinds: Sequence[str], angles: Sequence[float]) -> list[float]:
        """Each turn's distance to the nearest boundary turn of a state it may meet.

        Entry ``m - 1`` is turn ``alpha_m``'s (``m >= 2``): the states of positive
        probability before it (under the noise), every way its action may go.
        """
        periods = _periods(self.problem, kinds)
        qs = self.ev.forward(kinds, angles)
        return [
            margin(
                angles[m],
                self.ev.boundary_turns(kinds[m], np.flatnonzero(qs[m - 1] > 0)),
                periods[m],
            )
            for m in range(1, len(kinds))
        ]

    def off_edges(
        self, kinds: Sequence[str], angles: Sequence[float]
    ) -> tuple[list[float], bool, FloatArray]:
        """The turns, each moved off the unstable equilibria of the states it meets.

        A turn (exact turns) within the angle tolerance of a boundary turn of a state of
        positive probability (for the first action: of an atom of a sample prior) is moved
        to the middle of one of the two arcs beside that boundary, the one whose plan (the
        other turns as they are) earns more. Returns the turns, whether any moved, and the
        final distribution of the plan they make.
        """
        out = list(angles)
        periods = _periods(self.problem, kinds)
        atoms = getattr(self.problem.prior, "angles", None)  # a sample prior's atoms
        moved = False
        q = np.zeros(0)
        for m in range(len(kinds)):
            if m == 0:
                # The first action meets the prior itself: only atoms can sit on a boundary
                # (a density puts no mass on a point), at world angles ``x - o - B``.
                if atoms is None:
                    q = self.ev.nt.initial(kinds[0], out[0])
                    continue
                bounds = np.concatenate(
                    [
                        (np.asarray(atoms)[:, None] - c.offset - c.hi[None, :]).ravel()
                        for c in self.ev.nt.components(kinds[0])
                    ]
                )
            else:
                bounds = self.ev.boundary_turns(kinds[m], np.flatnonzero(q > 0))
            if margin(out[m], bounds, periods[m]) <= self.a_tol:
                starts, mids, _ = free_arcs(bounds, periods[m], self.a_tol)
                d = np.abs(np.mod(starts - out[m] + periods[m] / 2, periods[m]) - periods[m] / 2)
                j = int(np.argmin(d))
                best_v = -math.inf
                for x in (float(mids[j - 1]), float(mids[j])):
                    trial = [*out[:m], wrap_period(x, periods[m]), *out[m + 1 :]]
                    v = float(self.ev.value(self.ev.forward(kinds, trial)[-1]))
                    if v > best_v + self.p_tol:
                        best_v, out = v, trial
                moved = True
            if m == 0:
                q = self.ev.nt.initial(kinds[0], out[0])
            else:
                q = self.ev.step(q, kinds[m], np.array([out[m]]))[0]
        return out, moved, q

    def search_turns(self, kind: str, mids: FloatArray, period: float) -> FloatArray:
        """The search's turns for ``kind``: each on a boundary turn of any state replaced.

        The middles of the noise-free action classes keep away from the transfer's own
        boundaries; under contact noise a push-grasp's boundary may fall on one. Such a turn
        is replaced by the middles of the two arcs beside it (between all boundary turns).
        """
        bounds = self.ev.boundary_turns(kind)
        starts, free, _ = free_arcs(bounds, period, self.a_tol)
        out: list[float] = []
        for x in mids:
            if margin(float(x), bounds, period) > self.a_tol:
                out.append(float(x))
                continue
            d = np.abs(np.mod(starts - x + period / 2, period) - period / 2)
            j = int(np.argmin(d))
            out += [wrap_period(float(free[j - 1]), period), wrap_period(float(free[j]), period)]
        return np.array(list(dict.fromkeys(out)), dtype=np.float64)

    # -- refinement -----------------------------------------------------------------------
    def _right(
        self, kinds: Sequence[str], angles: Sequence[float], m: int, u: FloatArray
    ) -> FloatArray:
        """``r_m = M(alpha_{m+1}) ... M(alpha_k) u`` (applied right to left)."""
        r = u.copy()
        for t, a in zip(kinds[m + 1 :][::-1], angles[m + 1 :][::-1], strict=True):
            r = self.ev.nt.matrix(t, a) @ r
        return r

    def _line(
        self, kind: str, left: FloatArray, right: FloatArray, alphas: FloatArray
    ) -> FloatArray:
        """``f(alpha) = left M(alpha) right`` at many turns."""
        return self.ev.nt.line(kind, left, right, alphas)

    def _best_turn(
        self,
        kind: str,
        period: float,
        left: FloatArray,
        right: FloatArray,
        current: float,
        f0: float,
    ) -> tuple[float, float]:
        """The turn of largest ``f`` over ``(-g/2, g/2]`` and its value (``f0`` at ``current``)."""
        turn = self.turn
        if turn.exact:
            # Exact turns (contact noise only): f is constant between the turns that put a
            # state of positive probability on a basin boundary of any way the action may
            # go. Between the critical turns alone (boundaries where the value changes) a
            # middle may sit on a boundary where it does not: an unstable equilibrium, which
            # the matrices send to one side and a squeeze to either or neither. So the
            # middles of the arcs between *all* boundaries are tried: the widest of the best.
            rows = np.flatnonzero(left > 0)
            bounds = self.ev.boundary_turns(kind, rows)
            _, mids, half = free_arcs(bounds, period, self.a_tol)
            vals = self._line(kind, left, right, mids)
            top = np.flatnonzero(vals >= vals.max() - self.p_tol)
            i = int(top[np.argmax(half[top])])
            best, fb = float(mids[i]), float(vals[i])
            if margin(current, bounds, period) <= self.a_tol:
                # The current turn's value is one side's, not what a squeeze does: move.
                return wrap_period(best, period), fb
        elif turn.kind == "uniform":
            crit = self.ev.nt.critical(kind, left, right)
            pts = (crit[:, None] + np.array([-turn.scale, turn.scale])).ravel()
            kinks = np.unique(np.mod(pts + period / 2, period)) - period / 2
            if kinks.size == 0:
                # No state meets a basin boundary within the error's reach: the error spans
                # the whole period, so every turn leaves the same distribution.
                return current, f0
            vals = self._line(kind, left, right, kinks)
            top = vals.max()
            at = np.flatnonzero(vals >= top - self.p_tol)
            # The longest run of consecutive kinks at the top is a flat segment: its middle.
            runs = np.split(at, np.flatnonzero(np.diff(at) != 1) + 1)
            run = max(runs, key=lambda r: kinks[r[-1]] - kinks[r[0]])
            best = 0.5 * (kinks[run[0]] + kinks[run[-1]])
            fb = float(self._line(kind, left, right, np.array([best]))[0])
            if fb < top - self.p_tol:  # pragma: no cover - a flat run is flat
                best, fb = float(kinks[run[0]]), float(top)
        else:
            h = turn.scale / GRID_PER_SIGMA
            crit = self.ev.nt.critical(kind, left, right)
            grid = turn_grid(crit, period, h, FLAT_SIGMAS * turn.scale)
            vals = self._line(kind, left, right, grid)
            i = int(np.argmax(vals))
            best, fb = float(grid[i]), float(vals[i])
            # A finer grid around the best point (resolution h / 32).
            width = h
            fine = best + width * np.linspace(-1.0, 1.0, 65)
            fv = self._line(kind, left, right, fine)
            j = int(np.argmax(fv))
            if fv[j] > fb:
                best, fb = float(fine[j]), float(fv[j])
        if fb > f0 + _GAIN_TOL:
            return wrap_period(best, period), fb
        return current, f0

    def refine(self, cand: _Cand) -> _Cand:
        """Coordinate ascent over the turns (see the module notes)."""
        kinds, angles = cand.kinds, list(cand.angles)
        if len(kinds) < 2 or (self.turn.exact and self.noise.contact == 0):
            return cand
        periods = _periods(self.problem, kinds)
        moved = False
        ev = cand.ev or self.ev.evaluate(kinds, angles, cand.prefer)
        # A turn is optimised again only after another turn (or the target) has changed:
        # with the rest fixed its line, and so its best value, is the same.
        stale = set(range(1, len(kinds)))
        qs = self.ev.forward(kinds, angles)
        for _ in range(MAX_SWEEPS):
            u = ev.target
            for m in range(1, len(kinds)):
                if m not in stale:
                    continue
                stale.discard(m)
                right = self._right(kinds, angles, m, u)
                f0 = float(qs[m] @ right)
                new, _ = self._best_turn(kinds[m], periods[m], qs[m - 1], right, angles[m], f0)
                if new != angles[m]:
                    angles[m] = new
                    for j in range(m, len(kinds)):
                        qs[j] = self.ev.step(qs[j - 1], kinds[j], np.array([angles[j]]))[0]
                    stale |= set(range(1, len(kinds))) - {m}
                    moved = True
            # The target is chosen again: the payoff can only rise.
            ev = self.ev.finish(kinds, qs[-1], cand.prefer)
            if not np.array_equal(ev.target, u):
                stale = set(range(1, len(kinds)))
            if not stale:
                break
        if not moved:
            return dataclasses.replace(cand, ev=ev)
        return _Cand(kinds, angles, cand.source + "+refined", ev, cand.prefer)


def _cost(c: _Cand) -> float:
    if c.ev is None:  # pragma: no cover - every candidate is evaluated before it is ranked
        raise PlanningError("internal error: a plan was ranked before it was evaluated")
    return c.ev.expected_cost


def _ranked(cands: list[_Cand]) -> list[_Cand]:
    """Candidates by cost per unit payoff, then payoff (stable: seeds stay first on ties)."""
    return sorted(cands, key=lambda c: (_cost(c), -c.ev.expected_payoff))  # type: ignore[union-attr]


def _best(cands: list[_Cand], p_tol: float) -> _Cand:
    """The least cost; among costs tied within ``TIE_RTOL``, the highest payoff, then the first.

    So a seed of the exact planner (listed first) wins a tie with a later candidate.
    """
    m = min(_cost(c) for c in cands)
    tied = [c for c in cands if _cost(c) <= m * (1.0 + TIE_RTOL)] if math.isfinite(m) else cands
    top = max(c.ev.expected_payoff for c in tied)  # type: ignore[union-attr]
    return next(c for c in tied if c.ev.expected_payoff >= top - p_tol)  # type: ignore[union-attr]


def _seeds(problem: Problem, noise: NoiseModel, max_actions: int | None) -> list[_Cand]:
    """The exact planner's plans, noise-free and with accuracies of 1-3 error scales."""
    out = []
    runs: list[tuple[float, str]] = [(problem.accuracy, "exact")]
    if not noise.turn.exact:
        runs += [(problem.accuracy + m * noise.turn.scale, "accuracy") for m in ACCURACY_SEEDS]
    for acc, label in runs:
        pb = problem if acc == problem.accuracy else dataclasses.replace(problem, accuracy=acc)
        res = plan_exact(pb, max_actions)
        out += [
            _Cand(
                o.kinds,
                [s.alpha for s in o.steps],
                label,
                prefer=int(nearest_state(problem.states, np.array([o.final_orientation]))[0]),
            )
            for o in res.options
        ]
    return out


def _payoff_bound(problem: Problem, ev: PlanEvaluator, payoff: FloatArray | None) -> float:
    """The highest expected payoff any plan can reach (see the module notes)."""
    noise = ev.noise
    targets = ev.masks if payoff is None else payoff[None, :]  # (T, K)
    if noise.contact > 0:
        squeezes = all(math.isclose(a.gripper_period, math.pi) for a in problem.actions)
        if squeezes and isinstance(problem.prior, UniformPrior) and ev.half is not None:
            # Every action commutes with the turn by pi (the contact events are symmetric)
            # and the uniform prior is invariant under it, so is the final distribution q:
            # q . v = q . (v + v o pi) / 2 <= max of (v + v o pi) / 2.
            return float(np.max(0.5 * (targets + targets[:, ev.half])))
        return float(targets.max())
    if payoff is not None:
        return float(payoff.max())
    # Averaging over the errors cannot beat the best plan with exact turns.
    period = max(problem.transfer(t).period for t in problem.action_kinds)
    group = problem.goal_group
    p, _ = problem.prior.max_arc_mass(min(period, TWO_PI / group), group)
    return min(1.0, float(p))


def plan_noisy(
    problem: Problem,
    noise: NoiseModel,
    payoff: Payoff | FloatArray | None = None,
    max_actions: int | None = None,
    *,
    beam: int = 6,
    refine: int = 2,
    all_lengths: bool = False,
) -> NoisyPlanResult:
    """The Bayes plan (least expected cost per unit payoff) under a noise model.

    See the module notes for the method and its guarantee.

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel
    payoff : Payoff or array of shape (K,), optional
        Payoff of each final state (default: the problem's goal).
    max_actions : int, optional
        Longest plan (default: until longer plans cannot cost less).
    beam : int
        Hyperstates kept per level of the search.
    refine : int
        Candidates of each length refined continuously.
    all_lengths : bool
        Search every length up to ``max_actions`` (which is then required) even where
        longer plans cannot cost less.

    Returns
    -------
    NoisyPlanResult

    Raises
    ------
    PlanningError
        ``max_actions``, ``beam`` or ``refine`` below 1, or a bad payoff.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
    >>> res = plan_noisy(Problem.build(rect), NoiseModel(TurnNoise("normal", math.radians(5))))
    >>> [round(o.option.success_probability, 4) for o in res.options]
    [0.3176, 0.4964]
    """
    check_max_actions(max_actions)
    if all_lengths and max_actions is None:
        raise PlanningError("`all_lengths` needs `max_actions`")
    if beam < 1 or refine < 1:
        raise PlanningError(f"`beam` and `refine` must be at least 1; got {beam} and {refine}")
    u = None if payoff is None else as_vector(payoff, problem.states)
    pl = _Planner(problem, noise, u)
    ev = pl.ev
    if noise.exact and u is None and not all_lengths:
        return _noise_free(problem, noise, max_actions, pl)
    exact = ev if noise.exact else PlanEvaluator(problem, NoiseModel(), u)
    cost = problem.cost
    kinds_all = problem.action_kinds
    limit = min(max_plan_length(problem), max_actions or max_plan_length(problem))
    seeds = _seeds(problem, noise, max_actions)
    # The noise-free planner's lengths (up to its most certain plan) are always searched.
    reach = max(len(c.kinds) for c in seeds if c.source == "exact")
    bound = _payoff_bound(problem, ev, u)
    first_kind = min(kinds_all, key=lambda t: cost.action_cost(t, first=True))
    next_kind = min(kinds_all, key=lambda t: cost.action_cost(t))
    # Hyperstate search: level 1 is the first action at each seed's first angle.
    firsts = dict.fromkeys((c.kinds[0], c.angles[0]) for c in seeds)
    if isinstance(problem.prior, UniformPrior):
        firsts = dict.fromkeys((t, 0.0) for t in kinds_all)
    level = [_Cand((t,), [a], "search") for t, a in firsts]
    level_q = [ev.nt.initial(t, a) for t, a in firsts]
    mids = {
        t: np.array([wrap_period(float(x), a.gripper_period) for x in problem.classes(t).mid])
        for t, a in zip(kinds_all, plan_actions(problem, kinds_all), strict=True)
    }
    if noise.turn.exact:  # no turn may put a state on an unstable equilibrium
        for t, a in zip(kinds_all, plan_actions(problem, kinds_all), strict=True):
            mids[t] = pl.search_turns(t, mids[t], a.gripper_period)
    # Without noise the exact planner's plans are the best of each length (it is exact):
    # the search is needed only for a payoff, which it does not know.
    search = not noise.exact or u is not None
    options: list[NoisyOption] = []
    best_cost = math.inf
    k = 0
    while k < limit:
        k += 1
        if k > 1 and search:  # expand the beam
            children: list[tuple[float, _Cand, FloatArray]] = []
            for cand, q in zip(level, level_q, strict=True):
                for t in kinds_all:
                    qs = ev.step(q, t, mids[t])
                    vals = ev.value(qs)
                    for i in np.argsort(-vals)[: 2 * beam]:
                        c = _Cand((*cand.kinds, t), [*cand.angles, float(mids[t][i])], "search")
                        children.append((float(vals[i]), c, qs[i]))
            children.sort(key=lambda x: -x[0])
            seen: set[bytes] = set()
            level, level_q = [], []
            for _, c, q in children:
                key = np.round(q, 9).tobytes()
                if key in seen:
                    continue
                seen.add(key)
                level.append(c)
                level_q.append(q)
                if len(level) >= beam:
                    break
        cands = [c for c in seeds if len(c.kinds) == k]
        if search:
            cands += level
        for c in cands:
            if c.source == "search":  # seeds are in their short form already
                c.angles = _short(problem, c.kinds, c.angles)
            if noise.turn.exact:
                c.angles, moved, q_end = pl.off_edges(c.kinds, c.angles)
                if moved:
                    c.source += "+refined"
                c.ev = ev.finish(c.kinds, q_end, c.prefer)
            else:
                c.ev = ev.evaluate(c.kinds, c.angles, c.prefer)
        cands = _ranked(cands)
        refined: list[_Cand] = []
        done: set[tuple[tuple[str, ...], tuple[float, ...]]] = set()
        for c in cands:
            plan_key = (c.kinds, tuple(np.round(c.angles, 9).tolist()))
            if plan_key in done:
                continue
            done.add(plan_key)
            refined.append(pl.refine(c))
            if len(refined) >= refine:
                break
        best = _best(cands + refined, pl.p_tol)
        least = None
        if noise.turn.exact and k > 1:
            least = min(pl.margins(best.kinds, best.angles))
        options.append(_noisy_option(problem, exact, best, least))
        best_cost = min(best_cost, best.ev.expected_cost)  # type: ignore[union-attr]
        cheapest_next = cost.expected_cost((first_kind,) + (next_kind,) * k, bound)
        if not all_lengths and k >= reach and cheapest_next >= best_cost * (1.0 - 1e-12):
            break
    plans = tuple(o.option for o in options)
    bayes, most = choose_indices(plans, pl.p_tol)
    # The most certain: highest expected payoff (choose_indices reads success_probability).
    pays = np.array([o.expected_payoff for o in options])
    most = int(np.flatnonzero(pays >= pays.max() - pl.p_tol)[0])
    turn = noise.turn
    if turn.exact or turn.kind == "uniform":
        eps = 0.0
    else:
        h = turn.scale / GRID_PER_SIGMA
        eps = turn.curvature_bound * h * h / 8.0
    return NoisyPlanResult(problem, noise, u, tuple(options), bayes, most, ev.evaluated, eps, bound)


def _noise_free(
    problem: Problem, noise: NoiseModel, max_actions: int | None, pl: _Planner
) -> NoisyPlanResult:
    """Without noise, for the problem's goal: the exact planner's result, evaluated.

    The exact planner is exact for this case (its plans are the best of each length, up to
    the most certain), so its options are reported as they are, tolerances included, and
    each is evaluated by the matrices for the noise-specific fields.
    """
    res = plan_exact(problem, max_actions)
    options = []
    for o in res.options:
        prefer = int(nearest_state(problem.states, np.array([o.final_orientation]))[0])
        e = pl.ev.evaluate(o.kinds, [s.alpha for s in o.steps], prefer)
        options.append(NoisyOption(o, e, e.expected_payoff, "exact"))
    bound = _payoff_bound(problem, pl.ev, None)
    return NoisyPlanResult(
        problem,
        noise,
        None,
        tuple(options),
        res.bayes,
        res.most_certain,
        pl.ev.evaluated,
        0.0,
        bound,
    )


def _noisy_option(
    problem: Problem, exact: PlanEvaluator, c: _Cand, tolerance: float | None = None
) -> NoisyOption:
    """The reported plan of a candidate (``exact``: an evaluator without noise).

    ``tolerance``: with exact turns, the plan's least margin (:meth:`_Planner.margins`).
    """
    e = c.ev
    if e is None:  # pragma: no cover - every candidate is evaluated before it is chosen
        raise PlanningError("internal error: a plan was chosen before it was evaluated")
    steps = tuple(PlanStep(t, a) for t, a in zip(c.kinds, c.angles, strict=True))
    q0 = exact.forward(c.kinds, c.angles)[-1]
    p0 = float(q0 @ e.target)
    final = float(problem.states.stable[e.final_state])
    arc = _success_arc(problem, steps, e.target)
    opt = PlanOption(steps, final, e.success_probability, e.expected_cost, tolerance, arc)
    return NoisyOption(opt, e, p0, c.source)


def _success_arc(
    problem: Problem, steps: tuple[PlanStep, ...], target: FloatArray
) -> tuple[float, float]:
    """The widest run of first-action basins that the noise-free steps send to the target."""
    from .result import execute_plan

    f = problem.transfer(steps[0].kind)
    a = steps[0].alpha
    ends = execute_plan(problem, steps[1:], f.stable)
    from ..model.states import nearest_state

    good = target[nearest_state(problem.states, ends)] > 0
    n = len(good)
    if not good.any():
        return (a, a)
    if good.all():
        return (float(f.basin_lo[0]) + a, float(f.basin_lo[0]) + a + TWO_PI)
    start = int(np.flatnonzero(~good)[0])
    order = (np.arange(n) + start) % n
    best_len, best_run, run = 0.0, None, []
    for i in [*order, start]:
        if good[i]:
            run.append(i)
            continue
        if run:
            width = float(np.sum(f.basin_hi[run] - f.basin_lo[run]))
            if width > best_len:
                best_len, best_run = width, list(run)
        run = []
    if best_run is None:  # pragma: no cover - some basin is good and some is not
        return (a, a)
    lo = float(f.basin_lo[best_run[0]]) + a
    return (lo, lo + best_len)
