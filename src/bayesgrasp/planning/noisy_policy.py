"""Policies under noisy actions: jaw-width sensing and turn errors together (the paper, section 6).

The paper lists both extensions: branching on noisy jaw-width readings (section 6.2) and
noisy actions modelled by a conditional distribution (section 6.4). Here they combine. Under
a :class:`~bayesgrasp.model.noise.NoiseModel` (turn error, contact asynchrony) an action of
kind ``t`` turned by ``alpha`` is the row-stochastic matrix ``M_t(alpha)``
(:meth:`~bayesgrasp.model.noise.NoisyTransitions.matrices`; several candidate parts: the
block-diagonal matrix of each part's), and the first action at world angle ``a`` leaves the
prior convolved with its error (:meth:`~bayesgrasp.model.noise.NoisyTransitions.initial`).
A belief ``q`` (over the states, or (part, orientation) pairs) after the last reading becomes

    q -> q M_t(alpha) -> post(q M_t(alpha), b)

(Bayes' rule with the sensor's reading bins, :mod:`bayesgrasp.model.sensing`). The cost
semantics are those of :mod:`bayesgrasp.planning.policy`: a cycle pays its actions and, at a
declaring leaf, the verification; a failed or rejected cycle pays the retry overhead; the
policy minimises ``R = c / P``.

What is optimal, what is bounded
--------------------------------
1. *Exact programme over a candidate set.* At every node the candidate turns of kind ``t``
   are the middles of the noise-free action classes of ``t``
   (:meth:`~bayesgrasp.model.problem.Problem.transition`; several parts: their common
   refinement; with a gripper accuracy, the classes it keeps), as the noisy linear planner
   seeds its hyperstate search (:mod:`.noisy`). With contact asynchrony they also include
   the middles of the common refinement of the classes of every way a squeeze may go (the
   squeeze and the push-grasps from either side): with exact turns ``M_t(alpha)`` is
   constant on each of those classes, so under contact noise alone the candidates hold
   every matrix a turn can give and the programme is exact over all turns. The first
   angle is chosen as the noise-free planner chooses it (any angle under the uniform
   prior). Over the policies of at most ``max_actions`` actions that use only those
   turns, the programme of :mod:`.policy` (Dinkelbach's parametric search, a dynamic
   programme over beliefs, its exact bounds: the pi-pair bound stays valid because the
   turn error and the contact events are symmetric under a turn by pi) finds the least
   ``R``, up to the ``1e-12`` of the belief memo and of the leaf rule. Beliefs that
   coincide to ``2^-40`` count once. (A gripper ``accuracy`` restricts these candidates
   as it restricts the noise-free classes; the refinement below does not keep to it: the
   noise model says what errors do.)
2. *Known policies.* The noise-free Bayes policy (:func:`.policy.plan_policy`) and, for one
   part, the noise-aware sensorless Bayes plan (:func:`.noisy.plan_noisy` within
   ``max_actions``, a policy that never branches) are evaluated under the noise too; the
   returned policy is the least costly of the three after refinement, so it is never worse
   than either (both exactly evaluated under the same noise).
3. *Turn refinement* (bounded, not optimal). With the tree's structure fixed (its actions,
   reading branches and leaves) the value ``c - lambda P`` is linear in the belief entering
   any node, ``f(alpha) = left M_t(alpha) r`` with ``left`` the (unnormalised) belief that
   reaches the node and ``r`` the per-state value of what follows. Each turn after the
   first is optimised in turn over the whole circle at ``lambda = R`` of the current tree,
   as :mod:`.noisy` refines a plan's turns: exactly for a uniform error (``f`` is
   piecewise linear: its kinks) and for exact turns with contact noise (``f`` is constant
   between critical turns); for a normal error on a grid of step ``h = sigma / 6`` near the
   critical turns, then ``h / 32`` about the best point, so that the best grid point is
   within ``eps = |f''|max h^2 / 8`` of the turn's best with
   ``|f''| <= 2 phi(1) / sigma^2 * mass * span(r)``
   (:attr:`~bayesgrasp.model.noise.TurnNoise.curvature_bound`). A node whose
   ``mass * span(r)`` (the most any turn can change its value by) is below the grid bound
   of the heaviest node is not searched: its bound is that product. A new turn is taken
   only if the matrices the evaluation uses confirm the gain. Sweeps repeat (at most
   :data:`MAX_SWEEPS`) while the ratio falls (a lower value at ``lambda = R`` is a lower
   ratio: Dinkelbach's step). :attr:`Policy.refinement_bound` is the largest bound over the
   nodes in the last sweep: no single turn, the rest kept, lowers ``c - lambda P`` (at that
   sweep's ``lambda``, the ratio before it) by more. Not guaranteed: the best over all
   turns at once, or over turns outside the candidate set in the programme (a multimodal
   problem, as for noisy plans); the tests compare the policy with an exhaustive search
   over a 0.5 deg turn grid at depth 2.
4. *Exact figures.* The returned policy's branch probabilities, leaf success
   probabilities, success probability, cycle cost, expected cost, expected actions and
   expected entropy after each level are recomputed on the returned tree by propagating
   the beliefs of every reading history through each node's matrix and the reading
   likelihoods (:func:`evaluate_policy`); nothing is sampled. With a non-uniform prior the
   first action's average over its own error is a 512-node Gauss-Legendre rule (as for
   plans).

With no noise at all, :func:`plan_noisy_policy` returns :func:`.policy.plan_policy`'s policy.

Memory: the programme keeps the images of every belief it acts on (with their reading masses
and bounds); ``max_memory_mb`` bounds their size (a :class:`~bayesgrasp.errors.PlanningError`
says so when reached; the command line keeps the default, 2 GB). Noisy
actions make almost every belief new (the memo of the noise-free programme helps little),
so the work grows like ``(A B)^(K - 1)`` beliefs for ``A`` candidate turns, ``B`` reading
bins and ``K`` actions, less what the bounds prune.

Payoff (the paper, section 6.4; :mod:`bayesgrasp.model.payoff`, one part): the value
``u_j`` in [0, 1] of ending in state ``j`` replaces the goal. A declaring leaf then stops,
verifies and earns the payoff of the state the part is in: per unit mass it costs
``v + rho (1 - q . u)`` and succeeds ``q . u`` (the leaf names the state of most
``q_j u_j``). The policy minimises the expected cost per unit payoff,
``E[cycle cost] / E[payoff]``, as :func:`.noisy.plan_noisy` does for plans (for a 0/1
payoff that is today's cost); a payoff needs no noise. The pi-pair bound is not used
(both states of a pair may pay).

Examples
--------
>>> import math
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.model.noise import NoiseModel, TurnNoise
>>> rect = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
>>> noise = NoiseModel(TurnNoise("normal", math.radians(2)))
>>> pol = plan_noisy_policy(rect, "width", 2, noise)
>>> round(pol.success_probability, 6), round(pol.expected_cost, 4)
(0.5, 4.0)
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.noise import NoiseModel, NoisyTransitions
from ..model.payoff import Payoff, as_vector
from ..model.problem import Problem
from ..model.sensing import StateSpace, WidthSensor, parse_sensor
from ..model.states import nearest_state
from .evaluation import Evaluation, evaluate_tree
from .noisy import plan_noisy
from .policy import (
    DEFAULT_MAX_ACTIONS,
    DEFAULT_MAX_MEMORY_MB,
    DEFAULT_PRUNE,
    Branch,
    Declare,
    Policy,
    PolicyBuilder,
    PolicyNode,
    Reject,
    candidate_first_angles,
    make_solver,
    memory_bytes,
    plan_policy,
    policy_space,
    search_policy,
    start_ratio,
    time_seconds,
)
from .result import PlanStep
from .turns import FLAT_SIGMAS, GRID_PER_SIGMA, free_arcs, margin, turn_grid

__all__ = ["MAX_SWEEPS", "evaluate_policy", "plan_noisy_policy"]

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

MAX_SWEEPS = 4
"""Most refinement sweeps over the turns of a policy."""
_GAIN_TOL = 1e-12


# -- the noisy model of a state space -------------------------------------------------------


_SAME_TURN = 1e-9
"""Candidate turns closer than this (radians, modulo 2 pi) are one turn."""


def _first_of_each_turn(turns: FloatArray, tol: float) -> IntArray:
    """Indices of the first of each group of turns within ``tol`` of each other, mod 2 pi.

    In the order of ``turns`` (the first of a group is kept, the others dropped).

    Examples
    --------
    >>> _first_of_each_turn(np.array([math.pi, 0.5, -math.pi, 0.5 + 1e-12, 1.0]), 1e-9).tolist()
    [0, 1, 4]
    """
    if len(turns) < 2:
        return np.arange(len(turns), dtype=np.intp)
    k = np.mod(turns, TWO_PI)
    srt = np.argsort(k, kind="stable")
    ks = k[srt]
    group = np.cumsum(np.append(True, np.diff(ks) > tol)) - 1
    if ks[0] + TWO_PI - ks[-1] <= tol:  # the groups at 0 and just below 2 pi are one
        group[group == group[-1]] = 0
    ids = np.empty_like(group)
    ids[srt] = group
    _, first = np.unique(ids, return_index=True)
    return np.sort(first).astype(np.intp)


def _first_of_each_matrix(mats: FloatArray) -> IntArray:
    """Indices of the first of each group of equal matrices ``mats`` (A, N, N), in order.

    Examples
    --------
    >>> m = np.array([np.eye(2), np.ones((2, 2)) / 2, np.eye(2)])
    >>> _first_of_each_matrix(m).tolist()
    [0, 1]
    """
    if len(mats) < 2:
        return np.arange(len(mats), dtype=np.intp)
    _, first = np.unique(mats.reshape(len(mats), -1), axis=0, return_index=True)
    return np.sort(first).astype(np.intp)


class _Model:
    """Joint noisy matrices, first actions and reading likelihoods of a state space."""

    def __init__(self, space: StateSpace, sensor: WidthSensor, noise: NoiseModel) -> None:
        self.space = space
        self.noise = noise
        self.nts = [NoisyTransitions(p, noise) for p in space.problems]
        self.bins = space.bins(sensor)
        self.goal = space.success_matrix()
        self.payoff: FloatArray | None = None  # one part's payoff vector, if any
        self.cost = space.problems[0].cost
        self.n = space.n_states
        self.blocks = [
            (int(o), int(o) + p.n_states)
            for o, p in zip(space.offsets[: space.n_parts], space.problems, strict=True)
        ]
        self._one: dict[tuple[str, float], FloatArray] = {}

    def matrix(self, kind: str, alpha: float) -> FloatArray:
        """The (N, N) matrix of one turn (kept: refinement asks for the same turns often)."""
        key = (kind, float(alpha))
        hit = self._one.get(key)
        if hit is None:
            hit = self._one[key] = self.matrices(kind, np.array([alpha]))[0]
        return hit

    def matrices(self, kind: str, alphas: FloatArray) -> FloatArray:
        """Block-diagonal (A, N, N) matrices of turns ``alphas``."""
        out = np.zeros((len(alphas), self.n, self.n))
        for (lo, hi), nt in zip(self.blocks, self.nts, strict=True):
            out[:, lo:hi, lo:hi] = nt.matrices(kind, alphas)
        return out

    def candidates(
        self, kind: str, mid: FloatArray, half: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """The candidate turns of ``kind`` and their half widths, widest first.

        The noise-free classes' middles ``mid`` (half widths ``half``); with contact
        asynchrony also the middles of the common refinement of the classes of every way
        the action may go (each turn at which some state's basin changes in one of them):
        with exact turns ``M(alpha)`` is constant on each such class. A turn is a candidate
        once: a noise-free class that no other way of the action splits is also a class of
        the refinement, and a middle at pi is one at -pi; the widest class of a turn is kept.
        """
        comps = [(nt, c) for nt in self.nts for c in nt.components(kind)]
        if len(comps) == len(self.nts):  # one way to go: the noise-free classes
            return mid, half
        crit = np.concatenate(
            [(nt.stable[:, None] - c.offset - c.hi[None, :]).ravel() for nt, c in comps]
        )
        c = np.unique(np.mod(crit, TWO_PI))
        widths = np.diff(np.append(c, c[0] + TWO_PI))
        keep = widths > 1e-9
        c, widths = c[keep], widths[keep]
        more = np.mod(c + widths / 2 + math.pi, TWO_PI) - math.pi
        mids = np.concatenate([mid, more])
        halves = np.concatenate([half, widths / 2])
        order = np.argsort(-halves, kind="stable")
        mids, halves = mids[order], halves[order]
        once = _first_of_each_turn(mids, _SAME_TURN)
        return np.asarray(mids[once]), np.asarray(halves[once])

    def initial(self, kind: str, angle: float) -> FloatArray:
        """Joint distribution after the first action at world angle ``angle``."""
        return np.concatenate(
            [
                w * nt.initial(kind, angle)
                for w, nt in zip(self.space.part_prior, self.nts, strict=True)
            ]
        )

    def line(
        self, kind: str, left: FloatArray, right: FloatArray, alphas: FloatArray
    ) -> FloatArray:
        """``left M(alpha) right`` for many turns."""
        out = np.zeros(len(alphas))
        for (lo, hi), nt in zip(self.blocks, self.nts, strict=True):
            if np.any(left[lo:hi] > 0):
                out += nt.line(kind, left[lo:hi], right[lo:hi], alphas)
        return out

    def boundaries(self, kind: str, left: FloatArray) -> FloatArray:
        """Turns that put a state of positive ``left`` mass on a basin boundary of ``kind``.

        Every way the action may go counts, whether or not both sides of the boundary are
        worth the same: a squeeze at an unstable equilibrium goes either way, or jams.
        """
        pts = [
            nt.boundary_turns(kind, np.flatnonzero(left[lo:hi] > 0))
            for (lo, hi), nt in zip(self.blocks, self.nts, strict=True)
            if np.any(left[lo:hi] > 0)
        ]
        return np.concatenate(pts) if pts else np.zeros(0)

    def critical(self, kind: str, left: FloatArray, right: FloatArray) -> FloatArray:
        """Turns where ``left M(alpha) right`` may change with exact turns."""
        pts = [
            nt.critical(kind, left[lo:hi], right[lo:hi])
            for (lo, hi), nt in zip(self.blocks, self.nts, strict=True)
            if np.any(left[lo:hi] > 0)
        ]
        return np.concatenate(pts) if pts else np.zeros(0)

    def branch_bins(self, branches: Sequence[Branch]) -> list[IntArray]:
        """The reading bins of each branch (a branch's interval is a union of bins)."""
        lo, hi = self.bins.lo, self.bins.hi
        return [np.flatnonzero((lo >= b.lo) & (hi <= b.hi)) for b in branches]

    def earned(self, leaf: Declare) -> FloatArray:
        """What a declaring leaf earns in each state: the payoff, or its goal's success set."""
        if self.payoff is not None:
            return self.payoff
        return np.asarray(self.goal[self.state(leaf)], dtype=np.float64)

    def state(self, leaf: Declare) -> int:
        """The joint state a declaration names."""
        pb = self.space.problems[leaf.part]
        i = int(nearest_state(pb.states, np.array([leaf.orientation]))[0])
        return int(self.space.offsets[leaf.part]) + i


# -- a mutable tree for refinement and evaluation ------------------------------------------


@dataclass(slots=True)
class _Node:
    kind: str
    alpha: float
    branches: list[Branch]  # lo, hi, and (probability, next) refreshed by evaluation
    bins: list[IntArray]
    children: list[_Node | Declare | Reject]
    margin: float
    lik: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))  # (N, branches)


def _mutable(node: PolicyNode, model: _Model) -> _Node:
    bins = model.branch_bins(node.branches)
    kids: list[_Node | Declare | Reject] = [
        _mutable(b.next, model) if isinstance(b.next, PolicyNode) else b.next for b in node.branches
    ]
    lik = np.stack([model.bins.likelihood[:, ix].sum(axis=1) for ix in bins], axis=1)
    return _Node(node.step.kind, node.step.alpha, list(node.branches), bins, kids, node.margin, lik)


def _nodes(node: _Node, first: bool = True) -> list[tuple[_Node, bool]]:
    out = [(node, first)]
    for k in node.children:
        if isinstance(k, _Node):
            out += _nodes(k, False)
    return out


def _frozen(node: _Node, model: _Model) -> PolicyNode:
    """A subtree no history reaches (probabilities 0)."""
    kids = [_frozen(k, model) if isinstance(k, _Node) else k for k in node.children]
    return PolicyNode(
        PlanStep(node.kind, node.alpha),
        tuple(Branch(b.lo, b.hi, 0.0, k) for b, k in zip(node.branches, kids, strict=True)),
        node.margin,
    )


def _exact(model: _Model, root: _Node, first_angle: float) -> Evaluation:
    """Exact figures of a tree: :func:`.evaluation.evaluate_tree` under the model's matrices."""
    tree = _frozen(root, model)
    tree = dataclasses.replace(tree, step=PlanStep(tree.step.kind, first_angle))
    return evaluate_tree(model.space, tree, model, model.bins, model.payoff)


def _depth(node: _Node) -> int:
    return 1 + max((_depth(k) for k in node.children if isinstance(k, _Node)), default=0)


# -- refinement ------------------------------------------------------------------------------


def _rights(model: _Model, root: _Node, lam: float) -> dict[int, FloatArray]:
    """Per-state value (``c - lambda P``, per unit mass) of each node's readings and after.

    ``out[id(node)][j]``: the part is in state ``j`` after the node's action. One pass from
    the leaves up.
    """
    v, rho = model.cost.verify, model.cost.retry
    out: dict[int, FloatArray] = {}

    def walk(node: _Node) -> FloatArray:
        cols = []
        for nxt in node.children:
            if isinstance(nxt, Reject):
                cols.append(np.full(model.n, rho))
            elif isinstance(nxt, Declare):
                g = model.earned(nxt)
                cols.append(v + rho - (lam + rho) * g)
            else:
                below = walk(nxt)
                m = model.matrix(nxt.kind, nxt.alpha)
                cols.append(model.cost.action_cost(nxt.kind) + m @ below)
        r = np.asarray((node.lik * np.stack(cols, axis=1)).sum(axis=1), dtype=np.float64)
        out[id(node)] = r
        return r

    walk(root)
    return out


def _best_turn(
    model: _Model, kind: str, left: FloatArray, right: FloatArray, current: float
) -> tuple[float, float, float]:
    """The turn of least ``left M(alpha) right`` over the circle, its value, and ``eps``.

    ``eps`` bounds how much lower the true least value may be (the grid bound; 0 where the
    search is exact). Minimises by maximising ``left M (-right)``, as :mod:`.noisy` does.
    """
    turn = model.noise.turn
    neg = -right
    f0 = float(model.line(kind, left, neg, np.array([current]))[0])
    crit = model.critical(kind, left, neg)
    period = TWO_PI
    if len(crit) == 0:
        return current, -f0, 0.0
    eps = 0.0
    on_edge = False
    if turn.exact:
        # f is constant between critical turns, so between every boundary of every state the
        # node may hold (a refinement of them): the middle of each such arc, the widest of the
        # best, keeps the turn farthest from the unstable equilibria (arcs of a rounding's
        # width are not turns a gripper can make). A turn now on a boundary must move: its
        # value is one side's, not what the squeeze does there.
        edges = model.boundaries(kind, left)
        _, pts, half = free_arcs(edges, period, 1e-9)
        vals = np.where(half > 5e-10, model.line(kind, left, neg, pts), -np.inf)
        top = np.flatnonzero(vals >= vals.max() - _GAIN_TOL * max(1.0, abs(float(vals.max()))))
        i = int(top[np.argmax(half[top])])
        best, fb = float(pts[i]), float(vals[i])
        on_edge = margin(current, edges, period) < 1e-9
    elif turn.kind == "uniform":
        raw = (crit[:, None] + np.array([-turn.scale, turn.scale])).ravel()
        kinks = np.unique(np.mod(raw + period / 2, period)) - period / 2
        vals = model.line(kind, left, neg, kinks)
        i = int(np.argmax(vals))
        best, fb = float(kinks[i]), float(vals[i])
    else:
        h = turn.scale / GRID_PER_SIGMA
        grid = turn_grid(crit, period, h, FLAT_SIGMAS * turn.scale)
        vals = model.line(kind, left, neg, grid)
        i = int(np.argmax(vals))
        best, fb = float(grid[i]), float(vals[i])
        fine = best + h * np.linspace(-1.0, 1.0, 65)
        fv = model.line(kind, left, neg, fine)
        j = int(np.argmax(fv))
        if fv[j] > fb:
            best, fb = float(fine[j]), float(fv[j])
        span = float(right.max() - right.min())
        eps = turn.curvature_bound * h * h / 8.0 * float(left.sum()) * span
    if on_edge:
        best = float(math.remainder(best, TWO_PI))
        return best, float(left @ model.matrix(kind, best) @ right), eps
    if fb > f0 + _GAIN_TOL * max(1.0, abs(f0)):
        # Checked with the matrix the evaluation uses (the line's sums are arranged
        # differently, and may round differently right at a critical turn).
        best = float(math.remainder(best, TWO_PI))
        f_new = float(left @ model.matrix(kind, best) @ right)
        f_old = float(left @ model.matrix(kind, current) @ right)
        if f_new < f_old - _GAIN_TOL * max(1.0, abs(f_old)):
            return best, f_new, eps
    return current, -f0, eps


def _refine(model: _Model, root: _Node, first_angle: float, ratio: float) -> tuple[float, float]:
    """Coordinate descent over the turns (see the module notes); the new ratio and ``eps``.

    A node whose ``mass * span(r)`` (the most any turn can change its value by) is below
    the grid bound of the heaviest node is left as it is: its bound is that product, no
    larger than the reported ``eps``.
    """
    turn = model.noise.turn
    # eps = factor * mass * span on the grid (normal error); 0 where the search is exact.
    factor = 0.0
    if not turn.exact and turn.kind == "normal":
        h = turn.scale / GRID_PER_SIGMA
        factor = turn.curvature_bound * h * h / 8.0
    eps = 0.0

    def weights(node: _Node, left: FloatArray, rights: dict[int, FloatArray]) -> float:
        """The largest ``mass * span(r)`` over the nodes below (``left``: after the action)."""
        top = 0.0
        for j, nxt in enumerate(node.children):
            if isinstance(nxt, _Node):
                q = left * node.lik[:, j]
                r = rights[id(nxt)]
                top = max(top, float(q.sum()) * float(r.max() - r.min()))
                top = max(top, weights(nxt, q @ model.matrix(nxt.kind, nxt.alpha), rights))
        return top

    def sweep(node: _Node, left: FloatArray, rights: dict[int, FloatArray], tau: float) -> bool:
        """Refine the nodes below ``node`` (``left``: the belief after its action)."""
        nonlocal eps
        moved = False
        for j, nxt in enumerate(node.children):
            if not isinstance(nxt, _Node):
                continue
            q = left * node.lik[:, j]
            r = rights[id(nxt)]
            weight = float(q.sum()) * float(r.max() - r.min())
            if weight > 0 and weight > tau:
                new, _, e = _best_turn(model, nxt.kind, q, r, nxt.alpha)
                eps = max(eps, e)
                if new != nxt.alpha:
                    nxt.alpha, moved = new, True
            else:
                eps = max(eps, weight)
            moved |= sweep(nxt, q @ model.matrix(nxt.kind, nxt.alpha), rights, tau)
        return moved

    q0 = model.initial(root.kind, first_angle)
    for _ in range(MAX_SWEEPS):
        eps = 0.0
        rights = _rights(model, root, ratio)
        tau = max(factor * weights(root, q0, rights), 1e-15)
        moved = sweep(root, q0, rights, tau)
        new_ratio = _exact(model, root, first_angle).expected_cost
        done = not moved or new_ratio >= ratio * (1.0 - 1e-13)
        ratio = new_ratio
        if done:
            break
    return ratio, eps


# -- the planner -----------------------------------------------------------------------------


def _linear(model: _Model, kinds: Sequence[str], angles: Sequence[float], final: int) -> _Node:
    """A plan as a tree: one branch on every reading, then declare state ``final``."""
    part, theta = model.space.stable(final)
    leaf: _Node | Declare = Declare(part, model.space.names[part], float(theta), 0.0)
    whole = Branch(-math.inf, math.inf, 1.0, Reject())
    bins = model.branch_bins([whole])
    lik = np.ones((model.n, 1))
    for t, a in zip(kinds[::-1], angles[::-1], strict=True):
        leaf = _Node(t, float(a), [whole], bins, [leaf], 0.0, lik)
    if not isinstance(leaf, _Node):  # pragma: no cover - a plan has a step
        raise PlanningError("internal error: an empty plan")
    return leaf


def plan_noisy_policy(
    problems: Problem | Iterable[Problem],
    sensor: str | WidthSensor = "width",
    max_actions: int = DEFAULT_MAX_ACTIONS,
    noise: NoiseModel | None = None,
    *,
    payoff: Payoff | ArrayLike | None = None,
    part_prior: str | Sequence[float] | None = None,
    max_first_angles: int = 512,
    max_iterations: int = 50,
    max_memory_mb: float = DEFAULT_MAX_MEMORY_MB,
    time_limit_s: float | None = None,
    refine: bool = True,
    sensorless: bool = True,
    _always: bool = False,
) -> Policy:
    """The Bayes policy under noisy actions (see the module notes for what is optimal).

    Parameters
    ----------
    problems : Problem or iterable of Problem
        One problem, or one per candidate part (as :func:`.policy.plan_policy`).
    sensor : str or WidthSensor
        ``"width"`` (exact), ``"width:SIGMA,RES"`` (part units), or a :class:`WidthSensor`.
    max_actions : int
        At most this many actions on any path (>= 1; default 3).
    noise : NoiseModel, optional
        The action noise; ``None`` or no noise (and no payoff): :func:`.policy.plan_policy`'s
        policy.
    payoff : Payoff or array_like of shape (K,), optional
        One part only: the value in [0, 1] of each final state
        (:mod:`bayesgrasp.model.payoff`). A declaring leaf then stops and earns the payoff
        of the state the part is in, and the policy minimises the expected cost per unit
        payoff (see the module notes).
    part_prior : str or sequence of float, optional
        Prior weights of the candidate parts (default equal).
    max_first_angles : int
        Largest number of candidate first angles tried exhaustively.
    max_iterations : int
        Most parametric steps.
    max_memory_mb : float
        About the most memory (MB) the programme's kept beliefs may take (their images,
        reading masses and bounds; > 0): past it the search stops with a PlanningError.
    time_limit_s : float or None
        Most seconds the search may take (``None``: no bound); past it the search stops with
        a :class:`~bayesgrasp.planning.policy.SearchStopped` saying so.
    refine : bool
        Refine the turns (see the module notes); ``False`` keeps the candidate turns.
    sensorless : bool
        Also plan the noise-aware sensorless plan (one part): reported as
        ``Policy.sensorless_cost`` and one of the known policies.

    Returns
    -------
    Policy
        Its figures exact under the noise; ``noise`` and ``refinement_bound`` set.

    Raises
    ------
    PlanningError
        As :func:`.policy.plan_policy`, a ``max_memory_mb`` not above 0, or a search whose
        beliefs take more than ``max_memory_mb``.
    SensorError
        On a bad sensor or part prior.

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
    >>> noise = NoiseModel(TurnNoise("uniform", math.radians(3)))
    >>> pol = plan_noisy_policy(tri, "width", 2, noise)
    >>> pol.expected_cost <= plan_policy(tri, "width", 2).expected_cost + 1e-9
    True
    """
    sens = parse_sensor(sensor)
    memory_bytes(max_memory_mb)  # a bad bound: refused before any work
    seconds = time_seconds(time_limit_s)
    if noise is not None and not isinstance(noise, NoiseModel):
        raise PlanningError(f"`noise` must be a NoiseModel; got {type(noise).__name__}")
    if payoff is None and (noise is None or (noise.exact and not _always)):
        return plan_policy(
            problems,
            sens,
            max_actions,
            part_prior=part_prior,
            max_first_angles=max_first_angles,
            max_iterations=max_iterations,
            sensorless=sensorless,
        )
    noise = noise or NoiseModel()
    space = policy_space(problems, part_prior, max_actions)
    main = space.problems[0]
    model = _Model(space, sens, noise)
    solver = make_solver(space, sens, DEFAULT_PRUNE)
    u: FloatArray | None = None
    if payoff is not None:
        if space.n_parts > 1:
            raise PlanningError("a payoff is for one part; got several candidate parts")
        u = as_vector(payoff, main.states)
        model.payoff = u
        # Stopping earns ``q . u``: the programme's success is that one row (no pi-pair
        # bound: both states of a pair may pay; the payoff is at most 1, so the bound
        # ``U = total`` holds).
        solver.goal = cast(Any, u[None, :])
        solver.goal_is_identity = False
        solver.use_pairs = False
    solver.max_bytes = memory_bytes(max_memory_mb)
    solver.deadline, solver.time_limit = time.monotonic() + seconds, seconds
    for k in solver.kinds:
        mid, half = model.candidates(k.name, np.asarray(k.mid), np.asarray(k.half_width))
        if main.accuracy > 0:  # only turns that keep their class under the accuracy
            keep = half >= main.accuracy
            mid, half = mid[keep], half[keep]
        mats = model.matrices(k.name, mid)
        if noise.contact > 0:
            # A turn whose matrix an earlier (wider) candidate has already is the same
            # action: under exact turns, the middle of a noise-free class lies in a class
            # of the refinement (where the matrix is constant), whose middle is a candidate
            # too. (Without contact noise the candidates are the noise-free classes, each
            # its own action.)
            once = _first_of_each_matrix(mats)
            mid, half, mats = mid[once], half[once], mats[once]
        k.mid, k.half_width = mid, half
        k.classes = np.arange(len(mid), dtype=np.intp)
        k.transfer = np.zeros((len(mid), space.n_states), dtype=np.intp)  # unused: matrices
        k.matrices = np.ascontiguousarray(mats)
    kinds = solver.kinds
    angles, angles_exact = candidate_first_angles(space, main.action_kinds, max_first_angles)
    roots = np.array([model.initial(k.name, a) for k in kinds for a in angles])  # (R, N)
    root_kind = [ti for ti in range(len(kinds)) for _ in angles]
    root_angle = [a for _ in kinds for a in angles]

    # Known policies: their exact ratios under the noise start the parametric search.
    known: list[tuple[_Node, float, str]] = []
    free = plan_policy(
        list(space.problems),
        sens,
        max_actions,
        part_prior=list(space.part_prior),
        max_first_angles=max_first_angles,
        max_iterations=max_iterations,
        sensorless=False,
    )
    known.append((_mutable(free.root, model), free.root.step.alpha, "noise-free policy"))
    sensorless_cost: float | None = None
    if sensorless and space.n_parts == 1:
        res = plan_noisy(main, noise, u, max_actions=max_actions)
        opt = res.bayes_plan
        sensorless_cost = opt.option.expected_cost
        kinds_ = [s.kind for s in opt.option.steps]
        alphas = [s.alpha for s in opt.option.steps]
        known.append(
            (_linear(model, kinds_, alphas, opt.evaluation.final_state), alphas[0], "sensorless")
        )
    lam = start_ratio(solver, roots, root_kind)
    evaluated = [(_exact(model, t, a).expected_cost, t, a, label) for t, a, label in known]
    for c, *_ in evaluated:
        if math.isfinite(c):
            lam = min(lam, c)

    best_pick, it = search_policy(
        solver, roots, root_kind, lam, max_actions, max_iterations, sens.sigma > 0
    )
    builder = PolicyBuilder(solver, max_actions)
    k = kinds[root_kind[best_pick]]
    root = builder.node(
        k, root_angle[best_pick], math.inf, roots[best_pick], 1.0, max_actions - 1, 0.0, 1, True
    )
    dp = _mutable(root, model)
    cands = [(_exact(model, dp, root.step.alpha).expected_cost, dp, root.step.alpha, "dp")]
    cands += evaluated
    # Refinement (the dominant work) for the programme's policy, and for a known one only
    # if it is already better than that.
    out: list[tuple[float, float, int, _Node, float, str]] = []
    for order, (c, tree, a, label) in enumerate(cands):
        eps = 0.0
        if refine and math.isfinite(c) and (order == 0 or c < out[0][0]):
            c, eps = _refine(model, tree, a, c)
        out.append((c, eps, order, tree, a, label))
    c, eps, _, tree, a, label = min(out, key=lambda x: (x[0], x[2]))
    logger.debug("noisy policy: %s, ratio %.12g", label, c)
    for node, first in _nodes(tree):
        node.margin = math.inf if first else 0.0
    ev = _exact(model, tree, a)
    return Policy(
        ev.strategy,
        space.names,
        tuple(float(w) for w in space.part_prior),
        sens,
        max_actions,
        ev.expected_cost,
        ev.success_probability,
        ev.cycle_cost,
        ev.reject_probability,
        ev.expected_actions,
        ev.expected_entropy,
        sensorless_cost,
        it,
        len(solver.memo),
        angles_exact,
        main.part.units,
        solver.searched,
        None if noise.exact else noise,
        eps,
        None if u is None else tuple(float(x) for x in u),
    )


def evaluate_policy(
    problems: Problem | Iterable[Problem],
    policy: Policy,
    noise: NoiseModel | None = None,
) -> Policy:
    """A policy's figures recomputed exactly under a noise model (its tree unchanged).

    Every reading history's belief is propagated through each node's noisy matrix and the
    reading likelihoods of its branches (see the module notes); the branch and leaf
    probabilities are those under the noise.

    Parameters
    ----------
    problems : Problem or iterable of Problem
        The candidate parts, in the policy's order.
    policy : Policy
    noise : NoiseModel, optional
        Default: exact actions.

    Returns
    -------
    Policy

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
    >>> pol = plan_policy(tri, "width", 2)
    >>> abs(evaluate_policy(tri, pol).expected_cost - pol.expected_cost) < 1e-12
    True
    """
    noise = noise or NoiseModel()
    space = StateSpace.build(problems, list(policy.part_prior))
    model = _Model(space, policy.sensor, noise)
    if policy.payoff is not None:
        model.payoff = np.asarray(policy.payoff, dtype=np.float64)
    tree = _mutable(policy.root, model)
    ev = _exact(model, tree, policy.root.step.alpha)
    return dataclasses.replace(
        policy,
        root=ev.strategy,
        expected_cost=ev.expected_cost,
        success_probability=ev.success_probability,
        cycle_cost=ev.cycle_cost,
        reject_probability=ev.reject_probability,
        expected_actions=ev.expected_actions,
        expected_entropy=ev.expected_entropy,
        noise=None if noise.exact else noise,
    )
