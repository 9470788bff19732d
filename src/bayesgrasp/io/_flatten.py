"""Curves of part files, flattened to polylines within a stated chordal tolerance.

Every curve here is sampled at points *on* the curve, so the polyline's vertices are exact;
the number of samples comes from a bound on the curve's second derivative, so the distance
between the curve and its polyline is at most the tolerance everywhere (not only at the
middle of each chord). For a parametric curve ``P`` on a parameter step ``h``, the distance
from ``P(t)`` to its chord is at most ``h**2 / 8 * max |P''|`` (linear interpolation error).

- Elliptic arcs ``P(t) = c + M cos t + m sin t`` (circles, arcs, bulges, SVG arcs, DXF
  ellipses): ``|P''| <= sigma``, the largest singular value of ``[M m]`` (the major radius).
- Bezier curves of degree ``d``: ``|B''| <= d (d - 1) max_i |P_i - 2 P_{i+1} + P_{i+2}|``.
- Curves given only as a sampler (rational DXF splines) are flattened by
  ezdxf's adaptive subdivision, which checks the distance at the middle of each chord.

The number of points of a curve is known before it is sampled, so a curve that would
flatten to more than the allowed number of points is refused without allocating them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from itertools import islice

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "Adaptive",
    "Bezier",
    "Curve",
    "EllipticArc",
    "FlattenBudget",
    "Polyline",
    "Ring",
    "TooManyPoints",
    "join",
]

FloatArray = NDArray[np.float64]

#: Largest parameter step on an elliptic arc (radians): even a coarse tolerance gives at
#: least four chords per full turn, so a circle stays a polygon with area.
MAX_ARC_STEP = math.pi / 2

#: Chord counts are capped here: a tolerance absurdly small for the curve (whose count
#: would overflow, or whose step underflows to zero) is refused by the point limit anyway.
_MAX_COUNT = 2**62


def _count(x: float) -> int:
    """``ceil(x)`` of a chord count (at least 1), capped at ``_MAX_COUNT``."""
    if not x < _MAX_COUNT:  # also inf and NaN
        return _MAX_COUNT
    return max(1, math.ceil(x - 1e-9))


class TooManyPoints(Exception):  # an internal signal, turned into PartFileError
    """A curve (or the whole file) would flatten to more points than allowed."""

    def __init__(self, what: str, count: int, limit: int) -> None:
        super().__init__(what, count, limit)
        self.what = what
        self.count = count
        self.limit = limit


@dataclass
class FlattenBudget:
    """Counts flattened points against a limit.

    Examples
    --------
    >>> b = FlattenBudget(10)
    >>> b.spend(4, "arc")
    >>> b.used
    4
    """

    limit: int
    used: int = 0

    def spend(self, count: int, what: str) -> None:
        """Account for ``count`` more points; raise :class:`TooManyPoints` past the limit."""
        if self.used + count > self.limit:
            raise TooManyPoints(what, self.used + count, self.limit)
        self.used += count


class Curve:
    """A piece of an outline, from :meth:`start` to :meth:`end`."""

    def start(self) -> FloatArray:
        """First point."""
        raise NotImplementedError

    def end(self) -> FloatArray:
        """Last point."""
        raise NotImplementedError

    def bounds(self) -> FloatArray:
        """A box ``[[xmin, ymin], [xmax, ymax]]`` that contains the curve."""
        raise NotImplementedError

    def n_segments(self, tol: float) -> int | None:
        """Number of chords at tolerance ``tol`` (``None`` when known only by sampling)."""
        raise NotImplementedError

    def points(self, tol: float, budget: FlattenBudget, what: str) -> FloatArray:
        """Flattened points ``(n + 1, 2)`` including both ends."""
        raise NotImplementedError

    def reverse(self) -> Curve:
        """The same curve run the other way."""
        raise NotImplementedError


@dataclass(frozen=True, eq=False)
class Polyline(Curve):
    """Straight segments through given points.

    Examples
    --------
    >>> Polyline(np.array([[0.0, 0], [1, 0], [1, 1]])).n_segments(0.1)
    2
    """

    vertices: FloatArray

    def start(self) -> FloatArray:
        return np.asarray(self.vertices[0], dtype=np.float64)

    def end(self) -> FloatArray:
        return np.asarray(self.vertices[-1], dtype=np.float64)

    def bounds(self) -> FloatArray:
        return np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def n_segments(self, tol: float) -> int:
        return len(self.vertices) - 1

    def points(self, tol: float, budget: FlattenBudget, what: str) -> FloatArray:
        budget.spend(len(self.vertices) - 1, what)
        return self.vertices

    def reverse(self) -> Polyline:
        return Polyline(self.vertices[::-1].copy())


@dataclass(frozen=True, eq=False)
class EllipticArc(Curve):
    """``P(t) = center + major cos t + minor sin t`` for ``t`` from ``t0`` to ``t0 + span``.

    ``span`` is signed (negative runs clockwise in ``t``). A circle of radius ``r`` has
    ``major = (r, 0)`` and ``minor = (0, r)``; ``major`` and ``minor`` need not be
    perpendicular (an affine image of a circle).

    Examples
    --------
    >>> quarter = EllipticArc(np.zeros(2), np.array([1.0, 0]), np.array([0, 1.0]), 0.0, np.pi / 2)
    >>> quarter.n_segments(1e-3)
    18
    """

    center: FloatArray
    major: FloatArray
    minor: FloatArray
    t0: float
    span: float
    pin: tuple[FloatArray, FloatArray] | None = None  # exact end points, when known

    def at(self, t: ArrayLike) -> FloatArray:
        """Points at parameters ``t`` (vectorised)."""
        tt = np.asarray(t, dtype=np.float64)[:, None]
        out: FloatArray = self.center + np.cos(tt) * self.major + np.sin(tt) * self.minor
        return out

    def start(self) -> FloatArray:
        return self.pin[0] if self.pin is not None else self.at([self.t0])[0]

    def end(self) -> FloatArray:
        return self.pin[1] if self.pin is not None else self.at([self.t0 + self.span])[0]

    def bounds(self) -> FloatArray:
        half = np.hypot(
            [self.major[0], self.major[1]], [self.minor[0], self.minor[1]]
        )  # extent of the full ellipse
        return np.array([self.center - half, self.center + half])

    def sigma(self) -> float:
        """Largest ``|P''(t)|``: the largest singular value of ``[major minor]``."""
        return float(np.linalg.norm(np.column_stack([self.major, self.minor]), 2))

    def n_segments(self, tol: float) -> int:
        sigma = self.sigma()
        step = MAX_ARC_STEP if sigma == 0 else min(math.sqrt(8.0 * tol / sigma), MAX_ARC_STEP)
        return _count(abs(self.span) / step) if step > 0 else _MAX_COUNT

    def points(self, tol: float, budget: FlattenBudget, what: str) -> FloatArray:
        n = self.n_segments(tol)
        budget.spend(n, what)
        pts = self.at(self.t0 + self.span * np.linspace(0.0, 1.0, n + 1))
        if self.pin is not None:
            pts[0], pts[-1] = self.pin
        return pts

    def reverse(self) -> EllipticArc:
        pin = None if self.pin is None else (self.pin[1], self.pin[0])
        return EllipticArc(
            self.center, self.major, self.minor, self.t0 + self.span, -self.span, pin
        )


@dataclass(frozen=True, eq=False)
class Bezier(Curve):
    """A Bezier curve of any degree, from its control points ``(d + 1, 2)``.

    Examples
    --------
    >>> c = Bezier(np.array([[0.0, 0], [1, 2], [3, 2], [4, 0]]))
    >>> c.n_segments(0.01), c.points(0.01, FlattenBudget(100), "c")[-1].tolist()
    (13, [4.0, 0.0])
    """

    control: FloatArray

    @property
    def degree(self) -> int:
        """Degree ``d`` (number of control points minus one)."""
        return len(self.control) - 1

    def start(self) -> FloatArray:
        return np.asarray(self.control[0], dtype=np.float64)

    def end(self) -> FloatArray:
        return np.asarray(self.control[-1], dtype=np.float64)

    def bounds(self) -> FloatArray:
        return np.array([self.control.min(axis=0), self.control.max(axis=0)])

    def n_segments(self, tol: float) -> int:
        d = self.degree
        if d < 2:
            return 1
        second = self.control[:-2] - 2.0 * self.control[1:-1] + self.control[2:]
        bound = d * (d - 1) * float(np.max(np.hypot(second[:, 0], second[:, 1])))
        return _count(math.sqrt(bound / (8.0 * tol)))

    def at(self, t: ArrayLike) -> FloatArray:
        """Points at parameters ``t`` in ``[0, 1]`` (Bernstein form, vectorised)."""
        tt = np.asarray(t, dtype=np.float64)[:, None]
        d = self.degree
        k = np.arange(d + 1)
        binom = np.array([math.comb(d, int(i)) for i in k], dtype=np.float64)
        basis = binom * tt**k * (1.0 - tt) ** (d - k)  # (T, d + 1)
        out: FloatArray = basis @ self.control
        return out

    def points(self, tol: float, budget: FlattenBudget, what: str) -> FloatArray:
        n = self.n_segments(tol)
        budget.spend(n, what)
        pts = self.at(np.linspace(0.0, 1.0, n + 1))
        pts[0], pts[-1] = self.control[0], self.control[-1]
        return pts

    def reverse(self) -> Bezier:
        return Bezier(self.control[::-1].copy())


@dataclass(frozen=True, eq=False)
class Adaptive(Curve):
    """A curve known through a sampler ``flatten(tol) -> iterable of (x, y)``.

    Used for curves whose derivatives the readers do not bound (rational
    splines); the sampler is ezdxf's adaptive subdivision.
    """

    sampler: Callable[[float], Iterable[tuple[float, float]]]
    first: FloatArray
    last: FloatArray
    box: FloatArray
    backwards: bool = False

    def start(self) -> FloatArray:
        return self.last if self.backwards else self.first

    def end(self) -> FloatArray:
        return self.first if self.backwards else self.last

    def bounds(self) -> FloatArray:
        return self.box

    def n_segments(self, tol: float) -> None:
        return None

    def points(self, tol: float, budget: FlattenBudget, what: str) -> FloatArray:
        room = budget.limit - budget.used + 2
        pts = list(islice(iter(self.sampler(tol)), room))
        if len(pts) >= room:
            raise TooManyPoints(what, budget.used + len(pts), budget.limit)
        budget.spend(len(pts) - 1, what)
        out = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
        return out[::-1].copy() if self.backwards else out

    def reverse(self) -> Adaptive:
        return Adaptive(self.sampler, self.first, self.last, self.box, not self.backwards)


@dataclass(frozen=True, slots=True, eq=False)
class Ring:
    """A closed ring of curves, with where it came from (for messages)."""

    curves: tuple[Curve, ...]
    source: str
    group: str = ""
    points: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))


def join(curves: Iterable[Curve], tol: float, budget: FlattenBudget, what: str) -> FloatArray:
    """Flatten consecutive curves into one point list (each curve's first point dropped).

    The first point of each further curve is the previous curve's last point (within the
    reader's gap tolerance), so it is dropped rather than doubled.

    Examples
    --------
    >>> a = Polyline(np.array([[0.0, 0], [1, 0]]))
    >>> b = Polyline(np.array([[1.0, 0], [1, 1]]))
    >>> join([a, b], 0.1, FlattenBudget(10), "x").tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]
    """
    parts: list[FloatArray] = []
    for c in curves:
        pts = c.points(tol, budget, what)
        parts.append(pts if not parts else pts[1:])
    return np.concatenate(parts) if parts else np.zeros((0, 2))


def predicted_points(curves: Iterable[Curve], tol: float) -> Iterator[int]:
    """Chord counts of the curves whose count is known before sampling."""
    for c in curves:
        n = c.n_segments(tol)
        if n is not None:
            yield n
