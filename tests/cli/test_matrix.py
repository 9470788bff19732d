"""Every option of a strategy through every surface of ``plan`` and ``simulate``.

Each cell of the matrix (a set of planning options x a surface: the table, ``--json``,
``--plot``, ``--export`` as CSV and JSON, several PARTs, ``--batch``, ``simulate``) either works
and agrees with the others, or is refused with exit code 2 and one line that says why it cannot
mean anything. Never exit 0 with an option ignored (a figure or robot file asked for and not
written), never "not yet", never a traceback.

Agreement: the robot file's gripper angles are the document's (the Bayes plan's steps, turned
into absolute angles; a policy's state machine holds the policy's nodes); a line of several
PARTs or of ``--batch`` is the single run's document; ``simulate`` runs the strategy that
``plan`` gives (its prediction is the plan's figure).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path
from typing import Any

import pytest

from bayesgrasp.cli import main

PAYOFF = "tests/snapshots/parts/payoff-key.json"
ROOT = Path(__file__).resolve().parents[2]

OPTIONS: dict[str, list[str]] = {
    "plain": [],
    "prior": ["--prior", "vonmises:40,4"],
    "push-grasp": ["--actions", "squeeze,push-grasp"],
    "accuracy": ["--accuracy", "2"],
    "turn normal": ["--turn-noise", "normal:2"],
    "turn uniform": ["--turn-noise", "uniform:3"],
    "contact": ["--contact-noise", "0.1"],
    "payoff": ["--payoff", PAYOFF],
    "guaranteed": ["--guaranteed"],
    "guaranteed uniform": ["--guaranteed", "--turn-noise", "uniform:1"],
    "guaranteed normal": ["--guaranteed", "--turn-noise", "normal:2"],
    "sense": ["--sense", "width:0.5,0.1", "--max-actions", "2"],
    "sense normal": ["--sense", "width:0.5,0.1", "--max-actions", "2", "--turn-noise", "normal:2"],
    "sense contact": ["--sense", "width", "--max-actions", "2", "--contact-noise", "0.1"],
}
SURFACES = ("table", "plot", "export", "several", "batch", "simulate")
# The cells that have no meaning, with the words their refusal must contain: no plan
# guarantees anything under an unbounded turn error.
REFUSED: dict[tuple[str, str], str] = {
    ("guaranteed normal", surface): "unbounded" for surface in SURFACES
}


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def _check_refusal(code: int, err: str, cell: tuple[str, str]) -> None:
    """A refused cell: exit 2, one line, and only where the combination has no meaning."""
    assert code == 2, f"{cell}: exit {code}, {err}"
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1, f"{cell}: {err}"
    assert cell in REFUSED, f"{cell} refused: {err.strip()}"
    assert REFUSED[cell] in err, f"{cell}: {err}"


def _is_policy(doc: dict[str, Any]) -> bool:
    return str(doc.get("schema", "")).startswith("bayesgrasp.policy")


def _bayes_gripper_angles(doc: dict[str, Any]) -> list[float]:
    """The absolute gripper angles (rad, wrapped to (-pi, pi]) of a plan document's Bayes plan."""
    steps = doc["options"][doc["bayes"]]["steps"]
    out, total = [], 0.0
    for s in steps:
        total += s["alpha_rad"]
        out.append(math.remainder(total, 2 * math.pi))
    return out


def _doc(name: str) -> dict[str, Any]:
    code, out, err = _run(["plan", "key", *OPTIONS[name], "--json"])
    assert code in (0, 1), err
    return json.loads(out)


@pytest.fixture(autouse=True)
def _at_root(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)


@pytest.mark.parametrize("name", list(OPTIONS))
def test_table_and_json(name: str) -> None:
    code, out, err = _run(["plan", "key", *OPTIONS[name]])
    if code == 2:
        _check_refusal(code, err, (name, "table"))
        return
    assert code in (0, 1), err
    assert out.strip()
    code_j, out_j, err_j = _run(["plan", "key", *OPTIONS[name], "--json"])
    assert code_j == code, err_j
    json.loads(out_j)


@pytest.mark.parametrize("name", list(OPTIONS))
def test_plot(name: str, tmp_path: Path) -> None:
    fig = tmp_path / "fig.png"
    code, _, err = _run(["plan", "key", *OPTIONS[name], "--plot", str(fig)])
    if code == 2:
        _check_refusal(code, err, (name, "plot"))
        return
    assert code in (0, 1), err
    assert fig.exists() and fig.stat().st_size > 1000, f"{name}: --plot wrote nothing"


@pytest.mark.parametrize("suffix", ["csv", "json"])
@pytest.mark.parametrize("name", list(OPTIONS))
def test_export(name: str, suffix: str, tmp_path: Path) -> None:
    robot = tmp_path / f"robot.{suffix}"
    code, _, err = _run(["plan", "key", *OPTIONS[name], "--export", str(robot)])
    if code == 2:
        _check_refusal(code, err, (name, "export"))
        return
    assert code in (0, 1), err
    assert robot.exists(), f"{name}: --export wrote nothing"
    doc = _doc(name)
    if doc.get("noise") is not None:  # the file says what noise the strategy was made for
        head = robot.read_text(encoding="utf-8")
        if suffix == "json":
            assert json.loads(head)["noise"] == doc["noise"]
        else:
            assert f"# noise: {json.dumps(doc['noise'])}" in head
    if _is_policy(doc) or suffix == "csv":
        return  # a policy's state machine is checked against simulation in tests/io
    exported = json.loads(robot.read_text(encoding="utf-8"))
    angles = [s["gripper_rad"] for s in exported["steps"]]
    assert angles == pytest.approx(_bayes_gripper_angles(doc), abs=1e-9)


@pytest.mark.parametrize("name", list(OPTIONS))
def test_several_parts(name: str) -> None:
    # A payoff names one part's stable orientations: the same part twice.
    other = "key" if name == "payoff" else "triangle"
    code, out, err = _run(["plan", "key", other, *OPTIONS[name], "--json"])
    if code == 2:
        _check_refusal(code, err, (name, "several"))
        return
    if name.startswith("sense"):  # more PARTs are candidates to tell apart: one policy
        assert json.loads(out)["parts"] == ["key", other]
        return
    lines = [json.loads(x) for x in out.splitlines()]
    assert len(lines) == 2
    single = _doc(name)
    lines[0].pop("provenance", None), single.pop("provenance", None)
    assert _strip_times(lines[0]) == _strip_times(single)


@pytest.mark.parametrize("name", list(OPTIONS))
def test_batch(name: str, tmp_path: Path) -> None:
    batch = tmp_path / "parts.jsonl"
    batch.write_text('"key"\n', encoding="utf-8")
    code, out, err = _run(["plan", "--batch", str(batch), *OPTIONS[name]])
    if code == 2:
        _check_refusal(code, err, (name, "batch"))
        return
    (line,) = [json.loads(x) for x in out.splitlines()]
    single = _doc(name)
    line.pop("provenance", None), single.pop("provenance", None)
    assert _strip_times(line) == _strip_times(single)


def _strip_times(doc: Any) -> Any:
    if isinstance(doc, dict):
        return {k: _strip_times(v) for k, v in doc.items() if "seconds" not in k}
    if isinstance(doc, list):
        return [_strip_times(v) for v in doc]
    return doc


@pytest.mark.parametrize("name", list(OPTIONS))
def test_simulate(name: str) -> None:
    opts = [o for o in OPTIONS[name] if o != "--guaranteed"]
    plan_choice = ["--plan", "guaranteed"] if "--guaranteed" in OPTIONS[name] else []
    code, out, err = _run(
        ["simulate", "key", *opts, *plan_choice, "--trials", "2000", "--seed", "1", "--json"]
    )
    if code == 2:
        _check_refusal(code, err, (name, "simulate"))
        return
    assert code == 0, err
    json.loads(out)
