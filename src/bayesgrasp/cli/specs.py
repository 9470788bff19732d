"""What the shared options become: the part to read, the problem to build, the planner."""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
    from ..planning.result import PlanReport


class PartFormat(enum.StrEnum):
    """Part file formats (default: from the file's extension)."""

    json = "json"
    csv = "csv"
    wkt = "wkt"
    geojson = "geojson"
    svg = "svg"
    dxf = "dxf"


class Method(enum.StrEnum):
    """Planner to use."""

    exact = "exact"
    bfs = "bfs"


class Engine(enum.StrEnum):
    """How a plan is executed (simulate, sweep)."""

    kinematic = "kinematic"
    mujoco = "mujoco"


class GoalKind(enum.StrEnum):
    """What counts as success."""

    single = "single"
    symmetry = "symmetry"


@dataclass(frozen=True, slots=True)
class PartSpec:
    """PART and the part-file options (see :func:`bayesgrasp.io.resolve_part`)."""

    part: str
    fmt: PartFormat | None = None
    element: str | None = None
    layer: str | None = None
    flatten_tol: float | None = None
    shape_tol: float = 0.0

    def load(self) -> Part:
        """Read the part (``--shape-tol``: :func:`~bayesgrasp.geometry.curved.with_shape_tol`)."""
        from ..geometry.curved import with_shape_tol
        from ..io import resolve_part

        fmt = self.fmt.value if self.fmt else None
        part = resolve_part(
            self.part, fmt, element=self.element, layer=self.layer, tolerance=self.flatten_tol
        )
        return with_shape_tol(part, self.shape_tol)


@dataclass(frozen=True, slots=True)
class ProblemSpec:
    """The problem and planner options of a command, parsed."""

    prior: str = "uniform"
    costs: Mapping[str, float] | None = None
    first: Mapping[str, float] | None = None
    verify: float = 1.0
    retry: float = 0.0
    goal: GoalKind = GoalKind.single
    actions: tuple[str, ...] = ("squeeze",)
    accuracy_deg: float = 0.0
    method: Method = Method.exact
    max_actions: int | None = None

    def build(self, part: Part, more_actions: tuple[str, ...] = ()) -> Problem:
        """The problem for ``part`` (with ``more_actions`` added to the action kinds)."""
        from ..model.cost import CostModel
        from ..model.goal import Goal
        from ..model.prior import parse_prior
        from ..model.problem import Problem

        cost = CostModel(self.costs or {}, self.verify, self.first or {}, self.retry)
        return Problem.build(
            part,
            prior=parse_prior(self.prior),
            cost=cost,
            goal=Goal(self.goal.value),
            actions=tuple(dict.fromkeys((*self.actions, *more_actions))),
            accuracy=math.radians(self.accuracy_deg),
        )

    def plan(self, problem: Problem) -> PlanReport:
        """The best plan of every length, by the chosen planner."""
        from ..planning import plan_bfs, plan_exact

        planner = plan_bfs if self.method is Method.bfs else plan_exact
        return planner(problem, max_actions=self.max_actions)
