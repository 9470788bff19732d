"""Priors on the part's initial orientation (the seed, sections 3 and 4.3).

A prior is a probability distribution on the circle ``[0, 2 pi)`` of initial orientations of
the part in the world frame. Planning needs two things from it: the mass of an arc (the
probability of a stable orientation is the prior mass of its basin) and the arc of a given
length that holds the most mass, for a goal counted once or up to the part's symmetry (the
first squeeze's gripper angle places the plan's arc there).

Every prior exposes a cumulative function extended periodically,
``C(theta + 2 pi) = C(theta) + 1``, so ``mass(lo, hi) = C(hi) - C(lo)`` for any ``lo <= hi``.
The uniform and histogram priors have piecewise-linear ``C``; a density is tabulated into a
fine histogram (Simpson's rule on each bin); a sample of observed orientations is an
empirical distribution of atoms.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import PriorError

__all__ = [
    "DensityPrior",
    "HistogramPrior",
    "Prior",
    "SamplePrior",
    "UniformPrior",
    "parse_prior",
    "von_mises",
]

FloatArray = NDArray[np.float64]


class Prior(ABC):
    """A probability distribution of the initial orientation on ``[0, 2 pi)``."""

    name: str = "prior"

    @abstractmethod
    def cdf(self, theta: ArrayLike) -> FloatArray:
        """Cumulative mass, extended so that ``C(theta + 2 pi) = C(theta) + 1``."""

    @property
    @abstractmethod
    def breakpoints(self) -> FloatArray:
        """Angles in ``[0, 2 pi)`` where the cumulative function changes its form."""

    def mass(self, lo: ArrayLike, hi: ArrayLike) -> FloatArray:
        """Prior mass of the arcs from ``lo`` to ``hi`` (``hi >= lo``), vectorised.

        Examples
        --------
        >>> float(UniformPrior().mass(0.0, np.pi / 2))
        0.25
        """
        return self.cdf(hi) - self.cdf(lo)

    def arc_mass(self, start: ArrayLike, length: float, group: int = 1) -> FloatArray:
        """Mass of ``[start, start + length)`` plus its rotations by multiples of 2 pi / group."""
        s = np.asarray(start, dtype=np.float64)[..., None] + TWO_PI * np.arange(group) / group
        return np.asarray(np.sum(self.mass(s, s + length), axis=-1), dtype=np.float64)

    def max_arc_mass(
        self, length: float, group: int = 1, prefer: float = 0.0, tol: float = 1e-12
    ) -> tuple[float, float]:
        """Largest mass of an open arc of the given length (and its symmetric copies).

        Parameters
        ----------
        length : float
            Arc length (radians), at most ``2 pi / group``.
        group : int
            The goal counts ``group`` orientations ``2 pi / group`` apart as one.
        prefer : float
            Start returned when it is as good as the best (within ``tol``).
        tol : float
            Probability tolerance of that comparison.

        Returns
        -------
        mass : float
        start : float
            Start of an arc that holds that mass.

        Examples
        --------
        >>> UniformPrior().max_arc_mass(np.pi / 2)
        (0.25, 0.0)
        """
        best = float(self.arc_mass(prefer, length, group))
        shifts = TWO_PI * np.arange(group) / group
        b = self.breakpoints[:, None] - shifts  # (B, g)
        # The mass is piecewise linear in the start: the best start puts an end of the arc
        # (or of one of its copies) on a breakpoint.
        cand = np.mod(np.concatenate([b.ravel(), (b - length).ravel()]), TWO_PI)
        masses = self.arc_mass(cand, length, group)
        k = int(np.argmax(masses))
        if masses[k] > best + tol:
            return float(masses[k]), float(cand[k])
        return best, float(prefer)


@dataclass(frozen=True)
class UniformPrior(Prior):
    """The uniform prior ``f(theta) = 1 / (2 pi)`` (the seed's default, section 4.3)."""

    name: str = "uniform"

    def cdf(self, theta: ArrayLike) -> FloatArray:
        """Cumulative mass ``theta / (2 pi)``."""
        return np.asarray(theta, dtype=np.float64) / TWO_PI

    @property
    def breakpoints(self) -> FloatArray:
        """No breakpoints: every arc start is as good."""
        return np.zeros(0)

    def max_arc_mass(
        self, length: float, group: int = 1, prefer: float = 0.0, tol: float = 1e-12
    ) -> tuple[float, float]:
        """Every start is as good: ``group * length / (2 pi)`` at ``prefer``."""
        return float(group * length / TWO_PI), float(prefer)


@dataclass(frozen=True, eq=False)
class HistogramPrior(Prior):
    """A piecewise-constant density: ``weights[k]`` on the k-th of equal bins of ``[0, 2 pi)``.

    Parameters
    ----------
    weights : array_like of shape (B,)
        Non-negative bin weights (counts or masses), normalised to sum to one.

    Examples
    --------
    >>> p = HistogramPrior([3, 1])
    >>> float(p.mass(0.0, np.pi)), float(p.mass(np.pi / 2, 3 * np.pi / 2))
    (0.75, 0.5)
    """

    weights: FloatArray
    name: str = "histogram"
    recipe: tuple[tuple[str, object], ...] = field(default=(), repr=False)
    """How the histogram was made, when it is a tabulated formula (:func:`von_mises`): its
    parameters, so a document can name them instead of listing every bin."""
    _cum: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        try:
            w = np.array(self.weights, dtype=np.float64).ravel()
        except (TypeError, ValueError) as exc:
            raise PriorError(f"histogram `weights` must be numbers; {exc}") from None
        if len(w) == 0 or not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
            raise PriorError(
                "histogram `weights` must be finite, non-negative and not all zero; "
                f"got {len(w)} weight(s)"
            )
        w = w / w.sum()
        w.setflags(write=False)
        cum = np.concatenate([[0.0], np.cumsum(w)])
        cum[-1] = 1.0
        object.__setattr__(self, "weights", w)
        object.__setattr__(self, "_cum", cum)

    def cdf(self, theta: ArrayLike) -> FloatArray:
        """Piecewise-linear cumulative mass, extended periodically."""
        th = np.asarray(theta, dtype=np.float64)
        turns = np.floor(th / TWO_PI)
        x = (th - turns * TWO_PI) / TWO_PI * len(self.weights)  # bin coordinate in [0, B]
        k = np.clip(np.floor(x).astype(np.intp), 0, len(self.weights) - 1)
        return turns + self._cum[k] + self.weights[k] * (x - k)

    @property
    def breakpoints(self) -> FloatArray:
        """The bin edges."""
        return TWO_PI * np.arange(len(self.weights)) / len(self.weights)

    def density(self, theta: ArrayLike) -> FloatArray:
        """Density at the given angles."""
        th = np.mod(np.asarray(theta, dtype=np.float64), TWO_PI)
        b = len(self.weights)
        k = np.clip((th / TWO_PI * b).astype(np.intp), 0, b - 1)
        return self.weights[k] * b / TWO_PI


def DensityPrior(
    density: Callable[[FloatArray], ArrayLike], bins: int = 3600, name: str = "density"
) -> HistogramPrior:
    """A prior from a density function on ``[0, 2 pi)``, tabulated into a fine histogram.

    Each bin's mass is Simpson's rule on the bin; the density need not be normalised.

    Parameters
    ----------
    density : callable
        Takes an array of angles (radians), returns non-negative values of the same shape.
    bins : int
        Number of bins (3600: a tenth of a degree).

    Raises
    ------
    PriorError
        If the density is negative, not finite, zero everywhere or cannot be evaluated.

    Examples
    --------
    >>> p = DensityPrior(lambda t: 1.0 + np.cos(t))
    >>> round(float(p.mass(-np.pi / 2, np.pi / 2)), 6)
    0.81831
    """
    if isinstance(bins, bool) or not isinstance(bins, int | np.integer) or bins < 1:
        raise PriorError(f"`bins` must be an integer >= 1; got {bins!r}")
    edges = np.linspace(0.0, TWO_PI, bins + 1)
    mids = 0.5 * (edges[:-1] + edges[1:])
    try:
        fe = np.broadcast_to(np.asarray(density(edges), dtype=np.float64), edges.shape)
        fm = np.broadcast_to(np.asarray(density(mids), dtype=np.float64), mids.shape)
    except Exception as exc:
        raise PriorError(f"the prior density could not be evaluated: {exc}") from exc
    if not (np.all(np.isfinite(fe)) and np.all(np.isfinite(fm))):
        raise PriorError("the prior density must be finite on [0, 2 pi)")
    if np.any(fe < 0) or np.any(fm < 0):
        raise PriorError("the prior density must be non-negative")
    masses = (fe[:-1] + 4.0 * fm + fe[1:]) / 6.0
    return HistogramPrior(masses, name=name)


def von_mises(mean: float, kappa: float, bins: int = 3600) -> HistogramPrior:
    """A von Mises prior (the circular normal) with the given mean (radians) and concentration.

    Examples
    --------
    >>> p = von_mises(0.0, 4.0)
    >>> float(p.mass(-0.5, 0.5)) > 0.6
    True
    """
    for name, v in (("mean", mean), ("kappa", kappa)):
        if isinstance(v, bool) or not isinstance(v, int | float | np.floating | np.integer):
            raise PriorError(f"von Mises `{name}` must be a number; got {v!r}")
    if not (math.isfinite(mean) and math.isfinite(kappa)) or kappa < 0:
        shown = f"{math.degrees(mean):g} deg" if math.isfinite(mean) else f"{mean}"
        raise PriorError(
            f"von Mises needs a finite mean and kappa >= 0; got mean {shown}, kappa {kappa:g}"
        )
    name = f"von-mises({math.degrees(mean):g}deg,{kappa:g})"  # people read degrees
    hist = DensityPrior(lambda t: np.exp(kappa * (np.cos(t - mean) - 1.0)), bins, name)
    recipe = (("kind", "von-mises"), ("mean_rad", float(mean)), ("kappa", float(kappa)))
    object.__setattr__(hist, "recipe", (*recipe, ("bins", int(bins))))
    return hist


@dataclass(frozen=True, eq=False)
class SamplePrior(Prior):
    """The empirical distribution of a sample of observed orientations (radians).

    Each observation is an atom of mass ``1 / N``. ``C(theta)`` counts the atoms strictly
    below ``theta``, so ``mass(lo, hi)`` is the mass of ``[lo, hi)``.

    Examples
    --------
    >>> p = SamplePrior([0.1, 0.2, 3.0, 6.2])
    >>> float(p.mass(0.0, 1.0))
    0.5
    """

    angles: FloatArray
    name: str = "sample"

    def __post_init__(self) -> None:
        try:
            a = np.array(self.angles, dtype=np.float64).ravel()
        except (TypeError, ValueError) as exc:
            raise PriorError(f"sample `angles` must be numbers; {exc}") from None
        if len(a) == 0 or not np.all(np.isfinite(a)):
            raise PriorError(f"a sample prior needs at least one finite angle; got {len(a)}")
        a = np.mod(a, TWO_PI)
        a[a >= TWO_PI] = 0.0  # np.mod(-1e-20, 2 pi) rounds to 2 pi, the same angle as 0
        a = np.sort(a)
        a.setflags(write=False)
        object.__setattr__(self, "angles", a)

    def cdf(self, theta: ArrayLike) -> FloatArray:
        """Fraction of atoms strictly below ``theta``, extended periodically."""
        th = np.asarray(theta, dtype=np.float64)
        turns = np.floor(th / TWO_PI)
        frac = np.searchsorted(self.angles, th - turns * TWO_PI, side="left") / len(self.angles)
        return turns + frac

    @property
    def breakpoints(self) -> FloatArray:
        """The atoms."""
        return self.angles

    def max_arc_mass(
        self, length: float, group: int = 1, prefer: float = 0.0, tol: float = 1e-12
    ) -> tuple[float, float]:
        """Best open arc, placed so its atoms sit in its middle (away from its ends)."""
        period = TWO_PI / group
        folded = np.sort(np.mod(self.angles, period))  # (N,) atoms of the folded circle
        n = len(folded)
        ext = np.concatenate([folded, folded + period])
        if length >= period:
            gaps = np.diff(np.append(folded, folded[0] + period))
            k = int(np.argmax(gaps))
            return 1.0, float(folded[k] + gaps[k] / 2)
        # Atoms in [a_i, a_i + length): an open arc slightly wider holds them all.
        last = np.searchsorted(ext, folded + length, side="left") - 1  # (N,)
        counts = last - np.arange(n) + 1
        i = int(np.argmax(counts))
        slack = length - (ext[last[i]] - folded[i])
        start = float(folded[i] - slack / 2)
        # The open arc at ``prefer`` leaves out the atoms exactly at its start (copies too).
        starts = np.mod(prefer + period * np.arange(group), TWO_PI)
        starts[starts >= TWO_PI] = 0.0
        at_start = np.searchsorted(self.angles, starts, side="right") - np.searchsorted(
            self.angles, starts, side="left"
        )
        pref_mass = float(self.arc_mass(prefer, length, group)) - float(at_start.sum()) / n
        if pref_mass >= counts[i] / n - tol:
            return pref_mass, float(prefer)
        return float(counts[i] / n), start


def parse_prior(spec: str) -> Prior:
    """A prior from a short text, as given on the command line.

    ``uniform``; ``vonmises:MEAN_DEG,KAPPA``; ``histogram:FILE`` (bin weights over equal bins
    of ``[0, 360)`` degrees, numbers separated by commas, spaces or newlines);
    ``sample:FILE`` (observed orientations in degrees, same layout).

    Examples
    --------
    >>> parse_prior("vonmises:30,4").name
    'von-mises(30deg,4)'
    """
    if not isinstance(spec, str):
        raise PriorError(f"a prior is written as text (uniform, vonmises:...); got {spec!r}")
    if not spec.strip():
        raise PriorError(
            "the prior is empty; expected uniform, vonmises:MEAN_DEG,KAPPA, histogram:FILE or "
            "sample:FILE"
        )
    kind, _, arg = spec.partition(":")
    kind = kind.strip().lower()
    if kind == "uniform" and not arg:
        return UniformPrior()
    if kind in ("vonmises", "von-mises"):
        try:
            mean_deg, kappa = (float(x) for x in arg.split(","))
        except ValueError:
            raise PriorError(
                f"`--prior vonmises:MEAN_DEG,KAPPA` needs two numbers; got {arg!r}"
            ) from None
        return von_mises(math.radians(mean_deg), kappa)
    if kind in ("histogram", "sample"):
        from pathlib import Path

        from ..files import decode_text, read_bytes

        path = Path(arg)
        text = decode_text(path, read_bytes(path, PriorError, "prior file"), PriorError)
        try:
            values = [float(x) for x in text.replace(",", " ").split()]
        except ValueError:
            raise PriorError(f"prior file {arg!r} must hold numbers only") from None
        if kind == "histogram":
            return HistogramPrior(np.array(values), name=f"histogram({path.name})")
        return SamplePrior(np.radians(values), name=f"sample({path.name})")
    raise PriorError(
        f"unknown prior {spec!r}; expected uniform, vonmises:MEAN_DEG,KAPPA, "
        "histogram:FILE or sample:FILE"
    )
