"""The planning model: the seed's six-tuple <Theta, f_1, A, G, C, theta*> (section 3).

States (the stable orientations), the prior on the initial orientation, the actions and
their transfers, the cost model and the goal are separate, replaceable values; a
:class:`Problem` holds one of each.

The names are imported on first use (:mod:`bayesgrasp._lazy`): the command line's options
read the action registry (:mod:`.actions`) without loading numpy.
"""

from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:  # pragma: no cover
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

__getattr__, __dir__ = lazy_names(
    __name__,
    {
        **dict.fromkeys(["CostModel", "Goal", "Problem"], "problem"),
        **dict.fromkeys(
            [
                "DensityPrior",
                "HistogramPrior",
                "Prior",
                "SamplePrior",
                "UniformPrior",
                "parse_prior",
                "von_mises",
            ],
            "prior",
        ),
    },
)
