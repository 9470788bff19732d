"""bayesgrasp: Bayesian planning of parallel-jaw squeeze plans that orient planar parts.

The data flow is one-directional (design.md): part -> diameter function -> transfer
functions -> problem -> planners -> report.

Examples
--------
>>> import bayesgrasp as bg
>>> part = bg.Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], name="rectangle")
>>> report = bg.plan_exact(bg.Problem.build(part))
>>> [round(o.expected_cost, 2) for o in report.options]
[6.3, 6.0]
"""

from typing import TYPE_CHECKING

from ._lazy import lazy_names
from .errors import (
    BayesGraspError,
    CostError,
    MissingExtraError,
    NoPlanError,
    PartError,
    PartFileError,
    PlanningError,
    PriorError,
)

if TYPE_CHECKING:  # pragma: no cover
    from . import shapes
    from ._version import __version__ as __version__
    from .geometry.diameter import DiameterFunction, diameter_function
    from .geometry.polygon import ConvexPolygon, Part
    from .geometry.push import RadiusFunction, push_function, push_grasp_function, radius_function
    from .geometry.transfer import TransferFunction, squeeze_function
    from .io import read_part, resolve_part
    from .model.prior import (
        DensityPrior,
        HistogramPrior,
        Prior,
        SamplePrior,
        UniformPrior,
        parse_prior,
        von_mises,
    )
    from .model.problem import CostModel, Goal, Problem
    from .planning import (
        GuaranteedPlan,
        PlanOption,
        PlanReport,
        PlanResult,
        PlanStep,
        execute_plan,
        plan,
        plan_exact,
        plan_guaranteed,
    )
    from .tolerance import DEFAULT_TOLERANCE, Tolerance


# Names are imported on first use: ``bayesgrasp --help`` and light scripts do not pay for
# numpy and every layer up front.
_LAZY = {
    "ConvexPolygon": "geometry.polygon",
    "CostModel": "model.problem",
    "DEFAULT_TOLERANCE": "tolerance",
    "DensityPrior": "model.prior",
    "DiameterFunction": "geometry.diameter",
    "Goal": "model.problem",
    "GuaranteedPlan": "planning",
    "HistogramPrior": "model.prior",
    "Part": "geometry.polygon",
    "PlanOption": "planning",
    "PlanReport": "planning",
    "PlanStep": "planning",
    "Prior": "model.prior",
    "Problem": "model.problem",
    "RadiusFunction": "geometry.push",
    "SamplePrior": "model.prior",
    "Tolerance": "tolerance",
    "TransferFunction": "geometry.transfer",
    "UniformPrior": "model.prior",
    "diameter_function": "geometry.diameter",
    "execute_plan": "planning",
    "parse_prior": "model.prior",
    "plan": "planning",
    "PlanResult": "planning",
    "plan_exact": "planning",
    "plan_guaranteed": "planning",
    "push_function": "geometry.push",
    "push_grasp_function": "geometry.push",
    "radius_function": "geometry.push",
    "read_part": "io",
    "resolve_part": "io",
    "squeeze_function": "geometry.transfer",
    "von_mises": "model.prior",
    "shapes": "",
    # pyproject.toml's version, from the installed metadata (read on first use)
    "__version__": "_version",
}


__getattr__, __dir__ = lazy_names(__name__, _LAZY)


__all__ = [
    "DEFAULT_TOLERANCE",
    "BayesGraspError",
    "ConvexPolygon",
    "CostError",
    "CostModel",
    "DensityPrior",
    "DiameterFunction",
    "Goal",
    "GuaranteedPlan",
    "HistogramPrior",
    "MissingExtraError",
    "NoPlanError",
    "Part",
    "PartError",
    "PartFileError",
    "PlanOption",
    "PlanReport",
    "PlanResult",
    "PlanStep",
    "PlanningError",
    "Prior",
    "PriorError",
    "Problem",
    "RadiusFunction",
    "SamplePrior",
    "Tolerance",
    "TransferFunction",
    "UniformPrior",
    "diameter_function",
    "execute_plan",
    "parse_prior",
    "plan",
    "plan_exact",
    "plan_guaranteed",
    "push_function",
    "push_grasp_function",
    "radius_function",
    "read_part",
    "resolve_part",
    "shapes",
    "squeeze_function",
    "von_mises",
]
