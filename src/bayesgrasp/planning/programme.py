"""The Bayes-policy programme: a dynamic programme over beliefs at a price of success.

What :func:`~bayesgrasp.planning.policy.plan_policy` (and under noisy actions
:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`) solves at each parametric
step: for a price ``lambda`` of success, ``V(q, r)``, the least ``c - lambda P`` per unit
mass over the continuations of ``r`` actions from the belief ``q`` (distribution over the
joint states after the last reading), with its bounds, budgets (cuts) and floors. The
recurrence, the bounds and why each pruning is exact are in the notes of
:mod:`bayesgrasp.planning.policy`.

- :func:`joint_transition`: the classes of gripper turns of an action kind over the joint
  states of every candidate part;
- :class:`ActionKind`: one action kind's classes (or, under noise, candidate turns and their
  matrices), widest first;
- :class:`Prepared`: a belief's images under one kind and what does not depend on the price;
- :class:`Solver`: the programme itself (:meth:`Solver.value`, :meth:`Solver.best_act`);
- :func:`make_solver`: the programme of a state space and sensor.

Examples
--------
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.model.sensing import parse_sensor
>>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
>>> solver = make_solver(StateSpace.build(tri), parse_sensor("width"))
>>> solver.set_price(4.0)
>>> q = solver.space.initial("squeeze", 0.0)
>>> round(solver.value(q, 1)[0], 6)  # at the best ratio (4: plan_policy's) the value is 0
0.0
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Collection
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from ..angles import circle_distance
from ..model.actions import Action
from ..model.problem import ActionClasses, nearest_state
from ..model.sensing import ReadingBins, StateSpace, WidthSensor
from .search_bounds import SearchStopped

__all__ = [
    "DEFAULT_PRUNE",
    "EPS",
    "NO_FLOOR",
    "QUANT",
    "TINY",
    "ActionKind",
    "Memo",
    "Prepared",
    "Solver",
    "joint_transition",
    "make_solver",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
QUANT = float(2**40)  # beliefs are memoised after rounding to multiples of 2**-40
EPS = 1e-12  # value comparisons (ties go to fewer actions)
TINY = 1e-13  # a reading this unlikely times its most to gain by acting again ends in a leaf
Memo = dict[tuple[bytes, int], tuple[float, tuple[Any, ...] | None, float, float]]
NO_FLOOR = -1e300  # no lower bound known (finite, so that 0 * it is 0)
# The exact search's prunings (each can be turned off to test it against the search without):
# budgets passed down ("cut"), values at higher prices as lower bounds ("floor"), and
# starting the parametric search from the best ratio one action shorter ("deepen").
DEFAULT_PRUNE = frozenset({"cut", "floor", "deepen"})


# -- the joint transition ------------------------------------------------------------------


def joint_transition(space: StateSpace, kind: str) -> ActionClasses:
    """Classes of gripper turns of one action kind over the joint states of every part.

    One part: :meth:`Problem.transition`. Several: the common refinement of each part's
    classes (every part responds to the same turn with its own transfer function);
    ``transfer[a, i]`` is a joint state index.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> sq = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    >>> cl = joint_transition(StateSpace.build([sq, sq]), "squeeze")
    >>> cl.transfer.shape
    (2, 8)
    """
    return cast(ActionClasses, space.memo(("joint", kind), lambda: _joint(space, kind)))


def _joint(space: StateSpace, kind: str) -> ActionClasses:
    pbs = space.problems
    if len(pbs) == 1:
        return pbs[0].transition(kind)
    period = pbs[0].action(kind).gripper_period
    tol = max(p.states.angle_tol for p in pbs)
    crit = np.unique(np.concatenate([np.mod(p.transition(kind).lo, period) for p in pbs]))
    if len(crit) > 1:
        keep = np.append(True, np.diff(crit) > tol)
        if period - crit[-1] + crit[0] <= tol:
            keep[0] = False
        crit = crit[keep] if keep.any() else crit[:1]
    lo = crit
    hi = np.append(crit[1:], crit[0] + period)
    mid = 0.5 * (lo + hi)
    cols = []
    for j, p in enumerate(pbs):
        # Each part's transfer at the common class's turn (not at its own class's middle,
        # which may lie a gripper period away and so relabel the states by pi).
        after = p.transfer(kind)(p.states.stable[None, :] - mid[:, None])  # (A, K)
        cols.append(nearest_state(p.states, after) + int(space.offsets[j]))
    return ActionClasses(kind, lo, hi, mid, np.concatenate(cols, axis=1).astype(np.intp))


# -- the solver ----------------------------------------------------------------------------


@dataclass(slots=True)
class ActionKind:
    """One action kind's classes of turns (rows, widest first), costs and their effect."""

    action: Action
    name: str
    cost: float
    first_cost: float
    transfer: IntArray  # (A, N), classes ordered widest first
    classes: IntArray  # (A,) original class index of each row
    mid: FloatArray  # (A,)
    half_width: FloatArray  # (A,)
    pi_symmetric: bool
    patterns: dict[bytes, tuple[IntArray, IntArray, int]] = field(default_factory=dict)
    # Noisy actions (:mod:`.noisy_policy`): the (A, N, N) transition matrix of each row's
    # turn; ``None``: the one-hot ``transfer``.
    matrices: FloatArray | None = None


@dataclass(slots=True)
class Prepared:
    """Images of a belief under one kind's classes and what does not depend on ``lambda``.

    ``mass[i, b]`` is the probability of reading bin ``b`` after image ``i``; ``success`` the
    best declaration's success mass there; ``bound`` the bound's ``U`` and ``r``
    (:meth:`Solver.bound_of`) of those (image, reading) pairs, once asked for.

    ``floor[r][i, b]`` is a lower bound on ``V(post(i, b), r)`` (per unit mass): the value
    (or a cut's bound) found at this or an earlier, higher price of generation
    ``floor_gen``; ``NO_FLOOR`` where none was found (:meth:`Solver.floor`).
    """

    images: FloatArray  # (M, N)
    mass: FloatArray  # (M, B)
    success: FloatArray  # (M, B)
    bound: tuple[FloatArray, FloatArray] | None = None
    floor: dict[int, FloatArray] = field(default_factory=dict)
    floor_gen: int = 0


@dataclass(slots=True)
class Solver:
    """The programme of a state space and sensor at a price ``lam`` (see the module notes)."""

    space: StateSpace
    bins: ReadingBins
    kinds: list[ActionKind]
    verify: float
    retry: float
    goal: NDArray[np.bool_]  # (N, N) success matrix
    goal_is_identity: bool
    pair_a: IntArray
    pair_b: IntArray
    pair_both: NDArray[np.bool_]
    use_pairs: bool
    pair_likelihood: FloatArray  # (P, B): a reading's likelihood in either state of a pair
    lam: float = 0.0
    cut: bool = True  # children stop as soon as they cannot matter (see `value`)
    use_floor: bool = True  # values at earlier (higher) prices bound later ones from below
    floor_gen: int = 0
    searched: int = 0
    max_bytes: int = 0  # most memory (about) for prepared beliefs (0: no limit; `prepared`)
    prep_bytes: int = 0
    deadline: float = math.inf  # time.monotonic() past which the search stops (`prepared`)
    time_limit: float = math.inf  # the seconds that deadline allows (for the message)
    progress: Callable[[int, int], None] | None = None  # (seconds used, seconds allowed)
    shown: float = 0.0  # when progress was last called
    memo: Memo = field(default_factory=dict)
    prep_cache: dict[tuple[bytes, int], tuple[Prepared, IntArray]] = field(default_factory=dict)

    @property
    def c_min(self) -> float:
        """The least cost of a later action."""
        return min(k.cost for k in self.kinds)

    # -- belief arithmetic (rows of unnormalised beliefs in the last axis) -----------
    def success(self, m: FloatArray) -> tuple[FloatArray, IntArray]:
        """Best declaration's success mass and its state, for beliefs ``m`` (..., N)."""
        s = m if self.goal_is_identity else m @ self.goal.T.astype(np.float64)
        return np.max(s, axis=-1), np.asarray(np.argmax(s, axis=-1), dtype=np.intp)

    def bound(self, m: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Bounds on what any continuation from beliefs ``m`` (..., N) can reach.

        Returns ``U``, the most success mass, and ``r``, the largest share of a pi pair's
        mass in its likelier state: a declaring leaf of mass ``w`` succeeds with at most
        ``r w`` (readings keep each pair's split, actions average splits).
        """
        total = np.asarray(m.sum(axis=-1), dtype=np.float64)
        if not self.use_pairs:
            return total, np.ones_like(total)
        a, b = m[..., self.pair_a], m[..., self.pair_b]
        pair = a + b
        top = np.where(self.pair_both, pair, np.maximum(a, b))
        share = top / np.maximum(pair, 1e-300)  # 0 where the pair holds no mass
        return np.asarray(top.sum(axis=-1)), np.asarray(share.max(axis=-1))

    def leaf_value(self, m: FloatArray) -> FloatArray:
        """Best leaf value (unnormalised) of beliefs ``m`` (..., N)."""
        total = m.sum(axis=-1)
        s, _ = self.success(m)
        lam, v, rho = self.lam, self.verify, self.retry
        return np.asarray(np.minimum(rho * total, (v + rho) * total - (lam + rho) * s))

    def act_bound(self, m: FloatArray) -> FloatArray:
        """Lower bound (unnormalised) on acting at least once more from beliefs ``m``.

        The leaves below hold the mass; those that declare hold ``D`` of it and succeed with
        ``S <= min(U, r D)``, the rest reject: the value is at least
        ``c_min + rho total + min over D of (v D - (lambda + rho) S)``
        ``= c_min + rho total + min(0, U (v / r - lambda - rho))``.
        """
        total = m.sum(axis=-1)
        u, r = self.bound(m)
        lam, v, rho = self.lam, self.verify, self.retry
        # r = 0 only where there is no mass (then u = 0 too); r >= 1/2 elsewhere.
        gain = u * (v / np.maximum(r, 0.5) - lam - rho)
        return np.asarray((self.c_min + rho) * total + np.minimum(0.0, gain))

    def images(self, q: FloatArray, kind: ActionKind) -> tuple[FloatArray, IntArray]:
        """Distinct beliefs after each class of ``kind`` (M, N) and the row of each."""
        if kind.matrices is not None:
            return self.noisy_images(q, kind.matrices)
        pos = q > 0
        pattern = kind.patterns.get(pos.tobytes())
        if pattern is None:
            pattern = kind.patterns[pos.tobytes()] = self.pattern(pos, kind)
        first, idx, m = pattern
        w = np.broadcast_to(q[pos], (m, len(idx) // m)).ravel()
        out = np.bincount(idx, weights=w, minlength=m * self.space.n_states)
        return np.asarray(out.reshape(m, -1), dtype=np.float64), first

    def noisy_images(self, q: FloatArray, matrices: FloatArray) -> tuple[FloatArray, IntArray]:
        """Beliefs ``q M_a`` after each candidate turn (M, N), equal ones (to ``2^-40``) once."""
        imgs = np.asarray(np.tensordot(q, matrices, axes=([0], [1])), dtype=np.float64)
        _, first = np.unique(np.rint(imgs * QUANT), axis=0, return_index=True)
        if len(first) == len(imgs):
            return imgs, np.arange(len(imgs), dtype=np.intp)
        first = np.sort(first)
        return np.ascontiguousarray(imgs[first]), np.asarray(first, dtype=np.intp)

    def pattern(self, pos: NDArray[np.bool_], kind: ActionKind) -> tuple[IntArray, IntArray, int]:
        """The distinct effects of ``kind`` on a belief of support ``pos``.

        The class of each (widest first), the flat index of each (effect, state of the
        support) in the (M, N) images, and their number M (:meth:`images` adds the masses).
        """
        supp = np.flatnonzero(pos)
        t = kind.transfer[:, supp]  # (A, S)
        n = self.space.n_states
        if len(supp) * math.log2(max(n, 2)) < 62:  # each row as one integer in base n
            code = t @ (n ** np.arange(len(supp), dtype=np.int64))
            _, first = np.unique(code, return_index=True)
            first = np.sort(first)  # the widest class of each distinct effect, widest first
        else:
            seen: dict[bytes, int] = {}
            for ai, row in enumerate(t):
                seen.setdefault(row.tobytes(), ai)
            first = np.fromiter(seen.values(), dtype=np.intp, count=len(seen))
        rows = t[first]
        m = len(first)
        idx = (rows + n * np.arange(m)[:, None]).ravel()
        return np.asarray(first, dtype=np.intp), np.asarray(idx, dtype=np.intp), m

    def joint(self, imgs: FloatArray) -> FloatArray:
        """Joint (belief, reading) masses: (M, B, N)."""
        return np.asarray(imgs[:, None, :] * self.bins.likelihood.T[None, :, :])

    @staticmethod
    def key(q: FloatArray) -> bytes:
        """The memo's key of a belief: its masses rounded to multiples of ``2^-40``."""
        return np.rint(q * QUANT).astype(np.int64).tobytes()

    # -- the programme -----------------------------------------------------------------
    def prepare(self, imgs: FloatArray) -> Prepared:
        """What :meth:`best_act` needs of images ``imgs`` (M, N) at any price ``lambda``."""
        j = self.joint(imgs)  # (M, B, N)
        s = j if self.goal_is_identity else j @ self.goal.T.astype(np.float64)
        return Prepared(imgs, j.sum(axis=-1), np.max(s, axis=-1))

    def bound_of(self, prep: Prepared) -> tuple[FloatArray, FloatArray]:
        """The bound's ``U`` and ``r`` (:meth:`bound`) of every (image, reading) pair: (M, B).

        The two states of a pi pair have the same width, so a reading scales both by the
        same likelihood ``L_p(b)``: the pair's split (``share``) is the image's, and ``U`` is
        a matrix product. ``L_p`` is the larger of the pair's two likelihoods (equal up to
        rounding), so ``U`` stays an upper bound. Computed once per prepared images.
        """
        if prep.bound is not None:
            return prep.bound
        if not self.use_pairs:
            out = (prep.mass, np.ones_like(prep.mass))
        else:
            imgs, lik = prep.images, self.pair_likelihood
            a, b = imgs[:, self.pair_a], imgs[:, self.pair_b]  # (M, P)
            pair = a + b
            top = np.where(self.pair_both, pair, np.maximum(a, b))
            share = top / np.maximum(pair, 1e-300)
            reach = (pair[:, :, None] > 0) & (lik[None, :, :] > 0)  # (M, P, B)
            r = np.max(np.where(reach, share[:, :, None], 0.0), axis=1)  # (M, B)
            out = (np.asarray(top @ lik), np.asarray(r))
        prep.bound = out
        return out

    def leaf_figures_of(self, total: FloatArray, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Cycle cost and success mass of the leaf chosen for masses ``total`` (best ``s``).

        ``s`` is the success mass of the best declaration. Declares unless rejecting is
        strictly better or nothing declared can succeed (as :meth:`value` decides).
        """
        lam, v, rho = self.lam, self.verify, self.retry
        # A tie goes to rejecting where no declaration can succeed (s = 0, verify 0).
        declare = ((v + rho) * total - (lam + rho) * s <= rho * total + EPS * total) & (s > 0)
        c = np.where(declare, v * total + rho * (total - s), rho * total)
        return np.asarray(c), np.asarray(np.where(declare, s, 0.0))

    def best_act(
        self, prep: Prepared, cost: float, r_after: int, best: float
    ) -> tuple[float, int, float, float]:
        """Least value of acting into each image (``cost + children``) if below ``best``.

        Returns the value, the image index (-1 when none beats ``best``), and the chosen
        continuation's cycle cost and success probability (per unit mass).
        """
        lam, v, rho = self.lam, self.verify, self.retry
        pm, s = prep.mass, prep.success
        leaf = np.minimum(rho * pm, (v + rho) * pm - (lam + rho) * s)  # (M, B): leaves
        ub = cost + leaf.sum(axis=1)
        if r_after == 0:
            i = int(np.argmin(ub))
            if ub[i] < best - EPS:
                c, p = self.leaf_figures_of(pm[i], s[i])
                return float(ub[i]), i, cost + float(c.sum()), float(p.sum())
            return best, -1, math.nan, math.nan
        pick, pick_c, pick_p = -1, math.nan, math.nan
        # The bound on acting again (:meth:`act_bound`) of every (image, reading) pair.
        top, share = self.bound_of(prep)
        gain = top * (v / np.maximum(share, 0.5) - lam - rho)
        act = (self.c_min + rho) * pm + np.minimum(0.0, gain)
        lb_child = np.minimum(leaf, act)
        floor = self.floor(prep, r_after)
        if floor is not None:
            lb_child = np.maximum(lb_child, pm * floor)
        # A child whose leaf is no worse than acting's bound is a leaf (as `value` decides).
        settled = (leaf <= act + EPS * pm) | (leaf - act < TINY)
        # Each class's settled leaves, and the bounds of the rest (before any child).
        done_sum = (cost + np.where(settled, leaf, 0.0).sum(axis=1)).tolist()
        rest_sum = np.where(settled, 0.0, lb_child).sum(axis=1).tolist()
        lik_t = self.bins.likelihood.T  # (B, N)
        for i in np.argsort(ub, kind="stable").tolist():
            total, rest = done_sum[i], rest_sum[i]
            if total + rest >= best - EPS:
                continue
            aborted = False
            img = prep.images[i]
            kids: list[tuple[float, float]] = []
            # The children most above their bounds first: the class is abandoned soonest.
            open_ = np.flatnonzero((pm[i] > 0) & ~settled[i])
            for b in open_[np.argsort(lb_child[i, open_] - leaf[i, open_], kind="stable")]:
                rest -= float(lb_child[i, b])
                pb = float(pm[i, b])
                q = img * lik_t[b] / pb
                # The child matters only if its value is below this (the class is
                # abandoned otherwise): it may stop as soon as it knows it is not.
                budget = (best - EPS - total - rest) / pb if self.cut else math.inf
                val, cv, pv, exact = self.value(q, r_after, budget, True)
                if floor is None:
                    floor = np.full(pm.shape, NO_FLOOR)
                    if self.use_floor:
                        prep.floor[r_after] = floor
                if not exact:
                    # ``val`` is a lower bound: abandon the class if that already tells,
                    # with the same arithmetic as below (it is monotone in ``val``).
                    floor[i, b] = max(floor[i, b], val)
                    if total + pb * val + rest >= best - EPS:
                        aborted = True
                        break
                    val, cv, pv, exact = self.value(q, r_after, math.inf, True)
                floor[i, b] = val
                total += pb * val
                kids.append((pb * cv, pb * pv))
                if total + rest >= best - EPS:
                    aborted = True
                    break
            if not aborted and total < best - EPS:
                done = settled[i]
                lc, lp = self.leaf_figures_of(pm[i, done], s[i, done])
                c_sum, p_sum = cost + float(lc.sum()), float(lp.sum())
                for cv, pv in kids:
                    c_sum += cv
                    p_sum += pv
                best, pick, pick_c, pick_p = total, int(i), c_sum, p_sum
        return best, pick, pick_c, pick_p

    def floor(self, prep: Prepared, r_after: int) -> FloatArray | None:
        """The lower bounds ``prep.floor[r_after]`` if still valid at this price, else None.

        ``V(q, r)`` is the least of ``c(pi) - lambda P(pi)`` over the continuations ``pi``,
        each non-increasing in ``lambda`` (``P >= 0``), so it is non-increasing too: a value
        (or a lower bound) found at a price is a lower bound at every lower price. The
        parametric steps lower the price; a step at a higher price starts a new generation
        (:meth:`set_price`) and the old bounds are dropped.
        """
        if not self.use_floor or prep.floor_gen != self.floor_gen:
            prep.floor = {}
            prep.floor_gen = self.floor_gen
        return prep.floor.get(r_after)

    def set_price(self, lam: float) -> None:
        """Solve at price ``lam`` next (a fresh memo; the floors stay if it is no higher)."""
        if lam > self.lam:
            self.floor_gen += 1
        self.lam = lam
        self.memo = {}

    def prepared(self, key: bytes, q: FloatArray, ti: int) -> tuple[Prepared, IntArray]:
        """The images of belief ``q`` under kind ``ti``, prepared (kept across prices)."""
        hit = self.prep_cache.get((key, ti))
        if hit is None:
            if self.max_bytes and self.prep_bytes > self.max_bytes:
                raise SearchStopped.out_of_memory(self.max_bytes)
            now = time.monotonic()
            if self.progress is not None and now - self.shown > 0.25:
                self.shown = now
                used = self.time_limit - max(self.deadline - now, 0.0)
                self.progress(int(used), math.ceil(self.time_limit))
            if now > self.deadline:
                raise SearchStopped.out_of_time(self.time_limit)
            imgs, rows = self.images(q, self.kinds[ti])
            hit = (self.prepare(imgs), rows)
            self.prep_cache[(key, ti)] = hit
            if self.max_bytes:  # the images, reading masses, successes, bounds and floors
                self.prep_bytes += imgs.nbytes + 6 * hit[0].mass.nbytes + 200
        return hit

    def value(
        self, q: FloatArray, r: int, budget: float = math.inf, unsettled: bool = False
    ) -> tuple[float, float, float, bool]:
        """``V(q, r)`` per unit mass (``q`` normalised), its cycle cost and success, exactly.

        With a finite ``budget`` the caller only needs the value if it is below ``budget``:
        the search may then stop early and return ``(bound, nan, nan, False)`` with
        ``V(q, r) >= bound >= budget`` (a cut). Otherwise the last item is True and the value
        is the one the unbudgeted search finds. Memoised with the decision that reaches it
        (a cut is memoised as its bound, and searched again for a larger budget).

        ``unsettled``: the caller (:meth:`best_act`) has found the leaf worse than the bound
        on acting (:meth:`act_bound`, from the images' figures), and any finite budget above
        that bound: the search acts without computing the bound again.
        """
        qk = self.key(q)
        k = (qk, r)
        hit = self.memo.get(k)
        if hit is not None:
            if hit[1] is not None:
                return hit[0], hit[2], hit[3], True
            if hit[0] >= budget:
                return hit[0], math.nan, math.nan, False
        self.searched += 1
        s, o = self.success(q)
        lam, v, rho = self.lam, self.verify, self.retry
        sf = float(s)
        declare = v + rho - (lam + rho) * sf
        best: float
        decision: tuple[Any, ...]
        if declare <= rho + EPS and sf > 0:  # declaring what cannot succeed: reject
            best, decision, c, p = declare, ("declare", int(o)), v + rho * (1 - sf), sf
        else:
            best, decision, c, p = rho, ("reject",), rho, 0.0
        # An action must beat ``limit - EPS`` to be taken: the leaf, or the budget when
        # that is lower (then only a value below the budget is of use).
        cutting = budget + EPS < best
        limit = budget + EPS if cutting else best
        if r > 0 and (unsettled or limit > float(self.act_bound(q)) + EPS):
            for ti, kind in enumerate(self.kinds):
                if not len(kind.classes):  # an accuracy left no turn of this kind
                    continue
                prep, rows = self.prepared(qk, q, ti)
                val, i, ci, pi = self.best_act(prep, kind.cost, r - 1, limit)
                if i >= 0:
                    best, decision, c, p = val, ("act", ti, int(rows[i])), ci, pi
                    limit, cutting = val, False
        if cutting:
            self.memo[k] = (budget, None, math.nan, math.nan)
            return budget, math.nan, math.nan, False
        self.memo[k] = (best, decision, c, p)
        return best, c, p, True

    def decision(self, q: FloatArray, r: int) -> tuple[Any, ...]:
        """What the programme does from belief ``q`` with ``r`` actions left (at its price)."""
        k = (self.key(q), r)
        hit = self.memo.get(k)
        if hit is None or hit[1] is None:
            self.value(q, r)
        return cast(tuple[Any, ...], self.memo[k][1])


# -- making the programme ------------------------------------------------------------------


def pi_pairs(space: StateSpace) -> tuple[IntArray, IntArray, NDArray[np.bool_], bool]:
    """The pi pairs of each part's states (each once), and whether they are all pairs."""
    pa: list[int] = []
    pb: list[int] = []
    ok = True
    for j, p in enumerate(space.problems):
        s = p.states.stable
        k = len(s)
        if k % 2 or not np.all(
            circle_distance(np.roll(s, -k // 2), s + math.pi) < 1e3 * p.states.angle_tol
        ):
            ok = False
            break
        o = int(space.offsets[j])
        pa.extend(o + i for i in range(k // 2))
        pb.extend(o + i + k // 2 for i in range(k // 2))
    a = np.asarray(pa, dtype=np.intp)
    b = np.asarray(pb, dtype=np.intp)
    both = space.success_matrix()[a, b] if ok else np.zeros(0, dtype=bool)
    return a, b, np.asarray(both, dtype=bool), ok


def make_solver(
    space: StateSpace, sens: WidthSensor, prune: Collection[str] = DEFAULT_PRUNE
) -> Solver:
    """The programme of a state space and sensor (its kinds, bins, goal and bounds)."""
    main = space.problems[0]
    cost = main.cost
    kinds: list[ActionKind] = []
    for action in main.actions:
        cl = joint_transition(space, action.name)
        order = np.argsort(-(cl.hi - cl.lo), kind="stable")
        # with an accuracy, only the turns that keep their effect under any error below it
        if main.accuracy > 0:
            order = order[0.5 * (cl.hi - cl.lo)[order] >= main.accuracy]
        kinds.append(
            ActionKind(
                action,
                action.name,
                cost.action_cost(action.name),
                cost.action_cost(action.name, first=True),
                np.ascontiguousarray(cl.transfer[order]),
                np.asarray(order, dtype=np.intp),
                cl.mid[order],
                0.5 * (cl.hi - cl.lo)[order],
                math.isclose(action.gripper_period, math.pi),
            )
        )
    goal = space.success_matrix()
    pa, pb, both, paired = pi_pairs(space)
    bins = space.bins(sens)
    pair_lik = np.maximum(bins.likelihood[pa], bins.likelihood[pb]) if paired else np.zeros((0, 1))
    solver = Solver(
        space,
        bins,
        kinds,
        cost.verify,
        cost.retry,
        goal,
        bool(np.array_equal(goal, np.eye(space.n_states, dtype=bool))),
        pa,
        pb,
        both,
        paired and all(k.pi_symmetric for k in kinds),
        np.ascontiguousarray(pair_lik),
        cut="cut" in prune,
        use_floor="floor" in prune,
    )
    return solver
