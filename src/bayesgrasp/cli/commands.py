"""The command list: each command, the module that defines it and its line in the help.

Kept apart from the typer app (:mod:`._typer`) so that the package and the app both read it
without importing each other.
"""

from __future__ import annotations

__all__ = ["COMMANDS"]

COMMANDS: dict[str, tuple[str, str]] = {
    "squeeze": ("parts", "Stable orientations of a squeeze and their probabilities."),
    "push": ("parts", "Stable orientations of a push and of a push-grasp."),
    "plan": ("plan", "The best plan of every length; the Bayes and most certain plans."),
    "poses": ("poses", "Resting poses of a mesh, their probabilities and footprints."),
    "plot": ("plot", "Figures of a part and a plan, and the plan's animation."),
    "simulate": ("simulate", "Execute a plan many times; compare with the prediction."),
    "sweep": ("sweep", "Plan every part of a catalogue on Dask; one row a part."),
    "serve": ("serve", "The web page and the JSON API on localhost (extra `web`)."),
    "table1": ("paper", "The paper's Table 1 beside our expected costs."),
    "study": ("paper", "The paper's study: random polygons planned and counted."),
    "demo": ("paper", "The main job: Table 1, then the example part planned."),
}
"""Each command: the module that defines it, and its line in the command list."""
