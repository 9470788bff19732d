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

from . import shapes
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
    PlanStep,
    execute_plan,
    plan_exact,
    plan_guaranteed,
)
from .tolerance import DEFAULT_TOLERANCE, Tolerance

__version__ = "0.1.0"

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
