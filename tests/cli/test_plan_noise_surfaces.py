"""``plan`` with noise options through every surface, and per-part files for many parts.

Each combination either works and agrees with the single-part document (export angles =
the document's angles; a batch line = the single run's document; a plot file written and
not empty) or is refused with exit code 2 and one line naming the reason; none exits 0
with an option ignored.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.shapes import names

NOISES = [
    ["--turn-noise", "normal:2"],
    ["--turn-noise", "uniform:3", "--contact-noise", "0.1"],
    ["--contact-noise", "0.2"],
]
ZEROS = [
    ["--turn-noise", "normal:0"],
    ["--turn-noise", "uniform:0"],
    ["--contact-noise", "0"],
]


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def document(capsys: pytest.CaptureFixture[str], *args: str, code: int = 0) -> dict[str, Any]:
    got, out, err = run(capsys, "plan", *args, "--json")
    assert got == code, err
    doc = json.loads(out)
    assert isinstance(doc, dict)
    return doc


def refused(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    code, out, err = run(capsys, *args)
    assert code == 2 and out == "", (code, out, err)
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def bayes_angles(doc: dict[str, Any]) -> list[float]:
    return [s["alpha_rad"] for s in doc["options"][doc["bayes"]]["steps"]]


def robot_angles(path: Path) -> tuple[list[float], dict[str, Any]]:
    """The turns (rad) of a robot file, and its metadata (CSV header lines or JSON)."""
    if path.suffix == ".json":
        doc = json.loads(path.read_text())
        return [s["turn_rad"] for s in doc["steps"]], doc
    text = path.read_text().splitlines()
    meta = {}
    for line in text:
        if line.startswith("# "):
            key, _, value = line[2:].partition(": ")
            meta[key] = json.loads(value)
    rows = list(csv.DictReader(x for x in text if not x.startswith("#")))
    return [math.radians(float(r["turn_deg"])) for r in rows], meta


def same_where_shared(mine: Any, ref: Any) -> None:
    """Equal field by field where both documents have the field (``method`` aside)."""
    if isinstance(ref, dict):
        for key in ref.keys() & mine.keys():
            if key != "method":
                same_where_shared(mine[key], ref[key])
    elif isinstance(ref, list):
        assert len(mine) == len(ref)
        for a, b in zip(mine, ref, strict=True):
            same_where_shared(a, b)
    else:
        assert mine == ref


@pytest.mark.parametrize("noise", NOISES, ids=" ".join)
@pytest.mark.parametrize("ending", ["csv", "json"])
def test_export_is_the_documents_bayes_plan(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, noise: list[str], ending: str
) -> None:
    out = tmp_path / f"robot.{ending}"
    doc = document(capsys, "key", *noise, "--export", str(out))
    angles, meta = robot_angles(out)
    assert_allclose(angles, bayes_angles(doc), atol=1e-9)
    assert meta["noise"] == doc["noise"]
    if ending == "json":
        bayes = doc["options"][doc["bayes"]]
        assert meta["success_probability"] == bayes["success_probability"]


def test_export_with_a_payoff_writes_it(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    u = tmp_path / "u.csv"
    u.write_text("orientation_deg,value\n80.63,1\n260.63,0.5\n")
    out = tmp_path / "robot.json"
    doc = document(capsys, "key", "--payoff", str(u), "--export", str(out))
    angles, meta = robot_angles(out)
    assert_allclose(angles, bayes_angles(doc), atol=1e-9)
    assert meta["payoff"] == doc["payoff"]


@pytest.mark.parametrize("noise", NOISES[:2], ids=" ".join)
def test_plot_under_noise_is_written(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, noise: list[str]
) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "plan.svg"
    code, _, err = run(capsys, "plan", "key", *noise, "--plot", str(out))
    assert code == 0 and f"wrote {out}" in err
    svg = out.read_text()
    assert len(svg) > 10_000 and "under turn error" in svg


@pytest.mark.parametrize("noise", NOISES, ids=" ".join)
def test_several_parts_and_batch_equal_each_alone(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, noise: list[str]
) -> None:
    parts = ["key", "rectangle", "house"]
    alone = [document(capsys, p, *noise) for p in parts]
    code, out, _ = run(capsys, "plan", *parts, *noise)
    assert code == 0
    assert [json.loads(x) for x in out.splitlines()] == alone
    batch = tmp_path / "parts.jsonl"
    batch.write_text("".join(json.dumps(p) + "\n" for p in parts[1:]))
    code, out, _ = run(capsys, "plan", parts[0], "--batch", str(batch), *noise)
    assert code == 0
    assert [json.loads(x) for x in out.splitlines()] == alone


def test_only_best_under_noise(capsys: pytest.CaptureFixture[str]) -> None:
    full = document(capsys, "house", "--turn-noise", "normal:2")
    best = document(capsys, "house", "--turn-noise", "normal:2", "--only", "best")
    keep = sorted({full["bayes"], full["most_certain"]})
    assert best["options"] == [full["options"][i] for i in keep]
    assert best["noisy_options"] == [full["noisy_options"][i] for i in keep]
    assert best["options"][best["bayes"]] == full["options"][full["bayes"]]
    assert len(best["options"]) < len(full["options"])


def test_guaranteed_under_uniform_error_tolerates_it(capsys: pytest.CaptureFixture[str]) -> None:
    doc = document(capsys, "key", "--turn-noise", "uniform:3", "--guaranteed")
    g = doc["guaranteed"]
    assert g["tolerance_rad"] >= math.radians(3)
    plain = document(capsys, "key", "--guaranteed")["guaranteed"]
    assert g["squeezes"] >= plain["squeezes"]
    code, out, _ = run(capsys, "plan", "key", "--turn-noise", "uniform:3", "--guaranteed")
    assert code == 0 and "guaranteed under turn error uniform:3 deg" in out


def test_guaranteed_without_a_plan_exits_1_with_the_reason(
    capsys: pytest.CaptureFixture[str],
) -> None:
    args = ("house", "--turn-noise", "uniform:2", "--contact-noise", "0.1", "--guaranteed")
    doc = document(capsys, *args, code=1)
    assert doc["guaranteed"] is None
    assert "contact noise 0.1" in doc["guaranteed_missing"]
    assert "spans more than one orbit" in doc["guaranteed_missing"]
    code, out, _ = run(capsys, "plan", *args)
    assert code == 1 and "Guaranteed plan: none (" in out
    # Far more error than any plan tolerates: no plan, the turn error named.
    doc = document(capsys, "rectangle", "--turn-noise", "uniform:40", "--guaranteed", code=1)
    assert "no plan guarantees under turn error uniform:40 deg" in doc["guaranteed_missing"]


def test_guaranteed_under_contact_noise(capsys: pytest.CaptureFixture[str]) -> None:
    doc = document(
        capsys, "key", "--contact-noise", "0.1", "--turn-noise", "uniform:2", "--guaranteed"
    )
    g = doc["guaranteed"]
    assert g["tolerance_rad"] >= math.radians(2) and g["squeezes"] == 4
    assert g["success_probability"] <= 0.5 + 1e-12


def test_guaranteed_under_normal_error_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    err = refused(capsys, "plan", "key", "--turn-noise", "normal:1", "--guaranteed")
    assert "--guaranteed" in err and "unbounded" in err
    err = refused(capsys, "plan", "key", "house", "--turn-noise", "normal:1", "--guaranteed")
    assert "unbounded" in err


@pytest.mark.parametrize("zero", ZEROS, ids=" ".join)
@pytest.mark.parametrize("part", names())
def test_zero_noise_document_equals_the_noiseless_one(
    capsys: pytest.CaptureFixture[str], zero: list[str], part: str
) -> None:
    for extra in ([], ["--guaranteed", "--only", "best"]):
        ref = document(capsys, part, *extra)
        mine = document(capsys, part, *zero, *extra)
        assert mine["method"] == "noisy" and ref["method"] == "exact"
        same_where_shared(mine, ref)
        assert mine["options"] == ref["options"]
        assert (mine["bayes"], mine["most_certain"]) == (ref["bayes"], ref["most_certain"])


@pytest.mark.parametrize(
    "options",
    [
        ["--accuracy", "2", "--goal", "symmetry"],
        ["--actions", "squeeze,push-grasp", "--push-grasp-cost", "0.7"],
        ["--prior", "vonmises:30,2"],
        ["--max-squeezes", "2"],
        ["--retry-cost", "1", "--verify-cost", "2"],
    ],
    ids=" ".join,
)
@pytest.mark.parametrize("part", ["house", "key"])
def test_zero_noise_with_problem_options(
    capsys: pytest.CaptureFixture[str], options: list[str], part: str
) -> None:
    ref = document(capsys, part, *options)
    mine = document(capsys, part, "--turn-noise", "uniform:0", *options)
    same_where_shared(mine, ref)
    assert mine["provenance"] | {"method": "exact"} == ref["provenance"]


@pytest.mark.parametrize("noise", [[], NOISES[0]], ids=["no noise", "noise"])
@pytest.mark.parametrize("ending", ["csv", "json"])
def test_per_part_files_from_a_template(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, noise: list[str], ending: str
) -> None:
    pytest.importorskip("matplotlib")
    parts = ["key", "rectangle"]
    batch = tmp_path / "b.jsonl"
    batch.write_text(json.dumps("house") + "\n")
    robots = tmp_path / "robots"
    robots.mkdir()
    template = str(robots / f"{{name}}.{ending}")
    plots = str(robots / "{name}-{index}.png")
    argv = ["plan", *parts, "--batch", str(batch), *noise, "--export", template, "--plot", plots]
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    docs = [json.loads(x) for x in out.splitlines()]
    for i, (name, doc) in enumerate(zip([*parts, "house"], docs, strict=True), start=1):
        assert doc == document(capsys, name, *noise)
        angles, meta = robot_angles(robots / f"{name}.{ending}")
        assert_allclose(angles, bayes_angles(doc), atol=1e-9)
        assert meta.get("noise") == doc.get("noise")
        assert (robots / f"{name}-{i}.png").stat().st_size > 10_000
    # Again: every file exists, so every part's line is its error; --force replaces them.
    code, out, _ = run(capsys, *argv)
    errors = [json.loads(x) for x in out.splitlines()]
    assert code == 2 and all(e["exit_code"] == 2 and "exists" in e["error"] for e in errors)
    assert [e["part"] for e in errors] == [*parts, f"{batch}:1"]
    code, out, _ = run(capsys, *argv, "--force")
    assert code == 0 and [json.loads(x) for x in out.splitlines()] == docs


def test_a_template_fills_for_one_part(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    doc = document(capsys, "key", "--export", str(tmp_path / "{name}.csv"))
    angles, meta = robot_angles(tmp_path / "key.csv")
    assert_allclose(angles, bayes_angles(doc), atol=1e-9)
    assert meta == {}


def test_two_parts_of_one_name_do_not_share_a_file(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code, out, _ = run(capsys, "plan", "key", "key", "--export", str(tmp_path / "{name}.csv"))
    first, second = (json.loads(x) for x in out.splitlines())
    assert code == 2 and first["schema"].startswith("bayesgrasp.plan")
    assert "written for an earlier part" in second["error"] and "{index}" in second["error"]


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["key", "house", "--export", "robot.csv"], "give a path with {name}"),
        (["key", "house", "--plot", "plan.png"], "give a path with {name}"),
        (["key", "--batch", "-", "--export", "robot.csv"], "give a path with {name}"),
        (["key", "house", "--turn-noise", "normal:1", "--export", "r.csv"], "{name}"),
        (["key", "house", "--export", "{name}.txt"], "must end in .csv or .json"),
        (["key", "house", "--plot", "{name}.gif"], "must end in .png, .svg or .pdf"),
        (["key", "house", "--export", "nowhere/{name}.csv"], "no folder 'nowhere'"),
        (["key", "--turn-noise", "normal:1", "--also", "house"], "need --sense"),
        (["key", "--contact-noise", "0.1", "--part-prior", "1,1"], "need --sense"),
        (["key", "--turn-noise", "normal:1", "--method", "bfs"], "drop --method"),
        # an option of the other mode, given (even at its default value)
        (["key", "--sense", "width", "--guaranteed"], "takes no --guaranteed"),
        (["key", "--sense", "width", "--only", "best"], "takes no --only best"),
        (["key", "--sense", "width", "--method", "bfs"], "takes no --method"),
        (["key", "--fold-below", "0.01"], "--fold-below needs --sense"),
    ],
)
def test_refused_with_the_reason(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    args: list[str],
    match: str,
) -> None:
    monkeypatch.chdir(tmp_path)
    err = refused(capsys, "plan", *args)
    assert match in err
    assert list(tmp_path.iterdir()) == []


def test_an_input_is_never_a_template_output(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    part = tmp_path / "key.json"
    part.write_text(json.dumps({"name": "key", "vertices": [[0, 0], [3, 0], [3, 1], [0, 2]]}))
    before = part.read_text()
    code, out, _ = run(
        capsys, "plan", str(part), "rectangle", "--export", str(tmp_path / "{name}.json"), "--force"
    )
    first, second = (json.loads(x) for x in out.splitlines())
    assert code == 2 and "is an input" in first["error"] and "schema" in second
    assert part.read_text() == before


def test_the_payoff_file_is_an_input(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    u = tmp_path / "u.csv"
    u.write_text("orientation_deg,value\n80.63,1\n")
    err = refused(capsys, "plan", "key", "--payoff", str(u), "--export", str(u), "--force")
    assert "is an input" in err
    assert u.read_text() == "orientation_deg,value\n80.63,1\n"
