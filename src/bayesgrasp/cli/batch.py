"""``plan`` of many parts in one process: one JSON document a line, errors in their line.

:func:`run_batch` plans PART, the more PARTs and each line of ``--batch FILE.jsonl`` in
turn; ``plan`` calls it for several parts.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import BayesGraspError
from .specs import (
    PartSpec,
    ProblemSpec,
    guaranteed_plan,
    run_inputs,
)

if TYPE_CHECKING:
    from ..geometry.polygon import Part

__all__ = ["BatchFileError", "run_batch"]


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
