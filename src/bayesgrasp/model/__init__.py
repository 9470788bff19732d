"""The planning model: the seed's six-tuple <Theta, f_1, A, G, C, theta*> (section 3).

States (the stable orientations), the prior on the initial orientation, the actions and
their transfers, the cost model and the goal are separate, replaceable values; a
:class:`Problem` holds one of each.
"""

from .prior import (
    DensityPrior,
    HistogramPrior,
    Prior,
    SamplePrior,
    UniformPrior,
    parse_prior,
    von_mises,
)
from .problem import CostModel, Goal, Problem

__all__ = [
    "CostModel",
    "DensityPrior",
    "Goal",
    "HistogramPrior",
    "Prior",
    "Problem",
    "SamplePrior",
    "UniformPrior",
    "parse_prior",
    "von_mises",
]
