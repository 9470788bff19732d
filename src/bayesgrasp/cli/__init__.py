"""The ``bayesgrasp`` command line: parse, call the library, print. Nothing else.

One module per command group: :mod:`.parts` (squeeze, push), :mod:`.plan`, :mod:`.plot`,
:mod:`.simulate`, :mod:`.sweep`, :mod:`.paper` (table1, study, demo); the options they share are in
:mod:`.options`, the helpers in :mod:`.common`. A command's module is imported only when
the command runs (or shows its help), and the library only inside the command's body, so
``bayesgrasp --help`` loads no planner, figure or simulation code.

Exit codes: 0 success, 1 no plan reached the requested goal, 2 bad input (one line on
stderr, never a traceback). Bare ``bayesgrasp`` prints the help, as ``--help`` does.
"""

from __future__ import annotations

import importlib
import sys
from functools import cache
from typing import Annotated, Any

import typer
from typer.core import TyperGroup

from ..errors import BayesGraspError, NoPlanError
from ..shapes import names as catalogue_names

__all__ = ["COMMANDS", "app", "main"]

COMMANDS: dict[str, tuple[str, str]] = {
    "squeeze": ("parts", "Stable orientations of a squeeze and their probabilities."),
    "push": ("parts", "Stable orientations of a push and of a push-grasp."),
    "plan": ("plan", "The best plan of every length; the Bayes and most certain plans."),
    "plot": ("plot", "Figures of a part and a plan, and the plan's animation."),
    "simulate": ("simulate", "Execute a plan many times; compare with the prediction."),
    "sweep": ("sweep", "Plan every part of a catalogue on Dask; one row a part."),
    "serve": ("serve", "The web page and the JSON API on localhost (extra `web`)."),
    "table1": ("paper", "The seed's Table 1 beside our expected costs."),
    "study": ("paper", "The seed's study: random polygons planned and counted."),
    "demo": ("paper", "The main job: Table 1, then the example part planned."),
}
"""Each command: the module that defines it, and its line in the command list."""


@cache
def _commands_of(module: str) -> TyperGroup:
    """The click commands of one command module (imported on first use)."""
    mod = importlib.import_module(f"{__name__}.{module}")
    return typer.main.get_group(mod.app)


class LazyCommands(TyperGroup):
    """The commands of :data:`COMMANDS`, each module imported when its command is needed."""

    def list_commands(self, ctx: Any) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: Any, cmd_name: str) -> Any:
        if cmd_name not in COMMANDS:
            return None
        return _commands_of(COMMANDS[cmd_name][0]).get_command(ctx, cmd_name)

    def format_commands(self, ctx: Any, formatter: Any) -> None:
        with formatter.section("Commands"):
            formatter.write_dl([(name, summary) for name, (_, summary) in COMMANDS.items()])

    def get_help_option(self, ctx: Any) -> Any:
        """The ``--help`` flag, ``False`` when not given.

        Typer coerces a parameter whose value is not a bool through pydantic (imported on
        first use, about a third of ``bayesgrasp plan --help``); an absent flag is ``None``
        unless it has a default.
        """
        option = super().get_help_option(ctx)
        if option is not None and option.default is None:
            option.default = False
        return option


app = typer.Typer(
    cls=LazyCommands,
    help=(
        "Plan parallel-jaw squeeze sequences that orient a planar part at least expected "
        "cost (Goldberg & Mason, Bayesian Grasping). PART is a catalogue name "
        f"({', '.join(catalogue_names())}) or a part file (.json, .csv, .wkt, .geojson, "
        ".svg, .dxf)."
    ),
    context_settings={"help_option_names": ["-h", "--help"]},
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


def _print_version(value: bool) -> None:
    if value:
        from .. import __version__

        typer.echo(f"bayesgrasp {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", is_eager=True, callback=_print_version, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """The commands (see :data:`COMMANDS`)."""


# typer vendors click; its exception base is reached through a public subclass.
_ClickException: type[Exception] = next(
    c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException"
)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    args = sys.argv[1:] if argv is None else list(argv)
    from .batch import fast_main

    code = fast_main(args)  # plan --batch FILE with problem options: without typer
    if code is not None:
        return code
    try:
        rv = app(args=args or ["--help"], prog_name="bayesgrasp", standalone_mode=False)
    except _ClickException as exc:  # bad usage: one line, exit 2
        msg = exc.format_message()  # type: ignore[attr-defined]
        typer.echo(f"bayesgrasp: error: {msg} (see --help)", err=True)
        return int(getattr(exc, "exit_code", 2))
    except (typer.Exit, SystemExit) as exc:
        code = getattr(exc, "exit_code", getattr(exc, "code", 0))
        return code if isinstance(code, int) else 0
    except typer.Abort:
        typer.echo("bayesgrasp: aborted", err=True)
        return 130
    except NoPlanError as exc:  # a planner that raises where it should return no plan
        typer.echo(f"bayesgrasp: no plan: {exc}", err=True)
        return 1
    except BayesGraspError as exc:
        typer.echo(f"bayesgrasp: error: {exc}", err=True)
        return 2
    return rv if isinstance(rv, int) else 0
