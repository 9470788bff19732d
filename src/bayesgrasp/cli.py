"""The ``bayesgrasp`` command line: parse, call the library, print. Nothing else.

Exit codes: 0 success, 1 no plan reached the requested goal, 2 bad input (one line on stderr,
never a traceback).
"""

from __future__ import annotations

import enum
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from . import report
from .errors import BayesGraspError, NoPlanError
from .geometry.polygon import Part
from .geometry.transfer import squeeze_function
from .io import resolve_part
from .model.prior import parse_prior
from .model.problem import CostModel, Goal, Problem
from .planning import plan_exact
from .shapes import names as catalogue_names

app = typer.Typer(
    help=(
        "Plan parallel-jaw squeeze sequences that orient a planar part at least expected "
        "cost (Goldberg & Mason, Bayesian Grasping). PART is a catalogue name "
        f"({', '.join(catalogue_names())}) or a part file (.json, .csv, .wkt, .geojson, "
        ".svg, .dxf)."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

PartArg = Annotated[
    str,
    typer.Argument(help="Catalogue name or part file (.json, .csv, .wkt, .geojson, .svg, .dxf)."),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print JSON for machines.")]
PriorOpt = Annotated[
    str,
    typer.Option(
        help="Prior on the initial orientation: uniform | vonmises:MEAN_DEG,KAPPA | "
        "histogram:FILE (bin weights over [0, 360) deg) | sample:FILE (observed angles, deg)."
    ),
]


class PartFormat(enum.StrEnum):
    """Part file formats (default: from the file's extension)."""

    json = "json"
    csv = "csv"
    wkt = "wkt"
    geojson = "geojson"
    svg = "svg"
    dxf = "dxf"


# Options of every command that reads a PART (see bayesgrasp.io.read_part).
FormatOpt = Annotated[
    PartFormat | None,
    typer.Option("--format", help="Format of the part file (default: from its extension)."),
]
ElementOpt = Annotated[
    str | None,
    typer.Option(
        "--element",
        metavar="ID",
        help="Which outline when the file has several: SVG element id, GeoJSON feature "
        "name or id, or polygon index (GeoJSON, WKT).",
    ),
]
LayerOpt = Annotated[str | None, typer.Option("--layer", help="DXF: read only this layer.")]
FlattenTolOpt = Annotated[
    float | None,
    typer.Option(
        "--flatten-tol",
        help="Chordal tolerance for flattening curves, in the file's units "
        "(default: 0.1% of the drawing's diagonal).",
    ),
]


def load_part(
    part: str,
    fmt: PartFormat | None = None,
    element: str | None = None,
    layer: str | None = None,
    flatten_tol: float | None = None,
) -> Part:
    """Resolve PART and the part-file options into a part."""
    return resolve_part(
        part, fmt.value if fmt else None, element=element, layer=layer, tolerance=flatten_tol
    )


def emit_json(doc: dict[str, Any]) -> None:
    """Print a JSON document (no NaN or infinity: those become null upstream)."""
    typer.echo(json.dumps(doc, indent=2, allow_nan=False))


def with_progress(description: str, total: int, work: Callable[[Any], Any]) -> Any:
    """Run ``work(progress)`` with a rich progress bar on a terminal, without one elsewhere.

    ``progress`` is ``None`` or a callback ``(done, total)`` the library calls as it goes.
    """
    if not sys.stderr.isatty():
        return work(None)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    with Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=total)
        return work(lambda done, _total: bar.update(task, completed=done))


class Method(enum.StrEnum):
    """Planner to use."""

    exact = "exact"
    bfs = "bfs"


class GoalKind(enum.StrEnum):
    """What counts as success."""

    single = "single"
    symmetry = "symmetry"


@app.command()
def squeeze(
    part: PartArg,
    prior: PriorOpt = "uniform",
    as_json: JsonOpt = False,
    fmt: FormatOpt = None,
    element: ElementOpt = None,
    layer: LayerOpt = None,
    flatten_tol: FlattenTolOpt = None,
) -> None:
    """Stable orientations of a squeeze, their basins and probabilities after one squeeze."""
    p = load_part(part, fmt, element, layer, flatten_tol)
    pr = parse_prior(prior)
    f = squeeze_function(p.hull)
    if as_json:
        emit_json(report.squeeze_json(p, f, pr))
    else:
        typer.echo(report.squeeze_table(p, f, pr))


def build_problem(
    part: str | Part,
    prior: str,
    squeeze_cost: float,
    verify_cost: float,
    first_squeeze_cost: float | None,
    retry_cost: float,
    goal: GoalKind,
    actions: tuple[str, ...] = ("squeeze",),
    push_grasp_cost: float = 1.0,
    accuracy_deg: float = 0.0,
) -> Problem:
    """Parse the options shared by planning commands into a problem."""
    cost = CostModel(
        {"squeeze": squeeze_cost, "push-grasp": push_grasp_cost},
        verify=verify_cost,
        first={} if first_squeeze_cost is None else {"squeeze": first_squeeze_cost},
        retry=retry_cost,
    )
    p = resolve_part(part) if isinstance(part, str) else part
    return Problem.build(
        p,
        parse_prior(prior),
        cost,
        Goal(goal.value),
        actions=actions,
        accuracy=math.radians(accuracy_deg),
    )


# The gripper accuracy of the commands that plan (Problem.build's ``accuracy``, in degrees).
AccuracyOpt = Annotated[
    float,
    typer.Option(
        "--accuracy",
        min=0,
        metavar="DEG",
        help="Gripper accuracy: each turn between actions may err by up to DEG degrees; "
        "only plans whose tolerance is at least DEG are returned (exact planner).",
    ),
]


@app.command()
def plan(
    part: PartArg,
    prior: PriorOpt = "uniform",
    squeeze_cost: Annotated[float, typer.Option(min=0, help="Cost of a squeeze.")] = 1.0,
    verify_cost: Annotated[float, typer.Option(min=0, help="Cost of the verification.")] = 1.0,
    first_squeeze_cost: Annotated[
        float | None, typer.Option(min=0, help="Cost of the first squeeze (default: as others).")
    ] = None,
    retry_cost: Annotated[
        float, typer.Option(min=0, help="Overhead paid on each failed verification.")
    ] = 0.0,
    goal: Annotated[
        GoalKind, typer.Option(help="single: one final orientation; symmetry: up to symmetry.")
    ] = GoalKind.single,
    method: Annotated[Method, typer.Option(help="exact planner or the seed's search.")] = (
        Method.exact
    ),
    max_squeezes: Annotated[
        int | None, typer.Option(min=1, help="Longest plan to consider.")
    ] = None,
    actions: Annotated[
        str,
        typer.Option(
            metavar="KINDS",
            help="Action types a plan may use, comma-separated: squeeze, push-grasp "
            "(the pushing jaw is on the gripper's -x side).",
        ),
    ] = "squeeze",
    push_grasp_cost: Annotated[float, typer.Option(min=0, help="Cost of a push-grasp.")] = 1.0,
    accuracy: AccuracyOpt = 0.0,
    guaranteed: Annotated[
        bool,
        typer.Option(
            "--guaranteed",
            help="Also give the shortest plan that orients every initial orientation "
            "(up to the transfer functions' period).",
        ),
    ] = False,
    as_json: JsonOpt = False,
    fmt: FormatOpt = None,
    element: ElementOpt = None,
    layer: LayerOpt = None,
    flatten_tol: FlattenTolOpt = None,
    plot_file: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            metavar="FILE",
            help="Also draw the part, its diameter function and the Bayes plan's "
            "distributions into FILE (.png, .svg, .pdf).",
        ),
    ] = None,
) -> None:
    """Best squeeze plan of every length, the Bayes plan and the most certain plan."""
    if plot_file is not None:
        check_figure_path(plot_file)
    pb = build_problem(
        load_part(part, fmt, element, layer, flatten_tol),
        prior,
        squeeze_cost,
        verify_cost,
        first_squeeze_cost,
        retry_cost,
        goal,
        actions=tuple(a.strip() for a in actions.split(",") if a.strip()),
        push_grasp_cost=push_grasp_cost,
        accuracy_deg=accuracy,
    )
    if method is Method.bfs:
        from .planning.bfs import plan_bfs

        rep = plan_bfs(pb, max_actions=max_squeezes)
    else:
        rep = plan_exact(pb, max_actions=max_squeezes)
    sure = None
    no_plan: str | None = None  # why no guaranteed plan exists (exit code 1)
    if guaranteed:
        from .planning.guaranteed import plan_guaranteed

        try:
            sure = plan_guaranteed(pb)
        except NoPlanError as exc:
            no_plan = str(exc)
    if as_json:
        plan2 = guaranteed or "push-grasp" in pb.action_kinds
        doc = report.plan_json(rep, "bayesgrasp.plan/2" if plan2 else "bayesgrasp.plan/1")
        if sure is not None:
            doc["guaranteed"] = report.guaranteed_json(sure)
        if no_plan is not None:
            doc["guaranteed"] = None
            doc["guaranteed_missing"] = no_plan
        emit_json(doc)
    else:
        typer.echo(report.plan_table(rep))
        if sure is not None:
            typer.echo(report.guaranteed_text(sure))
        if no_plan is not None:
            typer.echo(f"Guaranteed plan: none ({no_plan})")
    if plot_file is not None:
        from .figures.plots import plan_figure

        save_figure(plan_figure(rep), plot_file)
        typer.echo(f"bayesgrasp: wrote {plot_file}", err=True)
    if no_plan is not None:
        raise typer.Exit(1)


IMAGE_FORMATS = ("png", "svg", "pdf")


def check_figure_path(path: Path) -> None:
    """Refuse a figure file name that cannot be written, before any work is done."""
    if path.suffix.lstrip(".").lower() not in IMAGE_FORMATS:
        raise typer.BadParameter(
            f"the figure file must end in .png, .svg or .pdf; got {path.name!r}",
            param_hint="--plot",
        )
    if not path.parent.is_dir():
        raise typer.BadParameter(
            f"no folder {str(path.parent)!r} to write into", param_hint="--plot"
        )


def save_figure(fig: Any, path: Path) -> None:
    """Write a figure; a bad file name is a usage error (exit 2), not a traceback."""
    check_figure_path(path)
    try:
        fig.savefig(path, dpi=110)
    except OSError as exc:
        raise typer.BadParameter(
            f"cannot write {path}: {exc.strerror or exc}", param_hint="--plot"
        ) from None


class PlotPlan(enum.StrEnum):
    """Which plan the figures show."""

    bayes = "bayes"
    most_certain = "most-certain"
    guaranteed = "guaranteed"


@app.command()
def plot(
    part: PartArg,
    out: Annotated[
        Path, typer.Option("--out", metavar="DIR", help="Folder for the figures (created).")
    ] = Path("figures"),
    which: Annotated[
        PlotPlan,
        typer.Option("--plan", help="The plan to draw: Bayes, most certain, or guaranteed."),
    ] = PlotPlan.bayes,
    prior: PriorOpt = "uniform",
    push_grasp: Annotated[
        bool, typer.Option("--push-grasp", help="Also draw the push-grasp function.")
    ] = False,
    image_formats: Annotated[
        str, typer.Option("--image-formats", help="Comma-separated: png, svg, pdf.")
    ] = "png,svg",
    animation: Annotated[
        bool,
        typer.Option(
            "--animation/--no-animation", help="Also write the plan's animation (plan.gif)."
        ),
    ] = True,
    frames: Annotated[
        int, typer.Option(min=4, max=240, help="Animation frames per plan step.")
    ] = 20,
    accuracy: AccuracyOpt = 0.0,
    as_json: JsonOpt = False,
    fmt: FormatOpt = None,
    element: ElementOpt = None,
    layer: LayerOpt = None,
    flatten_tol: FlattenTolOpt = None,
) -> None:
    """Figures of a part and a plan: part.*, diameter.*, transfer.*, plan.* and plan.gif."""
    from .figures.plots import write_figures

    formats = [f.strip().lower() for f in image_formats.split(",") if f.strip()]
    bad = [f for f in formats if f not in IMAGE_FORMATS]
    if bad or not formats:
        raise typer.BadParameter(
            f"expected a comma-separated list of png, svg, pdf; got {image_formats!r}",
            param_hint="--image-formats",
        )
    pb = Problem.build(
        load_part(part, fmt, element, layer, flatten_tol),
        parse_prior(prior),
        accuracy=math.radians(accuracy),
    )
    if which is PlotPlan.guaranteed:
        from .planning.guaranteed import plan_guaranteed

        option = plan_guaranteed(pb).option
    else:
        rep = plan_exact(pb)
        option = rep.bayes_plan if which is PlotPlan.bayes else rep.most_certain_plan
    label = {"bayes": "Bayes", "most-certain": "most certain"}.get(which.value, which.value)
    try:
        files = write_figures(
            pb,
            option,
            out,
            label=label,
            formats=formats,
            push_grasp=push_grasp,
            animation=animation,
            frames_per_step=frames,
        )
    except OSError as exc:
        raise typer.BadParameter(
            f"cannot write into {out}: {exc.strerror or exc}", param_hint="--out"
        ) from None
    if as_json:
        emit_json({"schema": "bayesgrasp.plot/1", "files": [str(f) for f in files]})
    else:
        for f in files:
            typer.echo(str(f))


@app.command()
def push(
    part: PartArg,
    prior: PriorOpt = "uniform",
    as_json: JsonOpt = False,
    fmt: FormatOpt = None,
    element: ElementOpt = None,
    layer: LayerOpt = None,
    flatten_tol: FlattenTolOpt = None,
) -> None:
    """Stable orientations of a push and a push-grasp, their basins and probabilities.

    The push turns the part down its radius function about the centre of mass until an edge
    lies flat against the pushing jaw (on the gripper's -x side); the table names that edge.
    """
    from .geometry.push import push_function, push_grasp_function, radius_function

    p = load_part(part, fmt, element, layer, flatten_tol)
    pr = parse_prior(prior)
    r = radius_function(p)
    f, g = push_function(r), push_grasp_function(p)
    if as_json:
        emit_json(report.push_json(p, r, f, g, pr))
    else:
        typer.echo(report.push_table(p, r, f, g, pr))


@app.command()
def demo() -> None:
    """The main job: the seed's Table 1, then the example part analysed and planned."""
    from .paper.table1 import table1_rows, table1_text
    from .shapes import load

    typer.echo(table1_text(table1_rows()))
    typer.echo("")
    example = load("example")
    typer.echo(report.squeeze_table(example, squeeze_function(example.hull)))
    typer.echo("")
    typer.echo(report.plan_table(plan_exact(Problem.build(example))))
    typer.echo("")
    typer.echo("With push-grasps (cost 1) as well as squeezes, the same part:")
    mixed = Problem.build(example, actions=("squeeze", "push-grasp"))
    typer.echo(report.plan_table(plan_exact(mixed)))


@app.command()
def table1(as_json: JsonOpt = False) -> None:
    """The seed's Table 1: our expected cost per plan length beside the printed numbers."""
    from .paper.table1 import table1_json, table1_rows, table1_text

    rows = table1_rows()
    if as_json:
        emit_json(table1_json(rows))
    else:
        typer.echo(table1_text(rows))


@app.command()
def study(
    polygons: Annotated[
        int, typer.Option(min=1, help="How many random polygons (the seed: 2000).")
    ] = 2000,
    seed: Annotated[int, typer.Option(help="Seed of the random generator.")] = 1,
    method: Annotated[Method, typer.Option(help="Planner whose plans give the figures.")] = (
        Method.exact
    ),
    bfs_stats: Annotated[
        bool,
        typer.Option(
            "--bfs-stats/--no-bfs-stats",
            help="Also run the breadth-first baseline for its node statistics.",
        ),
    ] = True,
    as_json: JsonOpt = False,
) -> None:
    """The seed's study: hulls of 10 random points in the unit square, planned and counted."""
    from .paper.study import run_study, study_json, study_table

    kwargs: dict[str, Any] = {
        "polygons": polygons,
        "seed": seed,
        "method": method.value,
        "bfs_stats": bfs_stats or method is Method.bfs,
    }
    res = with_progress(
        "planning polygons", polygons, lambda progress: run_study(**kwargs, progress=progress)
    )
    if as_json:
        emit_json(study_json(res))
    else:
        typer.echo(study_table(res))


class Engine(enum.StrEnum):
    """How a plan is executed."""

    kinematic = "kinematic"
    mujoco = "mujoco"


class NoiseKind(enum.StrEnum):
    """Distribution of the gripper angle error."""

    normal = "normal"
    uniform = "uniform"


def simulated_plan(which: str, pb: Problem) -> tuple[Any, str]:
    """The plan option named by ``--plan`` (bayes, most-certain, guaranteed or a file)."""
    from .sim.kinematic import SimulationError, plan_from_json

    if which in ("bayes", "most-certain"):
        rep = plan_exact(pb)
        return (rep.bayes_plan, "Bayes") if which == "bayes" else (rep.most_certain_plan, which)
    if which == "guaranteed":
        try:
            from .planning.guaranteed import plan_guaranteed
        except ImportError:
            raise SimulationError(
                "--plan guaranteed needs bayesgrasp.planning.guaranteed, which this "
                "installation lacks; use bayes, most-certain or a plan file"
            ) from None
        return plan_guaranteed(pb).option, which
    path = Path(which)
    if path.suffix.lower() != ".json":
        raise SimulationError(
            f"--plan must be bayes, most-certain, guaranteed or a .json plan file; got {which!r}"
        )
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        reason = exc.strerror or exc
        raise SimulationError(f"plan file {which!r} cannot be read ({reason})") from None
    except json.JSONDecodeError as exc:
        raise SimulationError(f"plan file {which!r} is not valid JSON ({exc.msg})") from None
    try:
        return plan_from_json(doc), path.name
    except SimulationError as exc:
        raise SimulationError(f"plan file {which!r}: {exc}") from None


@app.command()
def simulate(
    part: PartArg,
    which: Annotated[
        str,
        typer.Option(
            "--plan", metavar="PLAN", help="bayes | most-certain | guaranteed | FILE.json"
        ),
    ] = "bayes",
    engine: Annotated[
        Engine, typer.Option(help="kinematic: the model's transfer functions; mujoco: physics.")
    ] = Engine.kinematic,
    trials: Annotated[
        int | None,
        typer.Option(min=1, help="Executions (default: 1,000,000 kinematic, 200 mujoco)."),
    ] = None,
    workers: Annotated[
        int, typer.Option(min=1, help="Processes for mujoco trials (kinematic uses one).")
    ] = 1,
    offset: Annotated[
        float,
        typer.Option(
            min=0,
            metavar="MM",
            help="mujoco: the part's centre is MM millimetres off the gripper centre along "
            "the squeeze axis (random side each action).",
        ),
    ] = 0.0,
    noise: Annotated[
        float,
        typer.Option(min=0, metavar="DEG", help="Gripper angle error: sigma or bound, degrees."),
    ] = 0.0,
    noise_kind: Annotated[
        NoiseKind, typer.Option(help="Gripper error distribution.")
    ] = NoiseKind.normal,
    seed: Annotated[int, typer.Option(help="Seed of the random generator.")] = 0,
    prior: PriorOpt = "uniform",
    goal: Annotated[
        GoalKind, typer.Option(help="single: one final orientation; symmetry: up to symmetry.")
    ] = GoalKind.single,
    push_grasp: Annotated[
        bool,
        typer.Option("--push-grasp", help="Plan with push-grasps as well as squeezes."),
    ] = False,
    accuracy: AccuracyOpt = 0.0,
    units: Annotated[
        str | None,
        typer.Option(help="mujoco: units of the part's coordinates (default: the part's, or m)."),
    ] = None,
    as_json: JsonOpt = False,
    fmt: FormatOpt = None,
    element: ElementOpt = None,
    layer: LayerOpt = None,
    flatten_tol: FlattenTolOpt = None,
) -> None:
    """Execute a plan many times and compare the final orientations with the prediction."""
    import math

    from .sim.kinematic import GripperNoise, simulate_kinematic

    if engine is Engine.kinematic and offset > 0:
        raise typer.BadParameter(
            "applies to --engine mujoco only (the kinematic model has no positions)",
            param_hint="--offset",
        )
    p = load_part(part, fmt, element, layer, flatten_tol)
    actions: tuple[str, ...] = ("squeeze", "push-grasp") if push_grasp else ("squeeze",)
    acc = math.radians(accuracy)
    pb = Problem.build(p, parse_prior(prior), goal=Goal(goal.value), actions=actions, accuracy=acc)
    option, label = simulated_plan(which, pb)
    if "push-grasp" in option.kinds and "push-grasp" not in pb.transfers:
        pb = Problem.build(
            p, pb.prior, goal=pb.goal, actions=("squeeze", "push-grasp"), accuracy=acc
        )
    n = trials or (1_000_000 if engine is Engine.kinematic else 200)
    err = GripperNoise(noise_kind.value, math.radians(noise))

    def run(progress: Any) -> Any:
        if engine is Engine.kinematic:
            return simulate_kinematic(pb, option, n, err, rng=seed, progress=progress)
        from .sim import simulate_mujoco
        from .sim.scene import units_scale

        scale = units_scale(units) if units is not None else None
        return simulate_mujoco(
            pb,
            option,
            n,
            offset=offset / 1000.0,  # millimetres to metres
            noise=err,
            rng=seed,
            workers=workers,
            scale=scale,
            progress=progress,
        )

    res = with_progress(f"{engine.value} trials", n, run)
    if as_json:
        emit_json(report.simulate_json(res, p))
    else:
        title = f"{p.name}: {label} plan, prior {pb.prior.name}; "
        typer.echo(report.simulate_table(res, title))


# typer vendors click; its exception base is reached through a public subclass.
_ClickException: type[Exception] = next(
    c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException"
)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    try:
        rv = app(args=argv, prog_name="bayesgrasp", standalone_mode=False)
    except _ClickException as exc:  # bad usage: one line, exit 2
        msg = exc.format_message()  # type: ignore[attr-defined]
        typer.echo(f"bayesgrasp: error: {msg} (see --help)", err=True)
        return int(getattr(exc, "exit_code", 2))
    except (typer.Exit, SystemExit) as exc:
        code = getattr(exc, "exit_code", getattr(exc, "code", 0))
        return code if isinstance(code, int) else 0
    except typer.Abort:
        typer.echo("bayesgrasp: aborted", err=True)
        return 130
    except BayesGraspError as exc:
        typer.echo(f"bayesgrasp: error: {exc}", err=True)
        return 2
    return rv if isinstance(rv, int) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
