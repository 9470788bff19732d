"""Planners: each takes a :class:`~bayesgrasp.model.problem.Problem` and returns a result.

:func:`plan` (:mod:`.methods`) is the front door:
``plan(problem, method="exact" | "bfs" | "guaranteed")`` returns a
:class:`~bayesgrasp.planning.result.PlanResult` with a ``status`` (``"ok"`` or ``"no-plan"``,
with the ``reason``) whichever planner runs. The planners are also
importable one by one: :func:`plan_exact` (:mod:`.exact`), :func:`plan_bfs` (the seed's
breadth-first baseline, :mod:`.bfs`) and :func:`plan_guaranteed` (:mod:`.guaranteed`).
The arc machinery the exact and guaranteed planners share is :mod:`.arcs`.

Noise and sensing: :func:`~.noisy.plan_noisy` (plans under noisy actions and a payoff),
:func:`~.robust.plan_guaranteed_noisy` (guaranteed plans under a bounded error),
:func:`~.policy.plan_policy` (policies that branch on jaw-width readings) and
:func:`~.noisy_policy.plan_noisy_policy` (both together). Every plan and policy is a tree
(:mod:`.policy_tree`), whose :func:`~.evaluation.evaluate` gives its exact figures under any
noise, sensor and payoff.

One front door for all of them: :func:`solve` (:func:`.strategy.solve`) plans with whichever
planner the model calls for (a sensor, noise, a payoff, a method) and returns one
:class:`StrategyResult` (:class:`.strategy.StrategyResult`): the chosen strategy as a tree,
its exact evaluation, the alternatives, tolerances and provenance. (Both are imported on first
use: the policy planners load only when asked for.)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .bfs import plan_bfs
from .exact import plan_exact
from .guaranteed import GuaranteedPlan, plan_guaranteed
from .methods import METHODS, Method, plan
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
