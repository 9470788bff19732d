"""What the commands share besides options: printing, progress, figure files, plans.

:func:`chosen_plan` is the one way to get the plan a command acts on, by name (bayes,
most-certain, guaranteed) or from a plan file.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import typer

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.result import PlanOption
    from .specs import ProblemSpec

IMAGE_FORMATS = ("png", "svg", "pdf")
PLAN_NAMES = {"bayes": "Bayes", "most-certain": "most certain", "guaranteed": "guaranteed"}
"""The plans ``--plan`` names, and how titles call them."""


def emit_json(doc: dict[str, Any]) -> None:
    """Print a JSON document (no NaN or infinity: those become null upstream)."""
    typer.echo(json.dumps(doc, indent=2, allow_nan=False))


def with_progress(description: str, total: int, work: Callable[[Any], Any]) -> Any:
    """Run ``work(progress)`` with a rich progress bar on a terminal, without one elsewhere.

    ``progress`` is ``None`` or a callback ``(done, total)`` the library calls as it goes.
    """
    if not sys.stderr.isatty():
        return work(None)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    with Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=total)
        return work(lambda done, total: bar.update(task, completed=done, total=total))


def no_plan(reason: str) -> NoReturn:
    """No plan reached the requested goal: say why on stderr, exit code 1."""
    typer.echo(f"bayesgrasp: no plan: {reason}", err=True)
    raise typer.Exit(1)


def check_figure_path(path: Path, hint: str = "--plot") -> None:
    """Refuse a figure file name that cannot be written, before any work is done."""
    if path.suffix.lstrip(".").lower() not in IMAGE_FORMATS:
        raise typer.BadParameter(
            f"the figure file must end in .png, .svg or .pdf; got {path.name!r}", param_hint=hint
        )
    if not path.parent.is_dir():
        raise typer.BadParameter(f"no folder {str(path.parent)!r} to write into", param_hint=hint)


def save_figure(fig: Any, path: Path) -> None:
    """Write a figure; a bad file name is a usage error (exit 2), not a traceback."""
    check_figure_path(path)
    try:
        fig.savefig(path, dpi=110)
    except OSError as exc:
        reason = exc.strerror or exc
        raise typer.BadParameter(f"cannot write {path}: {reason}", param_hint="--plot") from None


def guaranteed_plan(problem: Problem) -> GuaranteedPlan | str:
    """The guaranteed plan of a problem, or the reason none exists (a string)."""
    from ..planning import guaranteed

    found = guaranteed.plan_guaranteed(problem)
    return found if found.status == "ok" else str(found.reason or "no guaranteed plan")


def chosen_plan(which: str, spec: ProblemSpec, part: Part) -> tuple[Problem, PlanOption, str]:
    """The problem and the plan ``--plan`` names (bayes, most-certain, guaranteed, a file).

    Returns the problem (with the action kinds of a plan file added), the plan and its name
    for titles. No guaranteed plan: exit code 1. A bad name or file: exit code 2.
    """
    path = Path(which)
    if which not in PLAN_NAMES and path.suffix.lower() != ".json":
        names = ", ".join(PLAN_NAMES)
        raise typer.BadParameter(
            f"expected {names} or a .json plan file; got {which!r}", param_hint="--plan"
        )
    problem = spec.build(part)
    if which == "guaranteed":
        found = guaranteed_plan(problem)
        if isinstance(found, str):
            no_plan(found)
        return problem, found.option, PLAN_NAMES[which]
    if which in PLAN_NAMES:
        result = spec.plan(problem)
        plan = result.bayes_plan if which == "bayes" else result.most_certain_plan
        return problem, plan, PLAN_NAMES[which]
    from ..io.plans import read_plan_document

    plan = read_plan_document(path)
    missing = tuple(k for k in plan.kinds if k not in problem.action_kinds)
    return (spec.build(part, missing) if missing else problem), plan, path.name
