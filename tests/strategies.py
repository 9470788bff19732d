"""Hypothesis strategies for random parts and angles, shared by the test modules.

Three families of point sets, each returned as a float64 array of shape (N, 2):

``lattice_points``
    Integer points in a box, scaled by a power of two (exact). Small lattices are full of exact
    degeneracies (parallel edges, right angles, collinear and duplicate points, symmetric
    shapes), while every *non*-degenerate angle or distance stays far (about 1e-7 relative)
    above the library's tolerances, so invariance properties cannot trip over a tolerance
    threshold by round-off alone.
``uniform_points``
    The seed paper's random polygons: N uniform points in the unit square, from a seed.
``ellipse_points``
    Convex polygons with up to 40 vertices on an ellipse of random aspect, rotation and centre.

``convex_points`` draws from all three.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def has_area(points: FloatArray) -> bool:
    """Whether the points are not all collinear (exact for integer coordinates)."""
    p = points - points[0]
    cross = p[:, 0, None] * p[None, :, 1] - p[:, 1, None] * p[None, :, 0]
    return bool(np.any(cross != 0))


@st.composite
def lattice_points(
    draw: st.DrawFn, min_size: int = 3, max_size: int = 14, bound: int = 1000
) -> FloatArray:
    """Integer points in ``[-bound, bound]^2`` (not all collinear), times ``2**k``."""
    ints = st.integers(-bound, bound)
    pts = draw(
        st.lists(st.tuples(ints, ints), min_size=min_size, max_size=max_size).filter(
            lambda p: has_area(np.array(p, dtype=np.float64))
        )
    )
    scale = 2.0 ** draw(st.integers(-12, 4))
    return np.array(pts, dtype=np.float64) * scale


@st.composite
def uniform_points(draw: st.DrawFn, n: int = 10) -> FloatArray:
    """``n`` uniform points in the unit square (the seed's 2000-polygon study)."""
    seed = draw(st.integers(0, 2**32 - 1))
    return np.random.default_rng(seed).random((n, 2))


@st.composite
def ellipse_points(draw: st.DrawFn, min_size: int = 3, max_size: int = 40) -> FloatArray:
    """Vertices of a convex polygon inscribed in a random ellipse."""
    n = draw(st.integers(min_size, max_size))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 2.0 * math.pi, n))
    aspect = draw(st.floats(0.05, 1.0))
    turn = draw(st.floats(0.0, 2.0 * math.pi))
    cx, cy = draw(st.tuples(st.floats(-5, 5), st.floats(-5, 5)))
    x, y = np.cos(t), aspect * np.sin(t)
    c, s = math.cos(turn), math.sin(turn)
    return np.column_stack([cx + c * x - s * y, cy + s * x + c * y])


def convex_points() -> st.SearchStrategy[FloatArray]:
    """Point sets from any of the three families."""
    return st.one_of(lattice_points(), uniform_points(), ellipse_points())


def angles(lo: float = -2.0 * math.pi, hi: float = 4.0 * math.pi) -> st.SearchStrategy[float]:
    """Finite angles (radians), also outside ``[0, 2 pi)``."""
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)
