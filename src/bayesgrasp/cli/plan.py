"""``plan``: the best plan of every length, the Bayes plan, the most certain plan."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import check_figure_path, emit_json, guaranteed_plan, save_figure
from .options import JsonOpt, command_app, part_options, problem_options
from .specs import PartSpec, ProblemSpec

app = command_app()

GuaranteedOpt = Annotated[
    bool,
    typer.Option(
        "--guaranteed",
        help="Also give the shortest plan that orients every initial orientation "
        "(up to the transfer functions' period).",
    ),
]
PlotOpt = Annotated[
    Path | None,
    typer.Option(
        "--plot",
        metavar="FILE",
        help="Also draw the part, its diameter function and the Bayes plan's distributions "
        "into FILE (.png, .svg, .pdf).",
    ),
]


@app.command()
@part_options
@problem_options()
def plan(
    part: PartSpec,
    spec: ProblemSpec,
    guaranteed: GuaranteedOpt = False,
    as_json: JsonOpt = False,
    plot_file: PlotOpt = None,
) -> None:
    """Best squeeze plan of every length, the Bayes plan and the most certain plan."""
    from .. import report
    from ..io.plans import plan_document

    if plot_file is not None:
        check_figure_path(plot_file)
    pb = spec.build(part.load())
    result = spec.plan(pb)
    found = guaranteed_plan(pb) if guaranteed else None
    sure, missing = (None, found) if isinstance(found, str) else (found, None)
    if as_json:
        emit_json(plan_document(result, guaranteed=sure, guaranteed_missing=missing))
    else:
        typer.echo(report.plan_table(result))
        if sure is not None:
            typer.echo(report.guaranteed_text(sure))
        if missing is not None:
            typer.echo(f"Guaranteed plan: none ({missing})")
    if plot_file is not None:
        from ..figures.plots import plan_figure

        save_figure(plan_figure(result), plot_file)
        typer.echo(f"bayesgrasp: wrote {plot_file}", err=True)
    if missing is not None:  # no plan reached the goal asked for
        raise typer.Exit(1)
