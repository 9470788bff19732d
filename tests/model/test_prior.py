"""Tests of bayesgrasp.model.prior: priors on the initial orientation and their best arcs."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.errors import BayesGraspError, PriorError
from bayesgrasp.model.prior import (
    DensityPrior,
    HistogramPrior,
    Prior,
    SamplePrior,
    UniformPrior,
    parse_prior,
    von_mises,
)
from reference import TWO_PI

DENSITIES = {
    "cosine": lambda t: 1.0 + np.cos(t),
    "bimodal": lambda t: np.exp(3 * np.cos(t - 1.0)) + 0.5 * np.exp(8 * np.cos(t - 4.0)),
    "step": lambda t: np.where(np.mod(t, TWO_PI) < 1.0, 3.0, 0.5),
    "triangle": lambda t: np.abs(np.mod(t, TWO_PI) - math.pi),
}


def integrate(f: object, lo: float, hi: float) -> float:
    """Numerical integral of f over [lo, hi] (scipy's adaptive quadrature)."""
    integrate_mod = pytest.importorskip("scipy.integrate")
    value, _ = integrate_mod.quad(
        lambda x: float(f(np.array(x))),  # type: ignore[operator]
        lo,
        hi,
        limit=400,
        points=[p for p in np.arange(-4, 5) * math.pi if lo < p < hi] or None,
    )
    return float(value)


def open_arc_mass(atoms: np.ndarray, start: object, length: float, group: int) -> np.ndarray:
    """Fraction of atoms strictly inside the open arcs (one per start) and their copies."""
    st = np.asarray(start, dtype=np.float64)[..., None]  # (..., 1)
    total = np.zeros(st.shape[:-1])
    for j in range(group):
        rel = np.mod(atoms - st - TWO_PI * j / group, TWO_PI)  # (..., N)
        total += np.count_nonzero((rel > 0) & (rel < length), axis=-1)
    return total / len(atoms)


def grid_best(prior: Prior, length: float, group: int, m: int = 20000) -> float:
    """Brute force: the largest arc mass over a grid of starts."""
    starts = np.arange(m) * (TWO_PI / m)
    return float(prior.arc_mass(starts, length, group).max())


# --------------------------------------------------------------------------- uniform


def test_uniform() -> None:
    p = UniformPrior()
    assert_allclose(p.mass(0.0, math.pi), 0.5)
    assert_allclose(p.mass(-1.0, 1.0), 1.0 / math.pi)
    assert_allclose(p.cdf(TWO_PI + 1.0) - p.cdf(1.0), 1.0)
    assert p.breakpoints.shape == (0,)
    assert p.max_arc_mass(1.0) == (1.0 / TWO_PI, 0.0)
    assert_allclose(p.max_arc_mass(0.5, group=3, prefer=2.0), (1.5 / TWO_PI, 2.0))
    assert_allclose(p.arc_mass(1.0, 0.5, group=3), 1.5 / TWO_PI)
    assert p.name == "uniform"


# --------------------------------------------------------------------------- histogram


def test_histogram_masses() -> None:
    p = HistogramPrior([3, 1])
    assert_allclose(p.weights, [0.75, 0.25])
    assert_allclose(p.mass(0.0, math.pi), 0.75)
    assert_allclose(p.mass(math.pi / 2, 3 * math.pi / 2), 0.5)
    assert_allclose(p.mass(-math.pi, 0.0), 0.25)  # wraps to the second bin
    assert_allclose(p.mass(0.0, 3 * TWO_PI), 3.0)  # whole turns
    assert_allclose(p.density([0.1, 4.0]), [0.75 / math.pi, 0.25 / math.pi])
    assert_allclose(p.breakpoints, [0.0, math.pi])
    assert not p.weights.flags.writeable


@given(
    weights=st.lists(st.floats(0, 100), min_size=1, max_size=40).filter(lambda w: sum(w) > 0),
    a=st.floats(-20, 20),
    b=st.floats(-20, 20),
)
def test_histogram_cdf_matches_integral_of_its_density(
    weights: list[float], a: float, b: float
) -> None:
    p = HistogramPrior(weights)
    lo, hi = min(a, b), max(a, b)
    # The density is piecewise constant: integrate it exactly on a fine partition.
    grid = np.arange(-4, 5)[:, None] * TWO_PI + p.breakpoints[None, :]  # (9, B) bin edges
    edges = np.unique(np.concatenate([[lo, hi], grid.ravel()]))
    edges = edges[(edges >= lo) & (edges <= hi)]
    mids = 0.5 * (edges[:-1] + edges[1:])
    exact = float(np.sum(p.density(mids) * np.diff(edges)))
    assert_allclose(p.mass(lo, hi), exact, atol=1e-12)
    assert_allclose(p.cdf(a + TWO_PI) - p.cdf(a), 1.0, atol=1e-12)
    assert p.mass(lo, hi) >= -1e-15


@pytest.mark.parametrize(
    ("weights", "match"),
    [
        ([], "got 0 weight"),
        ([0, 0, 0], "not all zero"),
        ([1, -1, 2], "non-negative"),
        ([1, math.nan], "finite"),
        ([1, math.inf], "finite"),
        (["a", "b"], "must be numbers"),
    ],
)
def test_histogram_rejects_bad_weights(weights: list[object], match: str) -> None:
    with pytest.raises(PriorError, match=match):
        HistogramPrior(weights)  # type: ignore[arg-type]


def test_prior_error_is_a_value_error() -> None:
    with pytest.raises(ValueError, match="not all zero"):
        HistogramPrior([0.0])
    with pytest.raises(BayesGraspError, match="not all zero"):
        HistogramPrior([0.0])


# --------------------------------------------------------------------------- density


@pytest.mark.parametrize("name", sorted(DENSITIES))
def test_density_prior_matches_numerical_integration(name: str) -> None:
    f = DENSITIES[name]
    prior = DensityPrior(f)
    total = integrate(f, 0.0, TWO_PI)
    # The histogram interpolates linearly inside a bin; where the density jumps inside a bin
    # (the step, at theta = 1) Simpson's rule errs by up to that bin's mass.
    atol = 2e-5 if name != "step" else 3.0 * (TWO_PI / 3600) / total
    for lo, hi in [(0.0, 1.0), (0.5, 3.0), (-1.0, 1.0), (2.0, 6.0), (5.0, 8.0), (-7.0, -2.5)]:
        expected = integrate(f, lo, hi) / total
        assert_allclose(prior.mass(lo, hi), expected, atol=atol)
    edges = np.linspace(0.0, TWO_PI, 3601)
    assert_allclose(
        prior.cdf(edges[::90]),
        [integrate(f, 0.0, e) / total for e in edges[::90]],
        atol=1e-7 if name != "step" else atol,
    )


def test_density_prior_accepts_unnormalised_and_scalar_densities() -> None:
    assert_allclose(DensityPrior(lambda t: 7.0).mass(0.0, math.pi), 0.5)
    assert_allclose(
        DensityPrior(lambda t: 1 + np.cos(t)).mass(-math.pi / 2, math.pi / 2),
        (math.pi + 2) / TWO_PI,
        atol=1e-9,
    )
    assert DensityPrior(lambda t: 1.0 + 0 * t, bins=4).weights.shape == (4,)


@pytest.mark.parametrize(
    ("density", "bins", "match"),
    [
        (lambda t: np.cos(t), 360, "non-negative"),
        (lambda t: np.full_like(t, np.nan), 360, "finite"),
        (lambda t: 1.0 / np.sin(t / 2) ** 0 * np.inf, 360, "finite"),
        (lambda t: np.zeros_like(t), 360, "not all zero"),
        (lambda t: np.ones(3), 360, "could not be evaluated"),
        (lambda t: 1 / 0, 360, "could not be evaluated: division by zero"),
        (lambda t: 1.0, 0, "`bins` must be an integer >= 1; got 0"),
    ],
)
def test_density_prior_rejects_bad_densities(density: object, bins: int, match: str) -> None:
    with pytest.raises(PriorError, match=match):
        DensityPrior(density, bins=bins)  # type: ignore[arg-type]


# --------------------------------------------------------------------------- von Mises


@pytest.mark.parametrize(("mean", "kappa"), [(0.0, 0.5), (1.0, 4.0), (5.5, 20.0), (-2.0, 1.0)])
def test_von_mises_matches_scipy(mean: float, kappa: float) -> None:
    stats = pytest.importorskip("scipy.stats")
    prior = von_mises(mean, kappa)
    for lo, hi in [(mean - 0.3, mean + 0.3), (mean, mean + 2.0), (mean + 1.0, mean + 4.0)]:
        # scipy's von Mises lives on [loc - pi, loc + pi]; split arcs that leave it.
        a, b = lo - mean, hi - mean
        ref = 0.0
        for k in (-1, 0, 1):
            x0 = min(max(a - k * TWO_PI, -math.pi), math.pi)
            x1 = min(max(b - k * TWO_PI, -math.pi), math.pi)
            ref += stats.vonmises.cdf(x1, kappa) - stats.vonmises.cdf(x0, kappa)
        assert_allclose(prior.mass(lo, hi), ref, atol=2e-5)
    assert "von-mises" in prior.name


def test_von_mises_limits_and_errors() -> None:
    assert_allclose(von_mises(1.0, 0.0).weights, 1.0 / 3600, rtol=1e-12)
    assert von_mises(0.0, 1e4).mass(-0.05, 0.05) > 0.99
    with pytest.raises(PriorError, match="kappa >= 0"):
        von_mises(0.0, -1.0)
    with pytest.raises(PriorError, match="finite mean"):
        von_mises(math.nan, 1.0)
    with pytest.raises(PriorError, match="finite mean"):
        von_mises(0.0, math.inf)


# --------------------------------------------------------------------------- sample


def test_sample_prior() -> None:
    p = SamplePrior([0.1, 0.2, 3.0, 6.2, 0.2])
    assert_allclose(p.mass(0.0, 1.0), 0.6)
    assert_allclose(p.mass(0.2, 3.0), 0.4)  # [0.2, 3.0): both atoms at 0.2, not 3.0
    assert_allclose(p.mass(-1.0, 0.15), 0.4)  # 6.2 - 2 pi and 0.1
    assert_allclose(p.mass(0.0, TWO_PI * 2), 2.0)
    assert_allclose(p.angles, [0.1, 0.2, 0.2, 3.0, 6.2])
    assert not p.angles.flags.writeable
    wrapped = SamplePrior([-0.1, TWO_PI + 0.3])
    assert_allclose(wrapped.angles, [0.3, TWO_PI - 0.1])


@pytest.mark.parametrize(
    ("angles", "match"),
    [([], "at least one finite angle; got 0"), ([1.0, math.nan], "finite"), (["x"], "numbers")],
)
def test_sample_prior_rejects_bad_samples(angles: list[object], match: str) -> None:
    with pytest.raises(PriorError, match=match):
        SamplePrior(angles)  # type: ignore[arg-type]


@given(
    atoms=st.lists(st.floats(-10, 10), min_size=1, max_size=30),
    a=st.floats(-20, 20),
    span=st.floats(0, 20),
)
def test_sample_mass_counts_atoms(atoms: list[float], a: float, span: float) -> None:
    p = SamplePrior(atoms)
    b = a + span
    ang = p.angles  # folded into [0, 2 pi)
    # An atom exactly at an end is on either side of it by round-off alone.
    for end in (a, b):
        assume(np.all(np.abs(np.mod(ang - end + math.pi, TWO_PI) - math.pi) > 1e-9))
    count = 0
    for k in range(-10, 11):
        x = ang + k * TWO_PI
        count += int(np.count_nonzero((x >= a) & (x < b)))
    assert_allclose(p.mass(a, b), count / len(ang), atol=1e-12)


# --------------------------------------------------------------------------- best arcs


@pytest.mark.parametrize("group", [1, 2, 3, 4])
def test_max_arc_mass_of_histograms_against_grid_search(
    group: int, rng: np.random.Generator
) -> None:
    for _ in range(20):
        prior = HistogramPrior(rng.random(int(rng.integers(1, 40))) ** 3)
        length = float(rng.uniform(0.01, TWO_PI / group))
        mass, start = prior.max_arc_mass(length, group)
        assert_allclose(float(prior.arc_mass(start, length, group)), mass, atol=1e-12)
        best = grid_best(prior, length, group)
        # The grid can only miss the optimum by the mass a start step moves.
        slack = group * 2 * float(prior.density(np.linspace(0, TWO_PI, 5000)).max())
        assert best - 1e-12 <= mass <= best + slack * TWO_PI / 20000
        assert mass <= 1.0 + 1e-12


@pytest.mark.parametrize("group", [1, 2, 3])
def test_max_arc_mass_of_von_mises_against_grid_search(group: int) -> None:
    prior = von_mises(2.0, 6.0, bins=720)
    for length in (0.1, 0.5, TWO_PI / group - 0.2):
        mass, start = prior.max_arc_mass(length, group)
        best = grid_best(prior, length, group, m=40000)
        assert best - 1e-12 <= mass <= best + 1e-4
        assert_allclose(float(prior.arc_mass(start, length, group)), mass, atol=1e-12)
        if group == 1:  # a symmetric unimodal density: the arc is centred on the mode
            assert_allclose(
                np.mod(start + length / 2 - 2.0 + math.pi, TWO_PI) - math.pi, 0.0, atol=TWO_PI / 720
            )


def test_max_arc_mass_keeps_the_preferred_start_on_ties() -> None:
    prior = HistogramPrior([1, 1, 1, 1])
    assert prior.max_arc_mass(1.0, prefer=0.3) == (pytest.approx(1.0 / TWO_PI), 0.3)
    peaked = HistogramPrior([1, 5, 1, 1])
    mass, start = peaked.max_arc_mass(0.5, prefer=0.3)
    assert mass > float(peaked.arc_mass(0.3, 0.5))
    assert math.pi / 2 <= start <= math.pi - 0.5 + 1e-12


@pytest.mark.parametrize("group", [1, 2, 3, 5])
def test_max_arc_mass_of_samples_against_brute_force(group: int, rng: np.random.Generator) -> None:
    for _ in range(25):
        n = int(rng.integers(1, 25))
        # Clustered atoms, some repeated, some in whole degrees (ties with arc ends).
        atoms = np.concatenate(
            [rng.normal(rng.uniform(0, TWO_PI), 0.3, size=n), np.radians(rng.integers(0, 360, 3))]
        )
        atoms = np.concatenate([atoms, atoms[:2]])
        prior = SamplePrior(atoms)
        length = float(rng.uniform(0.05, TWO_PI / group - 0.01))
        prefer = float(rng.choice(prior.angles))  # a preferred start exactly on an atom
        mass, start = prior.max_arc_mass(length, group, prefer=prefer)
        # The returned open arc holds the returned mass.
        assert_allclose(open_arc_mass(prior.angles, start, length, group), mass, atol=1e-12)
        assert_allclose(
            open_arc_mass(prior.angles, prefer, length, group) >= mass - 1e-12, start == prefer
        )
        # Brute force: starts on a grid and just inside every atom, both ends.
        eps = 1e-9
        cands = np.concatenate(
            [
                np.arange(2000) * TWO_PI / 2000,
                prior.angles - eps,
                prior.angles - length + eps,
            ]
        )
        cands = np.concatenate([cands - TWO_PI * j / group for j in range(group)])
        best = float(open_arc_mass(prior.angles, cands, length, group).max())
        assert_allclose(mass, best, atol=1e-12)


def test_max_arc_mass_of_samples_with_a_whole_period() -> None:
    prior = SamplePrior([0.5, 1.0, 4.0])
    mass, start = prior.max_arc_mass(TWO_PI)
    assert mass == 1.0
    assert float(open_arc_mass(prior.angles, start, TWO_PI, 1)) == 1.0


# --------------------------------------------------------------------------- parse_prior


def test_parse_prior_good(tmp_path: Path) -> None:
    assert isinstance(parse_prior("uniform"), UniformPrior)
    assert isinstance(parse_prior(" Uniform"), UniformPrior)
    vm = parse_prior("vonmises:30,4")
    assert isinstance(vm, HistogramPrior)
    assert_allclose(
        vm.mass(math.radians(30) - 0.2, math.radians(30) + 0.2),
        von_mises(math.radians(30), 4.0).mass(math.radians(30) - 0.2, math.radians(30) + 0.2),
    )
    assert parse_prior("von-mises:0,1").name == "von-mises(0deg,1)"
    hist = tmp_path / "h.txt"
    hist.write_text("1, 3\n0 0\n", encoding="utf-8")
    hp = parse_prior(f"histogram:{hist}")
    assert isinstance(hp, HistogramPrior)
    assert_allclose(hp.weights, [0.25, 0.75, 0.0, 0.0])
    assert hp.name == "histogram(h.txt)"
    sample = tmp_path / "s.csv"
    sample.write_text("0\n90\n90,  180\n-90\n", encoding="utf-8")
    sp = parse_prior(f"sample:{sample}")
    assert isinstance(sp, SamplePrior)
    assert_allclose(sp.angles, np.radians([0, 90, 90, 180, 270]))


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("", "the prior is empty"),
        ("gauss:1,2", "unknown prior 'gauss:1,2'; expected uniform"),
        ("uniform:3", "unknown prior"),
        ("vonmises:30", "needs two numbers; got '30'"),
        ("vonmises:30,4,5", "needs two numbers"),
        ("vonmises:a,b", "needs two numbers"),
        ("vonmises:", "needs two numbers"),
        ("vonmises:30,-1", "kappa >= 0"),
        ("vonmises:nan,1", "finite mean"),
        ("histogram:/no/such/file.txt", "no such file"),
        ("sample:/no/such/file.txt", "no such file"),
    ],
)
def test_parse_prior_bad(spec: str, match: str) -> None:
    with pytest.raises(PriorError, match=match):
        parse_prior(spec)


@pytest.mark.parametrize(
    ("kind", "text", "match"),
    [
        ("histogram", "1, 2, x", "must hold numbers only"),
        ("histogram", "", "the file is empty"),
        ("histogram", "0 0 0", "not all zero"),
        ("histogram", "1 -2", "non-negative"),
        ("sample", "", "the file is empty"),
        ("sample", "10 nan", "finite"),
        ("sample", "ten", "must hold numbers only"),
    ],
)
def test_parse_prior_bad_files(kind: str, text: str, match: str, tmp_path: Path) -> None:
    path = tmp_path / "prior.txt"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(PriorError, match=match):
        parse_prior(f"{kind}:{path}")


def test_parse_prior_directory_is_not_a_file(tmp_path: Path) -> None:
    with pytest.raises(PriorError, match="cannot be read"):
        parse_prior(f"histogram:{tmp_path}")


def test_priors_are_frozen() -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        HistogramPrior([1.0]).name = "x"  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        SamplePrior([1.0]).name = "x"  # type: ignore[misc]


def test_prior_files_are_read_safely(tmp_path: Path) -> None:
    latin = tmp_path / "angles.txt"
    latin.write_bytes(b"\xff\xfe10\n20\n")
    with pytest.raises(PriorError, match="not UTF-8"):
        parse_prior(f"sample:{latin}")
    fifo = tmp_path / "pipe.txt"
    os.mkfifo(fifo)
    with pytest.raises(PriorError, match="FIFO"):
        parse_prior(f"histogram:{fifo}")
