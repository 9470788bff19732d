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
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, circle_distance
from ..errors import MissingExtraError, SimulationError
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
from .scene import prism, scene_xml, units_scale

__all__ = ["ActionOutcome", "Squeezer", "require_mujoco", "simulate_mujoco"]

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]

#: Part sizes (metres across, twice the hull's largest distance from its centroid) the
#: defaults were checked on: random 10-gons agreed with the squeeze model in 30/30 single
#: squeezes from 1.2 cm to 35 cm across; at 0.5 and 0.7 cm none agreed, at 94 cm 24/30.
SIZE_RANGE = (0.01, 0.5)


def require_mujoco() -> Any:
    """Import MuJoCo, or raise :class:`MissingExtraError` naming the ``sim`` extra.

    Examples
    --------
    >>> require_mujoco().__version__
    '4.0.0'
    """
    try:
        import mujoco
    except ImportError:
        raise MissingExtraError("mujoco", "sim") from None
    return mujoco


@dataclass(frozen=True, slots=True)
class ActionOutcome:
    """What one simulated action did.

    Attributes
    ----------
    start : float
        Yaw (radians) when the jaws began to close, in the gripper frame.
    end : float
        Yaw where the part stopped, in ``[0, 2 pi)``.
    settled : bool
        Whether the jaws came to rest in time (``SimParams.max_time``).
    sim_time : float
        Simulated seconds.
    width : float
        The jaw separation when the action ended, less the vertex capsules' diameter
        (:meth:`Squeezer.width`), metres: what a gripper's encoder reads.
    """

    start: float
    end: float
    settled: bool
    sim_time: float
    width: float = math.nan


class Squeezer:
    """One MuJoCo model and data of the part between the jaws; runs actions in turn.

    Parameters
    ----------
    part : Part
    scale : float
        Metres per unit of the part's coordinates.
    params : SimParams, optional

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> tri = Part.from_points([(0, 0), (0.04, 0), (0.01, 0.03)])
    >>> out = Squeezer(tri, 1.0).act(np.radians(30.0))
    >>> predicted = squeeze_function(tri.hull)(np.radians(30.0))
    >>> out.settled, round(float(np.degrees(out.end)), 1), round(float(np.degrees(predicted)), 1)
    (True, 18.4, 18.4)
    """

    def __init__(self, part: Part, scale: float, params: SimParams | None = None) -> None:
        mj = require_mujoco()
        self._mj = mj
        self.params = params or SimParams()
        self.scale = scale
        self.model = mj.MjModel.from_xml_string(scene_xml(part, scale, self.params))
        self.data = mj.MjData(self.model)
        self.body = prism(part, scale, self.params)
        self._rel = self.body.vertices  # (N, 2) body-frame hull
        self._size = self.body.size
        self.force = self.body.force  # each jaw's force limit (N)
        m = self.model
        self._part_q = int(m.jnt_qposadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, "part")])
        self._part_v = int(m.jnt_dofadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, "part")])
        self._jaw_q = [
            int(m.jnt_qposadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, n)])
            for n in ("jaw_neg", "jaw_pos")
        ]
        self._jaw_v = [
            int(m.jnt_dofadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, n)])
            for n in ("jaw_neg", "jaw_pos")
        ]
        self._act = [mj.mj_name2id(m, mj.mjtObj.mjOBJ_ACTUATOR, n) for n in ("jaw_neg", "jaw_pos")]
        self._z = self._rest_height()
        #: Draws the leading jaw of a squeeze when ``params.jaw_lag > 0`` and ``lead_jaw``
        #: is ``random`` and :meth:`act` is given no ``lead``; replace it to reseed.
        self.rng = np.random.default_rng(0)
        # The jaws touch capsules of this radius at the hull's vertices (scene_xml).
        self._rc = min(self.params.edge_radius, 0.25 * self.body.thickness)

    def _rest_height(self) -> float:
        """Height of the part's body frame when it rests on the table (one short settle)."""
        mj, d = self._mj, self.data
        mj.mj_resetData(self.model, d)
        for q, a, x in zip(self._jaw_q, self._act, (-1.0, 1.0), strict=True):
            d.qpos[q] = x * (self._size + 0.05)
            d.ctrl[a] = d.qpos[q]
        mj.mj_forward(self.model, d)
        mj.mj_step(self.model, d, max(1, round(0.2 / self.params.timestep)))
        return float(d.qpos[self._part_q + 2])

    def yaw(self) -> float:
        """The part's yaw (radians, ``[0, 2 pi)``) from the free joint's quaternion."""
        w, x, y, z = self.data.qpos[self._part_q + 3 : self._part_q + 7]
        return float(np.mod(math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)), TWO_PI))

    def width(self) -> float:
        """The jaw separation less the capsules' diameter (metres): the part's width read.

        The slide joints' positions are the x of the jaws' inner faces; the capsules at the
        hull's vertices add ``2 * edge_radius`` to every width (:mod:`bayesgrasp.sim.scene`).
        """
        d = self.data
        sep = float(d.qpos[self._jaw_q[1]] - d.qpos[self._jaw_q[0]])
        return sep - 2.0 * self._rc

    def _place(self, theta: float, offset: float) -> tuple[float, float]:
        """Put the part at yaw ``theta``, x-extent centred at ``offset``; return its extent."""
        c, s = math.cos(theta), math.sin(theta)
        xs = c * self._rel[:, 0] - s * self._rel[:, 1]  # (N,) x of the rotated hull
        lo, hi = float(xs.min()), float(xs.max())
        mid = 0.5 * (lo + hi)
        d = self.data
        q = self._part_q
        d.qpos[q : q + 3] = (offset - mid, 0.0, self._z)
        d.qpos[q + 3 : q + 7] = (math.cos(theta / 2), 0.0, 0.0, math.sin(theta / 2))
        d.qvel[self._part_v : self._part_v + 6] = 0.0
        return lo - mid + offset, hi - mid + offset

    def act(
        self, theta: float, offset: float = 0.0, push: bool = False, lead: int | None = None
    ) -> ActionOutcome:
        """One squeeze (or push-grasp when ``push``) from yaw ``theta`` in the gripper frame.

        Parameters
        ----------
        theta : float
            The part's orientation in the gripper frame when the jaws start to close.
        offset : float
            Shift (metres) along x of the part's x-extent from the gripper's centre.
        push : bool
            Close the -x jaw first (an action that ``pushes_first``, the push-grasp).
        lead : int, optional
            For a squeeze with ``params.jaw_lag > 0``: ``-1`` or ``+1``, the side (-x or
            +x) of the jaw that starts ``jaw_lag`` seconds early. Default from
            ``params.lead_jaw`` (``random``: drawn from :attr:`rng`).

        Returns
        -------
        ActionOutcome
        """
        mj, m, d, sp = self._mj, self.model, self.data, self.params
        lo, hi = self._place(theta, offset)
        half = 0.5 * (hi - lo) + abs(offset) + sp.clearance
        push_len = (sp.push_distance or 2.0 * self._size) if push else 0.0
        # A push-grasp's +x jaw starts beyond where the pushed part can reach while it
        # turns (its x-extent never exceeds twice its size).
        far = -half + 2.0 * sp.clearance + push_len + 2.0 * self._size
        start = (-half, max(half, far)) if push else (-half, half)
        for q, v, a, x in zip(self._jaw_q, self._jaw_v, self._act, start, strict=True):
            d.qpos[q] = x
            d.qvel[v] = 0.0
            d.ctrl[a] = x
        d.time = 0.0
        mj.mj_forward(m, d)
        n = sp.check_every
        dt = n * sp.timestep
        need = max(1, math.ceil(sp.settle_time / dt))
        vn, vp = self._jaw_v
        an, ap = self._act
        # The +x jaw of a push-grasp waits until the -x jaw has pushed push_len past contact;
        # no settling test before the (last) jaw can have reached the part.
        wait = (push_len + sp.clearance) / sp.jaw_speed if push else 0.0
        wait_neg = 0.0
        if not push and sp.jaw_lag > 0:  # contact asynchrony: the lagging jaw starts late
            if lead is None:
                lead = {"-x": -1, "+x": 1}.get(sp.lead_jaw) or int(self.rng.choice((-1, 1)))
            if lead not in (-1, 1):
                raise SimulationError(f"`lead` must be -1 or +1 (the leading jaw); got {lead!r}")
            wait, wait_neg = (sp.jaw_lag, 0.0) if lead < 0 else (0.0, sp.jaw_lag)
        earliest = max(wait, wait_neg) + sp.clearance / sp.jaw_speed
        # Time for the last jaw to cross the whole opening, plus max_time to settle.
        travel_time = max(wait, wait_neg) + (start[1] - start[0]) / sp.jaw_speed
        steps_max = math.ceil((travel_time + sp.max_time) / dt)
        force = 0.999 * self.force
        calm = 0
        t = 0.0
        for _ in range(steps_max):
            t += dt
            d.ctrl[an] = start[0] + sp.jaw_speed * max(0.0, t - wait_neg)
            d.ctrl[ap] = start[1] - sp.jaw_speed * max(0.0, t - wait)
            mj.mj_step(m, d, n)
            slow = max(abs(d.qvel[vn]), abs(d.qvel[vp])) < sp.settle_speed
            # Blocked jaws are slow while their force still ramps up (kp * jaw_speed per
            # second): the squeeze is over only when both push with their full force.
            full = min(abs(d.actuator_force[an]), abs(d.actuator_force[ap])) >= force
            pv = self._part_v
            still = (
                math.hypot(d.qvel[pv], d.qvel[pv + 1]) < sp.part_speed
                and abs(d.qvel[pv + 5]) < sp.part_spin
            )
            if t > earliest and slow and full and still:
                calm += 1
                if calm >= need:
                    return ActionOutcome(theta, self.yaw(), True, t, self.width())
            else:
                calm = 0
        return ActionOutcome(theta, self.yaw(), False, t, self.width())


# --- parallel trials ---------------------------------------------------------------------

_WORKER: Squeezer | None = None


def _init_worker(part: Part, scale: float, params: SimParams) -> None:
    global _WORKER
    _WORKER = Squeezer(part, scale, params)


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
        res = sq.act(float(np.mod(yaw - angle, TWO_PI)), off, push, lead)
        out.append(res)
        yaw = res.end
    return out


def _map_trials(
    part: Part, scale: float, params: SimParams, trials: Sequence[_Trial], workers: int
) -> Iterator[list[ActionOutcome]]:
    if workers <= 1:
        _init_worker(part, scale, params)
        for t in trials:
            yield _run_trial(t)
        return
    # fork where the platform has it: workers start at once and the caller's script needs
    # no `if __name__ == "__main__"` guard (spawn re-imports it); spawn elsewhere.
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    chunk = max(1, min(8, len(trials) // (4 * workers)))
    with ctx.Pool(workers, initializer=_init_worker, initargs=(part, scale, params)) as pool:
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
    from .rollout import BatchSqueezer

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
        from Python (:class:`Squeezer`). Both run the same scene and settled test.

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
        for res in _map_trials(problem.part, sc, params, tasks, workers):
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
