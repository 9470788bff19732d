"""``plan``, ``simulate`` and ``plot --sense``: plan a sensing policy, run its cycles, draw it.

Each command's --sense options arrive as one :class:`~.specs.SenseSpec`, which reads the
candidate parts and plans their policy.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from .common import emit_json, list_files, with_progress, write_failed
from .specs import Engine, PartSpec, ProblemSpec, SenseSpec

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..io.export import Stroke
    from ..model.noise import NoiseModel
    from ..model.problem import Problem
    from ..model.sensing import WidthSensor
    from ..planning.policy import Policy
    from .outputs import PartOutputs
    from .strategies import StrategyRun


@dataclass(frozen=True)
class ActionModel:
    """The noise and payoff options of a --sense command (either may be absent)."""

    noise: NoiseModel | None = None
    payoff: Path | None = None


def sensing_run(
    spec: ProblemSpec, sensing: SenseSpec, model: ActionModel | None, n_parts: int = 1
) -> StrategyRun:
    """The run of a --sense command (:class:`~.strategies.StrategyRun`) for ``n_parts`` parts.

    Reads the payoff file; a payoff with candidate parts is refused (exit 2).
    """
    from .strategies import StrategyRun

    if model is None:
        return StrategyRun(spec, sensing=sensing)
    from ..model.payoff import read_payoff

    payoff = read_payoff(model.payoff) if model.payoff is not None else None
    if payoff is not None and n_parts > 1:
        raise typer.BadParameter("a payoff is for one part: drop --also", param_hint="--payoff")
    return StrategyRun(spec, noise=model.noise, payoff=payoff, noisy=True, sensing=sensing)


def plan_sensing_policy(
    sensing: SenseSpec,
    parts: list[Part],
    spec: ProblemSpec,
    model: ActionModel | None,
    sensor: WidthSensor | None = None,
) -> tuple[list[Problem], Policy]:
    """The candidates' problems and their Bayes policy, under the action noise if given."""
    from ..planning.policy import Policy

    res = sensing_run(spec, sensing, model, len(parts)).solve_parts(parts, sensor)
    assert isinstance(res.source, Policy)
    return list(res.problems), res.source


def sense_noise(turn: str | None, contact: float | None, payoff: Path | None) -> ActionModel | None:
    """The action noise and payoff of a --sense command (``None``: neither asked)."""
    if turn is None and contact is None and payoff is None:
        return None
    from .noisy import noise_model

    noise = noise_model(turn, contact) if turn is not None or contact is not None else None
    return ActionModel(noise, payoff)


def plan_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sensing: SenseSpec,
    as_json: bool,
    fold_below: float = 0.0,
    outputs: PartOutputs | None = None,
    stroke: Stroke | None = None,
    fold_figure: float | None = None,
    noise: ActionModel | None = None,
) -> None:
    """Plan and print a sensing policy over PART and the candidate parts.

    The text leaves out the branches below ``fold_below`` at their node (the JSON keeps all).
    ``outputs``: also draw the policy (``--plot``, folded at ``fold_figure`` when given) and
    write its robot state machine (``--export``); ``stroke``: refuse a policy with a state
    outside the gripper's stroke.
    With ``noise`` the policy is planned, and its figures computed, under that action noise
    (and payoff).
    """
    from .strategies import check_stroke, document, text, write_outputs

    parts = sensing.parts(part)
    if outputs is not None:
        outputs.check(parts[0].name, 1)
    result = sensing_run(spec, sensing, noise, len(parts)).solve_parts(parts)
    check_stroke(result, stroke)
    if outputs is not None:
        write_outputs(outputs, 1, result, fold_figure)
    if as_json:
        emit_json(document(result))
        return
    typer.echo(text(result, fold_below=fold_below))


def simulate_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sensing: SenseSpec,
    engine: Engine,
    cycles: int | None,
    workers: int,
    offset_mm: float,
    seed: int,
    units: str | None,
    sensor_error: bool,
    as_json: bool,
    action: ActionModel | None = None,
    jaw_lag: float = 0.0,
) -> None:
    """Plan the Bayes policy of PART (and the --also parts), run it, print the comparison.

    With ``--engine mujoco`` and ``--sense width`` (no SIGMA given) the policy is planned
    for MuJoCo's default reading error (:func:`bayesgrasp.sim.policy.mujoco_sensor`).
    With ``action`` (the noise and payoff options) the policy is planned under that noise
    (and payoff) and the runs draw the noise: turn error and contact asynchrony in the
    kinematic runs, the turn error in MuJoCo (whose contacts are its own; ``jaw_lag``
    seconds: one jaw of each MuJoCo squeeze leads, as ``simulate --jaw-lag`` does a plan's).
    """
    from ..model.sensing import parse_sensor
    from ..sim.policy import (
        mujoco_sensor,
        policy_simulation_json,
        policy_simulation_text,
        simulate_policy,
        simulate_policy_mujoco,
    )
    from ..sim.scene import units_scale

    sensor = parse_sensor(sensing.sense)
    parts = sensing.parts(part)
    scale = units_scale(units) if units is not None else None
    params = None  # --jaw-lag: checked for every candidate before any work
    if jaw_lag:
        from .engines import lagged_params

        checked = [lagged_params(jaw_lag, p, units) for p in parts]  # one SimParams for all
        params = checked[0]
    if engine is Engine.mujoco and sensor.kind == "exact":
        sensor = mujoco_sensor(parts[0], scale or units_scale(parts[0].units))
    from ..sim.noise import GripperNoise

    noise = None if action is None else action.noise
    problems, pol = plan_sensing_policy(sensing, parts, spec, action, sensor)
    n = cycles or (200_000 if engine is Engine.kinematic else 200)

    def run(progress: Any) -> Any:
        if engine is Engine.kinematic:
            return simulate_policy(problems, pol, n, noise, rng=seed, progress=progress)
        return simulate_policy_mujoco(
            problems,
            pol,
            n,
            offset=offset_mm / 1000.0,
            noise=None if noise is None else GripperNoise.of(noise.turn),
            rng=seed,
            workers=workers,
            scale=scale,
            add_sensor_error=sensor_error,
            progress=progress,
            params=params,
        )

    res = with_progress(f"{engine.value} cycles", n, run)
    if as_json:
        emit_json(policy_simulation_json(res))
        return
    names = " or ".join(pol.parts)
    most = sensing.max_actions
    title = f"{names}: Bayes policy of at most {most} actions; "
    if noise is not None and not noise.exact:
        title += f"planned and predicted under {noise.describe()}; "
    if jaw_lag:
        title += f"jaw lag {jaw_lag:g} s; "
    typer.echo(policy_simulation_text(res, title))


def plot_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sensing: SenseSpec,
    out: Path,
    formats: list[str],
    as_json: bool,
    noise: ActionModel | None = None,
) -> None:
    """Plan the Bayes policy (under ``noise`` if given) and draw its tree into ``out/policy.*``."""
    from ..figures.policy import policy_figure

    problems, pol = plan_sensing_policy(sensing, sensing.parts(part), spec, noise)
    fig = policy_figure(problems, pol)
    files = []
    try:
        out.mkdir(parents=True, exist_ok=True)
        for fmt in formats:
            path = out / f"policy.{fmt}"
            fig.savefig(path, dpi=110)
            files.append(path)
    except OSError as exc:
        write_failed(out, exc)
    list_files(files, as_json)
