"""``plan --within-stroke``: plans of actions the stroke allows, through plan's surfaces."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.io import resolve_part
from bayesgrasp.io.export import Stroke, check_stroke
from bayesgrasp.io.plans import read_plan_document
from bayesgrasp.model import Problem
from bayesgrasp.model.prior import SamplePrior
from bayesgrasp.planning.stroke import plan_within_stroke

SAMPLES = [0.1, 0.2, 1.3]  # radians: the key's one squeeze closes to 24.26 from them


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def refused(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    code, out, err = run(capsys, *args)
    assert code == 2 and out == "", (code, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


@pytest.fixture
def prior(tmp_path: Path) -> str:
    path = tmp_path / "samples.txt"
    path.write_text("\n".join(repr(math.degrees(a)) for a in SAMPLES) + "\n")
    return f"sample:{path}"


def test_the_plan_within_the_stroke_is_the_planners(
    capsys: pytest.CaptureFixture[str], prior: str, tmp_path: Path
) -> None:
    argv = ["plan", "key", "--prior", prior, "--min-opening", "24.3", "--max-actions", "3"]
    err = refused(capsys, *argv, "--json")  # the Bayes plan does not fit: refused
    assert "less than the least opening" in err
    robot = tmp_path / "robot.json"
    code, out, err = run(capsys, *argv, "--within-stroke", "--json", "--export", str(robot))
    assert code == 0 and err == f"bayesgrasp: wrote {robot}\n"
    doc = json.loads(out)
    pb = Problem.build(resolve_part("key"), prior=SamplePrior(np.array(SAMPLES)))
    want = plan_within_stroke(pb, min_opening=24.3, max_actions=3)
    assert doc["method"] == "stroke" and doc["provenance"]["method"] == "stroke"
    got = [o["success_probability"] for o in doc["options"]]
    assert got == pytest.approx([o.success_probability for o in want.options], abs=1e-12)
    for which in ("bayes", "most-certain"):
        check_stroke(pb, read_plan_document(doc, which), Stroke(24.3, math.inf))
    steps = json.loads(robot.read_text())["steps"]
    bayes = doc["options"][doc["bayes"]]
    assert len(steps) == bayes["squeezes"]


def test_a_batch_line_is_the_single_run(
    capsys: pytest.CaptureFixture[str], prior: str, tmp_path: Path
) -> None:
    argv = ["--prior", prior, "--min-opening", "24.3", "--within-stroke", "--max-actions", "2"]
    code, single, _ = run(capsys, "plan", "key", *argv, "--json")
    assert code == 0
    batch = tmp_path / "parts.jsonl"
    batch.write_text('"key"\n')
    code, out, _ = run(capsys, "plan", "--batch", str(batch), *argv)
    assert code == 0 and json.loads(out) == json.loads(single)


def test_the_table(capsys: pytest.CaptureFixture[str], prior: str) -> None:
    argv = ["plan", "key", "--prior", prior, "--min-opening", "24.3", "--within-stroke"]
    code, out, _ = run(capsys, *argv, "--max-actions", "2")
    assert code == 0 and "method stroke" in out
    assert "1.0000" in out  # the two-squeeze plan orients every sample


@pytest.mark.parametrize(
    ("more", "words"),
    [
        ([], "needs the stroke"),
        (["--max-opening", "50", "--sense", "width"], "policy"),
        (["--max-opening", "50", "--turn-noise", "normal:2"], "noise-free"),
        (["--max-opening", "50", "--method", "bfs"], "--method"),
        (["--max-opening", "50", "--accuracy", "1"], "--accuracy"),
    ],
)
def test_refused_where_it_cannot_plan(
    capsys: pytest.CaptureFixture[str], more: list[str], words: str
) -> None:
    err = refused(capsys, "plan", "key", "--within-stroke", *more)
    assert words in err and "--within-stroke" in err


def test_a_part_wider_than_the_stroke_has_no_plan(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plan", "rectangle", "--max-opening", "30", "--within-stroke")
    assert code == 1 and out == "" and "no plan" in err and "widest" in err
