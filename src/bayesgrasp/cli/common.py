"""What the commands share besides options: printing, progress, output files, plans.

:func:`chosen_plan` is the one way to get the plan a command acts on, by name (bayes,
most-certain, guaranteed) or from a plan file. :func:`check_outputs` is the one way a
command decides that it may write a file: never over one of its inputs (the part file, a
prior file, a plan file; also through a symlink, a hard link or another letter case), and
over any other existing file only with ``--force``.
"""

from __future__ import annotations

import errno
import json
import math
import os
import sys
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import typer

from ..runs.specs import PLAN_NAMES, guaranteed_plan, simulate_inputs

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
    from ..planning.result import PlanOption
    from ..runs.specs import ProblemSpec

__all__ = [
    "IMAGE_FORMATS",
    "PLAN_NAMES",
    "accuracy_value",
    "bound_value",
    "check_figure_path",
    "check_outputs",
    "chosen_plan",
    "cost_value",
    "emit_json",
    "flatten_value",
    "input_files",
    "list_files",
    "no_plan",
    "print_note",
    "save_figure",
    "simulate_inputs",
    "with_progress",
    "write_failed",
]

IMAGE_FORMATS = ("png", "svg", "pdf")


def emit_json(doc: dict[str, Any]) -> None:
    """Print a JSON document (no NaN or infinity: those become null upstream)."""
    typer.echo(json.dumps(doc, indent=2, allow_nan=False))


def print_note(text: str) -> None:
    """Tell the user something about how their input was read: one line on stderr."""
    typer.echo(f"bayesgrasp: note: {text}", err=True)


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


def cost_value(value: float | None) -> float | None:
    """A cost option: a number, >= 0, small enough that expected costs stay finite."""
    from ..model.cost import MAX_COST

    if value is None:
        return value
    if math.isnan(value):
        raise typer.BadParameter("is not a number; give a cost >= 0")
    if value < 0:
        raise typer.BadParameter(f"should be >= 0; got {value:g}")
    if math.isfinite(value) and value > MAX_COST:  # infinity: the cost model says why
        raise typer.BadParameter(
            f"should be at most {MAX_COST:g} (larger costs overflow the expected cost); "
            f"got {value:g}"
        )
    return value


def accuracy_value(value: float) -> float:
    """The gripper accuracy in degrees: a number in [0, 90)."""
    if math.isnan(value):
        raise typer.BadParameter("is not a number; give degrees >= 0")
    if value < 0:
        raise typer.BadParameter(f"should be >= 0 deg; got {value:g} deg")
    if value >= 90:
        raise typer.BadParameter(
            f"no plan keeps a tolerance of {value:g} deg (stable orientations repeat every "
            "180 deg at most, so every tolerance is below 90 deg); give less than 90"
        )
    return value


def bound_value(value: float | None) -> float | None:
    """A search bound (``--max-memory``, ``--time-limit``): a finite number > 0."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise typer.BadParameter(f"should be a number > 0; got {value:g}")
    return value


def flatten_value(value: float | None) -> float | None:
    """The chordal tolerance of ``--flatten-tol``: a finite number > 0 (or left out)."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise typer.BadParameter(f"should be a number > 0 in the part's units; got {value:g}")
    return value


def input_files(part: str | None, prior: str | None = None, *more: str | Path | None) -> list[Path]:
    """The files a command reads: the part file, the prior's file, plan files and the like.

    ``part`` is PART as given (a catalogue name or ``-`` is no file); ``prior`` the
    ``--prior`` text (``histogram:FILE`` and ``sample:FILE`` name a file).
    """
    names: list[str | Path] = [m for m in more if m is not None]
    if part is not None:
        names.append(part)
    if prior is not None:
        kind, _, arg = prior.partition(":")
        if kind.strip().lower() in ("histogram", "sample") and arg:
            names.append(arg)
    return [Path(n) for n in names if str(n) != "-" and Path(n).exists()]


def _same_file(a: Path, b: Path) -> bool:
    """Whether writing ``a`` would write ``b``.

    One path after symlinks, the same inode (a hard link), or the same path but for letter
    case (one file on a case-insensitive file system; refused on every system, so that a
    command line means the same everywhere).
    """
    ra, rb = a.resolve(), b.resolve()
    if ra == rb or str(ra).casefold() == str(rb).casefold():
        return True
    try:
        return os.path.samefile(ra, rb)
    except OSError:  # one of them does not exist
        return False


def check_outputs(
    outputs: Sequence[Path],
    inputs: Iterable[Path],
    force: bool = False,
    hint: str = "--out",
    folders: bool = False,
) -> None:
    """Refuse, before any work, to write over an input or (without ``--force``) any file.

    An output that is an input (:func:`_same_file`) is refused even with ``--force``: the
    user's part or prior would be lost. An existing output is refused unless ``force``; a
    folder where a file would go is refused unless ``folders`` (an output that is a folder).

    Raises
    ------
    typer.BadParameter
        Exit code 2, one line naming the file.
    """
    given = list(inputs)
    for out in outputs:
        for src in given:
            if _same_file(out, src):
                raise typer.BadParameter(
                    f"{str(out)!r} is an input of this command ({str(src)!r}); "
                    "refusing to write over it, choose another name",
                    param_hint=hint,
                )
        try:
            out.lstat()
        except OSError as exc:
            if exc.errno == errno.ENAMETOOLONG:  # the checks below would raise it
                raise typer.BadParameter(
                    f"cannot write {str(out)!r} ({exc.strerror})", param_hint=hint
                ) from None
        if out.is_dir() and not folders:
            raise typer.BadParameter(f"{str(out)!r} is a folder, not a file", param_hint=hint)
    there = [out for out in outputs if out.exists() or out.is_symlink()]
    if there and not force:
        more = f" (and {len(there) - 1} more the command writes)" if len(there) > 1 else ""
        raise typer.BadParameter(
            f"{str(there[0])!r} exists{more}; use --force to replace", param_hint=hint
        )


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


def write_failed(out: Path, exc: OSError) -> NoReturn:
    """``--out`` could not be written: one line, exit 2."""
    reason = exc.strerror or exc
    raise typer.BadParameter(f"cannot write into {out}: {reason}", param_hint="--out") from None


def list_files(files: Sequence[Path], as_json: bool) -> None:
    """Print the figures a command wrote: one path a line, or ``bayesgrasp.plot/1``."""
    if as_json:
        emit_json({"schema": "bayesgrasp.plot/1", "files": [str(f) for f in files]})
    else:
        for f in files:
            typer.echo(str(f))


def chosen_plan(
    which: str, spec: ProblemSpec, part: Part, force: bool = False
) -> tuple[Problem, PlanOption, str]:
    """The problem and the plan ``--plan`` names (bayes, most-certain, guaranteed, a file).

    Returns the problem (with the action kinds of a plan file added), the plan and its name
    for titles. No guaranteed plan: exit code 1. A bad name or file: exit code 2.

    A plan file made for another part (:func:`bayesgrasp.io.plans.same_part`) is refused
    unless ``force``; the prior and goal it was made under apply unless ``--prior`` or
    ``--goal`` was given, so the prediction is the plan's own.
    """
    path = Path(which)
    if which not in PLAN_NAMES and path.suffix.lower() != ".json":
        names = ", ".join(PLAN_NAMES)
        raise typer.BadParameter(
            f"expected {names} or a .json plan file; got {which!r}", param_hint="--plan"
        )
    if which not in PLAN_NAMES:
        return _plan_file(path, spec, part, force)
    problem = spec.build(part)
    if which == "guaranteed":
        found = guaranteed_plan(problem)
        if isinstance(found, str):
            no_plan(found)
        return problem, found.option, PLAN_NAMES[which]
    result = spec.plan(problem)
    plan = result.bayes_plan if which == "bayes" else result.most_certain_plan
    return problem, plan, PLAN_NAMES[which]


def _plan_file(
    path: Path, spec: ProblemSpec, part: Part, force: bool
) -> tuple[Problem, PlanOption, str]:
    """The plan of a plan file, checked against the part, and the problem it was made for."""
    from ..io.plans import part_id, read_plan, same_part
    from ..runs.specs import spec_for_plan

    src = read_plan(path)
    if same_part(src.part, part) is False and not force:
        theirs = src.part or {}
        raise typer.BadParameter(
            f"plan file {path.name!r} is for part {theirs.get('name', '?')!r} "
            f"({theirs.get('id', 'other vertices')}), not {part.name!r} ({part_id(part)}); "
            "use --force to run it anyway",
            param_hint="--plan",
        )
    spec, prior = spec_for_plan(src, spec)
    return spec.build(part, (), prior), src.option, path.name
