"""Plans and plan results: what every planner returns.

A plan is a sequence of steps. Step 1 is made with the gripper at ``steps[0].alpha`` in the
world frame; before step ``i > 1`` the gripper turns by ``steps[i].alpha`` (counter-clockwise)
relative to the previous step, so the part at ``theta`` in the old gripper frame is at
``theta - alpha`` in the new one (design.md). A verification step follows the last action.

Every planner returns a :class:`PlanResult`: the plans it found (:class:`PlanOption`, which
satisfies the :class:`Plan` protocol), which of them is the Bayes plan and which the most
certain, and a ``status``: ``"ok"``, or ``"no-plan"`` with the ``reason`` (no plan reached
the goal asked for is a result, not an exception; style.md).

This module also holds what the planners share about plans: the gripper turns reported in
their shortest form (:func:`short_turns`), the choice of the Bayes and most certain plans
(:func:`choose_indices`) and the bound on plan lengths (:func:`max_plan_length`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import NoPlanError, PlanningError
from ..model.actions import Action
from ..model.problem import Problem
from ..tolerance import DEFAULT_TOLERANCE

__all__ = [
    "COST_RTOL",
    "Plan",
    "PlanOption",
    "PlanReport",
    "PlanResult",
    "PlanStep",
    "Status",
    "check_max_actions",
    "choose_among",
    "choose_indices",
    "execute_plan",
    "max_plan_length",
    "new_option",
    "new_result",
    "plan_actions",
    "short_turns",
]

Status = Literal["ok", "no-plan"]
"""A result's status: ``"ok"`` (it holds plans) or ``"no-plan"`` (none reached the goal)."""

COST_RTOL = 1e-12
"""Two expected costs closer than this (relative) tie: the plan with fewer actions wins."""


@dataclass(frozen=True, slots=True)
class PlanStep:
    """One action: rotate the gripper by ``alpha`` (radians), then act (``kind``).

    ``kind`` is the action's name (:attr:`bayesgrasp.model.actions.Action.name`).
    """

    kind: str
    alpha: float


@runtime_checkable
class Plan(Protocol):
    """What every plan tells: its actions, where the part ends, how likely and how costly.

    :class:`PlanOption` (a linear plan: the same actions whatever happens) satisfies it.

    Room for a tree: a *policy* whose nodes branch on readings (the seed's section 6.2,
    jaw-width sensing; :mod:`bayesgrasp.planning.policy`) shares ``success_probability``
    and ``expected_cost`` (over its branches) but has no single sequence of steps nor one
    final orientation. When results carry policies this protocol splits in two: a base of
    what any plan has (``n_actions`` as the longest path, ``success_probability``,
    ``expected_cost``) and the linear plan's ``steps``, ``final_orientation`` and
    ``tolerance``; code typed against ``Plan`` today keeps working with linear plans.

    Examples
    --------
    >>> opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    >>> isinstance(opt, Plan)
    True
    """

    @property
    def steps(self) -> tuple[PlanStep, ...]:
        """The actions in order (angles as in the module notes)."""
        ...

    @property
    def n_actions(self) -> int:
        """Number of actions."""
        ...

    @property
    def final_orientation(self) -> float:
        """The goal orientation of the part in the frame of the last action (radians)."""
        ...

    @property
    def success_probability(self) -> float:
        """Probability that the part ends at the goal."""
        ...

    @property
    def expected_cost(self) -> float:
        """Expected cost of repeating the plan until verification succeeds."""
        ...

    @property
    def tolerance(self) -> float | None:
        """Error every relative turn may have at once and keep the plan's success."""
        ...


@dataclass(frozen=True, slots=True)
class PlanOption:
    """The best plan with a given number of actions.

    Attributes
    ----------
    steps : tuple of PlanStep
        ``steps[0].alpha`` is the world gripper angle of the first action; ``steps[i].alpha``
        (i >= 1) the turn of the gripper relative to the previous action, in
        ``(-g/2, g/2]`` for an action of gripper period ``g`` (:func:`short_turns`: a squeeze
        gripper turned by pi is the same gripper).
    final_orientation : float
        The goal orientation of the part in the frame of the last action (radians, in
        ``[0, 2 pi)``).
    success_probability : float
        Probability that the part ends at the goal (or, for a symmetry goal, one of its
        symmetric copies).
    expected_cost : float
        Expected cost of repeating the plan until verification succeeds.
    tolerance : float or None
        Every relative turn ``alpha_2..alpha_k`` may be off by less than this, all at once and
        with any signs, and every orientation of ``success_arc`` still ends at the goal
        (the exact planner: the largest such margin of any plan with this probability).
        ``None`` for a single action.
    success_arc : tuple of float
        An open arc ``(lo, hi)`` of initial world orientations that the plan sends to the goal.
    """

    steps: tuple[PlanStep, ...]
    final_orientation: float
    success_probability: float
    expected_cost: float
    tolerance: float | None
    success_arc: tuple[float, float]

    @property
    def n_actions(self) -> int:
        """Number of actions (squeezes and push-grasps)."""
        return len(self.steps)

    @property
    def first_angle(self) -> float:
        """World gripper angle of the first action."""
        return self.steps[0].alpha

    @property
    def alphas(self) -> tuple[float, ...]:
        """Relative rotations before actions 2..k."""
        return tuple(s.alpha for s in self.steps[1:])

    @property
    def kinds(self) -> tuple[str, ...]:
        """Action type of each step."""
        return tuple(s.kind for s in self.steps)


@dataclass(frozen=True, slots=True, eq=False)
class PlanResult:
    """What a planner found for one problem: plans of every length up to the most certain.

    Attributes
    ----------
    problem : Problem
    options : tuple of PlanOption
        The exact and breadth-first planners: ``options[k - 1]`` is the best plan with ``k``
        actions (possibly one more, see :func:`~bayesgrasp.planning.exact.plan_exact`). The
        guaranteed planner: its one plan. Empty when ``status`` is ``"no-plan"``.
    bayes : int
        Index of the plan of least expected cost (ties go to fewer actions).
    most_certain : int
        Index of the shortest plan with the highest attainable success probability.
    method : str
        ``"exact"``, ``"bfs"`` or ``"guaranteed"``.
    nodes : int or None
        Hyperstates generated (breadth-first baseline only).
    status : {"ok", "no-plan"}
        ``"no-plan"``: no plan reached the goal asked for (``options`` is empty).
    reason : str or None
        Why there is no plan (``None`` when ``status`` is ``"ok"``).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.planning import plan
    >>> res = plan(Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])))
    >>> res.status, res.reason, res.method, res.bayes_plan.n_actions
    ('ok', None, 'exact', 1)
    """

    problem: Problem
    options: tuple[PlanOption, ...]
    bayes: int
    most_certain: int
    method: str
    nodes: int | None = None
    status: Status = "ok"
    reason: str | None = None

    @property
    def ok(self) -> bool:
        """Whether the result holds plans (``status == "ok"``)."""
        return self.status == "ok"

    def _plan(self, index: int) -> PlanOption:
        if self.status != "ok":
            raise NoPlanError(self.reason or "no plan")
        return self.options[index]

    @property
    def bayes_plan(self) -> PlanOption:
        """The plan of least expected cost.

        Raises
        ------
        NoPlanError
            If ``status`` is ``"no-plan"`` (the message is the ``reason``).
        """
        return self._plan(self.bayes)

    @property
    def most_certain_plan(self) -> PlanOption:
        """The shortest plan with the highest success probability.

        Raises
        ------
        NoPlanError
            If ``status`` is ``"no-plan"`` (the message is the ``reason``).
        """
        return self._plan(self.most_certain)

    def best_only(self) -> PlanResult:
        """The same result with only the Bayes and the most certain plans.

        In order of length, one when they are the same: what ``plan_exact(...,
        report="best")`` gives.

        Examples
        --------
        >>> from bayesgrasp.geometry.polygon import Part
        >>> from bayesgrasp.planning import plan
        >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
        >>> res = plan(Problem.build(rect)).best_only()
        >>> [o.n_actions for o in res.options], res.bayes, res.most_certain
        ([2], 0, 0)
        """
        if self.status != "ok":
            return self
        keep = sorted({self.bayes, self.most_certain})
        return dataclasses.replace(
            self,
            options=tuple(self.options[i] for i in keep),
            bayes=keep.index(self.bayes),
            most_certain=keep.index(self.most_certain),
        )


PlanReport = PlanResult
"""The former name of :class:`PlanResult`."""


def check_max_actions(max_actions: object) -> None:
    """Refuse a bound on plan lengths that is not an integer >= 1 (``None``: no bound).

    Examples
    --------
    >>> check_max_actions(2), check_max_actions(None)
    (None, None)
    >>> check_max_actions(0)
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.PlanningError: `max_actions` must be an integer >= 1; got 0
    """
    if max_actions is not None and (
        isinstance(max_actions, bool) or not isinstance(max_actions, int) or max_actions < 1
    ):
        raise PlanningError(f"`max_actions` must be an integer >= 1; got {max_actions!r}")


def max_plan_length(problem: Problem) -> int:
    """The most actions a planner tries before it gives up: ``4 n + 8`` for an n-gon hull.

    Goldberg 1993 bounds plans by O(n) (Chen and Ierardi: ``2 n - 1`` squeezes); the
    planners never get near this bound, which only stops a search on a degenerate part.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> max_plan_length(Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])))
    24
    """
    return 4 * problem.part.hull.n_sides + 8


def choose_indices(
    options: tuple[PlanOption, ...], tol: float = DEFAULT_TOLERANCE.probability
) -> tuple[int, int]:
    """Indices of the Bayes plan (least cost, ties to fewer actions) and the most certain.

    Costs tie within a relative :data:`COST_RTOL` (so the choice does not depend on the cost
    units: costs of 1e-13 are ranked as costs of 1); when every cost is infinite the plan of
    fewest actions is chosen. Probabilities tie within ``tol``
    (:attr:`bayesgrasp.tolerance.Tolerance.probability`).

    Examples
    --------
    >>> opts = [PlanOption((PlanStep("squeeze", 0.0),), 0.0, p, c, None, (0.0, 1.0))
    ...         for p, c in [(0.3, 6.0), (0.5, 6.0), (0.5, 7.0)]]
    >>> choose_indices(tuple(opts))
    (0, 1)
    """
    return choose_among(
        [o.expected_cost for o in options], [o.success_probability for o in options], tol
    )


def choose_among(
    costs: Sequence[float], probs: Sequence[float], tol: float = DEFAULT_TOLERANCE.probability
) -> tuple[int, int]:
    """:func:`choose_indices` from the plans' expected costs and success probabilities.

    Examples
    --------
    >>> choose_among([6.0, 6.0, 7.0], [0.3, 0.5, 0.5])
    (0, 1)
    """
    if not costs:
        raise ValueError("no plans to choose among")
    # Loops, not min/max and generators: the exact planner calls this for every part. The
    # values are floats (or numpy's, which compare and subtract as floats do).
    m = math.inf
    for c in costs:
        if c < m:
            m = c
    bayes = 0
    if math.isfinite(m):
        slack = COST_RTOL * abs(m)
        while costs[bayes] - m > slack:
            bayes += 1
    top = -math.inf
    for q in probs:
        if q > top:
            top = q
    top -= tol
    most = 0
    while not probs[most] >= top:
        most += 1
    return bayes, most


def plan_actions(problem: Problem, kinds: Iterable[str]) -> tuple[Action, ...]:
    """The problem's :class:`~bayesgrasp.model.actions.Action` of each action name.

    Raises
    ------
    PlanningError
        If a name is not one of the problem's actions.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> [a.tag for a in plan_actions(pb, ["squeeze", "squeeze"])]
    ['S', 'S']
    """
    by_name = {a.name: a for a in problem.actions}
    try:
        return tuple(by_name[k] for k in kinds)
    except KeyError as exc:
        known = ", ".join(problem.action_kinds)
        raise PlanningError(
            f"action {exc.args[0]!r} is not one of this problem's ({known})"
        ) from None


def short_turns(actions: Sequence[Action], angles: Sequence[float]) -> tuple[list[PlanStep], float]:
    """Steps with each gripper angle in its shortest form, and the turn of the final frame.

    ``angles[m]`` is the turn (or, for ``m = 0``, the world angle) before ``actions[m]``.
    An action of gripper period ``g`` (:attr:`~bayesgrasp.model.actions.Action.gripper_period`)
    made with the gripper turned by ``g`` is the same action: a squeeze gripper turned by pi
    is the same gripper with its jaws swapped. The part then lies ``g`` further round in its
    frame, and stays so after the action (``s(theta + pi) = s(theta) + pi``). So each angle
    is reported in ``(-g/2, g/2]`` and the rest of the turn is carried into the next angle
    (or, after the last action, the final orientation). A push-grasp (``g = 2 pi``) has a
    pushing side, so its angle only wraps into ``(-pi, pi]``.

    Returns
    -------
    steps : list of PlanStep
    carry : float
        How much further round (0 or a multiple of pi) the part lies in the last frame than
        the unshortened angles would leave it: add it to the final orientation.

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.model.actions import PUSH_GRASP, SQUEEZE
    >>> steps, carry = short_turns([SQUEEZE, PUSH_GRASP], [math.radians(100), 0.0])
    >>> [round(math.degrees(s.alpha), 6) for s in steps], round(math.degrees(carry), 6)
    ([-80.0, 180.0], 0.0)
    """
    steps = []
    carry = 0.0  # how much further round the part lies in the current frame
    remainder, pi = math.remainder, math.pi
    for action, angle in zip(actions, angles, strict=True):
        # The gripper's turn in (-pi, pi] (angles.wrap), then within the gripper's period
        # (angles.wrap_period): the same angle as the gripper sees it.
        r = remainder(angle + carry, TWO_PI)
        a = pi if r == -pi else r
        g = action.gripper_period
        r = remainder(a, g)
        short = g / 2.0 if r == -g / 2.0 else r
        carry = a - short  # 0, or +-pi for a period of pi
        step = _new(PlanStep)
        _set_kind(step, action.name)
        _set_alpha(step, short)
        steps.append(step)
    return steps, carry


# The planners make thousands of steps, options and results a second; a frozen dataclass's
# __init__ sets each field through object.__setattr__, about twice the cost of setting its
# slots directly. short_turns, new_option and new_result make the same objects (none of the
# classes has a __post_init__; tests/planning/test_small.py checks them against their
# constructors).
_new = object.__new__
_set_kind, _set_alpha = (vars(PlanStep)[name].__set__ for name in ("kind", "alpha"))
_set_option = [vars(PlanOption)[name].__set__ for name in PlanOption.__slots__]


def slot_setters(cls: type[PlanStep | PlanOption | PlanResult]) -> list[Callable[[Any, Any], None]]:
    """The setters of the fields of a plan step, option or result, in field order.

    For a planner that makes these objects in its own loop, as :func:`short_turns` does:
    ``object.__new__(cls)``, then every field set.
    """
    return _SETTERS[cls]


def new_option(
    steps: tuple[PlanStep, ...],
    final_orientation: float,
    success_probability: float,
    expected_cost: float,
    tolerance: float | None,
    success_arc: tuple[float, float],
) -> PlanOption:
    """The same object as ``PlanOption(...)`` of these fields, for the planners' loops."""
    out = _new(PlanOption)
    a, b, c, d, e, f = _set_option
    a(out, steps)
    b(out, final_orientation)
    c(out, success_probability)
    d(out, expected_cost)
    e(out, tolerance)
    f(out, success_arc)
    return out


_set_result = [vars(PlanResult)[name].__set__ for name in PlanResult.__slots__]
_SETTERS: dict[type, list[Callable[[Any, Any], None]]] = {
    PlanStep: [_set_kind, _set_alpha],
    PlanOption: _set_option,
    PlanResult: _set_result,
}


def new_result(
    problem: Problem,
    options: tuple[PlanOption, ...],
    bayes: int,
    most_certain: int,
    method: str,
) -> PlanResult:
    """The same object as ``PlanResult(problem, options, bayes, most_certain, method)``."""
    out = _new(PlanResult)
    a, b, c, d, e, f, g, h = _set_result
    a(out, problem)
    b(out, options)
    c(out, bayes)
    d(out, most_certain)
    e(out, method)
    f(out, None)
    g(out, "ok")
    h(out, None)
    return out


def execute_plan(
    problem: Problem, steps: tuple[PlanStep, ...] | list[PlanStep], initial: ArrayLike
) -> NDArray[np.float64]:
    """Run a plan through the transfer functions from initial world orientations (vectorised).

    Returns the part's orientation in the frame of the last action, in ``[0, 2 pi)``.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> out = execute_plan(pb, [PlanStep("squeeze", 0.0)], [0.1, 1.0])
    >>> np.degrees(out).round(6).tolist()
    [0.0, 90.0]
    """
    theta = np.asarray(initial, dtype=np.float64)
    for step in steps:
        theta = problem.transfers[step.kind](theta - step.alpha)
    return np.mod(theta, TWO_PI)
