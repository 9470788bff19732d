"""One squeeze in MuJoCo, stepped from Python, and the jam test both engines share.

:class:`Squeezer` holds one MuJoCo model and data of a part between two jaws and runs one
action at a time (:meth:`Squeezer.act`); :class:`~bayesgrasp.sim.rollout.BatchSqueezer`
runs the same scene for a batch of trials in C threads. Both decide whether an action
jammed, and run a jammed action again with slower jaws, through :func:`jammed` and
:func:`retry_params`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..angles import TWO_PI
from ..errors import MissingExtraError, SimulationError
from ..geometry.polygon import Part
from .params import SimParams
from .scene import prism, scene_xml

__all__ = [
    "SIZE_RANGE",
    "ActionOutcome",
    "Squeezer",
    "jammed",
    "require_mujoco",
    "retry_params",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


def jammed(end: ArrayLike, settled: ArrayLike, stable: ArrayLike, jam_tol: float) -> BoolArray:
    """Which actions jammed: did not settle, or stopped beyond ``jam_tol`` of every state.

    Parameters
    ----------
    end : array_like of shape (B,)
        Final yaws (radians).
    settled : array_like of bool, shape (B,)
    stable : array_like of shape (K,)
        The part's stable orientations.
    jam_tol : float
        Radians.

    Returns
    -------
    ndarray of bool, shape (B,)

    Examples
    --------
    >>> jammed([0.0, 0.5, 1.0], [True, True, False], [0.0, np.pi], 0.1).tolist()
    [False, True, True]
    """
    e = np.atleast_1d(np.asarray(end, dtype=np.float64))
    st = np.atleast_1d(np.asarray(stable, dtype=np.float64))
    err = np.abs(np.remainder(e[:, None] - st[None, :] + np.pi, TWO_PI) - np.pi)  # (B, K)
    ok = np.atleast_1d(np.asarray(settled, dtype=bool))
    return np.asarray((err.min(axis=1) > jam_tol) | ~ok, dtype=bool)


def retry_params(params: SimParams) -> SimParams | None:
    """The settings a jammed action is run again with (jaws at ``retry_speed``), or None.

    None when ``retry_speed`` is 0 or not below ``jaw_speed`` (no retry).

    Examples
    --------
    >>> retry_params(SimParams()).jaw_speed
    0.01
    >>> retry_params(SimParams(jaw_speed=0.01)) is None
    True
    """
    if not 0 < params.retry_speed < params.jaw_speed:
        return None
    return replace(params, jaw_speed=params.retry_speed)


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
        self,
        theta: float,
        offset: float = 0.0,
        push: bool = False,
        lead: int | None = None,
        stable: ArrayLike | None = None,
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
        stable : array_like, optional
            The part's stable orientations: an action that jams (:func:`jammed`) is run
            again from ``theta`` with the jaws at ``params.retry_speed``
            (:func:`retry_params`) and that outcome is kept, as
            :meth:`~bayesgrasp.sim.rollout.BatchSqueezer.act` does.

        Returns
        -------
        ActionOutcome
            After a retry, ``sim_time`` is both runs' simulated time.
        """
        if lead is None and not push and self.params.jaw_lag > 0:
            lead = {"-x": -1, "+x": 1}.get(self.params.lead_jaw) or int(self.rng.choice((-1, 1)))
        out = self._once(theta, offset, push, lead)
        slow = retry_params(self.params)
        if stable is None or slow is None:
            return out
        if not jammed([out.end], [out.settled], stable, self.params.jam_tol)[0]:
            return out
        again = self._once(theta, offset, push, lead, slow)  # the same model, slower jaws
        return replace(again, sim_time=out.sim_time + again.sim_time)

    def _once(
        self,
        theta: float,
        offset: float,
        push: bool,
        lead: int | None,
        sp: SimParams | None = None,
    ) -> ActionOutcome:
        """:meth:`act` once, at ``sp.jaw_speed`` (default :attr:`params`; the scene's)."""
        mj, m, d = self._mj, self.model, self.data
        sp = sp or self.params
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
