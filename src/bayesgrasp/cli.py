"""The ``bayesgrasp`` command line: parse, call the library, print. Nothing else.

Exit codes: 0 success, 1 no plan reached the requested goal, 2 bad input (one line on stderr,
never a traceback).
"""

from __future__ import annotations

import enum
import json
import sys
from typing import Annotated, Any

import typer

from . import report
from .errors import BayesGraspError
from .io import resolve_part
from .planning import plan_exact
from .prior import parse_prior
from .problem import CostModel, Goal, Problem
from .shapes import names as catalogue_names
from .transfer import squeeze_function

app = typer.Typer(
    help=(
        "Plan parallel-jaw squeeze sequences that orient a planar part at least expected "
        "cost (Goldberg & Mason, Bayesian Grasping). PART is a catalogue name "
        f"({', '.join(catalogue_names())}) or a part file (.json, .csv)."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

PartArg = Annotated[str, typer.Argument(help="Catalogue name or part file (.json, .csv).")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print JSON for machines.")]


def emit_json(doc: dict[str, Any]) -> None:
    """Print a JSON document (no NaN or infinity: those become null upstream)."""
    typer.echo(json.dumps(doc, indent=2, allow_nan=False))


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
    prior: Annotated[
        str, typer.Option(help="uniform | vonmises:MEAN_DEG,KAPPA | histogram:FILE | sample:FILE")
    ] = "uniform",
    as_json: JsonOpt = False,
) -> None:
    """Stable orientations of a squeeze, their basins and probabilities after one squeeze."""
    p = resolve_part(part)
    pr = parse_prior(prior)
    f = squeeze_function(p.hull)
    if as_json:
        emit_json(report.squeeze_json(p, f, pr))
    else:
        typer.echo(report.squeeze_table(p, f, pr))


def build_problem(
    part: str,
    prior: str,
    squeeze_cost: float,
    verify_cost: float,
    first_squeeze_cost: float | None,
    retry_cost: float,
    goal: GoalKind,
    actions: tuple[str, ...] = ("squeeze",),
    push_grasp_cost: float = 1.0,
) -> Problem:
    """Parse the options shared by planning commands into a problem."""
    cost = CostModel(
        squeeze=squeeze_cost,
        verify=verify_cost,
        first_squeeze=first_squeeze_cost,
        retry=retry_cost,
        push_grasp=push_grasp_cost,
    )
    return Problem.build(
        resolve_part(part), parse_prior(prior), cost, Goal(goal.value), actions=actions
    )


@app.command()
def plan(
    part: PartArg,
    prior: Annotated[
        str, typer.Option(help="uniform | vonmises:MEAN_DEG,KAPPA | histogram:FILE | sample:FILE")
    ] = "uniform",
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
    as_json: JsonOpt = False,
) -> None:
    """Best squeeze plan of every length, the Bayes plan and the most certain plan."""
    pb = build_problem(part, prior, squeeze_cost, verify_cost, first_squeeze_cost, retry_cost, goal)
    if method is Method.bfs:
        from .planning.bfs import plan_bfs

        rep = plan_bfs(pb, max_actions=max_squeezes)
    else:
        rep = plan_exact(pb, max_actions=max_squeezes)
    if as_json:
        emit_json(report.plan_json(rep))
    else:
        typer.echo(report.plan_table(rep))


@app.command()
def demo() -> None:
    """The main job: the squeeze analysis of every catalogue part, then the example's plans."""
    from .shapes import load

    for name in catalogue_names():
        p = load(name)
        typer.echo(report.squeeze_table(p, squeeze_function(p.hull)))
        typer.echo("")
    if "example" in catalogue_names():
        typer.echo(report.plan_table(plan_exact(Problem.build(load("example")))))


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
    from .study import run_study, study_json, study_table

    kwargs: dict[str, Any] = {
        "polygons": polygons,
        "seed": seed,
        "method": method.value,
        "bfs_stats": bfs_stats or method is Method.bfs,
    }
    if sys.stderr.isatty():
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
            task = bar.add_task("planning polygons", total=polygons)
            res = run_study(
                **kwargs, progress=lambda done, _total: bar.update(task, completed=done)
            )
    else:
        res = run_study(**kwargs)
    if as_json:
        emit_json(study_json(res))
    else:
        typer.echo(study_table(res))


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
