"""The files ``bayesgrasp plot`` writes: every figure of a plan, and its animation."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ..model.problem import Problem
from ..planning.result import PlanOption
from .animation import plan_animation, save_animation
from .canvas import save_metadata
from .functions import diameter_figure, transfer_figure
from .part import part_figure
from .plans import evolution_figure, noise_note

if TYPE_CHECKING:  # pragma: no cover
    from ..model.noise import NoiseModel

__all__ = ["write_figures"]


def write_figures(
    problem: Problem,
    option: PlanOption,
    out_dir: str | Path,
    label: str = "chosen",
    formats: Sequence[str] = ("png", "svg"),
    push_grasp: bool | None = None,
    animation: bool = True,
    frames_per_step: int = 24,
    noise: NoiseModel | None = None,
    per_payoff: bool = False,
) -> list[Path]:
    """Write figures (a) to (d) in each format, and the animation (e), into a folder.

    Files: ``part``, ``diameter``, ``transfer`` and ``plan`` with each extension, and
    ``plan.gif`` (``plan.mp4`` when ffmpeg is present). Every figure reads the one problem
    (the transfer figure draws each of its actions).

    Under a noise model the plan figure (d) draws the exact distributions after each step
    under it (:func:`~bayesgrasp.planning.noisy.step_distributions_noisy`, as the bottom half
    of :func:`~bayesgrasp.figures.plans.noisy_plan_figure`) and its title says the noise; the
    animation's caption says it too (its panels run the plan without the noise).
    Figures (a) to (c) are the part's own, whatever the noise.

    Parameters
    ----------
    problem : Problem
    option : PlanOption
        The plan drawn (its first action gives the diameter figure's histogram).
    out_dir : str or Path
        Created if missing.
    label : str, optional
        How titles name the plan.
    formats : sequence of str, optional
        Image formats (``png``, ``svg``, ``pdf``).
    push_grasp : bool, optional
        Deprecated, see :func:`transfer_figure`: the problem's actions are drawn.
    animation : bool, optional
        Also write the animation.
    frames_per_step : int, optional
        Animation frames per plan step.
    noise : NoiseModel, optional
        The noise the plan is drawn under; ``option``'s success probability and expected
        cost are then the ones under it (as :func:`~bayesgrasp.planning.noisy.plan_noisy`
        gives them), which the titles print.
    per_payoff : bool, optional
        The option's expected cost is per unit payoff (said in the title).

    Returns
    -------
    list of Path
        The files written, in order.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    qs, note, caption = None, None, None
    if noise is not None:
        from ..planning.noisy import step_distributions_noisy

        qs = step_distributions_noisy(problem, noise, option.steps)
        note = noise_note(noise, per_payoff)
        caption = f"P(success) exact under {noise.describe()}; the panels run the plan without it"
    figures = {
        "part": part_figure(problem),
        "diameter": diameter_figure(problem, option.first_angle, option.steps[0].kind),
        "transfer": transfer_figure(problem, push_grasp=push_grasp),
        "plan": evolution_figure(problem, option, label, qs, note),
    }
    written: list[Path] = []
    for name, fig in figures.items():
        for fmt in formats:
            target = out / f"{name}.{fmt}"
            fig.savefig(target, dpi=110, metadata=save_metadata(fmt))
            # Laid out once: the other formats keep the positions (same size and dpi).
            fig.set_layout_engine("none")
            written.append(target)
    if animation:
        anim = plan_animation(
            problem, option, frames_per_step=frames_per_step, label=label, note=caption
        )
        written += save_animation(anim, out / "plan.gif")
    return written
