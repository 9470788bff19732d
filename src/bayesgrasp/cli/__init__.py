"""The ``bayesgrasp`` command line: parse, call the library, print. Nothing else.

One module per command group: :mod:`.parts` (squeeze, push), :mod:`.plan`, :mod:`.plot`,
:mod:`.simulate`, :mod:`.sweep`, :mod:`.paper` (table1, study, demo); the options they share are in
:mod:`.options`, the helpers in :mod:`.common`. A command's module is imported only when
the command runs (or shows its help), and the library only inside the command's body, so
``bayesgrasp --help`` loads no planner, figure or simulation code. The command list is
:mod:`.commands`; the typer app is :mod:`._typer`, imported when first needed. What a run
asks of the library (the part, the problem, the planner) is :mod:`bayesgrasp.runs`, shared
with the web service and sweeps.

Exit codes: 0 success, 1 no plan reached the requested goal, 2 bad input (one line on
stderr, never a traceback). Bare ``bayesgrasp`` prints the help, as ``--help`` does.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from .._lazy import lazy_names
from .commands import COMMANDS

if TYPE_CHECKING:
    from ._typer import app

__all__ = ["COMMANDS", "app", "main"]

# The typer app (and typer) are imported when first needed.
__getattr__, __dir__ = lazy_names(__name__, {"app": "_typer"})


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    args = sys.argv[1:] if argv is None else list(argv)
    from ._typer import run

    return run(args)
