"""Geometry and mechanics: the part, its diameter function and its transfer functions.

The first layer of the data flow (design.md): part -> convex hull -> diameter function ->
squeeze, push and push-grasp functions. Every value here is immutable and knows nothing of
priors, costs or plans.
"""

from .diameter import DiameterFunction, diameter_function
from .polygon import ConvexPolygon, Part, as_points, find_crossing, polygon_area_centroid
from .push import RadiusFunction, push_function, push_grasp_function, radius_function
from .transfer import TransferFunction, detect_period, squeeze_function, transfer_from_extrema

__all__ = [
    "ConvexPolygon",
    "DiameterFunction",
    "Part",
    "RadiusFunction",
    "TransferFunction",
    "as_points",
    "detect_period",
    "diameter_function",
    "find_crossing",
    "polygon_area_centroid",
    "push_function",
    "push_grasp_function",
    "radius_function",
    "squeeze_function",
    "transfer_from_extrema",
]
