"""The exact planner (planning/exact.py) against checks that do not share its logic.

- Execution: every returned plan is replayed with ``execute_plan`` (the squeeze function
  applied step by step) on orientations drawn from the prior; the fraction that ends at the
  stated final orientation must match the stated probability (binomial bound, fixed seed),
  also after perturbing every turn by just under the stated tolerance.
- Brute force: a planner written here from the seed's section 4.4 only. After a first
  squeeze at angle 0 each state sits at its stable orientation; each further action is tried
  at one turn from every class of equivalent turns (the effect changes only where an
  occupied orientation minus the turn crosses a basin boundary) and the orientations are
  moved by the transfer function. It records which sets of first-squeeze states end
  together; their probabilities come from a fine grid of initial orientations pushed through
  the squeeze function. No arcs, lengths or fronts.
- Tolerance: a grid search over the turns of three-squeeze plans for the largest cube of
  errors that keeps one success set, and a dense search over every chain of arcs.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from numpy.typing import NDArray
from scipy import ndimage, stats

from bayesgrasp import (
    CostModel,
    Goal,
    HistogramPrior,
    Part,
    PlanningError,
    PlanStep,
    Problem,
    SamplePrior,
    UniformPrior,
    execute_plan,
    plan_exact,
    squeeze_function,
    von_mises,
)
from bayesgrasp.geometry.diameter import diameter_function
from bayesgrasp.geometry.transfer import TransferFunction, transfer_from_extrema
from bayesgrasp.model.actions import PUSH_GRASP, SQUEEZE
from bayesgrasp.model.prior import Prior
from bayesgrasp.planning.arcs import arc_front
from bayesgrasp.planning.result import PlanOption, PlanReport, choose_indices
from bayesgrasp.shapes import load, names
from reference import regular_polygon, rotate
from strategies import convex_points

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]

RECTANGLE = [(0.0, 0.0), (31.0, 0.0), (31.0, 20.0), (0.0, 20.0)]
SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
EQUILATERAL = [(0.0, 0.0), (1.0, 0.0), (0.5, math.sqrt(3.0) / 2.0)]
# Hulls of 10 random points (rounded) where a plan's turns can be chosen to tolerate much
# more error than the widest arcs of each length allow (found by the grid search below).
WIDE_MARGIN_PARTS = {
    "hexagon-a": [
        (0.0775, 0.7632),
        (0.1307, 0.0813),
        (0.6199, 0.1871),
        (0.9064, 0.2692),
        (0.7765, 0.8258),
        (0.4348, 0.8839),
    ],
    "hexagon-b": [
        (0.1955, 0.8787),
        (0.1978, 0.4543),
        (0.5932, 0.2222),
        (0.7443, 0.3804),
        (0.8189, 0.6781),
        (0.5535, 0.807),
    ],
    "heptagon": [
        (0.0443, 0.3324),
        (0.2495, 0.1737),
        (0.4377, 0.1411),
        (0.9216, 0.0702),
        (0.9239, 0.1013),
        (0.8492, 0.9103),
        (0.107, 0.8179),
    ],
}


def random_part(rng: np.random.Generator, n: int = 10) -> Part:
    """The seed's random polygon: the hull of ``n`` uniform points in the unit square."""
    return Part.from_points(rng.uniform(size=(n, 2)))


# --------------------------------------------------------------------------------------
# The brute-force planner
# --------------------------------------------------------------------------------------


def turn_classes(pos: FloatArray, bounds: FloatArray, period: float) -> FloatArray:
    """One turn from each class of equivalent gripper turns for orientations ``pos``."""
    crit = np.unique(np.mod(np.unique(pos)[:, None] - bounds[None, :], period).ravel())
    hi = np.append(crit[1:], crit[0] + period)
    wide = hi - crit > 1e-9
    return np.asarray(0.5 * (crit + hi)[wide], dtype=np.float64)


def relative_key(pos: FloatArray) -> bytes:
    """Orientations up to a common turn (the next turn absorbs it)."""
    d = np.mod(pos - pos[0], TWO_PI)
    d[d > TWO_PI - 1e-9] = 0.0
    return np.round(d, 9).tobytes()


def collapsible_sets(
    transfers: dict[str, TransferFunction],
    k_max: int,
    goal_period: float = TWO_PI,
) -> list[dict[tuple[str, ...], set[int]]]:
    """For k = 1..k_max and each sequence of action types: the sets of first-action states
    (bit masks) that some choice of turns sends to one final orientation (mod goal_period).
    """
    level = {(kind,): [f.stable.copy()] for kind, f in transfers.items()}
    out: list[dict[tuple[str, ...], set[int]]] = []
    for k in range(1, k_max + 1):
        if k > 1:
            nxt: dict[tuple[str, ...], dict[bytes, FloatArray]] = {}
            for seq, states in level.items():
                for kind, f in transfers.items():
                    grip = math.pi if kind == "squeeze" else TWO_PI
                    seen = nxt.setdefault((*seq, kind), {})
                    for pos in states:
                        for a in turn_classes(pos, f.boundaries, grip):
                            new = f(pos - a)
                            seen.setdefault(relative_key(new), new)
            level = {seq: list(v.values()) for seq, v in nxt.items()}
        sets: dict[tuple[str, ...], set[int]] = {}
        for seq, states in level.items():
            found = sets.setdefault(seq, set())
            for pos in states:
                q = np.mod(pos, goal_period)
                q[q > goal_period - 1e-7] = 0.0
                q = np.round(q, 7)
                for v in np.unique(q):
                    found.add(int(np.sum(1 << np.flatnonzero(q == v).astype(object))))
        out.append(sets)
    return out


GRID = 1 << 16


def masses_at(
    f: TransferFunction,
    theta: FloatArray,
    weight: FloatArray | None = None,
    first_angles: FloatArray | float = 0.0,
) -> FloatArray:
    """Mass of each state after a first squeeze at each of ``first_angles``: the initial
    orientations ``theta`` (with ``weight``) pushed through the squeeze function.

    Returns an array of shape (A, K) (or (K,) for one angle).
    """
    a = np.atleast_1d(np.asarray(first_angles, dtype=np.float64))
    end = f(theta[None, :] - a[:, None])  # (A, N)
    state = np.argmin(np.abs(wrap_pi(end[..., None] - f.stable)), axis=-1)  # (A, N)
    w = np.ones(len(theta)) if weight is None else np.asarray(weight, dtype=np.float64)
    k = f.n_states
    flat = (state + k * np.arange(len(a))[:, None]).ravel()
    out = np.bincount(flat, weights=np.tile(w, len(a)), minlength=k * len(a)) / w.sum()
    out = out.reshape(len(a), k)
    return out if np.ndim(first_angles) else out[0]


def wrap_pi(x: FloatArray) -> FloatArray:
    return np.asarray(np.mod(x + math.pi, TWO_PI) - math.pi, dtype=np.float64)


def uniform_grid(n: int = GRID) -> FloatArray:
    return (np.arange(n) + 0.5) * (TWO_PI / n)


def best_mass(sets: set[int], masses: FloatArray) -> FloatArray:
    """Largest total mass of one of the sets (for each row of ``masses``)."""
    k = masses.shape[-1]
    member = np.array([[m >> i & 1 for i in range(k)] for m in sets], dtype=np.float64)
    return np.asarray((masses @ member.T).max(axis=-1), dtype=np.float64)


def lands(out: FloatArray, final: float, period: float = TWO_PI) -> NDArray[np.bool_]:
    """Whether each orientation is the final one (or a copy ``period`` apart)."""
    return np.abs(np.mod(out - final + period / 2, period) - period / 2) < 1e-6


def period_of_goal(pb: Problem) -> float:
    return TWO_PI / pb.goal_group


# --------------------------------------------------------------------------------------
# Brute force agrees with the planner
# --------------------------------------------------------------------------------------


def check_against_brute_force(pb: Problem) -> None:
    rep = plan_exact(pb)
    f = pb.states
    k_max = len(rep.options)
    sets = collapsible_sets({"squeeze": f}, k_max + 1, period_of_goal(pb))
    masses = masses_at(f, uniform_grid())
    atol = 2.0 * (f.n_states + 1) / GRID  # each basin end costs at most one grid point
    brute = [float(best_mass(s[("squeeze",) * (k + 1)], masses)) for k, s in enumerate(sets)]
    planned = [o.success_probability for o in rep.options]
    assert_allclose(planned, brute[:k_max], atol=atol)
    # The search stops at the first length that reaches what no longer plan beats.
    assert brute[k_max] <= planned[-1] + atol
    if k_max > 1:
        assert planned[-2] < planned[-1] - 1e-9
    assert rep.most_certain == k_max - 1
    costs = [(k + 2) / p for k, p in enumerate(planned)]
    assert_allclose([o.expected_cost for o in rep.options], costs, rtol=1e-12)


def test_brute_force_agrees_on_random_polygons(rng: np.random.Generator) -> None:
    for _ in range(30):
        check_against_brute_force(Problem.build(random_part(rng, int(rng.integers(5, 12)))))


@pytest.mark.parametrize("name", names())
def test_brute_force_agrees_on_catalogue(name: str) -> None:
    check_against_brute_force(Problem.build(load(name)))


@pytest.mark.parametrize("goal", [Goal("single"), Goal("symmetry")], ids=["single", "symmetry"])
@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_brute_force_agrees_on_regular_polygons(n: int, goal: Goal) -> None:
    check_against_brute_force(Problem.build(Part.from_points(regular_polygon(n)), goal=goal))


# --------------------------------------------------------------------------------------
# Execution of the returned plans
# --------------------------------------------------------------------------------------


def draw(prior: Prior, spec: tuple[str, object], n: int, rng: np.random.Generator) -> FloatArray:
    """Initial orientations from the prior, drawn here without the library."""
    kind, arg = spec
    if kind == "uniform":
        return rng.uniform(0.0, TWO_PI, n)
    if kind == "vonmises":
        mean, kappa = arg  # type: ignore[misc]
        return rng.vonmises(mean, kappa, n)
    if kind == "histogram":
        w = np.asarray(arg, dtype=np.float64)
        b = rng.choice(len(w), size=n, p=w / w.sum())
        return (b + rng.uniform(size=n)) * (TWO_PI / len(w))
    return rng.choice(np.asarray(arg, dtype=np.float64), size=n)


PRIOR_SPECS: list[tuple[str, object]] = [
    ("uniform", None),
    ("vonmises", (1.2, 3.0)),
    ("histogram", [1.0, 6.0, 2.0, 0.5, 0.0, 1.0]),
    ("sample", [0.3, 0.35, 0.5, 2.0, 2.1, 4.0, 4.05, 4.1, 6.0]),
]


def make_prior(spec: tuple[str, object]) -> Prior:
    kind, arg = spec
    if kind == "uniform":
        return UniformPrior()
    if kind == "vonmises":
        mean, kappa = arg  # type: ignore[misc]
        return von_mises(mean, kappa)
    if kind == "histogram":
        return HistogramPrior(np.asarray(arg))
    return SamplePrior(np.asarray(arg))


def replay(
    pb: Problem, option: PlanOption, theta: FloatArray, errors: FloatArray | None = None
) -> NDArray[np.bool_]:
    steps = list(option.steps)
    if errors is not None:
        steps = [steps[0]] + [
            PlanStep(s.kind, s.alpha + e) for s, e in zip(steps[1:], errors, strict=True)
        ]
    return lands(execute_plan(pb, steps, theta), option.final_orientation, period_of_goal(pb))


def binomial_ok(hits: NDArray[np.bool_], p: float) -> bool:
    n = len(hits)
    return abs(float(hits.mean()) - p) <= 5.0 * math.sqrt(p * (1.0 - p) / n) + 1e-12


def error_patterns(m: int, rng: np.random.Generator) -> list[FloatArray]:
    """Both signs together, and random signs."""
    pats = [np.ones(m), -np.ones(m)]
    pats += [rng.choice([-1.0, 1.0], size=m) for _ in range(4)]
    return pats


def arc_grid(option: PlanOption, n: int = 2001) -> FloatArray:
    lo, hi = option.success_arc
    return np.linspace(lo, hi, n)[1:-1]


@pytest.mark.parametrize("spec", PRIOR_SPECS, ids=[s[0] for s in PRIOR_SPECS])
@pytest.mark.parametrize("which", ["triangle", "rectangle", "random", "symmetric"])
def test_plans_replay_to_their_probability(
    which: str, spec: tuple[str, object], rng: np.random.Generator
) -> None:
    if which == "random":
        part, goal = random_part(rng), Goal()
    elif which == "symmetric":
        part, goal = Part.from_points(regular_polygon(6, phase=0.3)), Goal("symmetry")
    else:
        part, goal = load(which), Goal()
    pb = Problem.build(part, make_prior(spec), goal=goal)
    rep = plan_exact(pb)
    theta = draw(pb.prior, spec, 20_000, rng)
    for o in rep.options:
        assert binomial_ok(replay(pb, o, theta), o.success_probability), o
        assert replay(pb, o, arc_grid(o)).all()
        if o.tolerance is None:
            continue
        for sign in error_patterns(o.n_actions - 1, rng):
            errors = 0.999 * o.tolerance * sign
            assert replay(pb, o, arc_grid(o), errors).all(), (o, errors)
            assert binomial_ok(replay(pb, o, theta, errors), o.success_probability)


def test_perturbed_plans_keep_exact_probability(rng: np.random.Generator) -> None:
    """Under the uniform prior the fraction of a fine grid that succeeds is p exactly."""
    theta = uniform_grid(1 << 14)
    for _ in range(12):
        pb = Problem.build(random_part(rng))
        for o in plan_exact(pb).options:
            m = o.n_actions - 1
            tol = o.tolerance or 0.0
            for sign in error_patterns(m, rng):
                frac = replay(pb, o, theta, 0.999 * tol * sign).mean()
                assert_allclose(frac, o.success_probability, atol=3.0 / len(theta))


def test_tolerance_is_tight(rng: np.random.Generator) -> None:
    """Errors just over the tolerance break the plan for some choice of signs."""
    for _ in range(25):
        pb = Problem.build(random_part(rng))
        for o in plan_exact(pb).options:
            if o.tolerance is None:
                continue
            grid = arc_grid(o)
            m = o.n_actions - 1
            broken = any(
                not replay(pb, o, grid, 1.01 * o.tolerance * np.array(sign)).all()
                for sign in itertools.product([-1.0, 1.0], repeat=m)
            )
            assert broken, o


# --------------------------------------------------------------------------------------
# Tolerance: the largest of any plan
# --------------------------------------------------------------------------------------


def grid_tolerance(f: TransferFunction, p: float, cells: int = 360) -> float:
    """Largest cube of errors on (alpha_2, alpha_3) keeping one success set, by grid search.

    Every pair of turns on a grid is tried; the cells where one set of first-squeeze states
    reaches one final orientation with probability ``p`` form regions, and the largest
    chessboard disc inside a region bounds the tolerance (to one cell).
    """
    w = f.widths / TWO_PI
    a = np.arange(cells) * (TWO_PI / cells)
    pos = f(f.stable[None, :] - a[:, None])  # (cells, K)
    pos = f(pos[:, None, :] - a[None, :, None]).reshape(-1, f.n_states)  # (cells^2, K)
    eq = np.abs(pos[:, :, None] - pos[:, None, :]) < 1e-9
    mass = eq @ w
    i = np.argmax(mass, axis=1)
    n = np.arange(len(pos))
    bits = (eq[n, i] * (1 << np.arange(f.n_states))).sum(axis=1)
    final = np.round(pos[n, i] * 1e6).astype(np.int64)
    key = np.where(mass[n, i] >= p - 1e-9, bits * 10**8 + final, -1).reshape(cells, cells)
    best = 0
    for value in np.unique(key[key >= 0]):
        region = np.pad(key == value, cells, mode="wrap")
        best = max(best, int(ndimage.distance_transform_cdt(region, metric="chessboard").max()))
    return best * TWO_PI / cells


@pytest.mark.parametrize("name", sorted(WIDE_MARGIN_PARTS))
def test_tolerance_is_largest_by_grid_search(name: str) -> None:
    pb = Problem.build(Part.from_points(WIDE_MARGIN_PARTS[name]))
    o = plan_exact(pb).options[2]
    cell = TWO_PI / 360
    found = grid_tolerance(pb.states, o.success_probability)
    assert o.tolerance is not None
    assert found - 1.01 * cell <= o.tolerance <= found + 1e-9


def dense_tolerance(f: TransferFunction, k: int, length: float, tol: float = 1e-9) -> float:
    """Best least margin over every chain of k boundary-to-boundary arcs (O(K^4) a step)."""
    kk = f.n_states
    s2 = np.concatenate([f.stable, f.stable + TWO_PI])
    hi2 = np.concatenate([f.basin_hi, f.basin_hi + TWO_PI])
    i, j = np.divmod(np.arange(kk * kk), kk)
    j = i + j
    width, span = hi2[j] - f.basin_lo[i], s2[j] - s2[i]
    best = np.where(i == j, np.inf, -np.inf)  # the last action takes one basin
    for _ in range(k - 1):
        margin = (width[None, :] - span[:, None]) / 2.0  # (arc, next arc)
        value = np.where(margin > tol, np.minimum(margin, best[None, :]), -np.inf)
        best = value.max(axis=1)
    return float(best[width >= length - tol].max())


def test_tolerance_is_largest_over_all_arc_chains(rng: np.random.Generator) -> None:
    for _ in range(60):
        pb = Problem.build(random_part(rng))
        for o in plan_exact(pb).options[1:]:
            length = o.success_arc[1] - o.success_arc[0]
            assert o.tolerance is not None
            assert_allclose(o.tolerance, dense_tolerance(pb.states, o.n_actions, length), atol=1e-9)


def test_turns_are_short_and_first_squeeze_is_zero_under_uniform(
    rng: np.random.Generator,
) -> None:
    for _ in range(30):
        for o in plan_exact(Problem.build(random_part(rng))).options:
            assert o.first_angle == 0.0
            assert all(-math.pi / 2 < a <= math.pi / 2 for a in o.alphas)
            assert 0.0 <= o.final_orientation < TWO_PI


# --------------------------------------------------------------------------------------
# Symmetric parts
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("points", "r", "period"),
    [(SQUARE, 4, math.pi / 2), (EQUILATERAL, 3, math.pi / 3), (RECTANGLE, 2, math.pi)],
    ids=["square", "triangle", "rectangle"],
)
def test_symmetric_parts_cannot_beat_their_period(
    points: list[tuple[float, float]], r: int, period: float
) -> None:
    pb = Problem.build(Part.from_points(points))
    rep = plan_exact(pb)
    assert pb.part.hull.symmetry_order == r
    assert_allclose(pb.states.period, period, atol=1e-12)
    # The seed's accounting: each orientation its own state, so p = period / 2 pi.
    assert_allclose(rep.most_certain_plan.success_probability, period / TWO_PI, atol=1e-12)
    sets = collapsible_sets({"squeeze": pb.states}, len(rep.options) + 2)
    masses = masses_at(pb.states, uniform_grid())
    for k, s in enumerate(sets, start=1):
        assert best_mass(s[("squeeze",) * k], masses) <= period / TWO_PI + 1e-4


@pytest.mark.parametrize(
    ("points", "p", "k"),
    [(SQUARE, 1.0, 1), (EQUILATERAL, 0.5, 1), (RECTANGLE, 1.0, 2)],
    ids=["square", "triangle", "rectangle"],
)
def test_symmetry_goal(points: list[tuple[float, float]], p: float, k: int) -> None:
    pb = Problem.build(Part.from_points(points), goal=Goal("symmetry"))
    rep = plan_exact(pb)
    assert len(rep.options) == k
    assert_allclose(rep.most_certain_plan.success_probability, p, atol=1e-12)
    theta = np.linspace(0.0, TWO_PI, 10_001)
    hits = replay(pb, rep.most_certain_plan, theta)
    # Only the unstable equilibria (measure zero) may be missed.
    assert_allclose(hits.mean(), p, atol=1e-3)


# --------------------------------------------------------------------------------------
# Non-uniform priors
# --------------------------------------------------------------------------------------


def basin_masses(
    f: TransferFunction, cdf: Callable[[FloatArray], FloatArray], first_angles: FloatArray
) -> FloatArray:
    """Mass of each state after a first squeeze at each angle (shape (A, K)).

    ``cdf`` is a cumulative distribution extended so that ``cdf(x + 2 pi) = cdf(x) + 1``;
    the gripper at angle ``a`` sees the part at ``theta - a``, so basin ``(lo, hi)`` in its
    frame holds the initial orientations ``(lo + a, hi + a)``.
    """
    a = np.asarray(first_angles, dtype=np.float64)[:, None]
    return np.asarray(cdf(f.basin_hi + a) - cdf(f.basin_lo + a), dtype=np.float64)


def histogram_cdf(weights: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """Periodic cumulative distribution of a histogram on equal bins of [0, 2 pi)."""
    w = np.asarray(weights, dtype=np.float64) / np.sum(weights)
    edges = np.linspace(0.0, TWO_PI, len(w) + 1)
    cum = np.concatenate([[0.0], np.cumsum(w)])

    def cdf(x: FloatArray) -> FloatArray:
        turns = np.floor(x / TWO_PI)
        return np.asarray(turns + np.interp(x - turns * TWO_PI, edges, cum), dtype=np.float64)

    return cdf


def atoms_cdf(atoms: FloatArray) -> Callable[[FloatArray], FloatArray]:
    """Periodic count (as a fraction) of the atoms strictly below ``x``."""
    a = np.sort(np.mod(atoms, TWO_PI))

    def cdf(x: FloatArray) -> FloatArray:
        turns = np.floor(x / TWO_PI)
        frac = np.searchsorted(a, x - turns * TWO_PI, side="left") / len(a)
        return np.asarray(turns + frac, dtype=np.float64)

    return cdf


ANGLES = np.arange(3600) * (TWO_PI / 3600)  # first-squeeze angles on a 0.1 degree grid


def check_first_angle_grid(
    pb: Problem, cdf: Callable[[FloatArray], FloatArray], step_mass: float, exact: float
) -> None:
    """For each first angle on a grid: the distribution after the first squeeze, then the
    best set the brute force collapses; no angle beats the planner, whose own angle reaches
    its probability (to ``exact``); the grid comes within ``step_mass`` of it."""
    rep = plan_exact(pb)
    sets = collapsible_sets({"squeeze": pb.states}, len(rep.options))
    for k, o in enumerate(rep.options, start=1):
        found = best_mass(sets[k - 1][("squeeze",) * k], basin_masses(pb.states, cdf, ANGLES))
        at = best_mass(
            sets[k - 1][("squeeze",) * k], basin_masses(pb.states, cdf, np.array([o.first_angle]))
        )
        assert_allclose(at[0], o.success_probability, atol=exact)
        assert found.max() <= o.success_probability + exact
        assert found.max() >= o.success_probability - step_mass - exact


@pytest.mark.parametrize("name", ["triangle", "rectangle"])
def test_peaked_prior_moves_first_squeeze_and_raises_probability(name: str) -> None:
    mean, kappa = 1.1, 6.0
    part = load(name)
    uniform = plan_exact(Problem.build(part))
    pb = Problem.build(part, von_mises(mean, kappa))
    rep = plan_exact(pb)
    assert len(rep.options) == len(uniform.options)
    vm = stats.vonmises(kappa, loc=mean)
    for o, u in zip(rep.options, uniform.options, strict=True):
        length = u.success_arc[1] - u.success_arc[0]
        # The best arc of a symmetric unimodal density is centred on its mode.
        expect = vm.cdf(mean + length / 2) - vm.cdf(mean - length / 2)
        assert_allclose(o.success_probability, expect, atol=1e-5)
        assert o.success_probability > u.success_probability + 0.05
        centre = 0.5 * (o.success_arc[0] + o.success_arc[1])
        assert abs(math.remainder(centre - mean, TWO_PI)) < 2e-3
        assert abs(math.remainder(o.first_angle, math.pi)) > 0.01  # not the uniform 0
    peak = vm.pdf(mean)
    check_first_angle_grid(pb, vm.cdf, 2.0 * peak * TWO_PI / len(ANGLES), 1e-5)


@pytest.mark.parametrize("name", ["triangle", "random"])
def test_histogram_and_sample_priors_against_first_angle_grid(
    name: str, rng: np.random.Generator
) -> None:
    part = load(name) if name != "random" else random_part(rng)
    hist = np.array([1.0, 8.0, 2.0, 0.5, 0.0, 1.0, 3.0, 0.2])
    peak = hist.max() / hist.sum() * len(hist) / TWO_PI
    pb = Problem.build(part, HistogramPrior(hist))
    check_first_angle_grid(pb, histogram_cdf(hist), 2.0 * peak * TWO_PI / len(ANGLES), 1e-12)
    atoms = np.mod(rng.vonmises(2.0, 2.0, 40), TWO_PI)
    pb = Problem.build(part, SamplePrior(atoms))
    check_first_angle_grid(pb, atoms_cdf(atoms), 1.0 / len(atoms), 1e-12)


# --------------------------------------------------------------------------------------
# The cost model
# --------------------------------------------------------------------------------------


def costs_of(rep: PlanReport) -> list[float]:
    return [o.expected_cost for o in rep.options]


def test_cost_formula_and_bayes_plan_change() -> None:
    tri = load("triangle")
    base = plan_exact(Problem.build(tri))
    ps = np.array([o.success_probability for o in base.options])
    k = np.arange(1, len(ps) + 1)
    cases = [
        (CostModel(), (k + 1) / ps),
        (CostModel(first={"squeeze": 4.0}), (4.0 + (k - 1) + 1) / ps),
        (CostModel({"squeeze": 2.0}, verify=3.0), (2.0 * k + 3.0) / ps),
        (CostModel(retry=1.5), (k + 1) / ps + 1.5 * (1 / ps - 1)),
        (CostModel(verify=0.0), k / ps),
    ]
    for cost, expect in cases:
        rep = plan_exact(Problem.build(tri, cost=cost))
        assert_allclose(costs_of(rep), expect, rtol=1e-12)
        assert [o.success_probability for o in rep.options] == list(ps)
        assert rep.bayes == int(np.flatnonzero(expect <= expect.min() * (1 + 1e-12))[0])
    # The seed's triangle row, 10.8 8.7 8.0: the most certain plan is the Bayes plan.
    assert_allclose(costs_of(base), [10.8, 8.7, 8.0], atol=0.05)
    assert base.bayes == 2 and base.most_certain == 2
    # A free verification makes shorter plans relatively cheaper: k / p_k.
    free = plan_exact(Problem.build(tri, cost=CostModel(verify=0.0)))
    assert free.bayes == int(np.argmin(k / ps)) and free.bayes < 2
    # Ties go to fewer squeezes: a cost model making plans 2 and 3 equal picks 2.
    tie = CostModel({"squeeze": 1.0}, verify=(3 * ps[1] - 2 * ps[2]) / (ps[2] - ps[1]))
    tied = plan_exact(Problem.build(tri, cost=tie))
    assert_allclose(costs_of(tied)[1], costs_of(tied)[2], rtol=1e-9)
    assert tied.bayes == 1
    # A free first squeeze makes the one-squeeze plan the Bayes plan of the rectangle.
    rect = load("rectangle")
    assert plan_exact(Problem.build(rect)).bayes == 1
    assert plan_exact(Problem.build(rect, cost=CostModel(first={"squeeze": 0.0}))).bayes == 0
    assert plan_exact(Problem.build(rect, cost=CostModel({"squeeze": 10.0}))).bayes == 0


def test_choose_indices_ties_and_tolerance() -> None:
    def opt(p: float, c: float) -> PlanOption:
        return PlanOption((PlanStep("squeeze", 0.0),), 0.0, p, c, None, (0.0, 1.0))

    assert choose_indices((opt(0.3, 8.0), opt(0.4, 8.0), opt(0.5, 8.0))) == (0, 2)
    assert choose_indices((opt(0.3, 8.0 + 1e-9), opt(0.5, 8.0))) == (1, 1)
    assert choose_indices((opt(0.3, 6.0), opt(0.5, 7.0), opt(0.5, 8.0))) == (0, 1)


def test_max_actions() -> None:
    pb = Problem.build(load("triangle"))
    rep = plan_exact(pb, max_actions=2)
    assert len(rep.options) == 2
    assert rep.most_certain == 1
    with pytest.raises(PlanningError, match="`max_actions` must be an integer >= 1; got 0"):
        plan_exact(pb, max_actions=0)


# --------------------------------------------------------------------------------------
# Several action types: the dynamic programme over counts and orders
# --------------------------------------------------------------------------------------


def synthetic_transfer(rng: np.random.Generator, k: int) -> TransferFunction:
    """A monotone step function of period 2 pi with k random states (a stand-in push)."""
    cuts = np.sort(rng.uniform(0.0, TWO_PI, 2 * k))
    while np.min(np.diff(np.append(cuts, cuts[0] + TWO_PI))) < 0.05:
        cuts = np.sort(rng.uniform(0.0, TWO_PI, 2 * k))
    return transfer_from_extrema("push-grasp", cuts[0::2], cuts[1::2], 1e-9, 1e-6)


@pytest.mark.parametrize("push_cost", [0.2, 1.0, 3.0])
def test_two_action_types_against_brute_force(rng: np.random.Generator, push_cost: float) -> None:
    longest = 4
    for _ in range(5):
        part = random_part(rng, 7)
        squeeze = squeeze_function(part.hull)
        push = synthetic_transfer(rng, int(rng.integers(2, 5)))
        cost = CostModel({"push-grasp": push_cost}, first={"squeeze": 0.5})
        pb = Problem(
            part,
            squeeze,
            diameter_function(part.hull),
            UniformPrior(),
            (SQUEEZE, PUSH_GRASP),
            {"squeeze": squeeze, "push-grasp": push},
            cost,
            Goal(),
        )
        rep = plan_exact(pb, max_actions=longest)
        sets = collapsible_sets(pb.transfers, longest)
        masses = {kind: f.widths / TWO_PI for kind, f in pb.transfers.items()}
        # The best probability of each order of action types, for each length.
        brute = [
            {seq: float(best_mass(s, masses[seq[0]])) for seq, s in level.items()} for level in sets
        ]
        p_top = [max(b.values()) for b in brute]
        c_top = [min(cost.expected_cost(seq, p) for seq, p in b.items()) for b in brute]
        m = rep.most_certain
        assert [o.n_actions for o in rep.options[: m + 1]] == list(range(1, m + 2))
        for i, o in enumerate(rep.options):
            k = o.n_actions
            assert_allclose(brute[k - 1][o.kinds], o.success_probability, atol=1e-12)
            if i < m:  # below the most certain length: the cheapest plan of each length
                assert_allclose(o.expected_cost, c_top[k - 1], rtol=1e-12)
            elif i == m:  # the most certain plan
                assert_allclose(o.success_probability, p_top[k - 1], atol=1e-12)
            theta = np.linspace(0.0, TWO_PI, 20_001)
            assert_allclose(replay(pb, o, theta).mean(), o.success_probability, atol=1e-3)
            assert replay(pb, o, arc_grid(o)).all()
            if o.tolerance is not None:
                for sign in error_patterns(k - 1, rng):
                    assert replay(pb, o, arc_grid(o), 0.999 * o.tolerance * sign).all()
        # At the most certain length or longer, a cheaper plan (cheap actions, or less
        # certain) is reported after the most certain one, and only if it beats them all.
        cheapest_long = min(c_top[m:])
        costs = [o.expected_cost for o in rep.options[: m + 1]]
        if len(rep.options) > m + 1:
            assert len(rep.options) == m + 2
            extra = rep.options[-1]
            assert_allclose(extra.expected_cost, cheapest_long, rtol=1e-12)
            assert extra.expected_cost < min(costs)
            assert rep.bayes == m + 1
        else:
            assert cheapest_long >= min(costs) * (1 - 1e-12)


# --------------------------------------------------------------------------------------
# Invariance (hypothesis)
# --------------------------------------------------------------------------------------


def summary(rep: PlanReport) -> tuple[FloatArray, FloatArray, FloatArray]:
    opts = rep.options
    return (
        np.array([o.success_probability for o in opts]),
        np.array([o.expected_cost for o in opts]),
        np.array([o.tolerance or 0.0 for o in opts]),
    )


@settings(max_examples=60)
@given(
    points=convex_points(),
    beta=st.floats(-math.pi, math.pi),
    scale=st.floats(1e-3, 1e3),
    shift=st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
)
def test_plans_invariant_under_similarity(
    points: FloatArray, beta: float, scale: float, shift: tuple[float, float]
) -> None:
    base_pb = Problem.build(Part.from_points(points))
    base = plan_exact(base_pb)
    moved_pts = rotate(points, beta) * scale + np.array(shift)
    moved_pb = Problem.build(Part.from_points(moved_pts))
    moved = plan_exact(moved_pb)
    assert len(moved.options) == len(base.options)
    for a, b in zip(summary(base), summary(moved), strict=True):
        assert_allclose(a, b, rtol=1e-7, atol=1e-7)
    assert (moved.bayes, moved.most_certain) == (base.bayes, base.most_certain)
    # Rotating the coordinates by beta turns every orientation by -beta.
    s0, s1 = base_pb.states, moved_pb.states
    period = s0.period
    turned = wrap_pi(s1.stable[:, None] + beta - s0.stable[None, :])  # (K, K) differences
    assert s1.n_states == s0.n_states
    assert np.all(np.min(np.abs(turned), axis=1) < 1e-6)
    for o0, o1 in zip(base.options, moved.options, strict=True):
        turn = math.remainder(o1.final_orientation + beta - o0.final_orientation, period)
        assert abs(turn) < 1e-6
        # The moved plan, replayed on the moved part, orients its own success arc.
        assert replay(moved_pb, o1, arc_grid(o1, 201)).all()


# --------------------------------------------------------------------------------------
# Parts with many stable orientations
# --------------------------------------------------------------------------------------


def noisy_circle(rng: np.random.Generator, n: int, noise: float) -> Part:
    a = np.sort(rng.uniform(0.0, TWO_PI, n))
    r = 1.0 + noise * rng.uniform(size=n)
    return Part.from_points(np.column_stack([r * np.cos(a), r * np.sin(a)]))


def test_many_states_plans_replay(rng: np.random.Generator) -> None:
    pb = Problem.build(noisy_circle(rng, 600, 1e-3))
    rep = plan_exact(pb)
    assert pb.n_states > 100 and len(rep.options) > 20
    probs = [o.success_probability for o in rep.options]
    assert np.all(np.diff(probs) > 0) and probs[-1] == pytest.approx(0.5, abs=1e-12)
    theta = uniform_grid(1 << 14)
    for o in rep.options[1::7]:
        assert o.tolerance is not None
        for sign in (1.0, -1.0):
            errors = 0.999 * o.tolerance * sign * np.ones(o.n_actions - 1)
            assert replay(pb, o, arc_grid(o, 501), errors).all()
        frac = replay(pb, o, theta).mean()
        assert_allclose(frac, o.success_probability, atol=3.0 / len(theta))


def test_arc_enumeration_in_chunks_changes_nothing(rng: np.random.Generator) -> None:
    pb = Problem.build(noisy_circle(rng, 200, 1e-2))
    f = pb.states
    for max_span in (0.0, 0.3, math.pi, TWO_PI + 1e-9):
        whole = arc_front(f, max_span)
        for chunk in (1, 50, 1000):
            part = arc_front(f, max_span, chunk=chunk)
            for name in ("lo", "width", "s_first", "span"):
                assert np.array_equal(getattr(part, name), getattr(whole, name)), name
