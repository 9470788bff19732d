"""The options the commands share, declared once: part, problem and planner.

The problem options are the prior, costs, goal, actions and accuracy; the planner options
the method and the longest plan. A command takes each group as one value
(:mod:`.specs`): a parameter ``part: PartSpec`` under :func:`part_options`, ``spec:
ProblemSpec`` under :func:`problem_options`; the decorator puts the options in the
command's signature (typer reads it) and builds the value. The cost options come from the
action registry: ``--NAME-cost`` and ``--first-NAME-cost`` for every action kind registered
when the command is loaded.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from .common import accuracy_value, bound_value, cost_value, flatten_value, print_note
from .specs import GoalKind, Method, PartFormat, PartSpec, ProblemSpec, SenseSpec, problem_spec

F = TypeVar("F", bound=Callable[..., Any])

PartArg = Annotated[
    str,
    typer.Argument(help="Catalogue name or part file (.json, .csv, .wkt, .geojson, .svg, .dxf)."),
]
OptionalPartArg = Annotated[
    str | None,
    typer.Argument(metavar="PART", help=PartArg.__metadata__[0].help, show_default=False),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print JSON for machines.")]
ForceOpt = Annotated[
    bool,
    typer.Option(
        "--force", help="Replace output files that exist (an input file is never replaced)."
    ),
]
PlanChoiceOpt = Annotated[
    str,
    typer.Option("--plan", metavar="PLAN", help="bayes | most-certain | guaranteed | FILE.json"),
]


FORMAT_HELP = "Format of the part file (default: from its extension)."
ELEMENT_HELP = (
    "Which outline when the file has several: SVG element id, GeoJSON feature name or id, "
    "or polygon index (GeoJSON, WKT)."
)
FLATTEN_HELP = (
    "Chordal tolerance for flattening curves, in the file's units "
    "(default: 0.1% of the drawing's diagonal)."
)
COM_HELP = (
    "The part's centre of mass, in the file's coordinates (default: the area centroid of "
    "the outline; a CSV or JSON point list that crosses itself is a point cloud, whose part "
    "is its convex hull, so its default is the hull's centroid)."
)
SHAPE_HELP = (
    "Manufacturing tolerance of the part, in its units: minima of the diameter function that "
    "a shape error this large could remove are not stable orientations (default 0)."
)
PRIOR_HELP = (
    "Prior on the initial orientation: uniform | vonmises:MEAN_DEG,KAPPA | histogram:FILE "
    "(bin weights over [0, 360) deg) | sample:FILE (observed angles, deg)."
)
PriorOpt = Annotated[str, typer.Option(help=PRIOR_HELP)]
GOAL_HELP = "single: one final orientation; symmetry: up to symmetry."
ACTIONS_HELP = (
    "Action types a plan may use, comma-separated: {} (the pushing jaw is on the gripper's "
    "-x side)."
)
MAX_HELP = "Longest plan to consider, counting actions of every kind (push-grasps too)."
MAX_SENSE_HELP = (
    "Longest plan to consider, counting actions of every kind (push-grasps too; default: "
    "the planner's own bound); with --sense, the deepest policy (default {}, at most {})."
)
ACCURACY_HELP = (
    "Gripper accuracy: each turn between actions may err by up to DEG degrees; only plans "
    "whose tolerance is at least DEG are returned (exact planner)."
)

# The noise and payoff options of plan, simulate and plot, see cli/noisy.py.
TurnNoiseOpt = Annotated[
    str | None,
    typer.Option(
        "--turn-noise",
        metavar="normal:SIGMA_DEG|uniform:A_DEG",
        help="Gripper turns executed as alpha + e, e ~ Normal(0, SIGMA^2) or uniform on "
        "[-A, A] degrees: plan gives the noise-aware Bayes plan; simulate runs it, draws e "
        "and predicts exactly under it; plot draws it and its distributions under the noise.",
    ),
]
ContactNoiseOpt = Annotated[
    float | None,
    typer.Option(
        "--contact-noise",
        metavar="Q",
        min=0.0,
        max=1.0,
        help="Jaws touch one after the other with probability Q (either side first): such a "
        "squeeze acts as a push-grasp from that side (plan plans for it, simulate draws it, "
        "plot draws the distributions under it).",
    ),
]
PayoffOpt = Annotated[
    Path | None,
    typer.Option(
        "--payoff",
        metavar="FILE",
        help="Payoff in [0, 1] of final stable orientations (.json or .csv, orientation_deg,"
        "value): minimise the expected cost per unit payoff (simulate: judge by the mean; "
        "plot: draw that plan).",
    ),
]


SenseOpt = Annotated[
    str | None,
    typer.Option(
        "--sense",
        metavar="width[:SIGMA,RES]",
        help="Plan a policy that branches on the jaw width read after each action: exact "
        "readings (width), or read as RES * round((d + e) / RES), e ~ Normal(0, SIGMA^2), in "
        "the part's units.",
    ),
]
AlsoOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--also",
        metavar="PART",
        help="With --sense: another candidate part (repeat it); the policy also tells them apart.",
    ),
]
PartPriorOpt = Annotated[
    str | None,
    typer.Option(
        "--part-prior", metavar="W1,W2,...", help="With --sense: weights of PART and each --also."
    ),
]
MaxOpeningOpt = Annotated[
    float | None,
    typer.Option(
        "--max-opening",
        min=0.0,
        metavar="WIDTH",
        help="The widest the gripper opens (part units): refuse a plan or policy with a step "
        "that needs the jaws open wider than the part can lie across them.",
    ),
]
MinOpeningOpt = Annotated[
    float | None,
    typer.Option(
        "--min-opening",
        min=0.0,
        metavar="WIDTH",
        help="The narrowest the gripper closes (part units): refuse a plan or policy with a "
        "step that may close the jaws on a width narrower than this.",
    ),
]
# A mesh PART's options (plan MESH; see cli/meshes.py).
PoseOpt = Annotated[
    int | None,
    typer.Option(
        "--pose",
        min=0,
        metavar="K",
        help="With a mesh PART: plan resting pose K (0 the most probable, as `poses` lists "
        "them), its footprint a planar part (default 0).",
    ),
]
GoalPoseOpt = Annotated[
    str | None,
    typer.Option(
        "--goal-pose",
        metavar="K|any",
        help="With a mesh PART and --sense: only pose K may be declared, the others are "
        "rejected (dropped again, --retry-cost) (default 0); any: every pose may be declared.",
    ),
]
JawHeightOpt = Annotated[
    float | None,
    typer.Option(
        "--jaw-height",
        min=0.0,
        metavar="H",
        help="With a mesh PART: height of the jaws' contact above the table (the mesh's "
        "units). A pose that a squeeze at this height may topple (the first jaw's push tips it "
        "before it slides, table friction 0.5) is refused: with --pose K that pose, with "
        "--sense the policy, naming the poses. Default: the jaws at the table, no squeeze "
        "topples a part.",
    ),
]
PosePriorOpt = Annotated[
    str | None,
    typer.Option(
        "--pose-prior",
        metavar="quasi-static|perturbed|drops:N|FILE",
        help="With a mesh PART and --sense: the poses' prior: the quasi-static estimate "
        "(default), the perturbed one, the frequencies of N MuJoCo drops (extra `sim`), or a "
        "bayesgrasp.poses/1 file (`poses --json`; its probabilities, matched by normal).",
    ),
]
# SenseOpt, AlsoOpt, PartPriorOpt and the problem option --max-actions: the options of a
# sensing policy (plan, simulate and plot --sense), gathered into a SenseSpec (sense_spec).
POLICY_DEPTH = 3
"""The depth of a policy when ``--max-actions`` is not given (a plan has no such default)."""
DEEPEST_POLICY = 8
"""The deepest policy ``--max-actions`` asks for (the policy's tree grows with each level)."""
MaxMemoryOpt = Annotated[
    float | None,
    typer.Option(
        "--max-memory",
        metavar="MB",
        min=1.0,
        callback=bound_value,
        help="With --sense: the most memory (MB, about) the policy search may keep for the "
        "beliefs it acts on; past it the search stops with a message (default 2048).",
    ),
]
TimeLimitOpt = Annotated[
    float | None,
    typer.Option(
        "--time-limit",
        metavar="S",
        min=0.001,
        callback=bound_value,
        help="With --sense: the most seconds the policy search may take (default 60). Past "
        "it (or --max-memory) the search plans again within the same bounds, one action more "
        "at a time, and answers with the deepest policy that finished, saying so and giving "
        "a lower bound on the cost of any policy of --max-actions.",
    ),
]
FoldOpt = Annotated[
    float,
    typer.Option(
        "--fold-below",
        min=0.0,
        max=1.0,
        metavar="P",
        help="With --sense: the printed tree leaves out the branches whose probability at "
        "their node is below P, counted on one line (0 prints every branch; --json keeps "
        "every branch); given, the --plot figure too draws them as one edge (its default: "
        "0.05).",
    ),
]


def command_app() -> typer.Typer:
    """The typer app of one command module (settings as the main app's)."""
    return typer.Typer(add_completion=False, pretty_exceptions_enable=False, rich_markup_mode=None)


def _opt(name: str, kind: Any, default: Any, *decls: str, **info: Any) -> inspect.Parameter:
    """A keyword-only parameter ``name: Annotated[kind, typer.Option(*decls, **info)]``."""
    hint = Annotated[kind, typer.Option(*decls, **info)]
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=hint)


def _part_params(optional: bool = False) -> list[inspect.Parameter]:
    part = inspect.Parameter("part", inspect.Parameter.KEYWORD_ONLY, annotation=PartArg)
    if optional:  # PART may be left out (plan --batch)
        part = part.replace(annotation=OptionalPartArg, default=None)
    return [
        part,
        _opt("fmt", PartFormat | None, None, "--format", help=FORMAT_HELP),
        _opt("element", str | None, None, metavar="ID", help=ELEMENT_HELP),
        _opt("layer", str | None, None, help="DXF: read only this layer."),
        _opt("flatten_tol", float | None, None, callback=flatten_value, help=FLATTEN_HELP),
        _opt("com", str | None, None, "--com", metavar="X,Y", help=COM_HELP),
        _opt("shape_tol", float, 0.0, min=0, help=SHAPE_HELP),
    ]


def _problem_params(
    names: list[str], push_grasp_alias: bool, plan_file: bool = True, sense: bool = False
) -> list[inspect.Parameter]:
    money = {"callback": cost_value}
    cost = [
        _opt(f"cost_{i}", float, 1.0, f"--{n}-cost", **money, help=f"Cost of a {n}.")
        for i, n in enumerate(names)
    ]
    first_help = "Cost of the first {} (default: as others)."
    first = [
        _opt(
            f"first_{i}",
            float | None,
            None,
            f"--first-{n}-cost",
            **money,
            help=first_help.format(n),
        )
        for i, n in enumerate(names)
    ]
    kinds = ACTIONS_HELP.format(", ".join(names))
    from_file = " (default: {}; with --plan FILE: the file's)" if plan_file else " (default: {})"
    longest = MAX_SENSE_HELP.format(POLICY_DEPTH, DEEPEST_POLICY) if sense else MAX_HELP
    old_longest = "The old name of --max-actions."
    params = [
        _opt("prior", str | None, None, help=PRIOR_HELP + from_file.format("uniform")),
        cost[0],
        _opt("verify_cost", float, 1.0, **money, help="Cost of the verification."),
        *first,
        _opt("retry_cost", float, 0.0, **money, help="Overhead paid on each failed verification."),
        *cost[1:],
        _opt("goal", GoalKind | None, None, help=GOAL_HELP + from_file.format("single")),
        _opt("actions", str, "squeeze", metavar="KINDS", help=kinds),
        _opt("accuracy", float, 0.0, callback=accuracy_value, metavar="DEG", help=ACCURACY_HELP),
        _opt("method", Method, Method.exact, help="exact planner or the paper's search."),
        _opt("max_actions", int | None, None, "--max-actions", min=1, help=longest),
        _opt("max_squeezes", int | None, None, min=1, hidden=True, help=old_longest),
    ]
    if push_grasp_alias:  # the old spelling of simulate and plot, kept working
        alias = "Same as --actions squeeze,push-grasp."
        params.append(_opt("push_grasp", bool, False, "--push-grasp", hidden=True, help=alias))
    return params


def _replace(func: F, name: str, params: list[inspect.Parameter], make: Callable[..., Any]) -> F:
    """``func`` with its parameter ``name`` replaced by ``params``, whose values ``make`` joins."""
    sig = inspect.signature(func, eval_str=True)
    new: list[inspect.Parameter] = []
    for p in sig.parameters.values():  # keyword-only: typer passes every value by name
        new += params if p.name == name else [p.replace(kind=inspect.Parameter.KEYWORD_ONLY)]
    own = [p.name for p in params]

    @functools.wraps(func)
    def command(**kwargs: Any) -> Any:
        values = {k: kwargs.pop(k) for k in own}
        return func(**kwargs, **{name: make(values)})

    command.__signature__ = sig.replace(parameters=new)  # type: ignore[attr-defined]
    command.__annotations__ = {p.name: p.annotation for p in new}
    command.__annotations__["return"] = sig.return_annotation
    return command  # type: ignore[return-value]


def part_options(func: F, optional: bool = False) -> F:
    """Give a command PART and the part-file options, as its parameter ``part: PartSpec``.

    ``optional``: PART may be left out (``PartSpec.part`` is then ``None``).
    """
    return _replace(
        func, "part", _part_params(optional), lambda values: PartSpec(**values, note=print_note)
    )


def problem_options(push_grasp_alias: bool = False) -> Callable[[F], F]:
    """Give a command the problem and planner options, as its parameter ``spec: ProblemSpec``.

    ``push_grasp_alias`` adds the hidden ``--push-grasp`` (``--actions squeeze,push-grasp``).
    """

    def decorate(func: F) -> F:
        from ..model.actions import ACTIONS

        names = list(ACTIONS)  # the kinds registered now: one cost option each
        # the help names --plan FILE and --sense only where the command has them
        hints = inspect.signature(func, eval_str=True).parameters.values()
        plan_file = any(p.annotation == PlanChoiceOpt for p in hints)
        sense = any(p.name == "sense" for p in hints)
        params = _problem_params(names, push_grasp_alias, plan_file, sense)

        def make(values: dict[str, Any]) -> ProblemSpec:
            values["max_squeezes"] = longest(values.pop("max_actions"), values["max_squeezes"])
            return problem_spec(names, values)

        return _replace(func, "spec", params, make)

    return decorate


def longest(max_actions: int | None, max_squeezes: int | None) -> int | None:
    """The value of ``--max-actions``, or of its old name ``--max-squeezes``.

    Both given with different values: exit 2 (one option cannot say two lengths).

    Examples
    --------
    >>> longest(None, 2), longest(3, None), longest(2, 2), longest(None, None)
    (2, 3, 2, None)
    """
    if max_actions is not None and max_squeezes is not None and max_actions != max_squeezes:
        raise typer.BadParameter(
            f"is the old name of --max-actions; give one of them (got --max-actions "
            f"{max_actions} and --max-squeezes {max_squeezes})",
            param_hint="--max-squeezes",
        )
    return max_squeezes if max_actions is None else max_actions


def sense_spec(
    sense: str,
    also: Iterable[str],
    part_prior: str | None,
    spec: ProblemSpec,
    max_memory_mb: float | None = None,
    time_limit_s: float | None = None,
) -> SenseSpec:
    """The :class:`SenseSpec` of the --sense options, its depth ``spec``'s --max-actions.

    Without --max-actions a policy is :data:`POLICY_DEPTH` deep; deeper than
    :data:`DEEPEST_POLICY` is refused (exit 2).

    Examples
    --------
    >>> sense_spec("width", ["key"], None, ProblemSpec()).max_actions
    3
    >>> sense_spec("width", [], None, ProblemSpec(max_actions=2)).max_actions
    2
    """
    depth = POLICY_DEPTH if spec.max_actions is None else spec.max_actions
    if depth > DEEPEST_POLICY:
        raise typer.BadParameter(
            f"a policy is at most {DEEPEST_POLICY} actions deep (its tree grows with each "
            f"level); got {depth}",
            param_hint="--max-actions",
        )
    bounds = {
        k: v
        for k, v in (("max_memory_mb", max_memory_mb), ("time_limit_s", time_limit_s))
        if v is not None
    }
    return SenseSpec(sense, tuple(also), part_prior, depth, **bounds)
