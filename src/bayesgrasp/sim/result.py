"""What every simulation of a plan returns: predicted against observed outcomes.

A plan's success probability is a statement about the initial orientations it sends to the
goal (design.md). A simulation executes the plan many times, on the model
(:func:`~bayesgrasp.sim.kinematic.simulate_kinematic`) or in a physics engine
(:func:`~bayesgrasp.sim.engine.simulate_mujoco`), and :func:`summarize` turns the trials
into one :class:`SimulationResult`: counts per final orientation, success rate with a
Wilson score interval, a chi-square goodness-of-fit p-value, jams (the part stopped away
from every stable orientation) and starts near a basin boundary (where a real part can jam
or go either way).

The prediction is exact, not sampled (:func:`predicted_distribution`). With exact actions
the first action sends a whole basin to one stable orientation, so the final orientation is
a function of the first action's state: the predicted probability of a final orientation
is the prior mass of the basins whose stable orientation the remaining actions send there.
Under a noise model (turn error, contact asynchrony; :mod:`bayesgrasp.model.noise`) it is
the plan's exact evaluation through the noisy transition matrices
(:func:`~bayesgrasp.planning.noisy.evaluate_plan`), the same numbers the noise-aware
planner reports.

The verdict (:attr:`SimulationResult.agrees`; :mod:`~bayesgrasp.sim.verdict` prints it):
the predicted success probability lies in the Wilson interval of the observed rate at
``z = 4`` (:data:`~bayesgrasp.sim.verdict.VERDICT_Z`), and with a payoff the predicted
expected payoff lies in the ``z = 4`` interval of the mean payoff of the final states (the
central limit theorem: payoffs are bounded, the trials many). At ``z = 4`` a correct
prediction is called wrong once in about 16,000 runs; the 95% intervals are reported beside.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI, mod_2pi
from ..errors import SimulationError
from ..model.cost import CostModel
from ..model.noise import NoiseModel
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption, PlanStep, execute_plan
from .stats import goodness_of_fit, wilson_interval
from .verdict import VERDICT_Z, confidence, verdict_document, verdict_lines

__all__ = [
    "DEFAULT_BOUNDARY_MARGIN",
    "PHYSICS_FIT",
    "VERDICT_Z",
    "Progress",
    "SimulationResult",
    "boundary_distance",
    "check_steps",
    "check_trials",
    "combine",
    "predicted_distribution",
    "summarize",
    "verdict_document",
    "verdict_lines",
    "with_prediction",
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

_Z95 = 1.959963984540054  # the normal quantile of a two-sided 95% interval

PHYSICS_FIT = "physics: the success test below counts every trial"
"""Why a physics run has no chi-square over final states (``fit_unavailable``)."""


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


def predicted_distribution(
    problem: Problem, steps: Sequence[PlanStep], noise: NoiseModel | None = None
) -> FloatArray:
    """Exact probability of each final state (stable orientation) under the problem's prior.

    With exact actions the first action sends each of its basins to one stable orientation
    (state ``i``, with the prior mass of the basin, :meth:`Problem.state_distribution`); the
    remaining actions are deterministic on states, so they push the masses forward. Under a
    noise model the distribution is the plan's exact evaluation through the noisy transition
    matrices (:func:`~bayesgrasp.planning.noisy.evaluate_plan`).

    Parameters
    ----------
    problem : Problem
    steps : sequence of PlanStep
        At least one.
    noise : NoiseModel, optional
        Default: exact actions.

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
    if noise is not None and not noise.exact:
        from ..planning.noisy import evaluate_plan

        return np.asarray(evaluate_plan(problem, noise, steps).distribution, dtype=np.float64)
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
    noise : NoiseModel
        The noise the trials drew and the prediction is exact under (default: none).
    payoff : ndarray of shape (K,) or None
        The payoff of each state when the plan is judged by its expected payoff (then
        ``goal`` is the states of positive payoff); ``None`` for a goal.
    cost : CostModel or None
        The problem's cost model (for the cost per unit payoff).
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
    noise: NoiseModel = field(default_factory=NoiseModel)
    payoff: FloatArray | None = field(repr=False, default=None)
    cost: CostModel | None = field(repr=False, default=None)

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
    def success_interval(self) -> tuple[float, float]:
        """Wilson score interval of the success rate at ``z =`` :data:`VERDICT_Z`."""
        return wilson_interval(self.successes, self.trials, confidence(VERDICT_Z))

    @property
    def predicted_payoff(self) -> float:
        """Exact expected payoff (NaN without a payoff)."""
        if self.payoff is None:
            return math.nan
        return float(self.predicted @ self.payoff)

    @property
    def observed_payoff(self) -> float:
        """Mean payoff of the final states (a jammed trial earns 0; NaN without a payoff)."""
        if self.payoff is None or not self.trials:
            return math.nan
        return float(self.observed @ self.payoff) / self.trials

    def payoff_interval(self, z: float = _Z95) -> tuple[float, float]:
        """Interval of the mean payoff: the Wilson score interval of a mean in [0, 1].

        A payoff in [0, 1] of mean ``m`` has variance at most ``m (1 - m)`` (Bhatia and
        Davis 2000), the variance of a 0/1 payoff of that mean, so the score interval of a
        proportion covers the mean payoff at least as often as it says; for a 0/1 payoff it
        is the success interval. ``(nan, nan)`` without a payoff.
        """
        if self.payoff is None:
            return (math.nan, math.nan)
        m = min(max(self.observed_payoff, 0.0), 1.0)
        lo, hi = wilson_interval(m * self.trials, self.trials, confidence(z))
        return min(lo, m), max(hi, m)  # rounding at a mean of 0 or 1

    def cost_per_unit_payoff(self) -> tuple[float, float, float, float]:
        """Predicted and observed cost per unit payoff, and the observed one's 95% interval.

        ``E[cycle cost] / E[payoff]`` (:meth:`~bayesgrasp.model.cost.CostModel.expected_cost`
        with the payoff in place of the success probability); it falls as the payoff rises,
        so the interval's ends are the costs at the payoff interval's ends. NaN without a
        payoff; inf where the payoff is 0.
        """
        if self.payoff is None or self.cost is None:
            return (math.nan,) * 4
        kinds = self.option.kinds
        lo, hi = self.payoff_interval()
        pred = self.cost.expected_cost(kinds, self.predicted_payoff)
        obs = self.cost.expected_cost(kinds, self.observed_payoff)
        return pred, obs, self.cost.expected_cost(kinds, hi), self.cost.expected_cost(kinds, lo)

    @property
    def agrees(self) -> bool:
        """Whether the prediction lies in the observed intervals at ``z =`` :data:`VERDICT_Z`.

        The predicted success probability in the Wilson interval of the observed rate and,
        with a payoff, the predicted expected payoff in the interval of the mean payoff.
        """
        checks = [(self.predicted_success, self.success_interval)]
        if self.payoff is not None:
            checks.append((self.predicted_payoff, self.payoff_interval(VERDICT_Z)))
        slack = 1e-9
        return all(lo - slack <= v <= hi + slack for v, (lo, hi) in checks)

    @property
    def fit_unavailable(self) -> str | None:
        """Why the goodness of fit says nothing, or ``None`` when it does.

        When most trials jam, the few that end in a stable orientation are not a sample of
        the plan's outcomes (the jams are not spread over the states as the prediction is),
        and a p-value of their fit would read as agreement. So it is not given. Nor for a
        physics engine (:data:`PHYSICS_FIT`): its outcomes include jams, which the states'
        chi-square leaves out (a plan whose part jams in one trial of five looked fine),
        and starts near a basin boundary that go the other way, into a state the model
        calls impossible (a chi-square of 0 for a plan whose success matched); its test is
        :attr:`success_p_value`, every trial counted.
        """
        unjammed = self.trials - self.final_jams
        if self.trials and 2 * self.jams > self.trials:
            return f"{self.jams} of {self.trials} trials jammed"
        if self.engine != "kinematic":
            return PHYSICS_FIT
        if unjammed <= 0:
            return "no trial ended in a stable orientation"
        return None

    @property
    def p_value(self) -> float:
        """Chi-square p-value of the final states (jammed trials left out) against prediction.

        NaN when :attr:`fit_unavailable` gives a reason: always for a physics engine, whose
        test is :attr:`success_p_value`.
        """
        if self.fit_unavailable is not None:
            return math.nan
        return goodness_of_fit(self.observed, self.predicted)

    @property
    def success_p_value(self) -> float:
        """Exact two-sided binomial p-value of the successes, every trial counted.

        A jammed trial did not reach the goal: it is a failure. The test asks whether
        ``successes`` of ``trials`` is a likely count when each trial succeeds with the
        predicted probability.

        Examples
        --------
        >>> from bayesgrasp.geometry.polygon import Part
        >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
        >>> opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
        >>> r = summarize("mujoco", pb, opt, np.zeros(10), np.zeros(10, bool),
        ...               np.zeros(10, bool), 1.0, 1e-6)
        >>> round(r.predicted_success, 3), r.successes, round(r.success_p_value, 4)
        (0.148, 10, 0.0)
        """
        if not self.trials:
            return math.nan
        from scipy.stats import binomtest

        p = min(max(self.predicted_success, 0.0), 1.0)
        return float(binomtest(self.successes, self.trials, p).pvalue)

    @property
    def prediction_interval(self) -> tuple[float, float]:
        """Where 95% of observed success rates fall if the prediction is right.

        The central 95% of the binomial distribution of ``trials`` trials at the predicted
        success probability, as rates (exact quantiles).
        """
        from scipy.stats import binom

        p = min(max(self.predicted_success, 0.0), 1.0)
        lo, hi = binom.ppf([0.025, 0.975], self.trials, p)
        return float(lo) / self.trials, float(hi) / self.trials

    @property
    def assumption_flags(self) -> list[str]:
        """Why the squeeze model's assumptions break in these trials (physics only).

        The model assumes every action ends in a stable orientation of the width function
        and that a start's basin decides it. Flagged: more than 2% of trials jammed (the
        part stopped away from every stable orientation: jaw force against table
        friction where the turning couple vanishes, at shallow minima or near maxima of
        the width), and, when the observed success strays from the prediction (outside the
        observed 95% interval, or :attr:`success_p_value` below 0.1), more
        than 10% of trials starting an action within ``boundary_margin`` of a basin
        boundary (a tight plan: there the outcome is a coin toss in physics; a plan whose
        states land on boundaries by design, as push-grasps' can, and still succeed is not
        flagged). Empty for the kinematic engine, which is the model.
        """
        if self.engine == "kinematic" or not self.trials:
            return []
        out = []
        if self.jams > 0.02 * self.trials:
            out.append(
                f"{self.jams} of {self.trials} trials jammed (stopped away from every stable "
                "orientation: jaw force against table friction)"
            )
        lo, hi = self.ci95
        missed = not lo - 1e-9 <= self.predicted_success <= hi + 1e-9
        missed = missed or self.success_p_value < 0.1
        if missed and self.near_boundary > 0.1 * self.trials:
            out.append(
                f"{self.near_boundary} of {self.trials} trials started an action within "
                f"{math.degrees(self.boundary_margin):g} deg of a basin boundary "
                "(a tight plan: there physics may go either way)"
            )
        return out

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
        same = same and r.noise == first.noise and _same_payoff(r.payoff, first.payoff)
        if not same or not np.array_equal(r.orientations, first.orientations):
            raise SimulationError(
                "only results of one plan on one problem, noise and payoff can be combined"
            )
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
        noise=first.noise,
        payoff=first.payoff,
        cost=first.cost,
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
    noise: NoiseModel | None = None,
    payoff: FloatArray | None = None,
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
    noise : NoiseModel, optional
        The noise the trials drew: the prediction is exact under it (default: none).
    payoff : ndarray of shape (K,), optional
        Judge the plan by its expected payoff (success: a state of positive payoff).

    Returns
    -------
    SimulationResult
        Success is a final state of the problem's goal (:meth:`Problem.success_states`),
        or of positive payoff.

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
    model = noise if noise is not None else NoiseModel()
    u = _payoff_vector(problem, payoff)
    return SimulationResult(
        engine=engine,
        option=option,
        trials=len(final),
        orientations=states.stable,
        predicted=predicted_distribution(problem, option.steps, model),
        observed=observed,
        goal=_goal(problem, option, u),
        jams=int(np.count_nonzero(jam_all)),
        final_jams=int(np.count_nonzero(final_jam)),
        near_boundary=int(np.count_nonzero(near_all)),
        boundary_margin=boundary_margin,
        seconds=seconds,
        final=final,
        jammed_trials=jam_all,
        near_trials=near_all,
        noise=model,
        payoff=u,
        cost=problem.cost,
    )


def with_prediction(
    result: SimulationResult,
    problem: Problem,
    noise: NoiseModel | None = None,
    payoff: FloatArray | None = None,
) -> SimulationResult:
    """The result predicted exactly under ``noise`` and judged by ``payoff``.

    For a simulation that drew the noise itself (MuJoCo with the turn error) but summarised
    against the noise-free prediction.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> from bayesgrasp.planning import plan_exact
    >>> from bayesgrasp.sim.kinematic import simulate_kinematic
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> r = simulate_kinematic(pb, plan_exact(pb).bayes_plan, 1000, rng=0)
    >>> noisy = with_prediction(r, pb, NoiseModel(TurnNoise("normal", 0.3)))
    >>> round(r.predicted_success, 4), round(noisy.predicted_success, 4)
    (0.5, 0.3803)
    """
    import dataclasses

    model = noise if noise is not None else NoiseModel()
    u = _payoff_vector(problem, payoff)
    return dataclasses.replace(
        result,
        predicted=predicted_distribution(problem, result.option.steps, model),
        goal=_goal(problem, result.option, u),
        noise=model,
        payoff=u,
        cost=problem.cost,
    )


def _same_payoff(a: FloatArray | None, b: FloatArray | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return bool(np.array_equal(a, b))


def _payoff_vector(problem: Problem, payoff: object) -> FloatArray | None:
    """A payoff (a :class:`~bayesgrasp.model.payoff.Payoff` or K values) as a vector."""
    if payoff is None:
        return None
    from ..model.payoff import as_vector

    return np.asarray(as_vector(payoff, problem.states), dtype=np.float64)  # type: ignore[arg-type]


def _goal(problem: Problem, option: PlanOption, payoff: FloatArray | None) -> BoolArray:
    """The states that count as success: the plan's goal, or those of positive payoff."""
    if payoff is not None:
        return np.asarray(payoff > 0, dtype=bool)
    return np.asarray(problem.success_states(option.final_orientation), dtype=bool)


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
