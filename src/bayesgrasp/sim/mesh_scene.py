"""A solid part in MuJoCo: validation, mass properties and the MJCF of a mesh on a table.

No MuJoCo import is needed here. MuJoCo sees metres: the mesh is scaled uniformly so that
the longest side of its bounding box is ``size`` metres (5 cm unless told), whatever its
units, so a part drawn in millimetres, inches or metres behaves like a real hand-sized part.
Which face a part comes to rest on does not depend on its scale when the drop height scales
with it (the same motion, slower by the square root of the scale), so scaling loses nothing.

Contacts use the convex hull of the mesh (MuJoCo builds it from the vertices). That is exact
here, not an approximation: a table and a flat jaw plate touch a solid only on its hull, so a
non-convex part (an L-bracket, a nut) meets them as its hull does. Mass and inertia come from
the solid itself, not the hull (the divergence theorem over the closed triangle mesh,
Mirtich 1996, *Fast and accurate computation of polyhedral mass properties*), about the
centre of mass the caller gives; a centre of mass away from the solid's centroid (a loaded
part) keeps the uniform solid's inertia about its centroid, moved to the given point by the
parallel-axis theorem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import SimulationError

__all__ = ["MeshBody", "mass_properties", "mesh_body", "pose_frame", "rotation_between"]

FloatArray = NDArray[np.float64]

#: Density of the solid, kg/m^3 (a plastic part); the pose statistics do not depend on it.
DENSITY = 1200.0


def finite_array(value: ArrayLike, name: str, shape: tuple[int | None, ...]) -> FloatArray:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(f"`{name}` must be an array of numbers") from None
    if arr.ndim != len(shape) or any(
        s is not None and a != s for a, s in zip(arr.shape, shape, strict=True)
    ):
        want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise SimulationError(f"`{name}` must have shape {want}; got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SimulationError(f"`{name}` must be finite; got NaN or infinity")
    return arr


def mass_properties(vertices: ArrayLike, faces: ArrayLike) -> tuple[float, FloatArray, FloatArray]:
    """Volume, centroid and inertia tensor (unit density, about the centroid) of a closed mesh.

    Sums signed tetrahedra from the origin to each triangle: a tetrahedron with edge vectors
    ``A = [a b c]`` has volume ``det A / 6`` and second moment ``det A * A S A^T`` with
    ``S = (1 + I) / 120`` (ones plus identity), so the sums are exact for any closed,
    consistently oriented mesh, convex or not. Inward-facing meshes are turned outward.

    Parameters
    ----------
    vertices : array_like of shape (N, 3)
    faces : array_like of shape (M, 3)
        Vertex indices of each triangle.

    Returns
    -------
    volume : float
    centroid : ndarray of shape (3,)
    inertia : ndarray of shape (3, 3)
        About the centroid, for unit density.

    Examples
    --------
    >>> v = [(0, 0, 0), (2, 0, 0), (0, 2, 0), (2, 2, 0), (0, 0, 2), (2, 0, 2), (0, 2, 2), (2, 2, 2)]
    >>> f = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4),
    ...      (2, 6, 3), (3, 6, 7), (0, 4, 2), (2, 4, 6), (1, 3, 5), (3, 7, 5)]
    >>> vol, c, inertia = mass_properties(v, f)
    >>> float(vol), c.tolist(), np.round(np.diag(inertia), 6).tolist()  # 8 * (4 + 4) / 12
    (8.0, [1.0, 1.0, 1.0], [5.333333, 5.333333, 5.333333])
    """
    v = np.asarray(vertices, dtype=np.float64)
    tri = v[np.asarray(faces, dtype=np.int64)]  # (M, 3 corners, 3 coordinates)
    det = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))  # (M,)
    volume = float(det.sum() / 6.0)
    if volume < 0:
        det, volume = -det, -volume
    if volume <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    centroid = (det[:, None] * tri.sum(axis=1)).sum(axis=0) / (24.0 * volume)
    s = (np.ones((3, 3)) + np.eye(3)) / 120.0
    cov = np.einsum("m,mai,ab,mbj->ij", det, tri, s, tri)  # second moment about the origin
    cov -= volume * np.outer(centroid, centroid)
    inertia = np.trace(cov) * np.eye(3) - cov
    return volume, centroid, inertia


def rotation_between(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """The smallest rotation matrix taking unit vector ``a`` to unit vector ``b``.

    Opposite vectors turn by pi about an axis perpendicular to ``a``.

    Examples
    --------
    >>> np.round(rotation_between([0, 0, 1], [0, 0, -1]) @ [0, 0, 1], 12).tolist()
    [0.0, 0.0, -1.0]
    """
    u = np.asarray(a, dtype=np.float64)
    w = np.asarray(b, dtype=np.float64)
    u, w = u / np.linalg.norm(u), w / np.linalg.norm(w)
    v = np.cross(u, w)
    c = float(u @ w)
    if c < -1.0 + 1e-12:
        axis = np.cross(u, np.eye(3)[int(np.argmin(np.abs(u)))])
        axis /= np.linalg.norm(axis)
        flip: FloatArray = 2.0 * np.outer(axis, axis) - np.eye(3)
        return flip
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    rot: FloatArray = np.eye(3) + vx + vx @ vx / (1.0 + c)
    return rot


def pose_frame(normal: ArrayLike) -> FloatArray:
    """The planar frame of a part resting on the face with outward unit ``normal``.

    Rows ``x, y, z`` in mesh coordinates: ``z = -normal`` points up from the table, ``x`` is
    the mesh axis most parallel to the table (the first of x, y, z on ties) projected on it,
    ``y = z x x``; the frame of the pose's footprint, in which a gripper angle is measured.

    Examples
    --------
    >>> pose_frame([0, 0, -1]).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    z = -np.asarray(normal, dtype=np.float64)
    z = z / np.linalg.norm(z)
    e = np.zeros(3)
    e[int(np.argmin(np.round(np.abs(z), 12)))] = 1.0
    x = e - (e @ z) * z
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z]) + 0.0


@dataclass(frozen=True, slots=True, eq=False)
class MeshBody:
    """A validated solid, scaled to metres, about its centre of mass.

    Attributes
    ----------
    points : ndarray of shape (H, 3)
        The hull's vertices in metres, relative to the centre of mass (the body frame).
    mass : float
        Kilograms (``DENSITY`` times the solid's volume).
    inertia : ndarray of shape (3, 3)
        About the centre of mass, kg m^2.
    scale : float
        Metres per mesh unit.
    """

    points: FloatArray
    mass: float
    inertia: FloatArray
    scale: float

    def geom_xml(self, name: str, attrs: str) -> tuple[str, str]:
        """The ``<mesh>`` asset and the body's ``<inertial>`` and ``<geom>`` elements."""
        verts = " ".join(f"{x:.9g}" for x in self.points.ravel())
        i = self.inertia
        full = " ".join(f"{x:.9g}" for x in (i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]))
        asset = f'<mesh name="{name}" vertex="{verts}" maxhullvert="-1"/>'
        body = (
            f'<inertial pos="0 0 0" mass="{self.mass:.9g}" fullinertia="{full}"/>'
            f'<geom name="{name}" type="mesh" mesh="{name}" {attrs}/>'
        )
        return asset, body


def mesh_body(
    vertices: ArrayLike, faces: ArrayLike, com: ArrayLike, size: float | None = 0.05
) -> MeshBody:
    """Validate a closed mesh and its centre of mass; scale it for MuJoCo.

    Parameters
    ----------
    vertices : array_like of shape (N, 3)
        Mesh units.
    faces : array_like of shape (M, 3)
        Triangles (vertex indices) of a closed mesh.
    com : array_like of shape (3,)
        Centre of mass, mesh units; inside the hull.
    size : float or None
        Longest side of the bounding box, metres, after scaling; ``None`` takes the mesh
        units as metres.

    Returns
    -------
    MeshBody

    Raises
    ------
    SimulationError
        Bad shapes, NaN, indices out of range, zero volume, a centre of mass outside the
        hull, a size that is not a positive number.

    Examples
    --------
    >>> body = mesh_body([(0, 0, 0), (10, 0, 0), (0, 10, 0), (0, 0, 10)],
    ...                  [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)], (2.5, 2.5, 2.5))
    >>> round(body.scale, 6), body.points.shape
    (0.005, (4, 3))
    """
    from scipy.spatial import ConvexHull, QhullError

    v = finite_array(vertices, "vertices", (None, 3))
    c = finite_array(com, "com", (3,))
    try:
        f = np.asarray(faces)
    except (TypeError, ValueError):
        raise SimulationError("`faces` must be an array of vertex indices") from None
    if f.ndim != 2 or f.shape[1] != 3 or len(f) < 4:
        raise SimulationError(f"`faces` must have shape (M, 3) with M >= 4; got shape {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        raise SimulationError(f"`faces` must hold integer vertex indices; got dtype {f.dtype}")
    if f.min() < 0 or f.max() >= len(v):
        raise SimulationError(f"`faces` index vertices 0..{len(v) - 1}; got {f.min()}..{f.max()}")
    if size is not None and not (math.isfinite(size) and size > 0):
        raise SimulationError(f"`size` must be a finite number > 0 (metres) or None; got {size}")
    volume, centroid, inertia = mass_properties(v, f)
    extent = float(np.ptp(v, axis=0).max()) if len(v) else 0.0
    if not volume > 1e-12 * max(extent, 1e-300) ** 3:
        raise SimulationError("the mesh encloses no volume (is it closed?)")
    try:
        hull = ConvexHull(v)
    except QhullError:
        raise SimulationError("the mesh is flat: its hull has no volume") from None
    inside = hull.equations[:, :3] @ c + hull.equations[:, 3]
    if inside.max() > 1e-9 * extent:
        raise SimulationError(f"`com` {c.tolist()} lies outside the mesh's hull")
    scale = 1.0 if size is None else size / extent
    d = c - centroid  # parallel axis: the solid's inertia about the given centre of mass
    inertia_c = inertia + volume * (float(d @ d) * np.eye(3) - np.outer(d, d))
    mass = DENSITY * volume * scale**3
    points = (v[hull.vertices] - c) * scale
    return MeshBody(points, mass, DENSITY * inertia_c * scale**5, scale)
