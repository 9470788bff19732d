"""The diameter function of a curved part and its extrema (the squeeze's states).

See :mod:`bayesgrasp.geometry.curved`, "Diameter" and "Certainty": :class:`CurvedDiameter`
and :func:`curved_diameter`; the extrema of a function of pieces, their cancellation by
persistence and their refinement on exact curves, which the radius function shares.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from .curved_support import CurvedHull, CurvePatches

__all__ = [
    "PUSHER_JAW",
    "CurvedDiameter",
    "Extremum",
    "cancel_shallow",
    "curved_diameter",
    "extrema_of_pieces",
    "refined_extrema",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


# --------------------------------------------------------------------------------------
# The diameter function and its extrema


@dataclass(frozen=True, slots=True)
class Extremum:
    """A local extremum of ``d``: where, how wide the jaws are, and which kind."""

    theta: float
    value: float
    is_max: bool
    kink: bool  # at an edge alignment (a flush edge for a minimum)


@dataclass(frozen=True, slots=True, eq=False)
class CurvedDiameter:
    """The exact diameter function of a curved hull over ``[0, pi)``, and its extrema.

    Piece ``k`` covers ``[breaks[k], breaks[k + 1])`` (the last ends at ``breaks[0] + pi``);
    on it ``d(theta) = chords[k] . (cos theta, -sin theta) + offsets[k]``.

    Attributes
    ----------
    hull : CurvedHull
    breaks : ndarray of shape (B,)
    chords : ndarray of shape (B, 2)
    offsets : ndarray of shape (B,)
    extrema : tuple of Extremum
        Every local extremum of ``d`` over ``[0, pi)``, alternating, before the uncertain
        pairs are cancelled.
    minima, maxima : ndarray
        The certain ones (states and basin boundaries over ``[0, pi)``), alternating.
    error : float
        The bound on how far the outline may be from the true part (flattening and shape
        tolerance); ``d`` is within ``2 error`` of the true diameter function.
    depth : float
        Pairs shallower than this were cancelled (``4 error``, at least the barrier).

    Examples
    --------
    >>> from bayesgrasp.geometry.curved_ring import CurvedRing
    >>> from bayesgrasp.geometry.curved_support import curved_hull
    >>> slot = CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1])
    >>> d = curved_diameter(curved_hull(slot))
    >>> np.degrees(d.minima).round(9).tolist(), np.round(d([0.0, np.pi / 2]), 12).tolist()
    ([90.0], [4.0, 2.0])
    """

    hull: CurvedHull
    breaks: FloatArray
    chords: FloatArray
    offsets: FloatArray
    extrema: tuple[Extremum, ...]
    minima: FloatArray
    maxima: FloatArray
    error: float = 0.0
    depth: float = 0.0
    _kept: tuple[Extremum, ...] = field(default=(), repr=False)

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """``d(theta)``, vectorised."""
        th = self._representative(theta)
        k = self.piece_index(th)
        g = self.chords[k]
        out: FloatArray = g[..., 0] * np.cos(th) - g[..., 1] * np.sin(th) + self.offsets[k]
        return out

    def _representative(self, theta: ArrayLike) -> FloatArray:
        """The angle in ``[breaks[0], breaks[0] + pi)`` equal to ``theta`` mod pi.

        A piece's chord belongs to its own angles: a half turn swaps the contacts.
        """
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        return np.asarray(t + self.breaks[0], dtype=np.float64)

    def slope(self, theta: ArrayLike) -> FloatArray:
        """``d'(theta)`` (from the right at a kink)."""
        th = self._representative(theta)
        k = self.piece_index(th)
        g = self.chords[k]
        out: FloatArray = -g[..., 0] * np.sin(th) - g[..., 1] * np.cos(th)
        return out

    def piece_index(self, theta: ArrayLike) -> IntArray:
        """Index of the piece holding each angle."""
        t = np.mod(np.asarray(theta, dtype=np.float64) - self.breaks[0], math.pi)
        k = np.searchsorted(self.breaks - self.breaks[0], t, side="right") - 1
        return np.asarray(np.clip(k, 0, len(self.breaks) - 1), dtype=np.intp)

    @property
    def diameter(self) -> float:
        """The largest width of the part."""
        if self.maxima.size:
            return float(np.max(self(self.maxima)))
        return float(np.max(self(np.linspace(0.0, math.pi, 721))))

    @property
    def kept(self) -> tuple[Extremum, ...]:
        """The certain extrema over ``[0, pi)`` (minima and maxima, alternating)."""
        return self._kept


def _sub_pieces(hull: CurvedHull, tol: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Breaks of ``d`` in ``[0, pi)`` and each piece's chord and offset."""
    b = np.sort(np.mod(-hull.starts, math.pi))
    wide = np.diff(b, prepend=b[-1] - math.pi) > tol
    breaks = b[wide] if wide.any() else b[:1]
    ends = np.append(breaks[1:], breaks[0] + math.pi)
    mids = 0.5 * (breaks + ends)
    a = hull.piece_index(-mids)
    o = hull.piece_index(math.pi - mids)
    chords = hull.centers[a] - hull.centers[o]
    offsets = hull.radii[a] + hull.radii[o]
    return breaks, chords, offsets


_BOTH = (0.0, math.pi)  # the jaws' outward directions are u(jaw - theta): both jaws
PUSHER_JAW = (math.pi,)  # the pushing jaw only (the radius function)


def _flush(hull: CurvedHull, theta: float, tol: float, jaws: tuple[float, ...] = _BOTH) -> float:
    """Total length of the edges parallel to the jaws at ``theta`` (0: a smooth point)."""
    total = 0.0
    for phi in (j - theta for j in jaws):
        k = int(hull.piece_index(phi + tol))
        if abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol:
            total += float(hull.edges[k])
    return total


def extrema_of_pieces(
    breaks: FloatArray,
    chords: FloatArray,
    offsets: FloatArray,
    hull: CurvedHull,
    atol: float,
    period: float = math.pi,
    jaws: tuple[float, ...] = _BOTH,
) -> list[Extremum]:
    """Every local extremum of ``d`` over ``[0, pi)``, in order (see the module docstring).

    The same for the radius function (``period`` 2 pi, the pushing jaw only): any function
    ``chords[k] . (cos theta, -sin theta) + offsets[k]`` on pieces starting at ``breaks``.

    The slope of ``d`` is cut into runs of one sign: each piece is split at the zeros of
    its slope inside it; a run whose slope is within the length tolerance of zero is flat.
    Reading the runs around the circle without the flat ones, each change from - to + is a
    minimum and each change from + to - a maximum: at the junction of the two runs, or the
    middle of the flat stretch between them.
    """
    ltol = hull.tol.length_for(hull.size)
    ends = np.append(breaks[1:], breaks[0] + period)
    runs: list[tuple[float, float, int, bool]] = []  # start, end, sign, starts at a break
    for k in range(len(breaks)):
        s, e = float(breaks[k]), float(ends[k])
        gx, gy = float(chords[k, 0]), float(chords[k, 1])
        z0 = math.atan2(-gy, gx)  # the slope -gx sin - gy cos is zero at z0 + j pi
        zeros = sorted(
            z
            for j in range(-2, 4)
            if s + atol < (z := z0 + j * math.pi + math.floor(s / math.pi) * math.pi) < e - atol
        )
        cuts = [s, *zeros, e]
        for i in range(len(cuts) - 1):
            a, b = cuts[i], cuts[i + 1]
            m = 0.5 * (a + b)
            slope = -gx * math.sin(m) - gy * math.cos(m)
            sign = 0 if abs(slope) <= ltol else (1 if slope > 0 else -1)
            runs.append((a, b, sign, i == 0))
    signed = [i for i, run in enumerate(runs) if run[2] != 0]
    out: list[Extremum] = []
    if not signed:
        return out
    n = len(runs)
    for t, j in enumerate(signed):
        i = signed[t - 1]
        if runs[i][2] == runs[j][2]:
            continue
        lo = runs[i][1]
        hi = runs[j][0] if j > i else runs[j][0] + period
        if (j - i) % n == 1:
            at = lo
            kink = runs[j][3] and _flush(hull, lo, atol, jaws) > 0.0
        else:
            at = 0.5 * (lo + hi)
            kink = False
        at = at % period
        if period - at <= atol:  # the start of the period, not its end
            at = 0.0
        value = float(_evaluate(breaks, chords, offsets, at, period))
        out.append(Extremum(at, value, runs[i][2] > 0, kink))
    out.sort(key=lambda e: e.theta)
    return out


def _evaluate(
    breaks: FloatArray, chords: FloatArray, offsets: FloatArray, th: float, period: float
) -> float:
    t = (th - breaks[0]) % period
    k = int(np.clip(np.searchsorted(breaks - breaks[0], t, side="right") - 1, 0, len(breaks) - 1))
    th = t + float(breaks[0])  # a half turn swaps the contacts: use the piece's own angle
    return float(chords[k, 0] * math.cos(th) - chords[k, 1] * math.sin(th) + offsets[k])


def cancel_shallow(
    ext: list[Extremum],
    depth: float,
    exact: Sequence[Extremum] = (),
    exact_depth: float = 0.0,
) -> list[Extremum]:
    """Cancel adjacent minimum/maximum pairs at most ``depth`` apart, shallowest first.

    A persistence simplification of a cyclic, alternating sequence: what remains are the
    extrema that a perturbation of ``d`` by less than ``depth / 2`` cannot remove. Unlike
    the polygons' barrier, nothing is kept when every pair is shallow (a disc).

    The minima in ``exact`` exist whatever the flattening did (see :func:`_exact_minima`): a
    pair holding one is cancelled only when at most ``exact_depth`` deep (the uncertainty
    that is really there: the shape tolerance and the barrier).
    """
    ext = list(ext)
    sure = {id(e) for e in exact}
    while len(ext) >= 2:
        best, at = math.inf, -1
        for i in range(len(ext)):
            gap = abs(ext[i].value - ext[i - 1].value)
            limit = exact_depth if (id(ext[i]) in sure or id(ext[i - 1]) in sure) else depth
            if gap <= limit and gap < best:
                best, at = gap, i
        if at < 0:
            break
        if len(ext) == 2:
            return []
        j = (at - 1) % len(ext)
        ext = [e for m, e in enumerate(ext) if m not in (at, j)]
    return ext


def _exact_support(hull: CurvedHull, patches: CurvePatches | None) -> Callable[[float], float]:
    """The true support function ``H = max(h_flat, h_patches)`` (the outline is inscribed)."""
    if patches is None or not (len(patches.bezier) or len(patches.ellipses)):
        return lambda phi: float(hull.support(phi))
    return lambda phi: max(float(hull.support(phi)), patches.support(phi))


def _exact_minima(
    hull: CurvedHull, ext: list[Extremum], patches: CurvePatches | None
) -> list[Extremum]:
    """The minima placed exactly: a straight edge of the part flush, and ``d`` falling to it.

    At such a kink the jaw on the edge is exact; the other jaw's contact is on the exact
    curves (``patches``), so the true ``d = H(-theta) + H(pi - theta)`` is known near it. The
    minimum is real when the true one-sided slopes are ``-`` and ``+`` (each beyond the
    rounding of a central difference), however shallow: flattening cannot remove it, only
    the shape tolerance can. Chords of flattened curves are never exact; nor is anything
    when some curve has no exact form (rational splines).
    """
    if hull.chord_edges is None or (patches is not None and not patches.complete):
        return []
    if patches is None and hull.approximate is not None and bool(np.any(hull.approximate)):
        return []
    support = _exact_support(hull, patches)
    tol = hull.tol.angle
    step = 1e-7
    margin = 1e-5 * hull.size  # slopes within this (per radian) count as flat

    def d(th: float) -> float:
        return support(-th) + support(math.pi - th)

    out = []
    for e in ext:
        if e.is_max or not e.kink:
            continue
        real = False
        for phi in (-e.theta, math.pi - e.theta):
            k = int(hull.piece_index(phi + tol))
            if abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol and hull.edges[k]:
                real = real or not bool(hull.chord_edges[k])
        if not real:
            continue
        at = d(e.theta)
        if (at - d(e.theta - step)) / step < -margin and (d(e.theta + step) - at) / step > margin:
            out.append(e)
    return out


def _needs_refining(hull: CurvedHull, e: Extremum, jaws: tuple[float, ...]) -> bool:
    """Whether an extremum lies where the model only approximates a curve."""
    if hull.approximate is None or hull.chord_edges is None:
        return False
    tol = hull.tol.angle
    for phi in (j - e.theta for j in jaws):
        k = int(hull.piece_index(phi + tol))
        at_start = abs(math.remainder(float(hull.starts[k]) - phi, TWO_PI)) <= tol
        if at_start and hull.edges[k] > 0:
            if hull.chord_edges[k]:
                return True
            continue  # a straight edge of the part is flush: exact
        if hull.approximate[int(hull.piece_index(phi))]:
            return True
    return False


def _signed(f: Callable[[float], float], sign: float, t: float) -> float:
    return sign * f(t)


def refined_extrema(
    hull: CurvedHull,
    kept: list[Extremum],
    patches: CurvePatches,
    period: float = math.pi,
    jaws: tuple[float, ...] = _BOTH,
    center: FloatArray | None = None,
    placed: Sequence[Extremum] = (),
) -> list[Extremum]:
    """The extrema that flattened curves carry, placed on the exact curves.

    The minima in ``placed`` (a straight edge flush) stay where they are; only their width
    is read on the exact curves.

    Each such extremum of the flattened model is searched again on the exact diameter
    ``d(theta) = H(-theta) + H(pi - theta)``, ``H = max(h_flat, h_curves)``, between the
    midpoints to its neighbours (bounded Brent): a smooth extremum of the true curve, to
    about 1e-8 rad, instead of a kink of a chord. For the radius function (the pushing jaw
    only, ``center`` the centre of mass): ``r(theta) = H(pi - theta) - center . u``.
    """
    from scipy.optimize import minimize_scalar

    c = np.zeros(2) if center is None else center

    def exact(th: float) -> float:
        total = 0.0
        for phi in (j - th for j in jaws):
            h = max(float(hull.support(phi)), patches.support(phi))
            total += h - (c[0] * math.cos(phi) + c[1] * math.sin(phi) if center is not None else 0)
        return total

    out = list(kept)
    m = len(kept)
    sure = {id(e) for e in placed}
    for i, e in enumerate(kept):
        if not _needs_refining(hull, e, jaws):
            continue
        if id(e) in sure:
            out[i] = Extremum(e.theta, exact(e.theta), False, True)
            continue
        if m > 1:
            before = (e.theta - kept[i - 1].theta) % period or period
            after = (kept[(i + 1) % m].theta - e.theta) % period or period
        else:
            before = after = period
        sign = -1.0 if e.is_max else 1.0
        res = minimize_scalar(
            functools.partial(_signed, exact, sign),
            bounds=(e.theta - 0.5 * before, e.theta + 0.5 * after),
            method="bounded",
            options={"xatol": 1e-12},
        )
        th = float(res.x) % period
        if period - th <= hull.tol.angle:  # the start of the period, not its end
            th = 0.0
        out[i] = Extremum(th, exact(th), e.is_max, False)
    out.sort(key=lambda e: e.theta)  # a refined extremum may have crossed 0
    return out


def curved_diameter(
    hull: CurvedHull,
    error: float = 0.0,
    patches: CurvePatches | None = None,
    shape_tol: float = 0.0,
) -> CurvedDiameter:
    """The diameter function of a curved hull, its extrema and the certain ones.

    Parameters
    ----------
    hull : CurvedHull
    error : float
        How far the outline may be from the true part, in its units: the flattening
        tolerance of non-arc curves plus a shape tolerance. Minimum/maximum pairs shallower
        than ``4 error`` (and than ``tol.barrier`` times the size) are not states.
    patches : CurvePatches, optional
        The flattened curves in exact form: the certain extrema they carry are placed on
        them (see :func:`refined_extrema`).
    shape_tol : float
        The part of ``error`` that is the user's shape tolerance. A minimum where a straight
        edge of the part lies flush is placed exactly and, when the exact curves show the
        true ``d`` falling to it from both sides, it is real however shallow: only pairs
        shallower than ``4 shape_tol`` (and the barrier) remove it (:func:`_exact_minima`).

    Returns
    -------
    CurvedDiameter

    Examples
    --------
    >>> from bayesgrasp.geometry.curved_ring import CurvedRing
    >>> from bayesgrasp.geometry.curved_support import curved_hull
    >>> disc = curved_diameter(curved_hull(CurvedRing([(1, 0), (-1, 0)], [1.0, 1.0])))
    >>> disc.minima.size, float(disc(0.3))
    (0, 2.0)
    """
    atol = hull.tol.angle
    breaks, chords, offsets = _sub_pieces(hull, atol)
    ext = extrema_of_pieces(breaks, chords, offsets, hull, atol)
    barrier = hull.tol.barrier_for(hull.size)
    depth = max(barrier, 4.0 * float(error))
    sure = _exact_minima(hull, ext, patches) if error > shape_tol else []
    kept = cancel_shallow(ext, depth, sure, max(barrier, 4.0 * float(shape_tol)))
    if patches is not None and (len(patches.bezier) or len(patches.ellipses)):
        kept = refined_extrema(hull, kept, patches, placed=sure)
    minima = np.array([e.theta for e in kept if not e.is_max], dtype=np.float64)
    maxima = np.array([e.theta for e in kept if e.is_max], dtype=np.float64)
    for arr in (breaks, chords, offsets, minima, maxima):
        arr.setflags(write=False)
    return CurvedDiameter(
        hull, breaks, chords, offsets, tuple(ext), minima, maxima, float(error), depth, tuple(kept)
    )
