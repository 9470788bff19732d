"""Shared fixtures and hypothesis settings of the test suite.

Hypothesis profiles (choose one with ``HYPOTHESIS_PROFILE=<name>``):

``default``
    100 examples a property, no deadline (the machine is shared; timing is not a test).
``ci``
    The same, derandomised: every run checks the same examples.
``thorough``
    1000 examples a property, for a long local run after touching the geometry.

Strategies for random parts live in ``tests/strategies.py``; brute-force references that the
exact code must agree with live in ``tests/reference.py``.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "default",
    max_examples=100,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "ci",
    max_examples=100,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "thorough",
    max_examples=1000,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded random generator: each test gets the same stream on every run."""
    return np.random.default_rng(20240601)
