"""A solid's resting poses as planar parts: each pose's footprint, as ``poses`` lists it.

Pose ``k`` (most probable first) is the planar :class:`~bayesgrasp.geometry.Part` whose
outline is the pose's footprint, in the pose's planar frame about the centre of mass
(:func:`bayesgrasp.solid.poses.pose_frame`): its centre of mass is the origin. A squeeze
keeps the pose, so planning a pose is planning that part.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..errors import PartError, PartFileError

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..io import ReadOptions
    from .mesh import Solid
    from .poses import PoseStudy

__all__ = ["mesh_part", "parse_com", "pose_index", "pose_part", "pose_parts"]


def parse_com(text: str | None) -> ArrayLike | None:
    """``--com X,Y,Z`` as three finite numbers (``None``: not given).

    Examples
    --------
    >>> parse_com("0.5, 1, 2")
    [0.5, 1.0, 2.0]
    """
    if text is None:
        return None
    try:
        xyz = [float(v) for v in text.split(",")]
    except ValueError:
        xyz = []
    if len(xyz) != 3 or not all(np.isfinite(xyz)):
        raise PartError(f"`--com` of a mesh must be X,Y,Z (three finite numbers); got {text!r}")
    return xyz


def pose_part(study: PoseStudy, k: int, name: str, units: str | None = None) -> Part:
    """Pose ``k``'s footprint as a planar part named ``name`` (centre of mass at the origin).

    Examples
    --------
    >>> from bayesgrasp.solid.poses import resting_poses
    >>> box = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 4)], float)
    >>> p = pose_part(resting_poses(box, [0.5, 1, 2]), 0, "pose-0")
    >>> p.name, p.hull.n_sides, p.center_of_mass.tolist()
    ('pose-0', 4, [0.0, 0.0])
    """
    from ..geometry.polygon import Part

    pose = study.poses[k]
    return Part.from_points(pose.footprint, name=name, center_of_mass=[0.0, 0.0], units=units)


def pose_parts(study: PoseStudy, units: str | None = None) -> list[Part]:
    """Every pose's footprint as a planar part, named ``pose-0``, ``pose-1``, ... in order."""
    return [pose_part(study, k, f"pose-{k}", units) for k in range(len(study.poses))]


def pose_index(text: str | int | None, n: int, source: str = "--pose") -> int:
    """A pose index ``0 <= k < n`` from its text (``None``: 0, the most probable).

    Examples
    --------
    >>> pose_index("2", 3), pose_index(None, 3)
    (2, 0)
    """
    if text is None:
        return 0
    try:
        k = int(str(text).strip())
    except ValueError:
        k = -1
    if not 0 <= k < n:
        raise PartError(
            f"{source}: pose {text!r} does not exist; the mesh has {n} stable poses (0 to {n - 1})"
        )
    return k


def study_of(
    solid: Solid, estimator: Literal["quasi-static", "perturbed"] = "quasi-static"
) -> PoseStudy:
    """The poses of a solid by ``estimator`` (the perturbed one's samples seeded: reproducible)."""
    from .poses import resting_poses

    points = solid.hull if solid.hull is not None else solid.vertices[np.unique(solid.faces)]
    return resting_poses(points, solid.center_of_mass, estimator=estimator, rng=0)


def mesh_part(
    data: bytes,
    path: Path,
    options: ReadOptions,
    fmt: str | None = None,
    com: ArrayLike | None = None,
) -> Part:
    """The part reader of mesh files: the footprint of one resting pose.

    ``options.element`` is the pose (default 0, the most probable); the part is named
    ``STEM-pose-K``. Other reader options (layer, curve tolerance) are refused.
    """
    from .mesh import read_mesh_bytes

    if options.layer is not None:
        raise PartFileError(f"{path}: a mesh has no layers (--layer is for DXF)")
    if options.tolerance is not None:
        raise PartFileError(f"{path}: a mesh has no curves to flatten (--flatten-tol)")
    kind = fmt or path.suffix.lstrip(".").lower()
    solid = read_mesh_bytes(data, kind, str(path), com=com)
    study = study_of(solid)
    k = pose_index(options.element, len(study.poses), f"{path}: pose")
    return pose_part(study, k, f"{solid.name}-pose-{k}", solid.units)
