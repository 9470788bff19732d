"""The planning problem: the seed's six-tuple <Theta, f_1, A, G, C, theta*> (section 3).

- ``Theta`` (states): the stable orientations of the squeeze function (section 4.3); every
  action here ends in one of them (a push-grasp ends with a squeeze).
- ``f_1`` (prior): a :class:`~bayesgrasp.model.prior.Prior` on the initial orientation; the
  distribution over states after the first action is the prior mass of each basin.
- ``A`` (actions): gripper rotations ``alpha`` followed by an action of a given type. For each
  type the continuum of angles falls into finitely many classes with the same effect on the
  states (section 4.4: at most n^2 for squeezes), see :class:`ActionClasses`. The gripper's
  ``accuracy`` (radians, default 0) bounds the error of each relative rotation
  ``alpha_2..alpha_k``: a planner that honours it returns only plans that keep their success
  under any errors of less than ``accuracy`` on every turn (plan tolerance >= accuracy).
- ``G`` (transfer): one :class:`~bayesgrasp.geometry.transfer.TransferFunction` per action type.
- ``C`` (cost): a :class:`CostModel`.
- ``theta*`` (goal): a :class:`Goal`: one final orientation (the seed), or a set of
  orientations equivalent under the part's rotational symmetry.

The pieces are separate values so that sensing, noisy actions or payoffs can later replace
one of them without touching the others.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..errors import CostError, PlanningError
from ..geometry.polygon import Part
from ..geometry.transfer import TransferFunction, squeeze_function
from .prior import Prior, UniformPrior

__all__ = ["ActionClasses", "CostModel", "Goal", "Problem", "action_classes"]

TWO_PI = 2.0 * math.pi
ActionKind = Literal["squeeze", "push-grasp"]


@dataclass(frozen=True, slots=True)
class CostModel:
    """Costs of actions and of the verification that ends each attempt (the seed, 3 and 4.5).

    An attempt is the plan's actions plus one verification; on failure the plan is run again
    on a part whose orientation is a fresh draw from the prior (the seed's model: expected
    number of attempts ``1 / p``). Each failed verification also pays ``retry``. So

        E[cost] = attempt / p + retry * (1 / p - 1).

    Parameters
    ----------
    squeeze : float
        Cost of a squeeze (default 1, the seed).
    verify : float
        Cost of the verification step (default 1, the seed).
    first_squeeze : float or None
        Cost of the first action when it is a squeeze (default: ``squeeze``).
    retry : float
        Overhead paid on each failed verification (default 0).
    push_grasp : float
        Cost of a push-grasp (default 1).

    Examples
    --------
    >>> CostModel().expected_cost(("squeeze", "squeeze"), 0.5)
    6.0
    """

    squeeze: float = 1.0
    verify: float = 1.0
    first_squeeze: float | None = None
    retry: float = 0.0
    push_grasp: float = 1.0

    def __post_init__(self) -> None:
        for name in ("squeeze", "verify", "first_squeeze", "retry", "push_grasp"):
            value = getattr(self, name)
            if value is None:
                continue
            if (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not math.isfinite(value)
                or value < 0
            ):
                raise CostError(f"cost `{name}` must be a finite number >= 0; got {value!r}")

    def check_positive(self, kinds: tuple[str, ...]) -> None:
        """Raise :class:`CostError` if every plan made of these action types costs nothing.

        Expected costs could not rank such plans.
        """
        costs = [self.verify, self.retry] + [self.action_cost(k) for k in kinds]
        if "squeeze" in kinds and self.first_squeeze is not None:
            costs.append(self.first_squeeze)
        if not any(c > 0 for c in costs):
            names = ", ".join(
                ["`verify`", "`retry`"]
                + (["`squeeze`", "`first_squeeze`"] if "squeeze" in kinds else [])
                + (["`push_grasp`"] if "push-grasp" in kinds else [])
            )
            raise CostError(f"at least one of the costs {names} must be positive; got all zero")

    def action_cost(self, kind: str, first: bool = False) -> float:
        """Cost of one action of the given kind."""
        if kind == "squeeze":
            if first and self.first_squeeze is not None:
                return self.first_squeeze
            return self.squeeze
        if kind == "push-grasp":
            return self.push_grasp
        raise PlanningError(f"unknown action kind {kind!r}")

    def attempt_cost(self, kinds: tuple[str, ...]) -> float:
        """Cost of one attempt: the actions in order, then the verification."""
        return self.verify + sum(self.action_cost(k, i == 0) for i, k in enumerate(kinds))

    def expected_cost(self, kinds: tuple[str, ...], p: float) -> float:
        """Expected cost of repeating the plan until verification succeeds (inf if p = 0)."""
        if p <= 0.0:
            return math.inf
        return self.attempt_cost(kinds) / p + self.retry * (1.0 / p - 1.0)


@dataclass(frozen=True, slots=True)
class Goal:
    """The desired final state.

    ``"single"`` (the seed): one final orientation, the most probable one.
    ``"symmetry"``: the ``r`` orientations ``2 pi / r`` apart of an r-fold symmetric part
    count as one (they are the same physical placement).

    Examples
    --------
    >>> Goal("symmetry").group_order(4)
    4
    """

    kind: Literal["single", "symmetry"] = "single"

    def group_order(self, symmetry_order: int) -> int:
        """How many orientations ``2 pi / g`` apart the goal counts as one."""
        return symmetry_order if self.kind == "symmetry" else 1


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


def action_classes(
    states: TransferFunction, action: TransferFunction, gripper_period: float
) -> ActionClasses:
    """Enumerate the action classes of ``action`` acting on the states of ``states``.

    ``gripper_period`` is ``pi`` for a squeeze (the gripper turned by pi is the same gripper)
    and ``2 pi`` for a push-grasp (the pushing jaw is on one side).
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
    lo = crit
    hi = np.append(crit[1:], crit[0] + gripper_period)
    mid = 0.5 * (lo + hi)
    after = action(s[None, :] - mid[:, None])  # (A, K) orientations after the action
    transfer = nearest_state(states, after)
    return ActionClasses(action.kind, lo, hi, mid, transfer)


def nearest_state(states: TransferFunction, theta: NDArray[np.float64]) -> NDArray[np.intp]:
    """Index of the stable orientation nearest (on the circle) to each angle."""
    s = states.stable
    diff = np.abs(np.mod(theta[..., None] - s + math.pi, TWO_PI) - math.pi)
    return np.asarray(np.argmin(diff, axis=-1), dtype=np.intp)


@dataclass(frozen=True, slots=True, eq=False)
class Problem:
    """A planning problem: part, prior, actions, transfer functions, cost and goal.

    Build it with :meth:`build`.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> pb.n_states, pb.action_kinds
    (4, ('squeeze',))
    """

    part: Part
    prior: Prior
    transfers: dict[str, TransferFunction]
    cost: CostModel
    goal: Goal
    action_kinds: tuple[str, ...]
    accuracy: float = 0.0
    _classes: dict[str, ActionClasses] = field(default_factory=dict, repr=False)
    _memo: dict[str, int] = field(default_factory=dict, repr=False)

    @classmethod
    def build(
        cls,
        part: Part,
        prior: Prior | None = None,
        cost: CostModel | None = None,
        goal: Goal | None = None,
        actions: tuple[str, ...] = ("squeeze",),
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
        actions : tuple of str
            Action types available: ``"squeeze"`` and/or ``"push-grasp"``.
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
        if (
            isinstance(accuracy, bool)
            or not isinstance(accuracy, int | float)
            or not math.isfinite(accuracy)
            or accuracy < 0
        ):
            raise PlanningError(
                f"`accuracy` must be a finite number of radians >= 0; got {accuracy!r}"
            )
        if not actions:
            raise PlanningError("at least one action type is needed")
        transfers: dict[str, TransferFunction] = {"squeeze": squeeze_function(part.hull)}
        for kind in actions:
            if kind == "push-grasp":
                from ..geometry.push import push_grasp_function

                transfers[kind] = push_grasp_function(part, transfers["squeeze"])
            elif kind != "squeeze":
                raise PlanningError(
                    f"unknown action type {kind!r}; expected 'squeeze' or 'push-grasp'"
                )
        kinds = tuple(dict.fromkeys(actions))
        cost = cost or CostModel()
        cost.check_positive(kinds)
        return cls(
            part, prior or UniformPrior(), transfers, cost, goal or Goal(), kinds, float(accuracy)
        )

    @property
    def states(self) -> TransferFunction:
        """The squeeze function, whose stable orientations are the states."""
        return self.transfers["squeeze"]

    @property
    def n_states(self) -> int:
        """Number of states over ``[0, 2 pi)``."""
        return self.states.n_states

    @property
    def goal_group(self) -> int:
        """Number of orientations the goal counts as one (computed once)."""
        if "goal_group" not in self._memo:
            self._memo["goal_group"] = self.goal.group_order(self.part.hull.symmetry_order)
        return self._memo["goal_group"]

    def classes(self, kind: str) -> ActionClasses:
        """The action classes of one action type (computed once)."""
        if kind not in self._classes:
            period = math.pi if kind == "squeeze" else TWO_PI
            self._classes[kind] = action_classes(self.states, self.transfers[kind], period)
        return self._classes[kind]

    def state_distribution(self, first_angle: float = 0.0, kind: str = "squeeze") -> np.ndarray:
        """Probability of each state after the first action made at gripper angle ``first_angle``.

        The part at world orientation ``theta`` is at ``theta - first_angle`` in the gripper
        frame; state ``i`` collects the prior mass of its basin shifted by ``first_angle``.
        """
        f = self.transfers[kind]
        masses = self.prior.mass(f.basin_lo + first_angle, f.basin_hi + first_angle)
        if kind == "squeeze":
            return np.asarray(masses, dtype=np.float64)
        idx = nearest_state(self.states, f.stable)
        return np.bincount(idx, weights=masses, minlength=self.n_states)
