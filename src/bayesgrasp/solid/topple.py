r"""Which squeezes topple a resting part: the statics of a push at the jaws' height.

A squeeze closes two frictionless jaws on the part; one touches first and pushes the part
across the table until the other meets it. The push is a horizontal force :math:`F` at the
jaws' contact height :math:`h` above the table, along the closing direction :math:`u`. The
part (weight :math:`mg`, table friction :math:`\mu`) slides when :math:`F > \mu m g`; it
tips over the edge of its support that is farthest along :math:`u` when the moment of the
push about that edge beats the weight's, :math:`F h > m g\, l(u)`, with

.. math:: l(u) = \max_{s \in S} \langle s - c, u \rangle

the horizontal distance from the centre of mass's projection :math:`c` to that edge
(:math:`S` the support polygon, the hull's points on the table). As :math:`F` grows from
zero the first condition met wins, so the push tips the part before it slides exactly when

.. math:: \mu h > l(u)

(the sliding-versus-tipping test of a pushed block: Lynch, *Toppling manipulation*,
ICRA 1999, section 3; Mason, *Mechanics of Robotic Manipulation*, MIT Press 2001,
chapter 6). Either jaw may touch first (the part's place between them is unknown), so a
squeeze whose closing direction makes the angle :math:`\varphi` with the pose's planar x
axis may topple it when :math:`\mu h > \min(l(u), l(-u))`, :math:`u = (\cos\varphi,
\sin\varphi)`. Once both jaws touch, their forces are equal, opposite and at one height:
they add no moment, so only the first push can tip the part. Jaws higher than the part
touch its top: :math:`h` is the smaller of the jaws' height and the pose's height.

This is :func:`bayesgrasp.sim.drops.static_topples` for every angle and both jaws at once,
with the height in the part's units; :func:`bayesgrasp.sim.drops.squeeze_topples` checks it
in MuJoCo.

Examples
--------
>>> from bayesgrasp.solid.poses import resting_poses
>>> tall = np.array([[x, y, z] for x in (0, 10) for y in (0, 10) for z in (0, 60)], float)
>>> study = resting_poses(tall, [5, 5, 30])
>>> [round(p.com_height, 1) for p in study.poses]
[5.0, 5.0, 5.0, 5.0, 30.0, 30.0]
>>> topples = toppling_angles(study, 4, jaw_height=40.0)
>>> bool(topples.all()), bool(toppling_angles(study, 0, jaw_height=40.0).any())
(True, False)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from .poses import PoseStudy

__all__ = [
    "ANGLE_STEPS",
    "TABLE_FRICTION",
    "PoseToppling",
    "pose_levers",
    "toppling_angles",
    "toppling_report",
]

TABLE_FRICTION = 0.5
"""The table's friction coefficient the statics assume (as :func:`static_topples`)."""
ANGLE_STEPS = 3600
"""Closing directions checked per pose: every tenth of a degree of [0, 360)."""


def _pose_points(study: PoseStudy, k: int) -> tuple[NDArray[np.float64], float]:
    """Pose ``k``'s support points (planar frame, about the centre of mass) and its height."""
    pose = study.poses[k]
    rel = (study.hull.points - study.center_of_mass) @ pose.frame.T
    base = float(rel[:, 2].min())
    height = float(rel[:, 2].max()) - base
    support = rel[rel[:, 2] <= base + 1e-6 * max(height, 1e-300), :2]
    return support, height


def pose_levers(study: PoseStudy, k: int, angles: NDArray[np.float64]) -> NDArray[np.float64]:
    """``min(l(u), l(-u))`` for pose ``k`` at closing directions ``angles`` (radians).

    Examples
    --------
    >>> from bayesgrasp.solid.poses import resting_poses
    >>> box = np.array([[x, y, z] for x in (0, 4) for y in (0, 2) for z in (0, 1)], float)
    >>> study = resting_poses(box, [2, 1, 0.5])
    >>> pose_levers(study, 0, np.array([0.0, np.pi / 2])).round(6).tolist()
    [2.0, 1.0]
    """
    support, _ = _pose_points(study, k)
    u = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    proj = support @ u.T  # (S, A)
    return np.asarray(np.minimum(proj.max(axis=0), -proj.min(axis=0)), dtype=np.float64)


def toppling_angles(
    study: PoseStudy,
    k: int,
    jaw_height: float,
    friction: float = TABLE_FRICTION,
    steps: int = ANGLE_STEPS,
) -> NDArray[np.bool_]:
    """Whether a squeeze at each of ``steps`` closing directions may topple pose ``k``.

    Parameters
    ----------
    study : PoseStudy
    k : int
        The pose.
    jaw_height : float
        Height of the jaws' contact above the table, the part's units; 0: no push tips it.
    friction : float
        The table's friction coefficient.
    steps : int
        Directions ``2 pi i / steps`` in the pose's planar frame, ``i = 0 .. steps - 1``.

    Returns
    -------
    ndarray of bool, shape (steps,)
        ``friction * min(jaw_height, pose height) > min(l(u), l(-u))`` (module notes).
    """
    if not jaw_height > 0:
        return np.zeros(steps, dtype=bool)
    _, height = _pose_points(study, k)
    angles = 2 * np.pi * np.arange(steps) / steps
    h = min(float(jaw_height), height)
    return np.asarray(friction * h > pose_levers(study, k, angles), dtype=np.bool_)


@dataclass(frozen=True, slots=True)
class PoseToppling:
    """The squeezes that topple one pose.

    Attributes
    ----------
    pose : int
    fraction : float
        Share of closing directions (in the pose's planar frame) at which a squeeze may
        topple it; 0: none, 1: all.
    arcs : tuple of (float, float)
        Those directions as arcs ``(start, end)`` in degrees, counter-clockwise.
    """

    pose: int
    fraction: float
    arcs: tuple[tuple[float, float], ...]

    def describe(self) -> str:
        """The directions as text: ``"every closing direction"`` or the arcs in degrees.

        Examples
        --------
        >>> PoseToppling(0, 0.5, ((0.0, 89.9), (180.0, 269.9))).describe()
        'closing directions 0.0-89.9, 180.0-269.9 deg'
        """
        if self.fraction >= 1:
            return "every closing direction"
        return "closing directions " + ", ".join(f"{a:.1f}-{b:.1f}" for a, b in self.arcs) + " deg"


def _arcs(mask: NDArray[np.bool_]) -> tuple[tuple[float, float], ...]:
    n = len(mask)
    if mask.all() or not mask.any():
        return ((0.0, 360.0),) if mask.all() else ()
    start = int(np.argmin(mask))  # a direction that does not topple: arcs do not wrap past it
    rolled = np.roll(mask, -start)
    step = 360.0 / n
    out = []
    i = 0
    while i < n:
        if rolled[i]:
            j = i
            while j + 1 < n and rolled[j + 1]:
                j += 1
            out.append((((i + start) * step) % 360.0, ((j + start) * step) % 360.0))
            i = j + 1
        else:
            i += 1
    return tuple(sorted(out))


def toppling_report(
    study: PoseStudy, jaw_height: float, friction: float = TABLE_FRICTION
) -> list[PoseToppling]:
    """Every pose's toppling squeezes, in the study's order.

    Examples
    --------
    >>> from bayesgrasp.solid.poses import resting_poses
    >>> tall = np.array([[x, y, z] for x in (0, 10) for y in (0, 10) for z in (0, 60)], float)
    >>> [(r.pose, r.fraction) for r in toppling_report(resting_poses(tall, [5, 5, 30]), 40)]
    [(0, 0.0), (1, 0.0), (2, 0.0), (3, 0.0), (4, 1.0), (5, 1.0)]
    """
    out = []
    for k in range(len(study.poses)):
        mask = toppling_angles(study, k, jaw_height, friction)
        out.append(PoseToppling(k, float(mask.mean()), _arcs(mask)))
    return out
