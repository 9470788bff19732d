"""What every figure shares: the Agg canvas, colours, degree axes and file metadata.

Matplotlib is imported inside :func:`new_figure` only, so importing the figures costs nothing
until one is drawn (the core never imports matplotlib, style.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import MissingExtraError
from ..geometry.polygon import Part
from ..model.actions import SQUEEZE
from ..model.problem import Problem

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "BAR_COLOR",
    "FAIL_COLOR",
    "GOAL_COLOR",
    "HULL_COLOR",
    "JAW_COLOR",
    "PART_COLOR",
    "PART_EDGE",
    "as_problem",
    "degree_axis",
    "new_figure",
    "save_metadata",
    "units",
]

PART_COLOR = "#9fb8d6"
PART_EDGE = "#1f3b5c"
HULL_COLOR = "#d62728"
JAW_COLOR = "#555555"
BAR_COLOR = "#4c72b0"
GOAL_COLOR = "#2ca02c"
FAIL_COLOR = "#d62728"


def new_figure(width: float, height: float) -> Figure:
    """A new figure on the Agg canvas (no window, no pyplot state).

    Raises
    ------
    MissingExtraError
        If matplotlib is not installed (extra ``plot``).
    """
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise MissingExtraError("matplotlib", "plot") from None
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def as_problem(problem: Problem | Part, actions: tuple[str, ...] = (SQUEEZE.name,)) -> Problem:
    """The problem a figure draws: a part is built into one (uniform prior) here, once."""
    if isinstance(problem, Problem):
        return problem
    return Problem.build(problem, actions=actions)


def degree_axis(ax: Axes, which: str, upper: float, margin: float = 0.0) -> None:
    """Degree ticks every 45 (or 30) degrees on an axis from 0 to ``upper`` degrees.

    ``margin`` (degrees) widens the limits on both sides, so that marks at 0 and at
    ``upper`` are drawn whole instead of half hidden on the frame.
    """
    step = 45 if upper > 180 else 30
    ticks = np.arange(0, upper + 1e-9, step)
    if which == "x":
        ax.set_xlim(-margin, upper + margin)
        ax.set_xticks(ticks)
    else:
        ax.set_ylim(-margin, upper + margin)
        ax.set_yticks(ticks)


def units(part: Part) -> str:
    """`` (mm)`` for axis labels, or nothing when the part's units are unknown."""
    return f" ({part.units})" if part.units else ""


def save_metadata(fmt: str) -> dict[str, Any] | None:
    """Metadata without dates or versions, so regenerated files only change with content."""
    if fmt == "png":
        return {"Software": None}
    if fmt == "svg":
        return {"Date": None, "Creator": None}
    if fmt == "pdf":
        return {"CreationDate": None, "Producer": None, "Creator": None}
    return None
