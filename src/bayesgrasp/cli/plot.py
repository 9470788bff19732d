"""``plot``: figures of a part and a plan, and the plan's animation."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

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
    JsonOpt,
    PartPriorOpt,
    PlanChoiceOpt,
    SenseOpt,
    command_app,
    part_options,
    problem_options,
    sense_spec,
)
from .specs import PartSpec, ProblemSpec

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
) -> None:
    """Figures of a part and a plan: part.*, diameter.*, transfer.*, plan.* and plan.gif.

    With --sense: the Bayes sensing policy's tree with the part at each node (policy.*).
    Files that exist in the folder are replaced only with --force; an input (the part, the
    prior or the plan file) never is.
    """
    from ..figures.plots import write_figures
    from ..model.actions import PUSH_GRASP

    formats = [f.strip().lower() for f in image_formats.split(",") if f.strip()]
    if not formats or any(f not in IMAGE_FORMATS for f in formats):
        raise typer.BadParameter(
            f"expected a comma-separated list of png, svg, pdf; got {image_formats!r}",
            param_hint="--image-formats",
        )
    if out.exists() and not out.is_dir():
        raise typer.BadParameter(f"{str(out)!r} is a file, not a folder", param_hint="--out")
    inputs = input_files(part.part, spec.prior, which)
    if sense is not None:
        from .sensing import plot_policy_command

        check_outputs([out / f"policy.{f}" for f in formats], inputs, force, "--out")
        sensing = sense_spec(sense, also or (), part_prior, spec)
        plot_policy_command(part, spec, sensing, out, formats, as_json)
        return
    if also or part_prior is not None:
        raise typer.BadParameter("--also and --part-prior need --sense")
    check_outputs(figure_files(out, formats, animation), inputs, force, "--out")
    pb, option, label = chosen_plan(which, spec, part.load(), force)
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
        )
    except OSError as exc:
        write_failed(out, exc)
    list_files(files, as_json)
