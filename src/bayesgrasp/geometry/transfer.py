"""Transfer functions: what one action does to the part's orientation.

A transfer function here is a step function on the circle: the part, at orientation
``theta`` in the gripper frame, ends at ``F(theta)``. Both the squeeze function (the seed,
section 4.2) and the push-grasp function (Goldberg 1993) have this form: finitely many stable
orientations, each with a *basin* (an open arc between consecutive unstable equilibria) that
it attracts, and ``F(theta + 2 pi) = F(theta) + 2 pi`` with ``F`` non-decreasing. An
orientation exactly at a basin boundary is an unstable equilibrium and stays where it is.

The squeeze function descends the diameter function: each minimum of ``d`` over ``[0, 2 pi)``
is a stable orientation and its basin runs between the neighbouring maxima. It commutes with
the part's symmetry: ``s(theta + T) = s(theta) + T`` for the period ``T`` (pi, or
``2 pi / (r (1 + r mod 2))`` for an r-fold symmetric part, Goldberg 1993).

Periods are measured to the angle tolerance, so ``F(theta + T) = F(theta) + T`` holds to
that tolerance. A part symmetric within ``Tolerance.symmetry`` (its ``symmetry_order``) is
symmetric everywhere downstream: its diameter and radius functions have exactly periodic
extrema (diameter.py), so the squeeze period is the formula's and the push and push-grasp
periods are ``2 pi / r`` (when the centre of mass is the centroid). A part that is not
symmetric within that tolerance has the period pi, however nearly periodic its extrema.
"""

from __future__ import annotations

import bisect
import dataclasses
import functools
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import BayesGraspError
from .diameter import DiameterFunction, diameter_function
from .polygon import ConvexPolygon

__all__ = ["TransferFunction", "detect_period", "squeeze_function", "transfer_from_extrema"]

FloatArray = NDArray[np.float64]


class TransferFunction:
    """A monotone step function on the circle: stable orientations and their basins.

    State ``i`` is the stable orientation ``stable[i]`` in ``[0, 2 pi)`` (increasing); its
    basin is the open arc ``(basin_lo[i], basin_hi[i])`` around it (``basin_lo[0]`` may be
    negative and ``basin_hi[-1]`` may pass ``2 pi``). Basins tile the circle. A frozen value:
    the arrays are read-only, and made on first use when the function was built from Python
    floats (a squeeze function of a few states: see :attr:`values`).

    Attributes
    ----------
    kind : str
        ``"squeeze"`` or ``"push-grasp"`` (or ``"push"``).
    stable, basin_lo, basin_hi : ndarray of shape (K,)
    period : float
        Smallest ``T`` with ``F(theta + T) = F(theta) + T`` to ``angle_tol`` (divides
        ``2 pi``).
    angle_tol : float
        Angles closer than this are equal.

    Examples
    --------
    >>> s = squeeze_function(ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    >>> np.degrees(s.stable).round(6).tolist(), round(float(np.degrees(s.period)), 6)
    ([0.0, 90.0, 180.0, 270.0], 90.0)
    >>> float(np.degrees(s(np.radians(30.0))))
    0.0
    >>> s.values[0] == tuple(s.stable.tolist())
    True
    """

    __slots__ = ("_arrays", "_values", "angle_tol", "kind", "period")

    kind: str
    period: float
    angle_tol: float
    _values: tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None
    _arrays: tuple[FloatArray, FloatArray, FloatArray] | None

    def __init__(
        self,
        kind: str,
        stable: ArrayLike,
        basin_lo: ArrayLike,
        basin_hi: ArrayLike,
        period: float,
        angle_tol: float,
    ) -> None:
        cols = (stable, basin_lo, basin_hi)
        put = object.__setattr__
        put(self, "kind", kind)
        put(self, "period", period)
        put(self, "angle_tol", angle_tol)
        if all(type(c) is np.ndarray for c in cols):  # kept as given (push.py: read-only)
            put(self, "_values", None)
            put(self, "_arrays", cols)
        else:
            floats = (tuple(np.asarray(c, dtype=np.float64).tolist()) for c in cols)
            put(self, "_values", tuple(floats))
            put(self, "_arrays", None)

    @classmethod
    def _of_floats(
        cls,
        kind: str,
        values: tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]],
        period: float,
        angle_tol: float,
    ) -> TransferFunction:
        """From tuples of Python floats, unchecked; the arrays are made on first use."""
        f = object.__new__(cls)
        _SET_KIND(f, kind)
        _SET_PERIOD(f, period)
        _SET_ANGLE_TOL(f, angle_tol)
        _SET_VALUES(f, values)
        _SET_ARRAYS(f, None)
        return f

    def __setattr__(self, name: str, value: object) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[object, ...]:
        return (TransferFunction, (self.kind, *self._columns(), self.period, self.angle_tol))

    def __repr__(self) -> str:
        st, lo, hi = self._columns()
        return (
            f"TransferFunction(kind={self.kind!r}, stable={st!r}, basin_lo={lo!r}, "
            f"basin_hi={hi!r}, period={self.period!r}, angle_tol={self.angle_tol!r})"
        )

    def renamed(self, kind: str) -> TransferFunction:
        """The same function under another ``kind`` (an action named after its own motion)."""
        f = object.__new__(TransferFunction)
        for name in TransferFunction.__slots__:
            object.__setattr__(f, name, getattr(self, name))
        object.__setattr__(f, "kind", kind)
        return f

    def _columns(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        arrays = self._arrays
        if arrays is None:
            assert self._values is not None
            arrays = tuple(np.array(c, dtype=np.float64) for c in self._values)  # type: ignore[assignment]
            assert arrays is not None
            for arr in arrays:
                arr.setflags(write=False)
            object.__setattr__(self, "_arrays", arrays)
        return arrays

    @property
    def values(self) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
        """``stable``, ``basin_lo`` and ``basin_hi`` as tuples of Python floats.

        For loops over a few states, where numpy's cost per call is most of the work.
        """
        values = self._values
        if values is None:
            assert self._arrays is not None
            values = tuple(tuple(a.tolist()) for a in self._arrays)  # type: ignore[assignment]
            assert values is not None
            object.__setattr__(self, "_values", values)
        return values

    @property
    def stable(self) -> FloatArray:
        """Stable orientations in ``[0, 2 pi)``, increasing (read-only)."""
        return self._columns()[0]

    @property
    def basin_lo(self) -> FloatArray:
        """Start of each stable orientation's basin (read-only)."""
        return self._columns()[1]

    @property
    def basin_hi(self) -> FloatArray:
        """End of each stable orientation's basin (read-only)."""
        return self._columns()[2]

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Final orientation in ``[0, 2 pi)`` for each initial orientation (vectorised).

        An orientation within ``angle_tol`` of a basin boundary is an unstable equilibrium
        and is returned unchanged (reduced to ``[0, 2 pi)``).
        """
        th = np.mod(np.asarray(theta, dtype=np.float64), TWO_PI)
        idx = self.state_index(th)
        out = self.stable[idx]
        at_edge = (
            np.minimum(
                np.abs(np.mod(th - self.basin_lo[idx] + math.pi, TWO_PI) - math.pi),
                np.abs(np.mod(th - self.basin_hi[idx] + math.pi, TWO_PI) - math.pi),
            )
            <= self.angle_tol
        )
        return np.where(at_edge, th, out)

    def state_index(self, theta: ArrayLike) -> NDArray[np.intp]:
        """Index of the basin that holds each orientation."""
        th = np.mod(np.asarray(theta, dtype=np.float64), TWO_PI)
        hi = np.mod(self.basin_hi, TWO_PI)
        order = np.argsort(hi)
        k = np.searchsorted(hi[order], th, side="right")
        return order[k % len(order)]

    @property
    def n_states(self) -> int:
        """Number of stable orientations over ``[0, 2 pi)``."""
        values = self._values
        return len(values[0]) if values is not None else len(self.stable)

    @property
    def boundaries(self) -> FloatArray:
        """Basin boundaries (unstable equilibria) in ``[0, 2 pi)``, increasing."""
        return np.sort(np.mod(self.basin_hi, TWO_PI))

    @property
    def widths(self) -> FloatArray:
        """Width of each basin (radians)."""
        return self.basin_hi - self.basin_lo


# The slots' own setters: a frozen value's fields set at about half the cost of
# object.__setattr__ (the squeeze function of every part is built this way).
_SET_KIND, _SET_PERIOD, _SET_ANGLE_TOL, _SET_VALUES, _SET_ARRAYS = (
    TransferFunction.__dict__[name].__set__
    for name in ("kind", "period", "angle_tol", "_values", "_arrays")
)


def detect_period(stable: FloatArray, boundaries: FloatArray, tol: float) -> float:
    """Smallest shift ``T = 2 pi / m`` mapping both point sets onto themselves.

    ``m`` runs over the divisors of ``K = len(stable)``; a shift by ``T`` moves every point
    ``K / m`` places along, so the test is exact up to ``tol`` radians for any ``m``.

    Examples
    --------
    >>> T = detect_period(np.radians([0.0, 120, 240]), np.radians([60.0, 180, 300]), 1e-9)
    >>> round(float(np.degrees(T)), 9)
    120.0
    """
    st = np.asarray(stable, dtype=np.float64).tolist()
    bd = np.asarray(boundaries, dtype=np.float64).tolist()
    return TWO_PI / _period_count(st, bd, len(st), 1, tol)


def _period_count(
    stable: list[float], bounds: list[float], top: int, base: int, tol: float, known: int = 1
) -> int:
    """Largest ``m <= top``, a multiple of ``base`` dividing ``K``, whose shift maps both lists.

    Returns ``base`` when no larger ``m`` works. ``known`` is a count whose shift is known
    to map both lists to within ``tol`` (a squeeze function's half turn: 2); counts from
    ``known`` down are then not tested and ``known`` is returned in their place, which is
    what their test would give. Plain Python: ``K`` is small, and numpy's cost per call
    would be most of the work.
    """
    first = stable[0]
    pi, two_pi = math.pi, TWO_PI
    k = len(stable)
    floor = max(base, known)  # what every count from here down gives (tested or not)
    every = top >= k and base == 1  # every divisor is a candidate (the squeeze function)
    for m, step, t in _divisors(k):  # largest first
        if m <= floor:
            break
        if not every and (m > top or m % base):
            continue
        # Cheap test on one point first: most m fail there.
        if abs((stable[step] - first - t + pi) % two_pi - pi) > tol:
            continue
        if _shifts_onto_itself(stable, step, t, tol) and _shifts_onto_itself(bounds, step, t, tol):
            return m
    return floor


@functools.cache
def _divisors(k: int) -> tuple[tuple[int, int, float], ...]:
    """The divisors ``m`` of ``k``, largest first, with the step ``k / m`` and ``2 pi / m``."""
    return tuple((m, k // m, TWO_PI / m) for m in range(k, 0, -1) if k % m == 0)


def _shifts_onto_itself(points: list[float], step: int, shift: float, tol: float) -> bool:
    """Whether point ``i + step`` lies ``shift`` after point ``i`` (cyclically), for all i."""
    k, pi = len(points), math.pi
    return all(
        abs((points[(i + step) % k] - points[i] - shift + pi) % TWO_PI - pi) <= tol
        for i in range(k)
    )


def _wrap(x: float) -> float:
    """``x`` reduced to ``[0, 2 pi)`` (``%`` can round a tiny negative to ``2 pi``)."""
    out = x % TWO_PI
    return 0.0 if out >= TWO_PI else out


def transfer_from_extrema(
    kind: str, minima: FloatArray, maxima: FloatArray, angle_tol: float, period_tol: float
) -> TransferFunction:
    """Build a transfer function from its stable orientations and unstable equilibria.

    Parameters
    ----------
    kind : str
    minima, maxima : ndarray
        Stable orientations and basin boundaries over ``[0, 2 pi)``; they must alternate.
    angle_tol, period_tol : float
        Angle equality, and the looser tolerance of the period test.
    """
    stable = sorted(_wrap(x) for x in np.asarray(minima, dtype=np.float64).tolist())
    bounds = sorted(_wrap(x) for x in np.asarray(maxima, dtype=np.float64).tolist())
    return _from_sorted(kind, stable, bounds, angle_tol, period_tol)


def _from_sorted(
    kind: str,
    stable: list[float],
    bounds: list[float],
    angle_tol: float,
    period_tol: float,
    known: int = 1,
) -> TransferFunction:
    """:func:`transfer_from_extrema` for sorted lists in ``[0, 2 pi)``.

    ``known``: a count of equal shifts known to map both lists onto themselves (see
    :func:`_period_count`).
    """
    n = len(stable)
    if n != len(bounds) or n == 0:  # pragma: no cover - a bug
        raise BayesGraspError("internal error: stable orientations and boundaries differ")
    # The boundary above each stable orientation (wrapping past 2 pi). They alternate when
    # that index counts up by one: 0, 1, ..., K - 1 or 1, 2, ..., K.
    k0 = bisect.bisect_right(bounds, stable[0])
    # Boundary k0 + i - 1 <= stable[i] < boundary k0 + i, for every i (bisect's counts).
    # (Equal lengths, checked above: zip's strict= would cost a third of these loops.)
    alternate = True
    prev = -math.inf
    if k0 == 0:  # stable[0] < bounds[0] <= stable[1] < bounds[1] <= ...
        for x, b in zip(stable, bounds):  # noqa: B905
            if not prev <= x < b:
                alternate = False
                break
            prev = b
    else:  # bounds[0] <= stable[0] < bounds[1] <= stable[1] < ...
        for x, b in zip(stable, bounds):  # noqa: B905
            if not prev < b <= x:
                alternate = False
                break
            prev = x
    if k0 > 1 or not alternate:
        raise BayesGraspError(  # pragma: no cover - a bug
            "internal error: extrema of the transfer function do not alternate"
        )
    if k0 == 0:  # stable[i] lies between bounds[i - 1] and bounds[i]
        lo = (bounds[-1] - TWO_PI, *bounds[:-1])
        hi = tuple(bounds)
    else:  # stable[i] lies between bounds[i] and bounds[i + 1]
        lo = tuple(bounds)
        hi = (*bounds[1:], bounds[0] + TWO_PI)
    period = TWO_PI / _period_count(stable, bounds, n, 1, period_tol, known)
    return TransferFunction._of_floats(kind, (tuple(stable), lo, hi), period, angle_tol)


def squeeze_function(
    part: ConvexPolygon | DiameterFunction,
) -> TransferFunction:
    """The squeeze function of a polygon (the seed, section 4.2).

    Parameters
    ----------
    part : ConvexPolygon or DiameterFunction

    Returns
    -------
    TransferFunction
        Stable orientations are the minima of ``d`` over ``[0, 2 pi)``; basins run between
        consecutive maxima. The period is the smallest shift ``2 pi / m`` that maps them
        onto themselves to the angle tolerance, so ``s(theta + T) = s(theta) + T`` holds to
        that tolerance: ``pi``, or ``2 pi / (r (1 + r mod 2))`` for a part r-fold symmetric
        within ``tol.symmetry`` (``symmetry_order``): the diameter function of such a part
        has exactly periodic extrema (those of its symmetrized vertices), also when rounded
        coordinates make the part's own extrema periodic only to about 1e-5 rad. (A finer
        period would need extrema that are periodic by coincidence, beyond the symmetry.)

    Examples
    --------
    >>> tri = ConvexPolygon.from_points([(0, 0), (1, 0), (0.5, np.sqrt(3) / 2)])
    >>> s = squeeze_function(tri)
    >>> s.n_states, round(float(np.degrees(s.period)), 9), s.widths.round(9).tolist()[0]
    (6, 60.0, 1.047197551)
    """
    d = part if isinstance(part, DiameterFunction) else diameter_function(part)
    tol = d.polygon.tol.angle
    pi, two_pi = math.pi, TWO_PI
    lows: list[float]
    highs: list[float]
    lows, highs = d._data[4], d._data[5]  # type: ignore[assignment]  # lists, or arrays
    # Lists are diameter_function's own, sorted in [0, pi); arrays any the caller gave.
    ordered = type(lows) is list and type(highs) is list
    if not ordered:
        lows, highs = d._extrema_lists()
    # x in [0, pi): a + pi is no tiny negative, so % needs none of _wrap's care.
    stable, bounds = [*lows], [*highs]
    for a in lows:
        stable.append((a + pi) % two_pi)
    for a in highs:
        bounds.append((a + pi) % two_pi)
    # Sorted lists shifted by pi stay sorted in [pi, 2 pi) after them, but for those that
    # round up to 2 pi and wrap to 0 (the last ones): only then is there anything to sort.
    if not ordered or (stable and stable[-1] < pi):
        stable.sort()
    if not ordered or (bounds and bounds[-1] < pi):
        bounds.sort()
    # A half turn maps the lists onto themselves to a few rounding errors of 2 pi, well
    # within any angle tolerance (>= MIN_ANGLE): two equal shifts are known.
    return _from_sorted("squeeze", stable, bounds, tol, tol, 2)
