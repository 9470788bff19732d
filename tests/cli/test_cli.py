"""The ``squeeze``, ``plan`` and ``demo`` commands, run for real through ``cli.main``.

Every bad input must give exit code 2, nothing on stdout and exactly one line on stderr that
names the problem; the files the user gave are never changed.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp import (
    CostModel,
    Goal,
    Part,
    Problem,
    plan_exact,
    resolve_part,
    squeeze_function,
    von_mises,
)
from bayesgrasp.cli import main
from bayesgrasp.shapes import names

SQUEEZE_KEYS = {
    "schema",
    "part",
    "stable_orientations_rad",
    "basins_rad",
    "probabilities",
    "period_rad",
}
PART_KEYS = {"name", "vertices", "n_sides", "symmetry_order", "center_of_mass", "id"}
PLAN_KEYS = {
    "schema",
    "part",
    "stable_orientations_rad",
    "stable_probabilities",
    "period_rad",
    "first_squeeze_rad",
    "options",
    "bayes",
    "most_certain",
}
OPTION_KEYS = {
    "squeezes",
    "actions_rad",
    "final_orientation_rad",
    "success_probability",
    "expected_cost",
    "tolerance_rad",
}


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def strict_json(text: str) -> dict[str, object]:
    def no_constants(name: str) -> None:
        raise AssertionError(f"JSON holds {name}")

    doc = json.loads(text, parse_constant=no_constants)
    assert isinstance(doc, dict)
    return doc


@pytest.fixture
def files(tmp_path: Path) -> Path:
    """Good and bad part and prior files."""
    good = {
        "wedge.json": '{"name": "wedge", "vertices": [[0, 0], [3, 0], [0.5, 1], [1, 0.2]]}',
        "wedge.csv": "x,y\n0,0\n3,0\n0.5,1\n1,0.2\n",
        "hist.txt": "1 5 2 1",
        "sample.txt": "10, 12, 15, 200, 201\n",
    }
    bad = {
        "broken.json": '{"vertices": [[0, 0], [1, 0]',
        "nan.json": '{"vertices": [[0, 0], [1, 0], [NaN, 1]]}',
        "inf.json": '{"vertices": [[0, 0], [1, 0], [Infinity, 1]]}',
        "overflow.json": '{"vertices": [[0, 0], [1, 0], [1e999, 1]]}',
        "two.json": '{"vertices": [[0, 0], [1, 0], [1, 0], [0, 0]]}',
        "collinear.json": '{"vertices": [[0, 0], [1, 1], [2, 2], [3, 3]]}',
        "shape.json": '{"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}',
        "flat.json": '{"vertices": [0, 1, 2, 3, 4, 5]}',
        "words.json": '{"vertices": [[0, 0], [1, 0], ["a", 1]]}',
        "ragged.json": '{"vertices": [[0, 0], [1, 0], [0, [1]]]}',
        "novertices.json": '{"points": [[0, 0], [1, 0], [0, 1]]}',
        "garbage.csv": "x,y\n0,0\n1,0\nfoo,bar\n",
        "fields.csv": "0,0\n1,0\n0,1,2\n",
        "nan.csv": "0,0\n1,0\nnan,1\n",
        "empty.csv": "",
        "binary.json": b"\xff\xfe\x00",
        "hist_bad.txt": "1 two 3",
        "hist_neg.txt": "1 -2 3",
        "hist_zero.txt": "0 0 0",
        "sample_empty.txt": "",
    }
    for name, text in {**good, **bad}.items():
        path = tmp_path / name
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8")
    (tmp_path / "folder.json").mkdir()
    return tmp_path


def fingerprint(folder: Path) -> dict[str, tuple[str, int, int]]:
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            st = p.stat()
            out[p.name] = (hashlib.sha256(p.read_bytes()).hexdigest(), st.st_size, st.st_mtime_ns)
    return out


# --------------------------------------------------------------------------------------
# squeeze
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", names())
def test_squeeze_table(capsys: pytest.CaptureFixture[str], name: str) -> None:
    code, out, err = run(capsys, "squeeze", name)
    assert (code, err) == (0, "")
    part = resolve_part(name)
    f = squeeze_function(part.hull)
    lines = out.splitlines()
    units = f" ({part.units})" if part.units else ""
    assert lines[0].startswith(f"{name}{units}: {part.hull.n_sides} sides")
    rows = lines[2:]
    assert len(rows) == f.n_states
    stable = [float(r.split()[1]) for r in rows]
    probs = [float(r.split()[-1]) for r in rows]
    assert_allclose(stable, np.degrees(f.stable), atol=5e-4)
    assert_allclose(probs, f.widths / (2 * math.pi), atol=5e-5)


def test_squeeze_json_schema(capsys: pytest.CaptureFixture[str], files: Path) -> None:
    code, out, err = run(capsys, "squeeze", str(files / "wedge.json"), "--json")
    assert (code, err) == (0, "")
    doc = strict_json(out)
    assert set(doc) == SQUEEZE_KEYS
    assert doc["schema"] == "bayesgrasp.squeeze/1"
    part = doc["part"]
    assert isinstance(part, dict)
    assert set(part) == PART_KEYS  # no units in the file, so none reported
    assert part["name"] == "wedge"
    assert part["n_sides"] == 3 and part["symmetry_order"] == 1
    assert_allclose(part["vertices"], [[0, 0], [3, 0], [0.5, 1]])
    f = squeeze_function(Part.from_points([[0, 0], [3, 0], [0.5, 1]]).hull)
    assert_allclose(doc["stable_orientations_rad"], f.stable, atol=1e-12)
    assert_allclose(doc["basins_rad"], np.stack([f.basin_lo, f.basin_hi], axis=1), atol=1e-12)
    assert_allclose(doc["probabilities"], f.widths / (2 * math.pi), atol=1e-12)
    assert_allclose(doc["period_rad"], math.pi, atol=1e-12)


def test_squeeze_json_units_and_prior(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "squeeze", "rectangle", "--json", "--prior", "vonmises:30,4")
    assert code == 0
    doc = strict_json(out)
    part = doc["part"]
    assert isinstance(part, dict)
    assert set(part) == PART_KEYS | {"units"} and part["units"] == "mm"
    f = squeeze_function(resolve_part("rectangle").hull)
    mass = von_mises(math.radians(30), 4.0).mass(f.basin_lo, f.basin_hi)
    assert_allclose(doc["probabilities"], mass, atol=1e-12)
    assert_allclose(sum(doc["probabilities"]), 1.0, atol=1e-12)  # type: ignore[arg-type]


def test_squeeze_csv_equals_json(capsys: pytest.CaptureFixture[str], files: Path) -> None:
    _, a, _ = run(capsys, "squeeze", str(files / "wedge.json"), "--json")
    _, b, _ = run(capsys, "squeeze", str(files / "wedge.csv"), "--json")
    da, db = strict_json(a), strict_json(b)
    da.pop("part"), db.pop("part")
    assert da == db


# --------------------------------------------------------------------------------------
# plan
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", names())
def test_plan_table(capsys: pytest.CaptureFixture[str], name: str) -> None:
    code, out, err = run(capsys, "plan", name)
    assert (code, err) == (0, "")
    rep = plan_exact(Problem.build(resolve_part(name)))
    lines = out.splitlines()
    rows = [ln for ln in lines if ln[:3].strip().isdigit()]
    assert len(rows) == len(rep.options)
    for row, o in zip(rows, rep.options, strict=True):
        fields = row.split()
        assert int(fields[0]) == o.n_actions
        assert float(fields[1]) == pytest.approx(math.degrees(o.first_angle), abs=0.006)
        tail = fields[-4:] if fields[-1] in ("B", "C", "BC") else [*fields[-3:], ""]
        p, cost, tol = (float(x) if x != "-" else None for x in tail[:3])
        assert p == pytest.approx(o.success_probability, abs=6e-5)
        assert cost == pytest.approx(o.expected_cost, abs=6e-4)
        if o.tolerance is None:
            assert tol is None
        else:
            assert tol == pytest.approx(math.degrees(o.tolerance), abs=6e-4)
    marks = [r.split()[-1] for r in rows]
    assert sum("B" in m for m in marks) == 1 and sum("C" in m for m in marks) == 1
    assert "B" in rows[rep.bayes].split()[-1]
    assert "C" in rows[rep.most_certain].split()[-1]


def test_plan_json_schema(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plan", "triangle", "--json")
    assert (code, err) == (0, "")
    doc = strict_json(out)
    assert PLAN_KEYS <= set(doc)
    assert doc["schema"] == "bayesgrasp.plan/1"
    assert isinstance(doc["part"], dict) and set(doc["part"]) >= PART_KEYS
    pb = Problem.build(resolve_part("triangle"))
    rep = plan_exact(pb)
    assert_allclose(doc["stable_orientations_rad"], pb.states.stable, atol=1e-12)
    assert_allclose(doc["period_rad"], pb.states.period, atol=1e-12)
    opts = doc["options"]
    assert isinstance(opts, list) and len(opts) == len(rep.options)
    for k, (d, o) in enumerate(zip(opts, rep.options, strict=True), start=1):
        assert OPTION_KEYS | {"first_squeeze_rad"} <= set(d)
        assert d["squeezes"] == k
        assert len(d["actions_rad"]) == k - 1
        assert_allclose(d["actions_rad"], o.alphas, atol=1e-12)
        assert d["final_orientation_rad"] == pytest.approx(o.final_orientation, abs=1e-12)
        assert d["success_probability"] == pytest.approx(o.success_probability, abs=1e-12)
        assert d["expected_cost"] == pytest.approx(o.expected_cost, rel=1e-12)
        assert d["first_squeeze_rad"] == pytest.approx(o.first_angle, abs=1e-12)
        if k == 1:
            assert d["tolerance_rad"] is None
        else:
            assert d["tolerance_rad"] == pytest.approx(o.tolerance, abs=1e-12)
    assert (doc["bayes"], doc["most_certain"]) == (rep.bayes, rep.most_certain) == (2, 2)
    # Top-level fields follow the Bayes plan.
    assert doc["first_squeeze_rad"] == opts[rep.bayes]["first_squeeze_rad"]
    assert_allclose(doc["stable_probabilities"], pb.state_distribution(0.0), atol=1e-12)


def test_plan_json_peaked_prior_follows_bayes_plan(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "plan", "triangle", "--prior", "vonmises:60,5", "--json")
    assert code == 0
    doc = strict_json(out)
    pb = Problem.build(resolve_part("triangle"), von_mises(math.radians(60), 5.0))
    rep = plan_exact(pb)
    bayes = doc["options"][doc["bayes"]]  # type: ignore[index]
    assert doc["first_squeeze_rad"] == bayes["first_squeeze_rad"] != 0.0
    assert_allclose(
        doc["stable_probabilities"], pb.state_distribution(rep.bayes_plan.first_angle), atol=1e-12
    )
    assert_allclose(sum(doc["stable_probabilities"]), 1.0, atol=1e-12)  # type: ignore[arg-type]
    assert bayes["success_probability"] > 0.7


@pytest.mark.parametrize(
    ("args", "cost", "goal", "bayes", "n_options"),
    [
        ([], CostModel(), Goal(), 1, 2),
        (["--first-squeeze-cost", "0"], CostModel(first={"squeeze": 0.0}), Goal(), 0, 2),
        (["--squeeze-cost", "10"], CostModel({"squeeze": 10.0}), Goal(), 0, 2),
        (["--verify-cost", "9", "--retry-cost", "2"], CostModel(verify=9, retry=2), Goal(), 1, 2),
        (["--goal", "symmetry"], CostModel(), Goal("symmetry"), 1, 2),
        (["--max-squeezes", "1"], CostModel(), Goal(), 0, 1),
    ],
)
def test_plan_options(
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    cost: CostModel,
    goal: Goal,
    bayes: int,
    n_options: int,
) -> None:
    code, out, _ = run(capsys, "plan", "rectangle", "--json", *args)
    assert code == 0
    doc = strict_json(out)
    pb = Problem.build(resolve_part("rectangle"), cost=cost, goal=goal)
    max_k = 1 if "--max-squeezes" in args else None
    rep = plan_exact(pb, max_actions=max_k)
    opts = doc["options"]
    assert isinstance(opts, list) and len(opts) == n_options == len(rep.options)
    assert doc["bayes"] == bayes == rep.bayes
    assert_allclose(
        [d["expected_cost"] for d in opts], [o.expected_cost for o in rep.options], rtol=1e-12
    )
    if goal.kind == "symmetry":
        assert opts[-1]["success_probability"] == pytest.approx(1.0, abs=1e-12)


def test_plan_prior_files(capsys: pytest.CaptureFixture[str], files: Path) -> None:
    for spec in (f"histogram:{files / 'hist.txt'}", f"sample:{files / 'sample.txt'}"):
        code, out, err = run(capsys, "plan", "triangle", "--prior", spec, "--json")
        assert (code, err) == (0, "")
        doc = strict_json(out)
        assert_allclose(sum(doc["stable_probabilities"]), 1.0, atol=1e-12)  # type: ignore[arg-type]


def test_plan_bfs_method(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "plan", "rectangle", "--method", "bfs", "--json")
    assert code == 0
    doc = strict_json(out)
    assert doc["method"] == "bfs" and PLAN_KEYS <= set(doc)


def test_demo(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "demo")
    assert (code, err) == (0, "")
    for name in names():
        assert f"\n{name} " in f"\n{out}"


# --------------------------------------------------------------------------------------
# Bad input: one line on stderr, exit code 2, files untouched
# --------------------------------------------------------------------------------------

BAD = [
    (["{d}/missing.json"], "missing.json: no such file"),
    (["{d}/broken.json"], "broken.json: not valid JSON"),
    (["{d}/binary.json"], "binary.json"),
    (["{d}/folder.json"], "folder.json"),
    (["{d}/nan.json"], "`vertices` must be finite; point 2 is [nan, 1.0]"),
    (["{d}/inf.json"], "`vertices` must be finite; point 2 is [inf, 1.0]"),
    (["{d}/overflow.json"], ("must be finite", "coordinates too large")),
    (["{d}/two.json"], "at least 3 distinct points; got 4 point(s) with 2 distinct"),
    (["{d}/collinear.json"], "all collinear"),
    (["{d}/shape.json"], "must have shape (N, 2); got shape (3, 3)"),
    (["{d}/flat.json"], "must have shape (N, 2); got shape (6,)"),
    (["{d}/words.json"], "`vertices` must be numbers"),
    (["{d}/ragged.json"], "`vertices` must be numbers"),
    (["{d}/novertices.json"], '"vertices"'),
    (["{d}/garbage.csv"], "row 4 is not two numbers: 'foo,bar'"),
    (["{d}/fields.csv"], "has 3 fields; expected 2"),
    (["{d}/nan.csv"], "is not finite"),
    (["{d}/empty.csv"], "empty.csv"),
    (["nosuchpart"], "'nosuchpart' is neither a catalogue part"),
    (["triangle", "--prior", "gauss"], "unknown prior 'gauss'"),
    (["triangle", "--prior", "vonmises:30"], "needs two numbers; got '30'"),
    (["triangle", "--prior", "vonmises:30,-1"], "kappa >= 0"),
    (["triangle", "--prior", "histogram:{d}/missing.txt"], "no such file"),
    (["triangle", "--prior", "histogram:{d}/hist_bad.txt"], "must hold numbers only"),
    (["triangle", "--prior", "histogram:{d}/hist_neg.txt"], "non-negative"),
    (["triangle", "--prior", "histogram:{d}/hist_zero.txt"], "not all zero"),
    (["triangle", "--prior", "sample:{d}/sample_empty.txt"], "the file is empty"),
]
PLAN_BAD = [
    (["triangle", "--squeeze-cost", "-1"], "--squeeze-cost"),
    (["triangle", "--verify-cost", "-0.5"], "--verify-cost"),
    (["triangle", "--first-squeeze-cost", "-2"], "--first-squeeze-cost"),
    (["triangle", "--retry-cost", "-1"], "--retry-cost"),
    (["triangle", "--squeeze-cost", "abc"], "--squeeze-cost"),
    (["triangle", "--squeeze-cost", "nan"], "--squeeze-cost"),
    (["triangle", "--verify-cost", "inf"], "cost `verify` must be a finite number"),
    (["triangle", "--squeeze-cost", "0", "--verify-cost", "0"], "must be positive"),
    (["triangle", "--max-squeezes", "0"], "--max-squeezes"),
    (["triangle", "--method", "dfs"], "--method"),
    (["triangle", "--goal", "any"], "--goal"),
    ([], "give a PART"),
]


def check_one_line_error(code: int, out: str, err: str, needle: str | tuple[str, ...]) -> None:
    """Exit 2, nothing on stdout, one line on stderr holding ``needle`` (or one of them)."""
    assert code == 2, (out, err)
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("bayesgrasp: error: ")
    needles = (needle,) if isinstance(needle, str) else needle
    assert any(n.lower() in lines[0].lower() for n in needles), lines[0]
    assert "Traceback" not in err


@pytest.mark.parametrize("command", ["squeeze", "plan"])
@pytest.mark.parametrize(("args", "needle"), BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input(
    capsys: pytest.CaptureFixture[str],
    files: Path,
    command: str,
    args: list[str],
    needle: str | tuple[str, ...],
) -> None:
    before = fingerprint(files)
    argv = [a.format(d=files) for a in args]
    needles = (needle,) if isinstance(needle, str) else needle
    check_one_line_error(*run(capsys, command, *argv), tuple(n.format(d=files) for n in needles))
    assert fingerprint(files) == before


@pytest.mark.parametrize(("args", "needle"), PLAN_BAD, ids=[" ".join(a) for a, _ in PLAN_BAD])
def test_bad_plan_options(capsys: pytest.CaptureFixture[str], args: list[str], needle: str) -> None:
    check_one_line_error(*run(capsys, "plan", *args), needle)


def test_good_runs_leave_files_untouched(capsys: pytest.CaptureFixture[str], files: Path) -> None:
    before = fingerprint(files)
    for argv in (
        ["squeeze", str(files / "wedge.json"), "--json"],
        ["squeeze", str(files / "wedge.csv")],
        ["plan", str(files / "wedge.json"), "--prior", f"histogram:{files / 'hist.txt'}"],
        ["plan", str(files / "wedge.csv"), "--prior", f"sample:{files / 'sample.txt'}", "--json"],
    ):
        assert main(argv) == 0
    capsys.readouterr()
    assert fingerprint(files) == before


def test_console_script_bad_file_one_line(files: Path) -> None:
    """The installed entry point, in a fresh interpreter: no warnings, no traceback."""
    env = {**os.environ, "PYTHONWARNINGS": "default"}
    for name in ("nan.json", "garbage.csv", "overflow.json"):
        proc = subprocess.run(
            [sys.executable, "-m", "bayesgrasp.cli", "plan", str(files / name)],
            capture_output=True,
            text=True,
            env=env,
            check=False,
        )
        assert proc.returncode == 2
        assert proc.stdout == ""
        assert len(proc.stderr.splitlines()) == 1, proc.stderr
    proc = subprocess.run(
        [sys.executable, "-m", "bayesgrasp.cli", "plan", "rectangle", "--json"],
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    assert proc.returncode == 0 and proc.stderr == ""
    assert strict_json(proc.stdout)["schema"] == "bayesgrasp.plan/1"


def test_jaw_lag_is_refused_with_the_kinematic_engine(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 14: the MuJoCo jaw lag had no option; the kinematic model has no jaws to lag."""
    code, _, err = run(capsys, "simulate", "triangle", "--jaw-lag", "1", "--trials", "10")
    assert code == 2
    assert "--jaw-lag" in err and "--engine mujoco only" in err and "--contact-noise" in err
    assert len(err.strip().splitlines()) == 1
    code, _, err = run(capsys, "simulate", "triangle", "--engine", "mujoco", "--jaw-lag", "100")
    assert code == 2 and "more than twice its size" in err and "give at most 9.847 s" in err


def test_jaw_lag_reaches_the_engine_and_the_provenance(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """`--jaw-lag 2`: SimParams(jaw_lag=2), clearance the push (10 mm) + 1 mm, recorded."""
    import bayesgrasp.sim
    from bayesgrasp.sim.kinematic import simulate_kinematic

    seen: list[Any] = []

    def fake(pb: Any, option: Any, n: int, **kw: Any) -> Any:
        seen.append(kw.get("params"))
        return simulate_kinematic(pb, option, n, kw["noise"], rng=kw["rng"])

    monkeypatch.setattr(bayesgrasp.sim, "simulate_mujoco", fake)
    args = ["simulate", "triangle", "--engine", "mujoco", "--trials", "5", "--json"]
    code, out, _ = run(capsys, *args, "--jaw-lag", "2")
    assert code == 0
    (params,) = seen
    assert params.jaw_lag == 2.0 and params.lead_jaw == "random"
    assert params.clearance == pytest.approx(params.jaw_speed * 2.0 / 2 + 0.001)
    assert json.loads(out)["provenance"]["jaw_lag_s"] == 2.0
    code, out, _ = run(capsys, *args)
    assert code == 0 and seen[-1] is None
    assert "jaw_lag_s" not in json.loads(out)["provenance"]


@pytest.mark.physics
def test_jaw_lag_in_mujoco(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("mujoco")
    from bayesgrasp.sim import measure_asynchrony  # exported with the option

    assert callable(measure_asynchrony)
    args = ["simulate", "triangle", "--engine", "mujoco", "--trials", "3", "--seed", "1"]
    code, out, _ = run(capsys, *args, "--jaw-lag", "0.5", "--json")
    assert code == 0
    doc = json.loads(out)
    assert doc["provenance"]["jaw_lag_s"] == 0.5 and doc["trials"] == 3
