"""The MuJoCo scene of a squeeze, as an MJCF string (no MuJoCo import needed here).

World frame = gripper frame: the jaws close along x. The part is its convex hull extruded
into a prism (the jaws only ever touch the hull), with its body frame at the part's centre of
mass and its yaw equal to the orientation ``theta`` of the design notes (the user's
coordinates are not rotated). Contacts:

- part-table: friction ``table_friction`` (support friction, as on a real table);
- part-jaw: frictionless. The jaw geoms have ``condim="1"`` *and* ``priority="1"``: with
  equal priority MuJoCo takes the larger friction of the two geoms, so without the priority
  the jaws grip (physics notes: 137/183 agreement instead of 183/183). The jaws touch thin
  vertical capsules at the hull's vertices, not the mesh: a flat jaw touches a convex part
  only at vertices, a capsule's contact normal is the jaw's face normal, and the capsules
  add ``2 * edge_radius`` to every width, which moves no extremum of the diameter (or
  radius) function. Against the mesh, MuJoCo's convex collider sometimes returned the
  normal of a part edge a few degrees from the jaw, whose sideways force pushed the part
  out between the jaws (the ``example`` part: 199 jams in 200 trials);
- jaw-table: none (contact bit masks), the jaws hover 1 mm above the table (less under
  a thin part).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import PartError
from ..geometry.polygon import Part
from .params import SimParams

__all__ = ["Prism", "part_inertia", "prism", "scene_xml", "units_scale"]

FloatArray = NDArray[np.float64]

#: Metres per unit for the units a part file may give.
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "um": 1e-6, "in": 0.0254, "inch": 0.0254, "ft": 0.3048}


def units_scale(units: str | None) -> float:
    """Metres per unit of a part's coordinates (``None``: metres).

    Examples
    --------
    >>> units_scale("mm"), units_scale(None)
    (0.001, 1.0)
    """
    if units is None:
        return 1.0
    key = units.strip().lower()
    if key not in UNITS:
        raise PartError(f"unknown units {units!r}; expected one of {', '.join(sorted(UNITS))}")
    return UNITS[key]


def part_inertia(
    vertices: FloatArray, com: FloatArray, thickness: float, density: float
) -> tuple[float, FloatArray]:
    """Mass and diagonal inertia (about the centre of mass) of the extruded hull.

    The hull's uniform-density moments (shoelace sums) are shifted to ``com`` by the
    parallel-axis rule; a centre of mass away from the centroid changes the yaw inertia
    that way (its other effects on a squeeze are nil: jaws meet the hull, not the mass).

    Parameters
    ----------
    vertices : ndarray of shape (N, 2)
        Counter-clockwise hull, metres.
    com : ndarray of shape (2,)
    thickness, density : float

    Returns
    -------
    mass : float
    diaginertia : ndarray of shape (3,)

    Examples
    --------
    >>> sq = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    >>> m, inertia = part_inertia(sq, np.array([0.5, 0.5]), 0.1, 10.0)
    >>> round(m, 9), np.round(inertia, 9).tolist()
    (1.0, [0.084166667, 0.084166667, 0.166666667])
    """
    p = vertices
    q = np.roll(p, -1, axis=0)
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]  # (N,)
    area = 0.5 * float(cross.sum())
    c = ((p + q) * cross[:, None]).sum(axis=0) / (6.0 * area)
    r, s = p - c, q - c
    cr = r[:, 0] * s[:, 1] - s[:, 0] * r[:, 1]
    ixx = float((cr * (r[:, 1] ** 2 + r[:, 1] * s[:, 1] + s[:, 1] ** 2)).sum()) / 12.0  # int y^2
    iyy = float((cr * (r[:, 0] ** 2 + r[:, 0] * s[:, 0] + s[:, 0] ** 2)).sum()) / 12.0  # int x^2
    mass = density * thickness * area
    dx, dy = (np.asarray(com) - c).tolist()
    lam = density * thickness
    out = np.array(
        [
            lam * ixx + mass * thickness**2 / 12.0 + mass * dy * dy,
            lam * iyy + mass * thickness**2 / 12.0 + mass * dx * dx,
            lam * (ixx + iyy) + mass * (dx * dx + dy * dy),
        ]
    )
    return mass, out


@dataclass(frozen=True, slots=True, eq=False)
class Prism:
    """The part as a body: hull in the body frame (metres), thickness, mass, jaw force.

    Attributes
    ----------
    vertices : ndarray of shape (N, 2)
        Hull vertices relative to the centre of mass (the body frame's origin).
    thickness : float
        ``SimParams.thickness``, or half the part's least width if that is smaller (a prism
        taller than it is wide would tip over between the jaws).
    mass : float
    inertia : ndarray of shape (3,)
        Diagonal inertia about the centre of mass.
    size : float
        Largest distance of a vertex from the centre of mass.
    force, kp, damping : float
        Each jaw's force limit, position gain and joint damping (:meth:`SimParams.jaw_gains`).
    """

    vertices: FloatArray
    thickness: float
    mass: float
    inertia: FloatArray
    size: float
    force: float
    kp: float
    damping: float


def prism(part: Part, scale: float, params: SimParams | None = None) -> Prism:
    """The extruded hull of a part, in metres, with its mass properties.

    Examples
    --------
    >>> body = prism(Part.from_points([(0, 0), (40, 0), (10, 30)]), 0.001)
    >>> round(body.mass, 6), body.thickness, round(body.force, 4)
    (0.006, 0.01, 0.4709)
    """
    if not (math.isfinite(scale) and scale > 0):
        raise PartError(f"`scale` must be a finite number > 0 (metres per unit); got {scale!r}")
    sp = params or SimParams()
    com = np.asarray(part.center_of_mass, dtype=np.float64) * scale
    from ..geometry.curved import mesh_vertices

    rel = mesh_vertices(part) * scale - com  # (N, 2) body frame (arcs finely sampled)
    # Least width of the hull: the smallest extent over its edge normals.
    e = np.roll(rel, -1, axis=0) - rel
    nrm = np.column_stack([e[:, 1], -e[:, 0]]) / np.hypot(e[:, 0], e[:, 1])[:, None]
    proj = rel @ nrm.T  # (N, N) projections on each edge normal
    width = float(np.min(proj.max(axis=0) - proj.min(axis=0)))
    h = min(sp.thickness, 0.5 * width)
    mass, inertia = part_inertia(rel, np.zeros(2), h, sp.density)
    size = float(np.max(np.hypot(rel[:, 0], rel[:, 1])))
    return Prism(rel, h, mass, inertia, size, *sp.jaw_gains(mass))


def _fmt(values: FloatArray | list[float]) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.ravel(values))


def scene_xml(part: Part, scale: float, params: SimParams | None = None) -> str:
    """MJCF of the table, the part and the two jaws.

    Parameters
    ----------
    part : Part
    scale : float
        Metres per unit of the part's coordinates (:func:`units_scale`).
    params : SimParams, optional

    Returns
    -------
    str
        The model. Joints: ``part`` (free), ``jaw_neg`` and ``jaw_pos`` (x slides whose
        position is the x of the jaw's inner face); actuators of the same names.

    Examples
    --------
    >>> xml = scene_xml(Part.from_points([(0, 0), (40, 0), (10, 30)]), 0.001)
    >>> 'priority="1"' in xml and 'condim="1"' in xml
    True
    """
    sp = params or SimParams()
    body = prism(part, scale, sp)
    rel, h, size, force = body.vertices, body.thickness, body.size, body.force
    mass, inertia = body.mass, body.inertia
    pts = np.concatenate(
        [np.column_stack([rel, np.zeros(len(rel))]), np.column_stack([rel, np.full(len(rel), h)])]
    )
    jaw_half = 0.5 * max(sp.jaw_length, 4.0 * size)
    t = sp.jaw_thickness
    gap = min(0.001, 0.25 * h)  # the jaws hover this far above the table
    jaw_h = 0.5 * (h - gap + 0.003)  # half-height: up to 3 mm above the part
    jaw_z = gap + jaw_h
    rc = min(sp.edge_radius, 0.25 * h)
    capsules = "\n".join(
        f'      <geom name="vertex{i}" type="capsule" size="{rc:.9g}" '
        f'fromto="{x:.9g} {y:.9g} {rc:.9g} {x:.9g} {y:.9g} {h - rc:.9g}" '
        'mass="0" contype="2" conaffinity="2"/>'
        for i, (x, y) in enumerate(rel)
    )
    tc = sp.solref_timeconst
    fr = sp.table_friction
    # The jaws' mass scales with their force (as gain and damping do): the same motion,
    # time constant jaw_mass / jaw_damping, for every part.
    jaw_mass = sp.jaw_mass * (body.force / sp.jaw_force if sp.scale_jaw_mass else 1.0)
    return f"""<mujoco model="bayesgrasp-squeeze">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{sp.timestep:.9g}" integrator="{sp.integrator}" solver="{sp.solver}"
          cone="{sp.cone}" gravity="0 0 -9.81"/>
  <default>
    <geom solref="{tc:.9g} 1"/>
  </default>
  <asset>
    <mesh name="part" vertex="{_fmt(pts)}"/>
  </asset>
  <worldbody>
    <geom name="table" type="plane" size="1 1 0.01" contype="1" conaffinity="1"
          friction="{fr:.9g} 0.005 0.0001"/>
    <body name="part" pos="0 0 0">
      <freejoint name="part"/>
      <inertial pos="0 0 {h / 2:.9g}" mass="{mass:.9g}" diaginertia="{_fmt(inertia)}"/>
      <geom name="part" type="mesh" mesh="part" contype="1" conaffinity="1"
            friction="{fr:.9g} 0.005 0.0001"/>
{capsules}
    </body>
    <body name="jaw_neg" pos="0 0 {jaw_z:.9g}">
      <joint name="jaw_neg" type="slide" axis="1 0 0" damping="{body.damping:.9g}"/>
      <geom name="jaw_neg" type="box" pos="{-t / 2:.9g} 0 0" size="{t / 2:.9g} {jaw_half:.9g} \
{jaw_h:.9g}" mass="{jaw_mass:.9g}" condim="1" priority="1" contype="2" conaffinity="2"/>
    </body>
    <body name="jaw_pos" pos="0 0 {jaw_z:.9g}">
      <joint name="jaw_pos" type="slide" axis="1 0 0" damping="{body.damping:.9g}"/>
      <geom name="jaw_pos" type="box" pos="{t / 2:.9g} 0 0" size="{t / 2:.9g} {jaw_half:.9g} \
{jaw_h:.9g}" mass="{jaw_mass:.9g}" condim="1" priority="1" contype="2" conaffinity="2"/>
    </body>
  </worldbody>
  <actuator>
    <position name="jaw_neg" joint="jaw_neg" kp="{body.kp:.9g}"
              forcerange="{-force:.9g} {force:.9g}"/>
    <position name="jaw_pos" joint="jaw_pos" kp="{body.kp:.9g}"
              forcerange="{-force:.9g} {force:.9g}"/>
  </actuator>
</mujoco>
"""
