"""One strategy type over every planner: :func:`solve` and its :class:`StrategyResult`.

:func:`solve` plans with whichever planner the model calls for (a sensor, action noise, a
payoff, a method) and returns one :class:`StrategyResult`: the chosen strategy as a tree
(:class:`~bayesgrasp.planning.policy_tree.PolicyNode`; a linear plan is the tree that never
branches), its exact evaluation, the alternatives a user compares, tolerances and
provenance. The evaluation of any strategy under any noise, sensor and payoff (the paper,
section 6) is :mod:`bayesgrasp.planning.evaluation`; its names are importable from here too.

Examples
--------
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
>>> res = solve(pb)
>>> ev = evaluate(pb, plan_strategy(pb, res.bayes_plan))
>>> round(ev.expected_cost, 9) == round(res.expected_cost, 9)
True
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PlanningError
from ..model.noise import NoiseModel
from ..model.payoff import Payoff
from ..model.problem import Problem
from ..model.sensing import WidthSensor
from . import exact, policy
from . import guaranteed as guaranteed_planner  # looked up at each call
from .evaluation import (
    Evaluation,
    ExactTransitions,
    NoisyJointTransitions,
    Transitions,
    evaluate,
    evaluate_tree,
    linear_strategy,
    plan_strategy,
    transitions,
)
from .guaranteed import GuaranteedPlan
from .noisy import NoisyPlanResult
from .policy_tree import Policy, PolicyNode, tree_depth
from .result import PlanOption, PlanResult, Status
from .search_bounds import DEFAULT_MAX_MEMORY_MB, DEFAULT_TIME_LIMIT_S

__all__ = [
    "Alternative",
    "Evaluation",
    "ExactTransitions",
    "NoisyJointTransitions",
    "StrategyResult",
    "Transitions",
    "evaluate",
    "evaluate_tree",
    "linear_strategy",
    "plan_strategy",
    "solve",
    "transitions",
]

FloatArray = NDArray[np.float64]


# One result for every planner


Kind = Literal["plan", "policy"]
"""What a result's strategy is: ``"plan"`` (linear: never branches) or ``"policy"``."""


@dataclass(frozen=True, slots=True)
class Alternative:
    """One strategy a user compares with the chosen one (the best of a length, the most certain).

    Attributes
    ----------
    strategy : PolicyNode
        The strategy as a tree (a linear plan: the tree that never branches).
    n_actions : int
        Its number of actions (a policy: its depth, the most actions on any path).
    success_probability : float
        As the planner reports it (with a payoff: the expected payoff of a cycle).
    expected_cost : float
        As the planner reports it (with a payoff: per unit payoff).
    tolerance : float or None
        A linear plan's margin (see :attr:`~bayesgrasp.planning.result.PlanOption.tolerance`);
        ``None`` where it is not defined (one action, a turn error, a policy).
    option : PlanOption or None
        The linear plan itself (``None`` for a policy).
    """

    strategy: PolicyNode
    n_actions: int
    success_probability: float
    expected_cost: float
    tolerance: float | None
    option: PlanOption | None


@dataclass(frozen=True, eq=False)
class StrategyResult:
    """What every planner's front door (:func:`solve`) returns: one strategy and its figures.

    The planner's own result is kept as :attr:`source` (a
    :class:`~bayesgrasp.planning.result.PlanResult` of the exact, breadth-first or guaranteed
    planner, a :class:`~bayesgrasp.planning.noisy.NoisyPlanResult` of the noise-aware
    planner, or a :class:`~bayesgrasp.planning.policy_tree.Policy`); everything a surface needs is
    read through this one type: the chosen strategy (:attr:`strategy`, a tree), its exact
    evaluation (:attr:`evaluation`, by :func:`evaluate` under the model the strategy was
    planned for), the alternatives (:attr:`alternatives`, :attr:`bayes`,
    :attr:`most_certain`), tolerances (in each alternative) and provenance
    (:attr:`provenance`).

    Attributes
    ----------
    problems : tuple of Problem
        One problem, or one per candidate part (a policy that recognises parts).
    source : PlanResult, NoisyPlanResult or Policy
        The planner's own result (its figures, as it reports them).
    guaranteed : GuaranteedPlan or None
        The guaranteed plan, when one was asked for and exists.
    guaranteed_missing : str or None
        Why there is none, when one was asked for and none exists.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> res = solve(pb)
    >>> res.kind, res.method, [a.n_actions for a in res.alternatives], res.bayes
    ('plan', 'exact', [1, 2], 1)
    >>> round(res.evaluation.expected_cost, 9) == round(res.expected_cost, 9)
    True
    >>> pol = solve(pb, sensor="width", max_actions=2)
    >>> pol.kind, pol.method, pol.alternatives[0].n_actions
    ('policy', 'policy', 1)
    """

    problems: tuple[Problem, ...]
    source: PlanResult | NoisyPlanResult | Policy
    guaranteed: GuaranteedPlan | None = None
    guaranteed_missing: str | None = None

    @property
    def problem(self) -> Problem:
        """The (first candidate's) problem."""
        return self.problems[0]

    @property
    def kind(self) -> Kind:
        """``"policy"`` for a strategy that branches on readings, else ``"plan"``."""
        return "policy" if isinstance(self.source, Policy) else "plan"

    @property
    def method(self) -> str:
        """The planner's name (``noisy-policy``: a policy under noisy actions or a payoff).

        ``exact``, ``bfs``, ``guaranteed``, ``noisy``, ``policy`` or ``noisy-policy``.
        """
        src = self.source
        if isinstance(src, Policy):
            return "policy" if src.noise is None and src.payoff is None else "noisy-policy"
        if isinstance(src, NoisyPlanResult):
            return "noisy"
        return src.method

    @property
    def status(self) -> Status:
        """``"ok"``, or ``"no-plan"`` (only a guaranteed planner's result holds no plan)."""
        src = self.source
        return src.status if isinstance(src, PlanResult) else "ok"

    @property
    def ok(self) -> bool:
        """Whether the result holds a strategy."""
        return self.status == "ok"

    @property
    def reason(self) -> str | None:
        """Why there is no strategy (``None`` when :attr:`ok`)."""
        src = self.source
        return src.reason if isinstance(src, PlanResult) else None

    @property
    def noise(self) -> NoiseModel | None:
        """The action noise the strategy was planned under (``None``: exact actions)."""
        src = self.source
        return None if isinstance(src, PlanResult) else src.noise

    @property
    def payoff(self) -> FloatArray | None:
        """The value of each state the strategy was planned for (``None``: the goal)."""
        src = self.source
        if isinstance(src, Policy):
            return None if src.payoff is None else np.asarray(src.payoff, dtype=np.float64)
        return src.payoff if isinstance(src, NoisyPlanResult) else None

    @property
    def sensor(self) -> WidthSensor | None:
        """The sensor a policy branches on (``None`` for a plan)."""
        return self.source.sensor if isinstance(self.source, Policy) else None

    @property
    def plans(self) -> PlanResult | None:
        """The linear plans as a :class:`PlanResult` (``None`` for a policy).

        For tables, figures and simulation; the noise-aware planner's as method ``"noisy"``.
        """
        src = self.source
        if isinstance(src, Policy):
            return None
        return src.plan_result() if isinstance(src, NoisyPlanResult) else src

    @property
    def bayes_plan(self) -> PlanOption:
        """The Bayes plan of a linear result (raises for a policy or a result without plans)."""
        plans = self.plans
        if plans is None:
            raise PlanningError("a policy is not a linear plan: use `strategy`")
        return plans.bayes_plan

    @property
    def robot_strategy(self) -> PlanOption | Policy:
        """What a robot file writes: the Bayes plan, or the policy (its state machine)."""
        src = self.source
        return src if isinstance(src, Policy) else self.bayes_plan

    @property
    def alternatives(self) -> tuple[Alternative, ...]:
        """The strategies a user compares: the best plan of each length (a policy: itself)."""
        src = self.source
        if isinstance(src, Policy):
            alt = Alternative(
                src.root,
                tree_depth(src.root),
                src.success_probability,
                src.expected_cost,
                None,
                None,
            )
            return (alt,)
        pb = self.problem
        if isinstance(src, NoisyPlanResult):  # the payoff earned (a 0/1 payoff: P(success))
            return tuple(
                Alternative(
                    plan_strategy(pb, o.option),
                    o.option.n_actions,
                    o.expected_payoff,
                    o.option.expected_cost,
                    o.option.tolerance,
                    o.option,
                )
                for o in src.options
            )
        return tuple(
            Alternative(
                plan_strategy(pb, o),
                o.n_actions,
                o.success_probability,
                o.expected_cost,
                o.tolerance,
                o,
            )
            for o in src.options
        )

    @property
    def bayes(self) -> int:
        """Index of the strategy of least expected cost among :attr:`alternatives`."""
        src = self.source
        return 0 if isinstance(src, Policy) else src.bayes

    @property
    def most_certain(self) -> int:
        """Index of the shortest strategy of the highest success among :attr:`alternatives`."""
        src = self.source
        return 0 if isinstance(src, Policy) else src.most_certain

    @property
    def strategy(self) -> PolicyNode:
        """The chosen (Bayes) strategy as a tree.

        Raises
        ------
        NoPlanError
            If the result holds no strategy (the message is the :attr:`reason`).
        """
        src = self.source
        if isinstance(src, Policy):
            return src.root
        plans = self.plans
        assert plans is not None
        return plan_strategy(self.problem, plans.bayes_plan)

    @property
    def success_probability(self) -> float:
        """The chosen strategy's success probability as its planner reports it."""
        return self.alternatives[self.bayes].success_probability

    @property
    def expected_cost(self) -> float:
        """The chosen strategy's expected cost as its planner reports it."""
        return self.alternatives[self.bayes].expected_cost

    def evaluate(self, strategy: PolicyNode | None = None) -> Evaluation:
        """A strategy's exact figures under this result's model (default: the chosen one).

        The model is the one the strategy was planned for: the candidate parts and their
        prior, the sensor, the action noise and the payoff.
        """
        src = self.source
        root = self.strategy if strategy is None else strategy
        prior = src.part_prior if isinstance(src, Policy) else None
        return evaluate(
            self.problems,
            root,
            sensor=self.sensor,
            noise=self.noise,
            payoff=self.payoff,
            part_prior=prior,
        )

    @functools.cached_property
    def evaluation(self) -> Evaluation:
        """The chosen strategy's exact evaluation (:meth:`evaluate`, computed once)."""
        return self.evaluate()

    @property
    def provenance(self) -> dict[str, Any]:
        """How the strategy was made: planner, noise, payoff, sensor, longest path.

        The documents (:mod:`bayesgrasp.io.plans`) add the prior, cost model, goal, actions
        and the command line's inputs.
        """
        out: dict[str, Any] = {"method": self.method}
        src = self.source
        if self.noise is not None:
            out["noise"] = self.noise.to_json()
        if self.payoff is not None:
            out["payoff"] = self.payoff.tolist()
        if isinstance(src, Policy):
            out["sensor"] = src.sensor.to_json()
            out["max_actions"] = src.max_actions
            out["parts"] = list(src.parts)
            out["part_prior"] = list(src.part_prior)
        return out

    def best_only(self) -> StrategyResult:
        """The same result with only the Bayes and the most certain plans (a policy: itself)."""
        src = self.source
        if isinstance(src, Policy):
            return self
        return dataclasses.replace(self, source=src.best_only())


def solve(
    problems: Problem | Iterable[Problem],
    *,
    method: str = "exact",
    sensor: str | WidthSensor | None = None,
    noise: NoiseModel | None = None,
    payoff: Payoff | ArrayLike | None = None,
    max_actions: int | None = None,
    best_only: bool = False,
    guaranteed: bool = False,
    part_prior: str | Sequence[float] | None = None,
    max_memory_mb: float | None = None,
    time_limit_s: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    stroke: tuple[float, float] | None = None,
) -> StrategyResult:
    """Plan with whichever planner the model calls for; one :class:`StrategyResult`.

    - a ``sensor``: the Bayes policy that branches on its readings
      (:func:`~bayesgrasp.planning.policy.plan_policy`), under ``noise`` and ``payoff`` when
      given (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`); several problems
      are candidate parts (weighted by ``part_prior``); ``max_actions`` is the depth
      (default 3);
    - else ``noise`` or ``payoff``: the noise-aware Bayes plan
      (:func:`~bayesgrasp.planning.noisy.plan_noisy`), with ``guaranteed`` the plan guaranteed
      under the (bounded) noise (:func:`~bayesgrasp.planning.robust.plan_guaranteed_noisy`);
    - else the planner ``method`` (:func:`bayesgrasp.planning.plan`: ``"exact"``, ``"bfs"``
      or ``"guaranteed"``), with ``guaranteed`` also the guaranteed plan.

    Parameters
    ----------
    problems : Problem or iterable of Problem
    method : {"exact", "bfs", "guaranteed"}
        The noise-free planner (the others seed from the exact planner: only ``"exact"``).
    sensor : str or WidthSensor, optional
    noise : NoiseModel, optional
    payoff : Payoff or array_like, optional
        The value of each stable state (one part).
    max_actions : int, optional
        The longest plan (a policy: its depth).
    best_only : bool
        Only the Bayes and the most certain plans (plans only).
    guaranteed : bool
        Also the guaranteed plan (plans only).
    part_prior : str or sequence of float, optional
        Weights of the candidate parts (policies only).
    max_memory_mb : float, optional
        The policy search's memory bound.
    time_limit_s : float, optional
        The exact policy search's time bound (default 60 s; past it or the memory bound the
        deepest policy that finishes is returned, saying so: :attr:`Policy.stopped`).
    progress : callable, optional
        ``(seconds used, seconds allowed)`` now and then during the exact policy search.
    stroke : (float, float), optional
        ``(min_opening, max_opening)`` in part units: plan only actions the gripper's stroke
        allows (:func:`~bayesgrasp.planning.stroke.plan_within_stroke`; noise-free plans).

    Raises
    ------
    PlanningError
        For a combination that means nothing: several problems without a sensor, a part
        prior or memory bound without a sensor, ``best_only`` or ``guaranteed`` with a sensor,
        another ``method`` than ``"exact"`` with a sensor, noise or payoff, a guarantee under
        an unbounded (normal) turn error, a payoff for several parts.

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> res = solve(pb, noise=NoiseModel(TurnNoise("normal", math.radians(2))))
    >>> res.method, res.kind, res.noise.describe()
    ('noisy', 'plan', 'turn error normal:2 deg')
    """
    from .methods import plan as plan_with
    from .noisy import plan_noisy

    pbs = (problems,) if isinstance(problems, Problem) else tuple(problems)
    if not pbs:
        raise PlanningError("no problem to plan for")
    if stroke is not None:
        others = sensor, noise, payoff, part_prior, max_memory_mb, time_limit_s
        if any(x is not None for x in others) or method != "exact" or len(pbs) > 1:
            raise PlanningError(
                "planning within the stroke searches noise-free linear plans of one part: it "
                "takes no sensor, noise, payoff, part prior or other method (check any "
                "strategy against the stroke with bayesgrasp.io.export.check_stroke)"
            )
        from .stroke import plan_within_stroke

        found_s = plan_within_stroke(pbs[0], stroke[0], stroke[1], max_actions)
        if best_only:
            found_s = found_s.best_only()
        sure_s = guaranteed_planner.plan_guaranteed(pbs[0]) if guaranteed else None
        return _with_guarantee(StrategyResult(pbs, found_s), sure_s)
    if sensor is not None:
        refused = [
            name
            for name, on in (
                ("best_only", best_only),
                ("guaranteed", guaranteed),
                (f"method {method!r}", method != "exact"),
            )
            if on
        ]
        if refused:
            raise PlanningError(f"a policy (a sensor) takes no {', '.join(refused)}")
        depth = 3 if max_actions is None else max_actions
        memory = DEFAULT_MAX_MEMORY_MB if max_memory_mb is None else max_memory_mb
        if noise is None and payoff is None:
            seconds = DEFAULT_TIME_LIMIT_S if time_limit_s is None else time_limit_s
            pol = policy.plan_policy(  # looked up at each call, as the exact planner
                pbs,
                sensor=sensor,
                max_actions=depth,
                part_prior=part_prior,
                max_memory_mb=memory,
                time_limit_s=seconds,
                progress=progress,
            )
        else:
            from .noisy_policy import plan_noisy_policy

            if payoff is not None and len(pbs) > 1:
                raise PlanningError("a payoff is for one part")
            pol = plan_noisy_policy(
                pbs,
                sensor,
                depth,
                noise,
                payoff=payoff,
                part_prior=part_prior,
                max_memory_mb=memory,
                time_limit_s=DEFAULT_TIME_LIMIT_S if time_limit_s is None else time_limit_s,
            )
        return StrategyResult(pbs, pol)
    if len(pbs) > 1:
        raise PlanningError("several parts are told apart by a sensor: give `sensor`")
    if part_prior is not None or max_memory_mb is not None or time_limit_s is not None:
        raise PlanningError(
            "`part_prior`, `max_memory_mb` and `time_limit_s` are for policies: give `sensor`"
        )
    pb = pbs[0]
    if noise is not None or payoff is not None:
        from .robust import UNBOUNDED_GUARANTEE, plan_guaranteed_noisy

        if method != "exact":
            raise PlanningError("the noise-aware planner seeds from the exact planner")
        model = NoiseModel() if noise is None else noise
        if guaranteed and not model.turn.exact and model.turn.kind == "normal":
            raise PlanningError(UNBOUNDED_GUARANTEE)
        res = plan_noisy(pb, model, payoff, max_actions)  # type: ignore[arg-type]
        if best_only:
            res = res.best_only()
        sure = plan_guaranteed_noisy(pb, model) if guaranteed else None
        return _with_guarantee(StrategyResult(pbs, res), sure)
    if method == "exact":  # looked up at each call (a test may stand in for the planner)
        report: Literal["all", "best"] = "best" if best_only else "all"
        found = exact.plan_exact(pb, max_actions=max_actions, report=report)
    else:
        found = plan_with(pb, method, max_actions)  # type: ignore[arg-type]
        if best_only:
            found = found.best_only()
    sure = guaranteed_planner.plan_guaranteed(pb) if guaranteed else None
    return _with_guarantee(StrategyResult(pbs, found), sure)


def _with_guarantee(res: StrategyResult, found: GuaranteedPlan | None) -> StrategyResult:
    """The result with its guaranteed plan, or the reason none exists (``found``'s status)."""
    if found is None:
        return res
    if found.status == "ok":
        return dataclasses.replace(res, guaranteed=found)
    return dataclasses.replace(res, guaranteed_missing=str(found.reason or "no guaranteed plan"))
