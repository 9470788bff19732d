"""The paper's reproductions: ``table1``, ``study``, and the ``demo`` of the main job."""

from __future__ import annotations

from typing import Annotated

import typer

from .common import emit_json, with_progress
from .options import JsonOpt, command_app
from .specs import Method

app = command_app()

PolygonsOpt = Annotated[
    int, typer.Option(min=1, help="How many random polygons (the paper: 2000).")
]
SeedOpt = Annotated[int, typer.Option(min=0, help="Seed of the random generator (>= 0).")]
MethodOpt = Annotated[Method, typer.Option(help="Planner whose plans give the figures.")]
StudySenseOpt = Annotated[
    str | None,
    typer.Option(
        "--sense",
        metavar="width[:SIGMA,RES]",
        help="The sensing study instead: mean cost without sensing, with exact readings and "
        "with SIGMA 1% and 5% (or the SIGMA,RES given) of each part's largest diameter, "
        "squeezes only and with push-grasps, on the polygons and the Table 1 parts.",
    ),
]
StudyDepthOpt = Annotated[
    int, typer.Option("--max-actions", min=1, max=6, help="With --sense: deepest policy.")
]
BfsStatsOpt = Annotated[
    bool,
    typer.Option(
        "--bfs-stats/--no-bfs-stats",
        help="Also run the breadth-first baseline for its node statistics.",
    ),
]


@app.command()
def table1(as_json: JsonOpt = False) -> None:
    """The paper's Table 1: our expected cost per plan length beside the printed numbers."""
    from ..paper.table1 import table1_json, table1_rows, table1_text

    rows = table1_rows()
    if as_json:
        emit_json(table1_json(rows))
    else:
        typer.echo(table1_text(rows))


@app.command()
def study(
    polygons: PolygonsOpt = 2000,
    seed: SeedOpt = 1,
    method: MethodOpt = Method.exact,
    bfs_stats: BfsStatsOpt = True,
    as_json: JsonOpt = False,
    sense: StudySenseOpt = None,
    max_actions: StudyDepthOpt = 2,
) -> None:
    """The paper's study: hulls of 10 random points in the unit square, planned and counted."""
    if sense is not None:
        from ..paper.sensing import run_sensing_study, sensing_json, sensing_table

        res = with_progress(
            "planning polygons",
            polygons,
            lambda progress: run_sensing_study(
                polygons, seed, max_actions, sense, progress=progress
            ),
        )
        emit_json(sensing_json(res)) if as_json else typer.echo(sensing_table(res))
        return
    from ..paper.study import run_study, study_json, study_table

    bfs = bfs_stats or method is Method.bfs
    res = with_progress(
        "planning polygons",
        polygons,
        lambda progress: run_study(
            polygons=polygons, seed=seed, method=method.value, bfs_stats=bfs, progress=progress
        ),
    )
    if as_json:
        emit_json(study_json(res))
    else:
        typer.echo(study_table(res))


@app.command()
def demo() -> None:
    """The main job: the seed's Table 1, then the example part analysed and planned."""
    from .. import report
    from ..geometry.transfer import squeeze_function
    from ..model.actions import PUSH_GRASP, SQUEEZE
    from ..model.problem import Problem
    from ..paper.table1 import table1_rows, table1_text
    from ..planning import plan_exact
    from ..shapes import load

    typer.echo(table1_text(table1_rows()))
    typer.echo("")
    example = load("example")
    typer.echo(report.squeeze_table(example, squeeze_function(example.hull)))
    typer.echo("")
    typer.echo(report.plan_table(plan_exact(Problem.build(example))))
    typer.echo("")
    typer.echo("With push-grasps (cost 1) as well as squeezes, the same part:")
    mixed = Problem.build(example, actions=(SQUEEZE, PUSH_GRASP))
    typer.echo(report.plan_table(plan_exact(mixed)))
