"""``plan``: the best plan of every length, the Bayes plan, the most certain plan."""

from __future__ import annotations

import dataclasses
import enum
import functools
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from .common import emit_json, input_files
from .options import (
    AlsoOpt,
    ContactNoiseOpt,
    FoldOpt,
    ForceOpt,
    GoalPoseOpt,
    JawHeightOpt,
    JsonOpt,
    MaxMemoryOpt,
    MaxOpeningOpt,
    MinOpeningOpt,
    PartPriorOpt,
    PayoffOpt,
    PoseOpt,
    PosePriorOpt,
    SenseOpt,
    TimeLimitOpt,
    TurnNoiseOpt,
    command_app,
    part_options,
    problem_options,
    sense_spec,
)
from .specs import PartSpec, ProblemSpec, SenseSpec, run_inputs

if TYPE_CHECKING:
    from ..io.export import Stroke
    from .sensing import ActionModel

app = command_app()


def _given(ctx: typer.Context, *names: str) -> list[str]:
    """The options among ``names`` (parameter names) given on the command line, as typed."""
    flags = {p.name: p.opts[0] for p in ctx.command.params if p.opts}
    return [
        flags.get(n, n)
        for n in names
        if (source := ctx.get_parameter_source(n)) is not None and source.name != "DEFAULT"
    ]


#: Above this many stable orientations a plain ``plan PART`` reports only the Bayes and the
#: most certain plans: a table of every length would have thousands of rows nobody reads.
HUGE_STATES = 1000


class Only(enum.StrEnum):
    """Which plans ``plan`` reports."""

    all = "all"
    best = "best"


GuaranteedOpt = Annotated[
    bool,
    typer.Option(
        "--guaranteed",
        help="Also give the shortest plan that orients every initial orientation "
        "(up to the transfer functions' period). Under uniform turn noise of half-width A: "
        "a plan whose turns tolerate A; under contact noise, one that holds whichever jaw "
        "touches first; normal turn noise is refused (unbounded error).",
    ),
]
PlotOpt = Annotated[
    Path | None,
    typer.Option(
        "--plot",
        metavar="FILE",
        help="Also draw the part, its diameter function and the Bayes plan's distributions "
        "(under the noise, with noise options) into FILE (.png, .svg, .pdf); with --sense, the "
        "policy's tree as plot --sense draws it. Several parts: FILE must hold {name}, the "
        "part's name (and may hold {index}, its place in the run).",
    ),
]

ExportOpt = Annotated[
    Path | None,
    typer.Option(
        "--export",
        metavar="FILE",
        help="Also write the Bayes plan for a robot into FILE (.csv or .json): per step the "
        "action, the absolute gripper angle (deg and rad) and the jaw widths to expect (with "
        "noise options, the noise-aware plan and its noise model). With --sense: the policy as "
        "a state machine, a row per state and reading range [lo, hi) leading to the next "
        "state, a declaration or a rejection (units in the CSV's # lines and the JSON's "
        "units). Several parts: FILE must hold {name}, as --plot.",
    ),
]


WithinStrokeOpt = Annotated[
    bool,
    typer.Option(
        "--within-stroke",
        help="Plan only actions the stroke allows (--max-opening, --min-opening): the best "
        "plan of each length whose every step fits, instead of refusing a plan that does not "
        "(noise-free plans of one part; up to --max-actions, default 4).",
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
    Only | None,
    typer.Option(
        "--only",
        help="all: the best plan of every length; best: only the Bayes and the most certain "
        f"plans (default: all, or best for a part of more than {HUGE_STATES:,} stable "
        "orientations, saying so).",
    ),
]
BatchOpt = Annotated[
    Path | None,
    typer.Option(
        "--batch",
        metavar="FILE.jsonl",
        help='Plan one part a line ({"name": ..., "vertices": [...]} as a .json part file, or '
        "a catalogue name or path as a JSON string; '-' reads stdin); one JSON document a "
        "line, an error in its line. With --sense: each part's policy (with the --also "
        "parts as its candidates).",
    ),
]


@app.command()
@functools.partial(part_options, optional=True)
@problem_options()
def plan(
    ctx: typer.Context,
    part: PartSpec,
    spec: ProblemSpec,
    more_parts: MorePartsArg = None,
    guaranteed: GuaranteedOpt = False,
    as_json: JsonOpt = False,
    plot_file: PlotOpt = None,
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_memory: MaxMemoryOpt = None,
    time_limit: TimeLimitOpt = None,
    fold_below: FoldOpt = 0.01,
    turn_noise: TurnNoiseOpt = None,
    contact_noise: ContactNoiseOpt = None,
    payoff: PayoffOpt = None,
    force: ForceOpt = False,
    export: ExportOpt = None,
    only: OnlyOpt = None,
    batch: BatchOpt = None,
    max_opening: MaxOpeningOpt = None,
    min_opening: MinOpeningOpt = None,
    within_stroke: WithinStrokeOpt = False,
    pose: PoseOpt = None,
    goal_pose: GoalPoseOpt = None,
    pose_prior: PosePriorOpt = None,
    jaw_height: JawHeightOpt = None,
) -> None:
    """Best squeeze plan of every length, the Bayes plan and the most certain plan.

    With --sense: the policy of least expected cost that branches on the jaw widths read
    after each action (and tells the candidate parts apart), beside the sensorless Bayes plan;
    --max-actions is then the policy's depth (default 3). With --sense and --batch: each
    line's part gets its policy (the --also parts its other candidates), one document a line.

    With --turn-noise, --contact-noise or --payoff: the noise-aware Bayes plan, through
    every other option (--only, --guaranteed, --plot, --export, several parts, --batch).

    Several PARTs or --batch: each part planned in turn, one JSON document a line (as
    --json prints it); a part that fails gets {"part": ..., "error": ..., "exit_code": ...}
    on its line and the others go on; the exit code is the largest of the parts'. --plot
    and --export then write one file a part, named by a path with {name}.
    """
    from . import noisy
    from .meshes import check_pose_toppling, is_mesh_part, mesh_options, pose_sensing
    from .outputs import PartOutputs
    from .strategies import check_stroke, document, exit_code, text, write_outputs

    candidates = bool(more_parts or also or part_prior is not None)
    part = mesh_options(part, sense, pose, goal_pose, pose_prior, candidates, batch)
    if jaw_height is not None and (sense is None or not is_mesh_part(part)):
        check_pose_toppling(part, jaw_height)
    stroke = None
    if max_opening is not None or min_opening is not None:
        from ..io.export import Stroke

        stroke = Stroke(min_opening or 0.0, math.inf if max_opening is None else max_opening)
    if sense is None and (also or part_prior is not None):
        raise typer.BadParameter("--also and --part-prior need --sense")
    if sense is None and _given(ctx, "fold_below"):
        raise typer.BadParameter("--fold-below needs --sense")
    if sense is None and (max_memory, time_limit) != (None, None):
        raise typer.BadParameter(
            "--max-memory and --time-limit bound a policy search: they need --sense"
        )
    if within_stroke:
        _check_within_stroke(stroke, sense, spec, turn_noise, contact_noise, payoff)
    if sense is not None:
        refused = [
            name
            for name, on in (
                ("--guaranteed", guaranteed),
                ("--only best", only is Only.best),
                ("--method", spec.method.value != "exact"),
            )
            if on
        ]
        if refused:
            raise typer.BadParameter(f"--sense plans a policy; it takes no {', '.join(refused)}")
        more = (*(more_parts or []), *(also or []))  # more PARTs are candidates, as --also
        sensing = sense_spec(sense, more, part_prior, spec, max_memory, time_limit)
        if is_mesh_part(part):  # the candidates are the mesh's resting poses
            sensing, spec = pose_sensing(part, sensing, spec, goal_pose, pose_prior, jaw_height)
        fold = fold_below if _given(ctx, "fold_below") else None  # the figure's, when given
        from .sensing import plan_policy_command, sense_noise

        noise = sense_noise(turn_noise, contact_noise, payoff)
        if batch is not None:
            _policy_batch(part, batch, spec, sensing, plot_file, export, force, stroke, fold, noise)
            return
        if part.part is None:
            raise typer.BadParameter("give a PART (or --batch FILE.jsonl)")
        files = input_files(part.part, spec.prior, payoff, *more)
        outputs = PartOutputs.of(plot_file, export, force, files, several=False)
        plan_policy_command(part, spec, sensing, as_json, fold_below, outputs, stroke, fold, noise)
        return
    several = batch is not None or bool(more_parts)
    if part.part is None and not several:
        raise typer.BadParameter("give a PART (or --batch FILE.jsonl)")
    run = noisy.strategy_run(spec, turn_noise, contact_noise, payoff, only is Only.best, guaranteed)
    if within_stroke and stroke is not None:
        run = dataclasses.replace(run, stroke=(stroke.min_opening, stroke.max_opening))
    files = input_files(part.part, spec.prior, batch, payoff)
    outputs = PartOutputs.of(plot_file, export, force, files, several)
    if several:
        from .batch import BatchFileError, run_batch

        try:
            code = run_batch(part, more_parts or [], batch, run, outputs=outputs, stroke=stroke)
        except BatchFileError as exc:
            raise typer.BadParameter(str(exc), param_hint="--batch") from None
        if code:
            raise typer.Exit(code)
        return
    loaded = part.load()
    if outputs is not None:
        outputs.check(loaded.name, 1)
    problem = spec.build(loaded)
    if only is None and problem.n_states > HUGE_STATES and not run.best_only:
        typer.echo(
            f"bayesgrasp: note: {loaded.name} has {problem.n_states:,} stable orientations: "
            "only the Bayes and the most certain plans (--only all: the best of every length)",
            err=True,
        )
        run = dataclasses.replace(run, best_only=True)
    result = run.solve(problem)
    check_stroke(result, stroke)
    if as_json:
        emit_json(document(result, run_inputs(part, spec)))
    else:
        typer.echo(text(result, spec.max_actions))
    if outputs is not None:
        write_outputs(outputs, 1, result)
    code = exit_code(result)
    if code:  # no guaranteed plan reached the goal asked for
        raise typer.Exit(code)


def _check_within_stroke(
    stroke: Stroke | None,
    sense: str | None,
    spec: ProblemSpec,
    turn: str | None,
    contact: float | None,
    payoff: Path | None,
) -> None:
    """Refuse ``--within-stroke`` where it cannot plan (exit 2, one line)."""
    hint = "--within-stroke"
    if stroke is None:
        raise typer.BadParameter(
            "needs the stroke: --max-opening and/or --min-opening", param_hint=hint
        )
    if sense is not None:
        raise typer.BadParameter(
            "plans linear plans; a policy is checked against the stroke (drop --within-stroke)",
            param_hint=hint,
        )
    if turn is not None or contact is not None or payoff is not None:
        raise typer.BadParameter(
            "searches noise-free plans; a noise-aware plan is checked against the stroke "
            "(drop --within-stroke)",
            param_hint=hint,
        )
    if spec.method.value != "exact":
        raise typer.BadParameter("is its own planner; drop --method", param_hint=hint)
    if spec.accuracy_deg:
        raise typer.BadParameter("takes exact turns; drop --accuracy", param_hint=hint)


def _policy_batch(
    part: PartSpec,
    batch: Path,
    spec: ProblemSpec,
    sensing: SenseSpec,
    plot_file: Path | None,
    export: Path | None,
    force: bool,
    stroke: Stroke | None,
    fold: float | None,
    noise: ActionModel | None = None,
) -> None:
    """``plan --batch FILE.jsonl --sense S``: each line's part's policy, one document a line.

    PART beside the batch has no place: with --sense, more parts are candidates of one
    policy, and each line already names the part its policy is for.
    """
    from .batch import BatchFileError, run_policy_batch
    from .outputs import PartOutputs

    if part.part is not None:
        raise typer.BadParameter(
            "with --sense each line's part gets its policy (its other candidates: --also); "
            "give PART in the batch file, not beside it",
            param_hint="--batch",
        )
    files = input_files(None, spec.prior, batch, *sensing.also)
    if noise is not None and noise.payoff is not None:
        files = input_files(None, spec.prior, batch, noise.payoff, *sensing.also)
    outputs = PartOutputs.of(plot_file, export, force, files, several=True)
    try:
        code = run_policy_batch(
            part, batch, spec, sensing, outputs=outputs, stroke=stroke, fold=fold, noise=noise
        )
    except BatchFileError as exc:
        raise typer.BadParameter(str(exc), param_hint="--batch") from None
    if code:
        raise typer.Exit(code)
