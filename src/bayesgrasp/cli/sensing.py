"""``simulate --sense`` and ``plot --sense``: run a sensing policy's cycles, draw its tree."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import typer

from .common import emit_json, list_files, with_progress, write_failed
from .specs import Engine, PartSpec, ProblemSpec


def simulate_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sense: str,
    also: list[str],
    part_prior: str | None,
    max_actions: int,
    engine: Engine,
    cycles: int | None,
    workers: int,
    offset_mm: float,
    noise: Any,
    seed: int,
    units: str | None,
    sensor_error: bool,
    as_json: bool,
) -> None:
    """Plan the Bayes policy of PART (and the --also parts), run it, print the comparison.

    With ``--engine mujoco`` and ``--sense width`` (no SIGMA given) the policy is planned
    for MuJoCo's default reading error (:func:`bayesgrasp.sim.policy.mujoco_sensor`).
    """
    from ..model.sensing import parse_sensor
    from ..planning.policy import plan_policy
    from ..sim.policy import (
        mujoco_sensor,
        policy_simulation_json,
        policy_simulation_text,
        simulate_policy,
        simulate_policy_mujoco,
    )
    from ..sim.scene import units_scale

    sensor = parse_sensor(sense)
    parts = [part.load(), *(dataclasses.replace(part, part=p).load() for p in also)]
    scale = units_scale(units) if units is not None else None
    if engine is Engine.mujoco and sensor.kind == "exact":
        sensor = mujoco_sensor(parts[0], scale or units_scale(parts[0].units))
    problems = [spec.build(p) for p in parts]
    pol = plan_policy(problems, sensor=sensor, max_actions=max_actions, part_prior=part_prior)
    n = cycles or (200_000 if engine is Engine.kinematic else 200)

    def run(progress: Any) -> Any:
        if engine is Engine.kinematic:
            return simulate_policy(problems, pol, n, noise, rng=seed, progress=progress)
        return simulate_policy_mujoco(
            problems,
            pol,
            n,
            offset=offset_mm / 1000.0,
            noise=noise,
            rng=seed,
            workers=workers,
            scale=scale,
            add_sensor_error=sensor_error,
            progress=progress,
        )

    res = with_progress(f"{engine.value} cycles", n, run)
    if as_json:
        emit_json(policy_simulation_json(res))
        return
    names = " or ".join(pol.parts)
    typer.echo(
        policy_simulation_text(res, f"{names}: Bayes policy of at most {max_actions} actions; ")
    )


def plot_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sense: str,
    also: list[str],
    part_prior: str | None,
    max_actions: int,
    out: Path,
    formats: list[str],
    as_json: bool,
) -> None:
    """Plan the Bayes policy and draw its tree into ``out/policy.FORMAT``."""
    from ..figures.policy import policy_figure
    from ..planning.policy import plan_policy

    parts = [part.load(), *(dataclasses.replace(part, part=p).load() for p in also)]
    problems = [spec.build(p) for p in parts]
    pol = plan_policy(problems, sensor=sense, max_actions=max_actions, part_prior=part_prior)
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
