"""Kinematic Monte Carlo of a plan under a noise model (turn error and contact asynchrony).

The independent check of :mod:`bayesgrasp.model.noise`: instead of transition matrices it
draws what the model says happens, trial by trial, and runs the transfer functions on
orientations. Each trial draws the initial world orientation from the prior; every commanded
angle gets an error drawn from the turn noise (as
:func:`~bayesgrasp.sim.kinematic.simulate_kinematic` does); each squeeze is, with probability
``q``, a push-grasp from the ``-x`` or the ``+x`` side (equally likely): ``g(theta)`` or
``g(theta - pi) + pi``, ``g`` the push-grasp function.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import SimulationError
from ..geometry.push import push_grasp_function
from ..model.actions import SQUEEZE
from ..model.noise import NoiseModel
from ..model.problem import Problem
from ..model.states import nearest_state
from ..planning.result import PlanStep
from .kinematic import sample_prior
from .noise import GripperNoise, as_generator
from .result import check_steps, check_trials

__all__ = ["simulate_noise"]


def simulate_noise(
    problem: Problem,
    noise: NoiseModel,
    steps: Sequence[PlanStep],
    trials: int,
    rng: np.random.Generator | int | None = None,
    chunk: int = 1 << 17,
) -> NDArray[np.intp]:
    """Run a plan ``trials`` times with the noise drawn; count the final states.

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel
    steps : sequence of PlanStep
    trials : int
    rng : numpy.random.Generator or int or None
    chunk : int
        Trials per vectorised batch.

    Returns
    -------
    ndarray of shape (K,)
        How many trials ended in each state (frame of the last action).

    Raises
    ------
    SimulationError
        ``trials`` below 1 or a step whose action the problem does not have.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> counts = simulate_noise(pb, NoiseModel(contact=0.5), [PlanStep("squeeze", 0.0)], 1000, 0)
    >>> int(counts.sum())
    1000
    """
    check_trials(trials)
    check_steps(problem, steps)
    gen = as_generator(rng)
    turn = GripperNoise(noise.turn.kind, noise.turn.scale)
    q = noise.contact
    push = push_grasp_function(problem.part, problem.states) if q > 0 else None
    counts = np.zeros(problem.n_states, dtype=np.intp)
    done = 0
    while done < trials:
        m = min(chunk, trials - done)
        theta = sample_prior(problem.prior, m, gen)
        for step in steps:
            f = problem.transfer(step.kind)
            x = theta - (step.alpha + turn.draw((m,), gen))
            out = f(x)
            if push is not None and step.kind == SQUEEZE.name:
                event = gen.random(m)
                left = event < q / 2
                right = (event >= q / 2) & (event < q)
                out = np.where(left, push(x), out)
                out = np.where(right, push(x - math.pi) + math.pi, out)
            theta = np.mod(out, TWO_PI)
        counts += np.bincount(nearest_state(problem.states, theta), minlength=problem.n_states)
        done += m
    if int(counts.sum()) != trials:  # pragma: no cover - a bug
        raise SimulationError("internal error: trials lost")
    return counts
