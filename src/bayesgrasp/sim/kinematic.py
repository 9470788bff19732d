"""Running a plan on orientations: the kinematic Monte Carlo check of a plan.

Draw initial orientations from the prior (:func:`sample_prior`), optionally perturb every
commanded gripper angle (:class:`~bayesgrasp.sim.noise.GripperNoise`), run the plan through
the transfer functions exactly as :func:`~bayesgrasp.planning.result.execute_plan` does, and
compare the final orientations with the exact prediction
(:class:`~bayesgrasp.sim.result.SimulationResult`).
"""

from __future__ import annotations

import time

import numpy as np

from ..angles import TWO_PI, mod_2pi
from ..errors import SimulationError
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from ..model.problem import Problem
from ..planning.result import PlanOption
from .noise import GripperNoise, as_generator
from .result import (
    DEFAULT_BOUNDARY_MARGIN,
    BoolArray,
    FloatArray,
    Progress,
    SimulationResult,
    boundary_distance,
    check_steps,
    check_trials,
    summarize,
)

__all__ = [
    # Defined elsewhere in bayesgrasp.sim; listed so that today's imports from this module
    # keep working (cli/simulate.py, sweep/tasks.py, report.py, benchmarks). New code
    # imports them from bayesgrasp.sim.
    "GripperNoise",
    "SimulationResult",
    "boundary_distance",
    # Defined here.
    "sample_prior",
    "simulate_kinematic",
]

#: A kinematic trial jams when an action ends farther than this many times the states'
#: angle tolerance from every stable orientation (only a start on a basin boundary can).
JAM_TOLERANCE_FACTOR = 10.0


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

    Raises
    ------
    SimulationError
        ``n`` is negative, or ``rng`` is not a generator, None or an integer seed >= 0.

    Examples
    --------
    >>> x = sample_prior(HistogramPrior([1, 0, 0, 0]), 1000, rng=1)
    >>> bool(np.all((x >= 0) & (x < np.pi / 2)))
    True
    """
    if n < 0:
        raise SimulationError(f"`n` must be >= 0; got {n}")
    gen = as_generator(rng)
    own = getattr(prior, "sample", None)
    if callable(own):
        return mod_2pi(own(n, gen))
    if isinstance(prior, UniformPrior):
        return gen.uniform(0.0, TWO_PI, n)
    if isinstance(prior, SamplePrior):
        return np.asarray(gen.choice(prior.angles, size=n), dtype=np.float64)
    if isinstance(prior, HistogramPrior):
        nodes = np.append(prior.breakpoints, TWO_PI)
    else:  # unknown form: a fine table (a 65536th of a turn) plus the prior's breakpoints
        nodes = np.union1d(np.linspace(0.0, TWO_PI, 65537), mod_2pi(prior.breakpoints))
    cum = prior.cdf(nodes) - prior.cdf(0.0)
    u = gen.random(n)
    return mod_2pi(np.interp(u, cum, nodes))


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

    Raises
    ------
    SimulationError
        ``trials`` or ``chunk`` below 1, a step whose action the problem does not have, or
        an ``rng`` that is not a generator, None or an integer seed >= 0.

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
    check_trials(trials)
    if chunk < 1:
        raise SimulationError(f"`chunk` must be >= 1; got {chunk}")
    check_steps(problem, option.steps)
    noise = noise or GripperNoise()
    gen = as_generator(rng)
    transfers = [problem.transfer(s.kind) for s in option.steps]
    bounds = [f.boundaries for f in transfers]
    alphas = np.array([s.alpha for s in option.steps])
    jam_tol = JAM_TOLERANCE_FACTOR * problem.states.angle_tol
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
