"""The command line as a package: the shared options, the one way to name a plan, exit codes,
``--version``, ``-h``, bare ``bayesgrasp`` and lazy command modules; run through ``cli.main``.
"""

from __future__ import annotations

import importlib
import json
import math
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import typer
from numpy.testing import assert_allclose

import bayesgrasp
from bayesgrasp import CostModel, Problem, plan_exact, resolve_part
from bayesgrasp.cli import COMMANDS, main

NO_PLAN = ["key", "--plan", "guaranteed", "--accuracy", "30"]  # widths stop at 78.95 deg


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, Any]:
    code, out, err = run(capsys, *args, "--json")
    assert (code, err) == (0, ""), err
    doc = json.loads(out)
    doc.pop("seconds", None)  # wall time
    assert isinstance(doc, dict)
    return doc


# --- the program: --version, -h, bare invocation, the command list ------------------------


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "--version") == (0, f"bayesgrasp {bayesgrasp.__version__}\n", "")


def test_short_help_and_bare_invocation_print_the_help_once(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, helptext, err = run(capsys, "--help")
    assert (code, err) == (0, "")
    assert helptext.count("Usage: bayesgrasp") == 1
    assert run(capsys, "-h") == (0, helptext, "")
    assert run(capsys) == (0, helptext, "")
    for name in COMMANDS:
        assert f"\n  {name} " in helptext
    code, plan_help, _ = run(capsys, "plan", "-h")
    assert code == 0 and "--actions" in plan_help


def test_command_list_matches_the_modules() -> None:
    defined: dict[str, str] = {}
    for module in sorted({m for m, _ in COMMANDS.values()}):
        app = importlib.import_module(f"bayesgrasp.cli.{module}").app
        for name in typer.main.get_group(app).commands:
            defined[name] = module
    assert defined == {name: module for name, (module, _) in COMMANDS.items()}


def test_unknown_command_is_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plna", "triangle")
    assert (code, out) == (2, "")
    assert err.startswith("bayesgrasp: error: ") and len(err.splitlines()) == 1


def test_help_loads_no_command_module() -> None:
    """``--help`` imports the command list only; ``plan --help`` only the plan module."""
    probe = (
        "import sys, contextlib, io\n"
        "from bayesgrasp.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    main(sys.argv[1:])\n"
        "heavy = ('bayesgrasp.cli.', 'bayesgrasp.report', 'bayesgrasp.io.plans',\n"
        "         'bayesgrasp.figures.plots', 'bayesgrasp.sim.kinematic', 'matplotlib', 'mujoco')\n"
        "print(sorted(m for m in sys.modules if m.startswith(heavy)))\n"
    )

    def loaded(*args: str) -> list[str]:
        proc = subprocess.run(
            [sys.executable, "-c", probe, *args], capture_output=True, text=True, check=True
        )
        return list(json.loads(proc.stdout.replace("'", '"')))

    # the app itself and its command list
    assert loaded("--help") == ["bayesgrasp.cli._typer", "bayesgrasp.cli.commands"]
    assert loaded("plan", "--help") == [
        f"bayesgrasp.cli.{m}" for m in ("_typer", "commands", "common", "options", "plan", "specs")
    ]


# --- one set of options: --actions everywhere, hidden --push-grasp, costs -------------------


@pytest.mark.parametrize("command", ["simulate", "plot"])
def test_push_grasp_alias_is_hidden(capsys: pytest.CaptureFixture[str], command: str) -> None:
    code, out, _ = run(capsys, command, "--help")
    assert code == 0
    assert "--actions" in out and "--squeeze-cost" in out and "--method" in out
    assert "--push-grasp " not in out and "--push-grasp\n" not in out


def test_simulate_push_grasp_alias_is_actions(capsys: pytest.CaptureFixture[str]) -> None:
    args = ("simulate", "house", "--trials", "2000", "--seed", "4")
    alias = run_json(capsys, *args, "--push-grasp")
    spelled = run_json(capsys, *args, "--actions", "squeeze,push-grasp")
    assert alias == spelled
    assert "push-grasp" in [s["type"] for s in alias["plan"]["steps"]]
    # --push-grasp puts squeeze,push-grasp first in whatever --actions says.
    assert run_json(capsys, *args, "--actions", "push-grasp", "--push-grasp") == spelled


@pytest.mark.parametrize(
    "extra",
    [
        ["--actions", "squeeze,push-grasp"],
        ["--actions", "squeeze,push-grasp", "--push-grasp-cost", "3", "--first-squeeze-cost", "4"],
        ["--squeeze-cost", "2", "--verify-cost", "3", "--retry-cost", "1", "--goal", "symmetry"],
        ["--prior", "vonmises:40,4", "--accuracy", "2"],
        ["--method", "bfs", "--max-squeezes", "2"],
    ],
)
def test_simulate_plans_as_plan_does(capsys: pytest.CaptureFixture[str], extra: list[str]) -> None:
    """simulate's Bayes plan is plan's, under the same problem options."""
    planned = run_json(capsys, "plan", "house", *extra)
    simulated = run_json(capsys, "simulate", "house", "--trials", "500", *extra)
    bayes = planned["options"][planned["bayes"]]
    assert simulated["plan"]["steps"] == bayes["steps"]
    assert simulated["plan"]["expected_cost"] == pytest.approx(bayes["expected_cost"], rel=1e-12)


def test_cost_options_come_from_the_registry(capsys: pytest.CaptureFixture[str]) -> None:
    doc = run_json(
        capsys, "plan", "house", "--actions", "squeeze,push-grasp", "--first-push-grasp-cost", "9"
    )
    cost = CostModel(first={"push-grasp": 9.0})
    rep = plan_exact(
        Problem.build(resolve_part("house"), cost=cost, actions=("squeeze", "push-grasp"))
    )
    assert_allclose(
        [o["expected_cost"] for o in doc["options"]],
        [o.expected_cost for o in rep.options],
        rtol=1e-12,
    )
    code, _, err = run(capsys, "plan", "house", "--first-push-grasp-cost", "-1")
    assert code == 2 and "--first-push-grasp-cost" in err


class FigureRecorder:
    """Stands in for figures.plots.write_figures: records what it was asked to draw."""

    def __init__(self) -> None:
        self.calls: list[dict[str, Any]] = []

    def __call__(self, problem: Problem, option: Any, out: Path, **kw: Any) -> list[Path]:
        self.calls.append({"actions": problem.action_kinds, "option": option, **kw})
        return [Path(out) / "part.png"]


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> FigureRecorder:
    import bayesgrasp.figures.plots as plots

    recorder = FigureRecorder()
    monkeypatch.setattr(plots, "write_figures", recorder)
    return recorder


def test_plot_takes_the_shared_options(
    capsys: pytest.CaptureFixture[str], figures: FigureRecorder, tmp_path: Path
) -> None:
    out = str(tmp_path)
    assert run(capsys, "plot", "house", "--out", out, "--push-grasp")[0] == 0
    assert run(capsys, "plot", "house", "--out", out, "--actions", "squeeze,push-grasp")[0] == 0
    assert run(capsys, "plot", "house", "--out", out)[0] == 0
    alias, spelled, plain = figures.calls
    assert alias == spelled
    assert alias["actions"] == ("squeeze", "push-grasp") and alias["push_grasp"] is True
    assert plain["actions"] == ("squeeze",) and plain["push_grasp"] is False
    assert "push-grasp" in alias["option"].kinds and alias["label"] == "Bayes"
    # The goal, cost and method options reach the plot's plan too.
    assert (
        run(capsys, "plot", "rectangle", "--out", out, "--goal", "symmetry", "--squeeze-cost", "9")[
            0
        ]
        == 0
    )
    pb = Problem.build(
        resolve_part("rectangle"),
        cost=CostModel({"squeeze": 9.0}),
        goal=bayesgrasp.Goal("symmetry"),
    )
    assert figures.calls[-1]["option"] == plan_exact(pb).bayes_plan


def test_plot_and_simulate_read_a_plan_file(
    capsys: pytest.CaptureFixture[str], figures: FigureRecorder, tmp_path: Path
) -> None:
    code, text, _ = run(capsys, "plan", "house", "--actions", "squeeze,push-grasp", "--json")
    assert code == 0
    doc = json.loads(text)
    path = tmp_path / "mixed.json"
    path.write_text(text, encoding="utf-8")
    assert run(capsys, "plot", "house", "--out", str(tmp_path), "--plan", str(path))[0] == 0
    drawn = figures.calls[-1]
    steps = [{"type": s.kind, "alpha_rad": s.alpha} for s in drawn["option"].steps]
    assert steps == doc["options"][doc["bayes"]]["steps"]
    assert drawn["label"] == "mixed.json" and drawn["actions"] == ("squeeze", "push-grasp")
    sim = run_json(capsys, "simulate", "house", "--plan", str(path), "--trials", "500")
    assert sim["plan"]["steps"] == doc["options"][doc["bayes"]]["steps"]


# --- exit codes: 1 no plan, 2 bad input ----------------------------------------------------


@pytest.mark.parametrize("command", ["simulate", "plot"])
def test_no_guaranteed_plan_is_exit_1(
    capsys: pytest.CaptureFixture[str], command: str, tmp_path: Path
) -> None:
    extra = ["--out", str(tmp_path / "figs")] if command == "plot" else ["--trials", "10"]
    code, out, err = run(capsys, command, *NO_PLAN, *extra)
    assert (code, out) == (1, "")
    assert err.startswith("bayesgrasp: no plan: no guaranteed plan for part 'key'")
    assert len(err.splitlines()) == 1
    assert not (tmp_path / "figs").exists()


def test_plan_without_guaranteed_plan_is_exit_1(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plan", "key", "--guaranteed", "--accuracy", "30")
    assert (code, err) == (1, "")
    assert "Guaranteed plan: none (no guaranteed plan for part 'key'" in out


def test_no_plan_result_is_exit_1(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A guaranteed planner that returns a no-plan result (status, reason) instead of raising."""
    import bayesgrasp.planning.guaranteed as guaranteed

    result = SimpleNamespace(status="no-plan", reason="the widths stop short", option=None)
    monkeypatch.setattr(guaranteed, "plan_guaranteed", lambda problem: result)
    code, out, err = run(capsys, "simulate", "triangle", "--plan", "guaranteed", "--trials", "10")
    assert (code, out, err) == (1, "", "bayesgrasp: no plan: the widths stop short\n")
    code, out, _ = run(capsys, "plan", "triangle", "--guaranteed", "--json")
    doc = json.loads(out)
    assert code == 1 and doc["schema"] == "bayesgrasp.plan/2"
    assert doc["guaranteed"] is None and doc["guaranteed_missing"] == "the widths stop short"


@pytest.mark.parametrize("command", ["simulate", "plot"])
@pytest.mark.parametrize(
    ("plan", "needle"),
    [
        ("best", "--plan"),
        ("nope.json", "nope.json"),
        ("tests/snapshots/parts/random-1.json", "a plan needs `steps` or `first_squeeze_rad`"),
    ],
)
def test_bad_plan_is_exit_2(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    command: str,
    plan: str,
    needle: str,
) -> None:
    monkeypatch.chdir(Path(__file__).resolve().parents[2])
    extra = ["--out", str(tmp_path / "figs")] if command == "plot" else []
    code, out, err = run(capsys, command, "triangle", "--plan", plan, *extra)
    assert (code, out) == (2, "")
    assert err.startswith("bayesgrasp: error: ") and needle in err and len(err.splitlines()) == 1


def test_unknown_action_is_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    for command in ("plan", "simulate"):
        code, out, err = run(capsys, command, "triangle", "--actions", "squeeze,teleport")
        assert (code, out) == (2, "")
        assert "unknown action 'teleport'" in err and len(err.splitlines()) == 1


def test_most_certain_plan_is_named_as_in_plot(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "simulate", "triangle", "--plan", "most-certain", "--trials", "100")
    assert code == 0 and out.startswith("triangle: most certain plan, prior uniform;")


def test_a_registered_action_gets_cost_options(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Options are made from the registry when a command module loads (README, Architecture)."""
    import bayesgrasp.cli._typer as cli_typer
    import bayesgrasp.cli.plan as plan_module
    from bayesgrasp.model.actions import Action, register_action, unregister_action

    station = Action(
        name="station-x",
        tag="X",
        gripper_period=math.pi,
        pushes_first=False,
        reads="width",
        description="a second squeeze station",
        build=lambda part, squeeze: squeeze,
    )
    register_action(station)
    try:
        importlib.reload(plan_module)
        cli_typer._commands_of.cache_clear()
        doc = run_json(
            capsys, "plan", "house", "--actions", "squeeze,station-x", "--station-x-cost", "0.5"
        )
        cost = CostModel({"station-x": 0.5})
        pb = Problem.build(resolve_part("house"), cost=cost, actions=("squeeze", station))
        expected = [o.expected_cost for o in plan_exact(pb).options]
        assert_allclose([o["expected_cost"] for o in doc["options"]], expected, rtol=1e-12)
        assert any(s["type"] == "station-x" for o in doc["options"] for s in o["steps"])
    finally:
        unregister_action("station-x")
        importlib.reload(plan_module)
        cli_typer._commands_of.cache_clear()
    code, _, err = run(capsys, "plan", "house", "--station-x-cost", "1")
    assert code == 2 and "No such option: --station-x-cost" in err
