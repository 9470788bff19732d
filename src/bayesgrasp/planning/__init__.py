"""Planners: each takes a :class:`~bayesgrasp.model.problem.Problem` and returns a result.

:func:`plan` is the front door: ``plan(problem, method="exact" | "bfs" | "guaranteed")``
returns a :class:`~bayesgrasp.planning.result.PlanResult` with a ``status`` (``"ok"`` or
``"no-plan"``, with the ``reason``) whichever planner runs. The planners are also
importable one by one: :func:`plan_exact` (:mod:`.exact`), :func:`plan_bfs` (the seed's
breadth-first baseline, :mod:`.bfs`) and :func:`plan_guaranteed` (:mod:`.guaranteed`).
The arc machinery the exact and guaranteed planners share is :mod:`.arcs`.

Noise and sensing: :func:`~.noisy.plan_noisy` (plans under noisy actions and a payoff),
:func:`~.robust.plan_guaranteed_noisy` (guaranteed plans under a bounded error),
:func:`~.policy.plan_policy` (policies that branch on jaw-width readings) and
:func:`~.noisy_policy.plan_noisy_policy` (both together). Every plan and policy is a tree of
:mod:`.strategy`, whose :func:`~.strategy.evaluate` gives its exact figures under any noise,
sensor and payoff.

One front door for all of them: :func:`solve` (:func:`.strategy.solve`) plans with whichever
planner the model calls for (a sensor, noise, a payoff, a method) and returns one
:class:`StrategyResult` (:class:`.strategy.StrategyResult`): the chosen strategy as a tree,
its exact evaluation, the alternatives, tolerances and provenance. (Both are imported on first
use: the policy planners load only when asked for.)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, get_args

from ..errors import PlanningError
from ..model.problem import Problem
from .bfs import plan_bfs
from .exact import plan_exact
from .guaranteed import GuaranteedPlan, plan_guaranteed
from .result import (
    Plan,
    PlanOption,
    PlanReport,
    PlanResult,
    PlanStep,
    Status,
    execute_plan,
    max_plan_length,
)

if TYPE_CHECKING:
    from .strategy import StrategyResult, solve

__all__ = [
    "METHODS",
    "GuaranteedPlan",
    "Method",
    "Plan",
    "PlanOption",
    "PlanReport",
    "PlanResult",
    "PlanStep",
    "Status",
    "StrategyResult",
    "execute_plan",
    "max_plan_length",
    "plan",
    "plan_bfs",
    "plan_exact",
    "plan_guaranteed",
    "solve",
]


def __getattr__(name: str) -> Any:
    """:class:`StrategyResult` and :func:`solve`, imported on first use."""
    if name in ("StrategyResult", "solve"):
        from . import strategy

        return getattr(strategy, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


Method = Literal["exact", "bfs", "guaranteed"]
METHODS: tuple[Method, ...] = get_args(Method)
"""The planners :func:`plan` runs, by name."""


def plan(problem: Problem, method: Method = "exact", max_actions: int | None = None) -> PlanResult:
    """Plan with one of the planners; every planner returns a :class:`PlanResult`.

    Parameters
    ----------
    problem : Problem
    method : {"exact", "bfs", "guaranteed"}
        ``"exact"``: the best plan of every length and the Bayes plan
        (:func:`plan_exact`); ``"bfs"``: the same by the seed's breadth-first search
        (:func:`plan_bfs`, a baseline; exact gripper turns only); ``"guaranteed"``: the
        shortest plan that orients every initial orientation (:func:`plan_guaranteed`, a
        :class:`GuaranteedPlan`: one option, plus its period and widths).
    max_actions : int, optional
        No plan longer than this (the guaranteed planner: status ``"no-plan"`` if none
        that short exists).

    Returns
    -------
    PlanResult
        ``status`` is ``"ok"``, or ``"no-plan"`` with the ``reason`` (only the guaranteed
        planner finds no plan: with a gripper accuracy the widths may stop short of the
        period).

    Raises
    ------
    PlanningError
        If ``method`` is unknown or ``max_actions`` is less than 1 (and as each planner
        raises: the breadth-first baseline refuses a gripper accuracy).

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry.polygon import Part
    >>> rect = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    >>> [plan(Problem.build(rect), m).bayes_plan.n_actions for m in METHODS]
    [1, 1, 2]
    >>> res = plan(Problem.build(rect, accuracy=math.radians(30)), "guaranteed")
    >>> res.status, res.options
    ('no-plan', ())
    """
    if method == "exact":
        return plan_exact(problem, max_actions)
    if method == "bfs":
        return plan_bfs(problem, max_actions)
    if method == "guaranteed":
        return plan_guaranteed(problem, max_actions)
    known = ", ".join(repr(m) for m in METHODS)
    raise PlanningError(f"`method` must be one of {known}; got {method!r}")
