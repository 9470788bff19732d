r"""Resting poses of a solid on a table: the quasi-static estimator and its perturbed form.

The model (Goldberg, Mirtich, Zhuang, Craig, Carlisle, Canny, *Part pose statistics:
estimators and experiments*, IEEE T-RA 15(5), 1999). A part falls from an orientation
drawn uniformly at random and has no energy left when it touches the table:

1. *First contact.* The part touches the table with the face of its convex hull that the
   downward ray from the centre of mass ``c`` meets. Under a uniform orientation that ray's
   direction is uniform on the sphere, so hull face ``F`` is hit first with probability
   ``Omega_F / 4 pi``, where ``Omega_F`` is the solid angle ``F`` subtends at ``c``.
2. *Toppling.* Resting on ``F``, the part is stable when the projection ``p`` of ``c`` on
   ``F``'s plane lies strictly inside ``F``. Otherwise it rolls over an edge of ``F``: the
   edge crossed by the segment from ``F``'s area centroid to ``p``, onto the hull face
   across that edge. The height of ``c`` above the table falls strictly with each roll (the
   centre of mass lies beyond the edge's vertical plane, and rolling onto the next face turns
   it further down), so the walk ends on a stable face.

The probability of a stable pose is the sum of ``Omega_F / 4 pi`` over the faces whose walk
ends on it. *Faces* are hull facets: coplanar hull triangles are merged into one polygon
first (Qhull merges facets within its rounding error), so the answer does not depend on how
the mesh or the hull is triangulated. The solid angle of a face is the sum of its triangles'
(Van Oosterom and Strackee, *The solid angle of a plane triangle*, IEEE T-BME 30(2), 1983):

.. math::

    \tan \frac{\Omega}{2} = \frac{|a \cdot (b \times d)|}
        {|a| |b| |d| + (a \cdot b) |d| + (a \cdot d) |b| + (b \cdot d) |a|}

for the triangle's corners ``a, b, d`` taken from ``c``, summed exactly to rounding (the
triangles of a face tile it and do not overlap, so their solid angles add).

The *perturbed* estimator here is trimesh's form (``trimesh.poses.compute_stable_poses``
with its ``sigma`` and ``n_samples``): the Monte Carlo average of the quasi-static
probabilities over ``samples`` centres of mass drawn from the isotropic normal distribution
:math:`N(c, s^2 I)`, :math:`s` = ``sigma`` times the part's size (its largest distance from
the mean of its points; trimesh's ``sigma`` is the covariance :math:`s^2` in the mesh's
units), a draw outside the hull discarded and drawn again. The tests check it against
trimesh's own sampler. It is *not* verified to be the paper's perturbed quasi-static
estimator: the paper describes that one as taking "a measure of dynamic stability based on
perturbation" into account with the quasi-static estimator's :math:`O(n \log n)` time, a
deterministic computation, where this one is a sampled average. It blurs the sharp
boundaries of the quasi-static model: a face whose centre-of-mass projection lies near an
edge shares its probability with its neighbour.

Each stable pose has a planar frame: ``z`` points up (minus the face's outward normal), ``x``
is the mesh axis most parallel to the table projected on it, ``y = z x x``, and the origin
is the centre of mass's projection. Its *footprint* is the convex hull of the solid
projected on the table in that frame: the outline the jaws of a planar gripper meet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PartError

__all__ = [
    "ESTIMATORS",
    "HullFaces",
    "Pose",
    "PoseStudy",
    "footprint",
    "hull_faces",
    "pose_frame",
    "quasi_static",
    "resting_poses",
    "triangle_solid_angles",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

ESTIMATORS = ("quasi-static", "perturbed")
"""The pose estimators :func:`resting_poses` offers."""

_COPLANAR = 1e-9  # adjacent hull triangles whose unit normals differ by less are one face
_INSIDE = 1e-12  # a projection closer than this (x size) to a face's edge is not inside


@dataclass(frozen=True, slots=True, eq=False)
class HullFaces:
    """The convex hull of a point set as polygonal faces (coplanar triangles merged).

    Attributes
    ----------
    points : ndarray of shape (V, 3)
        The points the hull was built from (indices below refer to them).
    triangles : ndarray of shape (T, 3)
        The hull's triangles, counter-clockwise seen from outside.
    face_of : ndarray of shape (T,)
        The face each triangle belongs to.
    normals : ndarray of shape (F, 3)
        Outward unit normal of each face.
    offsets : ndarray of shape (F,)
        ``normals[f] . x = offsets[f]`` on face ``f``'s plane (inside: less).
    edges : ndarray of shape (E, 2)
        The faces' boundary edges, directed counter-clockwise about their face's normal.
    edge_face, edge_neighbour : ndarray of shape (E,)
        The face an edge bounds, and the face across it.
    size : float
        The largest distance of a point from the points' mean (the length scale).
    """

    points: FloatArray
    triangles: IntArray
    face_of: IntArray
    normals: FloatArray
    offsets: FloatArray
    edges: IntArray
    edge_face: IntArray
    edge_neighbour: IntArray
    size: float

    @property
    def n_faces(self) -> int:
        """Number of faces ``F``."""
        return len(self.normals)

    def face_loop(self, f: int) -> IntArray:
        """The vertices of face ``f`` in order, counter-clockwise about its outward normal.

        Examples
        --------
        >>> cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
        >>> h = hull_faces(cube)
        >>> h.n_faces, len(h.face_loop(0))
        (6, 4)
        """
        mine = np.flatnonzero(self.edge_face == f)
        nxt = {int(a): int(b) for a, b in self.edges[mine]}
        start = int(self.edges[mine[0], 0])
        loop = [start]
        while (v := nxt[loop[-1]]) != start:
            loop.append(v)
        return np.array(loop, dtype=np.intp)


def hull_faces(points: ArrayLike) -> HullFaces:
    """The convex hull of 3-D points, coplanar hull triangles merged into polygonal faces.

    Parameters
    ----------
    points : array_like of shape (V, 3)

    Returns
    -------
    HullFaces

    Raises
    ------
    PartError
        Fewer than four points, non-finite coordinates, or points that span no volume.

    Examples
    --------
    >>> tet = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    >>> hull_faces(tet).n_faces
    4
    """
    from scipy.spatial import ConvexHull, QhullError

    pts = np.array(points, dtype=np.float64)  # a copy: it is kept, read-only
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 4:
        raise PartError(f"`points` must have shape (V, 3) with V >= 4; got shape {pts.shape}")
    if not np.isfinite(pts).all():
        raise PartError("`points` must be finite; got NaN or infinite coordinates")
    size = float(np.max(np.linalg.norm(pts - pts.mean(axis=0), axis=1)))
    try:
        hull = ConvexHull(pts)
    except QhullError:
        raise PartError("the points span no volume (they lie on a plane or a line)") from None
    if hull.volume <= 1e-12 * size**3:
        raise PartError("the points span no volume (they lie on a plane or a line)")
    tri = np.array(hull.simplices, dtype=np.intp)  # (T, 3), orientation arbitrary
    eq = np.array(hull.equations, dtype=np.float64)  # (T, 4): n . x + d = 0, n outward
    n = eq[:, :3]
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), n) < 0
    tri[flip] = tri[flip][:, ::-1]
    # Adjacent triangles with the same plane are one face: connected components.
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    t = len(tri)
    nb = np.array(hull.neighbors, dtype=np.intp)  # (T, 3)
    rows = np.repeat(np.arange(t), 3)
    cols = nb.ravel()
    same = np.linalg.norm(n[rows] - n[cols], axis=1) < _COPLANAR
    same &= np.abs(eq[rows, 3] - eq[cols, 3]) < _COPLANAR * max(size, 1e-300) + 1e-300
    graph = coo_matrix((np.ones(int(same.sum())), (rows[same], cols[same])), shape=(t, t))
    n_faces, face_of = connected_components(graph, directed=False)
    face_of = face_of.astype(np.intp)
    # Face planes: area-weighted normals (all equal within the merge tolerance).
    area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    normals: FloatArray = np.stack(
        [np.bincount(face_of, weights=n[:, k] * area2, minlength=n_faces) for k in range(3)],
        axis=1,
    ).astype(np.float64)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    # The plane's offset: the largest over the face's corners (its support value, to rounding).
    fn = normals[face_of]  # (T, 3)
    corner = np.max(np.stack([np.einsum("ij,ij->i", fn, x) for x in (a, b, c)]), axis=0)
    order_f = np.argsort(face_of, kind="stable")
    starts = np.searchsorted(face_of[order_f], np.arange(n_faces))
    offsets = np.maximum.reduceat(corner[order_f], starts)
    # Directed edges (a, b) of every triangle; an edge is on its face's boundary when the
    # reverse edge (b, a) belongs to a triangle of another face.
    src = tri.ravel()
    dst = tri[:, [1, 2, 0]].ravel()
    owner = np.repeat(face_of, 3)
    v = len(pts)
    key = src * v + dst
    order = np.argsort(key)
    pos = np.searchsorted(key[order], dst * v + src)
    across = owner[order[np.minimum(pos, len(key) - 1)]]
    boundary = across != owner
    edges = np.stack([src[boundary], dst[boundary]], axis=1)
    return HullFaces(
        _frozen(pts),
        _frozen(tri),
        _frozen(face_of),
        _frozen(normals),
        _frozen(offsets),
        _frozen(edges),
        _frozen(owner[boundary]),
        _frozen(across[boundary]),
        size,
    )


_A = TypeVar("_A", bound=NDArray[Any])


def _frozen(a: _A) -> _A:
    a.setflags(write=False)
    return a


def triangle_solid_angles(triangles: ArrayLike, apex: ArrayLike) -> FloatArray:
    """Solid angle of each triangle seen from ``apex`` (Van Oosterom and Strackee, 1983).

    Parameters
    ----------
    triangles : array_like of shape (T, 3, 3)
    apex : array_like of shape (3,)

    Returns
    -------
    ndarray of shape (T,)
        Steradians, in ``[0, 2 pi]``.

    Examples
    --------
    >>> tri = [[[1, 0, 0], [0, 1, 0], [0, 0, 1]]]  # an octant's face
    >>> float(triangle_solid_angles(tri, [0, 0, 0])[0] / (4 * np.pi))
    0.125
    """
    t = np.asarray(triangles, dtype=np.float64) - np.asarray(apex, dtype=np.float64)
    a, b, d = t[:, 0], t[:, 1], t[:, 2]
    la, lb, ld = (np.linalg.norm(x, axis=1) for x in (a, b, d))
    num = np.abs(np.einsum("ij,ij->i", a, np.cross(b, d)))
    den = (
        la * lb * ld
        + np.einsum("ij,ij->i", a, b) * ld
        + np.einsum("ij,ij->i", a, d) * lb
        + np.einsum("ij,ij->i", b, d) * la
    )
    return np.asarray(2.0 * np.arctan2(num, den), dtype=np.float64)


def _inside(hull: HullFaces, com: FloatArray) -> bool:
    """Whether ``com`` lies strictly inside the hull (by more than the tolerance)."""
    return bool(np.all(hull.normals @ com - hull.offsets < -_INSIDE * hull.size))


def quasi_static(hull: HullFaces, com: ArrayLike) -> tuple[FloatArray, IntArray]:
    """First-contact probabilities of the hull's faces and the stable face each rolls to.

    Parameters
    ----------
    hull : HullFaces
    com : array_like of shape (3,)
        The centre of mass, strictly inside the hull.

    Returns
    -------
    first : ndarray of shape (F,)
        ``Omega_F / 4 pi``: the probability that face ``F`` touches the table first.
    rest : ndarray of shape (F,)
        The stable face the part rests on after landing on each face (a stable face maps to
        itself).

    Raises
    ------
    PartError
        The centre of mass is not strictly inside the hull.

    Examples
    --------
    >>> box = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 4)], float)
    >>> first, rest = quasi_static(hull_faces(box), [0.5, 1, 2])
    >>> round(float(first.sum()), 12), sorted(set(rest.tolist())) == list(range(6))
    (1.0, True)
    """
    c = np.asarray(com, dtype=np.float64)
    if c.shape != (3,) or not np.isfinite(c).all():
        raise PartError(f"`com` must be three finite numbers; got {com!r}")
    if not _inside(hull, c):
        raise PartError(
            "the centre of mass "
            + ", ".join(f"{x:.6g}" for x in c)
            + " is not strictly inside the convex hull"
        )
    pts = hull.points
    omega = triangle_solid_angles(pts[hull.triangles], c)  # (T,)
    first = np.bincount(hull.face_of, weights=omega, minlength=hull.n_faces) / (4 * math.pi)
    # Projection of c on each face's plane, and each face's area centroid.
    h = hull.offsets - hull.normals @ c  # (F,) height of c above each face
    proj = c + h[:, None] * hull.normals  # (F, 3)
    a, b, d = (pts[hull.triangles[:, i]] for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, d - a), axis=1)
    total = np.bincount(hull.face_of, weights=area, minlength=hull.n_faces)
    cen = (
        np.stack(
            [
                np.bincount(
                    hull.face_of, weights=area * (a + b + d)[:, k] / 3, minlength=hull.n_faces
                )
                for k in range(3)
            ],
            axis=1,
        )
        / total[:, None]
    )  # (F, 3)
    # Signed distance of the projection (and of the centroid) to each boundary edge's line,
    # positive inside the face: s = ((q - p0) x (p1 - p0)) . (-n) / |p1 - p0|.
    f = hull.edge_face
    p0, p1 = pts[hull.edges[:, 0]], pts[hull.edges[:, 1]]
    along = p1 - p0
    inward = np.cross(hull.normals[f], along)  # points into the face
    inward /= np.linalg.norm(inward, axis=1)[:, None]
    s_p = np.einsum("ij,ij->i", proj[f] - p0, inward)  # (E,)
    s_g = np.einsum("ij,ij->i", cen[f] - p0, inward)
    outside = s_p <= _INSIDE * hull.size
    stable = np.bincount(f, weights=outside, minlength=hull.n_faces) == 0
    # The exit edge of the segment centroid -> projection: the first edge line it crosses.
    t = np.full(len(f), np.inf)
    go = outside & (s_p < s_g)  # the centroid is inside (s_g > 0): the segment exits here
    t[go] = s_g[go] / (s_g[go] - s_p[go])
    order = np.lexsort((np.arange(len(f)), t, f))  # by face, then t, then edge index
    firsts = order[np.r_[True, f[order][1:] != f[order][:-1]]]
    step = np.arange(hull.n_faces, dtype=np.intp)
    unstable = ~stable[f[firsts]]
    step[f[firsts][unstable]] = hull.edge_neighbour[firsts][unstable]
    rest = step.copy()
    for _ in range(hull.n_faces.bit_length() + 2):  # pointer jumping to the fixed points
        nxt = rest[rest]
        if np.array_equal(nxt, rest):
            break
        rest = nxt
    if not np.all(stable[rest]):  # a cycle: only rounding could make one
        raise PartError("the topple walk did not end on a stable face (a degenerate hull)")
    return first, rest


def pose_frame(normal: ArrayLike) -> FloatArray:
    """The planar frame of a pose resting on the face with outward unit ``normal``.

    Rows ``x, y, z`` (mesh coordinates): ``z = -normal`` points up from the table, ``x`` is
    the mesh axis most parallel to the table (the first of x, y, z on ties) projected on it,
    ``y = z x x``. ``frame @ (p - c)`` gives a point's pose coordinates about ``c``.

    Examples
    --------
    >>> pose_frame([0, 0, -1]).tolist()  # resting on the bottom face: the mesh's own frame
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    z = -np.asarray(normal, dtype=np.float64)
    z = z / np.linalg.norm(z)
    axis = int(np.argmin(np.round(np.abs(z), 12)))
    e = np.zeros(3)
    e[axis] = 1.0
    x = e - (e @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.stack([x, y, z]) + 0.0  # + 0.0: no negative zeros


def footprint(points: ArrayLike, frame: ArrayLike, origin: ArrayLike) -> FloatArray:
    """Convex hull of ``points`` projected on the table, in the pose's planar frame.

    Parameters
    ----------
    points : array_like of shape (V, 3)
    frame : array_like of shape (3, 3)
        :func:`pose_frame`.
    origin : array_like of shape (3,)
        The point that is the frame's origin (the centre of mass).

    Returns
    -------
    ndarray of shape (K, 2)
        Counter-clockwise, no repeated vertex.

    Examples
    --------
    >>> box = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 4)], float)
    >>> footprint(box, pose_frame([0, 0, -1]), [0.5, 1, 2]).tolist()
    [[-0.5, -1.0], [0.5, -1.0], [0.5, 1.0], [-0.5, 1.0]]
    """
    from scipy.spatial import ConvexHull

    from ..geometry.polygon import ConvexPolygon

    xy = (np.asarray(points, dtype=np.float64) - np.asarray(origin, dtype=np.float64)) @ (
        np.asarray(frame, dtype=np.float64)[:2].T
    )
    if len(xy) > 64:  # Qhull's 2-D hull first: the exact hull below then sees few points
        xy = xy[ConvexHull(xy, qhull_options="Qc").vertices]
    # The planar hull drops points within its length tolerance of an edge (a point on a
    # solid's edge projects onto the footprint's edge, to rounding).
    ring = np.array(ConvexPolygon.from_points(xy).vertices)  # counter-clockwise
    scale = float(np.max(np.abs(ring))) or 1.0
    key = np.round(ring / scale, 9)
    start = int(np.lexsort((key[:, 0], key[:, 1]))[0])  # lowest, then leftmost, first
    return np.asarray(np.roll(ring, -start, axis=0) + 0.0, dtype=np.float64)


@dataclass(frozen=True, slots=True, eq=False)
class Pose:
    """One stable resting pose.

    Attributes
    ----------
    probability : float
    face : int
        The supporting face (:class:`HullFaces` index).
    normal : ndarray of shape (3,)
        Outward unit normal of the supporting face, mesh coordinates.
    com_height : float
        Height of the centre of mass above the table.
    frame : ndarray of shape (3, 3)
        :func:`pose_frame`: rows ``x, y, z`` of the pose's frame in mesh coordinates.
    footprint : ndarray of shape (K, 2)
        The solid's hull projected on the table, in the frame, about the centre of mass.
    """

    probability: float
    face: int
    normal: FloatArray
    com_height: float
    frame: FloatArray
    footprint: FloatArray


@dataclass(frozen=True, slots=True, eq=False)
class PoseStudy:
    """The stable poses of a solid, most probable first.

    Attributes
    ----------
    poses : tuple of Pose
    center_of_mass : ndarray of shape (3,)
    estimator : str
        ``"quasi-static"`` or ``"perturbed"`` (:data:`ESTIMATORS`).
    hull : HullFaces
    first_contact : ndarray of shape (F,)
        Quasi-static first-contact probability of each hull face.
    """

    poses: tuple[Pose, ...]
    center_of_mass: FloatArray
    estimator: str
    hull: HullFaces
    first_contact: FloatArray

    @property
    def probabilities(self) -> FloatArray:
        """The poses' probabilities, in order."""
        return np.array([p.probability for p in self.poses])

    @property
    def normals(self) -> FloatArray:
        """The poses' supporting normals, shape (k, 3), in order."""
        return np.array([p.normal for p in self.poses]).reshape(-1, 3)


def resting_poses(
    points: ArrayLike | HullFaces,
    com: ArrayLike,
    *,
    estimator: Literal["quasi-static", "perturbed"] = "quasi-static",
    sigma: float = 0.02,
    samples: int = 200,
    rng: np.random.Generator | int | None = None,
) -> PoseStudy:
    """The stable resting poses of a solid and their probabilities (module notes).

    Parameters
    ----------
    points : array_like of shape (V, 3) or HullFaces
        The solid's vertices (only their hull matters), or its hull.
    com : array_like of shape (3,)
        Centre of mass, strictly inside the hull.
    estimator : {"quasi-static", "perturbed"}
        Exact quasi-static probabilities, or their average over perturbed centres of mass.
    sigma : float
        Perturbed: standard deviation of the centre of mass, as a fraction of the part's
        size (its largest distance from the mean of its points).
    samples : int
        Perturbed: number of centres of mass drawn.
    rng : numpy.random.Generator or int, optional
        Perturbed: the draws' randomness.

    Returns
    -------
    PoseStudy
        Poses sorted by probability, descending (ties: by normal, lexicographic).

    Raises
    ------
    PartError
        A degenerate hull, a centre of mass outside it, or bad estimator settings.

    Examples
    --------
    >>> cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    >>> study = resting_poses(cube, [0.5, 0.5, 0.5])
    >>> len(study.poses), [round(p.probability, 12) for p in study.poses][:2]
    (6, [0.166666666667, 0.166666666667])
    """
    hull = points if isinstance(points, HullFaces) else hull_faces(points)
    c = np.asarray(com, dtype=np.float64)
    first, rest = quasi_static(hull, c)
    mass: FloatArray = np.bincount(rest, weights=first, minlength=hull.n_faces).astype(float)
    if estimator == "perturbed":
        if not (math.isfinite(sigma) and sigma > 0):
            raise PartError(f"`sigma` must be a number > 0; got {sigma!r}")
        if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
            raise PartError(f"`samples` must be an integer >= 1; got {samples!r}")
        gen = np.random.default_rng(rng)
        mass = np.zeros(hull.n_faces)
        kept = 0
        while kept < samples:
            for cc in gen.normal(c, sigma * hull.size, size=(samples - kept, 3)):
                if not _inside(hull, cc):
                    continue
                f1, r1 = quasi_static(hull, cc)
                mass += np.bincount(r1, weights=f1, minlength=hull.n_faces)
                kept += 1
        mass /= samples
    elif estimator != "quasi-static":
        raise PartError(f"`estimator` must be one of {', '.join(ESTIMATORS)}; got {estimator!r}")
    faces = np.flatnonzero(mass > 0)
    # Most probable first; ties (to rounding) by the normal, so no triangulation decides.
    nr = np.round(hull.normals[faces], 9)
    faces = faces[np.lexsort((nr[:, 2], nr[:, 1], nr[:, 0], -np.round(mass[faces], 12)))]
    corners = hull.points[np.unique(hull.triangles)]
    poses = []
    for f in faces.tolist():
        normal = np.array(hull.normals[f])
        frame = pose_frame(normal)
        poses.append(
            Pose(
                probability=float(mass[f]),
                face=int(f),
                normal=_frozen(normal),
                com_height=float(hull.offsets[f] - normal @ c),
                frame=_frozen(frame),
                footprint=_frozen(footprint(corners, frame, c)),
            )
        )
    return PoseStudy(tuple(poses), _frozen(c.copy()), estimator, hull, _frozen(first))
