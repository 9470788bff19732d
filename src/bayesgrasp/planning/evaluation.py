"""Strategies and their exact evaluation: one model for plans and policies (the paper, section 6).

A *strategy* is a tree (:class:`~bayesgrasp.planning.policy_tree.PolicyNode`): each node acts (an
action kind and a gripper turn; the root's turn is the world gripper angle, as in plans) and
branches on the jaw-width reading that follows; each leaf declares a final state
(:class:`~bayesgrasp.planning.policy_tree.Declare`: part and orientation in the frame of the last
action) and verifies, or rejects (:class:`~bayesgrasp.planning.policy_tree.Reject`). A linear plan
is the strategy that never branches: every node has one branch over all readings
(:func:`plan_strategy`).

The evaluation (:func:`evaluate`) follows the paper's section 6 framework literally. A belief
``q`` over the states (the stable orientations of each candidate part, weighted by the part
prior) is propagated down the tree:

- the first action at world angle ``a`` leaves ``q_1 = prior mass of each basin`` (with a turn
  error, the prior convolved with the error: :meth:`NoisyTransitions.initial`);
- a later action turned by ``alpha`` maps ``q -> q M_t(alpha)``, with ``M_t`` the action's
  transition matrix: one-hot from the transfer function ``F_t`` (state ``i`` goes to the
  state of ``F_t(S_i - alpha)``) when actions are exact, the row-stochastic matrix of the
  noise model otherwise (:class:`~bayesgrasp.model.noise.NoisyTransitions`);
- a reading multiplies ``q`` by its likelihood ``P(reading in [lo, hi) | state)`` (Bayes'
  rule, unnormalised: the mass left is the probability of reaching the branch); without a
  sensor there is one branch and nothing is read;
- a leaf that declares part ``j`` at orientation ``o`` succeeds on the states of its goal set
  (:meth:`Problem.success_states`); with a payoff vector ``u`` it earns ``q . u`` instead.

Summed over the leaves this gives, per *cycle* (one run of the tree on a fresh part), the
success probability ``P`` (the expected payoff with a payoff), the expected action cost
``E[A]`` (each node's cost times the mass reaching it; the root at its first-action cost), the
verification cost ``v`` times the declaring mass, the rejection probability, the expected
number of actions and the expected entropy of the belief after each level. Cycles repeat until
one succeeds (geometric, mean ``1 / P``), each failure paying the retry overhead ``rho``, so

    E[cost] = (E[A] + v P_declare + rho (1 - P)) / P,

the paper's ``C / p`` for a linear plan (:meth:`~bayesgrasp.model.cost.CostModel.expected_cost`)
and the cost every planner minimises (:mod:`bayesgrasp.planning.policy`'s module notes). All of
it is exact: sums of products of the matrices, nothing sampled (the tests hold it against
Monte Carlo runs of the same strategies and against every planner's own figures). The policy
planner under noisy actions (:mod:`.noisy_policy`) computes its figures with it
(:func:`evaluate_tree`, with its own cached matrices).

Examples
--------
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.planning import plan_exact
>>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
>>> best = plan_exact(pb).bayes_plan
>>> ev = evaluate(pb, plan_strategy(pb, best))
>>> round(ev.success_probability, 9) == round(best.success_probability, 9)
True
>>> round(ev.expected_cost, 9) == round(best.expected_cost, 9)
True
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Protocol, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PlanningError
from ..model.noise import NoiseModel, NoisyTransitions
from ..model.problem import Problem, nearest_state
from ..model.sensing import ReadingBins, StateSpace, WidthSensor, parse_sensor
from .policy_tree import Branch, Declare, Leaf, PolicyNode, Reject, tree_depth
from .result import PlanOption, PlanStep

__all__ = [
    "Evaluation",
    "ExactTransitions",
    "NoisyJointTransitions",
    "Transitions",
    "entropies",
    "evaluate",
    "evaluate_tree",
    "linear_strategy",
    "plan_strategy",
    "transitions",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True)
class Evaluation:
    """A strategy's figures, exact under its model (see the module notes).

    Attributes
    ----------
    success_probability : float
        ``P``: the probability that a cycle succeeds (with a payoff: its expected payoff).
    expected_cost : float
        Expected cost until a cycle succeeds (``inf`` when ``P = 0``).
    cycle_cost : float
        Expected cost of one cycle, the retry overhead of a failure included.
    reject_probability : float
        Probability that a cycle ends in a rejection.
    expected_actions : float
        Expected number of actions in one cycle.
    expected_entropy : tuple of float
        Expected entropy (bits) of the normalised belief after the reading of each level (a
        path that ended earlier keeps its last belief).
    final_distribution : ndarray of shape (N,)
        Probability of ending a cycle at each joint state (frame of the last action), over
        every leaf.
    strategy : PolicyNode
        The tree with its probabilities under the model: each branch's given its node, each
        declaration's success given its leaf (with a payoff, the leaf names the state of most
        value and its success is the payoff earned).
    """

    success_probability: float
    expected_cost: float
    cycle_cost: float
    reject_probability: float
    expected_actions: float
    expected_entropy: tuple[float, ...]
    final_distribution: FloatArray
    strategy: PolicyNode

    @property
    def expected_total_actions(self) -> float:
        """Expected number of actions until a cycle succeeds."""
        p = self.success_probability
        return self.expected_actions / p if p > 0 else math.inf


def plan_strategy(problem: Problem, option: PlanOption, part: int = 0) -> PolicyNode:
    """A linear plan as the strategy that never branches.

    Every node has one branch over all readings; the last leads to the declaration of the
    plan's final orientation (of candidate ``part``), with the plan's success probability.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> root = plan_strategy(pb, plan_exact(pb).bayes_plan)
    >>> [b.lo for b in root.branches], root.branches[0].next.step.kind
    ([-inf], 'squeeze')
    """
    leaf = Declare(
        part, problem.part.name, float(option.final_orientation), float(option.success_probability)
    )
    return linear_strategy(option.steps, leaf)


def linear_strategy(steps: Sequence[PlanStep], leaf: Declare | Reject) -> PolicyNode:
    """The strategy that makes ``steps`` whatever it reads, then ends at ``leaf``.

    Examples
    --------
    >>> root = linear_strategy([PlanStep("squeeze", 0.0)], Reject())
    >>> root.step.kind, root.branches[0].next
    ('squeeze', Reject())
    """
    if not steps:
        raise PlanningError("a plan must have at least one action")
    nxt: PolicyNode | Leaf = leaf
    for step in reversed(steps):
        nxt = PolicyNode(step, (Branch(-math.inf, math.inf, 1.0, nxt),))
    return cast(PolicyNode, nxt)  # the loop ran at least once


class Transitions(Protocol):
    """What the evaluation asks of an action model (joint states of every candidate part)."""

    def initial(self, kind: str, angle: float) -> FloatArray:
        """Joint belief (part prior times state mass) after the first action at ``angle``."""
        ...

    def matrix(self, kind: str, alpha: float) -> FloatArray:
        """The (N, N) row-stochastic matrix of an action turned by ``alpha``."""
        ...


class ExactTransitions:
    """Exact actions: state ``i`` goes to the state of ``F_t(S_i - alpha)``, part by part."""

    def __init__(self, space: StateSpace) -> None:
        self.space = space

    def initial(self, kind: str, angle: float) -> FloatArray:
        """The prior mass of each state's basins, shifted by ``angle``, times the part prior."""
        return self.space.initial(kind, angle)

    def matrix(self, kind: str, alpha: float) -> FloatArray:
        """The one-hot matrix of the transfer functions turned by ``alpha``."""
        sp = self.space
        m = np.zeros((sp.n_states, sp.n_states))
        for j, pb in enumerate(sp.problems):
            lo = int(sp.offsets[j])
            theta = pb.transfer(kind)(np.asarray(pb.states.stable) - alpha)
            to = nearest_state(pb.states, np.asarray(theta, dtype=np.float64))
            m[lo + np.arange(pb.n_states), lo + to] = 1.0
        return m


class NoisyJointTransitions:
    """Noisy actions: the block-diagonal matrices of each part's :class:`NoisyTransitions`."""

    def __init__(
        self,
        space: StateSpace,
        noise: NoiseModel,
        parts: Sequence[NoisyTransitions] | None = None,
    ) -> None:
        self.space = space
        # each part's matrices (``parts``: made already, one per candidate, kept between calls)
        self.parts = (
            list(parts)
            if parts is not None
            else [NoisyTransitions(p, noise) for p in space.problems]
        )

    def initial(self, kind: str, angle: float) -> FloatArray:
        """The prior convolved with the first action's error, times the part prior."""
        weights = self.space.part_prior
        return np.concatenate(
            [w * nt.initial(kind, angle) for w, nt in zip(weights, self.parts, strict=True)]
        )

    def propagate(self, hist: FloatArray, kind: str, alpha: float) -> FloatArray:
        """``hist @ matrix(kind, alpha)`` for beliefs ``hist`` (H, N), from the rows with mass.

        One part: only the rows of the states some belief gives mass are computed (as the
        noise-aware planner's :meth:`~bayesgrasp.planning.noisy.PlanEvaluator.step`).
        """
        if len(self.parts) != 1:
            return np.asarray(hist @ self.matrix(kind, alpha), dtype=np.float64)
        rows = np.flatnonzero(hist.any(axis=0))
        m = self.parts[0].matrices(kind, [alpha], rows)[0]  # (R, N)
        return np.asarray(hist[:, rows] @ m, dtype=np.float64)

    def matrix(self, kind: str, alpha: float) -> FloatArray:
        """The block-diagonal matrix of every part's noisy action turned by ``alpha``."""
        sp = self.space
        if len(self.parts) == 1:
            return self.parts[0].matrix(kind, alpha)
        m = np.zeros((sp.n_states, sp.n_states))
        for j, nt in enumerate(self.parts):
            lo, hi = int(sp.offsets[j]), int(sp.offsets[j + 1])
            m[lo:hi, lo:hi] = nt.matrix(kind, alpha)
        return m


def transitions(space: StateSpace, noise: NoiseModel | None = None) -> Transitions:
    """The action model of a state space: exact, or under ``noise``."""
    if noise is None or noise.exact:
        return ExactTransitions(space)
    return NoisyJointTransitions(space, noise)


class _Walk:
    """One evaluation: the model, and the sums the leaves and nodes add to."""

    def __init__(
        self,
        space: StateSpace,
        model: Transitions,
        bins: ReadingBins | None,
        payoff: FloatArray | None,
        check: Callable[[], None] | None = None,
    ) -> None:
        self.space, self.model, self.bins, self.payoff = space, model, bins, payoff
        self.check = check  # called before each node's and branch's work (it may raise)
        # ``hist @ M(alpha)`` computed by the model itself, when it can (only the rows of
        # states with mass, say); else by its matrix
        self.propagate = getattr(model, "propagate", None)
        self.cost = space.problems[0].cost
        self.success = self.action_cost = self.verify_cost = self.reject = self.actions = 0.0
        self.final = np.zeros(space.n_states)
        self.passing: dict[int, float] = {}  # level -> sum of mass * entropy, acting histories
        self.ended: list[tuple[int, float]] = []  # (level, mass * entropy) at the leaves

    def readings(self, branches: Sequence[Branch]) -> tuple[FloatArray, list[IntArray]]:
        """The likelihood ``L[i, b]`` of a reading in bin ``b`` in state ``i``; each branch's bins.

        The robot's belief after a reading is the prior times the likelihood of the reading's
        bin, whichever branch the bin belongs to: beliefs (and their entropies) are carried a
        reading history at a time, and the branch only says what to do next. Without a
        sensor there is one bin.
        """
        if self.bins is None:
            if len(branches) != 1:
                raise PlanningError(
                    "a strategy that branches on readings needs the sensor it was planned for"
                )
            return _NO_READING, [_ONE_BIN]
        b = self.bins
        # A bin lies inside one branch (the planners' branches join whole bins): its lower
        # end (for the first bin, -inf) falls in that branch.
        his = np.array([br.hi for br in branches])
        owner = np.searchsorted(his[:-1], b.lo, side="right")
        return b.likelihood, [np.flatnonzero(owner == k) for k in range(len(branches))]

    def blocks(self, rows: int, width: int) -> Iterator[slice]:
        """Slices of ``rows`` rows of ``width`` numbers each, :attr:`check` before each.

        One slice of all rows without a check (then nothing is gained by blocks).
        """
        if self.check is None:
            yield slice(0, rows)
            return
        step = max(1, _BLOCK // max(width, 1))
        for lo in range(0, max(rows, 1), step):
            self.check()
            yield slice(lo, min(lo + step, rows))

    def node(self, node: PolicyNode, hist: FloatArray, level: int, first: bool) -> PolicyNode:
        """The node with its exact probabilities, given the beliefs ``hist`` (H, N) reaching it.

        Each row of ``hist`` is the unnormalised belief of one reading history before the
        node's action (the root: after it, as the first action is the prior's).
        """
        if self.check is not None:
            self.check()
        if first:
            img = hist
        elif self.propagate is not None:
            img = self.propagate(hist, node.step.kind, node.step.alpha)
        else:
            img = hist @ self.model.matrix(node.step.kind, node.step.alpha)
        mass = float(img.sum())
        self.actions += mass
        self.action_cost += mass * self.cost.action_cost(node.step.kind, first)
        lik, bins = self.readings(node.branches)
        n = self.space.n_states
        out: list[Branch] = []
        for br, ix in zip(node.branches, bins, strict=True):
            # (H * bins, N): every history continued by every reading of the branch (without
            # a sensor, nothing is read: the histories go on as they are); the histories of
            # mass. Row by row, so a check may come between blocks of rows.
            if self.bins is None:
                parts = [img]
            else:
                lik_b = lik[:, ix].T[None]
                parts = [
                    (img[s, None, :] * lik_b).reshape(-1, n)
                    for s in self.blocks(len(img), len(ix) * n)
                ]
            per = np.concatenate(parts) if len(parts) > 1 else parts[0]
            w = per.sum(axis=1)
            keep = w > 0
            per, w = per[keep], w[keep]
            pb = float(w.sum())
            h = 0.0
            if len(w):
                ent = [entropies(per[s] / w[s, None]) for s in self.blocks(len(w), n)]
                h = float((w * (np.concatenate(ent) if len(ent) > 1 else ent[0])).sum())
            nxt: PolicyNode | Leaf
            if isinstance(br.next, PolicyNode):
                self.passing[level] = self.passing.get(level, 0.0) + h
                nxt = self.node(br.next, per, level + 1, False) if len(w) else _unreached(br.next)
            else:
                self.ended.append((level, h))
                nxt = self.leaf(br.next, per.sum(axis=0), pb)
            out.append(Branch(br.lo, br.hi, pb / mass if mass > 0 else 0.0, nxt))
        return PolicyNode(node.step, tuple(out), node.margin)

    def leaf(self, leaf: Leaf, q: FloatArray, mass: float) -> Leaf:
        """The leaf reached with the (unnormalised) belief ``q`` of mass ``mass``."""
        self.final += q
        if isinstance(leaf, Reject):
            self.reject += mass
            return leaf
        self.verify_cost += mass * self.cost.verify
        if self.payoff is not None:  # the payoff earned; the leaf names the state of most value
            s = float(q @ self.payoff)
            part, theta = self.space.stable(int(np.argmax(q * self.payoff)))
            leaf = Declare(part, self.space.names[part], theta, leaf.success_probability)
        else:
            lo = int(self.space.offsets[leaf.part])
            good = self.space.problems[leaf.part].success_states(leaf.orientation)
            s = float(q[lo : lo + len(good)][good].sum())
        self.success += s
        return dataclasses.replace(leaf, success_probability=s / mass if mass > 0 else 0.0)

    def entropies(self, depth: int) -> tuple[float, ...]:
        """Expected entropy after each level's reading (ended paths keep their last belief)."""
        out = [self.passing.get(level, 0.0) for level in range(1, depth + 1)]
        for level, h in self.ended:
            for x in range(level, depth + 1):
                out[x - 1] += h
        return tuple(out)


# Numbers of a belief array computed between two checks of a time bound (``_Walk.blocks``).
_BLOCK = 1 << 21

# Without a sensor: no likelihood (the walk reads nothing), and one bin.
_NO_READING = np.ones((0, 1))
_ONE_BIN = np.zeros(1, dtype=np.intp)


def _unreached(node: PolicyNode) -> PolicyNode:
    """A subtree no reading history reaches: its probabilities 0."""
    return PolicyNode(
        node.step,
        tuple(
            Branch(
                b.lo, b.hi, 0.0, _unreached(b.next) if isinstance(b.next, PolicyNode) else b.next
            )
            for b in node.branches
        ),
        node.margin,
    )


def entropies(q: FloatArray) -> FloatArray:
    """Shannon entropy (bits) of each row of normalised beliefs ``q`` (M, N).

    Examples
    --------
    >>> entropies(np.array([[0.5, 0.5], [0.25, 0.75]])).round(6).tolist()
    [1.0, 0.811278]
    """
    logs = np.zeros_like(q)
    np.log2(q, out=logs, where=q > 0)  # 0 log 0 = 0
    return np.asarray(-(q * logs).sum(axis=1), dtype=np.float64)


def evaluate_tree(
    space: StateSpace,
    strategy: PolicyNode,
    model: Transitions,
    bins: ReadingBins | None = None,
    payoff: FloatArray | None = None,
    check: Callable[[], None] | None = None,
) -> Evaluation:
    """:func:`evaluate` on a built state space, action model and reading bins.

    For planners that evaluate many trees of one problem (the matrices of ``model`` may be
    kept between calls). ``check`` is called before the work of each node and branch: a
    planner's time bound may stop the evaluation there by raising.
    """
    walk = _Walk(space, model, bins, payoff, check)
    q = model.initial(strategy.step.kind, strategy.step.alpha)[None, :]
    root = walk.node(strategy, q, 1, True)
    p = walk.success
    cycle = walk.action_cost + walk.verify_cost + walk.cost.retry * (1.0 - p)
    return Evaluation(
        success_probability=p,
        expected_cost=cycle / p if p > 0 else math.inf,
        cycle_cost=cycle,
        reject_probability=walk.reject,
        expected_actions=walk.actions,
        expected_entropy=walk.entropies(tree_depth(strategy)),
        final_distribution=walk.final,
        strategy=root,
    )


def evaluate(
    problems: Problem | Iterable[Problem],
    strategy: PolicyNode,
    *,
    sensor: str | WidthSensor | None = None,
    noise: NoiseModel | None = None,
    payoff: ArrayLike | None = None,
    part_prior: str | Sequence[float] | None = None,
) -> Evaluation:
    """The exact figures of a strategy under its model (see the module notes).

    Parameters
    ----------
    problems : Problem or iterable of Problem
        One problem, or one per candidate part (the first's costs are used for all).
    strategy : PolicyNode
        The root of the tree (a linear plan: :func:`plan_strategy`).
    sensor : str or WidthSensor, optional
        The sensor whose readings the tree branches on; ``None`` for a tree that never
        branches.
    noise : NoiseModel, optional
        Turn error and contact asynchrony of the actions (default: exact actions).
    payoff : array_like of shape (N,), optional
        Value in [0, 1] of ending at each state (default: the goal of each declaration).
    part_prior : str or sequence of float, optional
        Weights of the candidate parts (default equal).

    Returns
    -------
    Evaluation

    Raises
    ------
    PlanningError
        If the tree branches but no sensor is given, or the payoff has the wrong length.
    """
    space = StateSpace.build(problems, part_prior)
    u = None
    if payoff is not None:
        u = np.asarray(payoff, dtype=np.float64)
        if u.shape != (space.n_states,):
            raise PlanningError(
                f"`payoff` must have one value per state ({space.n_states}); got shape {u.shape}"
            )
    bins = None if sensor is None else space.bins(parse_sensor(sensor))
    return evaluate_tree(space, strategy, transitions(space, noise), bins, u)
