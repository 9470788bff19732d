"""The planning problem: the seed's six-tuple <Theta, f_1, A, G, C, theta*> (section 3).

- ``Theta`` (states): the stable orientations of the squeeze function (section 4.3); every
  action ends in one of them (:mod:`.states`), and the diameter there is what the gripper
  reads (:attr:`Problem.widths`).
- ``f_1`` (prior): a :class:`~bayesgrasp.model.prior.Prior` on the initial orientation; the
  distribution over states after the first action is the prior mass of each basin.
- ``A`` (actions): gripper rotations ``alpha`` followed by an :class:`~.actions.Action`.
  For each action the continuum of angles falls into finitely many classes with the same
  effect on the states (section 4.4: at most n^2 for squeezes), see :class:`ActionClasses`.
  The gripper's ``accuracy`` (radians, default 0) bounds the error of each relative rotation
  ``alpha_2..alpha_k``: a planner that honours it returns only plans that keep their success
  under any errors of less than ``accuracy`` on every turn (plan tolerance >= accuracy).
- ``G`` (transfer): each action class is a row-stochastic (K, K) transition matrix over the
  states (:meth:`ActionClasses.matrix`; one-hot for today's deterministic actions, so a noisy
  action is another matrix, not another code path), built from the action's transfer
  function on orientations (:meth:`Problem.transfer`).
- ``C`` (cost): a :class:`~.cost.CostModel`.
- ``theta*`` (goal): a :class:`~.goal.Goal`: one final orientation (the seed), or the set of
  orientations equivalent under the part's rotational symmetry.

The pieces are separate values so that sensing, noisy actions or payoffs replace one of them
without touching the others. Everything a planner needs is built with the problem or
computed on first use inside it; callers never prepare anything.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..geometry.curved import CurvedDiameter, squeeze_model
from ..geometry.diameter import DiameterFunction
from ..geometry.polygon import Part
from ..geometry.transfer import TransferFunction
from ..sizes import SMALL
from .actions import SQUEEZE, Action, get_action, parse_actions
from .cost import CostModel
from .goal import Goal
from .prior import Prior, UniformPrior
from .states import nearest_state

__all__ = [
    "ActionClasses",
    "CostModel",
    "Goal",
    "Problem",
    "action_classes",
    "critical_angles",
    "nearest_state",
]

_BLOCK = 1 << 16  # entries of the (classes, K) blocks that action_classes makes at a time


@dataclass(frozen=True, slots=True, eq=False)
class ActionClasses:
    """The finitely many classes of gripper rotations of one action type (the seed, 4.4).

    Rotating the gripper by ``alpha`` and acting sends state ``i`` (stable orientation
    ``S_i``) to ``F(S_i - alpha)``; the result changes only where ``S_i - alpha`` crosses a
    basin boundary ``B_j``, i.e. at ``alpha = S_i - B_j``. Between consecutive such angles
    every rotation is equivalent.

    Attributes
    ----------
    kind : str
    lo, hi, mid : ndarray of shape (A,)
        Each class's open interval of rotations and its middle.
    transfer : ndarray of shape (A, K)
        ``transfer[a, i]`` is the state reached from state ``i`` by class ``a``.
    """

    kind: str
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    mid: NDArray[np.float64]
    transfer: NDArray[np.intp]

    @property
    def n_classes(self) -> int:
        """Number of classes ``A``."""
        return len(self.lo)

    def matrix(self, a: int) -> NDArray[np.float64]:
        """The row-stochastic (K, K) transition matrix of class ``a``.

        Entry ``(i, j)`` is the probability that state ``i`` ends in state ``j``: one-hot rows
        for a deterministic action (``transfer[a, i]``); a noisy action spreads them.

        Examples
        --------
        >>> from bayesgrasp.geometry import Part
        >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
        >>> m = pb.transition("squeeze").matrix(0)
        >>> m.shape, m.sum(axis=1).tolist()
        ((4, 4), [1.0, 1.0, 1.0, 1.0])
        """
        k = self.transfer.shape[1]
        m = np.zeros((k, k))
        m[np.arange(k), self.transfer[a]] = 1.0
        return m


def action_classes(
    states: TransferFunction, action: TransferFunction, gripper_period: float
) -> ActionClasses:
    """Enumerate the action classes of ``action`` acting on the states of ``states``.

    ``gripper_period`` is the action's :attr:`~.actions.Action.gripper_period`: ``pi`` for
    a squeeze (the gripper turned by pi is the same gripper) and ``2 pi`` for a push-grasp
    (the pushing jaw is on one side).
    """
    s = states.stable
    lo = critical_angles(states, action, gripper_period)
    hi = np.append(lo[1:], lo[0] + gripper_period)
    mid = 0.5 * (lo + hi)
    # A is up to K^2 / 4 for a squeeze, so the table is O(K^3): made a block of classes at a
    # time, and nearest_state (a (.., K) array per angle) runs on the block's distinct
    # orientations only (the action's stable orientations, and the rare angle it leaves at
    # a basin boundary), not on all A K of them (A K^2 floats: 1.8 GB at K = 174).
    k = len(s)
    if len(mid) * k * k <= _BLOCK:  # a small part: at once
        transfer = nearest_state(states, action(s[None, :] - mid[:, None]))
        return ActionClasses(action.kind, lo, hi, mid, transfer)
    transfer = np.empty((len(mid), k), dtype=np.intp)
    rows = max(1, _BLOCK // k)
    for i in range(0, len(mid), rows):
        after = action(s[None, :] - mid[i : i + rows, None])  # (rows, K) orientations after
        values, inverse = np.unique(after, return_inverse=True)
        transfer[i : i + rows] = nearest_state(states, values)[inverse].reshape(after.shape)
    return ActionClasses(action.kind, lo, hi, mid, transfer)


def critical_angles(
    states: TransferFunction, action: TransferFunction, gripper_period: float
) -> NDArray[np.float64]:
    """Gripper rotations where the effect of ``action`` on the states changes, increasing.

    The lower ends of the classes of :func:`action_classes` (so their number is ``A``):
    the angles ``S_i - B_j`` modulo ``gripper_period``, those closer than the angle
    tolerance merged. Takes K K_t floats, where the classes' table takes A K integers.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part, squeeze_function
    >>> s = squeeze_function(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).hull)
    >>> np.degrees(critical_angles(s, s, math.pi)).round(6).tolist()
    [26.565051, 63.434949, 116.565051, 153.434949]
    """
    s = states.stable
    crit = np.unique(np.mod((s[:, None] - action.boundaries[None, :]).ravel(), gripper_period))
    # Merge critical angles closer than the angle tolerance: no rotation fits between them.
    tol = states.angle_tol
    if len(crit) > 1:
        keep = np.append(True, np.diff(crit) > tol)
        if gripper_period - crit[-1] + crit[0] <= tol:
            keep[0] = len(crit) == 1
        crit = crit[keep]
    return np.asarray(crit, dtype=np.float64)


# The defaults of Problem.build, made once: they are frozen values (the study builds 2000
# problems with them). The default cost's verification costs 1, so no plan of any actions
# costs nothing under it (CostModel.check_positive).
_DEFAULT_ACTIONS = parse_actions(("squeeze",))
_DEFAULT_COST = CostModel()
_DEFAULT_PRIOR = UniformPrior()
_DEFAULT_GOAL = Goal()


def shared_defaults(inputs: Mapping[str, Any]) -> dict[str, Any]:
    """The keywords of :meth:`Problem.build`, with build's own default objects where equal.

    A prior, cost or goal equal to its default and written alike (a -0.0 cost is not 0.0) is
    replaced by the shared default: the same problem, built quicker, since build need not
    check its default cost. For callers that make their keywords once for many parts.
    """
    out = dict(inputs)
    for key, default in (
        ("prior", _DEFAULT_PRIOR),
        ("cost", _DEFAULT_COST),
        ("goal", _DEFAULT_GOAL),
    ):
        value = out.get(key)
        if value is not None and value == default and repr(value) == repr(default):
            out[key] = default
    return out


@dataclass(frozen=True, slots=True, eq=False)
class Problem:
    """A planning problem: states, prior, actions and their transfers, cost and goal.

    Build it with :meth:`build`.

    Attributes
    ----------
    part : Part
    states : TransferFunction
        The squeeze function, whose K stable orientations are the states.
    diameter : DiameterFunction
        The part's diameter function (the squeeze function descends it).
    prior : Prior
    actions : tuple of Action
        The action kinds available, in the order given.
    transfers : mapping of str to TransferFunction
        Each action's transfer function on orientations, by action name.
    cost : CostModel
    goal : Goal
    accuracy : float
        Accuracy of the gripper's turns, radians.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> pb.n_states, pb.action_kinds
    (4, ('squeeze',))
    """

    part: Part
    states: TransferFunction
    diameter: DiameterFunction | CurvedDiameter
    prior: Prior
    actions: tuple[Action, ...]
    transfers: Mapping[str, TransferFunction]
    cost: CostModel
    goal: Goal
    accuracy: float = 0.0
    # Derived values computed on first use (the action classes, the goal's group order);
    # not an init field, so ``dataclasses.replace`` gives the new problem a fresh cache.
    _cache: dict[Any, Any] = field(default_factory=dict, init=False, repr=False)

    @classmethod
    def build(
        cls,
        part: Part,
        prior: Prior | None = None,
        cost: CostModel | None = None,
        goal: Goal | None = None,
        actions: str | Iterable[str | Action] = ("squeeze",),
        accuracy: float = 0.0,
    ) -> Problem:
        """Set up the six-tuple for a part.

        Parameters
        ----------
        part : Part
        prior : Prior, optional
            Default uniform.
        cost : CostModel, optional
            Default: every action 1, verification 1.
        goal : Goal, optional
            Default: a single final orientation.
        actions : str or iterable of str or Action
            Action kinds available (names from :data:`~.actions.ACTIONS`, e.g.
            ``"squeeze"`` and/or ``"push-grasp"``, or a comma-separated string).
        accuracy : float
            Accuracy of the gripper's turns, radians (default 0): every relative rotation
            ``alpha_2..alpha_k`` may err by less than this. The exact and guaranteed planners
            return only plans whose tolerance is at least ``accuracy``.

        Raises
        ------
        PlanningError
            If ``actions`` is empty or unknown, or ``accuracy`` is not a finite number >= 0.
        CostError
            If every plan would cost nothing.

        Examples
        --------
        >>> from bayesgrasp.geometry.polygon import Part
        >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]), accuracy=0.01)
        >>> pb.accuracy
        0.01
        """
        if not (type(accuracy) is float and 0.0 <= accuracy < math.inf) and (
            isinstance(accuracy, bool)
            or not isinstance(accuracy, int | float)
            or not math.isfinite(accuracy if isinstance(accuracy, float) else 0.0)
            or not 0 <= accuracy <= 1e300  # an int beyond a float is no angle either
        ):
            raise PlanningError(
                f"`accuracy` must be a finite number of radians >= 0; got {accuracy!r}"
            )
        if type(actions) is tuple and actions == ("squeeze",):
            acts = _DEFAULT_ACTIONS
        else:
            acts = parse_actions(actions)
        if not isinstance(part, Part):
            raise PlanningError(f"`part` must be a Part; got {type(part).__name__}")
        # (the shared defaults skip the checks: Prior is an ABC, whose isinstance is slow)
        if prior is not None and prior is not _DEFAULT_PRIOR and not isinstance(prior, Prior):
            raise PlanningError(f"`prior` must be a Prior; got {type(prior).__name__}")
        if cost is not None and cost is not _DEFAULT_COST and not isinstance(cost, CostModel):
            raise PlanningError(f"`cost` must be a CostModel; got {type(cost).__name__}")
        if goal is not None and goal is not _DEFAULT_GOAL and not isinstance(goal, Goal):
            raise PlanningError(f"`goal` must be a Goal; got {type(goal).__name__}")
        d, states = squeeze_model(part)  # a curved part: its exact model (geometry/curved.py)
        transfers = {SQUEEZE.name: states}
        if acts is not _DEFAULT_ACTIONS:  # the default's squeeze is the squeeze function
            for a in acts:
                f = a.build(part, states)
                # A transfer function is named by its action (two actions may move alike).
                transfers[a.name] = f if f.kind == a.name else f.renamed(a.name)
        if cost is None:
            cost = _DEFAULT_COST
        elif cost is not _DEFAULT_COST:  # (its verification costs 1: no plan costs nothing)
            cost.check_positive(a.name for a in acts)
        prior = prior or _DEFAULT_PRIOR
        goal = goal or _DEFAULT_GOAL
        accuracy = float(accuracy)
        proxy = MappingProxyType(transfers)
        if cls is not Problem:
            return cls(part, states, d, prior, acts, proxy, cost, goal, accuracy)
        # The dataclass's __init__, by the slots' own setters (half object.__setattr__'s cost).
        pb = object.__new__(Problem)
        _SET_PART(pb, part)
        _SET_STATES(pb, states)
        _SET_DIAMETER(pb, d)
        _SET_PRIOR(pb, prior)
        _SET_ACTIONS(pb, acts)
        _SET_TRANSFERS(pb, proxy)
        _SET_COST(pb, cost)
        _SET_GOAL(pb, goal)
        _SET_ACCURACY(pb, accuracy)
        _SET_CACHE(pb, {})
        return pb

    @property
    def action_kinds(self) -> tuple[str, ...]:
        """Names of the available actions, in order."""
        kinds: tuple[str, ...] | None = self._cache.get("kinds")
        if kinds is None:  # planners ask often: made once
            kinds = self._cache["kinds"] = tuple(a.name for a in self.actions)
        return kinds

    def action(self, name: str | Action) -> Action:
        """The action of that name: the problem's own first, else the registry's."""
        if isinstance(name, Action):
            return name
        for a in self.actions:
            if a.name == name:
                return a
        return get_action(name)

    def transfer(self, name: str | Action) -> TransferFunction:
        """The transfer function on orientations of one action of the problem."""
        key = name.name if isinstance(name, Action) else name
        try:
            return self.transfers[key]
        except KeyError:
            raise PlanningError(
                f"action {key!r} is not one of this problem's ({', '.join(self.action_kinds)})"
            ) from None

    @property
    def n_states(self) -> int:
        """Number of states over ``[0, 2 pi)``."""
        return self.states.n_states

    @property
    def widths(self) -> NDArray[np.float64]:
        """The jaw opening at each state, ``d(S_i)`` (part units): what a gripper reads."""
        if "widths" not in self._cache:
            self._cache["widths"] = self.diameter(self.states.stable)
        return np.asarray(self._cache["widths"], dtype=np.float64)

    @property
    def goal_group(self) -> int:
        """Number of orientations the goal counts as one (the part's symmetry only if asked)."""
        group: int | None = self._cache.get("goal_group")
        if group is None:
            # The symmetry test only when the goal counts symmetric orientations as one.
            order = self.part.hull.symmetry_order if self.goal.kind == "symmetry" else 1
            group = self._cache["goal_group"] = int(self.goal.group_order(order))
        return group

    def success_states(self, final_orientation: float) -> NDArray[np.bool_]:
        """Which states succeed when a plan ends at ``final_orientation`` (see :class:`Goal`)."""
        return self.goal.success_states(self.states, final_orientation, self.goal_group)

    def transition(self, name: str | Action) -> ActionClasses:
        """The action classes (and their transition matrices) of one action (computed once)."""
        action = self.action(name)
        key = ("classes", action.name)
        if key not in self._cache:
            self._cache[key] = action_classes(
                self.states, self.transfer(action), action.gripper_period
            )
        return self._cache[key]  # type: ignore[no-any-return]

    def classes(self, name: str | Action) -> ActionClasses:
        """Alias of :meth:`transition`."""
        return self.transition(name)

    def state_distribution(
        self, first_angle: float = 0.0, kind: str | Action = "squeeze"
    ) -> NDArray[np.float64]:
        """Probability of each state after the first action made at gripper angle ``first_angle``.

        The part at world orientation ``theta`` is at ``theta - first_angle`` in the gripper
        frame; state ``i`` collects the prior mass of the basins of the action's transfer
        function that end there, shifted by ``first_angle``.
        """
        f = self.transfer(kind)
        small = self._small_distribution(f, first_angle)
        if small is not None:
            return np.array(small, dtype=np.float64)
        masses = self.prior.mass(f.basin_lo + first_angle, f.basin_hi + first_angle)
        if f is self.states:
            return np.asarray(masses, dtype=np.float64)
        idx = nearest_state(self.states, f.stable)
        return np.bincount(idx, weights=masses, minlength=self.n_states).astype(np.float64)

    def state_probabilities(
        self, first_angle: float = 0.0, kind: str | Action = "squeeze"
    ) -> list[float]:
        """:meth:`state_distribution` as a list of Python floats (the same values).

        For writers of a few states (a plan document), where the array is only read back.
        """
        small = self._small_distribution(self.transfer(kind), first_angle)
        if small is not None:
            return small
        return self.state_distribution(first_angle, kind).tolist()  # type: ignore[no-any-return]

    def _small_distribution(self, f: TransferFunction, first_angle: float) -> list[float] | None:
        """:meth:`state_distribution` on Python floats, or ``None`` (numpy's case).

        For a uniform prior, the states' own transfer function and a few states: the uniform
        cdf's operations one element at a time, the same IEEE additions, divisions and
        subtractions as numpy's.
        """
        if not (
            type(self.prior) is UniformPrior
            and type(first_angle) is float
            and f is self.states
            and f.n_states <= SMALL
        ):
            return None
        _, lo, hi = f.values
        a = first_angle
        out = []  # (a loop: a comprehension would make a function and a cell for a each call)
        for b, h in zip(lo, hi):  # noqa: B905 (as long; strict= parses keywords each call)
            out.append((h + a) / TWO_PI - (b + a) / TWO_PI)
        return out


(
    _SET_PART,
    _SET_STATES,
    _SET_DIAMETER,
    _SET_PRIOR,
    _SET_ACTIONS,
    _SET_TRANSFERS,
    _SET_COST,
    _SET_GOAL,
    _SET_ACCURACY,
    _SET_CACHE,
) = (Problem.__dict__[f.name].__set__ for f in dataclasses.fields(Problem))
