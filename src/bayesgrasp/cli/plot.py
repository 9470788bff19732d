"""``plot``: figures of a part and a plan, and the plan's animation."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from .common import (
    IMAGE_FORMATS,
    check_outputs,
    chosen_plan,
    input_files,
    list_files,
    write_failed,
)
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
from .specs import PartSpec, ProblemSpec

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
    from ..planning.result import PlanOption
    from .noisy import NoisyRun

app = command_app()

OutOpt = Annotated[
    Path, typer.Option("--out", metavar="DIR", help="Folder for the figures (created).")
]
FormatsOpt = Annotated[str, typer.Option("--image-formats", help="Comma-separated: png, svg, pdf.")]
AnimationOpt = Annotated[
    bool,
    typer.Option("--animation/--no-animation", help="Also write the plan's animation (plan.gif)."),
]
ForceOpt = Annotated[
    bool,
    typer.Option(
        "--force",
        help="Replace figures that exist in DIR (an input file never), and draw a --plan FILE "
        "made for another part.",
    ),
]
FramesOpt = Annotated[int, typer.Option(min=4, max=240, help="Animation frames per plan step.")]
FIGURES = ("part", "diameter", "transfer", "plan")
"""The figure files, one per image format (:func:`bayesgrasp.figures.files.write_figures`)."""
ANIMATIONS = ("plan.gif", "plan.mp4")
"""The animation files (the MP4 only when ffmpeg is present)."""


def figure_files(out: Path, formats: list[str], animation: bool) -> list[Path]:
    """Every file ``plot`` may write into ``out``."""
    files = [out / f"{name}.{fmt}" for name in FIGURES for fmt in formats]
    return files + ([out / a for a in ANIMATIONS] if animation else [])


@app.command()
@part_options
@problem_options(push_grasp_alias=True)
def plot(
    part: PartSpec,
    spec: ProblemSpec,
    out: OutOpt = Path("figures"),
    which: PlanChoiceOpt = "bayes",
    image_formats: FormatsOpt = "png,svg",
    animation: AnimationOpt = True,
    frames: FramesOpt = 20,
    as_json: JsonOpt = False,
    force: ForceOpt = False,
    sense: SenseOpt = None,
    also: AlsoOpt = None,
    part_prior: PartPriorOpt = None,
    max_memory: MaxMemoryOpt = None,
    time_limit: TimeLimitOpt = None,
    goal_pose: GoalPoseOpt = None,
    pose_prior: PosePriorOpt = None,
    jaw_height: JawHeightOpt = None,
    turn_noise: TurnNoiseOpt = None,
    contact_noise: ContactNoiseOpt = None,
    payoff: PayoffOpt = None,
) -> None:
    """Figures of a part and a plan: part.*, diameter.*, transfer.*, plan.* and plan.gif.

    With --sense: the Bayes sensing policy's tree with the part at each node (policy.*).
    Files that exist in the folder are replaced only with --force; an input (the part, the
    prior, the plan or the payoff file) never is.

    With --turn-noise, --contact-noise or --payoff: --plan bayes, most-certain and
    guaranteed are the plans plan gives with the same options (--guaranteed under a bounded
    turn error), --plan FILE the plan it holds; plan.* draws the exact distributions after
    each step under the noise and its title says the noise (as plan --plot draws them); the
    part's figures are the same. With --sense: the policy planned under the noise, as plan
    --sense --plot draws it.
    """
    from ..figures.plots import write_figures
    from ..model.actions import PUSH_GRASP
    from . import noisy

    formats = [f.strip().lower() for f in image_formats.split(",") if f.strip()]
    if not formats or any(f not in IMAGE_FORMATS for f in formats):
        raise typer.BadParameter(
            f"expected a comma-separated list of png, svg, pdf; got {image_formats!r}",
            param_hint="--image-formats",
        )
    if out.exists() and not out.is_dir():
        raise typer.BadParameter(f"{str(out)!r} is a file, not a folder", param_hint="--out")
    inputs = input_files(part.part, spec.prior, which, payoff)
    if sense is not None:
        from .sensing import plot_policy_command, sense_noise

        check_outputs([out / f"policy.{f}" for f in formats], inputs, force, "--out")
        sensing = sense_spec(sense, also or (), part_prior, spec, max_memory, time_limit)
        from .meshes import mesh_sensing  # a mesh PART: the policy over its poses

        sensing, spec = mesh_sensing(
            part, sensing, spec, bool(also or part_prior), goal_pose, pose_prior, jaw_height
        )
        action = sense_noise(turn_noise, contact_noise, payoff)
        plot_policy_command(part, spec, sensing, out, formats, as_json, action)
        return
    if also or part_prior is not None:
        raise typer.BadParameter("--also and --part-prior need --sense")
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
    run = (
        noisy.NoisyRun.of(spec, turn_noise, contact_noise, payoff)
        if noisy.asked(turn_noise, contact_noise, payoff)
        else None
    )
    check_outputs(figure_files(out, formats, animation), inputs, force, "--out")
    if run is None:
        pb, option, label = chosen_plan(which, spec, part.load(), force)
    else:
        pb, option, label = _noisy_plan(which, spec, part.load(), force, run)
    try:
        files = write_figures(
            pb,
            option,
            out,
            label=label,
            formats=formats,
            push_grasp=PUSH_GRASP.name in pb.action_kinds,
            animation=animation,
            frames_per_step=frames,
            noise=None if run is None else run.noise,
            per_payoff=run is not None and run.payoff is not None,
        )
    except OSError as exc:
        write_failed(out, exc)
    list_files(files, as_json)


def _noisy_plan(
    which: str, spec: ProblemSpec, part: Part, force: bool, run: NoisyRun
) -> tuple[Problem, PlanOption, str]:
    """The problem, the plan ``--plan`` names under the noise and payoff, and its title name.

    ``bayes`` and ``most-certain``: the noise-aware planner's
    (:func:`~bayesgrasp.planning.noisy.plan_noisy`, the plans ``plan`` gives with the same
    options). ``guaranteed``: the plan ``plan --guaranteed`` gives under the noise; a plan
    file: the plan as without the options. Either with its success probability and expected
    cost exact under the noise with its own goal (the states of positive payoff with
    ``--payoff``), as ``simulate`` predicts it.
    """
    import dataclasses

    import numpy as np

    from ..model.payoff import as_vector
    from ..planning.noisy import step_distributions_noisy
    from .common import PLAN_NAMES

    if which in ("bayes", "most-certain"):
        pb = spec.build(part)
        res, _ = run.plan(pb)
        chosen = res.bayes if which == "bayes" else res.most_certain
        return pb, res.options[chosen].option, PLAN_NAMES[which]
    if which == "guaranteed":  # the plan plan --guaranteed gives under the noise
        from .simulate import noise_aware_plan

        pb, option, label = noise_aware_plan(which, spec, part, run.noise, run.payoff)
    else:
        pb, option, label = chosen_plan(which, spec, part, force)
    q = step_distributions_noisy(pb, run.noise, option.steps)[-1]
    if run.payoff is None:
        goal: Any = np.asarray(pb.success_states(option.final_orientation), dtype=np.float64)
    else:
        goal = as_vector(run.payoff, pb.states)
    gain = float(q @ goal)
    success = float(q[goal > 0].sum())
    cost = pb.cost.expected_cost(tuple(s.kind for s in option.steps), gain)
    return pb, dataclasses.replace(option, success_probability=success, expected_cost=cost), label
