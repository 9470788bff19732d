"""Strategies and their exact evaluation: one model for plans and policies (the paper, section 6).

A *strategy* is a tree (:class:`~bayesgrasp.planning.policy.PolicyNode`): each node acts (an
action kind and a gripper turn; the root's turn is the world gripper angle, as in plans) and
branches on the jaw-width reading that follows; each leaf declares a final state
(:class:`~bayesgrasp.planning.policy.Declare`: part and orientation in the frame of the last
action) and verifies, or rejects (:class:`~bayesgrasp.planning.policy.Reject`). A linear plan
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
Monte Carlo runs of the same strategies and against every planner's own figures).

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

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PlanningError
from ..model.noise import NoiseModel, NoisyTransitions
from ..model.problem import Problem, nearest_state
from ..model.sensing import StateSpace, WidthSensor, entropy_bits, parse_sensor
from .policy import Branch, Declare, PolicyNode, Reject
from .result import PlanOption

__all__ = ["Evaluation", "evaluate", "plan_strategy"]

FloatArray = NDArray[np.float64]
Leaf = Declare | Reject


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
    """

    success_probability: float
    expected_cost: float
    cycle_cost: float
    reject_probability: float
    expected_actions: float
    expected_entropy: tuple[float, ...]
    final_distribution: FloatArray

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
    if not option.steps:
        raise PlanningError("a plan must have at least one action")
    nxt: PolicyNode | Leaf = Declare(
        part, problem.part.name, float(option.final_orientation), float(option.success_probability)
    )
    for step in reversed(option.steps):
        nxt = PolicyNode(step, (Branch(-math.inf, math.inf, 1.0, nxt),))
    assert isinstance(nxt, PolicyNode)  # the loop ran at least once
    return nxt


class _Walk:
    """The propagation of one evaluation: the model's matrices and the running sums."""

    def __init__(
        self,
        space: StateSpace,
        sensor: WidthSensor | None,
        noise: NoiseModel | None,
        payoff: FloatArray | None,
    ) -> None:
        self.space = space
        self.noisy = (
            None
            if noise is None or (noise.exact and noise.contact == 0)
            else [NoisyTransitions(p, noise) for p in space.problems]
        )
        self.bins = None if sensor is None else space.bins(sensor)
        self.payoff = payoff
        self.cost = space.problems[0].cost
        self.success = self.action_cost = self.verify_cost = self.reject = self.actions = 0.0
        self.final = np.zeros(space.n_states)
        self.entropy: list[tuple[int, float, float]] = []  # (level, mass, entropy) at leaves
        self.passing: list[tuple[int, float, float]] = []  # (level, mass, entropy) at nodes

    def first(self, kind: str, angle: float) -> FloatArray:
        """Joint belief (unnormalised by nothing: part prior times state mass) after the root."""
        sp = self.space
        if self.noisy is None:
            return sp.initial(kind, angle)
        parts = [
            w * nt.initial(kind, angle) for w, nt in zip(sp.part_prior, self.noisy, strict=True)
        ]
        return np.concatenate(parts)

    def act(self, q: FloatArray, kind: str, alpha: float) -> FloatArray:
        """``q M_kind(alpha)``, part by part."""
        sp = self.space
        out = np.zeros_like(q)
        for j, pb in enumerate(sp.problems):
            lo, hi = int(sp.offsets[j]), int(sp.offsets[j + 1])
            qj = q[lo:hi]
            if self.noisy is None:
                theta = pb.transfer(kind)(np.asarray(pb.states.stable) - alpha)
                to = nearest_state(pb.states, np.asarray(theta, dtype=np.float64))
                out[lo:hi] = np.bincount(to, weights=qj, minlength=hi - lo)
            else:
                out[lo:hi] = qj @ self.noisy[j].matrix(kind, alpha)
        return out

    def readings(self, branches: Sequence[Branch]) -> tuple[FloatArray, NDArray[np.intp]]:
        """The likelihood ``L[i, b]`` of a reading in bin ``b`` in state ``i``; each bin's branch.

        The robot's belief after a reading is the prior times the likelihood of the reading's
        bin, whichever branch the bin belongs to: the belief (and its entropy) is carried bin
        by bin, and the branch only says what to do next. Without a sensor there is one bin.
        """
        if self.bins is None:
            if len(branches) != 1:
                raise PlanningError(
                    "a strategy that branches on readings needs the sensor it was planned for"
                )
            return np.ones((self.space.n_states, 1)), np.zeros(1, dtype=np.intp)
        b = self.bins
        # A bin lies inside one branch (the planners' branches join whole bins): its lower
        # end (for the first bin, -inf) falls in that branch.
        his = np.array([br.hi for br in branches])
        return b.likelihood, np.searchsorted(his[:-1], b.lo, side="right")

    def node(self, node: PolicyNode, q: FloatArray, level: int, first: bool) -> None:
        mass = float(q.sum())
        if mass <= 0.0:
            return
        self.actions += mass
        self.action_cost += mass * self.cost.action_cost(node.step.kind, first)
        lik, branch = self.readings(node.branches)
        joint = q[:, None] * lik  # (N, B) mass of each state and reading
        masses = joint.sum(axis=0)
        for b in np.flatnonzero(masses > 0):
            qb, m = joint[:, b], float(masses[b])
            h = entropy_bits(qb / m)
            nxt = node.branches[int(branch[b])].next
            if isinstance(nxt, PolicyNode):
                self.passing.append((level, m, h))
                self.node(nxt, self.act(qb, nxt.step.kind, nxt.step.alpha), level + 1, False)
            else:
                self.entropy.append((level, m, h))
                self.leaf(nxt, qb)

    def leaf(self, leaf: Leaf, q: FloatArray) -> None:
        self.final += q
        if isinstance(leaf, Reject):
            self.reject += float(q.sum())
            return
        sp = self.space
        self.verify_cost += float(q.sum()) * self.cost.verify
        if self.payoff is not None:
            self.success += float(q @ self.payoff)
            return
        lo = int(sp.offsets[leaf.part])
        good = sp.problems[leaf.part].success_states(leaf.orientation)
        self.success += float(q[lo : lo + len(good)][good].sum())

    def entropies(self, depth: int) -> tuple[float, ...]:
        """Expected entropy after each level's reading (ended paths keep their last belief)."""
        out = [0.0] * depth
        for level, m, h in self.passing:
            out[level - 1] += m * h
        for level, m, h in self.entropy:
            for x in range(level, depth + 1):
                out[x - 1] += m * h
        return tuple(out)


def _depth(node: PolicyNode) -> int:
    return 1 + max(
        (_depth(b.next) for b in node.branches if isinstance(b.next, PolicyNode)), default=0
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
    walk = _Walk(space, None if sensor is None else parse_sensor(sensor), noise, u)
    q = walk.first(strategy.step.kind, strategy.step.alpha)
    walk.node(strategy, q, 1, True)
    p = walk.success
    cycle = walk.action_cost + walk.verify_cost + walk.cost.retry * (1.0 - p)
    return Evaluation(
        success_probability=p,
        expected_cost=cycle / p if p > 0 else math.inf,
        cycle_cost=cycle,
        reject_probability=walk.reject,
        expected_actions=walk.actions,
        expected_entropy=walk.entropies(_depth(strategy)),
        final_distribution=walk.final,
    )
