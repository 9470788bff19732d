"""Gripper angles as robot files write them: radians wrapped to ``(-pi, pi]``, and degrees.

Shared by the robot file of a plan (:mod:`.export`) and the state machine of a strategy
(:mod:`.machine`).
"""

from __future__ import annotations

import math

__all__ = ["GripperAngles", "wrap_angle"]


class GripperAngles:
    """The degrees of a step's radians (a base of :class:`RobotStep` and machine states)."""

    __slots__ = ()
    turn_rad: float
    gripper_rad: float

    @property
    def turn_deg(self) -> float:
        """:attr:`turn_rad` in degrees."""
        return math.degrees(self.turn_rad)

    @property
    def gripper_deg(self) -> float:
        """:attr:`gripper_rad` in degrees, in ``(-180, 180]``."""
        return math.degrees(self.gripper_rad)


def wrap_angle(angle: float) -> float:
    """An angle in ``(-pi, pi]`` (plans' and state machines' gripper angles).

    Examples
    --------
    >>> wrap_angle(3 * math.pi) == math.pi, wrap_angle(-math.pi) == math.pi
    (True, True)
    """
    out = math.remainder(angle, 2.0 * math.pi)
    return math.pi if out <= -math.pi else out
