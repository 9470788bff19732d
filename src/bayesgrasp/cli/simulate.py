"""``simulate``: execute a plan many times and compare with the prediction.

The noise is the model's vocabulary, as ``plan`` takes it: ``--turn-noise`` (every gripper
angle off by a normal or uniform error) and ``--contact-noise Q`` (one jaw touches first);
``--noise DEG --noise-kind KIND`` is the older spelling of ``--turn-noise KIND:DEG``. Under
noise (or with ``--payoff``) the plans ``--plan bayes`` and ``--plan most-certain`` are the
noise-aware planner's (:func:`~bayesgrasp.planning.noisy.plan_noisy`, the ones ``plan``
gives with the same options), and every plan is predicted exactly under the noise
(:func:`~bayesgrasp.planning.noisy.evaluate_plan`).
"""

from __future__ import annotations

import enum
import math
from pathlib import Path
from typing import Annotated, Any

import typer

from .common import chosen_plan, emit_json, simulate_inputs, with_progress
from .engines import lagged_params
from .options import (
    AlsoOpt,
    ContactNoiseOpt,
    GoalPoseOpt,
    JawHeightOpt,
    JsonOpt,
    MaxMemoryOpt,
    PartPriorOpt,
    PayoffOpt,
    PlanChoiceOpt,
    PosePriorOpt,
    SenseOpt,
    TimeLimitOpt,
    TurnNoiseOpt,
    command_app,
    part_options,
    problem_options,
    sense_spec,
)
from .specs import Engine, PartSpec, ProblemSpec, run_inputs

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
        help="Executions (default: 1,000,000 kinematic, 200 mujoco; with --sense, cycles: "
        "200,000 kinematic, 200 mujoco; at most 1e9, run in blocks of 2^20 so memory stays "
        "bounded).",
    ),
]
WorkersOpt = Annotated[
    int,
    typer.Option(min=1, help="Threads for mujoco trials (kinematic uses one)."),
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
    float,
    typer.Option(
        min=0,
        metavar="DEG",
        hidden=True,
        help="Same as --turn-noise KIND:DEG, KIND from --noise-kind (sigma or bound, degrees).",
    ),
]
NoiseKindOpt = Annotated[
    NoiseKind, typer.Option(hidden=True, help="The distribution of --noise DEG.")
]
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
        "raised to that push + 1 mm (the documentation's calibration of --contact-noise).",
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
    contact_noise: ContactNoiseOpt = None,
    payoff: PayoffOpt = None,
    force: ForceOpt = False,
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_memory: MaxMemoryOpt = None,
    time_limit: TimeLimitOpt = None,
    goal_pose: GoalPoseOpt = None,
    pose_prior: PosePriorOpt = None,
    jaw_height: JawHeightOpt = None,
    sensor_error: SensorErrorOpt = False,
    jaw_lag: JawLagOpt = 0.0,
) -> None:
    """Execute a plan many times and compare the final orientations with the prediction.

    With --turn-noise, --contact-noise or --payoff the Bayes (or most certain) plan is the
    noise-aware one that plan gives with the same options; every plan is predicted exactly
    under the noise, and with --payoff judged by its expected payoff (the mean payoff of
    the final states). The verdict: each prediction within its observed interval (z = 4).
    With --engine mujoco every trial counts (a jam did not reach the goal): the observed
    success and its 95% interval, the range 95% of runs would give if the prediction were
    right, an exact binomial p-value, and flags where the model's assumptions break.

    With --plan FILE the plan must be for PART (else exit 2, unless --force) and runs under
    the prior and goal it was made for, unless --prior or --goal says otherwise.

    With --sense: plan the Bayes sensing policy, run it cycle after cycle (readings drawn
    from the sensor model, or MuJoCo's jaw separation with --engine mujoco: --sense width
    then means MuJoCo's default error, width:0.2,0.1 mm) and compare its success, cost a
    cycle, actions and cost per oriented part with the prediction.
    """
    from .. import report
    from ..io.plans import provenance
    from ..sim.noise import GripperNoise
    from ..sim.result import verdict_lines
    from ..sim.scene import units_scale

    if engine is Engine.kinematic and units is not None:
        raise typer.BadParameter(
            "applies to --engine mujoco only (the kinematic model has no sizes)",
            param_hint="--units",
        )
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
            "--contact-noise Q)",
            param_hint="--jaw-lag",
        )
    if contact_noise is not None and engine is Engine.mujoco:
        raise typer.BadParameter(
            "applies to the kinematic engine only: in MuJoCo the jaws' contacts are the "
            "physics' own (make one jaw touch first with --jaw-lag SECONDS)",
            param_hint="--contact-noise",
        )
    if sense is not None:
        if which != "bayes" or force:
            raise typer.BadParameter(
                "with --sense the Bayes policy is planned and run; --plan and --force choose or "
                "admit a linear plan",
                param_hint="--plan" if which != "bayes" else "--force",
            )
        from .sensing import ActionModel, simulate_policy_command

        model, _, _ = _noise_model(noise, noise_kind, turn_noise, contact_noise)
        asked = not model.exact or payoff is not None
        action = ActionModel(model, payoff) if asked else None
        sensing = sense_spec(sense, also or (), part_prior, spec, max_memory, time_limit)
        from .meshes import mesh_sensing  # a mesh PART: the policy over its poses

        sensing, spec = mesh_sensing(
            part, sensing, spec, bool(also or part_prior), goal_pose, pose_prior, jaw_height
        )
        simulate_policy_command(
            part, spec, sensing, engine, trials, workers, offset, seed, units,
            sensor_error, as_json, action, jaw_lag,
        )  # fmt: skip
        return
    if also or part_prior is not None or sensor_error:
        raise typer.BadParameter("--also, --part-prior and --sensor-error need --sense")
    if goal_pose is not None or pose_prior is not None:
        raise typer.BadParameter(
            "--goal-pose and --pose-prior plan a policy over poses: add --sense"
        )
    if jaw_height is not None:
        from .meshes import check_pose_toppling

        check_pose_toppling(part, jaw_height)
    if (max_memory, time_limit) != (None, None):
        raise typer.BadParameter(
            "--max-memory and --time-limit bound a policy search: they need --sense"
        )
    model, noise_deg, kind = _noise_model(noise, noise_kind, turn_noise, contact_noise)
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
    params = lagged_params(jaw_lag, p, units) if jaw_lag else None
    pay = _read_payoff(payoff)
    if (not model.exact or pay is not None) and which in ("bayes", "most-certain", "guaranteed"):
        pb, option, label = noise_aware_plan(which, spec, p, model, pay)
    else:
        pb, option, label = chosen_plan(which, spec, p, force)
        _note_plan_file(which, model, pay)
    u = None if pay is None else _payoff_vector(pay, pb)
    n = trials or (1_000_000 if engine is Engine.kinematic else 200)

    def run(progress: Any) -> Any:
        if engine is Engine.kinematic:
            return _kinematic_blocks(pb, option, n, model, seed, progress, u)
        from ..sim import simulate_mujoco
        from ..sim.result import with_prediction

        mm = offset / 1000.0  # millimetres to metres
        res = simulate_mujoco(
            pb,
            option,
            n,
            offset=mm,
            noise=GripperNoise.of(model.turn),
            rng=seed,
            workers=workers,
            scale=scale if units is not None else None,
            progress=progress,
            params=params,
        )
        # MuJoCo draws the turn error; the prediction is the exact one under it.
        return with_prediction(res, pb, model, u) if not model.exact or u is not None else res

    res = with_progress(f"{engine.value} trials", n, run)
    if as_json:
        doc = report.simulate_json(res, p)
        mujoco = engine is Engine.mujoco
        how = simulate_inputs(
            engine.value, which, seed, n, noise_deg, kind, offset, units,
            workers if mujoco else None,
        )  # fmt: skip
        how["contact_noise"] = contact_noise
        how["payoff"] = None if payoff is None else str(payoff)
        how["jaw_lag_s"] = jaw_lag or None
        doc["provenance"] = provenance(pb, None, **how, **run_inputs(part, spec))
        emit_json(doc)
    else:
        title = f"{p.name}: {label} plan, prior {pb.prior.name}; "
        if not model.exact:
            title += f"predicted under {model.describe()}; "
        if payoff is not None:
            title += f"payoff {payoff.name}; "
        if jaw_lag:
            title += f"jaw lag {jaw_lag:g} s; "
        typer.echo("\n".join([report.simulate_table(res, title), *verdict_lines(res)]))


def _noise_model(
    noise: float, kind: NoiseKind, turn_noise: str | None, contact: float | None
) -> tuple[Any, float, str]:
    """The noise model of the options, and the turn error's degrees and kind as given.

    ``--noise DEG --noise-kind KIND`` is ``--turn-noise KIND:DEG``; the degrees and kind go
    into the document's provenance as ``noise_deg`` and ``noise_kind`` whichever spelling
    gave them, so both spellings write the same document.
    """
    from ..model.noise import MAX_NORMAL_SIGMA, NoiseModel, TurnNoise
    from .noisy import turn_noise as parse

    if turn_noise is not None:
        if noise > 0:
            raise typer.BadParameter("give --noise or --turn-noise, not both", param_hint="--noise")
        if kind is not NoiseKind.normal:
            raise typer.BadParameter(
                "is the distribution of --noise; --turn-noise names its own (KIND:DEG)",
                param_hint="--noise-kind",
            )
        t = parse(turn_noise)
        deg = float(turn_noise.partition(":")[2])
    else:
        top = math.degrees(MAX_NORMAL_SIGMA)
        if kind is NoiseKind.normal and noise > top:
            raise typer.BadParameter(
                f"a normal gripper error of sigma {noise:g} deg is beyond the noise model "
                f"(at most {top:g} deg: beyond it the turn is a guess)",
                param_hint="--noise",
            )
        t = TurnNoise(kind.value, math.radians(noise))
        deg = noise
    return NoiseModel(t, contact or 0.0), deg, t.kind


def noise_aware_plan(
    which: str, spec: ProblemSpec, part: Any, noise: Any, payoff: Any
) -> tuple[Any, Any, str]:
    """The problem, the plan ``plan`` gives under the noise and payoff, and its title name.

    ``which`` is ``bayes`` or ``most-certain`` (the highest expected payoff); the planner
    is :func:`~bayesgrasp.planning.noisy.plan_noisy` with the options ``plan`` passes it.
    ``guaranteed``: the plan ``plan --guaranteed`` gives under the noise
    (:func:`~bayesgrasp.planning.robust.plan_guaranteed_noisy`; none under a normal turn error,
    which is unbounded).
    """
    from ..planning.noisy import plan_noisy
    from .common import PLAN_NAMES

    if spec.method.value != "exact":
        raise typer.BadParameter(
            "the noise-aware planner seeds from the exact planner; drop --method",
            param_hint="--method",
        )
    pb = spec.build(part)
    if which == "guaranteed":
        from ..planning.robust import UNBOUNDED_GUARANTEE, plan_guaranteed_noisy

        if not noise.turn.exact and noise.turn.kind == "normal":
            raise typer.BadParameter(UNBOUNDED_GUARANTEE, param_hint="--plan")
        found = plan_guaranteed_noisy(pb, noise)
        if found.status != "ok":
            raise typer.BadParameter(
                f"no guaranteed plan under {noise.describe()}: {found.reason}", param_hint="--plan"
            )
        return pb, found.options[0], "noise-aware guaranteed"
    res = plan_noisy(pb, noise, payoff, spec.max_actions)
    chosen = res.bayes if which == "bayes" else res.most_certain
    what = "noise-aware " if not noise.exact else "payoff "
    return pb, res.options[chosen].option, what + PLAN_NAMES[which]


def _note_plan_file(which: str, noise: Any, payoff: Any) -> None:
    """Say on stderr when a plan file was made under a noise or payoff the run does not use.

    The run uses the options as given (the same command prints the same numbers); the note
    names the options that would simulate the plan under the conditions it was made for.
    """
    import json

    from ..errors import BayesGraspError
    from ..model.noise import NoiseModel, TurnNoise

    path = Path(which)
    if path.suffix.lower() != ".json":
        return
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        made = doc.get("noise") if isinstance(doc, dict) else None
        theirs = NoiseModel(
            TurnNoise(made["turn"]["kind"], made["turn"]["scale_rad"]), made["contact"]
        ) if isinstance(made, dict) else NoiseModel()  # fmt: skip
        paid = isinstance(doc, dict) and doc.get("payoff") is not None
    except (OSError, ValueError, KeyError, TypeError, BayesGraspError):
        return  # the plan reader has checked the file; a note is never an error
    missing = []
    if theirs != noise and not theirs.exact:
        t, q = theirs.turn, theirs.contact
        missing += [f"--turn-noise {t.spec()}"] if not t.exact else []
        missing += [f"--contact-noise {q:g}"] if q > 0 else []
    if paid and payoff is None:
        missing.append("--payoff FILE")
    if missing:
        typer.echo(
            f"note: plan file {path.name!r} was made under other conditions "
            f"({theirs.describe()}{', a payoff' if paid else ''}); to simulate it under them "
            f"give {' '.join(missing)}",
            err=True,
        )


def _read_payoff(path: Path | None) -> Any:
    """The payoff of ``--payoff FILE`` (a bad file: exit 2, one line)."""
    if path is None:
        return None
    from ..model.payoff import PayoffError, read_payoff

    try:
        return read_payoff(path)
    except PayoffError as exc:
        raise typer.BadParameter(str(exc), param_hint="--payoff") from None


def _payoff_vector(payoff: Any, problem: Any) -> Any:
    """The payoff's value on each of the problem's states (a mismatch: exit 2)."""
    from ..model.payoff import PayoffError, as_vector

    try:
        return as_vector(payoff, problem.states)
    except PayoffError as exc:
        raise typer.BadParameter(str(exc), param_hint="--payoff") from None


def _kinematic_blocks(
    pb: Any, option: Any, n: int, noise: Any, seed: int, progress: Any, payoff: Any = None
) -> Any:
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
        one = simulate_kinematic(pb, option, m, noise, rng=rng, progress=tick, payoff=payoff)
        results = [*results, one]
        results = [combine(results)] if len(results) > 1 else results
        done += m
    return results[0]
