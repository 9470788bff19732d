"""``plan``: the best plan of every length, the Bayes plan, the most certain plan."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import (
    check_export,
    check_figure_path,
    check_outputs,
    emit_json,
    guaranteed_plan,
    input_files,
    run_inputs,
    save_figure,
)
from .options import (
    ContactNoiseOpt,
    ForceOpt,
    JsonOpt,
    PayoffOpt,
    TurnNoiseOpt,
    command_app,
    part_options,
    problem_options,
)
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
MaxActionsOpt = Annotated[
    int, typer.Option("--max-actions", min=1, max=8, help="With --sense: deepest policy.")
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


@app.command()
@part_options
@problem_options()
def plan(
    part: PartSpec,
    spec: ProblemSpec,
    guaranteed: GuaranteedOpt = False,
    as_json: JsonOpt = False,
    plot_file: PlotOpt = None,
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_actions: MaxActionsOpt = 3,
    turn_noise: TurnNoiseOpt = None,
    contact_noise: ContactNoiseOpt = None,
    payoff: PayoffOpt = None,
    force: ForceOpt = False,
    export: ExportOpt = None,
) -> None:
    """Best squeeze plan of every length, the Bayes plan and the most certain plan.

    With --sense: the policy of least expected cost that branches on the jaw widths read
    after each action (and tells the candidate parts apart), beside the sensorless Bayes plan.
    """
    from .. import report
    from ..io.plans import plan_document
    from . import noisy

    if noisy.asked(turn_noise, contact_noise, payoff):
        if sense is not None or guaranteed or plot_file is not None or export is not None:
            raise typer.BadParameter(
                "--sense, --guaranteed, --plot and --export do not take noise yet"
            )
        noisy.plan_noisy_command(part.load(), spec, turn_noise, contact_noise, payoff, as_json)
        return
    if sense is not None:
        _policy(part, spec, sense, also or [], part_prior, max_actions, as_json)
        return
    if also or part_prior is not None:
        raise typer.BadParameter("--also and --part-prior need --sense")
    if plot_file is not None:
        check_figure_path(plot_file)
        check_outputs([plot_file], input_files(part.part, spec.prior), force, "--plot")
    if export is not None:
        check_export(export, input_files(part.part, spec.prior), force)
    pb = spec.build(part.load())
    result = spec.plan(pb)
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


def _policy(
    part: PartSpec,
    spec: ProblemSpec,
    sense: str,
    also: list[str],
    part_prior: str | None,
    max_actions: int,
    as_json: bool,
) -> None:
    """Plan and print a sensing policy over PART and the --also parts."""
    import dataclasses

    from ..io.policies import policy_document
    from ..planning.policy import plan_policy, policy_text

    parts = [part.load(), *(dataclasses.replace(part, part=p).load() for p in also)]
    problems = [spec.build(p) for p in parts]
    pol = plan_policy(problems, sensor=sense, max_actions=max_actions, part_prior=part_prior)
    if as_json:
        emit_json(policy_document(pol))
    else:
        typer.echo(policy_text(pol, units=parts[0].units))
        entropy = ", ".join(f"{h:.3f}" for h in pol.expected_entropy)
        blind = pol.sensorless_cost
        versus = "" if blind is None else f" (sensorless Bayes plan {blind:.4f})"
        typer.echo(
            f"expected cost {pol.expected_cost:.4f}{versus}, "
            f"success {pol.success_probability:.4f} a cycle, "
            f"{pol.expected_actions:.3f} actions a cycle; expected entropy after each level "
            f"(bits): {entropy}"
        )
