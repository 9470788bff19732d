"""The ``bayesgrasp`` command line: parse, call the library, print. Nothing else.

One module per command group: :mod:`.parts` (squeeze, push), :mod:`.plan`, :mod:`.plot`,
:mod:`.simulate`, :mod:`.sweep`, :mod:`.paper` (table1, study, demo); the options they share are in
:mod:`.options`, the helpers in :mod:`.common`. A command's module is imported only when
the command runs (or shows its help), and the library only inside the command's body, so
``bayesgrasp --help`` loads no planner, figure or simulation code. The typer app is
:mod:`._typer`, imported when first needed.

Exit codes: 0 success, 1 no plan reached the requested goal, 2 bad input (one line on
stderr, never a traceback). Bare ``bayesgrasp`` prints the help, as ``--help`` does.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from .._lazy import lazy_names

if TYPE_CHECKING:
    from ._typer import app

__all__ = ["COMMANDS", "app", "main"]

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

# The typer app (and typer) are imported when first needed.
__getattr__, __dir__ = lazy_names(__name__, {"app": "_typer"})


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    args = sys.argv[1:] if argv is None else list(argv)
    from ._typer import run

    return run(args)
