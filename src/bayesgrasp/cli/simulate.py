"""``simulate``: execute a plan many times and compare with the prediction."""

from __future__ import annotations

import enum
import math
from typing import Annotated, Any

import typer

from .common import chosen_plan, emit_json, simulate_inputs, with_progress
from .options import (
    AlsoOpt,
    JsonOpt,
    MaxActionsOpt,
    PartPriorOpt,
    PlanChoiceOpt,
    SenseOpt,
    TurnNoiseOpt,
    command_app,
    part_options,
    problem_options,
)
from .specs import Engine, PartSpec, ProblemSpec, SenseSpec, run_inputs

app = command_app()

MAX_TRIALS = 10**9
"""The most trials a run takes: a billion kinematic trials put the 95% interval of the
success rate within +-3.1e-5 and take about half an hour (5e5 trials/s measured on a loaded
2-core machine); more narrow nothing a plan's numbers need and would run for hours."""
BLOCK = 1 << 20
"""Kinematic trials kept in memory at once (about 40 MB); a multiple of the simulator's
batch, so a run in blocks draws exactly what one call would."""


class NoiseKind(enum.StrEnum):
    """Distribution of the gripper angle error."""

    normal = "normal"
    uniform = "uniform"


EngineOpt = Annotated[
    Engine, typer.Option(help="kinematic: the model's transfer functions; mujoco: physics.")
]
TrialsOpt = Annotated[
    int | None,
    typer.Option(
        min=1,
        help="Executions (default: 1,000,000 kinematic, 200 mujoco; at most 1e9, run in "
        "blocks of 2^20 so memory stays bounded).",
    ),
]
WorkersOpt = Annotated[
    int, typer.Option(min=1, help="Processes for mujoco trials (kinematic uses one).")
]
OffsetOpt = Annotated[
    float,
    typer.Option(
        min=0,
        metavar="MM",
        help="mujoco: the part's centre is MM millimetres off the gripper centre along the "
        "squeeze axis (random side each action).",
    ),
]
NoiseOpt = Annotated[
    float, typer.Option(min=0, metavar="DEG", help="Gripper angle error: sigma or bound, degrees.")
]
NoiseKindOpt = Annotated[NoiseKind, typer.Option(help="Gripper error distribution.")]
SeedOpt = Annotated[int, typer.Option(min=0, help="Seed of the random generator (>= 0).")]
ForceOpt = Annotated[bool, typer.Option("--force", help="Run a --plan FILE made for another part.")]
UnitsOpt = Annotated[
    str | None,
    typer.Option(help="mujoco: units of the part's coordinates (default: the part's, or m)."),
]
JawLagOpt = Annotated[
    float,
    typer.Option(
        min=0,
        metavar="SECONDS",
        help="mujoco: contact asynchrony: in each squeeze one jaw (either, equally likely) "
        "starts closing SECONDS before the other and pushes the part jaw_speed * SECONDS / 2 "
        "(5 mm per second at the default 10 mm/s) before the other touches; the clearance is "
        "raised to that push + 1 mm, as in the README's calibration of --contact-noise.",
    ),
]
SensorErrorOpt = Annotated[
    bool,
    typer.Option(
        "--sensor-error",
        help="With --sense and --engine mujoco: add the sensor model's normal error to the "
        "jaw separation MuJoCo reads (default: the physics' own error only).",
    ),
]


@app.command()
@part_options
@problem_options(push_grasp_alias=True)
def simulate(
    part: PartSpec,
    spec: ProblemSpec,
    which: PlanChoiceOpt = "bayes",
    engine: EngineOpt = Engine.kinematic,
    trials: TrialsOpt = None,
    workers: WorkersOpt = 1,
    offset: OffsetOpt = 0.0,
    noise: NoiseOpt = 0.0,
    noise_kind: NoiseKindOpt = NoiseKind.normal,
    seed: SeedOpt = 0,
    units: UnitsOpt = None,
    as_json: JsonOpt = False,
    turn_noise: TurnNoiseOpt = None,
    force: ForceOpt = False,
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_actions: MaxActionsOpt = 3,
    sensor_error: SensorErrorOpt = False,
    jaw_lag: JawLagOpt = 0.0,
) -> None:
    """Execute a plan many times and compare the final orientations with the prediction.

    With --plan FILE the plan must be for PART (else exit 2, unless --force) and runs under
    the prior and goal it was made for, unless --prior or --goal says otherwise.

    With --sense: plan the Bayes sensing policy, run it cycle after cycle (readings drawn
    from the sensor model, or MuJoCo's jaw separation with --engine mujoco: --sense width
    then means MuJoCo's default error, width:0.2,0.1 mm) and compare its success, cost a
    cycle, actions and cost per oriented part with the prediction.
    """
    from .. import report
    from ..io.plans import provenance
    from ..sim.kinematic import GripperNoise
    from ..sim.scene import units_scale

    if engine is Engine.kinematic and offset > 0:
        raise typer.BadParameter(
            "applies to --engine mujoco only (the kinematic model has no positions)",
            param_hint="--offset",
        )
    if noise >= 90:
        raise typer.BadParameter(
            f"a gripper error of {noise:g} deg is no gripper (squeezes repeat every 180 deg "
            "at most: an error of 90 deg or more hides every orientation); give less than 90",
            param_hint="--noise",
        )
    if trials is not None and trials > MAX_TRIALS:
        raise typer.BadParameter(
            f"at most {MAX_TRIALS:,} trials; got {trials:,} (a billion put the 95% interval "
            "within +-3.1e-5 and take about half an hour; more would run for hours)",
            param_hint="--trials",
        )
    if jaw_lag and engine is Engine.kinematic:
        raise typer.BadParameter(
            "applies to --engine mujoco only (the kinematic model's contact asynchrony is "
            "plan --contact-noise Q)",
            param_hint="--jaw-lag",
        )
    err = GripperNoise(noise_kind.value, math.radians(noise))
    if sense is not None:
        if jaw_lag:
            raise typer.BadParameter("does not apply to --sense yet", param_hint="--jaw-lag")
        from .sensing import simulate_policy_command

        if turn_noise is not None and noise > 0:
            raise typer.BadParameter("give --noise or --turn-noise, not both", param_hint="--noise")
        sensing = SenseSpec(sense, tuple(also or ()), part_prior, max_actions)
        simulate_policy_command(
            part, spec, sensing, engine, trials, workers, offset, err, seed, units,
            sensor_error, as_json, turn_noise,
        )  # fmt: skip
        return
    if also or part_prior is not None or sensor_error:
        raise typer.BadParameter("--also, --part-prior and --sensor-error need --sense")
    p = part.load()
    given = units is not None
    scale = units_scale(units if given else p.units) if offset > 0 or given else 1.0
    if offset > 0 and offset / 1000.0 >= p.hull.size * scale:
        size_mm = p.hull.size * scale * 1000.0
        raise typer.BadParameter(
            f"{offset:g} mm is not less than the part's size ({size_mm:.4g} mm from its "
            "centroid to its farthest vertex): the jaws would close beside it",
            param_hint="--offset",
        )
    params = _lagged(jaw_lag, p, units) if jaw_lag else None
    pb, option, label = chosen_plan(which, spec, p, force)
    n = trials or (1_000_000 if engine is Engine.kinematic else 200)
    if turn_noise is not None:  # the spelling of plan --turn-noise
        from .noisy import turn_noise as parse

        if noise > 0:
            raise typer.BadParameter("give --noise or --turn-noise, not both", param_hint="--noise")
        t = parse(turn_noise)
        err = GripperNoise(t.kind, t.scale)

    def run(progress: Any) -> Any:
        if engine is Engine.kinematic:
            return _kinematic_blocks(pb, option, n, err, seed, progress)
        from ..sim import simulate_mujoco

        mm = offset / 1000.0  # millimetres to metres
        return simulate_mujoco(
            pb,
            option,
            n,
            offset=mm,
            noise=err,
            rng=seed,
            workers=workers,
            scale=scale if units is not None else None,
            progress=progress,
            params=params,
        )

    res = with_progress(f"{engine.value} trials", n, run)
    if turn_noise is not None:  # predicted exactly under the noise (--noise: without it)
        import dataclasses

        from ..model.noise import NoiseModel
        from ..planning.noisy import evaluate_plan

        ev = evaluate_plan(pb, NoiseModel(t), option.steps)
        res = dataclasses.replace(res, predicted=ev.distribution)
    if as_json:
        doc = report.simulate_json(res, p)
        mujoco = engine is Engine.mujoco
        how = simulate_inputs(
            engine.value, which, seed, n, noise, noise_kind.value, offset, units,
            workers if mujoco else None,
        )  # fmt: skip
        how["jaw_lag_s"] = jaw_lag or None
        doc["provenance"] = provenance(pb, None, **how, **run_inputs(part, spec))
        emit_json(doc)
    else:
        title = f"{p.name}: {label} plan, prior {pb.prior.name}; "
        if turn_noise is not None:
            title += f"predicted under turn error {t.spec()} deg; "
        if jaw_lag:
            title += f"jaw lag {jaw_lag:g} s; "
        typer.echo(report.simulate_table(res, title))


def _lagged(lag: float, part: Any, units: str | None) -> Any:
    """The MuJoCo settings of ``--jaw-lag``: the lag, and room for the push it makes.

    The leading jaw pushes ``jaw_speed * lag / 2`` before the other touches; the clearance is
    raised to that push + 1 mm (as :func:`~bayesgrasp.sim.asynchrony.measure_asynchrony`
    does) so the push does not saturate. A push of more than twice the part's size (the
    travel of a push-grasp, ``SimParams.push_distance``) is refused: it adds nothing but time.
    """
    from dataclasses import replace

    from ..sim.params import SimParams
    from ..sim.scene import units_scale

    base = SimParams()
    push = base.jaw_speed * lag / 2.0
    size = part.hull.size * units_scale(units if units is not None else part.units)
    if push > 2.0 * size:
        most = 4.0 * size / base.jaw_speed
        raise typer.BadParameter(
            f"a lag of {lag:g} s pushes the part {push * 1000:.4g} mm, more than twice its "
            f"size ({size * 1000:.4g} mm from its centroid to its farthest vertex): give at "
            f"most {most:.4g} s",
            param_hint="--jaw-lag",
        )
    return replace(base, jaw_lag=lag, clearance=max(base.clearance, push + 0.001))


def _kinematic_blocks(pb: Any, option: Any, n: int, err: Any, seed: int, progress: Any) -> Any:
    """The kinematic trials in blocks of :data:`BLOCK`, counts added (memory of one block).

    One generator runs through the blocks, so the draws are those of one call.
    """
    import numpy as np

    from ..sim.kinematic import simulate_kinematic
    from ..sim.result import combine

    rng = np.random.default_rng(seed)
    results: list[Any] = []
    done = 0
    while done < n:
        m = min(BLOCK, n - done)
        tick = None if progress is None else (lambda k, _t, d=done: progress(d + k, n))
        results = [*results, simulate_kinematic(pb, option, m, err, rng=rng, progress=tick)]
        results = [combine(results)] if len(results) > 1 else results
        done += m
    return results[0]
