"""``plan`` of many parts in one process: one JSON document a line, errors in their line.

:func:`run_batch` plans PART, the more PARTs and each line of ``--batch FILE.jsonl`` in
turn; ``plan`` calls it for several parts. :func:`run_policy_batch` plans each line's
sensing policy (``plan --batch FILE.jsonl --sense S``).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from ..errors import BayesGraspError
from .specs import PartSpec, ProblemSpec, SenseSpec, run_inputs

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..io.export import Stroke
    from ..planning.strategy import StrategyResult
    from .outputs import PartOutputs
    from .sensing import ActionModel
    from .strategies import StrategyRun

__all__ = ["BatchFileError", "run_batch", "run_policy_batch"]


class BatchFileError(Exception):
    """The ``--batch`` file cannot be opened (the message says why)."""


#: Parts planned together, stage by stage (:func:`run_batch`). On the study's 2000 hulls,
#: warm, against one part at a time: 8 parts 10% less CPU, 16 18%, 32 and 64 21%, 128 20%.
GROUP = 32


def run_batch(
    part: PartSpec,
    more: list[str],
    batch: Path | None,
    run: StrategyRun,
    *,
    outputs: PartOutputs | None = None,
    stroke: Stroke | None = None,
) -> int:
    """Plan each part in turn, one JSON document a line; the largest exit code of the parts.

    Each line is what ``plan PART --json`` prints for the part, as ``json.dumps`` writes it
    on one line (:func:`~bayesgrasp.io.plans.plan_document_json`); a part that fails gets
    ``{"part": ..., "error": ..., "exit_code": 2}``. What the parts share is made once: the
    problem's inputs and the planner before the loop, the provenance by the first document.

    The parts are planned in groups of up to :data:`GROUP`, stage by stage: every part of a
    group read, then every problem built, every plan made, every document written. The
    same work in another order, and the same lines, but each stage's code and data stay in
    the processor's caches: about 20% less time than one part at a time. A group ends early at
    a part of more than ``sizes.SMALL`` hull vertices (or a curved part), so at most one
    large problem is held at a time; lines read from standard input are planned one at a
    time (each answered as it comes, for a program that writes a line and waits). A failure
    that is not a bad part (a bug) makes the group planned again one part at a time, so the
    lines before it are written before it is raised.

    ``run``: how each part is planned (:class:`~.strategies.StrategyRun`: the problem
    options, ``--only best``, ``--guaranteed``, the noise and payoff options), each line
    what ``plan PART --json`` prints with them. ``outputs``: each part's ``--plot``
    and ``--export`` files (:class:`~.outputs.PartOutputs`, a path template); a part whose
    file is refused or cannot be written gets an error line instead of its document. With
    noise, files or ``stroke`` (the gripper's stroke: a part whose Bayes plan needs an
    opening outside it gets an error line, :func:`~bayesgrasp.io.export.check_stroke`), the
    parts are planned one at a time (:func:`_one_at_a_time`).

    Raises
    ------
    BatchFileError
        The batch file cannot be opened (before its first line; PARTs are written first).
    """
    from ..geometry.polygon import Part as PlainPart
    from ..io.plans import strategy_document_json
    from ..sizes import SMALL

    spec = run.spec
    inputs = run_inputs(part, spec)
    # json.dumps(doc, allow_nan=False); documents are trees, so no test for cycles
    encode = json.JSONEncoder(allow_nan=False, check_circular=False).encode
    out = sys.stdout
    if run.noisy or outputs is not None or stroke is not None:
        stage = _one_at_a_time(run, inputs, outputs, encode, stroke)
        return _each_alone(_batch_parts(part, more, batch), stage, encode, out)
    build, planned = _builder(spec), run.solve
    memo: dict[str, Any] = {}  # what the documents share (the provenance)

    def document(result: StrategyResult) -> _Line:
        text = strategy_document_json(result, inputs=inputs, memo=memo)
        return text, 0 if result.guaranteed_missing is None else 1

    stages = (build, planned, document)
    size = 1 if batch is not None and str(batch) == "-" else GROUP
    code = 0
    group: list[tuple[str, Any]] = []  # (label, its part, or the error that stopped it)
    for label, load in _batch_parts(part, more, batch):
        try:
            found = load()
        except BayesGraspError as exc:
            found = exc
        except Exception:  # a bug: the lines before it first
            if group:
                _finish(group, stages, encode, out, code)
            raise
        group.append((label, found))
        large = isinstance(found, PlainPart) and (
            type(found) is not PlainPart or found.hull.n_sides > SMALL
        )
        if len(group) >= size or large:
            code, group = _finish(group, stages, encode, out, code), []
    return _finish(group, stages, encode, out, code) if group else code


_Line = tuple[str, int]  # a document's text and its exit code


def _finish(
    group: list[tuple[str, Any]],
    stages: tuple[Callable[[Any], Any], ...],
    encode: Callable[[Any], str],
    out: TextIO,
    code: int,
) -> int:
    """Plan the group's parts stage by stage and write their lines; the largest exit code.

    Each value goes through the stages in turn; a BayesGraspError takes its part out, its
    line the error. Any other exception (a bug) in a group of several: the group again a
    part at a time, so the lines before the failing part are written before it is raised.
    """
    values = [found for _, found in group]
    try:
        for stage in stages:
            for i, value in enumerate(values):
                if not isinstance(value, BayesGraspError):
                    try:
                        values[i] = stage(value)
                    except BayesGraspError as exc:
                        values[i] = exc
    except Exception:
        if len(group) == 1:
            raise
        for one in group:
            code = _finish([one], stages, encode, out, code)
        raise  # (the failing part raised again above, unless it failed only once)
    text = []
    for (label, _), value in zip(group, values, strict=True):
        if isinstance(value, BayesGraspError):
            line = encode({"part": label, "error": str(value), "exit_code": 2}), 2
        else:
            line = value
        text.append(line[0] + "\n")
        code = max(code, line[1])
    out.write("".join(text))  # a group at a time (a line at a time from stdin)
    out.flush()
    return code


def _each_alone(
    parts: Iterator[tuple[str, Any]],
    stage: Callable[[tuple[int, str, Part]], _Line],
    encode: Callable[[Any], str],
    out: TextIO,
) -> int:
    """Each part's line, one part at a time: ``stage((index, label, part))`` or its error.

    ``parts``: (label, loader) pairs (:func:`_batch_parts`); the index counts from 1.
    Returns the largest exit code of the lines.
    """
    code = 0
    for index, (label, load) in enumerate(parts, start=1):
        try:
            found: Any = (index, label, load())
        except BayesGraspError as exc:
            found = exc
        code = _finish([(label, found)], (stage,), encode, out, code)
    return code


def _one_at_a_time(
    run: StrategyRun,
    inputs: dict[str, Any],
    outputs: PartOutputs | None,
    encode: Callable[[Any], str],
    stroke: Stroke | None = None,
) -> Callable[[tuple[int, str, Part]], _Line]:
    """The one stage of a part planned with noise or with files: its line.

    The same document as the single-part run (:func:`~.strategies.document`); a file refused
    or not written makes the line an error (exit code 2), as the single run exits 2.
    """
    import typer

    from .common import input_files
    from .strategies import check_stroke, document, exit_code, write_outputs

    build = _builder(run.spec)

    def stage(item: tuple[int, str, Part]) -> _Line:
        index, label, found = item
        try:
            if outputs is not None:
                outputs.check(found.name, index, input_files(label))
            result = run.solve(build(found))
            check_stroke(result, stroke)
            text = encode(document(result, inputs))
            if outputs is not None:
                write_outputs(outputs, index, result)
        except typer.BadParameter as exc:  # a file refused: this part's error
            return _refused(label, exc, encode)
        return text, exit_code(result)

    return stage


def _refused(label: str, exc: Any, encode: Callable[[Any], str]) -> _Line:
    """The error line of a part whose file was refused (a ``typer.BadParameter``)."""
    hint = f"{exc.param_hint}: " if isinstance(exc.param_hint, str) else ""
    return encode({"part": label, "error": hint + exc.message, "exit_code": 2}), 2


def run_policy_batch(
    part: PartSpec,
    batch: Path,
    spec: ProblemSpec,
    sensing: SenseSpec,
    *,
    outputs: PartOutputs | None = None,
    stroke: Stroke | None = None,
    fold: float | None = None,
    noise: ActionModel | None = None,
) -> int:
    """Plan each line's sensing policy, one policy document a line; the largest exit code.

    Each line is what ``plan PART --sense S --json`` prints for the line's part (with the
    same --also parts, part prior and depth), as ``json.dumps`` writes it on one line; a part
    that fails gets ``{"part": ..., "error": ..., "exit_code": 2}`` and the others go on.
    The --also parts are read and the sensor checked once, before the first line (a bad one
    is the run's error, exit 2). ``part`` gives the part-file options (its PART is
    ``None``); ``outputs``, ``stroke``: as :func:`run_batch`; ``fold``: the figures' folding
    (:func:`~.strategies.write_outputs`); ``noise``: the action noise and payoff each policy is
    planned under (:class:`~.sensing.ActionModel`). The parts are planned one at a time.

    Raises
    ------
    BatchFileError
        The batch file cannot be opened.
    """
    import typer

    from ..model.sensing import parse_sensor
    from .common import input_files
    from .sensing import sensing_run
    from .strategies import check_stroke, document, write_outputs

    parse_sensor(sensing.sense)  # a malformed sensor: the run's one error line
    others = [dataclasses.replace(part, part=p).load() for p in sensing.also]
    encode = json.JSONEncoder(allow_nan=False, check_circular=False).encode
    run = sensing_run(spec, sensing, noise, len(others) + 1)

    def stage(item: tuple[int, str, Part]) -> _Line:
        index, label, found = item
        try:
            if outputs is not None:
                outputs.check(found.name, index, input_files(label))
            result = run.solve_parts([found, *others])
            check_stroke(result, stroke)
            text = encode(document(result))
            if outputs is not None:
                write_outputs(outputs, index, result, fold)
        except typer.BadParameter as exc:  # a file refused: this part's error
            return _refused(label, exc, encode)
        return text, 0

    return _each_alone(_batch_parts(part, [], batch), stage, encode, sys.stdout)


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
    if stream is None:
        _regular(batch)
    try:  # a byte that is not UTF-8 is kept (as a lone surrogate) for its line to report
        handle = stream or batch.open(encoding="utf-8", errors="surrogateescape")
    except OSError as exc:
        raise BatchFileError(f"cannot read {batch}: {exc.strerror or exc}") from None
    lines = 0
    with handle:
        for number, line in enumerate(handle, start=1):
            text = line.strip()
            if not text:
                continue
            lines += 1
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
                except RecursionError:
                    raise PartFileError(f"{label}: JSON nested too deeply") from None
                if isinstance(value, str):
                    return dataclasses.replace(part, part=value).load()
                if isinstance(value, dict):  # a .json part file on one line
                    return read_part_bytes(text.encode(), "json", label)
                raise PartFileError(
                    f"{label}: expected a part object or a part name; got {type(value).__name__}"
                )

            yield label, load
    if not lines:
        where = "standard input" if stream is not None else str(batch)
        raise BatchFileError(f"{where} holds no part (every line is empty)")


def _regular(batch: Path) -> None:
    """Refuse a batch file that is not a regular file, before it can block or read forever."""
    import stat

    try:
        mode = batch.stat().st_mode
    except FileNotFoundError:
        raise BatchFileError(f"cannot read {batch}: no such file") from None
    except OSError as exc:
        raise BatchFileError(f"cannot read {batch}: {exc.strerror or exc}") from None
    if stat.S_ISDIR(mode):
        raise BatchFileError(f"{batch} is a folder, not a batch file")
    if not stat.S_ISREG(mode):
        raise BatchFileError(
            f"{batch} is not a regular file (a FIFO, device or socket): to stream lines, "
            "pipe them into --batch -"
        )


def _utf8(text: str) -> bool:
    """Whether the text was read from UTF-8 (holds no byte kept as a lone surrogate)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True
