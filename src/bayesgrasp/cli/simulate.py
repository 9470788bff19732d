"""``simulate``: execute a plan many times and compare with the prediction."""

from __future__ import annotations

import enum
import math
from typing import Annotated, Any

import typer

from .common import chosen_plan, emit_json, with_progress
from .options import JsonOpt, PlanChoiceOpt, command_app, part_options, problem_options
from .plan import AlsoOpt, MaxActionsOpt, PartPriorOpt, SenseOpt
from .specs import Engine, PartSpec, ProblemSpec

app = command_app()


class NoiseKind(enum.StrEnum):
    """Distribution of the gripper angle error."""

    normal = "normal"
    uniform = "uniform"


EngineOpt = Annotated[
    Engine, typer.Option(help="kinematic: the model's transfer functions; mujoco: physics.")
]
TrialsOpt = Annotated[
    int | None, typer.Option(min=1, help="Executions (default: 1,000,000 kinematic, 200 mujoco).")
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
SeedOpt = Annotated[int, typer.Option(help="Seed of the random generator.")]
UnitsOpt = Annotated[
    str | None,
    typer.Option(help="mujoco: units of the part's coordinates (default: the part's, or m)."),
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
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_actions: MaxActionsOpt = 3,
    sensor_error: SensorErrorOpt = False,
) -> None:
    """Execute a plan many times and compare the final orientations with the prediction.

    With --sense: plan the Bayes sensing policy, run it cycle after cycle (readings drawn
    from the sensor model, or MuJoCo's jaw separation with --engine mujoco: --sense width
    then means MuJoCo's default error, width:0.2,0.1 mm) and compare its success, cost a
    cycle, actions and cost per oriented part with the prediction.
    """
    from .. import report
    from ..sim.kinematic import GripperNoise, simulate_kinematic

    if engine is Engine.kinematic and offset > 0:
        raise typer.BadParameter(
            "applies to --engine mujoco only (the kinematic model has no positions)",
            param_hint="--offset",
        )
    err = GripperNoise(noise_kind.value, math.radians(noise))
    if sense is not None:
        from .sensing import simulate_policy_command

        simulate_policy_command(
            part, spec, sense, also or [], part_prior, max_actions, engine, trials, workers,
            offset, err, seed, units, sensor_error, as_json,
        )  # fmt: skip
        return
    if also or part_prior is not None or sensor_error:
        raise typer.BadParameter("--also, --part-prior and --sensor-error need --sense")
    p = part.load()
    pb, option, label = chosen_plan(which, spec, p)
    n = trials or (1_000_000 if engine is Engine.kinematic else 200)

    def run(progress: Any) -> Any:
        if engine is Engine.kinematic:
            return simulate_kinematic(pb, option, n, err, rng=seed, progress=progress)
        from ..sim import simulate_mujoco
        from ..sim.scene import units_scale

        scale = units_scale(units) if units is not None else None
        mm = offset / 1000.0  # millimetres to metres
        return simulate_mujoco(
            pb,
            option,
            n,
            offset=mm,
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
