"""What every simulation of a plan returns: predicted against observed outcomes.

A plan's success probability is a statement about the initial orientations it sends to the
goal (design.md). A simulation executes the plan many times, on the model
(:func:`~bayesgrasp.sim.kinematic.simulate_kinematic`) or in a physics engine
(:func:`~bayesgrasp.sim.engine.simulate_mujoco`), and :func:`summarize` turns the trials
into one :class:`SimulationResult`: counts per final orientation, success rate with a
Wilson score interval, a chi-square goodness-of-fit p-value, jams (the part stopped away
from every stable orientation) and starts near a basin boundary (where a real part can jam
or go either way).

The prediction is exact, not sampled (:func:`predicted_distribution`): the first action
sends a whole basin to one stable orientation, so the final orientation is a function of
the first action's state. The predicted probability of a final orientation is the prior
mass of the basins whose stable orientation the remaining actions send there.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI, mod_2pi
from ..errors import SimulationError
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption, PlanStep, execute_plan
from .stats import goodness_of_fit, wilson_interval

__all__ = [
    "DEFAULT_BOUNDARY_MARGIN",
    "Progress",
    "SimulationResult",
    "boundary_distance",
    "check_steps",
    "check_trials",
    "combine",
    "predicted_distribution",
    "summarize",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
BoolArray = NDArray[np.bool_]
Progress = Callable[[int, int], None]
"""A progress callback: ``progress(done, total)``, trials done out of trials asked for."""

#: Starts closer than this to a basin boundary are counted as near-boundary (radians). The
#: physics check (``/work/shared/physics-notes.md``) saw jams only within about 2.3 degrees
#: of a boundary; 2.5 degrees covers that with a margin.
DEFAULT_BOUNDARY_MARGIN = math.radians(2.5)


def check_trials(trials: int) -> None:
    """Raise :class:`SimulationError` unless ``trials`` is an integer >= 1.

    Examples
    --------
    >>> check_trials(0)
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.SimulationError: `trials` must be an integer >= 1; got 0
    """
    if not isinstance(trials, int | np.integer) or trials < 1:
        raise SimulationError(f"`trials` must be an integer >= 1; got {trials!r}")


def check_steps(problem: Problem, steps: Sequence[PlanStep]) -> None:
    """Raise :class:`SimulationError` if a step's action has no transfer function in ``problem``.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> check_steps(pb, [PlanStep("push-grasp", 0.0)])
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.SimulationError: the plan uses 'push-grasp' actions but the problem has only squeeze
    """  # noqa: E501
    for step in steps:
        if step.kind not in problem.transfers:
            raise SimulationError(
                f"the plan uses {step.kind!r} actions but the problem has only "
                f"{', '.join(problem.transfers)}"
            )


def boundary_distance(boundaries: FloatArray, theta: ArrayLike) -> FloatArray:
    """Distance (radians, on the circle) from each angle to the nearest of ``boundaries``.

    Parameters
    ----------
    boundaries : ndarray of shape (B,)
        Angles in ``[0, 2 pi)``, increasing (e.g. ``TransferFunction.boundaries``).
    theta : array_like

    Returns
    -------
    ndarray of the shape of ``theta``

    Examples
    --------
    >>> round(float(boundary_distance(np.array([0.0, np.pi]), 6.2)), 6)
    0.083185
    """
    th = mod_2pi(theta)
    b = np.concatenate([boundaries[-1:] - TWO_PI, boundaries, boundaries[:1] + TWO_PI])
    k = np.searchsorted(b, th)  # b[k - 1] <= th < b[k]
    return np.asarray(np.minimum(b[k] - th, th - b[k - 1]), dtype=np.float64)


def predicted_distribution(problem: Problem, steps: Sequence[PlanStep]) -> FloatArray:
    """Exact probability of each final state (stable orientation) under the problem's prior.

    The first action sends each of its basins to one stable orientation (state ``i``, with
    the prior mass of the basin, :meth:`Problem.state_distribution`); the remaining actions
    are deterministic on states, so they push the masses forward.

    Parameters
    ----------
    problem : Problem
    steps : sequence of PlanStep
        At least one.

    Returns
    -------
    ndarray of shape (K,)
        Indexed like ``problem.states.stable``; sums to one.

    Raises
    ------
    SimulationError
        ``steps`` is empty.

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
    def fit_unavailable(self) -> str | None:
        """Why the goodness of fit says nothing, or ``None`` when it does.

        When most trials jam, the few that end in a stable orientation are not a sample of
        the plan's outcomes (the jams are not spread over the states as the prediction is),
        and a p-value of their fit would read as agreement. So it is not given.
        """
        unjammed = self.trials - self.final_jams
        if self.trials and 2 * self.jams > self.trials:
            return f"{self.jams} of {self.trials} trials jammed"
        if unjammed <= 0:
            return "no trial ended in a stable orientation"
        return None

    @property
    def p_value(self) -> float:
        """Chi-square p-value of the final states (jammed trials left out) against prediction.

        NaN when :attr:`fit_unavailable` gives a reason.
        """
        if self.fit_unavailable is not None:
            return math.nan
        return goodness_of_fit(self.observed, self.predicted)

    @property
    def executions_per_second(self) -> float:
        """Trials per second of wall time."""
        return self.trials / self.seconds if self.seconds > 0 else math.inf


def combine(results: Sequence[SimulationResult]) -> SimulationResult:
    """One result of several runs of the same plan on the same problem (counts added).

    What streaming the trials in blocks needs: memory stays that of one block. The
    per-trial arrays (``final``, ``jammed_trials``, ``near_trials``) are joined only when
    one run is given; a combined result has none (length 0).

    Raises
    ------
    SimulationError
        No results, or results of different plans or states.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    >>> one = summarize("kinematic", pb, opt, np.array([0.0, np.pi / 2]),
    ...                 np.zeros(2, bool), np.zeros(2, bool), 1.0, 1e-6)
    >>> both = combine([one, one])
    >>> both.trials, both.observed.tolist(), len(both.final)
    (4, [2, 2, 0, 0], 0)
    """
    if not results:
        raise SimulationError("`results` must hold at least one simulation result")
    first = results[0]
    if len(results) == 1:
        return first
    for r in results[1:]:
        same = r.option.steps == first.option.steps and r.engine == first.engine
        if not same or not np.array_equal(r.orientations, first.orientations):
            raise SimulationError("only results of one plan on one problem can be combined")
    empty = np.zeros(0, dtype=bool)
    return SimulationResult(
        engine=first.engine,
        option=first.option,
        trials=sum(r.trials for r in results),
        orientations=first.orientations,
        predicted=first.predicted,
        observed=np.sum([r.observed for r in results], axis=0).astype(np.intp),
        goal=first.goal,
        jams=sum(r.jams for r in results),
        final_jams=sum(r.final_jams for r in results),
        near_boundary=sum(r.near_boundary for r in results),
        boundary_margin=first.boundary_margin,
        seconds=sum(r.seconds for r in results),
        final=np.zeros(0, dtype=np.float64),
        jammed_trials=empty,
        near_trials=empty,
    )


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

    Returns
    -------
    SimulationResult
        Success is a final state of the problem's goal (:meth:`Problem.success_states`).

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
    final = mod_2pi(final)
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
        goal=problem.success_states(option.final_orientation),
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
