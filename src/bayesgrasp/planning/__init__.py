"""Planners: each takes a :class:`~bayesgrasp.model.problem.Problem` and returns a plan report."""

from .bfs import plan_bfs
from .exact import plan_exact
from .guaranteed import GuaranteedPlan, plan_guaranteed
from .result import PlanOption, PlanReport, PlanStep, execute_plan

__all__ = [
    "GuaranteedPlan",
    "PlanOption",
    "PlanReport",
    "PlanStep",
    "execute_plan",
    "plan_bfs",
    "plan_exact",
    "plan_guaranteed",
]
