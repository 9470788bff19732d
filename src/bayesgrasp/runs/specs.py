"""What a run asks of the library: the part to read, the problem to build, the planner.

The command line, the web service and sweeps describe a run alike: a :class:`PartSpec` (the
part and its file options), a :class:`ProblemSpec` (prior, costs, goal, actions, accuracy,
planner), a :class:`SenseSpec` for a sensing policy; :func:`guaranteed_plan`, and what each
surface writes into a document's provenance (:func:`run_inputs`, :func:`simulate_inputs`).
Nothing here parses command-line text or prints: bad values raise a
:class:`~bayesgrasp.errors.BayesGraspError`.
"""

from __future__ import annotations

import enum
import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..io.plan_reader import PlanSource
    from ..model.prior import Prior
    from ..model.problem import Problem
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.result import PlanReport
    from ..solid.mesh import Solid


__all__ = [
    "PLAN_NAMES",
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
    "simulate_inputs",
    "spec_for_plan",
]

PLAN_NAMES = {"bayes": "Bayes", "most-certain": "most certain", "guaranteed": "guaranteed"}
"""The plans a run names (``--plan``, the web service's ``plan``), and how titles call them."""


class PartFormat(enum.StrEnum):
    """Part file formats (default: from the file's extension)."""

    json = "json"
    csv = "csv"
    wkt = "wkt"
    geojson = "geojson"
    svg = "svg"
    dxf = "dxf"
    stl = "stl"
    obj = "obj"
    ply = "ply"
    threemf = "3mf"
    glb = "glb"


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
    """PART and the part-file options (see :func:`bayesgrasp.io.resolve_part`).

    ``note`` receives what a person should know about how the part was read (a point list
    taken as its convex hull); the command line prints it on stderr, ``None`` drops it.
    """

    part: str
    fmt: PartFormat | None = None
    element: str | None = None
    layer: str | None = None
    flatten_tol: float | None = None
    com: str | None = None
    shape_tol: float = 0.0
    note: Callable[[str], None] | None = field(default=None, compare=False, repr=False)

    def load(self) -> Part:
        """Read the part: ``--shape-tol`` applied, then ``--com X,Y`` when given.

        A mesh file is one resting pose's footprint (:meth:`load_mesh_part`). See
        :func:`~bayesgrasp.geometry.curved.with_shape_tol`.
        """
        import dataclasses

        from ..errors import PartError
        from ..geometry.curved import with_shape_tol
        from ..geometry.polygon import Part
        from ..io import resolve_part
        from ..solid.mesh import is_mesh

        fmt = self.fmt.value if self.fmt else None
        if is_mesh(self.part, fmt):  # a solid: one resting pose's footprint
            return self.load_mesh_part()
        part = resolve_part(
            self.part, fmt, element=self.element, layer=self.layer, tolerance=self.flatten_tol
        )
        kind = fmt or self.part.rpartition(".")[2].lower()
        if kind in ("csv", "json") and part.outline is part.hull.vertices and self.note:
            self.note(  # a point cloud
                f"the points of {self.part} cross themselves in file order, "
                "so they are a point cloud: the part is their convex hull"
                + ("" if self.com else " (centre of mass its centroid; --com X,Y to set it)")
            )
        part = with_shape_tol(part, self.shape_tol)
        if self.com is None:
            return part
        try:
            xy = [float(v) for v in self.com.split(",")]
        except ValueError:
            xy = []
        if len(xy) != 2 or not all(math.isfinite(v) for v in xy):
            raise PartError(f"`--com` must be X,Y (two finite numbers); got {self.com!r}")
        try:  # validated as Part.from_points does: strictly inside the hull
            com = Part.from_points(part.hull.vertices, center_of_mass=xy).center_of_mass
        except PartError as exc:
            raise PartError(f"`--com` {self.com}: {exc}") from None
        return dataclasses.replace(part, center_of_mass=com)

    def load_solid(self) -> Solid:
        """The solid of a mesh PART (a file, or ``-`` with a format), ``--com X,Y,Z`` applied."""
        from ..errors import PartError
        from ..solid.mesh import read_mesh, read_mesh_bytes
        from ..solid.parts import parse_com

        com = parse_com(self.com)
        if self.layer is not None or self.flatten_tol is not None:
            raise PartError("a mesh has no layers or curves: drop --layer, --flatten-tol")
        if self.part == "-":
            import sys

            from ..io import MAX_BYTES

            data = sys.stdin.buffer.read(MAX_BYTES + 1)
            fmt = self.fmt.value if self.fmt else ""
            return read_mesh_bytes(data, fmt, "<stdin>", com=com)
        return read_mesh(self.part, self.fmt.value if self.fmt else None, com=com)

    def load_mesh_part(self) -> Part:
        """A mesh PART's pose footprint (``element``: the pose; default 0, the most probable).

        Quasi-static poses (:func:`~bayesgrasp.solid.parts.study_of`), ``--com X,Y,Z`` and
        ``--shape-tol`` applied.
        """
        from ..geometry.curved import with_shape_tol
        from ..solid.parts import pose_index, pose_part, study_of

        solid = self.load_solid()
        study = study_of(solid)
        k = pose_index(self.element, len(study.poses), f"{self.part}: pose")
        return with_shape_tol(
            pose_part(study, k, f"{solid.name}-pose-{k}", solid.units), self.shape_tol
        )


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
    given: frozenset[str] = frozenset()
    """The options of ``prior`` and ``goal`` the user gave (a plan file's own apply otherwise)."""

    def build(
        self, part: Part, more_actions: tuple[str, ...] = (), prior: Prior | None = None
    ) -> Problem:
        """The problem for ``part`` (with ``more_actions`` added to the action kinds).

        ``prior`` replaces the ``--prior`` text (a plan file's prior).
        """
        from ..model.problem import Problem

        return Problem.build(part, **self.problem_inputs(more_actions, prior))

    def problem_inputs(
        self, more_actions: tuple[str, ...] = (), prior: Prior | None = None
    ) -> dict[str, Any]:
        """The keywords of ``Problem.build`` but the part (immutable: a batch makes them once).

        A prior, cost or goal equal to build's default is build's shared one
        (:func:`~bayesgrasp.model.problem.shared_defaults`).
        """
        from ..model.cost import CostModel
        from ..model.goal import Goal
        from ..model.prior import parse_prior
        from ..model.problem import shared_defaults

        cost = CostModel(self.costs or {}, self.verify, self.first or {}, self.retry)
        return shared_defaults(
            {
                "prior": parse_prior(self.prior) if prior is None else prior,
                "cost": cost,
                "goal": Goal(self.goal.value),
                "actions": tuple(dict.fromkeys((*self.actions, *more_actions))),
                "accuracy": math.radians(self.accuracy_deg),
            }
        )

    def plan(self, problem: Problem, best_only: bool = False) -> PlanReport:
        """The best plan of every length, by the chosen planner.

        ``best_only``: only the Bayes and the most certain plans.
        """
        return self.planner(best_only)(problem)

    def planner(self, best_only: bool = False) -> Callable[[Problem], PlanReport]:
        """:meth:`plan` as a function of the problem (a batch looks the planner up once)."""
        from ..planning import plan_bfs, plan_exact

        if self.method is Method.bfs:
            max_actions = self.max_actions

            def bfs(problem: Problem) -> PlanReport:
                found = plan_bfs(problem, max_actions=max_actions)
                return found.best_only() if best_only else found

            return bfs
        report: Literal["all", "best"] = "best" if best_only else "all"
        return functools.partial(plan_exact, max_actions=self.max_actions, report=report)


def problem_spec(names: list[str], values: Mapping[str, Any]) -> ProblemSpec:
    """The :class:`ProblemSpec` of the problem options' values, keyed as the parameters.

    ``names``: the action kinds with a cost option each (``cost_0`` is ``--NAME-cost`` of
    ``names[0]``, ``first_0`` its ``--first-NAME-cost``); ``None`` is an option not given.
    The command line's options and a batch file's lines both make their spec here.
    """
    from ..model.actions import PUSH_GRASP, SQUEEZE

    actions = [a.strip() for a in values["actions"].split(",") if a.strip()]
    if values.get("push_grasp"):  # exactly --actions squeeze,push-grasp (order breaks ties)
        actions = [SQUEEZE.name, PUSH_GRASP.name, *actions]
    first = {n: values[f"first_{i}"] for i, n in enumerate(names)}
    given = frozenset(k for k in ("prior", "goal") if values[k] is not None)
    return ProblemSpec(
        prior="uniform" if values["prior"] is None else values["prior"],
        costs={n: values[f"cost_{i}"] for i, n in enumerate(names)},
        first={n: c for n, c in first.items() if c is not None},
        verify=values["verify_cost"],
        retry=values["retry_cost"],
        goal=values["goal"] or GoalKind.single,
        actions=tuple(dict.fromkeys(actions)),
        accuracy_deg=values["accuracy"],
        method=values["method"],
        max_actions=values["max_squeezes"],
        given=given,
    )


@dataclass(frozen=True, slots=True)
class SenseSpec:
    """``--sense`` and the options of a sensing policy (plan, simulate and plot --sense)."""

    sense: str
    """The sensor (``width[:SIGMA,RES]``)."""
    also: tuple[str, ...] = ()
    """The other candidate parts (``--also``; ``plan`` adds its further PARTs)."""
    part_prior: str | None = None
    max_actions: int = 3
    max_memory_mb: float = 2048.0
    """The policy search's memory bound (``--max-memory``)."""
    time_limit_s: float = 60.0
    """The policy search's time bound (``--time-limit``)."""

    def parts(self, part: PartSpec) -> list[Part]:
        """PART, then each candidate part, read with the same part-file options.

        Candidates in other units than PART are converted to PART's
        (:func:`~bayesgrasp.units.convert`): the gripper reads every width in one unit.
        """
        import dataclasses

        from ..units import convert

        first = part.load()
        more = [dataclasses.replace(part, part=p).load() for p in self.also]
        if first.units is None:
            return [first, *more]
        return [first, *(convert(p, first.units) if p.units else p for p in more)]


def spec_for_plan(src: PlanSource, spec: ProblemSpec) -> tuple[ProblemSpec, Prior | None]:
    """The options a read plan runs under (``simulate --plan FILE.json``), and its prior.

    The plan's document records the goal and the prior it was made for: they apply unless
    the options gave their own (``spec.given``); the plan's action kinds are added to the
    options' (a plan with push-grasps runs where they were not asked for). The prior is
    ``None`` where the options' own applies.

    Examples
    --------
    >>> from bayesgrasp.io.plan_reader import read_plan
    >>> step = {"type": "push-grasp", "alpha_rad": 0.5}
    >>> src = read_plan({"steps": [step], "final_orientation_rad": 0.0})
    >>> spec, prior = spec_for_plan(src, ProblemSpec())
    >>> spec.actions, spec.goal.value, prior
    (('squeeze', 'push-grasp'), 'single', None)
    """
    import dataclasses

    goal = spec.goal
    if "goal" not in spec.given and src.goal in tuple(GoalKind):
        goal = GoalKind(src.goal)
    prior = None if "prior" in spec.given else src.prior
    actions = tuple(dict.fromkeys((*spec.actions, *src.option.kinds)))
    return dataclasses.replace(spec, goal=goal, actions=actions), prior


def guaranteed_plan(problem: Problem) -> GuaranteedPlan | str:
    """The guaranteed plan of a problem, or the reason none exists (a string)."""
    from ..planning import guaranteed

    found = guaranteed.plan_guaranteed(problem)
    return found if found.status == "ok" else str(found.reason or "no guaranteed plan")


def run_inputs(part: PartSpec | None, spec: ProblemSpec) -> dict[str, Any]:
    """What a command adds to a document's provenance: the longest plan, the part-file options.

    Options not given are ``None`` (left out of the document); the web service, which
    reads no part files, gives ``part=None``.

    Examples
    --------
    >>> run_inputs(None, ProblemSpec(max_actions=3))
    {'max_actions': 3}
    """
    out: dict[str, Any] = {"max_actions": spec.max_actions}
    if part is not None:
        out |= {"format": part.fmt.value if part.fmt else None, "element": part.element}
        out |= {"layer": part.layer, "flatten_tolerance": part.flatten_tol, "com": part.com}
    return out


def simulate_inputs(
    engine: str,
    plan: str,
    seed: int,
    trials: int,
    noise_deg: float,
    noise_kind: str,
    offset_mm: float = 0.0,
    units: str | None = None,
    workers: int | None = None,
) -> dict[str, Any]:
    """How a simulation was run, for its document's provenance (defaults left out).

    Examples
    --------
    >>> simulate_inputs("kinematic", "bayes", 0, 100, 0.0, "normal")["offset_mm"] is None
    True
    """
    return {
        "engine": engine,
        "plan": plan,
        "seed": seed,
        "trials": trials,
        "noise_deg": noise_deg,
        "noise_kind": noise_kind,
        "offset_mm": offset_mm or None,
        "units": units,
        "workers": workers,
    }
