"""Sensing policies through ``plan --plot`` and ``plan --batch``, and the one length option.

``plan PART --sense S --plot FILE`` draws the policy it planned (the figure ``plot --sense``
draws, from one planning); ``plan --batch FILE.jsonl --sense S`` writes one policy document
a line, each the single run's ``--json`` document; ``--max-actions`` is the longest plan and
the deepest policy, ``--max-squeezes`` its old name giving byte-identical output.
"""

from __future__ import annotations

import io
import json
import re
import sys
from pathlib import Path
from typing import Any

import pytest

import bayesgrasp.figures.policy as policy_figures
import bayesgrasp.planning.policy as policy_planning
from bayesgrasp.cli import main

SQUARE = {"name": "sq", "vertices": [[0, 0], [3, 0], [3, 2], [0, 2]]}


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def refused(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    code, out, err = run(capsys, *args)
    assert code == 2 and out == "", (code, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def single(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """The single run's ``--json`` document, as a batch line writes it."""
    code, out, err = run(capsys, "plan", *args, "--json")
    assert code == 0, err
    return json.dumps(json.loads(out), allow_nan=False)


def batch_file(tmp_path: Path, *lines: Any) -> Path:
    path = tmp_path / "parts.jsonl"
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    return path


# --- plan PART --sense S --plot FILE ---------------------------------------------------


def test_plot_draws_the_policy_of_plot_sense(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The figure is byte for byte ``plot --sense``'s, and the policy is planned once."""
    calls = []
    plan_policy = policy_planning.plan_policy

    def counted(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        return plan_policy(*args, **kwargs)

    monkeypatch.setattr(policy_planning, "plan_policy", counted)
    sense = ["--sense", "width:0.5,0.1", "--also", "rectangle", "--max-actions", "2"]
    figure = tmp_path / "policy.png"
    code, out, err = run(capsys, "plan", "house", *sense, "--plot", str(figure))
    assert code == 0 and err == f"bayesgrasp: wrote {figure}\n"
    assert len(calls) == 1
    assert run(capsys, "plan", "house", *sense) == (0, out, "")  # the same text without --plot
    folder = tmp_path / "figs"
    argv = ["plot", "house", *sense, "--out", str(folder), "--image-formats", "png"]
    assert run(capsys, *argv)[0] == 0
    assert figure.read_bytes() == (folder / "policy.png").read_bytes()


def test_plot_and_export_together(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    figure, robot = tmp_path / "p.svg", tmp_path / "{name}-robot.json"
    code, out, err = run(
        capsys, "plan", "key", "--sense", "width", "--plot", str(figure), "--export", str(robot)
    )
    assert code == 0 and figure.stat().st_size > 1000
    filled = tmp_path / "key-robot.json"  # a template is filled for one part too
    assert json.loads(filled.read_text())["states"]
    assert err.splitlines() == [f"bayesgrasp: wrote {figure}", f"bayesgrasp: wrote {filled}"]
    assert out.startswith("squeeze with the gripper")


def test_fold_below_given_folds_the_figure(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen: list[float] = []
    draw = policy_figures.policy_figure

    def spy(problems: Any, policy: Any, min_probability: float = 0.05) -> Any:
        seen.append(min_probability)
        return draw(problems, policy, min_probability)

    monkeypatch.setattr(policy_figures, "policy_figure", spy)
    sense = ["plan", "house", "--sense", "width:0.5,0.1", "--max-actions", "2", "--force"]
    for fold in ([], ["--fold-below", "0.2"], ["--fold-below", "0"]):
        assert run(capsys, *sense, *fold, "--plot", str(tmp_path / "p.png"))[0] == 0
    assert seen == [0.05, 0.2, 0.0]


def test_plot_file_checks(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    part = tmp_path / "sq.json"
    part.write_text(json.dumps(SQUARE))
    figure = tmp_path / "p.png"
    figure.write_bytes(b"old")
    sense = ["plan", str(part), "--sense", "width"]
    assert "exists; use --force" in refused(capsys, *sense, "--plot", str(figure))
    assert figure.read_bytes() == b"old"
    err = refused(capsys, *sense, "--export", str(part), "--force")
    assert "is an input of this command" in err and json.loads(part.read_text()) == SQUARE
    weird = tmp_path / "in.png"  # an input file that ends in .png: never written over
    weird.write_text(json.dumps(SQUARE))
    err = refused(capsys, "plan", str(weird), "--format", "json", "--sense", "width",
                  "--plot", str(weird), "--force")  # fmt: skip
    assert "is an input of this command" in err
    assert json.loads(weird.read_text()) == SQUARE
    assert "must end in .png, .svg or .pdf" in refused(capsys, *sense, "--plot", "p.gif")
    assert "no folder" in refused(capsys, *sense, "--plot", str(tmp_path / "no" / "p.png"))
    code, _, err = run(capsys, *sense, "--plot", str(figure), "--force")
    assert code == 0 and figure.read_bytes()[:4] == b"\x89PNG"


# --- plan --batch FILE.jsonl --sense S ------------------------------------------------


@pytest.mark.parametrize(
    "options",
    [
        ["--sense", "width"],
        ["--sense", "width:0.5,0.1", "--max-actions", "2"],
        ["--sense", "width", "--also", "rectangle", "--part-prior", "1,3", "--max-squeezes", "2"],
    ],
    ids=["exact", "noisy sensor", "candidates"],
)
def test_batch_lines_equal_the_single_runs(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, options: list[str]
) -> None:
    lever = Path(__file__).resolve().parents[2] / "examples" / "lever.svg"  # a curved part
    square = {**SQUARE, "units": "mm"}  # the candidates are in mm: widths compare
    part = tmp_path / "sq.json"
    part.write_text(json.dumps(square))
    batch = batch_file(tmp_path, "house", str(part), square, str(lever))
    code, out, err = run(capsys, "plan", "--batch", str(batch), *options)
    assert (code, err) == (0, "")
    expected = [single(capsys, p, *options) for p in ["house", str(part), str(part), str(lever)]]
    assert out.splitlines() == expected
    assert [json.loads(x)["parts"][0] for x in expected] == ["house", "sq", "sq", "lever"]


def test_batch_bad_parts_in_their_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    batch = batch_file(tmp_path, "house", "no-such-part", [1, 2], {"name": "x"}, "key")
    code, out, err = run(capsys, "plan", "--batch", str(batch), "--sense", "width")
    docs = [json.loads(x) for x in out.splitlines()]
    assert code == 2 and err == "" and len(docs) == 5
    assert docs[0]["parts"] == ["house"] and docs[4]["parts"] == ["key"]
    for number, doc in zip([2, 3, 4], docs[1:4], strict=True):
        assert doc["part"] == f"{batch}:{number}" and doc["exit_code"] == 2 and doc["error"]
    assert out.splitlines()[4] == single(capsys, "key", "--sense", "width")


def test_batch_from_stdin(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO('"triangle"\n\n"key"\n'))
    code, out, err = run(capsys, "plan", "--batch", "-", "--sense", "width")
    assert (code, err) == (0, "")
    assert out.splitlines() == [single(capsys, p, "--sense", "width") for p in ["triangle", "key"]]


def test_batch_files_one_a_part(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    batch = batch_file(tmp_path, "house", "key", "key")
    plot, export = tmp_path / "{name}.png", tmp_path / "{name}.csv"
    (tmp_path / "house.csv").write_text("old")
    args = ["plan", "--batch", str(batch), "--sense", "width", "--plot", str(plot)]
    code, out, err = run(capsys, *args, "--export", str(export))
    docs = [json.loads(x) for x in out.splitlines()]
    assert code == 2 and len(docs) == 3
    assert "house.csv' exists; use --force" in docs[0]["error"]  # its files refused
    assert not (tmp_path / "house.png").exists() and (tmp_path / "house.csv").read_text() == "old"
    assert docs[1]["parts"] == ["key"]  # the others go on
    assert "written for an earlier part" in docs[2]["error"]
    assert (tmp_path / "key.png").stat().st_size > 1000
    assert (tmp_path / "key.csv").read_text().startswith("#")
    assert err.splitlines() == [f"bayesgrasp: wrote {tmp_path}/key.{x}" for x in ("png", "csv")]
    code, out, _ = run(capsys, *args, "--force")
    assert code == 2 and [json.loads(x).get("exit_code") for x in out.splitlines()] == [
        None
    ] * 2 + [2]
    indexed = tmp_path / "{name}-{index}.png"
    code, out, err = run(capsys, "plan", "--batch", str(batch), "--sense", "width", "--plot",
                         str(indexed))  # fmt: skip
    assert code == 0 and all(
        (tmp_path / f"{n}.png").exists() for n in ("house-1", "key-2", "key-3")
    )


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--plot", "p.png"], "give a path with {name}"),
        (["--export", "r.csv"], "give a path with {name}"),
        (["--plot", "{name}.gif"], "must end in .png, .svg or .pdf"),
        (["--export", "nowhere/{name}.csv"], "no folder 'nowhere'"),
        (["--also", "no-such-part"], "no-such-part"),
        (["--sense", "width:1"], "sensor must be written"),
        (["--sense", "width", "--max-actions", "9"], "at most 8 actions deep"),
        (["--sense", "width", "--guaranteed"], "takes no --guaranteed"),
    ],
)
def test_batch_refused_before_any_line(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    match: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    batch = batch_file(tmp_path, "house")
    sense = [] if "--sense" in args else ["--sense", "width"]
    assert match in refused(capsys, "plan", "--batch", str(batch), *sense, *args)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["parts.jsonl"]


def test_batch_with_part_beside_it_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    batch = batch_file(tmp_path, "house")
    err = refused(capsys, "plan", "key", "--batch", str(batch), "--sense", "width")
    assert "give PART in the batch file" in err
    assert "cannot read" in refused(
        capsys, "plan", "--batch", str(tmp_path / "missing.jsonl"), "--sense", "width"
    )


def test_batch_stroke_per_part(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A part outside the gripper's stroke gets its error line, as the single run exits 2."""
    batch = batch_file(tmp_path, SQUARE, {"name": "big", "vertices": [[0, 0], [90, 0], [0, 60]]})
    code, out, _ = run(capsys, "plan", "--batch", str(batch), "--sense", "width",
                       "--max-opening", "10")  # fmt: skip
    small, big = (json.loads(x) for x in out.splitlines())
    assert code == 2 and small["parts"] == ["sq"]
    assert big["exit_code"] == 2 and "does not fit the gripper's stroke" in big["error"]
    path = tmp_path / "big.json"
    path.write_text(json.dumps({"name": "big", "vertices": [[0, 0], [90, 0], [0, 60]]}))
    err = refused(capsys, "plan", str(path), "--sense", "width", "--max-opening", "10")
    assert big["error"] in err


# --- one length option: --max-actions, --max-squeezes its old name ----------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["plan", "key", "--json"],
        ["plan", "tuning-fork", "--actions", "squeeze,push-grasp"],
        ["plan", "key", "--method", "bfs", "--json"],
        ["plan", "key", "--turn-noise", "normal:2", "--json"],
        ["plan", "house", "--sense", "width:0.5,0.1", "--json"],
        ["plan", "house", "--sense", "width"],
        ["simulate", "key", "--trials", "3000", "--json"],
        ["simulate", "house", "--sense", "width", "--trials", "2000", "--json"],
    ],
    ids=lambda a: " ".join(a),
)
def test_old_name_gives_the_same_bytes(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    def timeless(*args: str) -> tuple[int, str, str]:  # a simulation's own running time out
        code, out, err = run(capsys, *argv, *args)
        return code, re.sub(r'\n *"seconds": [0-9.e-]+,?', "", out), err

    new = timeless("--max-actions", "2")
    assert new[0] == 0
    assert timeless("--max-squeezes", "2") == new
    assert timeless("--max-actions", "2", "--max-squeezes", "2") == new


@pytest.mark.parametrize(
    ("sense", "figure"), [([], "plan.png"), (["--sense", "width"], "policy.png")]
)
def test_old_name_draws_the_same_figures(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, sense: list[str], figure: str
) -> None:
    drawn = []
    for name in ("--max-actions", "--max-squeezes"):
        out = tmp_path / name
        argv = ["plot", "tuning-fork", *sense, name, "1", "--out", str(out)]
        code, printed, _ = run(capsys, *argv, "--image-formats", "png", "--no-animation")
        assert code == 0
        drawn.append((printed.replace(name, ""), (out / figure).read_bytes()))
    assert drawn[0] == drawn[1]


def test_one_option_is_the_longest_plan_and_the_deepest_policy(
    capsys: pytest.CaptureFixture[str],
) -> None:
    free = json.loads(run(capsys, "plan", "hand", "--json")[1])
    capped = json.loads(run(capsys, "plan", "hand", "--max-actions", "2", "--json")[1])
    assert max(len(o["steps"]) for o in free["options"]) > 2  # its own bound, longer
    assert max(len(o["steps"]) for o in capped["options"]) == 2
    assert capped["options"] == [o for o in free["options"] if len(o["steps"]) <= 2]
    policy = json.loads(run(capsys, "plan", "house", "--sense", "width", "--json")[1])
    assert policy["max_actions"] == 3  # a policy's default depth
    deep = json.loads(run(capsys, "plan", "house", "--sense", "width", "--max-actions", "4",
                          "--json")[1])  # fmt: skip
    assert deep["max_actions"] == 4 and deep["expected_cost"] <= policy["expected_cost"]
    # simulate without --sense: the plan it runs is the longest plan's Bayes plan
    sim = json.loads(run(capsys, "simulate", "hand", "--max-actions", "1", "--trials",
                         "2000", "--json")[1])  # fmt: skip
    one = next(o for o in free["options"] if len(o["steps"]) == 1)
    assert sim["predicted_success"] == one["success_probability"]
    assert sim["plan"]["steps"] == [
        {"type": s["type"], "alpha_rad": s["alpha_rad"]} for s in one["steps"]
    ]


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["plan", "key", "--max-actions", "2", "--max-squeezes", "3"], "old name of --max-actions"),
        (["plan", "key", "--max-actions", "0"], "--max-actions"),
        (["plan", "key", "--sense", "width", "--max-actions", "9"], "at most 8 actions deep"),
        (["simulate", "key", "--sense", "width", "--max-squeezes", "9"], "at most 8 actions"),
        (["plot", "key", "--sense", "width", "--max-actions", "12"], "at most 8 actions deep"),
        (["plan", "key", "--fold-below", "0.1"], "--fold-below needs --sense"),
    ],
)
def test_length_refused(capsys: pytest.CaptureFixture[str], argv: list[str], match: str) -> None:
    assert match in refused(capsys, *argv)


def test_deep_plans_need_no_sense(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "plan", "key", "--max-actions", "9", "--only", "best")[0] == 0


@pytest.mark.parametrize("command", ["plan", "simulate", "plot", "sweep"])
def test_help_names_one_length_option(capsys: pytest.CaptureFixture[str], command: str) -> None:
    code, out, _ = run(capsys, command, "--help")
    text = " ".join(out.split())
    assert code == 0 and "--max-actions" in text and "--max-squeezes" not in text
    assert "with --sense, the deepest policy (default 3, at most 8)" in text
    assert "--sense" in text  # every command that says --sense has it


def sweep_options(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path, *args: str
) -> Any:
    """The options ``sweep`` runs with (the sweep itself not run)."""
    import typer

    import bayesgrasp.sweep as sweeps

    seen = []

    def capture(paths: Any, out: Any, options: Any, **kwargs: Any) -> Any:
        seen.append(options)
        raise typer.Exit(0)

    monkeypatch.setattr(sweeps, "run_sweep", capture)
    parts = tmp_path / "parts"  # results never go where the sweep reads parts
    parts.mkdir(exist_ok=True)
    argv = ["sweep", str(parts), "--out", str(tmp_path / "rows.csv"), *args]
    assert run(capsys, *argv)[0] == 0
    return seen[0]


def test_sweep_takes_the_one_option(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    default = sweep_options(capsys, monkeypatch, tmp_path, "--sense", "width")
    assert (default.max_actions, default.sense_max_actions) == (None, 3)
    given = sweep_options(capsys, monkeypatch, tmp_path, "--sense", "width", "--max-actions", "2")
    assert (given.max_actions, given.sense_max_actions) == (2, 2)
    assert (
        sweep_options(capsys, monkeypatch, tmp_path, "--sense", "width", "--max-squeezes", "2")
        == given
    )
    plain = sweep_options(capsys, monkeypatch, tmp_path, "--max-squeezes", "12")
    assert (plain.max_actions, plain.sense) == (12, None)
    err = refused(capsys, "sweep", str(tmp_path / "parts"), "--out", str(tmp_path / "r.csv"),
                  "--sense", "width", "--max-actions", "9")  # fmt: skip
    assert "at most 8 actions deep" in err
