"""Final-state counts of a plan under a noise model (turn error and contact asynchrony).

The independent check of :mod:`bayesgrasp.model.noise`: instead of transition matrices it
draws what the model says happens, trial by trial, and runs the transfer functions on
orientations; the draws are :func:`~bayesgrasp.sim.kinematic.simulate_kinematic`'s (its
module notes say what they are). :func:`simulate_noise` returns only the counts of the
final states, for a plan given as steps (no goal, no jams: each trial ends in its nearest
state).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..errors import SimulationError
from ..model.noise import NoiseModel
from ..model.problem import Problem
from ..model.states import nearest_state
from ..planning.result import PlanStep
from .kinematic import contact_push, run_trials
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
    turn = GripperNoise.of(noise.turn)
    push = contact_push(problem, noise.contact)
    counts = np.zeros(problem.n_states, dtype=np.intp)
    done = 0
    while done < trials:
        m = min(chunk, trials - done)
        theta, _, _ = run_trials(problem, steps, turn, noise.contact, m, gen, push=push)
        counts += np.bincount(nearest_state(problem.states, theta), minlength=problem.n_states)
        done += m
    if int(counts.sum()) != trials:  # pragma: no cover - a bug
        raise SimulationError("internal error: trials lost")
    return counts
