"""Statistics of simulated trials: how well observed outcomes agree with the prediction.

A simulation's success count is binomial: :func:`wilson_interval` gives its confidence
interval. Its final states are multinomial: :func:`goodness_of_fit` tests them against the
predicted probabilities. SciPy is imported on use.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..errors import SimulationError

__all__ = ["goodness_of_fit", "wilson_interval"]


def wilson_interval(successes: float, trials: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion.

    Better than the normal approximation near 0 and 1 and for small samples (Wilson 1927;
    Brown, Cai and DasGupta 2001).

    Parameters
    ----------
    successes : int or float
        In ``[0, trials]``: a count, or ``trials`` times the mean of a value in [0, 1].
    trials : int
        ``0`` or fewer gives the uninformative interval ``(0, 1)``.
    confidence : float
        Coverage of the interval, in ``(0, 1)``.

    Returns
    -------
    tuple of float
        ``(low, high)`` within ``[0, 1]``.

    Raises
    ------
    SimulationError
        ``successes`` outside ``[0, trials]``.

    Examples
    --------
    >>> lo, hi = wilson_interval(50, 100)
    >>> round(lo, 4), round(hi, 4)
    (0.4038, 0.5962)
    """
    if trials <= 0:
        return (0.0, 1.0)
    if not 0 <= successes <= trials:
        raise SimulationError(f"`successes` must be in [0, {trials}]; got {successes}")
    from scipy.stats import norm

    z = float(norm.ppf(0.5 + confidence / 2.0))
    p = successes / trials
    denom = 1.0 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denom
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def goodness_of_fit(observed: ArrayLike, predicted: ArrayLike, min_expected: float = 5.0) -> float:
    """Chi-square goodness-of-fit p-value of observed counts against predicted probabilities.

    Categories whose expected count is below ``min_expected`` are pooled into one (the
    chi-square approximation needs about five per cell). An observation in a category the
    prediction calls impossible gives ``0.0``; a single category gives ``1.0``.

    Parameters
    ----------
    observed : array_like of shape (K,)
        Counts.
    predicted : array_like of shape (K,)
        Probabilities (normalised here).
    min_expected : float
        Smallest expected count of a category that is not pooled.

    Returns
    -------
    float
        The p-value, in ``[0, 1]``.

    Examples
    --------
    >>> round(goodness_of_fit([48, 52], [0.5, 0.5]), 4)
    0.6892
    """
    obs = np.asarray(observed, dtype=np.float64)
    prob = np.asarray(predicted, dtype=np.float64)
    n = obs.sum()
    if n == 0 or prob.sum() <= 0:
        return 1.0
    exp = prob / prob.sum() * n
    if np.any((exp <= 0) & (obs > 0)):
        return 0.0
    big = exp >= min_expected
    o = np.append(obs[big], obs[~big].sum())
    e = np.append(exp[big], exp[~big].sum())
    keep = e > 0
    o, e = o[keep], e[keep]
    if len(o) < 2:
        return 1.0
    from scipy.stats import chisquare

    e = e * (o.sum() / e.sum())  # chisquare checks the sums agree to 1e-8 relative
    return float(chisquare(o, e).pvalue)
