"""``plan``: the best plan of every length, the Bayes plan, the most certain plan."""

from __future__ import annotations

import enum
import functools
import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

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
from .specs import PartSpec, ProblemSpec, SenseSpec

if TYPE_CHECKING:
    from ..geometry.polygon import Part

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
        if sense is not None or guaranteed or plot_file is not None or export is not None:
            raise typer.BadParameter(
                "--sense, --guaranteed, --plot and --export do not take noise yet"
            )
        if part.part is None or batch is not None or more_parts:
            raise typer.BadParameter("noise options take one PART (no --batch)")
        noisy.plan_noisy_command(part.load(), spec, turn_noise, contact_noise, payoff, as_json)
        return
    if sense is not None:
        if part.part is None or batch is not None:
            raise typer.BadParameter("--sense needs PART and takes no --batch")
        from .sensing import plan_policy_command

        more = (*(more_parts or []), *(also or []))  # more PARTs are candidates, as --also
        sensing = SenseSpec(sense, more, part_prior, max_actions)
        plan_policy_command(part, spec, sensing, as_json, fold_below)
        return
    if also or part_prior is not None:
        raise typer.BadParameter("--also and --part-prior need --sense")
    if batch is not None or more_parts:
        if plot_file is not None:
            raise typer.BadParameter("--plot takes one PART", param_hint="--plot")
        _many(part, more_parts or [], batch, spec, guaranteed, only is Only.best)
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


def _many(
    part: PartSpec,
    more: list[str],
    batch: Path | None,
    spec: ProblemSpec,
    guaranteed: bool,
    best_only: bool,
) -> None:
    """Plan each part in turn, one JSON document a line; errors stay in their line.

    Each line is what ``plan PART --json`` prints for the part, as ``json.dumps`` writes it
    on one line. Everything made once per batch is made before the loop: the problem's
    inputs, the planner, the encoder.
    """
    from ..errors import BayesGraspError
    from ..io.plans import plan_document

    code = 0
    inputs = run_inputs(part, spec)
    # json.dumps(doc, allow_nan=False); documents are trees, so no test for cycles
    encode = json.JSONEncoder(allow_nan=False, check_circular=False).encode
    out = sys.stdout
    build, plan = _builder(spec), spec.planner(best_only)
    memo: dict[str, Any] = {}  # what the documents share (the provenance)
    texts: dict[str, Any] = {}  # and its text
    for label, load in _batch_parts(part, more, batch):
        try:
            pb = build(load())
            result = plan(pb)
            found = guaranteed_plan(pb) if guaranteed else None
        except BayesGraspError as exc:
            doc: dict[str, Any] = {"part": label, "error": str(exc), "exit_code": 2}
            code = 2
        else:
            sure, missing = (None, found) if isinstance(found, str) else (found, None)
            doc = plan_document(
                result, guaranteed=sure, guaranteed_missing=missing, inputs=inputs, memo=memo
            )
            if missing is not None:
                code = max(code, 1)
        out.write(_line(doc, encode, texts) + "\n")  # a line at a time, as typer.echo
        out.flush()
    if code:
        raise typer.Exit(code)


def _line(doc: dict[str, Any], encode: Any, texts: dict[str, Any]) -> str:
    """``encode(doc)``, the provenance shared with the previous line encoded once.

    The encoder writes an object as ``{"key": value, ...}`` (``", "`` and ``": "``), and the
    provenance is a plan document's last member, so its text can be appended. (``doc`` loses
    its provenance: it is written and dropped.)
    """
    if len(doc) < 2 or next(reversed(doc)) != "provenance":
        return str(encode(doc))
    shared = doc.pop("provenance")
    if texts.get("of") is not shared:
        texts["of"], texts["text"] = shared, encode(shared)
    return f'{encode(doc)[:-1]}, "provenance": {texts["text"]}}}'


def _builder(spec: ProblemSpec) -> Any:
    """``spec.build`` for many parts: the prior, costs and goal made once (all immutable).

    When making them fails, every part is built (and fails) the usual way, in its own line.
    """
    from ..model.problem import Problem

    try:
        made = spec.problem_inputs()
    except Exception:  # any failure: each part meets it as spec.build would
        return spec.build
    return functools.partial(Problem.build, **made)


def _batch_parts(part: PartSpec, more: list[str], batch: Path | None) -> Iterator[tuple[str, Any]]:
    """(label, loader) of each part: PART, the more PARTs, then each line of ``batch``.

    A loader returns the :class:`Part` or raises a BayesGraspError with its one-line reason.
    """
    import dataclasses

    from ..errors import PartFileError
    from ..io import read_part_bytes
    from ..io.points import json_line_part

    names = ([part.part] if part.part is not None else []) + more
    for name in names:
        yield name, dataclasses.replace(part, part=name).load
    if batch is None:
        return
    stream = sys.stdin if str(batch) == "-" else None
    try:
        handle = stream or batch.open(encoding="utf-8")
    except OSError as exc:
        raise typer.BadParameter(
            f"cannot read {batch}: {exc.strerror or exc}", param_hint="--batch"
        ) from None
    with handle:
        for number, line in enumerate(handle, start=1):
            text = line.strip()
            if not text:
                continue
            label = f"{batch}:{number}"

            def load(text: str = text, label: str = label) -> Part:
                found = json_line_part(text, label)  # a part object, parsed once
                if found is not None:
                    return found
                try:
                    value = json.loads(text)
                except ValueError as exc:
                    raise PartFileError(f"{label}: not a JSON value: {exc}") from None
                if isinstance(value, str):
                    return dataclasses.replace(part, part=value).load()
                if isinstance(value, dict):  # a .json part file on one line
                    return read_part_bytes(text.encode(), "json", label)
                raise PartFileError(
                    f"{label}: expected a part object or a part name; got {type(value).__name__}"
                )

            yield label, load
