"""Numerical tolerances, in one place.

All comparisons of lengths and angles in bayesgrasp go through a :class:`Tolerance`. Length
tolerances are relative to the part's size (its largest distance from the area centroid),
so a part drawn in metres and the same part drawn in millimetres behave identically.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields

from .errors import PartError

__all__ = ["DEFAULT_TOLERANCE", "MIN_ANGLE", "Tolerance"]

MIN_ANGLE = 1e-12
"""The smallest angle tolerance (radians), a thousand rounding errors of ``2 pi``."""


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
        to an edge, the margin that keeps a plan away from an unstable equilibrium. At
        least ``MIN_ANGLE`` (1e-12): angles are computed to about 1e-15 rad, so below that
        the edges a symmetry makes parallel, or the extrema it repeats, compare unequal.
    symmetry : float
        A rotation maps the part onto itself when every vertex lands within
        ``symmetry * size`` of a vertex; looser than ``length`` because symmetric parts
        often come from rounded coordinates (7 significant digits move a vertex of a part
        drawn a few sizes from the origin by up to about ``2e-6 * size``). A part symmetric
        within this tolerance is exactly symmetric everywhere downstream: its diameter and
        radius functions are built from its symmetrized vertices, so the squeeze period is
        ``2 pi / (r (1 + r mod 2))``, the push period ``2 pi / r`` (centre of mass at the
        centroid), and every period holds to ``angle``. A part not symmetric within it is
        not symmetric at all: its periods are those its extrema have to ``angle`` (pi and
        2 pi, unless by an exact coincidence).
    probability : float
        Probabilities closer than this are equal (ties between plans).
    barrier : float
        A minimum of the diameter function that lies less than ``barrier * size`` below an
        adjacent maximum is not a stable orientation: the pair is dropped. Such shallow pairs
        are what rounding does to parallel edges and to chords perpendicular to an edge
        (their depth grows with the square of the rounding angle: up to about
        ``1.3e-10 * size`` for 7 significant digits); no squeeze resolves them. Among
        random 10-point polygons about 1 in 3000 has such a pair of its own.

    Raises
    ------
    PartError
        A tolerance that is not a finite real number >= 0, or an angle below ``MIN_ANGLE``.

    Examples
    --------
    >>> Tolerance().length_for(2.0)
    2e-10
    """

    length: float = 1e-10
    angle: float = 1e-9
    symmetry: float = 1e-5
    probability: float = 1e-12
    barrier: float = 1e-9

    def __post_init__(self) -> None:
        for f in fields(self):
            x = getattr(self, f.name)
            if (
                isinstance(x, bool)
                or not isinstance(x, numbers.Real)
                or not math.isfinite(x)
                or x < 0
            ):
                raise PartError(f"`{f.name}` must be a finite number >= 0; got {x!r}")
            object.__setattr__(self, f.name, float(x))
        if self.angle < MIN_ANGLE:
            raise PartError(
                f"`angle` must be at least {MIN_ANGLE:g} rad (angles are computed to about "
                f"1e-15 rad, so smaller tolerances call equal angles unequal); got {self.angle!r}"
            )

    def length_for(self, size: float) -> float:
        """Absolute length tolerance for a part of the given size."""
        return self.length * size

    def symmetry_for(self, size: float) -> float:
        """Absolute tolerance of the symmetry test for a part of the given size."""
        return self.symmetry * size

    def barrier_for(self, size: float) -> float:
        """Smallest depth of a stable orientation of the diameter function, absolute."""
        return self.barrier * size


DEFAULT_TOLERANCE = Tolerance()
