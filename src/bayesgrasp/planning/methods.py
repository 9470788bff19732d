"""The noise-free planners by name: :func:`plan` runs one and returns its :class:`PlanResult`.

``plan(problem, method="exact" | "bfs" | "guaranteed")``: the exact planner
(:mod:`.exact`), the seed's breadth-first baseline (:mod:`.bfs`) or the guaranteed planner
(:mod:`.guaranteed`); every one returns a :class:`~bayesgrasp.planning.result.PlanResult`
with a ``status`` (``"ok"`` or ``"no-plan"``, with the ``reason``). Importable from
:mod:`bayesgrasp.planning` too.
"""

from __future__ import annotations

from typing import Literal, get_args

from ..errors import PlanningError
from ..model.problem import Problem
from . import bfs, exact, guaranteed  # looked up at each call (a test may stand in for one)
from .result import PlanResult

__all__ = ["METHODS", "Method", "plan"]

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
        (:func:`~.exact.plan_exact`); ``"bfs"``: the same by the seed's breadth-first search
        (:func:`~.bfs.plan_bfs`, a baseline; exact gripper turns only); ``"guaranteed"``: the
        shortest plan that orients every initial orientation
        (:func:`~.guaranteed.plan_guaranteed`, a :class:`~.guaranteed.GuaranteedPlan`: one
        option, plus its period and widths).
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
        return exact.plan_exact(problem, max_actions)
    if method == "bfs":
        return bfs.plan_bfs(problem, max_actions)
    if method == "guaranteed":
        return guaranteed.plan_guaranteed(problem, max_actions)
    known = ", ".join(repr(m) for m in METHODS)
    raise PlanningError(f"`method` must be one of {known}; got {method!r}")
