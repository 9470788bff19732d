"""What every front end does with a strategy: its document, its stroke check, its robot data.

The robot data is what a robot file says about the model the strategy was planned for.

The command line (``plan --json``, ``--export``), the web service (``/plan``, ``/export``)
and sweeps call these on the one result type of every planner,
:class:`~bayesgrasp.planning.strategy.StrategyResult`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..io.export import Stroke
    from ..planning.strategy import StrategyResult

__all__ = ["check_stroke", "document", "robot_metadata"]


def document(result: StrategyResult, inputs: dict[str, Any] | None = None) -> dict[str, Any]:
    """The result's document (``plan --json``; :func:`~bayesgrasp.io.plans.strategy_document`)."""
    from ..io.plans import strategy_document

    return strategy_document(result, inputs=inputs)


def check_stroke(result: StrategyResult, stroke: Stroke | None) -> None:
    """Refuse a strategy with a step outside the gripper's stroke (``None``: no stroke given)."""
    if stroke is None:
        return
    from ..io.export import check_stroke as check

    problems = result.problem if result.kind == "plan" else list(result.problems)
    check(problems, result.robot_strategy, stroke)


def robot_metadata(result: StrategyResult) -> dict[str, Any] | None:
    """What a robot file says about the model the strategy was planned for (noise, payoff)."""
    meta: dict[str, Any] = {}
    if result.noise is not None:
        meta["noise"] = result.noise.to_json()
    if result.payoff is not None:
        meta["payoff"] = result.payoff.tolist()
    return meta or None
