"""Executing plans in MuJoCo: the physics engine as an independent judge of the model.

The engine knows nothing of diameter or transfer functions: it gets the part's hull, a table
with friction, two frictionless jaws and a yaw to start from, and reports the yaw where the
part stops. The library then compares those yaws with the model's stable orientations
(:func:`bayesgrasp.sim.result.summarize`).

One action, in the gripper frame (which is the world frame of the scene):

1. *Turn and place.* Turning the gripper by ``alpha`` about the part while the jaws are
   open is a rigid motion that touches nothing, so the scene instead sets the part's yaw to
   ``yaw - alpha`` (zero velocity). The part is placed so that its x-extent is centred
   between the jaws (the model's assumption that both jaws touch together), shifted by the
   trial's ``offset`` along x; the jaws start ``clearance`` outside it.
2. *Squeeze.* Both jaw targets close at ``jaw_speed``; the force-limited position actuators
   push the part until both jaws are slower than ``settle_speed`` for ``settle_time``.
   An action that pushes first (:attr:`~bayesgrasp.model.actions.Action.pushes_first`, the
   push-grasp) closes the -x jaw first: it pushes the part ``push_distance`` beyond first
   contact, then the +x jaw closes.
3. *Read and open.* The part's yaw is read from the free joint's quaternion; opening the
   jaws is the next action's placement.

:func:`simulate_mujoco` runs a plan's trials in batches, an action at a time, through
MuJoCo's C rollout threads (:mod:`bayesgrasp.sim.rollout`), each trial stopped when jaws and
part have settled; ``method="stepped"`` runs them one at a time from Python
(:class:`Squeezer`, in processes when ``workers > 1``). Every random draw (initial
orientations, gripper errors, offset signs) is made up front from one seed, so results do
not depend on the number of workers or threads.
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, circle_distance
from ..errors import SimulationError
from ..geometry.polygon import Part
from ..model.actions import get_action
from ..model.problem import Problem
from ..planning.result import PlanOption
from .kinematic import sample_prior
from .noise import GripperNoise, as_generator
from .params import SimParams
from .result import (
    DEFAULT_BOUNDARY_MARGIN,
    Progress,
    SimulationResult,
    boundary_distance,
    check_steps,
    check_trials,
    summarize,
)
from .rollout import BatchSqueezer
from .scene import units_scale
from .squeezer import SIZE_RANGE, ActionOutcome, Squeezer, require_mujoco

__all__ = ["SIZE_RANGE", "ActionOutcome", "Squeezer", "require_mujoco", "simulate_mujoco"]

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]

# --- parallel trials ---------------------------------------------------------------------

_WORKER: Squeezer | None = None


_STABLE: FloatArray | None = None


def _init_worker(
    part: Part, scale: float, params: SimParams, stable: FloatArray | None = None
) -> None:
    global _WORKER, _STABLE
    _WORKER = Squeezer(part, scale, params)
    _STABLE = stable


@dataclass(frozen=True, slots=True)
class _Trial:
    theta0: float  # initial world orientation
    angles: tuple[float, ...]  # commanded (perturbed) angle of each action
    offsets: tuple[float, ...]  # signed offset of each action (metres)
    pushes: tuple[bool, ...]
    leads: tuple[int | None, ...] = ()  # leading jaw of each lagged squeeze (jaw_lag > 0)


def _run_trial(trial: _Trial) -> list[ActionOutcome]:
    sq = _WORKER
    if sq is None:  # pragma: no cover - the pool initialiser always runs first
        raise RuntimeError("worker not initialised")
    yaw = trial.theta0
    out = []
    leads = trial.leads or (None,) * len(trial.angles)
    steps = zip(trial.angles, trial.offsets, trial.pushes, leads, strict=True)
    for angle, off, push, lead in steps:
        res = sq.act(float(np.mod(yaw - angle, TWO_PI)), off, push, lead, _STABLE)
        out.append(res)
        yaw = res.end
    return out


def _map_trials(
    part: Part,
    scale: float,
    params: SimParams,
    trials: Sequence[_Trial],
    workers: int,
    stable: FloatArray | None = None,
) -> Iterator[list[ActionOutcome]]:
    if workers <= 1:
        _init_worker(part, scale, params, stable)
        for t in trials:
            yield _run_trial(t)
        return
    # fork where the platform has it: workers start at once and the caller's script needs
    # no `if __name__ == "__main__"` guard (spawn re-imports it); spawn elsewhere.
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    chunk = max(1, min(8, len(trials) // (4 * workers)))
    with ctx.Pool(
        workers, initializer=_init_worker, initargs=(part, scale, params, stable)
    ) as pool:
        yield from pool.imap(_run_trial, trials, chunksize=chunk)


#: Trials a rollout batch: progress is reported after each, and memory stays small.
ROLLOUT_BATCH = 2048


def _rollout_trials(
    part: Part,
    scale: float,
    params: SimParams,
    trials: Sequence[_Trial],
    nthread: int,
    progress: Progress | None,
    stable: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """Start yaw, end yaw and settled flag of every action of every trial, shape (T, k).

    ``stable``: the part's stable orientations; jammed actions are retried with slow jaws
    (:meth:`~bayesgrasp.sim.rollout.BatchSqueezer.act`).
    """
    n, k = len(trials), len(trials[0].angles)
    starts, ends = np.zeros((n, k)), np.zeros((n, k))
    settled = np.zeros((n, k), dtype=bool)
    with BatchSqueezer(part, scale, params, nthread) as bs:
        for lo in range(0, n, ROLLOUT_BATCH):
            batch = trials[lo : lo + ROLLOUT_BATCH]
            yaw = np.array([t.theta0 for t in batch])
            for j in range(k):
                ang = np.array([t.angles[j] for t in batch])
                off = np.array([t.offsets[j] for t in batch])
                lead = np.array([t.leads[j] for t in batch]) if batch[0].leads else None
                res = bs.act(np.mod(yaw - ang, TWO_PI), off, batch[0].pushes[j], lead, stable)
                starts[lo : lo + len(batch), j] = res.start
                ends[lo : lo + len(batch), j] = res.end
                settled[lo : lo + len(batch), j] = res.settled
                yaw = res.end
            if progress is not None:
                progress(lo + len(batch), n)
    return starts, ends, settled


def simulate_mujoco(
    problem: Problem,
    option: PlanOption,
    trials: int,
    params: SimParams | None = None,
    offset: float = 0.0,
    noise: GripperNoise | None = None,
    rng: np.random.Generator | int | None = None,
    workers: int = 1,
    scale: float | None = None,
    boundary_margin: float = DEFAULT_BOUNDARY_MARGIN,
    progress: Progress | None = None,
    method: str = "rollout",
) -> SimulationResult:
    """Execute a plan ``trials`` times in MuJoCo and compare with the model.

    Parameters
    ----------
    problem : Problem
        Part, prior (initial orientations are drawn from it) and transfer functions.
    option : PlanOption
        The plan; its ``final_orientation`` is the goal.
    trials : int
    params : SimParams, optional
    offset : float
        Distance (metres) of the part's x-extent centre from the gripper centre at each
        action, on a random side (+x or -x, drawn per action). 0: both jaws touch together.
    noise : GripperNoise, optional
        Error added to every commanded gripper angle.
    rng : numpy.random.Generator or int or None
    workers : int
        ``rollout``: C threads of MuJoCo's rollout; ``stepped``: processes (1: run here).
        The results do not depend on it.
    scale : float, optional
        Metres per unit of the part's coordinates; default from ``part.units`` (metres when
        the part gives none).
    boundary_margin : float
        Actions starting this close (radians) to a basin boundary count as near-boundary.
    progress : callable, optional
        ``progress(done, total)`` after each trial (``stepped``) or batch of trials.
    method : {"rollout", "stepped"}
        ``rollout`` (default): every action of a batch of trials in one call of
        :func:`mujoco.rollout.rollout`, stopped when each has settled
        (:class:`~bayesgrasp.sim.rollout.BatchSqueezer`); ``stepped``: one trial at a time
        from Python (:class:`Squeezer`). Both run the same scene and settled test, and both
        run a jammed action again with the jaws at ``params.retry_speed``
        (:func:`~bayesgrasp.sim.squeezer.retry_params`).

    Returns
    -------
    SimulationResult
        With ``engine="mujoco"``; a trial is jammed when some action stopped more than
        ``params.jam_tol`` from every stable orientation or did not settle.

    Raises
    ------
    MissingExtraError
        MuJoCo is not installed (extra ``sim``).
    SimulationError
        Bad ``trials``, ``workers`` or ``offset``, a step whose action the problem does not
        have, or a part too small or too large for the physics settings.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (0.04, 0), (0.01, 0.03)]))
    >>> plan = plan_exact(pb).options[0]
    >>> r = simulate_mujoco(pb, plan, 5, rng=0)
    >>> r.trials, r.engine
    (5, 'mujoco')
    """
    require_mujoco()
    check_trials(trials)
    if method not in ("rollout", "stepped"):
        raise SimulationError(f"`method` must be rollout or stepped; got {method!r}")
    if not isinstance(workers, int | np.integer) or workers < 1:
        raise SimulationError(f"`workers` must be an integer >= 1; got {workers!r}")
    if not (math.isfinite(offset) and offset >= 0):
        raise SimulationError(f"`offset` must be a finite distance >= 0 (metres); got {offset!r}")
    check_steps(problem, option.steps)
    params = params or SimParams()
    noise = noise or GripperNoise()
    sc = units_scale(problem.part.units) if scale is None else scale
    across = 2.0 * problem.part.hull.size * sc
    if not SIZE_RANGE[0] <= across <= SIZE_RANGE[1]:
        raise SimulationError(
            f"the part measures {across:.3g} m across at {sc:g} m per unit; the physics "
            f"settings suit parts of {SIZE_RANGE[0] * 1000:g} mm to {SIZE_RANGE[1] * 100:g} cm: "
            "give the part's units (the part file's \"units\", or --units)"
        )
    gen = as_generator(rng)
    k = option.n_actions
    theta0 = sample_prior(problem.prior, trials, gen)
    alphas = np.array([s.alpha for s in option.steps])
    angles = alphas[None, :] + noise.draw((trials, k), gen)  # (T, k)
    signs = np.where(gen.random((trials, k)) < 0.5, -1.0, 1.0)
    pushes = tuple(get_action(s.kind).pushes_first for s in option.steps)
    tasks = [
        _Trial(float(theta0[i]), tuple(angles[i].tolist()), tuple((offset * signs[i]).tolist()),
               pushes)
        for i in range(trials)
    ]  # fmt: skip
    if params.jaw_lag > 0 and params.lead_jaw == "random":  # drawn here: workers don't matter
        leads = np.where(gen.random((trials, k)) < 0.5, -1, 1)
        tasks = [replace(t, leads=tuple(leads[i].tolist())) for i, t in enumerate(tasks)]
    t0 = time.perf_counter()
    if method == "stepped":
        outcomes: list[list[ActionOutcome]] = []
        for res in _map_trials(problem.part, sc, params, tasks, workers, problem.states.stable):
            outcomes.append(res)
            if progress is not None:
                progress(len(outcomes), trials)
        starts = np.array([[a.start for a in r] for r in outcomes])  # (T, k)
        ends = np.array([[a.end for a in r] for r in outcomes])  # (T, k)
        settled = np.array([[a.settled for a in r] for r in outcomes])  # (T, k)
    else:
        starts, ends, settled = _rollout_trials(
            problem.part, sc, params, tasks, workers, progress, problem.states.stable
        )
    seconds = time.perf_counter() - t0
    states = problem.states
    near = np.zeros(trials, dtype=bool)
    jammed: NDArray[np.bool_] = np.asarray(~settled.all(axis=1), dtype=bool)
    for j, step in enumerate(option.steps):
        near |= boundary_distance(problem.transfer(step.kind).boundaries, starts[:, j]) < (
            boundary_margin
        )
        err = circle_distance(ends[:, j, None], states.stable)  # (T, K)
        jammed |= err.min(axis=1) > params.jam_tol
    final = np.where(settled[:, -1], ends[:, -1], np.nan)
    # A last action that did not settle is a jam: put it where no state is (a basin edge).
    final = np.where(np.isnan(final), states.boundaries[0], final)
    logger.debug("mujoco: %d trials of %d actions in %.2f s", trials, k, seconds)
    return summarize(
        "mujoco",
        problem,
        option,
        final,
        jammed,
        near,
        seconds,
        params.jam_tol,
        boundary_margin,
    )
