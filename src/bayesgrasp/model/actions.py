"""Actions as values: what a gripper can do, and the registry of the kinds.

An action (the seed's ``A``, section 3) is a gripper rotation ``alpha`` followed by a motion
of the jaws. Each kind is one frozen :class:`Action`: its name (used in costs, plans and
documents), the one-letter tag of tables, its *transfer function* on orientations (built from
the part and its squeeze function), the period of its gripper angle, and what it reads. The
planners, reports, execution and simulation read these attributes; adding a kind is one
:func:`register_action` call (the documentation's architecture page).

Every action here ends with the jaws closed on the part, so it ends in a stable orientation
of the squeeze function (the states of the problem) and reads the jaw separation there.

Examples
--------
>>> get_action("push-grasp").tag, get_action("push-grasp").gripper_period == TWO_PI
('P', True)
>>> [a.name for a in parse_actions("squeeze, push-grasp")]
['squeeze', 'push-grasp']
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

from ..errors import PlanningError

TWO_PI = math.tau  # bayesgrasp.angles.TWO_PI (2 pi, the same float) without importing numpy

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.polygon import Part
    from ..geometry.transfer import TransferFunction

__all__ = [
    "ACTIONS",
    "PUSH_GRASP",
    "SQUEEZE",
    "Action",
    "get_action",
    "parse_actions",
    "register_action",
    "unregister_action",
]

TransferBuilder = Callable[["Part", "TransferFunction"], "TransferFunction"]


@dataclass(frozen=True, slots=True)
class Action:
    """One kind of gripper action.

    Attributes
    ----------
    name : str
        Name in costs, plans, documents and the CLI's ``--actions`` (lower case, no commas).
    tag : str
        One letter for tables (``S`` squeeze, ``P`` push-grasp).
    gripper_period : float
        Smallest turn of the gripper that gives the same action: ``pi`` for a squeeze (the
        jaws are alike), ``2 pi`` for a push-grasp (one jaw pushes first).
    pushes_first : bool
        Whether the jaw on the gripper's -x side moves alone first (a push) before the
        squeeze: how a simulation drives the jaws.
    reads : str or None
        What the action measures when it ends: ``"width"``, the jaw separation (the part's
        diameter at the stable orientation it ends in).
    description : str
        One line for help texts.
    build : callable
        ``build(part, squeeze)`` returns the action's transfer function on orientations in
        the gripper frame (a non-decreasing step function ending in squeeze-stable
        orientations), given the part and its squeeze function.
    """

    name: str
    tag: str
    gripper_period: float
    pushes_first: bool
    reads: str | None
    description: str
    build: TransferBuilder

    def __post_init__(self) -> None:
        if not self.name or "," in self.name or self.name != self.name.strip().lower():
            raise PlanningError(
                f"an action's `name` must be lower case without commas; got {self.name!r}"
            )
        if len(self.tag) != 1:
            raise PlanningError(f"an action's `tag` must be one character; got {self.tag!r}")
        if not any(math.isclose(self.gripper_period, p) for p in (math.pi, TWO_PI)):
            raise PlanningError(
                f"an action's `gripper_period` must be pi or 2 pi; got {self.gripper_period!r}"
            )


def _squeeze(part: Part, squeeze: TransferFunction) -> TransferFunction:
    """A squeeze's transfer function is the squeeze function itself."""
    return squeeze


def _push_grasp(part: Part, squeeze: TransferFunction) -> TransferFunction:
    """The push-grasp function of the part (imported on use: it needs the radius function)."""
    from ..geometry.curved import CurvedPart, curved_push_grasp
    from ..geometry.push import push_grasp_function

    if isinstance(part, CurvedPart):  # the exact radius function of its arcs and curves
        return curved_push_grasp(part, squeeze)
    return push_grasp_function(part, squeeze)


SQUEEZE = Action(
    name="squeeze",
    tag="S",
    gripper_period=math.pi,
    pushes_first=False,
    reads="width",
    description="both jaws close at once; the part turns down its diameter function",
    build=_squeeze,
)
PUSH_GRASP = Action(
    name="push-grasp",
    tag="P",
    gripper_period=TWO_PI,
    pushes_first=True,
    reads="width",
    description="the -x jaw pushes first (the part turns about its centre of mass), then a squeeze",
    build=_push_grasp,
)

_REGISTRY: dict[str, Action] = {a.name: a for a in (SQUEEZE, PUSH_GRASP)}
ACTIONS: Mapping[str, Action] = MappingProxyType(_REGISTRY)
"""Every known action kind by name (read-only; add one with :func:`register_action`)."""


def register_action(action: Action) -> Action:
    """Add an action kind to the registry and return it.

    Raises
    ------
    PlanningError
        If another action of that name or tag is registered.
    """
    for known in _REGISTRY.values():
        if known == action:
            return action
        if known.name == action.name or known.tag == action.tag:
            raise PlanningError(
                f"an action named {known.name!r} with tag {known.tag!r} is registered already"
            )
    _REGISTRY[action.name] = action
    return action


def unregister_action(name: str) -> None:
    """Remove an action kind added with :func:`register_action` (the built-ins stay).

    Raises
    ------
    PlanningError
        If ``name`` is a built-in action.
    """
    if name in (SQUEEZE.name, PUSH_GRASP.name):
        raise PlanningError(f"the built-in action {name!r} cannot be removed")
    _REGISTRY.pop(name, None)


def get_action(name: str | Action) -> Action:
    """The action of a name (an :class:`Action` is returned as it is).

    Raises
    ------
    PlanningError
        If no action of that name is registered.
    """
    if isinstance(name, Action):
        return name
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        known = ", ".join(repr(n) for n in _REGISTRY)
        raise PlanningError(f"unknown action {name!r}; expected one of {known}") from None


def parse_actions(spec: str | Iterable[str | Action]) -> tuple[Action, ...]:
    """Actions from a comma-separated list of names (or names / actions), duplicates dropped.

    Raises
    ------
    PlanningError
        If the list is empty or names an unknown action.
    """
    items = spec.split(",") if isinstance(spec, str) else list(spec)
    names = [i.strip() if isinstance(i, str) else i for i in items]
    actions = tuple(dict.fromkeys(get_action(n) for n in names if n != ""))
    if not actions:
        raise PlanningError("at least one action type is needed")
    return actions
