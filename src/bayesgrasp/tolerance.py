"""Numerical tolerances, in one place.

All comparisons of lengths and angles in bayesgrasp go through a :class:`Tolerance`. Length
tolerances are relative to the part's size (its largest distance from the area centroid),
so a part drawn in metres and the same part drawn in millimetres behave identically.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["DEFAULT_TOLERANCE", "Tolerance"]


@dataclass(frozen=True, slots=True)
class Tolerance:
    """Relative tolerances used by geometry and planning.

    Parameters
    ----------
    length : float
        Points closer than ``length * size`` are the same point; a vertex closer than that
        to the line through its neighbours is collinear and dropped.
    angle : float
        Angles (radians) closer than this are equal: parallel edges, a chord perpendicular
        to an edge, the margin that keeps a plan away from an unstable equilibrium.
    symmetry : float
        A rotation maps the part onto itself when every vertex lands within
        ``symmetry * size`` of a vertex; looser than ``length`` because symmetric parts
        often come from rounded coordinates (7 significant digits move a vertex of a part
        drawn a few sizes from the origin by up to about ``2e-6 * size``).
    probability : float
        Probabilities closer than this are equal (ties between plans).

    Examples
    --------
    >>> Tolerance().length_for(2.0)
    2e-10
    """

    length: float = 1e-10
    angle: float = 1e-9
    symmetry: float = 1e-5
    probability: float = 1e-12

    def length_for(self, size: float) -> float:
        """Absolute length tolerance for a part of the given size."""
        return self.length * size

    def symmetry_for(self, size: float) -> float:
        """Absolute tolerance of the symmetry test for a part of the given size."""
        return self.symmetry * size


DEFAULT_TOLERANCE = Tolerance()
