"""``plan``, ``simulate`` and ``plot --sense``: plan a sensing policy, run its cycles, draw it.

Each command's --sense options arrive as one :class:`~.specs.SenseSpec`, which reads the
candidate parts and plans their policy.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from .common import emit_json, list_files, with_progress, write_failed
from .specs import Engine, PartSpec, ProblemSpec, SenseSpec

if TYPE_CHECKING:
    from ..io.export import Stroke
    from .outputs import PartOutputs


def plan_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sensing: SenseSpec,
    as_json: bool,
    fold_below: float = 0.0,
    outputs: PartOutputs | None = None,
    stroke: Stroke | None = None,
    fold_figure: float | None = None,
) -> None:
    """Plan and print a sensing policy over PART and the candidate parts.

    The text leaves out the branches below ``fold_below`` at their node (the JSON keeps all).
    ``outputs``: also draw the policy (``--plot``, folded at ``fold_figure`` when given) and
    write its robot state machine (``--export``); ``stroke``: refuse a policy with a state
    outside the gripper's stroke.
    """
    from ..io.export import check_stroke
    from ..io.policies import policy_document
    from ..planning.policy import policy_text

    parts = sensing.parts(part)
    if outputs is not None:
        outputs.check(parts[0].name, 1)
    problems, pol = sensing.policy(parts, spec)
    if stroke is not None:
        check_stroke(problems, pol, stroke)
    if outputs is not None:
        from .batch import write_policy_outputs

        write_policy_outputs(outputs, 1, problems, pol, fold_figure)
    if as_json:
        emit_json(policy_document(pol))
        return
    typer.echo(policy_text(pol, units=parts[0].units, min_probability=fold_below))
    entropy = ", ".join(f"{h:.3f}" for h in pol.expected_entropy)
    blind = pol.sensorless_cost
    versus = "" if blind is None else f" (sensorless Bayes plan {blind:.4f})"
    typer.echo(
        f"expected cost {pol.expected_cost:.4f}{versus}, "
        f"success {pol.success_probability:.4f} a cycle, "
        f"{pol.expected_actions:.3f} actions a cycle; expected entropy after each level "
        f"(bits): {entropy}"
    )


def simulate_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sensing: SenseSpec,
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
    if engine is Engine.mujoco and sensor.kind == "exact":
        sensor = mujoco_sensor(parts[0], scale or units_scale(parts[0].units))
    problems, pol = sensing.policy(parts, spec, sensor)
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
    most = sensing.max_actions
    typer.echo(policy_simulation_text(res, f"{names}: Bayes policy of at most {most} actions; "))


def plot_policy_command(
    part: PartSpec,
    spec: ProblemSpec,
    sensing: SenseSpec,
    out: Path,
    formats: list[str],
    as_json: bool,
) -> None:
    """Plan the Bayes policy and draw its tree into ``out/policy.FORMAT``."""
    from ..figures.policy import policy_figure

    problems, pol = sensing.policy(sensing.parts(part), spec)
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
