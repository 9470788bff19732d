"""The cost model ``C`` of the seed's six-tuple (sections 3 and 4.5).

An attempt is the plan's actions plus one verification; on failure the plan is run again on
a part whose orientation is a fresh draw from the prior (the seed's model: the number of
attempts is geometric with mean ``1 / p``). Each failed verification also pays ``retry``. So

    E[cost] = attempt / p + retry * (1 / p - 1),   attempt = verify + sum of action costs.

Costs are per action *name* (:mod:`bayesgrasp.model.actions`), so a new action kind needs no
change here.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from ..errors import CostError

__all__ = ["DEFAULT_ACTION_COST", "MAX_COST", "CostModel"]

DEFAULT_ACTION_COST = 1.0
"""Cost of an action the model does not name (the seed: every squeeze costs 1)."""

MAX_COST = 1e280
"""The largest cost of one action, verification or retry. An expected cost is an attempt's
cost (a few dozen costs at most) over the success probability ``p``; with costs up to 1e280
it stays below the float limit (1.8e308) for every ``p`` above about 1e-26, where a cost of
1e308 made every expected cost infinite and the Bayes choice one among infinities. Scaling
all costs by a factor up to there leaves the Bayes plan as it is."""


def _check(name: str, value: object) -> float:
    """A finite number in ``[0, MAX_COST]``, or :class:`CostError` naming the cost."""
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or (isinstance(value, float) and not math.isfinite(value))
        or value < 0
    ):
        raise CostError(f"cost `{name}` must be a finite number >= 0; got {value!r}")
    if value > MAX_COST:
        raise CostError(
            f"cost `{name}` must be at most {MAX_COST:g} (larger costs overflow the expected "
            f"cost); got {value!r}"
        )
    return float(value)


def _frozen(costs: Mapping[str, float] | None, what: str) -> Mapping[str, float]:
    if costs is None:
        return MappingProxyType({})
    if not isinstance(costs, Mapping):
        raise CostError(f"`{what}` must map action names to costs; got {costs!r}")
    out: dict[str, float] = {}
    for name, value in costs.items():
        if not isinstance(name, str):
            raise CostError(f"`{what}` must map action names to costs; got key {name!r}")
        label = name if what == "actions" else f"first {name}"
        cost = _check(label, value)
        if what != "actions" or cost != DEFAULT_ACTION_COST:  # one spelling of each model
            out[name] = cost
    return MappingProxyType(out)


@dataclass(frozen=True, slots=True)
class CostModel:
    """Costs of actions and of the verification that ends each attempt.

    Parameters
    ----------
    actions : mapping of str to float
        Cost of each action by name (default :data:`DEFAULT_ACTION_COST` = 1 for every
        action not named, the seed's unit cost).
    verify : float
        Cost of the verification step (default 1, the seed).
    first : mapping of str to float
        Cost of an action when it is the first of an attempt (picking up the part and the
        first closing often cost more); an action not named costs as usual.
    retry : float
        Overhead paid on each failed verification (default 0).

    Examples
    --------
    >>> CostModel().expected_cost(("squeeze", "squeeze"), 0.5)
    6.0
    >>> c = CostModel({"push-grasp": 4.0}, first={"squeeze": 5.0})
    >>> c.attempt_cost(("squeeze", "push-grasp")), c.attempt_cost(("push-grasp", "squeeze"))
    (10.0, 6.0)
    """

    actions: Mapping[str, float] = field(default_factory=dict)
    verify: float = 1.0
    first: Mapping[str, float] = field(default_factory=dict)
    retry: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "actions", _frozen(self.actions, "actions"))
        object.__setattr__(self, "first", _frozen(self.first, "first"))
        object.__setattr__(self, "verify", _check("verify", self.verify))
        object.__setattr__(self, "retry", _check("retry", self.retry))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, CostModel):
            return NotImplemented
        return (dict(self.actions), self.verify, dict(self.first), self.retry) == (
            dict(other.actions),
            other.verify,
            dict(other.first),
            other.retry,
        )

    def __hash__(self) -> int:
        return hash(
            (tuple(sorted(self.actions.items())), self.verify, tuple(sorted(self.first.items())))
        )

    def action_cost(self, name: str, first: bool = False) -> float:
        """Cost of one action (``first``: as the first action of an attempt)."""
        if first and name in self.first:
            return self.first[name]
        return self.actions.get(name, DEFAULT_ACTION_COST)

    def check_positive(self, names: Iterable[str]) -> None:
        """Raise :class:`CostError` if every plan made of these actions costs nothing.

        Expected costs could not rank such plans.
        """
        names = tuple(names)
        costs = {"verify": self.verify, "retry": self.retry}
        for n in names:
            costs[n] = self.action_cost(n)
            if n in self.first:
                costs[f"first {n}"] = self.first[n]
        if not any(c > 0 for c in costs.values()):
            listed = ", ".join(f"`{k}`" for k in costs)
            raise CostError(f"at least one of the costs {listed} must be positive; got all zero")

    def attempt_cost(self, names: Iterable[str]) -> float:
        """Cost of one attempt: the actions in order, then the verification.

        Added left to right in a loop (``sum`` of floats is compensated from Python 3.12):
        the planners' running sums of the same costs must be this value bit for bit.
        """
        run = 0.0
        for i, n in enumerate(names):
            run += self.action_cost(n, i == 0)
        return self.verify + run

    def expected_cost(self, names: Iterable[str], p: float) -> float:
        """Expected cost of repeating the plan until verification succeeds (inf if p = 0)."""
        if p <= 0.0:
            return math.inf
        return self.expected_from_attempt(self.attempt_cost(names), p)

    def expected_from_attempt(self, attempt: float, p: float) -> float:
        """:meth:`expected_cost` of a plan whose :meth:`attempt_cost` is ``attempt``."""
        if p <= 0.0:
            return math.inf
        return attempt / p + self.retry * (1.0 / p - 1.0)

    def to_json(self) -> dict[str, object]:
        """The cost model as a JSON object (for documents that record their inputs)."""
        return {
            "actions": dict(self.actions),
            "verify": self.verify,
            "first": dict(self.first),
            "retry": self.retry,
        }
