"""The bounds of a policy search (time, memory) and its best answer so far when one is reached.

A policy search (:func:`~bayesgrasp.planning.policy.plan_policy`, and under noisy actions
:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`) keeps the beliefs it acts on
and may run long: it stops with :class:`SearchStopped` past ``max_memory_mb`` (about, the
memory of its kept beliefs) or ``time_limit_s``. :func:`deepest_within_bounds` is what both
planners do then: plan again one action deeper at a time from one, within the same bounds
once more, and answer with the deepest policy that finished, saying that the search stopped
(:attr:`~bayesgrasp.planning.policy_tree.Policy.stopped`), how many actions were asked for
and a lower bound on the cost of every policy of that many.

Examples
--------
>>> time_seconds(2), memory_bytes(1)
(2.0, 1048576)
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable

from ..errors import PlanningError
from .policy_tree import Policy

__all__ = [
    "DEFAULT_MAX_MEMORY_MB",
    "DEFAULT_TIME_LIMIT_S",
    "SearchStopped",
    "check_deadline",
    "deepest_within_bounds",
    "memory_bytes",
    "time_seconds",
]

DEFAULT_MAX_MEMORY_MB = 2048.0
"""Default bound on the memory of the beliefs a policy search keeps (their images, readings)."""

DEFAULT_TIME_LIMIT_S = 60.0
"""Default bound on the seconds of a policy search (then once more for the fallback)."""


class SearchStopped(PlanningError):
    """A policy search reached its time or memory bound (``reason`` says which)."""

    def __init__(self, reason: str) -> None:
        super().__init__(
            f"the policy search stopped: {reason}; raise the bound, or plan fewer actions"
        )
        self.reason = reason

    @classmethod
    def out_of_time(cls, seconds: float) -> SearchStopped:
        """The search ran past its bound of ``seconds``."""
        return cls(
            f"it ran for {seconds:g} s (the time bound: --time-limit S, "
            "`time_limit_s` in the library)"
        )

    @classmethod
    def out_of_memory(cls, max_bytes: int) -> SearchStopped:
        """The search's kept beliefs took more than ``max_bytes``."""
        return cls(
            f"its beliefs took more than {max_bytes / 2**20:,.0f} MB (the memory "
            "bound: --max-memory MB, `max_memory_mb` in the library)"
        )


def check_deadline(deadline: float, seconds: float) -> None:
    """Raise :meth:`SearchStopped.out_of_time` past ``deadline`` (``time.monotonic()``).

    ``seconds``: the bound the deadline allows (for the message).
    """
    if time.monotonic() > deadline:
        raise SearchStopped.out_of_time(seconds)


def time_seconds(time_limit_s: float | None) -> float:
    """The time bound in seconds (``None``: none), or a PlanningError.

    Examples
    --------
    >>> time_seconds(2), time_seconds(None)
    (2.0, inf)
    """
    if time_limit_s is None:
        return math.inf
    if (
        isinstance(time_limit_s, bool)
        or not isinstance(time_limit_s, int | float)
        or not 0 < time_limit_s < 1e9
    ):
        raise PlanningError(f"`time_limit_s` must be a number of seconds > 0; got {time_limit_s!r}")
    return float(time_limit_s)


def memory_bytes(max_memory_mb: float) -> int:
    """The bound in bytes of ``max_memory_mb`` (a number > 0), or a PlanningError.

    Examples
    --------
    >>> memory_bytes(1.5)
    1572864
    """
    if (
        isinstance(max_memory_mb, bool)
        or not isinstance(max_memory_mb, int | float)
        or not 0 < max_memory_mb < 2**40
    ):
        raise PlanningError(f"`max_memory_mb` must be a number of MB > 0; got {max_memory_mb!r}")
    return max(1, int(max_memory_mb * 2**20))


def deepest_within_bounds(
    attempt: Callable[[int, float], Policy],
    max_actions: int,
    seconds: float,
    lower_bound: Callable[[], float],
    *,
    best_so_far: bool = True,
    complete_bound: Callable[[Policy], float] = lambda pol: math.nan,
) -> Policy:
    """The best policy of ``max_actions``, or the deepest that finishes within the bounds.

    ``attempt(depth, deadline)`` plans the best policy of at most ``depth`` actions and
    raises :class:`SearchStopped` past ``time.monotonic() > deadline`` or its memory bound.
    First ``attempt(max_actions, now + seconds)``: when it finishes its policy is the answer
    (with ``lower_bound = complete_bound(policy)``: the planner's own optimum, or ``nan``
    where the planner proves none). When it stops and ``best_so_far``, the depths ``1, 2,
    ...`` are planned again within one more ``seconds`` (the bound counts from the fallback's
    start) until one stops; the deepest that finished is the answer, with
    :attr:`Policy.stopped` the reason of the first stop, :attr:`Policy.requested_actions`
    ``max_actions`` and :attr:`Policy.lower_bound` ``lower_bound()``.

    Raises
    ------
    SearchStopped
        The first search stopped and ``best_so_far`` is false, ``max_actions`` is 1, or
        the search of one action stopped too.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
    >>> def attempt(depth, deadline):
    ...     if depth > 1:
    ...         raise SearchStopped("a stand-in for a bound")
    ...     return plan_policy(tri, "width", depth)
    >>> pol = deepest_within_bounds(attempt, 3, 1.0, lambda: 0.5)
    >>> pol.max_actions, pol.requested_actions, pol.stopped, pol.lower_bound
    (1, 3, 'a stand-in for a bound', 0.5)
    """
    try:
        pol = attempt(max_actions, time.monotonic() + seconds)
        return dataclasses.replace(pol, lower_bound=complete_bound(pol))
    except SearchStopped as exc:
        stop = exc
    if not best_so_far or max_actions == 1:
        raise stop
    # The best answer so far: the deepest search that finishes within the bounds again.
    deadline = time.monotonic() + seconds
    best: Policy | None = None
    for depth in range(1, max_actions):
        try:
            best = attempt(depth, deadline)
        except SearchStopped:
            break
    if best is None:
        raise SearchStopped(f"{stop.reason}, and so did the search of one action") from None
    return dataclasses.replace(
        best, stopped=stop.reason, requested_actions=max_actions, lower_bound=lower_bound()
    )
