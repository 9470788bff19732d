"""``--jaw-height`` means the same in ``simulate`` and ``plot`` as in ``plan``: a pose a squeeze
at that height may topple is refused (one line, exit 2), a pose it cannot topple runs."""

from __future__ import annotations

from pathlib import Path

import pytest

from bayesgrasp.cli import main

BRACKET = str(Path(__file__).resolve().parents[2] / "examples" / "bracket.obj")


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("command", ["simulate", "plot"])
def test_a_toppling_pose_is_refused_as_plan_refuses_it(
    capsys: pytest.CaptureFixture[str], command: str, tmp_path: Path
) -> None:
    more = ["--trials", "20"] if command == "simulate" else ["--out", str(tmp_path / "f")]
    want = _run(capsys, "plan", BRACKET, "--pose", "4", "--jaw-height", "30")
    got = _run(capsys, command, BRACKET, "--element", "4", "--jaw-height", "30", *more)
    assert want[0] == got[0] == 2
    assert got[1] == "" and got[2].count("\n") == 1 and "topples pose 4" in got[2]
    assert not (tmp_path / "f").exists()


def test_a_pose_that_holds_is_simulated_with_a_note(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = _run(capsys, "simulate", BRACKET, "--jaw-height", "30", "--trials", "20")
    assert code == 0 and "bracket-pose-0" in out
    assert "no squeeze with the jaws at height 30 topples pose 0" in err


def test_a_policy_over_poses_that_topple_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    args = ("--sense", "width", "--jaw-height", "30")
    plan = _run(capsys, "plan", BRACKET, *args)
    sim = _run(capsys, "simulate", BRACKET, *args, "--trials", "20")
    assert plan[0] == sim[0] == 2 and plan[2] == sim[2]


def test_jaw_height_needs_a_mesh(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, "simulate", "house", "--jaw-height", "3")
    assert code == 2 and "needs a mesh PART" in err
