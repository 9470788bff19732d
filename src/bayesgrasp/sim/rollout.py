"""Many squeezes per call: MuJoCo's C rollout threads, stopped when the part has settled.

:class:`~bayesgrasp.sim.squeezer.Squeezer` steps one action at a time from Python. A plan is
open-loop: once the starting yaw of an action is known, its whole control sequence (jaw
targets closing at ``jaw_speed`` after their waits) is known in advance. So
:class:`BatchSqueezer` runs the same action for a whole batch of trials through
:func:`mujoco.rollout.rollout`, which steps every trajectory in C on ``nthread`` threads, in
chunks of ``chunk_time`` simulated seconds; after each chunk it reads every step's state and
retires the trials that have settled. A plan of ``k`` actions is ``k`` batched calls (an
action's start is the previous one's end); a policy that branches on the read width groups
its trials by their next action and calls :meth:`BatchSqueezer.act` once per group and step.

The settled test, evaluated at every step (state after the step):

- both jaws slower than ``settle_speed`` (their damped motion has stopped),
- both jaws at their force limit (a blocked jaw is slow while its force still ramps up; the
  squeeze is over only when both push with the full force: the force of a position
  actuator is ``kp (target - position)``, clipped, so it is read from the state and the
  control),
- the part slower than ``part_speed`` (translation) and ``part_spin`` (yaw rate),

held for ``settle_time``. Once settled, nothing moves: the jaws push with equal, opposite,
constant forces on a part at rest in a minimum of its width. A trial that has not settled
``max_time`` after its jaws could have crossed the whole opening is cut off (it counts as
a jam).

Every trajectory is independent and the chunk boundaries are fixed by the simulated time,
not by the threads, so the results do not depend on ``nthread``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import SimulationError
from ..geometry.polygon import Part
from .params import SimParams
from .squeezer import Squeezer, jammed, require_mujoco, retry_params

__all__ = ["BatchOutcome", "BatchSqueezer"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True, slots=True)
class BatchOutcome:
    """What one action did in each trial of a batch (arrays of shape ``(B,)``).

    Attributes
    ----------
    start : ndarray
        Yaw when the jaws began to close, gripper frame.
    end : ndarray
        Yaw where the part stopped, in ``[0, 2 pi)``.
    settled : ndarray of bool
        Whether the trial passed the settled test in time.
    sim_time : ndarray
        Simulated seconds until it settled (or was cut off).
    width : ndarray
        Jaw separation less the vertex capsules' diameter (metres).
    """

    start: FloatArray
    end: FloatArray
    settled: BoolArray
    sim_time: FloatArray
    width: FloatArray


class BatchSqueezer:
    """One part's MuJoCo model; runs an action for a batch of trials in C threads.

    Parameters
    ----------
    part : Part
    scale : float
        Metres per unit of the part's coordinates.
    params : SimParams, optional
    nthread : int
        Rollout threads (1: the calling thread only).

    Examples
    --------
    >>> from bayesgrasp.geometry.transfer import squeeze_function
    >>> tri = Part.from_points([(0, 0), (0.04, 0), (0.01, 0.03)])
    >>> out = BatchSqueezer(tri, 1.0).act(np.radians([30.0, 100.0]))
    >>> predicted = squeeze_function(tri.hull)(np.radians([30.0, 100.0]))
    >>> out.settled.tolist()
    [True, True]
    >>> bool(np.degrees(np.abs(out.end - predicted)).max() < 0.2)
    True
    """

    def __init__(
        self, part: Part, scale: float, params: SimParams | None = None, nthread: int = 1
    ) -> None:
        if not isinstance(nthread, int | np.integer) or nthread < 1:
            raise SimulationError(f"`nthread` must be an integer >= 1; got {nthread!r}")
        mj = require_mujoco()
        from mujoco import rollout as mjr

        self._mj = mj
        self._mjr = mjr
        self.sq = Squeezer(part, scale, params)
        self.params = self.sq.params
        self.nthread = int(nthread)
        m = self.sq.model
        self._datas = [mj.MjData(m) for _ in range(self.nthread)]
        self._spec = mj.mjtState.mjSTATE_FULLPHYSICS.value
        self.nstate = int(mj.mj_stateSize(m, self._spec))
        # FULLPHYSICS = time, qpos, qvel, (act, ...): columns of the rollout's state output.
        self._qpos0 = 1
        self._qvel0 = 1 + m.nq
        self._kp = float(self.sq.body.kp)
        self._runner = mjr.Rollout(nthread=self.nthread) if self.nthread > 1 else None
        self.sq_part = part

    def close(self) -> None:
        """Stop the rollout threads (also done when the object is collected)."""
        if self._runner is not None:
            self._runner.close()
            self._runner = None

    def __enter__(self) -> BatchSqueezer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _initial(
        self, theta: float, offset: float, push: bool, lead: int, sp: SimParams
    ) -> tuple[FloatArray, tuple[float, float], tuple[float, float], float, float]:
        """Initial state, jaw starts, jaw waits (-x, +x), earliest settle time, travel time."""
        sq, d = self.sq, self.sq.data
        lo, hi = sq._place(theta, offset)
        half = 0.5 * (hi - lo) + abs(offset) + sp.clearance
        size = sq.body.size
        push_len = (sp.push_distance or 2.0 * size) if push else 0.0
        far = -half + 2.0 * sp.clearance + push_len + 2.0 * size
        start = (-half, max(half, far)) if push else (-half, half)
        for q, v, x in zip(sq._jaw_q, sq._jaw_v, start, strict=True):
            d.qpos[q] = x
            d.qvel[v] = 0.0
        d.time = 0.0
        state = np.empty(self.nstate)
        self._mj.mj_getState(sq.model, d, state, self._spec)
        wait = (push_len + sp.clearance) / sp.jaw_speed if push else 0.0
        wait_neg = 0.0
        if not push and sp.jaw_lag > 0:
            wait, wait_neg = (sp.jaw_lag, 0.0) if lead < 0 else (0.0, sp.jaw_lag)
        earliest = max(wait, wait_neg) + sp.clearance / sp.jaw_speed
        travel = max(wait, wait_neg) + (start[1] - start[0]) / sp.jaw_speed
        return state, start, (wait_neg, wait), earliest, travel

    def act(
        self,
        theta: FloatArray,
        offset: FloatArray | float = 0.0,
        push: bool = False,
        lead: NDArray[np.int_] | None = None,
        stable: FloatArray | None = None,
    ) -> BatchOutcome:
        """One squeeze (or push-grasp) from each yaw in ``theta`` (gripper frame).

        With ``stable`` (the part's stable orientations), an action that jams (ends farther
        than ``jam_tol`` from all of them, or does not settle) is run again with the jaws
        at ``params.retry_speed``, and that outcome is kept: fast jaws can throw a small
        part past a shallow minimum or stall it where slow ones turn it; a jam at slow jaws
        is a jam of the physics (see ``SimParams.retry_speed``).

        Parameters
        ----------
        theta : ndarray of shape (B,)
        offset : float or ndarray of shape (B,)
            Shift (metres) along x of the part's x-extent from the gripper's centre.
        push : bool
            Close the -x jaw first (the push-grasp).
        lead : ndarray of shape (B,), optional
            With ``params.jaw_lag > 0``, the leading jaw of each squeeze (-1 or +1);
            default from ``params.lead_jaw`` (``random`` needs it given).

        Returns
        -------
        BatchOutcome
        """
        sp = self.params
        th = np.atleast_1d(np.asarray(theta, dtype=np.float64))
        b = th.size
        off = np.broadcast_to(np.asarray(offset, dtype=np.float64), (b,))
        if lead is None:
            if not push and sp.jaw_lag > 0 and sp.lead_jaw == "random":
                raise SimulationError("a lagged squeeze with lead_jaw=random needs `lead` given")
            ld = np.full(b, -1 if sp.lead_jaw != "+x" else 1)
        else:
            ld = np.broadcast_to(np.asarray(lead), (b,))
        out = self._act(th, off, push, ld)
        slow = retry_params(sp)
        if stable is None or slow is None:
            return out
        bad = np.flatnonzero(jammed(out.end, out.settled, stable, sp.jam_tol))
        if not bad.size:
            return out
        again = self._act(th[bad], off[bad], push, ld[bad], slow)  # the same model
        fields = [np.array(getattr(out, f)) for f in ("end", "settled", "sim_time", "width")]
        for arr, f in zip(fields, ("end", "settled", "sim_time", "width"), strict=True):
            arr[bad] = getattr(again, f)
        fields[2][bad] += out.sim_time[bad]  # both runs' simulated time
        return BatchOutcome(th, fields[0], fields[1], fields[2], fields[3])

    def _act(
        self,
        th: FloatArray,
        off: FloatArray,
        push: bool,
        ld: NDArray[np.int_],
        sp: SimParams | None = None,
    ) -> BatchOutcome:
        """:meth:`act` once, at ``sp.jaw_speed`` (default :attr:`params`).

        Only the jaws' targets depend on ``sp`` (its jaw speed and waits): the scene is the
        one built from :attr:`params`.
        """
        sp = sp or self.params
        b = th.size
        init = [self._initial(float(th[i]), float(off[i]), push, int(ld[i]), sp) for i in range(b)]
        state = np.array([x[0] for x in init])  # (B, nstate)
        starts = np.array([x[1] for x in init])  # (B, 2)
        waits = np.array([x[2] for x in init])  # (B, 2)
        earliest = np.array([x[3] for x in init])
        t_max = np.array([x[4] for x in init]) + sp.max_time
        dt = sp.timestep
        chunk = max(1, round(sp.chunk_time / dt))
        need = max(1, math.ceil(sp.settle_time / dt))
        force = 0.999 * self.sq.force
        qn, qp = (self._qpos0 + q for q in self.sq._jaw_q)
        vn, vp = (self._qvel0 + v for v in self.sq._jaw_v)
        pq, pv = self._qpos0 + self.sq._part_q, self._qvel0 + self.sq._part_v
        end_state = state.copy()
        settled = np.zeros(b, dtype=bool)
        sim_time = np.zeros(b)
        calm = np.zeros(b, dtype=np.int64)
        active = np.arange(b)
        step0 = 0
        while active.size:
            tt = (step0 + 1 + np.arange(chunk)) * dt  # (C,) time at each step's end
            lag = np.maximum(0.0, tt[None, :, None] - waits[active, None, :])  # (A, C, 2)
            sign = np.array([1.0, -1.0])
            ctrl = starts[active, None, :] + sign * sp.jaw_speed * lag  # (A, C, 2)
            datas = self._datas
            if self._runner is not None:
                out, _ = self._runner.rollout(
                    self.sq.model, datas, state[active], ctrl, nstep=chunk
                )
            else:
                out, _ = self._mjr.rollout(self.sq.model, datas[0], state[active], ctrl,
                                           nstep=chunk)  # fmt: skip
            slow = (np.abs(out[:, :, vn]) < sp.settle_speed) & (
                np.abs(out[:, :, vp]) < sp.settle_speed
            )
            full = (self._kp * np.abs(ctrl[:, :, 0] - out[:, :, qn]) >= force) & (
                self._kp * np.abs(ctrl[:, :, 1] - out[:, :, qp]) >= force
            )
            still = (np.hypot(out[:, :, pv], out[:, :, pv + 1]) < sp.part_speed) & (
                np.abs(out[:, :, pv + 5]) < sp.part_spin
            )
            ok = slow & full & still & (tt[None, :] > earliest[active, None])  # (A, C)
            # Run lengths of consecutive calm steps, carried over from the previous chunk.
            # run[c] = steps since the last calm-breaking step (or carried + c + 1 if none).
            steps = np.arange(1, chunk + 1)
            last_break = np.maximum.accumulate(np.where(ok, 0, steps), axis=1)  # (A, C)
            carried = np.where(last_break == 0, calm[active, None], 0)
            run = carried + steps - last_break
            hit = run >= need
            done_here: BoolArray = np.asarray(hit.any(axis=1), dtype=bool)
            first = np.argmax(hit, axis=1)
            over = tt[-1] >= t_max[active]
            idx = np.where(done_here, first, chunk - 1)
            rows = np.arange(active.size)
            fin = done_here | over
            g = active[fin]
            end_state[g] = out[rows[fin], idx[fin]]
            settled[g] = done_here[fin]
            sim_time[g] = tt[idx[fin]]
            keep = ~fin
            state[active[keep]] = out[keep, -1]
            calm[active] = run[:, -1]
            active = active[keep]
            step0 += chunk
        w, x, y, z = (end_state[:, pq + 3 + i] for i in range(4))
        end = np.mod(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)), TWO_PI)
        width = end_state[:, qp] - end_state[:, qn] - 2.0 * self.sq._rc
        return BatchOutcome(th, end, settled, sim_time, width)
