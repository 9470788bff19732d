"""Running a plan on orientations: the kinematic Monte Carlo check of a plan.

A plan's success probability is a statement about the initial orientations it sends to the
goal (design.md). This module checks it by sampling: draw initial orientations from the
prior, optionally perturb every commanded gripper angle by an error, run the plan through
the transfer functions exactly as :func:`~bayesgrasp.planning.result.execute_plan` does, and
compare the empirical distribution of final orientations with the predicted one.

The prediction is exact, not sampled: the first action sends a whole basin to one stable
orientation, so the final orientation is a function of the first action's state. The
predicted probability of a final orientation is the prior mass of the basins whose stable
orientation the remaining actions send there (the prior mass of a basin is the cumulative
difference at its ends).

The same summary (:class:`SimulationResult`) holds the physics engine's trials
(:mod:`bayesgrasp.sim`): counts per final orientation, success rate with a Wilson score
interval, a chi-square goodness-of-fit p-value, jams (the part stopped away from every stable
orientation) and starts near a basin boundary (where a real part can jam or go either way).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import BayesGraspError
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption, PlanStep, execute_plan

__all__ = [
    "GripperNoise",
    "SimulationResult",
    "boundary_distance",
    "goal_states",
    "goodness_of_fit",
    "plan_from_json",
    "predicted_distribution",
    "sample_prior",
    "simulate_kinematic",
    "summarize",
    "wilson_interval",
]

TWO_PI = 2.0 * math.pi
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
BoolArray = NDArray[np.bool_]
Progress = Callable[[int, int], None]

#: Starts closer than this to a basin boundary are counted as near-boundary (radians). The
#: physics check (``/work/shared/physics-notes.md``) saw jams only within about 2.3 degrees
#: of a boundary; 2.5 degrees covers that with a margin.
DEFAULT_BOUNDARY_MARGIN = math.radians(2.5)


class SimulationError(BayesGraspError, ValueError):
    """Bad simulation settings (trials, noise, plan)."""


@dataclass(frozen=True, slots=True)
class GripperNoise:
    """An error added to every commanded gripper angle (radians).

    Parameters
    ----------
    kind : {"normal", "uniform"}
        ``normal``: zero-mean normal with standard deviation ``scale``; ``uniform``: uniform
        on ``[-scale, scale]``.
    scale : float
        Standard deviation or bound (radians, >= 0). ``0`` means no error.

    Examples
    --------
    >>> e = GripperNoise("uniform", 0.1).draw((1000,), 0)
    >>> bool(np.all(np.abs(e) <= 0.1))
    True
    """

    kind: Literal["normal", "uniform"] = "normal"
    scale: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("normal", "uniform"):
            raise SimulationError(
                f"gripper noise `kind` must be 'normal' or 'uniform'; got {self.kind!r}"
            )
        if not (isinstance(self.scale, int | float) and math.isfinite(self.scale)) or (
            self.scale < 0
        ):
            raise SimulationError(
                f"gripper noise `scale` must be a finite number >= 0; got {self.scale!r}"
            )

    def draw(self, shape: tuple[int, ...], rng: np.random.Generator | int | None) -> FloatArray:
        """Angle errors of the given shape (zeros when ``scale`` is 0)."""
        gen = np.random.default_rng(rng)
        if self.scale == 0.0:
            return np.zeros(shape)
        if self.kind == "normal":
            return gen.normal(0.0, self.scale, shape)
        return gen.uniform(-self.scale, self.scale, shape)


def sample_prior(prior: Prior, n: int, rng: np.random.Generator | int | None = None) -> FloatArray:
    """Draw ``n`` initial orientations in ``[0, 2 pi)`` from a prior.

    A prior with its own ``sample(n, rng)`` method is used as is. Otherwise the cumulative
    function is inverted: exactly for the uniform, histogram and density priors (their
    cumulative functions are linear between breakpoints), by drawing atoms for a sample
    prior, and by interpolating a fine table of the cumulative function for any other prior.

    Parameters
    ----------
    prior : Prior
    n : int
        Number of draws (>= 0).
    rng : numpy.random.Generator or int or None

    Returns
    -------
    ndarray of shape (n,)

    Examples
    --------
    >>> x = sample_prior(HistogramPrior([1, 0, 0, 0]), 1000, rng=1)
    >>> bool(np.all((x >= 0) & (x < np.pi / 2)))
    True
    """
    if n < 0:
        raise SimulationError(f"`n` must be >= 0; got {n}")
    gen = np.random.default_rng(rng)
    own = getattr(prior, "sample", None)
    if callable(own):
        return np.mod(np.asarray(own(n, gen), dtype=np.float64), TWO_PI)
    if isinstance(prior, UniformPrior):
        return gen.uniform(0.0, TWO_PI, n)
    if isinstance(prior, SamplePrior):
        return np.asarray(gen.choice(prior.angles, size=n), dtype=np.float64)
    if isinstance(prior, HistogramPrior):
        nodes = np.append(prior.breakpoints, TWO_PI)
    else:  # unknown form: a fine table (a 65536th of a turn) plus the prior's breakpoints
        nodes = np.union1d(np.linspace(0.0, TWO_PI, 65537), np.mod(prior.breakpoints, TWO_PI))
    cum = prior.cdf(nodes) - prior.cdf(0.0)
    u = gen.random(n)
    return np.asarray(np.mod(np.interp(u, cum, nodes), TWO_PI), dtype=np.float64)


def boundary_distance(boundaries: FloatArray, theta: ArrayLike) -> FloatArray:
    """Distance (radians, on the circle) from each angle to the nearest of ``boundaries``.

    Parameters
    ----------
    boundaries : ndarray of shape (B,)
        Angles in ``[0, 2 pi)``, increasing (e.g. ``TransferFunction.boundaries``).
    theta : array_like

    Examples
    --------
    >>> round(float(boundary_distance(np.array([0.0, np.pi]), 6.2)), 6)
    0.083185
    """
    th = np.mod(np.asarray(theta, dtype=np.float64), TWO_PI)
    b = np.concatenate([boundaries[-1:] - TWO_PI, boundaries, boundaries[:1] + TWO_PI])
    k = np.searchsorted(b, th)  # b[k - 1] <= th < b[k]
    return np.asarray(np.minimum(b[k] - th, th - b[k - 1]), dtype=np.float64)


def predicted_distribution(problem: Problem, steps: Sequence[PlanStep]) -> FloatArray:
    """Exact probability of each final state (stable orientation) under the problem's prior.

    The first action sends each of its basins to one stable orientation (state ``i``, with
    the prior mass of the basin, :meth:`Problem.state_distribution`); the remaining actions
    are deterministic on states, so they push the masses forward.

    Returns
    -------
    ndarray of shape (K,)
        Indexed like ``problem.states.stable``; sums to one.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> predicted_distribution(pb, [PlanStep("squeeze", 0.0)]).round(3).tolist()
    [0.148, 0.352, 0.148, 0.352]
    """
    if not steps:
        raise SimulationError("a plan needs at least one step")
    first = steps[0]
    masses = problem.state_distribution(first.alpha, first.kind)  # (K,)
    final = execute_plan(problem, tuple(steps[1:]), problem.states.stable)
    idx = nearest_state(problem.states, final)
    return np.bincount(idx, weights=masses, minlength=problem.n_states).astype(np.float64)


def plan_from_json(doc: dict[str, Any]) -> PlanOption:
    """A plan from JSON: a plan option, or a ``bayesgrasp.plan`` document (its Bayes plan).

    An option gives ``steps`` (``[{"type", "alpha_rad"}, ...]``, as ``bayesgrasp plan
    --json`` writes them) or, for squeezes only, ``first_squeeze_rad`` and ``actions_rad``.
    ``final_orientation_rad`` (the goal) is required; missing statistics (success
    probability, expected cost) are read as unknown (NaN).

    Examples
    --------
    >>> plan_from_json({"first_squeeze_rad": 0.0, "actions_rad": [0.5],
    ...                 "final_orientation_rad": 1.0}).n_actions
    2
    """
    if not isinstance(doc, dict):
        raise SimulationError(f"a plan must be a JSON object; got {type(doc).__name__}")
    if "options" in doc:
        opts = doc["options"]
        pick = doc.get("bayes", 0)
        if not isinstance(opts, list) or not isinstance(pick, int) or not 0 <= pick < len(opts):
            raise SimulationError("a plan document needs `options` and a valid `bayes` index")
        return plan_from_json(opts[pick])
    steps: list[PlanStep] = []
    if "steps" in doc:
        raw = doc["steps"]
        if not isinstance(raw, list) or not raw:
            raise SimulationError("`steps` must be a non-empty list")
        for i, st in enumerate(raw, start=1):
            ok = isinstance(st, dict) and isinstance(st.get("alpha_rad"), int | float)
            if not ok or st.get("type", "squeeze") not in ("squeeze", "push-grasp"):
                raise SimulationError(
                    f'step {i} must be {{"type": "squeeze" | "push-grasp", "alpha_rad": '
                    f"number}}; got {st!r}"
                )
            steps.append(PlanStep(str(st.get("type", "squeeze")), float(st["alpha_rad"])))
    elif "first_squeeze_rad" in doc:
        try:
            angles = [float(doc["first_squeeze_rad"])]
            angles += [float(a) for a in doc.get("actions_rad", [])]
        except (TypeError, ValueError):
            raise SimulationError("`first_squeeze_rad` and `actions_rad` must be numbers") from None
        steps = [PlanStep("squeeze", a) for a in angles]
    else:
        raise SimulationError("a plan needs `steps` or `first_squeeze_rad`")
    if not all(math.isfinite(s.alpha) for s in steps):
        raise SimulationError("plan angles must be finite")

    def num(key: str, default: float = math.nan) -> float:
        value = doc.get(key)
        return float(value) if isinstance(value, int | float) else default

    final = num("final_orientation_rad")
    if not math.isfinite(final):
        raise SimulationError("a plan needs a finite `final_orientation_rad` (its goal)")
    tol = doc.get("tolerance_rad")
    return PlanOption(
        tuple(steps),
        final,
        num("success_probability"),
        num("expected_cost"),
        float(tol) if isinstance(tol, int | float) else None,
        (math.nan, math.nan),
    )


def goal_states(problem: Problem, final_orientation: float) -> BoolArray:
    """Which states count as success: the goal and, for a symmetry goal, its copies.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> goal_states(pb, np.pi / 2).tolist()
    [False, True, False, False]
    """
    g = problem.goal_group
    targets = final_orientation + TWO_PI * np.arange(g) / g
    mask = np.zeros(problem.n_states, dtype=bool)
    mask[nearest_state(problem.states, targets)] = True
    return mask


def wilson_interval(successes: int, trials: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion.

    Better than the normal approximation near 0 and 1 and for small samples (Wilson 1927;
    Brown, Cai and DasGupta 2001).

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


@dataclass(frozen=True, slots=True, eq=False)
class SimulationResult:
    """Predicted against observed outcomes of executing one plan many times.

    Attributes
    ----------
    engine : str
        ``"kinematic"`` or ``"mujoco"``.
    option : PlanOption
        The plan executed.
    trials : int
    orientations : ndarray of shape (K,)
        The stable orientations (the problem's states), radians in ``[0, 2 pi)``.
    predicted : ndarray of shape (K,)
        Exact probability of ending at each state (:func:`predicted_distribution`).
    observed : ndarray of shape (K,)
        Trials that ended at each state (jammed trials are in no state).
    goal : ndarray of shape (K,) of bool
        States that count as success.
    jams : int
        Trials in which some action left the part away from every stable orientation.
    final_jams : int
        Trials whose last action did (counted as failures).
    near_boundary : int
        Trials in which some action started within ``boundary_margin`` of a basin boundary.
    boundary_margin : float
    seconds : float
        Wall time of the trials.
    final : ndarray of shape (trials,)
        Each trial's final orientation (radians, gripper frame of the last action).
    jammed_trials, near_trials : ndarray of shape (trials,) of bool
        Which trials jammed, and which started an action near a basin boundary.
    """

    engine: str
    option: PlanOption
    trials: int
    orientations: FloatArray
    predicted: FloatArray
    observed: IntArray
    goal: BoolArray
    jams: int
    final_jams: int
    near_boundary: int
    boundary_margin: float
    seconds: float
    final: FloatArray = field(repr=False)
    jammed_trials: BoolArray = field(repr=False, default_factory=lambda: np.zeros(0, bool))
    near_trials: BoolArray = field(repr=False, default_factory=lambda: np.zeros(0, bool))

    @property
    def successes(self) -> int:
        """Trials that ended in a goal state."""
        return int(self.observed[self.goal].sum())

    @property
    def predicted_success(self) -> float:
        """Exact success probability of the plan under the prior."""
        return float(self.predicted[self.goal].sum())

    @property
    def observed_success(self) -> float:
        """Fraction of trials that ended in a goal state."""
        return self.successes / self.trials if self.trials else 0.0

    @property
    def ci95(self) -> tuple[float, float]:
        """95% Wilson score interval of the success rate."""
        return wilson_interval(self.successes, self.trials)

    @property
    def p_value(self) -> float:
        """Chi-square p-value of the final states (jammed trials left out) against prediction."""
        return goodness_of_fit(self.observed, self.predicted)

    @property
    def executions_per_second(self) -> float:
        """Trials per second of wall time."""
        return self.trials / self.seconds if self.seconds > 0 else math.inf


def summarize(
    engine: str,
    problem: Problem,
    option: PlanOption,
    final: FloatArray,
    jammed: BoolArray,
    near: BoolArray,
    seconds: float,
    jam_tol: float,
    boundary_margin: float = DEFAULT_BOUNDARY_MARGIN,
) -> SimulationResult:
    """Turn per-trial outcomes into a :class:`SimulationResult`.

    Parameters
    ----------
    engine : str
    problem : Problem
    option : PlanOption
    final : ndarray of shape (T,)
        Final orientation of each trial (gripper frame of the last action).
    jammed : ndarray of shape (T,) of bool
        Whether some action of the trial jammed (left the part off every stable orientation).
    near : ndarray of shape (T,) of bool
        Whether some action of the trial started near a basin boundary.
    seconds : float
    jam_tol : float
        A final orientation farther than this from every stable orientation is a jam.
    boundary_margin : float

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    >>> r = summarize("kinematic", pb, opt, np.array([0.0, 0.0, np.pi / 2]),
    ...               np.zeros(3, bool), np.zeros(3, bool), 1.0, 1e-6)
    >>> r.observed.tolist(), r.successes
    ([2, 1, 0, 0], 2)
    """
    states = problem.states
    final = np.mod(np.asarray(final, dtype=np.float64), TWO_PI)
    idx, err = _nearest_stable(states.stable, final)  # (T,), (T,)
    final_jam = err > jam_tol
    observed = np.bincount(idx[~final_jam], minlength=problem.n_states).astype(np.intp)
    jam_all = np.asarray(jammed, dtype=bool) | final_jam
    near_all = np.asarray(near, dtype=bool)
    return SimulationResult(
        engine=engine,
        option=option,
        trials=len(final),
        orientations=states.stable,
        predicted=predicted_distribution(problem, option.steps),
        observed=observed,
        goal=goal_states(problem, option.final_orientation),
        jams=int(np.count_nonzero(jam_all)),
        final_jams=int(np.count_nonzero(final_jam)),
        near_boundary=int(np.count_nonzero(near_all)),
        boundary_margin=boundary_margin,
        seconds=seconds,
        final=final,
        jammed_trials=jam_all,
        near_trials=near_all,
    )


def _nearest_stable(stable: FloatArray, theta: FloatArray) -> tuple[IntArray, FloatArray]:
    """Index of the nearest of the increasing angles ``stable`` and the distance to it.

    A binary search, so large samples cost O(T log K) time and O(T) memory.
    """
    k = len(stable)
    ext = np.concatenate([stable[-1:] - TWO_PI, stable, stable[:1] + TWO_PI])  # (K + 2,)
    j = np.clip(np.searchsorted(ext, theta), 1, k + 1)  # ext[j - 1] <= theta < ext[j]
    below = theta - ext[j - 1]
    above = ext[j] - theta
    pick = np.where(above < below, j, j - 1)
    idx = np.asarray((pick - 1) % k, dtype=np.intp)
    return idx, np.asarray(np.minimum(below, above), dtype=np.float64)


def _check_trials(trials: int) -> None:
    if not isinstance(trials, int | np.integer) or trials < 1:
        raise SimulationError(f"`trials` must be an integer >= 1; got {trials!r}")


def simulate_kinematic(
    problem: Problem,
    option: PlanOption,
    trials: int,
    noise: GripperNoise | None = None,
    rng: np.random.Generator | int | None = None,
    boundary_margin: float = DEFAULT_BOUNDARY_MARGIN,
    chunk: int = 1 << 18,
    progress: Progress | None = None,
) -> SimulationResult:
    """Execute a plan ``trials`` times on the model: the kinematic Monte Carlo.

    Each trial draws an initial world orientation from the problem's prior, adds the gripper
    error to every commanded angle (the first action's world angle and each ``alpha``), and
    applies the transfer functions as :func:`~bayesgrasp.planning.result.execute_plan` does.
    Work is done in vectorised chunks.

    Parameters
    ----------
    problem : Problem
    option : PlanOption
        The plan (its ``final_orientation`` is the goal).
    trials : int
    noise : GripperNoise, optional
        Default: none. A plan's ``tolerance`` bounds the error on ``alpha_2 .. alpha_k`` that
        keeps its success probability; an error on the first angle only moves the arc of
        successful starts (harmless under a uniform prior).
    rng : numpy.random.Generator or int or None
    boundary_margin : float
        Starts this close to a basin boundary (radians) are counted as near-boundary.
    chunk : int
        Trials per vectorised batch (memory: about 40 bytes a trial).
    progress : callable, optional
        Called as ``progress(done, total)`` after each batch.

    Returns
    -------
    SimulationResult

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> plan = plan_exact(pb).bayes_plan
    >>> r = simulate_kinematic(pb, plan, 100_000, rng=0)
    >>> round(r.predicted_success, 4), abs(r.observed_success - 0.5) < 0.01, r.jams
    (0.5, True, 0)
    """
    _check_trials(trials)
    if chunk < 1:
        raise SimulationError(f"`chunk` must be >= 1; got {chunk}")
    for step in option.steps:
        if step.kind not in problem.transfers:
            raise SimulationError(
                f"the plan uses {step.kind!r} actions but the problem has only "
                f"{', '.join(problem.transfers)}"
            )
    noise = noise or GripperNoise()
    gen = np.random.default_rng(rng)
    transfers = [problem.transfers[s.kind] for s in option.steps]
    bounds = [f.boundaries for f in transfers]
    alphas = np.array([s.alpha for s in option.steps])
    jam_tol = 10.0 * problem.states.angle_tol
    finals: list[FloatArray] = []
    nears: list[BoolArray] = []
    jams: list[BoolArray] = []
    t0 = time.perf_counter()
    done = 0
    while done < trials:
        m = min(chunk, trials - done)
        theta = sample_prior(problem.prior, m, gen)  # (m,) world orientations
        near = np.zeros(m, dtype=bool)
        jam = np.zeros(m, dtype=bool)
        err = noise.draw((len(alphas), m), gen) if noise.scale > 0 else None
        for j, f in enumerate(transfers):
            theta = theta - alphas[j] if err is None else theta - (alphas[j] + err[j])
            if boundary_margin > 0:
                near |= boundary_distance(bounds[j], theta) < boundary_margin
            theta = f(theta)
            if j < len(transfers) - 1:
                jam |= boundary_distance(bounds[j], theta) <= f.angle_tol
        finals.append(theta)
        nears.append(near)
        jams.append(jam)
        done += m
        if progress is not None:
            progress(done, trials)
    seconds = time.perf_counter() - t0
    return summarize(
        "kinematic",
        problem,
        option,
        np.concatenate(finals),
        np.concatenate(jams),
        np.concatenate(nears),
        seconds,
        jam_tol,
        boundary_margin,
    )
