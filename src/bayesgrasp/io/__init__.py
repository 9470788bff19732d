"""Readers of part files; the format is chosen by the file's extension (or ``fmt``).

Formats: ``.json`` (``{"name": ..., "vertices": [[x, y], ...]}``, optional ``"units"`` and
``"center_of_mass"``) and ``.csv`` (one ``x,y`` row per point; a header row is allowed).
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

from ..errors import PartError, PartFileError
from ..geometry import Part

__all__ = ["read_part", "resolve_part"]


def _fail(path: Path, reason: str) -> PartFileError:
    return PartFileError(f"{path}: {reason}")


def _read_json(path: Path, text: str) -> Part:
    try:
        data: Any = json.loads(text)
    except json.JSONDecodeError as exc:
        raise _fail(path, f"not valid JSON ({exc.msg} at line {exc.lineno})") from None
    if isinstance(data, list):
        data = {"vertices": data}
    if not isinstance(data, dict) or "vertices" not in data:
        raise _fail(path, 'expected an object with "vertices": [[x, y], ...]')
    name = data.get("name", path.stem)
    units = data.get("units")
    if not isinstance(name, str) or (units is not None and not isinstance(units, str)):
        raise _fail(path, '"name" and "units" must be strings')
    try:
        return Part.from_points(
            data["vertices"], name=name, center_of_mass=data.get("center_of_mass"), units=units
        )
    except PartError as exc:
        raise _fail(path, str(exc)) from None


def _read_csv(path: Path, text: str) -> Part:
    rows = [r for r in csv.reader(text.splitlines()) if r and any(c.strip() for c in r)]
    pts: list[list[float]] = []
    for n, row in enumerate(rows, start=1):
        if len(row) != 2:
            raise _fail(path, f"row {n} has {len(row)} fields; expected 2 (x,y)")
        try:
            pts.append([float(row[0]), float(row[1])])
        except ValueError:
            if n == 1 and not pts:
                continue  # a header row
            raise _fail(path, f"row {n} is not two numbers: {','.join(row)!r}") from None
        if not all(math.isfinite(v) for v in pts[-1]):
            raise _fail(path, f"row {n} is not finite: {','.join(row)!r}")
    try:
        return Part.from_points(pts or [[]], name=path.stem)
    except PartError as exc:
        raise _fail(path, str(exc)) from None


READERS = {"json": _read_json, "csv": _read_csv}


def read_part(path: str | Path, fmt: str | None = None) -> Part:
    """Read a part file.

    Parameters
    ----------
    path : str or Path
    fmt : str, optional
        Format name; default from the extension.

    Raises
    ------
    PartFileError
        The file is missing, unreadable, of an unknown format, or holds no usable part.
    """
    p = Path(path)
    kind = (fmt or p.suffix.lstrip(".")).lower()
    if kind not in READERS:
        raise _fail(p, f"unknown part format {kind!r}; expected one of {sorted(READERS)}")
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise _fail(p, "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise _fail(p, f"cannot read the file ({exc})") from None
    return READERS[kind](p, text)


def resolve_part(spec: str, fmt: str | None = None) -> Part:
    """A catalogue name (see :func:`bayesgrasp.shapes.names`) or a part file.

    Examples
    --------
    >>> resolve_part("rectangle").hull.n_sides
    4
    """
    from ..shapes import load, names

    if fmt is None and spec in names():
        return load(spec)
    p = Path(spec)
    if not p.suffix and not p.exists():
        raise PartFileError(
            f"{spec!r} is neither a catalogue part ({', '.join(names())}) nor a file"
        )
    return read_part(p, fmt)
