"""Staircases: the best least margin of the actions left, for each span arriving.

``tau(x)`` of an action (see :mod:`bayesgrasp.planning.arcs`, "Witness chains and
staircases") as the Pareto front of its arcs' (width, later margin) pairs
(:class:`Staircase`); the same steps on plain Python floats for a few states
(:func:`tau_lists`, :func:`pick_entry`, :func:`stair_lists`, :func:`staircase_python`).
:func:`~bayesgrasp.planning.arcs.staircase` chooses between them.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .fronts import Arc, ArcFront

__all__ = [
    "ROUNDING",
    "Staircase",
    "pick_entry",
    "stair_lists",
    "staircase_python",
    "tau_lists",
]

FloatArray = NDArray[np.float64]

# The lengths admit a margin above ``accuracy`` by ``span < L - 2 accuracy``, the staircases
# compute it as ``(L - span) / 2``: these may differ by rounding, and the witness chain must
# exist whenever the lengths allow it.
ROUNDING = 1e-13


@dataclass(frozen=True, slots=True, eq=False)
class Staircase:
    """``tau(x)`` of one action: the best least margin of it and the actions after it.

    Entry ``r`` is arc ``index[r]`` of ``front``, with ``rest[r]`` the least margin of the
    later actions after that arc. Entries are sorted by ``rest`` decreasing, with widths
    strictly increasing: the Pareto front of (width, rest). With ``c = width - 2 rest``
    (non-decreasing), ``tau(x)`` is attained at the first entry with ``c >= x`` (value
    ``rest``) or at the one before it (value ``(width - x) / 2``). Build it with
    :func:`staircase`.
    """

    front: ArcFront
    index: NDArray[np.intp]
    rest: FloatArray
    width: FloatArray
    c: FloatArray
    c_list: list[float]
    tol: float
    accuracy: float
    rest_list: list[float] = field(default_factory=list)
    width_list: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        if len(self.rest_list) != len(self.c_list):
            object.__setattr__(self, "rest_list", self.rest.tolist())
            object.__setattr__(self, "width_list", self.width.tolist())

    def tau_list(self, xs: list[float]) -> list[float]:
        """:meth:`tau` in plain Python floats (the same operations, for a few spans)."""
        return tau_lists(self.c_list, self.rest_list, self.width_list, self.tol, self.accuracy, xs)

    def tau(self, x: FloatArray) -> FloatArray:
        """Best least margin for images of spans ``x`` (``-inf`` where none fits)."""
        n = len(self.rest)
        r = np.searchsorted(self.c, x, side="left")  # (M,) first entry with c >= x
        at = np.where(r < n, self.rest[np.minimum(r, n - 1)], -np.inf)
        before = np.where(r > 0, 0.5 * (self.width[np.maximum(r - 1, 0)] - x), -np.inf)
        value = np.maximum(at, before)
        ok = (value > self.tol) & (value >= self.accuracy - ROUNDING)
        return np.asarray(np.where(ok, value, -np.inf), dtype=np.float64)

    def pick(self, x: float) -> Arc:
        """The arc that attains ``tau(x)`` for one span ``x``."""
        r = pick_entry(self.c_list, self.rest_list, self.width_list, x)
        return self.front.arc(int(self.index[r]))


def tau_lists(
    c: list[float],
    rest: list[float],
    width: list[float],
    tol: float,
    accuracy: float,
    xs: list[float],
) -> list[float]:
    """:meth:`Staircase.tau` of the staircase ``(c, rest, width)`` on plain Python floats.

    With ``r`` the first entry with ``c >= x``: the larger of ``rest[r]`` (``-inf`` past
    the last) and ``(width[r - 1] - x) / 2`` (``-inf`` before the first), then ``-inf``
    unless above ``tol`` and at least ``accuracy`` (less the rounding slack).
    """
    inf = math.inf
    n = len(c)
    floor = accuracy - ROUNDING
    left = bisect.bisect_left
    out: list[float] = []
    add = out.append
    for x in xs:
        r = left(c, x)
        at = rest[r] if r < n else -inf
        before = 0.5 * (width[r - 1] - x) if r > 0 else -inf
        value = at if at >= before else before
        add(value if value > tol and value >= floor else -inf)
    return out


def pick_entry(c: list[float], rest: list[float], width: list[float], x: float) -> int:
    """The entry of the staircase ``(c, rest, width)`` that attains ``tau(x)``."""
    r = bisect.bisect_left(c, x)
    at = rest[r] if r < len(c) else -math.inf
    before = 0.5 * (width[r - 1] - x) if r > 0 else -math.inf
    return r if at >= before else r - 1


def staircase_python(
    front: ArcFront, after: Staircase | None, tol: float, accuracy: float
) -> Staircase:
    """:func:`staircase` in plain Python floats for a small front (:func:`stair_lists`)."""
    values = None if after is None else after.tau_list(front.span_list)
    idx, rest, width, c = stair_lists(front.span_list, front.width_list, values, tol)
    return Staircase(
        front,
        np.array(idx, dtype=np.intp),
        np.array(rest, dtype=np.float64),
        np.array(width, dtype=np.float64),
        np.array(c, dtype=np.float64),
        c,
        tol,
        accuracy,
        rest,
        width,
    )


def stair_lists(
    spans: list[float], widths: list[float], values: list[float] | None, tol: float
) -> tuple[list[int], list[float], list[float], list[float]]:
    """Front index, rest, width and ``c`` of a staircase's entries, step for step.

    ``values`` is the next action's ``tau`` at each arc of the front (``None``: this is the
    last action, and only single basins count). The entries are what :func:`staircase`
    keeps, ``pareto_front(-rest, width)`` of the arcs with ``rest > tol``: since the front's
    widths increase with the index, that is every arc whose rest exceeds the rest of each
    wider arc, found by one scan from the widest down, and already in the front's order
    (rest decreasing, widths increasing). For the last action every single basin has rest
    ``inf``: the widest of them (the front's spans increase from 0, so they come first).
    """
    if values is None:
        n = bisect.bisect_right(spans, 0.0)  # the arcs of span <= 0: single basins
        if n == 0:
            return [], [], [], []
        return [n - 1], [math.inf], [widths[n - 1]], [widths[n - 1] - 2.0 * math.inf]
    idx: list[int] = []
    rest: list[float] = []
    best = -math.inf
    for n in range(len(values) - 1, -1, -1):
        v = values[n]
        if v > tol and v > best:
            best = v
            idx.append(n)
            rest.append(v)
    idx.reverse()
    rest.reverse()
    width: list[float] = []
    c: list[float] = []
    for n, r in zip(idx, rest, strict=True):
        w = widths[n]
        width.append(w)
        c.append(w - 2.0 * r)
    return idx, rest, width, c
