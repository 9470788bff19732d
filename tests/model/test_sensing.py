"""The width sensor: parsing, reading bins, likelihoods, Bayes' rule, recognition states."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.stats import norm

from bayesgrasp.errors import BayesGraspError
from bayesgrasp.geometry import Part
from bayesgrasp.model import Problem
from bayesgrasp.model.sensing import (
    EXACT,
    SensorError,
    StateSpace,
    WidthSensor,
    entropy_bits,
    parse_part_prior,
    parse_sensor,
    update_belief,
)

RECT = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]
TRIANGLE = [(0.0, 0.0), (3.0, 0.0), (1.0, 2.0)]


@pytest.mark.parametrize(
    ("spec", "sigma", "res", "kind"),
    [
        ("width", 0.0, 0.0, "exact"),
        (" width ", 0.0, 0.0, "exact"),
        ("width:0,0.5", 0.0, 0.5, "quantised"),
        ("width:0.2,0.05", 0.2, 0.05, "noisy"),
        ("width: 1e-3 , 1e-4", 1e-3, 1e-4, "noisy"),
    ],
)
def test_parse_sensor(spec: str, sigma: float, res: float, kind: str) -> None:
    s = parse_sensor(spec)
    assert (s.sigma, s.resolution, s.kind) == (sigma, res, kind)
    assert parse_sensor(s.spec) == s


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("depth", "must be written `width` or `width:SIGMA,RES`"),
        ("width:", "must be written"),
        ("width:1", "must be written"),
        ("width:1,2,3", "must be written"),
        ("width:a,b", "must be numbers"),
        ("width:-0.1,0.1", "`sigma` must be >= 0"),
        ("width:0.1,-1", "`resolution` must be >= 0"),
        ("width:0.1,0", "needs a resolution RES > 0"),
        ("width:nan,1", "finite"),
        ("width:inf,1", "finite"),
    ],
)
def test_bad_sensor_is_a_clear_error(spec: str, match: str) -> None:
    with pytest.raises(SensorError, match=match) as info:
        parse_sensor(spec)
    assert isinstance(info.value, BayesGraspError) and isinstance(info.value, ValueError)
    assert "\n" not in str(info.value)


def test_exact_bins_split_halfway_and_merge_within_tolerance() -> None:
    b = EXACT.bins(np.array([2.0, 1.0, 2.0 + 1e-12, 3.0]), length_tol=1e-9)
    assert_allclose(b.lo, [-math.inf, 1.5, 2.5], atol=1e-11)
    assert_allclose(b.hi, [1.5, 2.5, math.inf], atol=1e-11)
    assert b.likelihood.argmax(axis=1).tolist() == [1, 0, 1, 2]
    assert b.index([1.0, 1.5, 2.4999, 100.0]).tolist() == [0, 1, 1, 2]


def test_quantised_bins_are_the_encoder_cells() -> None:
    d = np.array([1.24, 1.26, 3.0])
    b = WidthSensor(0.0, 0.5).bins(d)
    assert b.likelihood.argmax(axis=1).tolist() == [0, 1, 2]
    readings = WidthSensor(0.0, 0.5).read(d)
    assert readings.tolist() == [1.0, 1.5, 3.0]
    assert b.index(readings).tolist() == [0, 1, 2]


@settings(max_examples=30)
@given(
    st.lists(st.floats(0.5, 5.0), min_size=1, max_size=6),
    st.floats(0.01, 1.0),
    st.floats(0.01, 1.0),
)
def test_noisy_likelihoods_are_normal_cdf_differences(
    widths: list[float], sigma: float, res: float
) -> None:
    d = np.array(widths)
    b = WidthSensor(sigma, res).bins(d)
    assert_allclose(b.likelihood.sum(axis=1), 1.0, atol=1e-12)
    assert np.all(b.likelihood >= 0)
    assert b.lo[0] == -math.inf and b.hi[-1] == math.inf
    assert np.all(b.hi[:-1] == b.lo[1:])
    # Each bin's likelihood is the normal mass of the readings it holds (interior bins).
    for k in range(1, b.n_bins - 1):
        want = norm.cdf((b.hi[k] - d) / sigma) - norm.cdf((b.lo[k] - d) / sigma)
        assert_allclose(b.likelihood[:, k], want, atol=1e-12)


def test_noisy_bins_hold_the_quantised_readings() -> None:
    s = WidthSensor(0.3, 0.1)
    d = np.array([2.0, 2.5])
    b = s.bins(d)
    rng = np.random.default_rng(3)
    r = s.read(np.repeat(d, 20000), rng)
    assert_allclose(np.round(r / 0.1), r / 0.1, atol=1e-9)  # multiples of RES
    idx = b.index(r).reshape(2, 20000)
    for i in range(2):
        freq = np.bincount(idx[i], minlength=b.n_bins) / 20000
        sd = np.sqrt(b.likelihood[i] * (1 - b.likelihood[i]) / 20000)
        assert np.all(np.abs(freq - b.likelihood[i]) <= 5 * sd + 1e-9)


@pytest.mark.parametrize(
    ("sensor", "match"),
    [
        (WidthSensor(0.0, 1e-15), "reading step RES .* below the length tolerance"),
        (WidthSensor(0.0, 1e-18), "below the length tolerance"),
        (WidthSensor(1e-12, 0.1), "reading error SIGMA .* below the length tolerance"),
        (WidthSensor(1.0, 0.001), "cells within 8 SIGMA .* at least 0.0039"),
        (WidthSensor(100.0, 0.1), "cells"),
        (WidthSensor(1e300, 1.0), "cells"),
    ],
)
def test_readings_finer_than_the_geometry_or_too_many_cells_are_refused(
    sensor: WidthSensor, match: str
) -> None:
    # The house's widths: theta and theta + pi differ by rounding only (about 1e-15).
    d = np.array([40.0, 40.0 + 7e-15, 52.5, 56.0])
    with pytest.raises(SensorError, match=match) as info:
        sensor.bins(d, length_tol=1e-9)
    assert "\n" not in str(info.value)


def test_a_step_at_the_limit_is_taken() -> None:
    b = WidthSensor(1.0, 16.0 / 4095).bins(np.array([40.0, 52.5]), length_tol=1e-9)
    assert_allclose(b.likelihood.sum(axis=1), 1.0, atol=1e-12)


def test_far_cells_are_lumped_with_exact_totals() -> None:
    # Widths far apart: the cells between them are lumped, the likelihoods still sum to one.
    b = WidthSensor(0.01, 0.01).bins(np.array([1.0, 9.0]))
    assert b.n_bins < 50
    assert_allclose(b.likelihood.sum(axis=1), 1.0, atol=1e-14)


def test_update_belief_is_bayes_rule() -> None:
    prior = np.array([0.2, 0.3, 0.5])
    lik = np.array([0.9, 0.1, 0.5])
    post, ev = update_belief(prior, lik)
    assert_allclose(ev, 0.18 + 0.03 + 0.25, atol=1e-15)
    assert_allclose(post, prior * lik / ev, atol=1e-15)
    zero, ev0 = update_belief(prior, np.zeros(3))
    assert ev0 == 0 and not zero.any()


def test_entropy_bits() -> None:
    assert entropy_bits([1.0, 0.0]) == 0.0
    assert_allclose(entropy_bits([0.25] * 4), 2.0, atol=1e-15)
    assert entropy_bits([0.0, 0.0]) == 0.0


@pytest.mark.parametrize(
    ("spec", "n", "match"),
    [
        ("1,2", 3, "one weight per part \\(3\\); got 2"),
        ("1,x", 2, "must be numbers"),
        ("1,-1", 2, ">= 0"),
        ("0,0", 2, "not all zero"),
        ("1", 0, "at least one part"),
    ],
)
def test_bad_part_prior(spec: str, n: int, match: str) -> None:
    with pytest.raises(SensorError, match=match):
        parse_part_prior(spec, n)


def test_state_space_of_several_parts() -> None:
    a = Problem.build(Part.from_points(RECT, name="rect"))
    b = Problem.build(Part.from_points(TRIANGLE, name="tri"))
    sp = StateSpace.build([a, b], [1.0, 3.0])
    assert sp.names == ("rect", "tri")
    assert sp.n_states == a.n_states + b.n_states
    q = sp.initial("squeeze")
    assert_allclose(q[: a.n_states].sum(), 0.25, atol=1e-12)
    assert_allclose(q.sum(), 1.0, atol=1e-12)
    assert_allclose(sp.widths, np.concatenate([a.widths, b.widths]))
    g = sp.success_matrix()
    assert not g[: a.n_states, a.n_states :].any()  # a declaration names one part
    assert sp.stable(a.n_states) == (1, float(b.states.stable[0]))
    with pytest.raises(SensorError, match="one weight per part"):
        StateSpace.build([a, b], "1,2,3")


def test_state_space_needs_the_same_actions() -> None:
    a = Problem.build(Part.from_points(RECT))
    b = Problem.build(Part.from_points(TRIANGLE), actions=("push-grasp",))
    with pytest.raises(BayesGraspError, match="same actions"):
        StateSpace.build([a, b])
