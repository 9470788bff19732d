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
length ``L(seq')``). The last action alone collapses exactly one basin. ``L`` grows with the
allowed arc, so for a fixed count of each action type only the order of the *first* action
matters for cost; the rest takes the type that gives the widest arc.

Success probability: the plan collapses an open arc of length ``L`` placed anywhere by the
gripper angle of the first action, so ``p = max over placements of the prior mass of that
arc`` (with a symmetry goal, of the arc and its copies ``2 pi / r`` apart). Under the uniform
prior ``p = L / (2 pi)`` (times ``r``). Expected cost is ``CostModel.expected_cost``.

Angles come from chaining the witness arcs: the image of one witness, of span ``w``, is placed
in the middle of the next witness, of length ``L'``, so each relative rotation may err by
``(L' - w) / 2`` without changing the outcome; the plan's tolerance is the least of these.
The witnesses are chosen among the widest arcs as those of least span, which maximises every
margin. Cost: O(K log K) per (count, type), K stable orientations.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import PlanningError
from ..problem import Problem
from ..transfer import TransferFunction
from .plan import PlanOption, PlanReport, PlanStep, choose_indices

__all__ = ["plan_exact"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, slots=True)
class _Witness:
    """Widest collapsible arc for a count of actions whose first action is ``kind``."""

    width: float
    kind: str
    lo: float  # arc (lo, hi) in the frame of this action, before it
    hi: float
    s_first: float  # its image: the stable orientations from s_first to s_last
    s_last: float


def _widest(f: TransferFunction, limit: float, tol: float) -> _Witness:
    """Widest boundary-to-boundary arc of ``f`` whose stable orientations span < ``limit``."""
    k = f.n_states
    s = np.concatenate([f.stable, f.stable + TWO_PI])  # (2K,)
    lo = f.basin_lo
    hi = np.concatenate([f.basin_hi, f.basin_hi + TWO_PI])
    i = np.arange(k)
    j = np.searchsorted(s, f.stable + (limit - 2.0 * tol), side="left") - 1
    j = np.clip(j, i, i + k - 1)  # (K,) last basin of the arc starting at basin i
    width = hi[j] - lo
    span = s[j] - f.stable
    best = width.max()
    cand = np.flatnonzero(width >= best - tol)
    m = int(cand[np.argmin(span[cand])])
    jm = int(j[m])
    return _Witness(float(best), f.kind, float(lo[m]), float(hi[jm]), float(s[m]), float(s[jm]))


def _wrap(a: float) -> float:
    """Angle in (-pi, pi]."""
    r = math.remainder(a, TWO_PI)
    return math.pi if r == -math.pi else r


def plan_exact(problem: Problem, max_actions: int | None = None) -> PlanReport:
    """Best plans of every length, exactly, for any prior, cost model and goal.

    Parameters
    ----------
    problem : Problem
    max_actions : int, optional
        Stop after plans of this many actions even if more would raise the success
        probability (default: go on until the highest attainable probability).

    Returns
    -------
    PlanReport

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
    >>> rep = plan_exact(Problem.build(rect))
    >>> [round(o.expected_cost, 1) for o in rep.options], rep.bayes
    ([6.3, 6.0], 1)
    """
    if max_actions is not None and max_actions < 1:
        raise PlanningError(f"`max_actions` must be at least 1; got {max_actions}")
    tol = problem.states.angle_tol
    group = problem.goal_group
    prior = problem.prior
    kinds = problem.action_kinds
    transfers = problem.transfers
    cap = min(max(transfers[t].period for t in kinds), TWO_PI / group)
    p_best, _ = prior.max_arc_mass(cap, group)

    counts_of = {t: i for i, t in enumerate(kinds)}
    zero = (0,) * len(kinds)
    best: dict[tuple[int, ...], _Witness] = {}  # widest arc for each count of action types
    options: list[PlanOption] = []
    level: list[tuple[int, ...]] = [zero]
    limit_hard = 4 * problem.part.hull.n_sides + 8
    k = 0
    while True:
        k += 1
        nxt: dict[tuple[int, ...], None] = {}
        candidates: list[tuple[tuple[int, ...], _Witness]] = []
        for rest in level:
            for t in kinds:
                counts = list(rest)
                counts[counts_of[t]] += 1
                key = tuple(counts)
                limit = best[rest].width if rest != zero else 3.0 * tol
                w = _widest(transfers[t], limit, tol)
                candidates.append((key, w))
                nxt[key] = None
                if key not in best or w.width > best[key].width + tol:
                    best[key] = w
        scored = []
        for key, w in candidates:
            p, start = prior.max_arc_mass(min(w.width, cap), group, prefer=w.lo)
            chain = _chain(best, key, w, counts_of)
            cost = problem.cost.expected_cost(tuple(x.kind for x in chain), p)
            scored.append((p, cost, key, chain, start))
        top_p = max(s[0] for s in scored)
        done = top_p >= p_best - 1e-12 or (max_actions is not None and k >= max_actions)
        if done:  # the last level shows its most certain plan
            pick = min(scored, key=lambda s: (-round(s[0], 12), s[1]))
        else:
            pick = min(scored, key=lambda s: (s[1], -s[0]))
        options.append(_option(pick[0], pick[1], pick[3], pick[4]))
        if done:
            break
        if k >= limit_hard:  # pragma: no cover - Goldberg 1993 bounds plans by O(n)
            raise PlanningError(f"no plan reached probability {p_best:.6f} in {k} actions")
        level = list(nxt)
    bayes, most = choose_indices(tuple(options))
    return PlanReport(problem, tuple(options), bayes, most, "exact")


def _chain(
    best: dict[tuple[int, ...], _Witness],
    key: tuple[int, ...],
    first: _Witness,
    counts_of: dict[str, int],
) -> list[_Witness]:
    """Witness arcs of a plan, first action first."""
    chain = [first]
    counts = list(key)
    counts[counts_of[first.kind]] -= 1
    while any(counts):
        w = best[tuple(counts)]
        chain.append(w)
        counts[counts_of[w.kind]] -= 1
    return chain


def _option(p: float, cost: float, chain: list[_Witness], start: float) -> PlanOption:
    """Turn a chain of witness arcs into concrete angles, margins and the final orientation."""
    steps = [PlanStep(chain[0].kind, _wrap(start - chain[0].lo))]
    margins = []
    for prev, w in itertools.pairwise(chain):
        # Centre the image [s_first, s_last] of the previous arc inside this witness.
        alpha = 0.5 * (prev.s_first + prev.s_last) - 0.5 * (w.lo + w.hi)
        steps.append(PlanStep(w.kind, _wrap(alpha)))
        margins.append(0.5 * (w.width - (prev.s_last - prev.s_first)))
    final = math.fmod(chain[-1].s_first, TWO_PI)
    tolerance = min(margins) if margins else None
    arc = (start, start + chain[0].width)
    return PlanOption(tuple(steps), final, p, cost, tolerance, arc)
