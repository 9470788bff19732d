"""No command writes over the user's files: inputs never, other existing files only with --force.

``check_outputs`` (cli/common.py) is the one rule; ``plan --plot``, ``plan --export`` and
``plot --out`` go through it. An output that resolves to an input (the part file, a prior
file, a plan file; through a symlink, a hard link or another letter case) is refused even
with ``--force``.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

from bayesgrasp.cli import main
from bayesgrasp.cli.common import check_outputs, input_files

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

HOUSE = Path(__file__).resolve().parents[2] / "src" / "bayesgrasp" / "shapes" / "house.json"


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def one_error(err: str, *words: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in lines[0], err


def test_plan_plot_refuses_existing_file(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"my own picture")
    code, out, err = run(capsys, "plan", "triangle", "--plot", "mine.png")
    assert code == 2 and out == ""
    one_error(err, "mine.png", "exists", "--force")
    assert mine.read_bytes() == b"my own picture"
    code, out, err = run(capsys, "plan", "triangle", "--plot", "mine.png", "--force")
    assert code == 0, err
    assert mine.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("how", ["same", "symlink", "hardlink", "case"])
def test_plan_plot_never_replaces_the_part(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, how: str
) -> None:
    part = tmp_path / "in.svg"
    part.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><polygon points="0,0 30,0 30,20 0,20"/></svg>',
        encoding="utf-8",
    )
    before = digest(part)
    target = {"same": part, "case": tmp_path / "IN.SVG"}.get(how, tmp_path / "link.svg")
    if how == "symlink":
        target.symlink_to(part)
    elif how == "hardlink":
        os.link(part, target)
    code, out, err = run(capsys, "plan", str(part), "--plot", str(target), "--force")
    assert code == 2 and out == ""
    one_error(err, "input", "refusing")
    assert digest(part) == before


def test_prior_file_is_an_input(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    prior = tmp_path / "weights.svg"  # a figure name, so only the input rule can refuse it
    prior.write_text("1 2 3 4\n", encoding="utf-8")
    code, _, err = run(
        capsys, "plan", "triangle", "--prior", f"histogram:{prior}", "--plot", str(prior), "--force"
    )
    assert code == 2
    one_error(err, "input")
    assert prior.read_text(encoding="utf-8") == "1 2 3 4\n"


def test_plot_out_refuses_existing_figures(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "figs"
    args = ["plot", "triangle", "--out", str(out), "--image-formats", "svg", "--no-animation"]
    code, _, err = run(capsys, *args)
    assert code == 0, err
    (out / "diameter.svg").write_text("mine", encoding="utf-8")
    code, stdout, err = run(capsys, *args)
    assert code == 2 and stdout == ""
    one_error(err, "part.svg", "exists (and 3 more", "--force")
    assert (out / "diameter.svg").read_text(encoding="utf-8") == "mine"
    code, _, err = run(capsys, *args, "--force")
    assert code == 0, err
    assert (out / "diameter.svg").read_text(encoding="utf-8") != "mine"


def test_plot_out_never_replaces_the_part(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    part = tmp_path / "part.svg"
    part.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><polygon points="0,0 30,0 30,20 0,20"/></svg>',
        encoding="utf-8",
    )
    before = digest(part)
    args = ["plot", str(part), "--out", str(tmp_path), "--no-animation", "--force"]
    code, _, err = run(capsys, *args)
    assert code == 2
    one_error(err, "part.svg", "input")
    assert digest(part) == before
    assert not (tmp_path / "part.png").exists()  # refused before any figure was written


def test_plot_plan_file_is_an_input(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, doc, _ = run(capsys, "plan", "triangle", "--json")
    assert code == 0
    plan = tmp_path / "p.json"
    plan.write_text(doc, encoding="utf-8")
    out = tmp_path / "figs"
    out.mkdir()
    (out / "plan.svg").symlink_to(plan)  # writing the figure would write the plan file
    args = ["plot", "triangle", "--plan", str(plan), "--out", str(out), "--image-formats", "svg"]
    code, _, err = run(capsys, *args, "--force")
    assert code == 2
    one_error(err, "plan.svg", "input")
    assert plan.read_text(encoding="utf-8") == doc


def test_check_outputs_rules(tmp_path: Path) -> None:
    a = tmp_path / "a.png"
    check_outputs([a], [], force=False)  # a new file: fine
    a.write_bytes(b"x")
    with pytest.raises(Exception, match="exists; use --force to replace"):
        check_outputs([a], [])
    check_outputs([a], [], force=True)
    with pytest.raises(Exception, match="is a folder"):
        check_outputs([tmp_path], [], force=True)
    with pytest.raises(Exception, match="input"):
        check_outputs([tmp_path / "sub" / ".." / "a.png"], [a], force=True)


def test_input_files(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("w.txt").write_text("1 1", encoding="utf-8")
    Path("p.json").write_text("{}", encoding="utf-8")
    got = input_files("triangle", "histogram:w.txt", "p.json", None, "bayes")
    assert sorted(p.name for p in got) == ["p.json", "w.txt"]
    assert input_files("-", "uniform") == []
    assert input_files(str(HOUSE), "vonmises:0,1") == [HOUSE]


def test_sweep_never_writes_over_its_inputs(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    part = tmp_path / "a.csv"
    part.write_text("0,0\n3,0\n0,2\n", encoding="utf-8")
    before = digest(part)
    argv = ["sweep", str(part), "--out", str(part), "--format", "csv", "--force"]
    code, _, err = run(capsys, *argv)
    assert code == 2
    one_error(err, "input")
    report = tmp_path / "r.html"
    report.write_text("mine", encoding="utf-8")
    argv = ["sweep", str(part), "--out", str(tmp_path / "rows.csv"), "--format", "csv"]
    code, _, err = run(capsys, *argv, "--report", str(report))
    assert code == 2
    one_error(err, "r.html", "exists")
    code, _, err = run(capsys, *argv, "--report", str(part), "--force")
    assert code == 2
    one_error(err, "input")
    assert digest(part) == before and report.read_text(encoding="utf-8") == "mine"


@pytest.mark.parametrize("sense", [[], ["--sense", "width"]], ids=["plan", "policy"])
def test_plot_into_an_unwritable_folder_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, sense: list[str]
) -> None:
    blocker = tmp_path / "file.txt"
    blocker.write_text("mine")
    out = blocker / "figures"  # a folder below a file cannot be made
    args = ["plot", "triangle", "--out", str(out), "--no-animation", *sense]
    code, stdout, err = run(capsys, *args)
    assert (code, stdout) == (2, "")
    one_error(err, "cannot write into", str(out))
    assert blocker.read_text() == "mine"
