"""``plan`` of many parts in one process: one JSON document a line, errors in their line.

:func:`run_batch` plans PART, the more PARTs and each line of ``--batch FILE.jsonl`` in
turn; ``plan`` calls it for several parts. :func:`fast_main` runs the common case,
``bayesgrasp plan --batch FILE`` with problem options only, without typer and the pydantic
it validates option values with (about 0.1 s of imports and set-up a run); it hands
anything else back to the command line (``None``), which then gives its usual answer or
message. Nothing here imports typer.
"""

from __future__ import annotations

import dataclasses
import errno
import functools
import json
import math
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import BayesGraspError, NoPlanError
from .specs import (
    GoalKind,
    Method,
    PartSpec,
    ProblemSpec,
    guaranteed_plan,
    problem_spec,
    run_inputs,
)

if TYPE_CHECKING:
    from ..geometry.polygon import Part

__all__ = ["BatchFileError", "fast_main", "run_batch"]


class BatchFileError(Exception):
    """The ``--batch`` file cannot be opened (the message says why)."""


def run_batch(
    part: PartSpec,
    more: list[str],
    batch: Path | None,
    spec: ProblemSpec,
    guaranteed: bool,
    best_only: bool,
) -> int:
    """Plan each part in turn, one JSON document a line; the largest exit code of the parts.

    Each line is what ``plan PART --json`` prints for the part, as ``json.dumps`` writes it
    on one line (:func:`~bayesgrasp.io.plans.plan_document_json`); a part that fails gets
    ``{"part": ..., "error": ..., "exit_code": 2}``. Everything made once per batch is made
    before the loop: the problem's inputs, the planner, the provenance and its text.

    Raises
    ------
    BatchFileError
        The batch file cannot be opened (before its first line; PARTs are written first).
    """
    from ..io.plans import plan_document_json

    code = 0
    inputs = run_inputs(part, spec)
    # json.dumps(doc, allow_nan=False); documents are trees, so no test for cycles
    encode = json.JSONEncoder(allow_nan=False, check_circular=False).encode
    out = sys.stdout
    build, plan = _builder(spec), spec.planner(best_only)
    memo: dict[str, Any] = {}  # what the documents share (the provenance and its text)
    for label, load in _batch_parts(part, more, batch):
        try:
            pb = build(load())
            result = plan(pb)
            found = guaranteed_plan(pb) if guaranteed else None
        except BayesGraspError as exc:
            text = encode({"part": label, "error": str(exc), "exit_code": 2})
            code = 2
        else:
            sure, missing = (None, found) if isinstance(found, str) else (found, None)
            text = plan_document_json(
                result, guaranteed=sure, guaranteed_missing=missing, inputs=inputs, memo=memo
            )
            if missing is not None:
                code = max(code, 1)
        out.write(text + "\n")  # a line at a time, as typer.echo
        out.flush()
    return code


def _builder(spec: ProblemSpec) -> Any:
    """``spec.build`` for many parts: the prior, costs and goal made once (all immutable).

    When making them fails, every part is built (and fails) the usual way, in its own line.
    """
    from ..model.problem import Problem

    try:
        made = spec.problem_inputs()
    except Exception:  # any failure: each part meets it as spec.build would
        return spec.build
    return functools.partial(Problem.build, **made)


def _batch_parts(part: PartSpec, more: list[str], batch: Path | None) -> Iterator[tuple[str, Any]]:
    """(label, loader) of each part: PART, the more PARTs, then each line of ``batch``.

    A loader returns the :class:`Part` or raises a BayesGraspError with its one-line reason.
    """
    from ..errors import PartFileError
    from ..io import read_part_bytes
    from ..io.points import json_line_part

    names = ([part.part] if part.part is not None else []) + more
    for name in names:
        yield name, dataclasses.replace(part, part=name).load
    if batch is None:
        return
    stream = sys.stdin if str(batch) == "-" else None
    try:  # a byte that is not UTF-8 is kept (as a lone surrogate) for its line to report
        handle = stream or batch.open(encoding="utf-8", errors="surrogateescape")
    except OSError as exc:
        raise BatchFileError(f"cannot read {batch}: {exc.strerror or exc}") from None
    with handle:
        for number, line in enumerate(handle, start=1):
            text = line.strip()
            if not text:
                continue
            label = f"{batch}:{number}"

            def load(text: str = text, label: str = label) -> Part:
                if not text.isascii() and not _utf8(text):
                    raise PartFileError(f"{label}: not UTF-8 text; save the file as UTF-8")
                found = json_line_part(text, label)  # a part object, parsed once
                if found is not None:
                    return found
                try:
                    value = json.loads(text)
                except ValueError as exc:
                    raise PartFileError(f"{label}: not a JSON value: {exc}") from None
                if isinstance(value, str):
                    return dataclasses.replace(part, part=value).load()
                if isinstance(value, dict):  # a .json part file on one line
                    return read_part_bytes(text.encode(), "json", label)
                raise PartFileError(
                    f"{label}: expected a part object or a part name; got {type(value).__name__}"
                )

            yield label, load


def _utf8(text: str) -> bool:
    """Whether the text was read from UTF-8 (holds no byte kept as a lone surrogate)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


# The batch's own parser: a value it accepts is one typer would accept and convert to the
# same thing; anything else (another option, PART arguments, --help, a repeated option,
# a value typer might read otherwise or refuse) goes to typer. tests/cli/test_batch_fast.py
# holds the two to the same specs.
_NUMBER = re.compile(r"[0-9]{1,12}(?:\.[0-9]{1,17})?(?:[eE][-+]?[0-9]{1,2})?")
_COUNT = re.compile(r"[1-9][0-9]{0,5}")
_FLAGS = ("--guaranteed", "--json")
_CHOICES = {
    "--goal": tuple(GoalKind),
    "--method": tuple(Method),
    "--only": ("all", "best"),
}


def _cost_kinds() -> list[str] | None:
    """The kinds with cost options: the registry's, as ``plan`` would be decorated now.

    ``None`` when ``plan`` was loaded with other kinds (an action registered since): its
    options are typer's to read.
    """
    from ..model.actions import ACTIONS

    names = list(ACTIONS)
    options = sys.modules.get(f"{__package__}.options")
    made = None if options is None else options.COST_KINDS.get(f"{__package__}.plan.plan")
    return names if made is None or made == tuple(names) else None


def _options(names: list[str]) -> dict[str, str]:
    """The valued options the batch parser reads: each option and its parameter's name."""
    out = {"--batch": "batch", "--prior": "prior", "--actions": "actions"}
    out |= {"--goal": "goal", "--method": "method", "--only": "only"}
    out |= {"--accuracy": "accuracy", "--max-squeezes": "max_squeezes"}
    out |= {"--verify-cost": "verify_cost", "--retry-cost": "retry_cost"}
    out |= {f"--{n}-cost": f"cost_{i}" for i, n in enumerate(names)}
    out |= {f"--first-{n}-cost": f"first_{i}" for i, n in enumerate(names)}
    return out


def _number(text: str) -> float | None:
    """A plain decimal number, finite and >= 0 (``None``: typer decides)."""
    if _NUMBER.fullmatch(text) is None:
        return None
    value = float(text)
    return value if math.isfinite(value) else None


def parse_batch_args(args: list[str]) -> tuple[Path, ProblemSpec, bool, bool] | None:
    """``plan --batch FILE [options]`` as (file, spec, guaranteed, best only); else ``None``.

    The spec is the one ``plan`` builds from the same arguments (:func:`problem_spec`).
    """
    from ..model.cost import MAX_COST

    names = _cost_kinds()
    if not args or args[0] != "plan" or names is None:
        return None
    options = _options(names)
    given: dict[str, str] = {}
    flags: set[str] = set()
    rest = iter(args[1:])
    for arg in rest:
        name, eq, value = arg.partition("=")
        if name in _FLAGS and not eq and name not in flags:
            flags.add(name)
            continue
        if name not in options or options[name] in given:
            return None
        if not eq:
            value = next(rest, "")
        if not value or (value.startswith("-") and (value, name) != ("-", "--batch")):
            return None
        given[options[name]] = value
    if "batch" not in given:
        return None
    for key, choices in _CHOICES.items():
        if given.get(options[key], choices[0]) not in choices:
            return None
    values: dict[str, Any] = {"prior": given.get("prior"), "actions": given.get("actions")}
    values["actions"] = values["actions"] or "squeeze"
    defaults: dict[str, float | None] = {"verify_cost": 1.0, "retry_cost": 0.0}
    defaults |= {f"cost_{i}": 1.0 for i in range(len(names))}
    defaults |= {f"first_{i}": None for i in range(len(names))}
    for key, default in defaults.items():
        if key in given:  # as cost_value accepts it
            default = _number(given[key])
            if default is None or default > MAX_COST:
                return None
        values[key] = default
    accuracy = _number(given.get("accuracy", "0"))  # as accuracy_value accepts it
    count = given.get("max_squeezes")
    if accuracy is None or accuracy >= 90 or (count and _COUNT.fullmatch(count) is None):
        return None
    goal = given.get("goal")
    values |= {"goal": None if goal is None else GoalKind(goal), "accuracy": accuracy}
    values["method"] = Method(given.get("method", Method.exact.value))
    values["max_squeezes"] = None if count is None else int(count)
    spec = problem_spec(names, values)
    return Path(given["batch"]), spec, "--guaranteed" in flags, given.get("only") == "best"


def fast_main(args: list[str]) -> int | None:
    """Run ``plan --batch FILE [options]`` as the command line would; ``None``: not handled.

    Handed back (before anything is written): arguments :func:`parse_batch_args` leaves to
    typer, and a batch file that cannot be opened (typer words the usage error). The exit
    codes and messages are the command line's: 130 on an interrupt, 1 when the output pipe
    closes, ``no plan`` and ``error`` lines on stderr for the errors it reports so.
    """
    parsed = parse_batch_args(args)
    if parsed is None:
        return None
    batch, spec, guaranteed, best_only = parsed
    try:
        return run_batch(PartSpec(None), [], batch, spec, guaranteed, best_only)  # type: ignore[arg-type]
    except BatchFileError:
        return None
    except KeyboardInterrupt:
        return 130
    except OSError as exc:
        if exc.errno != errno.EPIPE:
            raise
        from typer._click.utils import PacifyFlushWrapper

        sys.stdout = PacifyFlushWrapper(sys.stdout)
        sys.stderr = PacifyFlushWrapper(sys.stderr)
        return 1
    except NoPlanError as exc:
        _say(f"bayesgrasp: no plan: {exc}")
        return 1
    except BayesGraspError as exc:
        _say(f"bayesgrasp: error: {exc}")
        return 2


def _say(text: str) -> None:
    """A line on stderr, as ``typer.echo(text, err=True)`` writes it."""
    sys.stderr.write(text + "\n")
    sys.stderr.flush()
