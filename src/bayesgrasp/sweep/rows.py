"""A sweep's rows: the part file a task gets, the columns of its row, and error rows.

A row holds one part (or one resting pose of a mesh) and the options it was planned with;
:data:`ROW_COLUMNS` lists its columns. A part that cannot be read or planned is a row too,
its error class and message in it (:func:`error_row`).
"""

from __future__ import annotations

import os
import socket
from dataclasses import dataclass, field
from typing import Any

from .options import SweepOptions

__all__ = [
    "MAX_OUTLINE_POINTS",
    "ROW_COLUMNS",
    "PartSource",
    "empty_row",
    "error_row",
    "part_id",
]


@dataclass(frozen=True, slots=True)
class PartSource:
    """One part file as the client sends it: its path, and its bytes or not.

    Attributes
    ----------
    path : str
        The path as the sweep found it (relative paths are relative to the client's working
        directory); the row's ``path`` and the name in error messages.
    sha256 : str
        Hex digest of the bytes the client hashed (``""`` when it could not read them).
    data : bytes, optional
        The file's bytes (for workers that do not share the client's file system); without
        them the worker reads ``path``.
    """

    path: str
    sha256: str = ""
    data: bytes | None = field(default=None, repr=False)

    @property
    def size(self) -> int:
        """Bytes sent (0 for a path)."""
        return 0 if self.data is None else len(self.data)


def part_id(path: str, sha256: str) -> str:
    """The stable id of a part: its path and the first 16 hex digits of its hash.

    Examples
    --------
    >>> part_id("parts/a.json", "0123456789abcdef0123")
    'parts/a.json#0123456789abcdef'
    """
    return f"{path}#{sha256[:16]}"


#: The columns of a row, in order, with their types (``str``, ``int``, ``float``, ``bool``);
#: every column may be missing (``None``), as for a part that failed.
ROW_COLUMNS: tuple[tuple[str, type], ...] = (
    ("part_id", str),
    ("path", str),
    ("sha256", str),
    ("options_key", str),
    ("status", str),  # ok | no-plan (no guaranteed plan: `plan` exits 1) | error
    ("error_class", str),
    ("error_message", str),
    ("name", str),
    ("units", str),
    ("sides", int),
    ("symmetry_order", int),
    ("states", int),
    ("period_rad", float),
    ("method", str),
    ("plans", int),
    ("bayes_actions", int),
    ("bayes_cost", float),
    ("bayes_probability", float),
    ("bayes_tolerance_rad", float),
    ("bayes_first_rad", float),
    ("bayes_final_rad", float),
    ("bayes_steps", str),  # JSON: [{"type": ..., "alpha_rad": ...}, ...]
    ("most_certain_actions", int),
    ("most_certain_probability", float),
    ("guaranteed_actions", int),
    ("guaranteed_missing", str),
    ("sim_engine", str),
    ("sim_trials", int),
    ("sim_predicted", float),
    ("sim_observed", float),
    ("sim_ci_low", float),
    ("sim_ci_high", float),
    ("sim_p_value", float),
    ("sim_jams", int),
    ("sim_seconds", float),
    ("plan_seconds", float),
    ("policy_cost", float),  # with `sense`: the Bayes policy's expected cost
    ("policy_success", float),
    ("policy_actions", float),  # expected actions a cycle
    ("policy_json", str),  # the document `bayesgrasp plan PATH --sense ... --json` prints
    ("outline", str),  # JSON: the outline's points (for the report's drawings)
    ("plan_json", str),  # the document `bayesgrasp plan PATH --json` prints
    ("sim_json", str),  # the document `bayesgrasp simulate PATH --json` prints
    ("worker", str),
    # last, so that results files written before them still resume
    ("turn_noise", str),  # `normal:SIGMA_DEG` / `uniform:A_DEG`, as given
    ("contact_noise", float),
    ("payoff", str),  # the payoff file
    ("bayes_payoff", float),  # the Bayes plan's expected payoff (with noise or a payoff)
    ("pose", int),  # a mesh's rows: the resting pose (0 the most probable), as `poses` lists
    ("pose_probability", float),  # its quasi-static probability
)

#: Most outline points a row keeps for drawing (evenly spaced beyond that).
MAX_OUTLINE_POINTS = 2000


def empty_row(path: str, sha256: str, options: SweepOptions) -> dict[str, Any]:
    """A row of ``path`` with only its identity, the options and the worker filled in."""
    row: dict[str, Any] = dict.fromkeys(name for name, _ in ROW_COLUMNS)
    row.update(
        part_id=part_id(path, sha256),
        path=path,
        sha256=sha256 or None,  # None: the bytes could not be read
        options_key=options.key,
        worker=f"{socket.gethostname()}:{os.getpid()}",
        turn_noise=options.turn_noise,
        contact_noise=options.contact_noise,
        payoff=options.payoff,
    )
    return row


def error_row(row: dict[str, Any], exc: BaseException) -> dict[str, Any]:
    """Fill the error columns: the class and the message the CLI prints, on one line."""
    row["status"] = "error"
    row["error_class"] = type(exc).__name__
    text = " ".join(str(exc).split("\n")).strip() or repr(exc)
    row["error_message"] = text
    return row
