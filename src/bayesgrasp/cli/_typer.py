"""The typer app of the command line (see :mod:`bayesgrasp.cli`), and its error handling."""

from __future__ import annotations

import importlib
from functools import cache
from typing import Annotated, Any

import typer
from typer.core import TyperGroup

from ..errors import BayesGraspError, NoPlanError
from ..shapes import names as catalogue_names
from .commands import COMMANDS

__all__ = ["app", "run"]


@cache
def _commands_of(module: str) -> TyperGroup:
    """The click commands of one command module (imported on first use)."""
    mod = importlib.import_module(f"{__package__}.{module}")
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


def run(args: list[str]) -> int:
    """Run the command line on ``args`` with typer; return the exit code."""
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
