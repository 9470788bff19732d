"""Where plain Python floats give way to numpy: one cut-off for the whole pipeline.

numpy costs about a microsecond a call whatever the array's size, so on the few vertices and
states of most parts (the seed's study: 6 sides, 6 states on average) loops over Python
floats are several times faster, and on thousands numpy is. Every step with two paths (the
hull, the diameter function's pieces and extrema, the symmetry test, the arc fronts) takes
the plain-Python one at or below :data:`SMALL` and makes the same decisions with the same
floating-point operations on either side (the tests run both on the same inputs).
"""

from __future__ import annotations

__all__ = ["SMALL"]

SMALL = 64
"""Most vertices (hull, diameter, symmetry) or states (arc fronts) done in plain Python."""
