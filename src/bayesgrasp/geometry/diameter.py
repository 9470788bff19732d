"""The exact diameter function of a convex polygon (the seed, Appendix A).

``d(theta)`` is the width, along the gripper's squeeze axis x, of the part rotated
counter-clockwise by ``theta``. With the part's vertices ``v`` and the world x-axis seen from
the part, ``u(theta) = (cos theta, -sin theta)``,

    d(theta) = max_i <v_i, u> - min_j <v_j, u> = <v_i* - v_j*, u> = l |cos(theta - phi)|,

where ``(v_i*, v_j*)`` is the antipodal vertex pair touching the two jaws, ``l`` its length and
``phi`` the orientation at which that chord lies along x. The touching pair only changes when
an edge becomes parallel to the jaws (an *edge alignment*, ``theta = -nu_e mod pi`` for the
edge's outward normal angle ``nu_e``), so ``d`` is a sinusoid on each interval between
consecutive alignments (Appendix A). We find each interval's pair by rotating calipers
(Toussaint, "Solving geometric problems with the rotating calipers", 1983) done as a
binary search of the sorted edge normals: O(n log n) for all pieces
(:mod:`~bayesgrasp.geometry.diameter_pieces`).

Extrema: ``d`` is the maximum of sinusoids, so it is concave inside a piece and has convex
kinks at alignments. Minima can only be kinks whose left slope is negative and right slope
positive; maxima are the points inside a piece where its chord lies along x, or kinks where
the slopes on both sides are zero within the angle tolerance. Read around the circle, with
the slopes that are zero within the tolerance left out, minima and maxima alternate and pair
up by construction (see :func:`~bayesgrasp.geometry.diameter_pieces.pieces_numpy`). A
minimum less than ``Tolerance.barrier`` times the part's size below an adjacent maximum is
dropped with that maximum: rounded coordinates make parallel edges and perpendicular chords
only nearly so, which splits one stable orientation into two a hair apart.

Near-symmetric parts: a part whose ``symmetry_order`` is r >= 3 (every vertex lands within
``Tolerance.symmetry`` times the size of another under a turn by ``2 pi / r``) is taken to be
exactly symmetric. Its extrema are those of the symmetrized polygon
(:meth:`~bayesgrasp.geometry.polygon.ConvexPolygon.symmetrized`) over one period, simplified
there and repeated, so they have the period ``2 pi / (r (1 + r mod 2))`` exactly and the
squeeze, push and push-grasp functions built on them agree with the symmetry order (a part
with 1e-8 noise on a regular 1000-gon would otherwise break ``s(theta + T) = s(theta) + T``
by 1e-5 rad, and shallow pairs could be dropped in some periods and not in others). The
pieces stay those of the polygon itself: ``d(theta)`` is the part's own width.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..sizes import SMALL
from .convex import ConvexPolygon
from .diameter_pieces import (
    Pieces,
    drop_shallow,
    extrema_python,
    in_order,
    merged,
    piece_lists,
    pieces_numpy,
    pieces_python,
    wrap1,
)

__all__ = ["DiameterFunction", "diameter_function"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


class DiameterFunction:
    """Piecewise-sinusoidal diameter function over one period ``[0, pi)``.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] + pi``);
    on it ``d(theta) = lengths[k] * cos(theta - phases[k])``, with ``phases[k]`` within
    ``pi / 2`` of every angle of the piece. A frozen value: all arrays are read-only, and
    made on first use when the function was built on Python floats (a polygon of a few
    vertices; :attr:`extrema` gives the extrema as floats).

    Attributes
    ----------
    polygon : ConvexPolygon
    breaks : ndarray of shape (P,)
        Edge-alignment angles in ``[0, pi)``, increasing (parallel edges give one).
    lengths : ndarray of shape (P,)
        Length of the chord touching both jaws on each piece.
    phases : ndarray of shape (P,)
        Orientation at which that chord lies along the squeeze axis.
    pairs : ndarray of shape (P, 2)
        Indices of the vertices touching the +x and -x jaws on each piece.
    minima : ndarray
        Local minima in ``[0, pi)`` (edge alignments where ``d`` is locally least), except
        those shallower than ``polygon.tol.barrier * polygon.size``; for a part symmetric
        within the tolerance (order 3 or more), those of its symmetrized vertices, exactly
        periodic (see the module docstring).
    maxima : ndarray
        Local maxima in ``[0, pi)`` (unstable equilibria of a squeeze), alternating with
        the minima.

    Examples
    --------
    >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> np.degrees(d.minima).round(6).tolist(), d([0.0, np.pi / 2]).round(12).tolist()
    ([0.0, 90.0], [2.0, 1.0])
    >>> d.extrema == (tuple(d.minima.tolist()), tuple(d.maxima.tolist()))
    True
    """

    __slots__ = ("_arrays", "_data", "polygon")

    polygon: ConvexPolygon
    # breaks, lengths, phases, pairs, minima, maxima: arrays, or (pairs: two) float tuples
    _data: tuple[object, ...]
    _arrays: tuple[NDArray[np.generic], ...] | None

    def __init__(
        self,
        polygon: ConvexPolygon,
        breaks: ArrayLike,
        lengths: ArrayLike,
        phases: ArrayLike,
        pairs: ArrayLike,
        minima: ArrayLike,
        maxima: ArrayLike,
    ) -> None:
        f8 = np.float64
        cols = (
            np.array(breaks, dtype=f8),
            np.array(lengths, dtype=f8),
            np.array(phases, dtype=f8),
            np.array(pairs, dtype=np.intp).reshape(-1, 2),
            np.array(minima, dtype=f8),
            np.array(maxima, dtype=f8),
        )  # copies: the caller's arrays stay theirs (and writeable)
        self._set(polygon, cols)

    def _set(self, polygon: ConvexPolygon, data: tuple[object, ...]) -> None:
        _SET_POLYGON(self, polygon)
        _SET_DATA(self, data)
        _SET_ARRAYS(self, None)

    @classmethod
    def _of_floats(
        cls,
        polygon: ConvexPolygon,
        pieces: tuple[list[float], list[float], list[float], list[int], list[int]],
        minima: list[float],
        maxima: list[float],
    ) -> DiameterFunction:
        """From the pieces as :func:`pieces_python` (lists) or :func:`pieces_numpy` gives them.

        Unchecked; lists become read-only arrays on first use.
        """
        breaks, lengths, phases, i_plus, i_minus = pieces
        out = cls.__new__(cls)
        _SET_POLYGON(out, polygon)
        _SET_DATA(out, (breaks, lengths, phases, (i_plus, i_minus), minima, maxima))
        _SET_ARRAYS(out, None)
        return out

    def __setattr__(self, name: str, value: object) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[object, ...]:
        return (DiameterFunction, (self.polygon, *self._columns()))

    def __repr__(self) -> str:
        names = ("breaks", "lengths", "phases", "pairs", "minima", "maxima")
        cols = ", ".join(f"{k}={v!r}" for k, v in zip(names, self._columns(), strict=True))
        return f"DiameterFunction(polygon={self.polygon!r}, {cols})"

    def _columns(self) -> tuple[NDArray[np.generic], ...]:
        arrays = self._arrays
        if arrays is None:
            out: list[NDArray[np.generic]] = []
            for k, col in enumerate(self._data):
                if type(col) is np.ndarray:
                    arr = col
                elif k == 3:  # the jaws' vertex indices (i_plus, i_minus), as two columns
                    arr = np.array(col, dtype=np.intp).reshape(2, -1).T.copy()
                else:
                    arr = np.array(col, dtype=np.float64)
                arr.setflags(write=False)
                out.append(arr)
            arrays = tuple(out)
            object.__setattr__(self, "_arrays", arrays)
        return arrays

    @property
    def extrema(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """``minima`` and ``maxima`` as tuples of Python floats (what the squeeze needs)."""
        lows, highs = self._data[4], self._data[5]
        return (
            tuple(lows.tolist() if isinstance(lows, np.ndarray) else lows),  # type: ignore[arg-type]
            tuple(highs.tolist() if isinstance(highs, np.ndarray) else highs),  # type: ignore[arg-type]
        )

    def _extrema_lists(self) -> tuple[list[float], list[float]]:
        """``minima`` and ``maxima`` as lists of Python floats (the caller must not change them)."""
        lows, highs = self._data[4], self._data[5]
        return (
            lows.tolist() if isinstance(lows, np.ndarray) else lows,  # type: ignore[return-value]
            highs.tolist() if isinstance(highs, np.ndarray) else highs,
        )

    @property
    def breaks(self) -> FloatArray:
        """Edge-alignment angles in ``[0, pi)``, increasing (read-only)."""
        return self._columns()[0]  # type: ignore[return-value]

    @property
    def lengths(self) -> FloatArray:
        """Length of the chord touching both jaws on each piece (read-only)."""
        return self._columns()[1]  # type: ignore[return-value]

    @property
    def phases(self) -> FloatArray:
        """Orientation at which each piece's chord lies along the squeeze axis (read-only)."""
        return self._columns()[2]  # type: ignore[return-value]

    @property
    def pairs(self) -> IntArray:
        """Vertices touching the +x and -x jaws on each piece, shape (P, 2) (read-only)."""
        return self._columns()[3]  # type: ignore[return-value]

    @property
    def minima(self) -> FloatArray:
        """Local minima in ``[0, pi)`` (read-only)."""
        return self._columns()[4]  # type: ignore[return-value]

    @property
    def maxima(self) -> FloatArray:
        """Local maxima in ``[0, pi)`` (read-only)."""
        return self._columns()[5]  # type: ignore[return-value]

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Evaluate ``d`` at any angles (radians), vectorised.

        Examples
        --------
        >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
        >>> np.round(d([0.0, np.pi / 4]), 12).tolist()
        [1.0, 1.414213562373]
        """
        th = np.asarray(theta, dtype=np.float64)
        k = self.piece_index(th)
        return self.lengths[k] * np.abs(np.cos(th - self.phases[k]))

    def piece_index(self, theta: ArrayLike) -> IntArray:
        """Index of the piece holding each angle."""
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        k = np.searchsorted(self.breaks - self.breaks[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.breaks) - 1), dtype=np.intp)

    @property
    def diameter(self) -> float:
        """The polygon's diameter (the largest value of ``d``)."""
        return float(self.lengths.max())


# The fields' setters, for the constructors: the class itself refuses assignment (a value).
_SET_POLYGON, _SET_DATA, _SET_ARRAYS = (
    DiameterFunction.__dict__[name].__set__ for name in ("polygon", "_data", "_arrays")
)


def diameter_function(polygon: ConvexPolygon) -> DiameterFunction:
    """Build the exact diameter function of a convex polygon in O(n log n).

    The pieces (``breaks``, ``lengths``, ``phases``, ``pairs``) are those of the polygon.
    The extrema are those of ``d`` too, except for a part that is r-fold symmetric within
    ``tol.symmetry`` (``polygon.symmetry_order``, r >= 3): it is treated as exactly
    symmetric, and its extrema are those of :meth:`ConvexPolygon.symmetrized` over one
    period ``T = 2 pi / (r (1 + r mod 2))``, repeated every ``T``. They then have the period
    exactly (to rounding), and lie within the part's own round-off (about ``tol.symmetry``
    times the size over an edge length, in radians) of its own extrema.

    Parameters
    ----------
    polygon : ConvexPolygon

    Returns
    -------
    DiameterFunction

    Raises
    ------
    BayesGraspError
        An internal error (a bug): no extremum, or minima and maxima that do not pair up.

    Examples
    --------
    >>> tri = ConvexPolygon.from_points([(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)])
    >>> d = diameter_function(tri)
    >>> len(d.minima), len(d.maxima)
    (3, 3)
    """
    tol = polygon.tol.angle
    small = len(polygon.vertices) <= _SMALL
    depth = polygon.tol.barrier_for(polygon.size)
    r = polygon.symmetry_order_from(3)  # a half turn changes nothing: d has the period pi
    periods = r * (1 + r % 2) // 2 if r > 1 else 1  # periods of d in [0, pi)
    pieces: Pieces
    if small:
        breaks, ends, lengths, phases, i_plus, i_minus, events = piece_lists(
            *polygon._coords(), tol
        )
        lists = (breaks, lengths, phases, i_plus, i_minus)
        if periods == 1:
            found = in_order(breaks, ends, lengths, phases, events, tol, depth)  # most parts
            if found is None:
                ext = extrema_python(breaks, ends, lengths, phases, len(breaks), tol)
                kept = drop_shallow(merged(ext, 0.0, math.pi), depth)
                found = [x for x, _, top in kept if not top], [x for x, _, top in kept if top]
            return DiameterFunction._of_floats(polygon, lists, *found)
        pieces = (*lists, ([], [], [], []))  # the extrema come from the symmetrized polygon
    else:
        pieces = pieces_numpy(polygon.vertices, tol, math.pi)
    if periods > 1:
        # One period of the exactly symmetric part, simplified as a periodic function and
        # repeated: the shallow pairs go in every period or in none.
        period = math.pi / periods
        sym = polygon.symmetrized(centred=True)  # translation-free: see its docstring
        if small:
            one = pieces_python(sym[:, 0].tolist(), sym[:, 1].tolist(), tol, period)
        else:
            one = pieces_numpy(sym, tol, period)
        origin = float(one[0][0])
        kept = drop_shallow(merged(one[5], origin, period), depth)
        minima, maxima = (
            np.sort(
                np.array(
                    [
                        wrap1(origin + at + k * period, math.pi)
                        for at, _, top in kept
                        if top is is_max
                        for k in range(periods)
                    ],
                    dtype=np.float64,
                )
            ).tolist()
            for is_max in (False, True)
        )
    else:
        kept = drop_shallow(merged(pieces[5], 0.0, math.pi), depth)
        minima = [at for at, _, top in kept if not top]
        maxima = [at for at, _, top in kept if top]
    return DiameterFunction._of_floats(polygon, pieces[:5], minima, maxima)  # type: ignore[arg-type]


# At or below this many vertices the pieces and extrema are computed on Python floats
# (numpy's cost of a call exceeds the work); both paths make the same decisions
# (tests/geometry/test_diameter.py and test_numerics.py compare them).
_SMALL = SMALL
