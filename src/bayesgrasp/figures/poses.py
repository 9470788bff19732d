"""The resting poses of a solid: each pose on the table, its footprint and its probability."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .canvas import HULL_COLOR, PART_COLOR, PART_EDGE, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..solid.mesh import Solid
    from ..solid.poses import PoseStudy

__all__ = ["poses_figure"]

_MAX_DRAWN = 4000  # more mesh triangles than this: the hull is drawn instead


def poses_figure(
    solid: Solid,
    study: PoseStudy,
    max_poses: int = 8,
    frequencies: list[tuple[float, float, float]] | None = None,
) -> Figure:
    """Each pose (most probable first): the solid resting on the table, and its footprint.

    Parameters
    ----------
    solid : Solid
    study : PoseStudy
    max_poses : int
        Draw at most this many poses (the most probable).
    frequencies : list of (frequency, low, high), optional
        Drop frequencies with their interval, one per pose, shown beside the probability.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from bayesgrasp.solid.mesh import solid_from_arrays
    >>> from bayesgrasp.solid.poses import resting_poses
    >>> corner = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    >>> s = solid_from_arrays(corner, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> fig = poses_figure(s, resting_poses(s.vertices, s.center_of_mass))
    >>> len(fig.axes)
    8
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    poses = study.poses[:max_poses]
    n = len(poses)
    fig = new_figure(2.6 * n, 5.4)
    if len(solid.faces) <= _MAX_DRAWN:
        tris = solid.vertices[solid.faces]
    else:
        tris = study.hull.points[study.hull.triangles]
    c = study.center_of_mass
    unit = f" {solid.units}" if solid.units else ""
    for k, pose in enumerate(poses):
        ax = fig.add_subplot(2, n, k + 1, projection="3d")
        placed = (tris - c) @ pose.frame.T  # (T, 3, 3) in the pose frame
        placed[..., 2] += pose.com_height  # the table at z = 0
        ax.add_collection3d(
            Poly3DCollection(
                placed, facecolor=PART_COLOR, edgecolor=PART_EDGE, linewidth=0.1, alpha=0.9
            )
        )
        lo, hi = placed.reshape(-1, 3).min(axis=0), placed.reshape(-1, 3).max(axis=0)
        span = float(np.max(hi - lo)) / 2 or 1.0
        mid = (lo + hi) / 2
        table = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * span * 1.2 + mid[:2]
        ax.add_collection3d(
            Poly3DCollection(
                [np.c_[table, np.zeros(4)]], facecolor="#dddddd", edgecolor="none", alpha=0.5
            )
        )
        ax.scatter([0], [0], [pose.com_height], color=HULL_COLOR, s=12)
        ax.set_xlim(mid[0] - span, mid[0] + span)
        ax.set_ylim(mid[1] - span, mid[1] + span)
        ax.set_zlim(0, 2 * span)
        ax.set_axis_off()
        title = f"pose {k}: p = {pose.probability:.3f}"
        if frequencies is not None:
            f, lo_f, hi_f = frequencies[k]
            title += f"\ndrops {f:.3f} [{lo_f:.3f}, {hi_f:.3f}]"
        ax.set_title(title, fontsize=9)
        ax2 = fig.add_subplot(2, n, n + k + 1)
        ring = np.vstack([pose.footprint, pose.footprint[:1]])
        ax2.fill(ring[:, 0], ring[:, 1], color=PART_COLOR, edgecolor=PART_EDGE)
        ax2.plot([0], [0], "+", color=HULL_COLOR)
        ax2.set_aspect("equal")
        ax2.set_title(f"footprint ({len(pose.footprint)} sides)", fontsize=8)
        ax2.set_xlabel(f"x{unit}", fontsize=8)
        ax2.tick_params(labelsize=7)
    fig.suptitle(f"{solid.name}: {len(study.poses)} stable poses ({study.estimator})")
    return fig
