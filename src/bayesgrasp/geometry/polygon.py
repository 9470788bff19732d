"""Planar parts: the convex polygon the gripper sees, and the part the user gave.

The names of the planar geometry in one place; each lives in a module of its own concern:

- :mod:`.coordinates`: :func:`as_points`, the validation of coordinates;
- :mod:`.hull`: the convex hull (Andrew's monotone chain) and :func:`polygon_area_centroid`;
- :mod:`.symmetry`: the order of rotational symmetry;
- :mod:`.convex`: :class:`ConvexPolygon`, what the gripper touches;
- :mod:`.rings`: :func:`find_crossing` and the other checks of a simple outline;
- :mod:`.part`: :class:`Part`, the user's part, and :func:`hull_contains`.

Examples
--------
>>> Part.from_points([(0, 0), (2, 0), (0, 1), (0.5, 0.2)]).hull.n_sides
3
"""

from __future__ import annotations

from .convex import ConvexPolygon
from .coordinates import as_points
from .hull import polygon_area_centroid
from .part import Part, hull_contains
from .rings import find_crossing

__all__ = [
    "ConvexPolygon",
    "Part",
    "as_points",
    "find_crossing",
    "hull_contains",
    "polygon_area_centroid",
]
