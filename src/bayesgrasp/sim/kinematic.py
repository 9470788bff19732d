"""Running a plan on orientations: the kinematic Monte Carlo check of a plan.

Draw initial orientations from the prior (:func:`sample_prior`), draw what the noise model
(:class:`~bayesgrasp.model.noise.NoiseModel`) says happens, run the plan through the
transfer functions exactly as :func:`~bayesgrasp.planning.result.execute_plan` does, and
compare the final orientations with the exact prediction under the same noise
(:class:`~bayesgrasp.sim.result.SimulationResult`).

The draws, trial by trial, are the model's (:mod:`bayesgrasp.model.noise`), and are its
independent check: every commanded angle (the first action's world angle and each turn
``alpha``) gets an independent turn error ``e``; each squeeze is, with probability ``q``
(the contact asynchrony), a push-grasp from the gripper's ``-x`` side or its ``+x`` side,
equally likely: ``g(theta)`` or ``g(theta - pi) + pi``, ``g`` the push-grasp function
(:func:`~bayesgrasp.geometry.push.push_grasp_function`). A push-grasp action pushes with one
jaw on purpose and is not affected.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..angles import TWO_PI, mod_2pi
from ..errors import SimulationError
from ..model.actions import SQUEEZE
from ..model.payoff import Payoff
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from ..model.problem import Problem
from ..planning.result import PlanOption, PlanStep
from .noise import AnyNoise, GripperNoise, as_generator, noise_model
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

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.transfer import TransferFunction

__all__ = [
    # Defined elsewhere in bayesgrasp.sim; listed so that today's imports from this module
    # keep working (cli/simulate.py, sweep/tasks.py, report.py, benchmarks). New code
    # imports them from bayesgrasp.sim.
    "GripperNoise",
    "SimulationResult",
    "boundary_distance",
    # Defined here.
    "contact_push",
    "run_trials",
    "sample_prior",
    "simulate_kinematic",
    "with_contacts",
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
    noise: AnyNoise = None,
    rng: np.random.Generator | int | None = None,
    boundary_margin: float = DEFAULT_BOUNDARY_MARGIN,
    chunk: int = 1 << 18,
    progress: Progress | None = None,
    payoff: Payoff | FloatArray | None = None,
) -> SimulationResult:
    """Execute a plan ``trials`` times on the model: the kinematic Monte Carlo.

    Each trial draws an initial world orientation from the problem's prior, draws the
    noise (see the module notes) and applies the transfer functions as
    :func:`~bayesgrasp.planning.result.execute_plan` does. Work is done in vectorised
    chunks. The prediction it is compared with is exact under the same noise
    (:func:`~bayesgrasp.sim.result.predicted_distribution`).

    Parameters
    ----------
    problem : Problem
    option : PlanOption
        The plan (its ``final_orientation`` is the goal).
    trials : int
    noise : NoiseModel or GripperNoise, optional
        Default: none. A :class:`~bayesgrasp.sim.noise.GripperNoise` is that turn error
        alone. A plan's ``tolerance`` bounds the turn error on ``alpha_2 .. alpha_k`` that
        keeps its noise-free success probability; an error on the first angle only moves
        the arc of successful starts (harmless under a uniform prior).
    rng : numpy.random.Generator or int or None
    boundary_margin : float
        Starts this close to a basin boundary (radians) are counted as near-boundary.
    chunk : int
        Trials per vectorised batch (memory: about 40 bytes a trial).
    progress : callable, optional
        Called as ``progress(done, total)`` after each batch.
    payoff : Payoff or array of shape (K,), optional
        Judge the plan by its expected payoff (the mean payoff of the final states) instead
        of its goal.

    Returns
    -------
    SimulationResult

    Raises
    ------
    SimulationError
        ``trials`` or ``chunk`` below 1, a step whose action the problem does not have, an
        ``rng`` that is not a generator, None or an integer seed >= 0, or a turn error the
        model cannot predict (:func:`~bayesgrasp.sim.noise.noise_model`).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> plan = plan_exact(pb).bayes_plan
    >>> r = simulate_kinematic(pb, plan, 100_000, rng=0)
    >>> round(r.predicted_success, 4), abs(r.observed_success - 0.5) < 0.01, r.jams
    (0.5, True, 0)

    The triangle's Bayes plan when one jaw touches first in 40% of the squeezes:

    >>> from bayesgrasp.model.noise import NoiseModel
    >>> from bayesgrasp.shapes import load
    >>> pb = Problem.build(load("triangle"))
    >>> plan = plan_exact(pb).bayes_plan
    >>> r = simulate_kinematic(pb, plan, 100_000, NoiseModel(contact=0.4), rng=0)
    >>> plan.success_probability, round(r.predicted_success, 4), r.observed_success, r.agrees
    (0.5, 0.349, 0.34942, True)
    """
    check_trials(trials)
    if chunk < 1:
        raise SimulationError(f"`chunk` must be >= 1; got {chunk}")
    check_steps(problem, option.steps)
    model = noise_model(noise)
    turn = noise if isinstance(noise, GripperNoise) else GripperNoise.of(model.turn)
    gen = as_generator(rng)
    push = contact_push(problem, model.contact)
    jam_tol = JAM_TOLERANCE_FACTOR * problem.states.angle_tol
    finals: list[FloatArray] = []
    nears: list[BoolArray] = []
    jams: list[BoolArray] = []
    t0 = time.perf_counter()
    done = 0
    while done < trials:
        m = min(chunk, trials - done)
        theta, near, jam = run_trials(problem, option.steps, turn, model.contact, m, gen,
                                      boundary_margin, push)  # fmt: skip
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
        noise=model,
        payoff=None if payoff is None else _vector(problem, payoff),
    )


def _vector(problem: Problem, payoff: Payoff | FloatArray) -> FloatArray:
    from ..model.payoff import as_vector

    return np.asarray(as_vector(payoff, problem.states), dtype=np.float64)


def contact_push(problem: Problem, contact: float) -> TransferFunction | None:
    """The push-grasp function a squeeze becomes when one jaw touches first (none if q = 0)."""
    if contact <= 0:
        return None
    from ..geometry.push import push_grasp_function

    return push_grasp_function(problem.part, problem.states)


def with_contacts(
    out: FloatArray, x: FloatArray, push: TransferFunction, event: FloatArray, contact: float
) -> FloatArray:
    """Squeeze outcomes ``out`` of parts at ``x`` (gripper frame), with the contact events drawn.

    With contact asynchrony ``q`` (``contact``) a squeeze is, with probability ``q / 2``
    each, the push-grasp from the ``-x`` side, ``push(x)``, or from the ``+x`` side,
    ``push(x - pi) + pi`` (:mod:`bayesgrasp.model.noise`); ``event`` holds one uniform draw a
    part. Returns a new array.
    """
    left = event < contact / 2
    right = (event >= contact / 2) & (event < contact)
    out = np.array(out, dtype=np.float64)
    if np.any(left):
        out[left] = push(x[left])
    if np.any(right):
        out[right] = push(x[right] - math.pi) + math.pi
    return out


def run_trials(
    problem: Problem,
    steps: Sequence[PlanStep],
    turn: GripperNoise,
    contact: float,
    m: int,
    gen: np.random.Generator,
    boundary_margin: float = 0.0,
    push: TransferFunction | None = None,
) -> tuple[FloatArray, BoolArray, BoolArray]:
    """``m`` trials of a plan: final orientations, near-boundary starts, jams.

    The draws, in order: the initial orientations, the turn errors (one per action and
    trial, none when there is no turn error), the contact events (one per action and trial,
    none without contact asynchrony); so a run without contact noise draws what it always
    drew. ``push``: :func:`contact_push` (made here when not given).
    """
    transfers = [problem.transfer(s.kind) for s in steps]
    alphas = np.array([s.alpha for s in steps])
    theta = sample_prior(problem.prior, m, gen)  # (m,) world orientations
    near = np.zeros(m, dtype=bool)
    jam = np.zeros(m, dtype=bool)
    err = turn.draw((len(alphas), m), gen) if turn.scale > 0 else None
    event = gen.random((len(alphas), m)) if contact > 0 else None
    if event is not None and push is None:
        push = contact_push(problem, contact)
    for j, f in enumerate(transfers):
        theta = theta - alphas[j] if err is None else theta - (alphas[j] + err[j])
        if boundary_margin > 0:
            near |= boundary_distance(f.boundaries, theta) < boundary_margin
        out = f(theta)
        if push is not None and event is not None and steps[j].kind == SQUEEZE.name:
            out = with_contacts(out, theta, push, event[j], contact)
        theta = out
        if j < len(transfers) - 1:
            jam |= boundary_distance(f.boundaries, theta) <= f.angle_tol
    return theta, near, jam
