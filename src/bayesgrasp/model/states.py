"""The states ``Theta`` of the seed's six-tuple: the stable orientations of the squeeze function.

Every action here ends with the jaws closed, so it ends at a stable orientation of the
squeeze function ``s`` (the steps of :class:`~bayesgrasp.geometry.transfer.TransferFunction`);
those K orientations over ``[0, 2 pi)`` are the states, and the diameter at each is the jaw
opening a gripper reads there (:attr:`bayesgrasp.model.problem.Problem.widths`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.transfer import TransferFunction

__all__ = ["nearest_state"]


def nearest_state(states: TransferFunction, theta: NDArray[np.float64]) -> NDArray[np.intp]:
    """Index of the stable orientation nearest (on the circle) to each angle.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part, squeeze_function
    >>> s = squeeze_function(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).hull)
    >>> nearest_state(s, np.array([0.1, 3.0])).tolist()
    [0, 2]
    """
    s = states.stable
    diff = np.abs(np.mod(theta[..., None] - s + math.pi, TWO_PI) - math.pi)
    return np.asarray(np.argmin(diff, axis=-1), dtype=np.intp)
