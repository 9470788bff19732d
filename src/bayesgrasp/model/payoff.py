"""Payoff: a value in [0, 1] per final stable orientation (the seed, section 6.4).

The seed: "[we could] include a utility or payoff function on the state space ... for example
a measure of grasp quality". The goal of today is the payoff that is 1 on one state (the one
the plan ends at) and 0 elsewhere. With a payoff ``u`` the plan's attempt ends in state ``j``
(in the frame of its last action, as the plan reports it) with probability ``P_j`` and earns
``u_j``; the objective is the expected cost per unit of payoff,

    E[cycle cost] / E[payoff],   E[payoff] = sum_j P_j u_j,
    E[cycle cost] = attempt + retry * (1 - E[payoff]),

which is :meth:`~bayesgrasp.model.cost.CostModel.expected_cost` with ``E[payoff]`` in place
of the success probability: for a 0/1 payoff it is today's expected cost (a retry overhead
is paid on each failure, here in proportion to the payoff missed).

A payoff file lists orientations in degrees (the stable orientations ``bayesgrasp plan`` and
``bayesgrasp squeeze`` print) with their values; states not listed get ``default`` (0 unless
given). JSON::

    {"payoff": {"80.63": 1.0, "260.63": 0.4}, "default": 0.0}

or a list ``[{"orientation_deg": 80.63, "value": 1.0}, ...]`` under ``"payoff"``; CSV::

    orientation_deg,value
    80.63,1.0
    260.63,0.4

Each listed orientation must lie within :data:`MATCH_DEG` of a stable orientation of the
part, and no two may name the same one.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI, circle_distance
from ..errors import PlanningError
from ..files import decode_text, load_json, read_bytes

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.transfer import TransferFunction

__all__ = ["MATCH_DEG", "Payoff", "PayoffError", "read_payoff"]

MATCH_DEG = 0.05
"""A listed orientation names the stable orientation within this many degrees of it (tables
print two decimals)."""


class PayoffError(PlanningError, ValueError):
    """A payoff that cannot be used (the message names the file or the entry)."""


def _value(x: object, where: str) -> float:
    if isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x):
        raise PayoffError(f"payoff {where} must be a number in [0, 1]; got {x!r}")
    if not 0.0 <= x <= 1.0:
        raise PayoffError(f"payoff {where} must be in [0, 1]; got {x!r}")
    return float(x)


@dataclass(frozen=True, slots=True, eq=False)
class Payoff:
    """Values in [0, 1] of final stable orientations.

    Parameters
    ----------
    orientations : array_like of shape (M,)
        Final orientations (radians, in the frame of the last action).
    values : array_like of shape (M,)
        Their payoffs, in [0, 1].
    default : float
        Payoff of every state not listed.
    name : str
        Where it came from (for reports).

    Raises
    ------
    PayoffError
        Values out of [0, 1], mismatched lengths or no positive payoff anywhere.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part, squeeze_function
    >>> s = squeeze_function(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).hull)
    >>> Payoff([np.pi / 2], [1.0], default=0.25).vector(s).tolist()
    [0.25, 1.0, 0.25, 0.25]
    """

    orientations: NDArray[np.float64]
    values: NDArray[np.float64]
    default: float = 0.0
    name: str = "payoff"

    def __post_init__(self) -> None:
        o = np.asarray(self.orientations, dtype=np.float64).ravel()
        v = np.asarray(self.values, dtype=np.float64).ravel()
        if len(o) != len(v):
            raise PayoffError(f"payoff needs one value per orientation; got {len(o)} and {len(v)}")
        if not np.all(np.isfinite(o)):
            raise PayoffError("payoff orientations must be finite")
        for i, x in enumerate(v.tolist()):
            _value(x, f"value #{i + 1}")
        default = _value(self.default, "`default`")
        if not (np.any(v > 0) or default > 0):
            raise PayoffError("a payoff must be positive somewhere; got all zero")
        for arr in (o, v):
            arr.setflags(write=False)
        object.__setattr__(self, "orientations", np.mod(o, TWO_PI))
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "default", default)

    @classmethod
    def one_state(cls, orientation: float) -> Payoff:
        """Payoff 1 on one final orientation and 0 elsewhere: the seed's single goal."""
        return cls(np.array([orientation]), np.array([1.0]), 0.0, "one state")

    def vector(self, states: TransferFunction) -> NDArray[np.float64]:
        """The payoff of each state, shape (K,).

        Raises
        ------
        PayoffError
            A listed orientation farther than :data:`MATCH_DEG` from every state, or two
            naming the same state.
        """
        stable = np.asarray(states.stable)
        out = np.full(len(stable), self.default)
        if len(self.orientations) == 0:
            return out
        dist = circle_distance(self.orientations[:, None], stable[None, :])  # (M, K)
        idx = np.argmin(dist, axis=1)
        far = dist[np.arange(len(idx)), idx] > math.radians(MATCH_DEG)
        if np.any(far):
            bad = math.degrees(float(self.orientations[np.flatnonzero(far)[0]]))
            known = ", ".join(f"{math.degrees(x):.2f}" for x in stable)
            raise PayoffError(
                f"payoff orientation {bad:.4f} deg is not a stable orientation of the part "
                f"(within {MATCH_DEG} deg); the stable orientations are {known}"
            )
        if len(np.unique(idx)) != len(idx):
            raise PayoffError("payoff names the same stable orientation twice")
        out[idx] = self.values
        return out

    def to_json(self, states: TransferFunction | None = None) -> dict[str, Any]:
        """The payoff as JSON (per state too when ``states`` is given)."""
        doc: dict[str, Any] = {
            "name": self.name,
            "orientations_rad": self.orientations.tolist(),
            "values": self.values.tolist(),
            "default": self.default,
        }
        if states is not None:
            doc["state_values"] = self.vector(states).tolist()
        return doc


def _entries_json(doc: Any, name: str) -> tuple[list[float], list[float], float]:
    if not isinstance(doc, dict) or "payoff" not in doc:
        raise PayoffError(f"payoff file {name!r} must be a JSON object with a 'payoff' member")
    unknown = set(doc) - {"payoff", "default"}
    if unknown:
        raise PayoffError(f"payoff file {name!r} has unknown member(s) {sorted(unknown)}")
    body = doc["payoff"]
    degs: list[float] = []
    vals: list[float] = []
    if isinstance(body, dict):
        for key, value in body.items():
            try:
                degs.append(float(key))
            except ValueError:
                raise PayoffError(
                    f"payoff file {name!r}: key {key!r} must be an orientation in degrees"
                ) from None
            vals.append(_value(value, f"of {key} deg"))
    elif isinstance(body, list):
        for i, item in enumerate(body):
            if not isinstance(item, dict) or set(item) != {"orientation_deg", "value"}:
                raise PayoffError(
                    f"payoff file {name!r}: entry #{i + 1} must be "
                    '{"orientation_deg": DEG, "value": V}'
                )
            deg = item["orientation_deg"]
            if isinstance(deg, bool) or not isinstance(deg, int | float):
                raise PayoffError(f"payoff file {name!r}: entry #{i + 1} needs a number of degrees")
            degs.append(float(deg))
            vals.append(_value(item["value"], f"entry #{i + 1}"))
    else:
        raise PayoffError(f"payoff file {name!r}: 'payoff' must be an object or a list")
    return degs, vals, _value(doc.get("default", 0.0), "`default`")


def _entries_csv(text: str, name: str) -> tuple[list[float], list[float], float]:
    try:
        rows = [r for r in csv.reader(io.StringIO(text)) if any(c.strip() for c in r)]
    except csv.Error as exc:  # a field over the csv module's limit (128 KiB), a stray NUL
        raise PayoffError(f"payoff file {name!r} is not valid CSV ({exc})") from None
    if rows and [c.strip().lower() for c in rows[0]] == ["orientation_deg", "value"]:
        rows = rows[1:]
    degs: list[float] = []
    vals: list[float] = []
    for i, row in enumerate(rows):
        try:
            if len(row) != 2:
                raise ValueError
            deg, val = float(row[0]), float(row[1])
        except ValueError:
            raise PayoffError(
                f"payoff file {name!r}: line {i + 1} must be ORIENTATION_DEG,VALUE; got {row!r}"
            ) from None
        degs.append(deg)
        vals.append(_value(val, f"on line {i + 1}"))
    if not degs:
        raise PayoffError(f"payoff file {name!r} lists no orientation")
    return degs, vals, 0.0


def read_payoff(path: str | Path) -> Payoff:
    r"""Read a payoff file (JSON, or CSV ``orientation_deg,value``; by the extension).

    Raises
    ------
    PayoffError
        The file cannot be read or is not a valid payoff.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "u.csv"
    ...     _ = p.write_text("orientation_deg,value\n90,1\n")
    ...     read_payoff(p).values.tolist()
    [1.0]
    """
    p = Path(path)
    if p.suffix.lower() not in (".json", ".csv"):
        raise PayoffError(f"payoff file {p.name!r} must end in .json or .csv")
    text = decode_text(p, read_bytes(p, PayoffError, "payoff file"), PayoffError)
    if p.suffix.lower() == ".json":
        degs, vals, default = _entries_json(load_json(p, text, PayoffError), p.name)
    else:
        degs, vals, default = _entries_csv(text, p.name)
    if not all(math.isfinite(d) for d in degs):
        raise PayoffError(f"payoff file {p.name!r}: orientations must be finite")
    return Payoff(np.radians(degs), np.asarray(vals, dtype=np.float64), default, p.name)


def as_vector(payoff: Payoff | ArrayLike, states: TransferFunction) -> NDArray[np.float64]:
    """A payoff, or an array of K values, as a (K,) vector (validated)."""
    if isinstance(payoff, Payoff):
        return payoff.vector(states)
    v = np.asarray(payoff, dtype=np.float64).ravel()
    if len(v) != states.n_states:
        raise PayoffError(f"a payoff vector needs {states.n_states} values; got {len(v)}")
    for i, x in enumerate(v.tolist()):
        _value(x, f"value #{i + 1}")
    if not np.any(v > 0):
        raise PayoffError("a payoff must be positive somewhere; got all zero")
    return v
