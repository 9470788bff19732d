"""Plans and plan reports: what every planner returns.

A plan is a sequence of steps. Step 1 is made with the gripper at ``steps[0].alpha`` in the
world frame; before step ``i > 1`` the gripper turns by ``steps[i].alpha`` (counter-clockwise)
relative to the previous step, so the part at ``theta`` in the old gripper frame is at
``theta - alpha`` in the new one (design.md). A verification step follows the last action.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.problem import Problem

__all__ = ["PlanOption", "PlanReport", "PlanStep", "execute_plan"]


@dataclass(frozen=True, slots=True)
class PlanStep:
    """One action: rotate the gripper by ``alpha`` (radians), then act (``kind``)."""

    kind: str
    alpha: float


@dataclass(frozen=True, slots=True)
class PlanOption:
    """The best plan with a given number of actions.

    Attributes
    ----------
    steps : tuple of PlanStep
        ``steps[0].alpha`` is the world gripper angle of the first action; ``steps[i].alpha``
        (i >= 1) the turn of the gripper relative to the previous action (the exact planner
        gives squeeze turns in ``(-pi/2, pi/2]``: a gripper turned by pi is the same gripper).
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
class PlanReport:
    """Plans of every length up to the most certain one, for one problem.

    Attributes
    ----------
    problem : Problem
    options : tuple of PlanOption
        ``options[k - 1]`` is the best plan with ``k`` actions.
    bayes : int
        Index of the plan of least expected cost (ties go to fewer actions).
    most_certain : int
        Index of the shortest plan with the highest attainable success probability.
    method : str
        ``"exact"`` or ``"bfs"``.
    nodes : int or None
        Hyperstates generated (breadth-first baseline only).
    """

    problem: Problem
    options: tuple[PlanOption, ...]
    bayes: int
    most_certain: int
    method: str
    nodes: int | None = None

    @property
    def bayes_plan(self) -> PlanOption:
        """The plan of least expected cost."""
        return self.options[self.bayes]

    @property
    def most_certain_plan(self) -> PlanOption:
        """The shortest plan with the highest success probability."""
        return self.options[self.most_certain]


def choose_indices(options: tuple[PlanOption, ...], tol: float = 1e-12) -> tuple[int, int]:
    """Indices of the Bayes plan (least cost, ties to fewer actions) and the most certain."""
    costs = np.array([o.expected_cost for o in options])
    probs = np.array([o.success_probability for o in options])
    bayes = int(np.flatnonzero(costs <= costs.min() * (1 + 1e-12) + tol)[0])
    most = int(np.flatnonzero(probs >= probs.max() - tol)[0])
    return bayes, most


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
    return np.mod(theta, 2.0 * math.pi)
