"""What the shared options become: the part to read, the problem to build, the planner.

The values live in :mod:`bayesgrasp.runs.specs` (the web service and sweeps make the same
ones); they are importable from here as the commands use them.
"""

from __future__ import annotations

from ..runs.specs import (
    Engine,
    GoalKind,
    Method,
    PartFormat,
    PartSpec,
    ProblemSpec,
    SenseSpec,
    guaranteed_plan,
    problem_spec,
    run_inputs,
)

__all__ = [
    "Engine",
    "GoalKind",
    "Method",
    "PartFormat",
    "PartSpec",
    "ProblemSpec",
    "SenseSpec",
    "guaranteed_plan",
    "problem_spec",
    "run_inputs",
]
