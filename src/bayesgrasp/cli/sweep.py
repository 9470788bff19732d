"""``sweep``: plan (and check in simulation) every part of a catalogue on Dask."""

from __future__ import annotations

import dataclasses
import enum
from pathlib import Path
from typing import Annotated, Any

import typer

from .common import emit_json, flatten_value, with_progress
from .options import (
    FLATTEN_HELP,
    POLICY_DEPTH,
    SHAPE_HELP,
    JsonOpt,
    command_app,
    problem_options,
    sense_spec,
)
from .specs import Engine, ProblemSpec

app = command_app()


class ResultFormat(enum.StrEnum):
    """How the rows are stored."""

    parquet = "parquet"
    csv = "csv"


PathsArg = Annotated[
    list[str],
    typer.Argument(help="Part files, folders (searched recursively) and globs."),
]


@app.command()
@problem_options()
def sweep(
    paths: PathsArg,
    spec: ProblemSpec,
    out: Annotated[Path, typer.Option("--out", help="Results: a Parquet folder, or a CSV file.")],
    output_format: Annotated[
        ResultFormat | None,
        typer.Option(
            "--output-format",
            show_default=False,
            help="Format of RESULTS (default: csv for a .csv path, else parquet).",
        ),
    ] = None,
    old_format: Annotated[
        ResultFormat | None,
        typer.Option("--format", hidden=True, help="The old name of --output-format."),
    ] = None,
    simulate: Annotated[
        Engine | None, typer.Option(help="Also execute each Bayes plan (kinematic or MuJoCo).")
    ] = None,
    trials: Annotated[
        int | None, typer.Option(min=1, help="Executions a part (default 1,000,000 / 200).")
    ] = None,
    seed: Annotated[int, typer.Option(min=0, help="Seed of every part's simulation.")] = 0,
    workers: Annotated[
        int | None, typer.Option(min=1, help="Local Dask worker processes (default: cores).")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(metavar="ADDRESS", help="Run on this Dask scheduler instead.")
    ] = None,
    timeout: Annotated[
        float | None, typer.Option(min=0, help="Seconds a part may take (then an error row).")
    ] = None,
    resume: Annotated[bool, typer.Option(help="Skip parts already in RESULTS.")] = False,
    force: Annotated[bool, typer.Option(help="Replace an existing RESULTS.")] = False,
    report_file: Annotated[
        Path | None, typer.Option("--report", metavar="FILE.html", help="Also write a report.")
    ] = None,
    guaranteed: Annotated[
        bool | None,
        typer.Option(
            show_default=False,
            help="Also find each part's guaranteed plan (default: yes, without noise).",
        ),
    ] = None,
    sense: Annotated[
        str | None,
        typer.Option(
            "--sense",
            metavar="width[:SIGMA,RES]",
            help="Also plan each part's Bayes policy on jaw-width readings, as plan --sense "
            "(SIGMA and RES in each part's units): the policy_* columns.",
        ),
    ] = None,
    turn_noise: Annotated[
        str | None,
        typer.Option(
            "--turn-noise",
            metavar="normal:SIGMA_DEG|uniform:A_DEG",
            help="Plan each part for gripper turns executed as alpha + e, e ~ Normal(0, "
            "SIGMA^2) or uniform on [-A, A] degrees: the noise-aware Bayes plan, as plan "
            "--turn-noise.",
        ),
    ] = None,
    contact_noise: Annotated[
        float | None,
        typer.Option(
            "--contact-noise",
            metavar="Q",
            min=0.0,
            max=1.0,
            help="Plan each part for jaws that touch one after the other with probability Q, "
            "as plan --contact-noise.",
        ),
    ] = None,
    payoff: Annotated[
        Path | None,
        typer.Option(
            "--payoff",
            metavar="FILE",
            help="Payoff in [0, 1] of final stable orientations (.json or .csv), as plan "
            "--payoff: each part's plan minimises the expected cost per unit payoff.",
        ),
    ] = None,
    layer: Annotated[str | None, typer.Option(help="DXF: read only this layer.")] = None,
    flatten_tol: Annotated[
        float | None, typer.Option(callback=flatten_value, help=FLATTEN_HELP)
    ] = None,
    shape_tol: Annotated[float, typer.Option(min=0, help=SHAPE_HELP)] = 0.0,
    as_json: JsonOpt = False,
) -> None:
    """Plan every part of a catalogue on a Dask cluster: one row a part in RESULTS.

    PATH is a part file, a folder (searched recursively for every format the readers know)
    or a glob. The planning options apply to every part; a part that cannot be read or
    planned is a row with its error, never a stopped sweep. By default a local cluster of
    worker processes runs the sweep; --scheduler ADDRESS uses an existing cluster
    (`dask scheduler` / `dask worker`).

    With --turn-noise, --contact-noise or --payoff each row is the noise-aware Bayes plan
    (as plan PATH --turn-noise ...); --guaranteed adds the plan guaranteed under a uniform
    turn error (normal noise has no bound to guarantee under), --sense the policy under the
    noisy actions (as plan PATH --sense S --turn-noise ...), and --simulate executes the
    noise-aware plan under the noise (as simulate PATH --turn-noise ...; MuJoCo takes no
    --contact-noise, its contacts are the physics' own).
    --resume continues a RESULTS planned with the same options only.
    """
    from ..sweep import SweepInterrupted, SweepOptions, run_sweep, write_report
    from .common import check_outputs, input_files

    if output_format is not None and old_format is not None and output_format != old_format:
        raise typer.BadParameter("give --output-format only", param_hint="--format")
    fmt = output_format or old_format
    if fmt is None:  # a .csv path is a CSV file (unless a Parquet folder of that name exists)
        csv = out.suffix.lower() == ".csv" and not out.is_dir()
        fmt = ResultFormat.csv if csv else ResultFormat.parquet
    noisy = not (turn_noise is None and contact_noise is None and payoff is None)
    if noisy and spec.method.value != "exact":
        raise typer.BadParameter(
            "the noise-aware planner seeds from the exact planner; drop --method",
            param_hint="--method",
        )
    if contact_noise is not None and simulate is Engine.mujoco:
        raise typer.BadParameter(
            "applies to the kinematic engine only: in MuJoCo the jaws' contacts are the "
            "physics' own",
            param_hint="--contact-noise",
        )
    if turn_noise is not None:
        from .noisy import turn_noise as parse_turn

        turn = parse_turn(turn_noise)  # a malformed spec: one line, exit 2
        if guaranteed and not turn.exact and turn.kind == "normal":
            from ..planning.robust import UNBOUNDED_GUARANTEE

            raise typer.BadParameter(UNBOUNDED_GUARANTEE, param_hint="--guaranteed")
    _check_paths(paths, [("--out", out), ("--report", report_file)])
    extra = () if payoff is None else (str(payoff),)
    inputs = input_files(None, spec.prior, *paths, *extra)  # RESULTS: its own --resume/--force
    check_outputs([out], inputs, force=True, hint="--out", folders=True)
    if report_file is not None:
        check_outputs([report_file], [*inputs, out], force, "--report")

    depth = POLICY_DEPTH if sense is None else sense_spec(sense, (), None, spec).max_actions
    options = SweepOptions(
        prior=spec.prior,
        squeeze_cost=(spec.costs or {}).get("squeeze", 1.0),
        push_grasp_cost=(spec.costs or {}).get("push-grasp", 1.0),
        verify_cost=spec.verify,
        first_squeeze_cost=(spec.first or {}).get("squeeze"),
        first_push_grasp_cost=(spec.first or {}).get("push-grasp"),
        retry_cost=spec.retry,
        goal=spec.goal.value,
        actions=spec.actions,
        accuracy_deg=spec.accuracy_deg,
        method=spec.method.value,
        max_actions=spec.max_actions,
        guaranteed=not noisy if guaranteed is None else guaranteed,
        simulate=simulate.value if simulate else None,
        trials=trials,
        seed=seed,
        layer=layer,
        flatten_tol=flatten_tol,
        shape_tol=shape_tol,
        sense=sense,
        sense_max_actions=depth,
        turn_noise=turn_noise,
        contact_noise=contact_noise,
        payoff=None if payoff is None else str(payoff),
    )

    def work(progress: Any) -> Any:
        tick = None if progress is None else (lambda p: progress(p.done, p.total))
        return run_sweep(
            paths,
            out,
            options,
            workers=workers,
            scheduler=scheduler,
            fmt=fmt.value,
            resume=resume,
            force=force,
            timeout=timeout,
            progress=tick,
        )

    try:
        summary = with_progress("sweep", 0, work)
    except SweepInterrupted as stop:
        typer.echo(
            f"bayesgrasp: stopped after {stop.summary.written} rows; run again with --resume",
            err=True,
        )
        raise typer.Exit(130) from None
    if report_file is not None:
        write_report(out, report_file)
    doc = {"schema": "bayesgrasp.sweep/1", **dataclasses.asdict(summary), "out": str(out)}
    if as_json:
        emit_json(doc)
    else:
        typer.echo(
            f"{summary.found} parts found, {summary.skipped} already done, {summary.written} "
            f"rows written to {out} ({summary.ok} planned, {summary.no_plan} without a "
            f"guaranteed plan, {summary.errors} errors of which {summary.timeouts} timeouts) "
            f"by {summary.workers} workers in {summary.seconds:.1f} s"
        )


def _check_paths(paths: list[str], outputs: list[tuple[str, Path | None]]) -> None:
    """PATHs that exist (or are globs), and no output where the sweep reads its parts.

    An output inside a folder being swept would be read as a part by the next sweep of that
    folder (results, their ``.meta.json``), and one named like a part file would replace it.
    """
    import glob

    for p in paths:
        if not glob.has_magic(p) and not Path(p).exists():
            raise typer.BadParameter(f"{p}: no such file or folder", param_hint="PATH")
    for hint, target in outputs:
        if target is None:
            continue
        t = target.resolve()
        for p in paths:
            for q in map(Path, glob.glob(p, recursive=True) if glob.has_magic(p) else [p]):
                q = q.resolve()
                if q == t:
                    why = f"is an input of this sweep ({p})"
                elif q.is_dir() and q in t.parents:
                    why = f"is inside {p}, an input folder (the next sweep would read it)"
                else:
                    continue
                raise typer.BadParameter(
                    f"{str(target)!r} {why}: write it elsewhere", param_hint=hint
                )
