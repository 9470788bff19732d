"""Light commands import only what they use (issue 12): checked on ``sys.modules``, not timed.

Each case runs the command line in a fresh interpreter and lists the modules it loaded:
``--help`` needs typer and the command names; ``plan --help`` the plan command's options
(the action registry, no numpy); ``squeeze`` the part, its squeeze function and the
tables, no planner.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

_PROBE = (
    "import sys, contextlib, io\n"
    "from bayesgrasp.cli import main\n"
    "with contextlib.redirect_stdout(io.StringIO()):\n"
    "    code = main(sys.argv[1:])\n"
    "print(code)\n"
    "print(sorted(sys.modules))\n"
)

PLANNERS = ("bayesgrasp.planning.exact", "bayesgrasp.planning.bfs", "bayesgrasp.planning.arcs")
FIGURES = ("matplotlib", "bayesgrasp.figures")
NUMERIC = ("numpy", "scipy")


def loaded(*args: str) -> list[str]:
    """The modules ``bayesgrasp ARGS`` imports (it must succeed)."""
    proc = subprocess.run(
        [sys.executable, "-c", _PROBE, *args], capture_output=True, text=True, check=True
    )
    code, modules = proc.stdout.splitlines()[-2:]
    assert code == "0", proc.stderr
    return list(json.loads(modules.replace("'", '"')))


def heavy(modules: list[str], *prefixes: str) -> list[str]:
    return [m for m in modules if m.startswith(prefixes)]


@pytest.mark.parametrize("args", [["--help"], ["plan", "--help"], ["squeeze", "--help"]])
def test_help_imports_no_numpy_planner_or_figure(args: list[str]) -> None:
    modules = loaded(*args)
    assert heavy(modules, *NUMERIC, *PLANNERS, *FIGURES, "bayesgrasp.model.problem") == []
    # typer validates option values through pydantic; help reads none of them
    assert heavy(modules, "pydantic") == []


def test_top_level_help_imports_no_command_module() -> None:
    app = ("bayesgrasp.cli._typer", "bayesgrasp.cli.commands")  # the app and its command list
    modules = [m for m in loaded("--help") if m not in app]
    assert heavy(modules, "bayesgrasp.cli.", "bayesgrasp.model") == []


def test_squeeze_imports_no_planner() -> None:
    modules = loaded("squeeze", "key", "--json")
    assert "bayesgrasp.geometry.curved" in modules  # what it does use
    assert heavy(modules, *PLANNERS, *FIGURES, "bayesgrasp.planning", "bayesgrasp.sim") == []
    assert heavy(modules, "bayesgrasp.model.problem") == []


def test_the_probe_sees_the_planners_of_plan() -> None:
    """The probe can fail: ``plan`` itself loads the planners."""
    assert set(PLANNERS) <= set(loaded("plan", "triangle"))
