"""``plan``: the best plan of every length, the Bayes plan, the most certain plan."""

from __future__ import annotations

import enum
import functools
from pathlib import Path
from typing import Annotated

import typer

from .common import (
    check_export,
    check_figure_path,
    check_outputs,
    emit_json,
    input_files,
    save_figure,
)
from .options import (
    AlsoOpt,
    ContactNoiseOpt,
    FoldOpt,
    ForceOpt,
    JsonOpt,
    MaxActionsOpt,
    PartPriorOpt,
    PayoffOpt,
    SenseOpt,
    TurnNoiseOpt,
    command_app,
    part_options,
    problem_options,
)
from .specs import PartSpec, ProblemSpec, SenseSpec, guaranteed_plan, run_inputs

app = command_app()


class Only(enum.StrEnum):
    """Which plans ``plan`` reports."""

    all = "all"
    best = "best"


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

ExportOpt = Annotated[
    Path | None,
    typer.Option(
        "--export",
        metavar="FILE",
        help="Also write the Bayes plan for a robot into FILE (.csv or .json): per step the "
        "action, the absolute gripper angle (deg and rad) and the jaw widths to expect.",
    ),
]


MorePartsArg = Annotated[
    list[str] | None,
    typer.Argument(
        metavar="[PART]...",
        show_default=False,
        help="More parts: each is planned on its own, one JSON document a line (with --sense: "
        "candidate parts, as --also).",
    ),
]
OnlyOpt = Annotated[
    Only,
    typer.Option(
        "--only",
        help="all: the best plan of every length; best: only the Bayes and the most certain "
        "plans (for parts of thousands of states).",
    ),
]
BatchOpt = Annotated[
    Path | None,
    typer.Option(
        "--batch",
        metavar="FILE.jsonl",
        help='Plan one part a line ({"name": ..., "vertices": [...]} as a .json part file, or '
        "a catalogue name or path as a JSON string; '-' reads stdin); one JSON document a "
        "line, an error in its line.",
    ),
]


@app.command()
@functools.partial(part_options, optional=True)
@problem_options()
def plan(
    part: PartSpec,
    spec: ProblemSpec,
    more_parts: MorePartsArg = None,
    guaranteed: GuaranteedOpt = False,
    as_json: JsonOpt = False,
    plot_file: PlotOpt = None,
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_actions: MaxActionsOpt = 3,
    fold_below: FoldOpt = 0.01,
    turn_noise: TurnNoiseOpt = None,
    contact_noise: ContactNoiseOpt = None,
    payoff: PayoffOpt = None,
    force: ForceOpt = False,
    export: ExportOpt = None,
    only: OnlyOpt = Only.all,
    batch: BatchOpt = None,
) -> None:
    """Best squeeze plan of every length, the Bayes plan and the most certain plan.

    With --sense: the policy of least expected cost that branches on the jaw widths read
    after each action (and tells the candidate parts apart), beside the sensorless Bayes plan.

    Several PARTs or --batch: each part planned in turn, one JSON document a line (as
    --json prints it); a part that fails gets {"part": ..., "error": ..., "exit_code": ...}
    on its line and the others go on; the exit code is the largest of the parts'.
    """
    from .. import report
    from ..io.plans import plan_document
    from . import noisy

    if noisy.asked(turn_noise, contact_noise, payoff):
        if guaranteed or plot_file is not None or export is not None:
            raise typer.BadParameter("--guaranteed, --plot and --export do not take noise yet")
    if noisy.asked(turn_noise, contact_noise, payoff) and sense is None:
        if part.part is None or batch is not None or more_parts:
            raise typer.BadParameter("noise options take one PART (no --batch)")
        noisy.plan_noisy_command(part.load(), spec, turn_noise, contact_noise, payoff, as_json)
        return
    if sense is not None:
        if part.part is None or batch is not None:
            raise typer.BadParameter("--sense needs PART and takes no --batch")
        from .sensing import plan_policy_command, sense_noise

        more = (*(more_parts or []), *(also or []))  # more PARTs are candidates, as --also
        sensing = SenseSpec(sense, more, part_prior, max_actions)
        noise = sense_noise(turn_noise, contact_noise, payoff)
        plan_policy_command(part, spec, sensing, as_json, fold_below, noise)
        return
    if also or part_prior is not None:
        raise typer.BadParameter("--also and --part-prior need --sense")
    if batch is not None or more_parts:
        if plot_file is not None:
            raise typer.BadParameter("--plot takes one PART", param_hint="--plot")
        from .batch import BatchFileError, run_batch

        try:
            code = run_batch(part, more_parts or [], batch, spec, guaranteed, only is Only.best)
        except BatchFileError as exc:
            raise typer.BadParameter(str(exc), param_hint="--batch") from None
        if code:
            raise typer.Exit(code)
        return
    if part.part is None:
        raise typer.BadParameter("give a PART (or --batch FILE.jsonl)")
    if plot_file is not None:
        check_figure_path(plot_file)
        check_outputs([plot_file], input_files(part.part, spec.prior), force, "--plot")
    if export is not None:
        check_export(export, input_files(part.part, spec.prior), force)
    pb = spec.build(part.load())
    result = spec.plan(pb, best_only=only is Only.best)
    found = guaranteed_plan(pb) if guaranteed else None
    sure, missing = (None, found) if isinstance(found, str) else (found, None)
    if as_json:
        inputs = run_inputs(part, spec)
        emit_json(plan_document(result, guaranteed=sure, guaranteed_missing=missing, inputs=inputs))
    else:
        typer.echo(report.plan_table(result, spec.max_actions))
        if sure is not None:
            typer.echo(report.guaranteed_text(sure))
        if missing is not None:
            typer.echo(f"Guaranteed plan: none ({missing})")
    if plot_file is not None:
        from ..figures.plots import plan_figure

        save_figure(plan_figure(result), plot_file)
        typer.echo(f"bayesgrasp: wrote {plot_file}", err=True)
    if export is not None:
        from ..io.export import write_robot

        write_robot(export, pb, result.bayes_plan)
        typer.echo(f"bayesgrasp: wrote {export}", err=True)
    if missing is not None:  # no plan reached the goal asked for
        raise typer.Exit(1)
