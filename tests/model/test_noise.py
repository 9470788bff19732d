"""Noise models (model/noise.py): exact transition matrices, against independent references.

- Every matrix is row-stochastic (hypothesis over parts, turns, error kinds and sizes,
  contact probabilities).
- No error: the matrices are today's one-hot class matrices; a vanishing error gives them too.
- Each entry against a Monte Carlo written here from the transfer functions (draw the error
  and the contact event, apply the squeeze or the push-grasp from either side): binomial
  bounds.
- The wrapped interval probability against a direct sum of the normal CDF (``math.erf``) over
  many turns of the circle, and against the uniform's interval overlap.
- The first action under a non-uniform prior against a fine trapezoid average over the error.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from bayesgrasp import shapes
from bayesgrasp.errors import PlanningError
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.model.noise import NoiseModel, NoisyTransitions, TurnNoise, parse_turn_noise
from bayesgrasp.model.prior import von_mises
from bayesgrasp.model.problem import Problem
from bayesgrasp.model.states import nearest_state
from bayesgrasp.paper.study import random_polygon

DEG = math.pi / 180


@given(
    seed=st.integers(0, 10_000),
    kind=st.sampled_from(["normal", "uniform"]),
    scale=st.sampled_from([0.0]) | st.floats(1e-12, 0.5),
    q=st.floats(0.0, 1.0),
    alphas=st.lists(st.floats(-10.0, 10.0), min_size=1, max_size=5),
)
def test_matrices_are_row_stochastic(
    seed: int, kind: str, scale: float, q: float, alphas: list[float]
) -> None:
    pb = Problem.build(random_polygon(seed), actions="squeeze,push-grasp")
    nt = NoisyTransitions(pb, NoiseModel(TurnNoise(kind, scale), q))  # type: ignore[arg-type]
    for action in pb.action_kinds:
        m = nt.matrices(action, alphas)
        assert m.shape == (len(alphas), pb.n_states, pb.n_states)
        assert np.all(m >= -1e-15)
        np.testing.assert_allclose(m.sum(axis=-1), 1.0, atol=1e-12)
    np.testing.assert_allclose(nt.initial("squeeze", alphas[0]).sum(), 1.0, atol=1e-12)


@pytest.mark.parametrize("name", shapes.names())
@pytest.mark.parametrize("scale", [0.0, 1e-9])
def test_no_error_gives_the_class_matrices(name: str, scale: float) -> None:
    pb = Problem.build(shapes.load(name), actions="squeeze,push-grasp")
    nt = NoisyTransitions(pb, NoiseModel(TurnNoise("normal", scale)))
    for action in pb.action_kinds:
        cl = pb.classes(action)
        wide = (cl.hi - cl.lo) > 1e-6  # a vanishing error still blurs a class narrower than it
        got = nt.matrices(action, cl.mid[wide])
        want = np.array([cl.matrix(a) for a in np.flatnonzero(wide)])
        np.testing.assert_allclose(got, want, atol=1e-12)
    np.testing.assert_allclose(nt.initial("squeeze", 0.3), pb.state_distribution(0.3), atol=1e-15)


def _monte_carlo(pb: Problem, noise: NoiseModel, alpha: float, n: int, seed: int) -> np.ndarray:
    """Frequencies of each state's end state, drawing error and contact event per trial."""
    gen = np.random.default_rng(seed)
    s = pb.states
    g = push_grasp_function(pb.part, s)
    k = pb.n_states
    out = np.zeros((k, k))
    for i, start in enumerate(s.stable):
        if noise.turn.kind == "normal":
            e = gen.normal(0.0, noise.turn.scale, n)
        else:
            e = gen.uniform(-noise.turn.scale, noise.turn.scale, n)
        x = start - alpha - e
        u = gen.random(n)
        q = noise.contact
        end = np.where(u < q / 2, g(x), np.where(u < q, g(x - math.pi) + math.pi, s(x)))
        out[i] = np.bincount(nearest_state(s, np.mod(end, 2 * math.pi)), minlength=k) / n
    return out


@pytest.mark.parametrize(
    "noise",
    [
        NoiseModel(TurnNoise("normal", 8 * DEG)),
        NoiseModel(TurnNoise("uniform", 15 * DEG)),
        NoiseModel(TurnNoise("normal", 5 * DEG), 0.4),
    ],
    ids=lambda n: n.describe(),
)
@pytest.mark.parametrize("name", ["key", "house", "triangle"])
def test_entries_agree_with_a_monte_carlo(name: str, noise: NoiseModel) -> None:
    pb = Problem.build(shapes.load(name))
    nt = NoisyTransitions(pb, noise)
    n = 40_000
    for j, alpha in enumerate([0.0, 0.7, -1.2]):
        exact = nt.matrix("squeeze", alpha)
        freq = _monte_carlo(pb, noise, alpha, n, seed=j)
        # Five standard deviations, and three trials for the rare entries (Poisson counts).
        sd = np.sqrt(np.clip(exact * (1 - exact), 0.0, None) / n)
        assert np.all(np.abs(freq - exact) < 5 * sd + 3 / n)


@given(
    a=st.floats(-20.0, 20.0),
    width=st.floats(0.0, 2 * math.pi),
    sigma=st.floats(1e-3, 30 * DEG),
)
def test_wrapped_normal_interval_against_erf(a: float, width: float, sigma: float) -> None:
    b = a + width
    ref = 0.0
    for m in range(-8, 9):  # e + 2 pi m in (a, b] for some m
        lo, hi = a + 2 * math.pi * m, b + 2 * math.pi * m
        ref += 0.5 * (math.erf(hi / (sigma * math.sqrt(2))) - math.erf(lo / (sigma * math.sqrt(2))))
    got = float(TurnNoise("normal", sigma).interval_prob(a, b))
    assert got == pytest.approx(ref, abs=1e-12)


@given(a=st.floats(-20.0, 20.0), width=st.floats(0.0, 2 * math.pi), half=st.floats(1e-3, math.pi))
def test_wrapped_uniform_interval_is_the_overlap(a: float, width: float, half: float) -> None:
    b = a + width
    overlap = 0.0
    for m in range(-8, 9):
        lo, hi = a + 2 * math.pi * m, b + 2 * math.pi * m
        overlap += max(0.0, min(hi, half) - max(lo, -half))
    got = float(TurnNoise("uniform", half).interval_prob(a, b))
    assert got == pytest.approx(overlap / (2 * half), abs=1e-12)


@pytest.mark.parametrize("noise", [TurnNoise("normal", 6 * DEG), TurnNoise("uniform", 10 * DEG)])
def test_first_action_under_a_peaked_prior(noise: TurnNoise) -> None:
    pb = Problem.build(shapes.load("key"), prior=von_mises(0.6, 5.0))
    nt = NoisyTransitions(pb, NoiseModel(noise))
    got = nt.initial("squeeze", 0.4)
    # Reference: a fine trapezoid average of the noise-free distribution over the error.
    e = np.linspace(-noise.support, noise.support, 1001)
    dens = np.exp(-0.5 * (e / noise.scale) ** 2) if noise.kind == "normal" else np.ones_like(e)
    dists = np.array([pb.state_distribution(0.4 + x) for x in e])
    ref = np.trapezoid(dists * dens[:, None], e, axis=0) / np.trapezoid(dens, e)
    np.testing.assert_allclose(got, ref, atol=2e-6)
    assert not np.allclose(got, pb.state_distribution(0.4), atol=1e-4)


def test_parse_and_validate() -> None:
    n = parse_turn_noise("uniform:1.5")
    assert n.kind == "uniform" and n.scale == pytest.approx(1.5 * DEG)
    assert n.spec() == "uniform:1.5"
    for bad in ["normal", "gauss:2", "normal:x", "normal:-1", "normal:nan"]:
        with pytest.raises(PlanningError, match="turn-noise"):
            parse_turn_noise(bad)
    with pytest.raises(PlanningError, match="scale"):
        parse_turn_noise("normal:45")
    with pytest.raises(PlanningError, match="kind"):
        TurnNoise("cauchy", 0.1)  # type: ignore[arg-type]
    with pytest.raises(PlanningError, match="contact"):
        NoiseModel(contact=1.5)
    with pytest.raises(PlanningError, match="TurnNoise"):
        NoiseModel(turn=0.1)  # type: ignore[arg-type]
    assert NoiseModel().exact and NoiseModel().describe() == "no noise"
    assert TurnNoise("uniform", 0.1).peak_density == pytest.approx(5.0)
    assert TurnNoise("normal", 0.1).curvature_bound == pytest.approx(
        2 * math.exp(-0.5) / math.sqrt(2 * math.pi) / 0.01
    )


@pytest.mark.parametrize("spec", ["normal:1e-300", "normal:1e-310", "uniform:1e-12"])
def test_a_vanishing_turn_error_is_refused(spec: str) -> None:
    with pytest.raises(PlanningError, match="exact to rounding: give 0 for exact turns"):
        parse_turn_noise(spec)
