"""Figure (a): the part between the jaws, with its hull and the chord that touches them.

Also the geometry every drawing of the part shares: the part turned to an orientation and
centred on the jaws (:func:`place_part`), and its outline as a filled patch with holes.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..geometry.curved import CurvedPart, mesh_vertices
from ..geometry.polygon import Part
from ..model.problem import Problem
from .canvas import GOAL_COLOR, HULL_COLOR, JAW_COLOR, PART_COLOR, PART_EDGE, as_problem, new_figure
from .canvas import units as axis_units

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "DRAWING_SAGITTA",
    "Placed",
    "draw_part",
    "drawn_rings",
    "outline_path",
    "part_figure",
    "part_patch",
    "place_part",
]

FloatArray = NDArray[np.float64]

#: A curved part's arcs are drawn as polylines whose sagitta is at most this fraction of its
#: size (a fraction of a pixel in any figure), not as the chords the part file was read at.
DRAWING_SAGITTA = 2e-4


@dataclass(frozen=True, slots=True)
class Placed:
    """A part turned to orientation ``theta`` in the gripper frame and centred on the jaws.

    Attributes
    ----------
    outline : ndarray of shape (M, 2)
    holes : tuple of ndarray of shape (H, 2)
    hull : ndarray of shape (N, 2)
    com : ndarray of shape (2,)
    width : float
        The part's extent along the squeeze axis x, ``d(theta)``.
    """

    outline: FloatArray
    holes: tuple[FloatArray, ...]
    hull: FloatArray
    com: FloatArray
    width: float


@functools.lru_cache(maxsize=16)
def drawn_rings(part: Part) -> tuple[FloatArray, tuple[FloatArray, ...], FloatArray]:
    """Outline, holes and convex hull to draw, in the part's frame.

    A polygon's own. A :class:`~bayesgrasp.geometry.curved.CurvedPart` keeps its arcs exact
    (:attr:`~bayesgrasp.geometry.curved.CurvedPart.ring`, ``hole_rings``), and its
    ``outline``, ``holes`` and ``hull`` are flattened at the part file's chordal tolerance,
    which shows the chords; so its outline and holes are sampled on the arcs within
    :data:`DRAWING_SAGITTA` of its size, and its hull is the exact hull sampled as finely
    (:func:`~bayesgrasp.geometry.curved.mesh_vertices`, Bezier and elliptic curves from their
    exact form). Non-arc curves of the outline stay the chords the model has (within its
    ``curve_error``).
    """
    if not isinstance(part, CurvedPart) or part.ring is None:
        return part.outline, part.holes, part.hull.vertices
    fine = DRAWING_SAGITTA * part.curved_hull.size
    outline = part.ring.flattened(fine)
    holes = tuple(h.flattened(fine) for h in part.hole_rings) if part.hole_rings else part.holes
    return outline, holes, mesh_vertices(part, DRAWING_SAGITTA)


def place_part(part: Part, theta: float) -> Placed:
    """Rotate the part by ``theta`` (counter-clockwise) and centre it between the jaws.

    Translation does not matter to the gripper, so the rotated part is shifted to put the
    middle of its x-extent at 0 and its centre of mass at y = 0. A curved part is drawn with
    its arcs as arcs (:func:`drawn_rings`).

    Examples
    --------
    >>> p = place_part(Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1)]), math.pi / 2)
    >>> round(p.width, 12), p.com.round(12).tolist()
    (1.0, [0.0, 0.0])
    """
    c, s = math.cos(theta), math.sin(theta)
    rot = np.array([[c, -s], [s, c]])
    outline, holes, vertices = drawn_rings(part)
    hull = vertices @ rot.T
    lo, hi = hull[:, 0].min(), hull[:, 0].max()
    com = part.center_of_mass @ rot.T
    shift = np.array([-(lo + hi) / 2.0, -com[1]])
    return Placed(
        outline @ rot.T + shift,
        tuple(h @ rot.T + shift for h in holes),
        hull + shift,
        com + shift,
        float(hi - lo),
    )


def outline_path(placed: Placed) -> Any:
    """The outline and its holes as one matplotlib path (holes run the other way)."""
    from matplotlib.path import Path as MplPath

    rings = [placed.outline] + [h[::-1] for h in placed.holes]
    verts = np.concatenate([np.vstack([r, r[:1]]) for r in rings])
    codes = np.concatenate(
        [[MplPath.MOVETO] + [MplPath.LINETO] * (len(r) - 1) + [MplPath.CLOSEPOLY] for r in rings]
    )
    return MplPath(verts, codes)


def part_patch(placed: Placed, **kwargs: Any) -> Any:
    """A filled patch of the outline with its holes."""
    from matplotlib.patches import PathPatch

    return PathPatch(outline_path(placed), **kwargs)


def draw_part(ax: Axes, problem: Problem, theta: float) -> None:
    """Panel (a): outline, hull, antipodal chord, centre of mass and jaws at ``theta``.

    The legend goes below the axes: inside, it covered the right jaw whatever its corner.
    """
    from matplotlib.patches import Rectangle

    part = problem.part
    placed = place_part(part, theta)
    pairs = getattr(problem.diameter, "pairs", None)  # a curved part's d has no vertex pairs
    if pairs is not None:
        i_plus, i_minus = pairs[int(problem.diameter.piece_index(theta))]
    else:
        i_plus, i_minus = int(np.argmax(placed.hull[:, 0])), int(np.argmin(placed.hull[:, 0]))
    ax.add_patch(
        part_patch(placed, facecolor=PART_COLOR, edgecolor=PART_EDGE, lw=1.2, label="part")
    )
    ax.patches[-1].set_gid("outline")
    ring = np.vstack([placed.hull, placed.hull[:1]])
    ax.plot(ring[:, 0], ring[:, 1], "--", color=HULL_COLOR, lw=1.2, label="convex hull", gid="hull")
    chord = placed.hull[[i_minus, i_plus]]
    ax.plot(
        chord[:, 0],
        chord[:, 1],
        "-o",
        color=GOAL_COLOR,
        lw=1.5,
        ms=4,
        label="antipodal chord",
        gid="chord",
    )
    ax.plot(*placed.com, "k+", ms=10, mew=2, label="centre of mass", gid="com")
    ys = placed.hull[:, 1]
    span = float(ys.max() - ys.min())
    y0, height = float(ys.min()) - 0.15 * span, 1.3 * span
    jaw = 0.08 * max(placed.width, span)
    half = placed.width / 2.0
    left = Rectangle((-half - jaw, y0), jaw, height, color=JAW_COLOR, alpha=0.8, gid="jaw-left")
    right = Rectangle((half, y0), jaw, height, color=JAW_COLOR, alpha=0.8, gid="jaw-right")
    right.set_label("jaws")
    ax.add_patch(left)
    ax.add_patch(right)
    for sign in (-1.0, 1.0):
        ax.annotate(
            "",
            xy=(sign * (half + jaw), y0 + height / 2),
            xytext=(sign * (half + 2.5 * jaw), y0 + height / 2),
            arrowprops={"arrowstyle": "->", "color": JAW_COLOR, "lw": 1.5},
        )
    ax.set_aspect("equal")
    ax.set_xlim(-half - 3 * jaw, half + 3 * jaw)
    ax.set_ylim(y0 - 0.1 * span, y0 + height + 0.1 * span)
    u = axis_units(part)
    ax.set_xlabel(f"x: squeeze axis{u}")
    ax.set_ylabel(f"y: along the jaws{u}")
    ax.set_title(
        f"{part.name} at {math.degrees(theta):.1f}°: hull, chord, jaws (gap {placed.width:.4g})"
    )
    ax.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, -0.14),
        ncols=3,
        fontsize="small",
        frameon=False,
    )


def part_figure(part: Problem | Part, theta: float = 0.0) -> Figure:
    """(a) The part in the gripper frame at orientation ``theta``, as the jaws hold it.

    Shows the outline (with holes), the convex hull the jaws touch, the antipodal chord of
    the diameter function at ``theta`` (its vertices touch the jaws), the centre of mass,
    and the two jaws a diameter ``d(theta)`` apart.

    Parameters
    ----------
    part : Problem or Part
        A problem's part is drawn with the problem's diameter function; a part is built into
        a problem first.
    theta : float, optional
        Orientation of the part (radians, counter-clockwise); 0 shows it as given.

    Returns
    -------
    Figure

    Examples
    --------
    >>> part = Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1)], name="bar")
    >>> fig = part_figure(part, theta=0.3)
    >>> [a.get_gid() for a in fig.axes[0].patches][:3]
    ['outline', 'jaw-left', 'jaw-right']
    """
    fig = new_figure(6.4, 5.6)
    draw_part(fig.add_subplot(), as_problem(part), theta)
    return fig
