"""``plan PART PART ...``, ``plan --batch FILE.jsonl`` and ``plan --only best``.

Each line of a batch is the document ``plan PART --json`` prints for that part alone; a bad
part is reported in its line and the batch goes on.
"""

from __future__ import annotations

import json
import select
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bayesgrasp.cli import main
from bayesgrasp.shapes import names


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def single(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, Any]:
    code, out, err = run(capsys, "plan", *args, "--json")
    assert (code, err) == (0, ""), err
    doc = json.loads(out)
    assert isinstance(doc, dict)
    return doc


def lines(out: str) -> list[dict[str, Any]]:
    return [json.loads(x) for x in out.splitlines()]


OPTION_SETS = [
    [],
    ["--actions", "squeeze,push-grasp", "--push-grasp-cost", "0.7"],
    ["--accuracy", "2", "--goal", "symmetry"],
    ["--only", "best"],
    ["--method", "bfs", "--only", "best"],
]


@pytest.mark.parametrize("options", OPTION_SETS, ids=lambda o: " ".join(o) or "default")
def test_several_parts_equal_each_alone(
    capsys: pytest.CaptureFixture[str], options: list[str]
) -> None:
    parts = names()[:5]
    code, out, err = run(capsys, "plan", *parts, *options)
    assert (code, err) == (0, "")
    assert lines(out) == [single(capsys, p, *options) for p in parts]


def test_batch_equals_each_part_alone(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, rng: np.random.Generator
) -> None:
    rows, expected = [], []
    for k in range(6):
        pts = rng.random((10, 2)).round(6)  # in angular order: an outline, not a point cloud
        c = pts.mean(axis=0)
        vertices = pts[np.argsort(np.arctan2(*(pts - c).T[::-1]))].tolist()
        obj = {"name": f"random-{k}", "vertices": vertices}
        rows.append(json.dumps(obj))
        path = tmp_path / f"random-{k}.json"
        path.write_text(json.dumps(obj))
        expected.append(single(capsys, str(path)))
    rows.append(json.dumps("house"))
    expected.append(single(capsys, "house"))
    batch = tmp_path / "parts.jsonl"
    batch.write_text("\n".join(rows) + "\n\n")
    code, out, err = run(capsys, "plan", "--batch", str(batch))
    assert (code, err) == (0, "")
    assert lines(out) == expected
    # PART arguments come first, then the batch.
    code, out, _ = run(capsys, "plan", "key", "--batch", str(batch))
    assert lines(out) == [single(capsys, "key"), *expected]


@pytest.mark.parametrize(
    "options",
    [*OPTION_SETS[1:3], ["--prior", "vonmises:30,4", "--verify-cost", "2"]],
    ids=lambda o: " ".join(o),
)
def test_batch_with_options_equals_each_part_alone(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, options: list[str]
) -> None:
    # The batch makes the prior, costs and goal once for all its parts.
    parts = names()[:3]
    rows = [json.dumps(p) for p in parts]
    rows.append(json.dumps({"name": "sq", "vertices": [[0, 0], [2, 0], [2, 1], [0, 1]]}))
    batch = tmp_path / "parts.jsonl"
    batch.write_text("\n".join(rows))
    sq = tmp_path / "sq.json"
    sq.write_text(rows[-1])
    code, out, err = run(capsys, "plan", "--batch", str(batch), *options)
    assert (code, err) == (0, "")
    alone = [single(capsys, p, *options) for p in [*parts, str(sq)]]
    docs = lines(out)
    assert docs == alone


def test_bad_parts_are_reported_in_their_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    batch = tmp_path / "mixed.jsonl"
    rows = [
        '"triangle"',
        '{"name": "segment", "vertices": [[0, 0], [1, 1]]}',
        "[1, 2]",
        "not json",
        '"no-such-part"',
        '{"name": "square", "vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]}',
    ]
    batch.write_text("\n".join(rows))
    code, out, err = run(capsys, "plan", "--batch", str(batch))
    assert code == 2 and err == ""
    docs = lines(out)
    assert len(docs) == 6
    assert docs[0] == single(capsys, "triangle")
    assert docs[5]["part"]["name"] == "square" and "error" not in docs[5]
    for n, doc in zip([2, 3, 4, 5], docs[1:5], strict=True):
        assert doc["part"] == f"{batch}:{n}" and doc["exit_code"] == 2
        assert "\n" not in doc["error"]
    assert "3 distinct points" in docs[1]["error"]
    assert "got list" in docs[2]["error"]
    assert "not a JSON value" in docs[3]["error"]
    assert "neither a catalogue part" in docs[4]["error"]


def test_no_plan_gives_exit_code_one(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "plan", "key", "rectangle", "--guaranteed", "--accuracy", "30")
    docs = lines(out)
    assert code == 1 and len(docs) == 2
    assert docs[0]["guaranteed"] is None and docs[0]["guaranteed_missing"]


def test_usage_errors(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = run(capsys, "plan")
    assert code == 2 and "give a PART" in err
    code, _, err = run(capsys, "plan", "--batch", str(tmp_path / "missing.jsonl"))
    assert code == 2 and "cannot read" in err and "\n" == err[-1] and err.count("\n") == 1
    code, _, err = run(capsys, "plan", "key", "house", "--plot", str(tmp_path / "a.png"))
    assert code == 2 and "several parts need one file each" in err and "{name}" in err


def test_only_best_is_the_bayes_and_most_certain(capsys: pytest.CaptureFixture[str]) -> None:
    for part in ["house", "key", "tuning-fork"]:
        every, best = single(capsys, part), single(capsys, part, "--only", "best")
        chosen = sorted({every["bayes"], every["most_certain"]})
        assert best["options"] == [every["options"][i] for i in chosen]
        assert best["options"][best["bayes"]] == every["options"][every["bayes"]]
        assert best["options"][best["most_certain"]] == every["options"][every["most_certain"]]
        assert {k: v for k, v in best.items() if k not in ("options", "bayes", "most_certain")} == {
            k: v for k, v in every.items() if k not in ("options", "bayes", "most_certain")
        }


def test_several_parts_with_sense_are_recognition(capsys: pytest.CaptureFixture[str]) -> None:
    a = run(capsys, "plan", "rectangle", "triangle", "--sense", "width", "--json")
    b = run(capsys, "plan", "rectangle", "--also", "triangle", "--sense", "width", "--json")
    assert a[0] == 0 and a == b


def test_batch_lines_are_json_dumps_of_each_document(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Byte for byte: a batch line is ``json.dumps`` of the document ``plan PART --json``
    prints (its floats read back exactly), the provenance shared between lines included."""
    lever = Path(__file__).resolve().parents[2] / "examples" / "lever.svg"  # a curved part
    parts = ["key", "triangle", str(lever)]
    batch = tmp_path / "parts.jsonl"
    batch.write_text("\n".join(json.dumps(p) for p in parts) + "\n")
    for options in ([], ["--actions", "squeeze,push-grasp", "--guaranteed"]):
        code, out, err = run(capsys, "plan", "--batch", str(batch), *options)
        assert (code, err) == (0, "")
        expected = [json.dumps(single(capsys, p, *options), allow_nan=False) for p in parts]
        assert out.splitlines() == expected


def test_a_line_that_is_not_utf8_is_reported_in_its_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    batch = tmp_path / "latin.jsonl"
    batch.write_bytes(
        b'"house"\n{"name": "caf\xe9", "vertices": [[0, 0], [1, 0], [0, 1]]}\n"key"\n'
    )
    code, out, err = run(capsys, "plan", "--batch", str(batch))
    docs = lines(out)
    assert (code, err, len(docs)) == (2, "", 3)
    assert docs[1] == {
        "part": f"{batch}:2",
        "error": f"{batch}:2: not UTF-8 text; save the file as UTF-8",
        "exit_code": 2,
    }
    assert docs[0] == single(capsys, "house") and docs[2] == single(capsys, "key")


def _study_rows(count: int, seed: int = 3) -> list[str]:
    rng = np.random.default_rng(seed)
    rows = []
    for k in range(count):
        pts = rng.random((10, 2))
        c = pts.mean(axis=0)
        outline = pts[np.argsort(np.arctan2(*(pts - c).T[::-1]))].tolist()  # angular order
        rows.append(json.dumps({"name": f"r{k}", "vertices": outline}))
    return rows


def test_groups_give_the_lines_of_one_part_at_a_time(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Parts planned stage by stage in groups (bad ones among them, a large part ending a
    group early) give the lines, in order, that one part at a time gives."""
    from bayesgrasp.cli import batch as batch_module

    rows = _study_rows(2 * batch_module.GROUP + 5)
    rows[3] = '{"name": "segment", "vertices": [[0, 0], [1, 1]]}'  # fails when read
    rows[7] = '"no-such-part"'
    t = np.linspace(0.0, 2 * np.pi, 100, endpoint=False)
    rows[20] = json.dumps({"name": "round", "vertices": np.c_[np.cos(t), np.sin(t)].tolist()})
    path = tmp_path / "parts.jsonl"
    path.write_text("\n".join(rows) + "\n")
    seen: list[list[str]] = []
    finish = batch_module._finish

    def spy(group: list[tuple[str, Any]], *args: Any) -> int:
        seen.append([label.rsplit(":", 1)[1] for label, _ in group])
        return finish(group, *args)

    monkeypatch.setattr(batch_module, "_finish", spy)
    size = batch_module.GROUP
    code, grouped, err = run(capsys, "plan", "--batch", str(path), "--guaranteed")
    monkeypatch.setattr(batch_module, "GROUP", 1)
    code_1, alone, err_1 = run(capsys, "plan", "--batch", str(path), "--guaranteed")
    assert (code, err) == (code_1, err_1) == (2, "")
    assert grouped == alone and len(grouped.splitlines()) == len(rows)
    assert "3 distinct points" in json.loads(grouped.splitlines()[3])["error"]
    # The 100-gon (line 21) ends the first group, then full groups and the rest; the run
    # with GROUP = 1 adds its one-line groups after.
    assert [len(g) for g in seen] == [21, size, len(rows) - 21 - size] + [1] * len(rows)
    assert seen[0][-1] == "21"


def test_a_bug_in_a_group_writes_the_lines_before_it(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A failure that is not a bad part still raises, after the lines of the parts before."""
    from bayesgrasp.planning import exact

    path = tmp_path / "parts.jsonl"
    rows = _study_rows(12)
    path.write_text("\n".join(rows) + "\n")
    code, before, _ = run(capsys, "plan", "--batch", str(path))
    plan = exact.plan_exact

    def broken(problem: Any, **kwargs: Any) -> Any:
        if problem.part.name == "r5":
            raise RuntimeError("a bug")
        return plan(problem, **kwargs)

    monkeypatch.setattr(exact, "plan_exact", broken)
    monkeypatch.setattr("bayesgrasp.planning.plan_exact", broken)
    with pytest.raises(RuntimeError, match="a bug"):
        main(["plan", "--batch", str(path)])
    out, _ = capsys.readouterr()
    assert code == 0 and out == "".join(before.splitlines(keepends=True)[:5])


def test_lines_from_stdin_are_answered_as_they_come(tmp_path: Path) -> None:
    """A program that writes a line and waits for its answer is answered (no grouping)."""
    rows = _study_rows(3)
    with subprocess.Popen(
        [sys.executable, "-m", "bayesgrasp.cli", "plan", "--batch", "-"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    ) as proc:
        assert proc.stdin is not None and proc.stdout is not None
        try:
            for k, row in enumerate(rows):
                proc.stdin.write(row + "\n")
                proc.stdin.flush()
                ready, _, _ = select.select([proc.stdout], [], [], 60)
                assert ready, f"no answer to line {k + 1} in 60 s"
                assert json.loads(proc.stdout.readline())["part"]["name"] == f"r{k}"
            proc.stdin.close()
            assert proc.wait(timeout=60) == 0 and proc.stdout.read() == ""
        finally:
            proc.kill()
