"""Exact evaluation of linear plans under noisy actions and a payoff.

A plan of actions ``t_1..t_k`` at angles ``a, alpha_2..alpha_k`` ends in the distribution

    q_k = q_1(a) M_{t_2}(alpha_2) ... M_{t_k}(alpha_k)

(``q_1`` the prior convolved with the first action,
:meth:`~bayesgrasp.model.noise.NoisyTransitions.initial`; ``M_t`` the row-stochastic matrix
of a noisy action, :mod:`bayesgrasp.model.noise`) and earns ``E[payoff] = q_k . u``: ``u``
the payoff vector (:mod:`bayesgrasp.model.payoff`), or for the problem's goal the indicator
of the best final state (of its symmetry orbit for a symmetry goal). Its cost is
``E[cycle cost] / E[payoff]``. :class:`PlanEvaluator` is what the noise-aware planners
(:mod:`bayesgrasp.planning.noisy`, :mod:`bayesgrasp.planning.robust`) evaluate their
candidates with, batched over the turns a search tries; :func:`evaluate_plan` evaluates one
plan by the evaluator of every strategy (:func:`~bayesgrasp.planning.evaluation.evaluate_tree`).

Examples
--------
>>> import math
>>> from bayesgrasp.geometry.polygon import Part
>>> from bayesgrasp.model.noise import TurnNoise
>>> from bayesgrasp.planning.exact import plan_exact
>>> pb = Problem.build(Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)]))
>>> steps = plan_exact(pb).bayes_plan.steps
>>> ev = evaluate_plan(pb, NoiseModel(TurnNoise("uniform", math.radians(5))), steps)
>>> round(float(ev.distribution.sum()), 12)
1.0
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.noise import NoiseModel, NoisyTransitions
from ..model.payoff import Payoff, as_vector
from ..model.problem import Problem, nearest_state
from ..model.sensing import StateSpace
from .evaluation import NoisyJointTransitions, evaluate_tree, linear_strategy
from .policy_tree import Reject
from .result import PlanStep, plan_actions

__all__ = ["NoisyEvaluation", "PlanEvaluator", "evaluate_plan", "step_distributions_noisy"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class NoisyEvaluation:
    """A plan evaluated exactly under a noise model.

    Attributes
    ----------
    distribution : ndarray of shape (K,)
        Probability of each final state (frame of the last action).
    target : ndarray of shape (K,)
        The payoff of each final state (today's goal: 1 on the chosen state or orbit).
    final_state : int
        The state the plan aims at: the one of largest ``distribution * target``.
    expected_payoff : float
    success_probability : float
        Probability of a final state of positive payoff.
    expected_cost : float
        Expected cost per unit payoff (inf if the payoff is 0).
    """

    distribution: FloatArray
    target: FloatArray
    final_state: int
    expected_payoff: float
    success_probability: float
    expected_cost: float


class PlanEvaluator:
    """Exact evaluation of linear plans of one problem under one noise model and payoff.

    What the noise-aware planners share (this one, and the guaranteed planner under noise,
    :func:`~bayesgrasp.planning.robust.plan_guaranteed_noisy`): the forward propagation
    ``q_k = q_1(a) M_{t_2}(alpha_2) ... M_{t_k}(alpha_k)`` of :meth:`forward` and
    :meth:`step` (only the states of positive mass, and many turns at once), and the choice
    of the final state a plan aims at (:meth:`targets`). The same propagation as
    :func:`~bayesgrasp.planning.evaluation.evaluate_tree`, which evaluates any strategy (the
    tests hold the two equal); this one is batched over the turns a search tries.

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel
    payoff : ndarray of shape (K,) or None
        The value of each state (``None``: the problem's goal).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> pb = Problem.build(Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)]))
    >>> ev = PlanEvaluator(pb, NoiseModel(TurnNoise("uniform", 0.05)), None)
    >>> qs = ev.forward(["squeeze", "squeeze"], [0.0, 0.7])
    >>> [round(float(q.sum()), 12) for q in qs]
    [1.0, 1.0]
    """

    def __init__(self, problem: Problem, noise: NoiseModel, payoff: FloatArray | None) -> None:
        self.problem = problem
        self.noise = noise
        self.nt = NoisyTransitions(problem, noise)
        self.payoff = payoff
        stable = problem.states.stable
        # (K, K): row j is the success vector of a plan ending at state j (the goal).
        self.masks = (
            np.eye(len(stable))
            if problem.goal_group == 1
            else np.array([problem.success_states(float(s)) for s in stable], dtype=np.float64)
        )
        self.evaluated = 0
        self.p_tol = problem.part.hull.tol.probability
        # The state pi further round of each state (None if the states are not pi-periodic).
        half = nearest_state(problem.states, stable + math.pi)
        ok = np.allclose(
            np.abs(np.mod(stable[half] - stable - math.pi + math.pi, TWO_PI) - math.pi),
            0.0,
            atol=1e3 * problem.states.angle_tol,
        )
        self.half = half if ok else None

    def boundary_turns(self, kind: str, rows: NDArray[np.intp] | None = None) -> FloatArray:
        """:meth:`NoisyTransitions.boundary_turns` of this problem."""
        return self.nt.boundary_turns(kind, rows)

    def targets(self, q: FloatArray, prefer: int | None = None) -> tuple[FloatArray, int]:
        """The payoff vector a final distribution is scored with, and the aimed state.

        ``prefer``: the state to aim at when it ties with the best (the exact planner's).
        """
        if self.payoff is not None:
            return self.payoff, int(np.argmax(q * self.payoff))
        vals = self.masks @ q
        j = int(np.argmax(vals))
        if prefer is not None and vals[prefer] >= vals[j] - self.p_tol:
            j = prefer
        members = np.flatnonzero(self.masks[j] > 0)
        return self.masks[j], int(members[np.argmax(q[members])])

    def value(self, q: FloatArray) -> FloatArray:
        """Expected payoff of distributions (rows), each with its best target."""
        if self.payoff is not None:
            return np.asarray(q @ self.payoff, dtype=np.float64)
        return np.asarray((q @ self.masks.T).max(axis=-1), dtype=np.float64)

    def forward(self, kinds: Sequence[str], angles: Sequence[float]) -> list[FloatArray]:
        """Distributions after each action: ``[q_1, ..., q_k]``."""
        qs = [self.nt.initial(kinds[0], angles[0])]
        for t, a in zip(kinds[1:], angles[1:], strict=True):
            qs.append(self.step(qs[-1], t, np.array([a]))[0])
        return qs

    def step(self, q: FloatArray, kind: str, alphas: FloatArray) -> FloatArray:
        """``q M(alpha)`` for each turn: shape (N, K); only states with mass are computed."""
        rows = np.flatnonzero(q > 0)
        m = self.nt.matrices(kind, alphas, rows)  # (N, R, K)
        return np.asarray(np.einsum("r,nrk->nk", q[rows], m), dtype=np.float64)

    def evaluate(
        self, kinds: Sequence[str], angles: Sequence[float], prefer: int | None = None
    ) -> NoisyEvaluation:
        """Exact distribution, payoff and cost of a plan (``prefer``: see :meth:`targets`)."""
        return self.finish(kinds, self.forward(kinds, angles)[-1], prefer)

    def finish(
        self, kinds: Sequence[str], q: FloatArray, prefer: int | None = None
    ) -> NoisyEvaluation:
        """The evaluation of a plan that ends in the distribution ``q``."""
        self.evaluated += 1
        u, j = self.targets(q, prefer)
        eu = float(q @ u)
        p = float(q[u > 0].sum())
        cost = self.problem.cost.expected_cost(tuple(kinds), eu)
        return NoisyEvaluation(q, u, j, eu, p, cost)


def evaluate_plan(
    problem: Problem,
    noise: NoiseModel,
    steps: Sequence[PlanStep],
    payoff: Payoff | FloatArray | None = None,
) -> NoisyEvaluation:
    """Evaluate a plan exactly under a noise model (and a payoff).

    The final distribution is :func:`~bayesgrasp.planning.evaluation.evaluate_tree`'s (the
    evaluator of every strategy) of the plan as the strategy that never branches; the
    payoff is scored on it as the noise-aware planner scores its candidates
    (:meth:`PlanEvaluator.finish`).

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel
    steps : sequence of PlanStep
        As a plan reports them (the final distribution is in the frame of the last one).
    payoff : Payoff or array of shape (K,), optional
        Default: the problem's goal (1 on the best final state or its orbit).

    Returns
    -------
    NoisyEvaluation

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> from bayesgrasp.planning.exact import plan_exact
    >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
    >>> pb = Problem.build(rect)
    >>> plan = plan_exact(pb).bayes_plan
    >>> ev = evaluate_plan(pb, NoiseModel(TurnNoise("uniform", math.radians(5))), plan.steps)
    >>> round(ev.success_probability, 6) == round(plan.success_probability, 6)
    True
    """
    if not steps:
        raise PlanningError("a plan needs at least one step")
    kinds = [s.kind for s in steps]
    plan_actions(problem, kinds)
    u = None if payoff is None else as_vector(payoff, problem.states)
    ev = PlanEvaluator(problem, noise, u)
    # The final distribution by the one evaluator of every strategy (the plan: a strategy
    # that never branches; its leaf does not matter, only the distribution reaching it).
    space = StateSpace.build(problem)
    model = NoisyJointTransitions(space, noise, [ev.nt])
    q = evaluate_tree(space, linear_strategy(steps, Reject()), model).final_distribution
    return ev.finish(kinds, q)


def step_distributions_noisy(
    problem: Problem, noise: NoiseModel, steps: Sequence[PlanStep]
) -> list[FloatArray]:
    """The distribution over the states after each step of a plan, under the noise.

    Entry ``k`` is the (K,) distribution after step ``k + 1`` (in that step's gripper
    frame), by the exact transition matrices: what a figure of the plan under the noise
    draws.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> from bayesgrasp.planning.exact import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)]))
    >>> steps = plan_exact(pb).bayes_plan.steps
    >>> qs = step_distributions_noisy(pb, NoiseModel(TurnNoise("normal", 0.2)), steps)
    >>> len(qs) == len(steps), [round(float(q.sum()), 12) for q in qs]
    (True, [1.0, 1.0])
    """
    if not steps:
        raise PlanningError("a plan needs at least one step")
    plan_actions(problem, [s.kind for s in steps])
    ev = PlanEvaluator(problem, noise, None)
    return ev.forward([s.kind for s in steps], [s.alpha for s in steps])
