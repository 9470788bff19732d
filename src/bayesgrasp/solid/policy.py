"""Strategies over resting poses: tell the poses apart by their widths and orient the part.

The state is (pose, planar orientation). Each pose is a planar part, its footprint
(:mod:`bayesgrasp.solid.parts`), and a squeeze keeps the pose; the pose prior is the
distribution of poses (quasi-static, perturbed, from drops, or given), the planar prior is
the problem's. The policy is the recognition policy of :mod:`bayesgrasp.planning.policy`
over the footprints as candidate parts with the pose probabilities as the part prior:

- ``goal_pose=None`` (``--goal-pose any``): every pose may be declared; the policy is
  exactly the recognition planner's.
- ``goal_pose=k``: only pose ``k`` may be declared. Declaring another pose never succeeds
  (its goal is :class:`NoDeclaration`), so the planner rejects it instead: the part is
  dropped again, at the retry cost.

Examples
--------
>>> from bayesgrasp.solid.poses import resting_poses
>>> box = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 4)], float)
>>> study = resting_poses(box, [0.5, 1, 2])
>>> [round(p.probability, 4) for p in study.poses]
[0.3344, 0.3344, 0.131, 0.131, 0.0346, 0.0346]
>>> pol = plan_pose_policy(study, "width", goal_pose=None, max_actions=2)
>>> pol.parts[:3], round(pol.expected_cost, 4)
(('pose-0', 'pose-1', 'pose-2'), 8.9892)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..model.goal import Goal

if TYPE_CHECKING:
    from ..geometry.transfer import TransferFunction
    from ..model.problem import Problem
    from ..model.sensing import WidthSensor
    from ..planning.policy import Policy
    from .poses import PoseStudy

__all__ = ["NoDeclaration", "plan_pose_policy", "pose_problems"]


@dataclass(frozen=True, slots=True)
class NoDeclaration(Goal):
    """The goal of a pose that may not be declared: no final state succeeds.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part, squeeze_function
    >>> s = squeeze_function(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).hull)
    >>> NoDeclaration().success_states(s, 0.0, 1).tolist()
    [False, False, False, False]
    """

    def success_states(
        self, states: TransferFunction, final_orientation: float, symmetry_order: int
    ) -> NDArray[np.bool_]:
        """No state succeeds."""
        return np.zeros(states.n_states, dtype=bool)


def pose_problems(
    study: PoseStudy,
    goal_pose: int | None = None,
    units: str | None = None,
    **inputs: Any,
) -> list[Problem]:
    """One problem per pose (footprint ``pose-k``); only ``goal_pose`` declarable if given.

    ``inputs`` are the keywords of :meth:`Problem.build` (prior, cost, goal, actions, ...).
    """
    from ..model.problem import Problem
    from .parts import pose_parts

    parts = pose_parts(study, units)
    goal = inputs.pop("goal", None) or Goal()
    out = []
    for k, part in enumerate(parts):
        g = goal if goal_pose is None or k == goal_pose else NoDeclaration(goal.kind)
        out.append(Problem.build(part, goal=g, **inputs))
    return out


def plan_pose_policy(
    study: PoseStudy,
    sensor: str | WidthSensor = "width",
    *,
    goal_pose: int | None = 0,
    pose_prior: Sequence[float] | None = None,
    max_actions: int = 3,
    units: str | None = None,
    **inputs: Any,
) -> Policy:
    """The Bayes policy over the poses of ``study`` (module notes).

    Parameters
    ----------
    study : PoseStudy
    sensor : str or WidthSensor
        As for :func:`~bayesgrasp.planning.policy.plan_policy`.
    goal_pose : int or None
        The only pose that may be declared; ``None``: any pose.
    pose_prior : sequence of float, optional
        Weights of the poses (default: the study's probabilities).
    max_actions : int
    units : str, optional
        The footprints' units.
    **inputs
        Keywords of :meth:`Problem.build` (prior, cost, goal, actions, accuracy).

    Returns
    -------
    Policy
        Its parts are ``pose-0``, ``pose-1``, ... in the study's order.
    """
    from ..planning.policy import plan_policy

    problems = pose_problems(study, goal_pose, units, **inputs)
    prior = study.probabilities if pose_prior is None else np.asarray(pose_prior, float)
    return plan_policy(problems, sensor, max_actions, part_prior=list(map(float, prior)))
