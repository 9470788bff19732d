"""Reading the small files a user gives: bounded, never blocking, one clear error.

Every file the library reads on a user's behalf (part files, payoff files, prior files, plan
documents, batch files) goes through :func:`read_bytes`: only a regular file is read (a FIFO,
a device such as ``/dev/zero`` or a socket is refused unopened, so nothing blocks or reads
without end), of at most :data:`MAX_BYTES` bytes; :func:`decode_text` wants UTF-8 and
:func:`load_json` refuses numbers beyond a float and nesting deeper than :data:`MAX_NESTING`
(Python's parser recurses, and a number of 400 digits overflows a float).

Each function raises the caller's error class (a :class:`~bayesgrasp.errors.BayesGraspError`)
with a message ``"<path>: <reason>"`` on one line, and ``what`` names the kind of file.

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> from bayesgrasp.errors import PriorError
>>> with tempfile.TemporaryDirectory() as d:
...     p = Path(d) / "deep.json"
...     _ = p.write_text("[" * 200 + "]" * 200)
...     load_json(p, decode_text(p, read_bytes(p, PriorError), PriorError), PriorError)
Traceback (most recent call last):
...
bayesgrasp.errors.PriorError: .../deep.json: JSON nested deeper than the limit of 100 levels
"""

from __future__ import annotations

import errno
import json
import math
import os
import stat
from pathlib import Path
from typing import Any

from .errors import BayesGraspError

__all__ = ["MAX_BYTES", "MAX_NESTING", "decode_text", "load_json", "nesting_depth", "read_bytes"]

MAX_BYTES = 64 * 1024 * 1024
"""Largest file read, in bytes (64 MiB)."""
MAX_NESTING = 100
"""Deepest nesting of JSON arrays and objects (files need a handful of levels)."""

_KINDS = (
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def _fail(error: type[BayesGraspError], path: Path | str, reason: str) -> BayesGraspError:
    """``error("<path>: <reason>")`` on one line (a parser's reason may hold line breaks)."""
    return error(f"{path}: {' '.join(reason.split())}")


def too_large(
    error: type[BayesGraspError], path: Path | str, what: str = "file"
) -> BayesGraspError:
    """The error for a file over :data:`MAX_BYTES`."""
    return _fail(
        error,
        path,
        f"the {what} is larger than the limit of {MAX_BYTES} bytes ({MAX_BYTES / 2**20:g} MiB)",
    )


def read_bytes(path: Path | str, error: type[BayesGraspError], what: str = "file") -> bytes:
    """The file's bytes: a regular file of at most :data:`MAX_BYTES` bytes, not empty.

    The file is opened without blocking and checked before it is read, so a FIFO or a
    device is refused at once instead of blocking or reading without end.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise _fail(error, path, "no such file") from None
    except IsADirectoryError:
        raise _fail(error, path, f"cannot be read: is a directory, not a {what}") from None
    except OSError as exc:
        if exc.errno == errno.ENXIO:  # a FIFO without a writer, a socket
            raise _fail(error, path, "is not a regular file (a FIFO or a socket)") from None
        if exc.errno == errno.ENAMETOOLONG:
            raise _fail(error, str(path)[:60] + "...", "the file name is too long") from None
        raise _fail(error, path, f"cannot read the file ({exc.strerror or exc})") from None
    try:
        info = os.fstat(fd)
        mode = info.st_mode
        if stat.S_ISDIR(mode):
            raise _fail(error, path, f"cannot be read: is a directory, not a {what}")
        if not stat.S_ISREG(mode):
            kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
            raise _fail(error, path, f"is {kind}, not a regular file; give a {what}")
        if info.st_size > MAX_BYTES:  # refused unread (the loop below also stops there)
            raise too_large(error, path, what)
        chunks: list[bytes] = []
        size = 0
        while size <= MAX_BYTES:
            chunk = os.read(fd, min(1 << 20, MAX_BYTES + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise _fail(error, path, f"cannot read the file ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > MAX_BYTES:
        raise too_large(error, path, what)
    if not data.strip():
        raise _fail(error, path, "the file is empty")
    return data


def decode_text(path: Path | str, data: bytes, error: type[BayesGraspError]) -> str:
    """The bytes as UTF-8 text (a byte-order mark is allowed)."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise _fail(
            error,
            path,
            f"not UTF-8 text (byte {exc.start} is 0x{data[exc.start]:02x}); save the file as "
            "UTF-8, or check the format",
        ) from None


class _NumberTooLarge(ValueError):
    """A JSON number beyond the range of a float."""


def json_int(text: str) -> int:
    """A JSON integer, refused (``ValueError``) beyond 300 digits."""
    # Python refuses to convert more than 4300 digits to an int (ValueError), and a float
    # cannot hold more than 308: no value a user gives has such numbers.
    if len(text.lstrip("-")) > 300:
        raise _NumberTooLarge(f"a number of {len(text.lstrip('-'))} digits")
    return int(text)


def json_float(text: str) -> float:
    """A JSON float, refused (``ValueError``) beyond the range of a float."""
    value = float(text)
    if math.isinf(value):
        shown = text if len(text) <= 60 else text[:60] + "..."
        raise _NumberTooLarge(f"the number {shown!r}")
    return value


def nesting_depth(data: Any) -> int:
    """Depth of nested lists and dicts (iterative: safe on any depth)."""
    if not isinstance(data, dict | list):
        return 0
    deepest = 0
    stack: list[tuple[dict[str, Any] | list[Any], int]] = [(data, 1)]
    while stack:
        item, depth = stack.pop()
        deepest = max(deepest, depth)
        children = item.values() if isinstance(item, dict) else item
        stack.extend((c, depth + 1) for c in children if isinstance(c, dict | list))
    return deepest


def load_json(
    path: Path | str, text: str, error: type[BayesGraspError], numbers: str = "numbers"
) -> Any:
    """Parse JSON text; malformed, too deeply nested or oversized numbers are errors.

    ``numbers`` names what the numbers are in the message (``"coordinates"`` for a part).
    """
    try:
        data = json.loads(text, parse_int=json_int, parse_float=json_float)
    except _NumberTooLarge as exc:
        raise _fail(
            error, path, f"{numbers} too large: {exc} is beyond the range of a float"
        ) from None
    except json.JSONDecodeError as exc:
        raise _fail(error, path, f"not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except RecursionError:
        raise _fail(
            error, path, f"JSON nested deeper than the limit of {MAX_NESTING} levels"
        ) from None
    except ValueError as exc:  # a number the parser cannot convert
        raise _fail(error, path, f"not valid JSON ({str(exc)[:120]})") from None
    if nesting_depth(data) > MAX_NESTING:
        raise _fail(error, path, f"JSON nested deeper than the limit of {MAX_NESTING} levels")
    return data
