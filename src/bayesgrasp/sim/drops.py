"""A solid part in MuJoCo: drops for its resting-pose statistics, and squeezes that topple it.

:func:`drop_poses` drops the part from uniform random orientations onto a table, lets it
settle and reads the face it rests on: the frequencies estimate the pose probabilities that
the quasi-static model (Goldberg, Mirtich, Zhuang, Craig, Carlisle and Canny, *Part pose
statistics: estimators and experiments*, IEEE T-RA 1999) predicts from solid angles. The
paper's drops pin a probability to within 5% at 90% confidence after about 385 drops.

:func:`squeeze_topples` rests the part on one face and squeezes it with two frictionless
jaw pads at a planar angle; it reports whether the part leaves its pose. A squeeze keeps the
pose while the jaws push where the part cannot tip; :func:`static_topples` is the static
check: a horizontal push at height ``h`` slides the part when the force reaches ``mu m g``
and tips it over the support's far edge when ``F h`` exceeds ``m g l`` (``l`` the horizontal
distance from the centre of mass to that edge), so it tips first when ``mu h > l``.

Both build a MuJoCo scene of their own (:mod:`~bayesgrasp.sim.mesh_scene`: metres, the
part scaled to ``size``, contacts on the hull, mass from the solid); MuJoCo is imported
only when they run. Bad input raises :class:`~bayesgrasp.errors.SimulationError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import MissingExtraError, SimulationError
from .mesh_scene import MeshBody, finite_array, mesh_body, pose_frame

__all__ = ["DropStudy", "SqueezeCheck", "drop_poses", "squeeze_topples", "static_topples"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Defaults of a drop (metres, seconds): the part's size, the height of its lowest point
#: above the table, the restitution and table friction, the time step, the settle test (both
#: speeds below their thresholds for ``settle_time``), the simulated-time bound per drop, and
#: the largest angle between the settled down-facing normal and -z that still names a pose.
DROP_DEFAULTS: dict[str, float] = {
    "size": 0.05,
    "height": 0.02,
    "restitution": 0.0,
    "friction": 0.5,
    "timestep": 0.001,
    "contact_time": 0.005,
    "settle_speed": 0.005,
    "settle_spin": 0.05,
    "settle_time": 0.1,
    "max_time": 4.0,
    "match_angle_deg": 5.0,
}

_GRAVITY = 9.81


def require_mujoco() -> Any:
    """Import MuJoCo, or raise :class:`MissingExtraError` naming the ``sim`` extra."""
    try:
        import mujoco
    except ImportError:
        raise MissingExtraError("mujoco", "sim") from None
    return mujoco


def _damping_ratio(restitution: float) -> float:
    """MuJoCo's contact damping ratio whose bounce has this coefficient of restitution.

    A damped spring released at contact separates with ``e = exp(-z pi / sqrt(1 - z^2))``;
    solved for the ratio ``z``; ``e = 0`` is critical damping.
    """
    if restitution <= 0:
        return 1.0
    log_e = math.log(restitution)
    return -log_e / math.sqrt(math.pi**2 + log_e**2)


def _number(
    value: Any, name: str, low: float, high: float = math.inf, *, open_low: bool = True
) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SimulationError(f"`{name}` must be a number; got {value!r}") from None
    bad = not math.isfinite(x) or x > high or (x <= low if open_low else x < low)
    if bad:
        bound = f"> {low:g}" if open_low else f">= {low:g}"
        upper = "" if math.isinf(high) else f" and <= {high:g}"
        raise SimulationError(f"`{name}` must be a finite number {bound}{upper}; got {value}")
    return x


def _unit_normals(normals: ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(normals, dtype=np.float64) if not isinstance(normals, str) else None
    if arr is None or arr.ndim not in (1, 2):
        raise SimulationError(f"`{name}` must be unit vectors of shape (K, 3)")
    arr = finite_array(np.atleast_2d(arr), name, (None, 3))
    if len(arr) == 0:
        raise SimulationError(f"`{name}` must hold at least one normal")
    norm = np.linalg.norm(arr, axis=1)
    if np.any(np.abs(norm - 1.0) > 1e-6):
        lengths = np.round(norm, 6).tolist()
        raise SimulationError(f"`{name}` must be unit vectors; got lengths {lengths}")
    unit: FloatArray = arr / norm[:, None]
    return unit


@dataclass(frozen=True, slots=True, eq=False)
class DropStudy:
    """The outcome of simulated drops: how often the part came to rest on each face.

    Attributes
    ----------
    counts : ndarray of int, shape (K,)
        Drops that settled on each candidate face, in the order of the ``normals`` given.
    unmatched : int
        Drops whose down-facing direction was further than ``match_angle_deg`` from every
        candidate normal (resting on an edge, leaning on a face the caller did not list).
    trials : int
        Drops made; ``counts.sum() + unmatched == trials``.
    settings : dict of str to float
        Everything the outcome depends on: ``size`` (m), ``height`` (m), ``restitution``,
        ``friction``, ``timestep`` (s), ``contact_time`` (s), ``settle_speed`` (m/s),
        ``settle_spin`` (rad/s), ``settle_time`` (s), ``max_time`` (s),
        ``match_angle_deg``, ``seed``.
    unsettled : int
        Drops still moving at ``max_time`` (classified by where they were).
    """

    counts: IntArray
    unmatched: int
    trials: int
    settings: dict[str, float] = field(default_factory=dict)
    unsettled: int = 0

    def __post_init__(self) -> None:
        """Keep a read-only copy of the counts; check they add up to the trials."""
        counts = np.array(self.counts, dtype=np.int64)
        if counts.ndim != 1 or np.any(counts < 0) or self.trials < 1:
            raise SimulationError("`counts` must be non-negative integers and `trials` >= 1")
        if int(counts.sum()) + self.unmatched != self.trials:
            total = int(counts.sum()) + self.unmatched
            raise SimulationError(
                f"counts and unmatched must add up to trials ({self.trials}); got {total}"
            )
        counts.flags.writeable = False
        object.__setattr__(self, "counts", counts)

    def frequencies(self) -> FloatArray:
        """Each face's share of all drops, ``counts / trials``.

        Examples
        --------
        >>> DropStudy(np.array([3, 1]), 0, 4).frequencies().tolist()
        [0.75, 0.25]
        """
        return self.counts / float(self.trials)

    def intervals(self, confidence: float = 0.95) -> FloatArray:
        """Clopper-Pearson (exact binomial) intervals of each face's probability.

        Parameters
        ----------
        confidence : float
            Coverage, in (0, 1).

        Returns
        -------
        ndarray of shape (K, 2)
            ``(low, high)`` of each face: the beta quantiles of Clopper and Pearson (1934),
            conservative at every count (coverage at least ``confidence``).

        Examples
        --------
        >>> np.round(DropStudy(np.array([50, 50]), 0, 100).intervals(), 4).tolist()[0]
        [0.3983, 0.6017]
        """
        from scipy.stats import beta

        c = _number(confidence, "confidence", 0.0, 1.0)
        if c >= 1.0:
            raise SimulationError(f"`confidence` must be in (0, 1); got {confidence}")
        k = self.counts.astype(np.float64)
        n = float(self.trials)
        a = (1.0 - c) / 2.0
        low = np.where(k > 0, beta.ppf(a, k, n - k + 1), 0.0)
        high = np.where(k < n, beta.ppf(1 - a, k + 1, n - k), 1.0)
        return np.stack([low, high], axis=1)


def _drop_xml(body: MeshBody, s: dict[str, float]) -> str:
    zeta = _damping_ratio(s["restitution"])
    # MuJoCo combines two geoms' frictions by taking the larger: the part must carry the
    # table's friction too, or its default of 1 wins.
    friction = f'friction="{s["friction"]} 0.001 0.0001"'
    asset, part = body.geom_xml("part", f'contype="1" conaffinity="1" {friction}')
    return f"""<mujoco model="drop">
  <option timestep="{s["timestep"]}" integrator="implicitfast" solver="Newton" cone="elliptic"/>
  <default><geom solref="{s["contact_time"]} {zeta:.6f}" solimp="0.95 0.99 0.0001"/></default>
  <asset>{asset}</asset>
  <worldbody>
    <geom name="table" type="plane" size="0 0 1" friction="{s["friction"]} 0.001 0.0001"/>
    <body name="part"><freejoint name="part"/>{part}</body>
  </worldbody>
</mujoco>"""


def drop_poses(
    vertices: ArrayLike,
    faces: ArrayLike,
    com: ArrayLike,
    normals: ArrayLike,
    trials: int,
    *,
    seed: int = 0,
    height: float | None = None,
    restitution: float | None = None,
    friction: float | None = None,
    size: float | None = 0.05,
) -> DropStudy:
    """Drop a solid part onto a table ``trials`` times; count the face it comes to rest on.

    Each drop starts at rest from a uniform random orientation (``Rotation.random`` with
    ``seed``, so a seed gives the same drops every time), its lowest point ``height`` above
    the table. The part falls, bounces and tumbles until its speed stays below
    ``settle_speed`` and its spin below ``settle_spin`` for ``settle_time`` (or
    ``max_time`` passes); the settled part's candidate normal closest to straight down
    names its pose, if within ``match_angle_deg`` (:data:`DROP_DEFAULTS`).

    Parameters
    ----------
    vertices : array_like of shape (N, 3)
        A closed mesh, any length unit: it is scaled so its bounding box's longest side is
        ``size`` metres.
    faces : array_like of shape (M, 3)
        Triangles (vertex indices).
    com : array_like of shape (3,)
        Centre of mass, mesh units, inside the hull.
    normals : array_like of shape (K, 3)
        Outward unit normals (mesh coordinates) of the candidate resting faces.
    trials : int
        Number of drops, >= 1.
    seed : int
        Seed of the initial orientations.
    height : float, optional
        Drop height of the lowest point, metres (default 0.02, 0.4 times the default size:
        a part tipped onto a table; from higher, flat parts land flat more often than the
        quasi-static model says).
    restitution : float, optional
        Coefficient of restitution of the part-table contact, in [0, 0.99] (default 0: a
        critically damped contact); MuJoCo's contact damping ratio is set to give it. A
        bouncy contact keeps chattering at rest, so its drops run to ``max_time``.
    friction : float, optional
        Part-table sliding friction coefficient, > 0 (default 0.5).
    size : float or None
        Longest side of the part in metres; ``None`` takes the mesh units as metres.

    Returns
    -------
    DropStudy

    Raises
    ------
    SimulationError
        Bad mesh, centre of mass, normals or settings (one line).
    MissingExtraError
        MuJoCo is not installed (extra ``sim``).

    Examples
    --------
    >>> cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    >>> tris = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
    ...         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    >>> six = np.vstack([np.eye(3), -np.eye(3)])
    >>> study = drop_poses(cube, tris, (0.5, 0.5, 0.5), six, 6, seed=1)
    >>> int(study.counts.sum() + study.unmatched), study.trials
    (6, 6)
    """
    n = _unit_normals(normals, "normals")
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 1:
        raise SimulationError(f"`trials` must be an integer >= 1; got {trials!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SimulationError(f"`seed` must be an integer >= 0; got {seed!r}")
    s = dict(DROP_DEFAULTS)
    if height is not None:
        s["height"] = _number(height, "height", 0.0, open_low=False)
    if restitution is not None:
        s["restitution"] = _number(restitution, "restitution", 0.0, 0.99, open_low=False)
    if friction is not None:
        s["friction"] = _number(friction, "friction", 0.0)
    body = mesh_body(vertices, faces, com, size)
    s["size"] = float(np.ptp(body.points, axis=0).max())
    s["seed"] = float(seed)
    mujoco = require_mujoco()
    from scipy.spatial.transform import Rotation

    model = mujoco.MjModel.from_xml_string(_drop_xml(body, s))
    data = mujoco.MjData(model)
    rotations = Rotation.random(int(trials), random_state=int(seed))
    mats = np.atleast_3d(rotations.as_matrix()).reshape(-1, 3, 3)
    quats = np.atleast_2d(rotations.as_quat())[:, [3, 0, 1, 2]]  # scipy xyzw -> MuJoCo wxyz
    chunk = max(1, round(0.01 / s["timestep"]))  # check the speeds every 10 ms
    hold = max(1, math.ceil(s["settle_time"] / (chunk * s["timestep"])))
    limit = math.ceil(s["max_time"] / (chunk * s["timestep"]))
    cos_match = math.cos(math.radians(s["match_angle_deg"]))
    counts = np.zeros(len(n), dtype=np.int64)
    unmatched = unsettled = 0
    for i in range(int(trials)):
        mujoco.mj_resetData(model, data)
        lowest = float((body.points @ mats[i].T)[:, 2].min())
        data.qpos[:3] = (0.0, 0.0, s["height"] - lowest)
        data.qpos[3:7] = quats[i]
        still = 0
        for _ in range(limit):
            mujoco.mj_step(model, data, chunk)
            speed = float(np.linalg.norm(data.qvel[:3]))
            spin = float(np.linalg.norm(data.qvel[3:6]))
            still = still + 1 if speed < s["settle_speed"] and spin < s["settle_spin"] else 0
            if still >= hold:
                break
        else:
            unsettled += 1
        rot = data.xmat[1].reshape(3, 3)
        down = -(n @ rot.T)[:, 2]  # (K,) cosine of each normal's angle to -z
        k = int(np.argmax(down))
        if down[k] >= cos_match:
            counts[k] += 1
        else:
            unmatched += 1
    return DropStudy(counts, unmatched, int(trials), s, unsettled)


@dataclass(frozen=True, slots=True)
class SqueezeCheck:
    """What one simulated squeeze of a resting part did; true when the part toppled.

    Attributes
    ----------
    toppled : bool
        The resting face's normal turned more than ``tilt_limit_deg`` from straight down at
        some time during the squeeze (the part left its pose, even if the jaws caught it).
    tilt_deg : float
        Its final angle from straight down, degrees.
    max_tilt_deg : float
        The largest angle during the squeeze.
    settled : bool
        The jaws came to rest before the time bound.
    static_prediction : bool
        :func:`static_topples` for the same squeeze.
    """

    toppled: bool
    tilt_deg: float
    max_tilt_deg: float
    settled: bool
    static_prediction: bool

    def __bool__(self) -> bool:
        """Whether the part toppled."""
        return self.toppled


def _placed(normal: FloatArray, gripper_angle: float) -> FloatArray:
    """Rotation (body to world) of the part resting on ``normal``, turned by ``-angle``."""
    c, s = math.cos(gripper_angle), math.sin(gripper_angle)
    yaw = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # turn by -gripper_angle
    return yaw @ pose_frame(normal)


def static_topples(
    vertices: ArrayLike,
    com: ArrayLike,
    normal: ArrayLike,
    gripper_angle: float,
    *,
    jaw_height: float = 0.5,
    friction: float = 0.5,
    push: float = 0.5,
) -> bool:
    """Whether the first jaw's push tips the resting part before it slides (statics).

    The part rests on the face with outward ``normal``, turned by ``-gripper_angle`` in the
    pose's planar frame; the jaws close along x, and the part sits off centre towards +x
    (``push > 0``; towards -x when ``push < 0``), so that jaw touches first and pushes it
    horizontally at ``jaw_height`` times the part's height. It tips first when
    ``friction * h > l``: ``h`` the push height above the table, ``l`` the horizontal
    distance from the centre of mass to the support's edge the push tips it over.

    Parameters
    ----------
    vertices : array_like of shape (N, 3)
    com : array_like of shape (3,)
    normal : array_like of shape (3,)
        Outward unit normal of the resting face, mesh coordinates.
    gripper_angle : float
        Radians, in the pose's planar frame (:func:`~bayesgrasp.sim.mesh_scene.pose_frame`).
    jaw_height : float
        Height of the jaw pads, a fraction of the part's height, in (0, 1].
    friction : float
        Table friction coefficient.
    push : float
        Signed distance the first jaw pushes the part (only its sign matters here); 0 gives
        ``False`` (both jaws touch together, no net push).

    Returns
    -------
    bool

    Examples
    --------
    >>> tall = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 6)]
    >>> static_topples(tall, (0.5, 0.5, 3), (0, 0, -1), 0.0, jaw_height=0.8)
    True
    >>> static_topples(tall, (0.5, 0.5, 3), (0, 0, -1), 0.0, jaw_height=0.05)
    False
    """
    v = finite_array(vertices, "vertices", (None, 3))
    c = finite_array(com, "com", (3,))
    nrm = _unit_normals(normal, "normal")[0]
    if push == 0:
        return False
    rot = _placed(nrm, float(gripper_angle))
    p = (v - c) @ rot.T  # (N, 3) about the centre of mass, world axes
    base = float(p[:, 2].min())
    height = float(p[:, 2].max()) - base
    support = p[p[:, 2] <= base + 1e-6 * height]
    push_height = jaw_height * height
    # A push towards -x (the +x jaw first) tips the part over the support's lowest x.
    lever = float(-support[:, 0].min()) if push > 0 else float(support[:, 0].max())
    return friction * push_height > lever


def _squeeze_xml(body: MeshBody, s: dict[str, float], pad: dict[str, float]) -> str:
    # MuJoCo combines two geoms' frictions by taking the larger: the part must carry the
    # table's friction too, or its default of 1 wins.
    friction = f'friction="{s["friction"]} 0.001 0.0001"'
    asset, part = body.geom_xml("part", f'contype="3" conaffinity="3" {friction}')
    jaws = ""
    for side in ("lo", "hi"):
        jaws += (
            f'<body name="jaw_{side}" pos="0 0 {pad["z"]:.9g}">'
            f'<joint name="{side}" type="slide" axis="1 0 0" damping="{pad["damping"]:.6g}"/>'
            f'<geom type="box" size="{pad["t"]:.6g} {pad["l"]:.6g} {pad["hz"]:.6g}"'
            f' mass="{pad["mass"]:.6g}"'
            ' contype="2" conaffinity="2" condim="1" priority="1" solref="0.02 1"/></body>'
        )
    act = "".join(
        f'<position joint="{side}" kp="{pad["kp"]:.6g}"'
        f' forcerange="{-pad["force"]:.6g} {pad["force"]:.6g}"'
        ' forcelimited="true"/>'
        for side in ("lo", "hi")
    )
    return f"""<mujoco model="squeeze">
  <option timestep="{s["timestep"]}" integrator="implicitfast" solver="Newton" cone="elliptic"/>
  <default><geom solref="{s["contact_time"]} 1" solimp="0.95 0.99 0.0001"/></default>
  <asset>{asset}</asset>
  <worldbody>
    <geom name="table" type="plane" size="0 0 1" contype="1" conaffinity="1"
          friction="{s["friction"]} 0.001 0.0001"/>
    <body name="part"><freejoint name="part"/>{part}</body>
    {jaws}
  </worldbody>
  <actuator>{act}</actuator>
</mujoco>"""


def squeeze_topples(
    vertices: ArrayLike,
    faces: ArrayLike,
    com: ArrayLike,
    normal: ArrayLike,
    gripper_angle: float,
    *,
    jaw_height: float = 0.5,
    friction: float = 0.5,
    push: float = 0.5,
    size: float | None = 0.05,
    tilt_limit_deg: float = 10.0,
) -> SqueezeCheck:
    """Squeeze a part resting on one face with frictionless parallel jaws; report a topple.

    The part rests on the face with outward unit ``normal`` (mesh coordinates), its pose's
    planar frame (:func:`~bayesgrasp.sim.mesh_scene.pose_frame`) turned by ``-gripper_angle``
    in the gripper frame, where the jaws close along x. Each jaw is a thin horizontal pad
    (3 mm tall, as long as twice the part) whose centre is at ``jaw_height`` times the
    part's height; pads are frictionless (``condim=1``, ``priority=1``) and do not touch
    the table. The part sits off centre, so one jaw touches first and pushes it ``push``
    times its longest side across the table (the push that tips a tall part) before the
    other jaw meets it. The jaws close at 1 cm/s, force-limited to three times the part's
    weight, and stop when both are slower than 1e-4 m/s for 0.1 s (at most 10 s simulated;
    the run ends early once the part has tipped past 60 degrees).

    Parameters
    ----------
    vertices, faces, com
        The solid, as :func:`drop_poses` takes it.
    normal : array_like of shape (3,)
        Outward unit normal of the resting face.
    gripper_angle : float
        Radians, in the pose's planar frame.
    jaw_height : float
        Pad height as a fraction of the part's height, in (0, 1].
    friction : float
        Part-table friction.
    push : float
        Signed distance the first jaw pushes the part before the other touches, a fraction
        of the part's longest side, in [-1, 1]; positive: the +x jaw pushes; 0: both jaws
        touch together (no push, no topple by the jaws).
    size : float or None
        Longest side of the part in metres (``None``: mesh units are metres).
    tilt_limit_deg : float
        The resting face's largest angle from straight down that still keeps the pose.

    Returns
    -------
    SqueezeCheck
        True (``bool``) when the part toppled; with :func:`static_topples` beside it.

    Examples
    --------
    >>> box = [(x, y, z) for x in (0, 4) for y in (0, 3) for z in (0, 2)]
    >>> tris = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
    ...         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    >>> bool(squeeze_topples(box, tris, (2, 1.5, 1), (0, 0, -1), 0.3))
    False
    """
    nrm = _unit_normals(normal, "normal")[0]
    angle = _number(gripper_angle, "gripper_angle", -math.inf)
    jaw_h = _number(jaw_height, "jaw_height", 0.0, 1.0)
    mu = _number(friction, "friction", 0.0)
    off = _number(push, "push", -1.0, 1.0, open_low=False)
    tilt_limit = _number(tilt_limit_deg, "tilt_limit_deg", 0.0, 90.0)
    body = mesh_body(vertices, faces, com, size)
    v_local = finite_array(vertices, "vertices", (None, 3))
    c_local = finite_array(com, "com", (3,))
    predicted = static_topples(
        v_local, c_local, nrm, angle, jaw_height=jaw_h, friction=mu, push=off
    )
    mujoco = require_mujoco()
    from scipy.spatial.transform import Rotation

    rot = _placed(nrm, angle)
    p = body.points @ rot.T  # (H, 3) hull about the centre of mass, world axes
    height = float(np.ptp(p[:, 2]))
    width = float(np.ptp(p[:, 0]))
    weight = body.mass * _GRAVITY
    pad = {
        "t": 0.002,
        "l": float(np.ptp(p[:, :2], axis=0).max()) + 0.01,
        "hz": min(0.0015, 0.5 * jaw_h * height),
        "mass": 0.01,
        "damping": 2.0,
        "kp": 200.0,
        "force": 3.0 * weight,
    }
    pad["z"] = max(jaw_h * height, pad["hz"] + 0.0005)
    s = dict(DROP_DEFAULTS, friction=mu)
    model = mujoco.MjModel.from_xml_string(_squeeze_xml(body, s, pad))
    data = mujoco.MjData(model)
    shift = 0.5 * off * float(np.ptp(body.points, axis=0).max())
    shift -= 0.5 * float(p[:, 0].max() + p[:, 0].min())  # the x-extent's centre, moved
    data.qpos[:3] = (shift, 0.0, -float(p[:, 2].min()) + 1e-5)
    data.qpos[3:7] = Rotation.from_matrix(rot).as_quat()[[3, 0, 1, 2]]
    reach = 0.5 * width + abs(shift) + pad["t"] + 0.002  # jaws start symmetric about x = 0
    lo0, hi0 = -reach, reach
    jlo, jhi = model.joint("lo").qposadr[0], model.joint("hi").qposadr[0]
    data.qpos[jlo], data.qpos[jhi] = lo0, hi0
    mujoco.mj_forward(model, data)
    down = np.array([0.0, 0.0, -1.0])
    speed, dt = 0.01, s["timestep"]
    chunk = 10
    steps = math.ceil(10.0 / (chunk * dt))
    hold = math.ceil(0.1 / (chunk * dt))
    still = 0
    settled = False
    max_tilt = 0.0
    tilt = 0.0
    for i in range(steps):
        t = (i + 1) * chunk * dt
        data.ctrl[0] = min(lo0 + speed * t, 0.0)
        data.ctrl[1] = max(hi0 - speed * t, 0.0)
        mujoco.mj_step(model, data, chunk)
        world_n = data.xmat[1].reshape(3, 3) @ nrm
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, float(world_n @ down)))))
        max_tilt = max(max_tilt, tilt)
        slow = abs(data.qvel[model.joint("lo").dofadr[0]]) < 1e-4
        slow = slow and abs(data.qvel[model.joint("hi").dofadr[0]]) < 1e-4
        blocked = data.ctrl[0] - data.qpos[jlo] > 1e-3 and data.qpos[jhi] - data.ctrl[1] > 1e-3
        still = still + 1 if slow and blocked else 0
        if still >= hold:
            settled = True
            break
        if tilt > 60.0:  # fallen over: nothing the jaws do now restores the pose
            break
    return SqueezeCheck(max_tilt > tilt_limit, tilt, max_tilt, settled, predicted)
