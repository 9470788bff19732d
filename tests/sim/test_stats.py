"""Statistics of simulated trials (bayesgrasp.sim.stats): Wilson interval, goodness of fit."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import SimulationError
from bayesgrasp.sim.stats import goodness_of_fit, wilson_interval


def test_wilson_interval_known_values() -> None:
    lo, hi = wilson_interval(0, 10)
    assert lo == 0.0
    assert_allclose(hi, 0.27753, atol=1e-5)
    # Newcombe (1998), Statistics in Medicine 17, Table I: 81/263 and 15/148
    assert_allclose(wilson_interval(81, 263), (0.2553, 0.3662), atol=1e-4)
    assert_allclose(wilson_interval(15, 148), (0.0624, 0.1605), atol=1e-4)
    assert wilson_interval(0, 0) == (0.0, 1.0)
    with pytest.raises(SimulationError, match=r"`successes` must be in \[0, 3\]; got 4"):
        wilson_interval(4, 3)


def test_wilson_interval_covers_the_truth(rng: np.random.Generator) -> None:
    p, n = 0.3, 200
    hits = sum(
        lo <= p <= hi for lo, hi in (wilson_interval(int(k), n) for k in rng.binomial(n, p, 2000))
    )
    assert 0.93 <= hits / 2000 <= 0.97


def test_goodness_of_fit_cases() -> None:
    assert goodness_of_fit([0, 0], [0.5, 0.5]) == 1.0
    assert goodness_of_fit([10, 1], [1.0, 0.0]) == 0.0  # an impossible outcome happened
    assert goodness_of_fit([100], [1.0]) == 1.0
    assert goodness_of_fit([500, 500], [0.5, 0.5]) == 1.0
    assert goodness_of_fit([700, 300], [0.5, 0.5]) < 1e-12
    # small expected counts are pooled: 3 cells of expectation 1 become one of 3
    assert_allclose(goodness_of_fit([97, 1, 1, 1], [0.97, 0.01, 0.01, 0.01]), 1.0, atol=1e-12)
