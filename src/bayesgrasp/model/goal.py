"""The goal ``theta*`` of the seed's six-tuple: which final states succeed.

The seed's goal is one final orientation; a *symmetry* goal counts the ``r`` orientations
``2 pi / r`` apart of an r-fold symmetric part as one (they are the same physical placement).
A goal answers two questions for the planners: how many orientations it counts as one (the
exact planner places arcs with that period), and which states succeed when a plan ends at
a given orientation (its success vector, 1 for a success and 0 otherwise; a payoff per state
is the generalisation the seed's section 6.4 sketches).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from .states import nearest_state

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.transfer import TransferFunction

__all__ = ["GOAL_KINDS", "Goal"]

GOAL_KINDS = ("single", "symmetry")


@dataclass(frozen=True, slots=True)
class Goal:
    """The desired final state.

    ``"single"`` (the seed): one final orientation, the most probable one.
    ``"symmetry"``: the ``r`` orientations ``2 pi / r`` apart of an r-fold symmetric part
    count as one.

    Examples
    --------
    >>> Goal("symmetry").group_order(4)
    4
    """

    kind: Literal["single", "symmetry"] = "single"

    def __post_init__(self) -> None:
        if self.kind not in GOAL_KINDS:
            raise PlanningError(
                f"`kind` of a goal must be one of {', '.join(map(repr, GOAL_KINDS))}; "
                f"got {self.kind!r}"
            )

    def group_order(self, symmetry_order: int) -> int:
        """How many orientations ``2 pi / g`` apart the goal counts as one."""
        return symmetry_order if self.kind == "symmetry" else 1

    def success_states(
        self, states: TransferFunction, final_orientation: float, symmetry_order: int
    ) -> NDArray[np.bool_]:
        """Which states count as success when a plan ends at ``final_orientation``.

        The state nearest the final orientation and, for a symmetry goal, those nearest its
        copies ``2 pi / r`` apart.

        Examples
        --------
        >>> from bayesgrasp.geometry import Part, squeeze_function
        >>> s = squeeze_function(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).hull)
        >>> Goal().success_states(s, np.pi / 2, 2).tolist()
        [False, True, False, False]
        >>> Goal("symmetry").success_states(s, np.pi / 2, 2).tolist()
        [False, True, False, True]
        """
        g = self.group_order(symmetry_order)
        targets = final_orientation + TWO_PI * np.arange(g) / g
        mask = np.zeros(states.n_states, dtype=bool)
        mask[nearest_state(states, targets)] = True
        return mask
