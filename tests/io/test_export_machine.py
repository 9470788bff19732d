"""Robot state machines (io/machine.py) read back from their files and run in simulation.

The independent check: the CSV is parsed back with the csv module alone and driven as a
robot would drive it, in the *world* frame: a part at world orientation ``phi`` squeezed by a
gripper at the file's absolute angle ``gamma`` ends at ``s(phi - gamma) + gamma``, the jaws
read ``d(s(phi - gamma))`` (plus the sensor's error), and the reading picks the row. Beside
it the policy tree is walked on the same readings (relative turns, the planner's frames).
At every step the file must give the gripper angle of the summed turns, the next state of
the tree's branch, and the tree's declaration, and the declarations the file makes must
succeed as often as the policy claims.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp import Part, Problem, plan_exact, resolve_part
from bayesgrasp.cli import main
from bayesgrasp.io.export import (
    ExportError,
    Stroke,
    check_stroke,
    robot_steps,
    stroke_violation,
    write_robot,
)
from bayesgrasp.io.machine import (
    MACHINE_COLUMNS,
    ROBOT_POLICY_SCHEMA,
    machine_csv,
    machine_document,
    plan_machine,
    policy_machine,
)
from bayesgrasp.model.cost import CostModel
from bayesgrasp.model.prior import SamplePrior, von_mises
from bayesgrasp.model.problem import nearest_state
from bayesgrasp.model.sensing import parse_sensor
from bayesgrasp.planning.policy import Declare, Policy, PolicyNode, Reject, plan_policy
from bayesgrasp.planning.result import PlanOption, PlanStep
from bayesgrasp.planning.strategy import plan_strategy
from bayesgrasp.sim.kinematic import sample_prior

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

TWO_PI = 2 * math.pi

# (candidate parts, sensor, most actions, action kinds, prior)
SP = ("squeeze", "push-grasp")
CASES = [
    (("house",), "width", 3, ("squeeze",), None),
    (("key",), "width:0.5,0.25", 2, ("squeeze",), None),
    (("triangle",), "width:0,2", 3, ("squeeze",), None),
    (("rectangle",), "width", 3, ("squeeze",), von_mises(1.0, 2.0)),
    (("house",), "width:0.5,0.25", 2, SP, None),
    (("example",), "width:0,2", 3, SP, None),
    (("house", "key"), "width", 3, ("squeeze",), None),
    (("house", "key"), "width:0,2", 3, SP, None),
    (("house", "key"), "width:0.3,0.1", 2, ("squeeze",), None),
    (("rectangle", "triangle"), "width:0,2", 3, ("squeeze",), None),
]


def _problems(names: Sequence[str], actions: tuple[str, ...], prior: object) -> list[Problem]:
    kw: dict[str, Any] = {"prior": prior} if prior is not None else {}
    return [Problem.build(resolve_part(n), actions=actions, **kw) for n in names]


def _wrap(a: float) -> float:
    out = math.remainder(a, TWO_PI)
    return math.pi if out <= -math.pi else out


def read_machine_csv(text: str) -> dict[int, list[dict[str, str]]]:
    """The rows of each state, read with the csv module alone (``#`` lines skipped)."""
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    rows = list(csv.DictReader(lines))
    assert rows and tuple(rows[0]) == MACHINE_COLUMNS
    out: dict[int, list[dict[str, str]]] = {}
    for r in rows:
        out.setdefault(int(r["state"]), []).append(r)
    return out


def _row_of(rows: list[dict[str, str]], reading: float) -> dict[str, str]:
    """The row a reading takes (``reading_lo <= r < reading_hi``), checked to be unique."""
    hits = [r for r in rows if float(r["reading_lo"]) <= reading < float(r["reading_hi"])]
    assert len(hits) == 1, (reading, [(r["reading_lo"], r["reading_hi"]) for r in rows])
    return hits[0]


def run_file(
    problems: Sequence[Problem],
    policy: Policy,
    table: dict[int, list[dict[str, str]]],
    n: int,
    seed: int,
) -> tuple[int, int]:
    """Drive the parsed file on ``n`` simulated parts beside the policy tree.

    Returns the number of successful declarations and of cycles that declared.
    """
    gen = np.random.default_rng(seed)
    sensor = policy.sensor
    parts = gen.choice(len(problems), size=n, p=np.asarray(policy.part_prior))
    phis = sample_prior(problems[0].prior, n, gen)  # world orientations
    node_of: dict[int, int] = {}  # state id -> id() of its tree node (one to one)
    ok = declared = 0
    for j, phi in zip(parts.tolist(), phis.tolist(), strict=True):
        pb = problems[j]
        state, node, turns = 1, policy.root, 0.0
        for _ in range(policy.max_actions + 1):
            assert node_of.setdefault(state, id(node)) == id(node)
            rows = table[state]
            turns += node.step.alpha
            gamma = float(rows[0]["gripper_rad"])
            assert_allclose(math.remainder(gamma - turns, TWO_PI), 0.0, atol=1e-8)
            assert_allclose(float(rows[0]["gripper_deg"]), math.degrees(gamma), atol=1e-6)
            assert rows[0]["action"] == node.step.kind
            assert all(r["gripper_rad"] == rows[0]["gripper_rad"] for r in rows)
            # world frame: the part at phi, the gripper at gamma
            before = float(pb.diameter(phi - gamma))
            assert before <= float(rows[0]["opening_before"]) * (1 + 1e-9)
            local = float(pb.transfer(node.step.kind)(np.array([phi - gamma]))[0])
            phi = local + gamma
            width = float(pb.diameter(local))
            lo, hi = float(rows[0]["width_after_min"]), float(rows[0]["width_after_max"])
            assert lo * (1 - 1e-9) <= width <= hi * (1 + 1e-9)
            reading = float(sensor.read(np.array([width]), gen)[0])
            row = _row_of(rows, reading)
            branch = node.branch(reading)
            assert_allclose(float(row["probability"]), branch.probability, rtol=1e-9)
            nxt = branch.next
            if row["outcome"] == "next":
                assert isinstance(nxt, PolicyNode)
                state, node = int(row["next_state"]), nxt
                continue
            if row["outcome"] == "reject":
                assert isinstance(nxt, Reject)
                break
            assert row["outcome"] == "declare" and isinstance(nxt, Declare)
            assert row["part"] == nxt.part_name
            theta = float(row["orientation_rad"])
            assert_allclose(theta, nxt.orientation, atol=1e-8)  # 10 digits in the file
            world = float(row["world_orientation_rad"])
            assert_allclose(math.remainder(world - theta - gamma, TWO_PI), 0.0, atol=1e-8)
            declared += 1
            if problems[j].part.name == row["part"]:
                # the part's world orientation against the declared world orientation
                here = nearest_state(pb.states, np.mod(np.array([phi - world + theta]), TWO_PI))
                ok += int(pb.success_states(theta)[here][0])
            break
        else:  # pragma: no cover - a path longer than the policy allows
            pytest.fail("the file's path is longer than max_actions")
    assert len(node_of) <= len(table)
    return ok, declared


@pytest.mark.parametrize(("names", "sense", "most", "actions", "prior"), CASES)
def test_file_runs_as_the_policy(
    names: tuple[str, ...],
    sense: str,
    most: int,
    actions: tuple[str, ...],
    prior: object,
    tmp_path: Path,
) -> None:
    pbs = _problems(names, actions, prior)
    pol = plan_policy(pbs, sense, most)
    path = write_robot(tmp_path / "robot.csv", pbs, pol)
    text = path.read_text(encoding="utf-8")
    assert text.startswith(f"# {ROBOT_POLICY_SCHEMA}")
    units = pbs[0].part.units
    assert f"in {units};" in text.splitlines()[1]
    table = read_machine_csv(text)
    assert sorted(table) == list(range(1, len(table) + 1))
    for rows in table.values():  # each state's rows tile the readings in order
        assert float(rows[0]["reading_lo"]) == -math.inf
        assert float(rows[-1]["reading_hi"]) == math.inf
        for a, b in itertools.pairwise(rows):
            assert a["reading_hi"] == b["reading_lo"]
        assert_allclose(sum(float(r["probability"]) for r in rows), 1.0, atol=1e-9)
    n = 2500
    ok, _ = run_file(pbs, pol, table, n, seed=7)
    p = pol.success_probability
    assert abs(ok / n - p) <= 4.5 * math.sqrt(p * (1 - p) / n) + 1e-9
    # the JSON holds the same machine
    doc = json.loads(write_robot(tmp_path / "robot.json", pbs, pol).read_text(encoding="utf-8"))
    assert doc["schema"] == ROBOT_POLICY_SCHEMA and doc["units"]["length"] == units
    assert doc["start_state"] == 1 and doc["parts"] == list(names)
    assert [s["state"] for s in doc["states"]] == sorted(table)
    for s in doc["states"]:
        rows = table[s["state"]]
        assert len(s["branches"]) == len(rows)
        assert_allclose(s["gripper_rad"], float(rows[0]["gripper_rad"]), atol=1e-8)
        for b, r in zip(s["branches"], rows, strict=True):
            lo, hi = b["reading"]
            assert (lo is None) == (r["reading_lo"] == "-inf")
            assert (hi is None) == (r["reading_hi"] == "inf")
            if r["outcome"] == "next":
                assert b["next_state"] == int(r["next_state"])
            elif r["outcome"] == "reject":
                assert b["reject"] is True
            else:
                assert b["declare"]["part"] == r["part"]


def test_rejections_run_from_the_file(tmp_path: Path) -> None:
    """Dear verification: the policy rejects some parts, and the file's reject rows agree."""
    pb = Problem.build(resolve_part("triangle"), cost=CostModel(verify=30.0))
    pol = plan_policy(pb, "width:1,0.5", 2)
    assert pol.reject_probability > 0.05
    text = write_robot(tmp_path / "tri.csv", pb, pol).read_text(encoding="utf-8")
    table = read_machine_csv(text)
    assert any(r["outcome"] == "reject" for rows in table.values() for r in rows)
    n = 4000
    ok, declared = run_file([pb], pol, table, n, seed=5)
    p, r = pol.success_probability, pol.reject_probability
    assert abs(ok / n - p) <= 4.5 * math.sqrt(p * (1 - p) / n)
    assert abs((n - declared) / n - r) <= 4.5 * math.sqrt(r * (1 - r) / n)
    # a part without units says so
    quad = Part.from_points([(0.0, 0.0), (4.0, 0.0), (3.6, 2.2), (0.5, 2.6)], name="quad")
    bare = Problem.build(quad)
    line = machine_csv(policy_machine(bare, plan_policy(bare, "width", 1))).splitlines()[1]
    assert "in the part's units;" in line


@pytest.mark.parametrize(
    ("names", "sense", "actions"),
    [
        (("house", "key"), "width", ("squeeze",)),
        (("house", "key"), "width:0,2", SP),
        (("house",), "width", SP),
    ],
)
def test_widths_are_those_the_parts_reach(
    names: tuple[str, ...], sense: str, actions: tuple[str, ...]
) -> None:
    """Each state's opening and closing widths are attained by simulated parts (exact sensors).

    Deterministic readings send every start of a state's support there, so over enough
    starts the widest and narrowest widths seen are the file's exactly.
    """
    pbs = _problems(names, actions, None)
    pol = plan_policy(pbs, sense, 3)
    m = policy_machine(pbs, pol)
    table = read_machine_csv(machine_csv(m))
    opening: dict[int, float] = {}
    after: dict[int, list[float]] = {}
    gen = np.random.default_rng(1)
    n = 6000
    which = gen.choice(len(pbs), size=n).tolist()
    for j, phi in zip(which, sample_prior(pbs[0].prior, n, gen).tolist(), strict=True):
        pb, state = pbs[j], 1
        while True:
            rows = table[state]
            gamma = float(rows[0]["gripper_rad"])
            if state > 1:
                opening[state] = max(opening.get(state, 0.0), float(pb.diameter(phi - gamma)))
            local = float(pb.transfer(rows[0]["action"])(np.array([phi - gamma]))[0])
            phi = local + gamma
            width = float(pb.diameter(local))
            after.setdefault(state, []).append(width)
            row = _row_of(rows, float(pol.sensor.read(np.array([width]))[0]))
            if row["outcome"] != "next":
                break
            state = int(row["next_state"])
    assert sorted(after) == [s.state for s in m.states]
    for s in m.states:
        if s.state > 1:
            assert_allclose(opening[s.state], s.opening_before, rtol=1e-9)
        assert_allclose(min(after[s.state]), s.width_after_min, rtol=1e-9)
        assert_allclose(max(after[s.state]), s.width_after_max, rtol=1e-9)
    widest = max(float(np.max(pb.diameter(np.linspace(0, math.pi, 20001)))) for pb in pbs)
    assert_allclose(m.states[0].opening_before, widest, rtol=1e-6)


@pytest.mark.parametrize(
    ("name", "actions", "prior"),
    [
        ("house", ("squeeze",), None),
        ("key", ("squeeze",), von_mises(2.0, 3.0)),
        ("example", ("push-grasp",), None),
        ("house", ("squeeze", "push-grasp"), None),
    ],
)
def test_a_plan_through_the_machine_has_the_plan_exports_angles(
    name: str, actions: tuple[str, ...], prior: object
) -> None:
    (pb,) = _problems((name,), actions, prior)
    plan = plan_exact(pb).bayes_plan
    steps = robot_steps(pb, plan)
    m = plan_machine(pb, plan)
    assert len(m.states) == len(steps)
    for s, st in zip(m.states, steps, strict=True):
        assert (s.state, s.action) == (st.step, st.action)
        assert s.gripper_rad == st.gripper_rad and s.turn_rad == st.turn_rad
        assert s.opening_before == st.opening_before
        assert len(s.transitions) == 1 and s.transitions[0].probability == 1.0
    last = m.states[-1].transitions[0]
    assert last.outcome == "declare" and last.orientation_rad == plan.final_orientation
    table = read_machine_csv(machine_csv(m))
    for s, st in zip(m.states, steps, strict=True):
        assert table[s.state][0]["gripper_deg"] == f"{st.gripper_deg:.10g}"
    # the chain run as a policy on exact readings succeeds as the plan claims
    p = plan.success_probability
    sensor = parse_sensor("width")
    chain = Policy(plan_strategy(pb, plan), (pb.part.name,), (1.0,), sensor, 9, 1.0, p, 1, 0, 1, ())
    ok, declared = run_file([pb], chain, table, 3000, seed=2)
    assert declared == 3000
    assert abs(ok / 3000 - p) <= 4.5 * math.sqrt(p * (1 - p) / 3000) + 1e-9


def test_machine_document_is_json_without_nan() -> None:
    pbs = _problems(("house",), ("squeeze",), None)
    pol = plan_policy(pbs, "width:0.3,0.1", 2)
    doc = machine_document(policy_machine(pbs, pol))
    text = json.dumps(doc, allow_nan=False)
    assert '"units"' in text and doc["states"][0]["branches"][0]["reading"][0] is None
    assert_allclose(doc["success_probability"], pol.success_probability)


# -- the stroke -----------------------------------------------------------------------------


def test_stroke_check_names_the_step() -> None:
    (pb,) = _problems(("house",), ("squeeze",), None)
    plan = plan_exact(pb).bayes_plan
    m = plan_machine(pb, plan)
    widest = m.states[0].opening_before
    narrowest = min(s.width_after_min for s in m.states)
    assert_allclose(narrowest, float(np.min(pb.widths)), rtol=1e-12)
    check_stroke(pb, plan, Stroke(narrowest, widest))  # exactly the stroke needed
    with pytest.raises(ExportError, match=r"step 1 \(squeeze, gripper at 0 deg\) needs .* 61\.98"):
        check_stroke(pb, plan, Stroke(max_opening=widest - 0.01))
    with pytest.raises(ExportError, match=r"may close the jaws to 40 mm, less than the least"):
        check_stroke(pb, plan, Stroke(min_opening=narrowest + 0.01))
    pol = plan_policy(pb, "width", 3)
    with pytest.raises(ExportError, match=r"state 1 \(squeeze"):
        check_stroke(pb, pol, Stroke(max_opening=widest - 0.01))
    assert stroke_violation(policy_machine(pb, pol), Stroke(narrowest, widest)) is None


def test_a_later_step_outside_the_stroke() -> None:
    """A prior of gaps: the first squeeze reaches only the wide state, the second the narrow."""
    rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], units="mm")
    pb = Problem.build(rect, prior=SamplePrior([0.1, -0.1, math.pi]))
    plan = PlanOption(
        (PlanStep("squeeze", 0.0), PlanStep("squeeze", math.pi / 2)), 0.0, 1, 2, None, (0, 1)
    )
    m = plan_machine(pb, plan)
    widths = [(s.width_after_min, s.width_after_max) for s in m.states]
    assert_allclose(widths, [(31.0, 31.0), (20.0, 20.0)], atol=1e-9)
    assert_allclose(m.states[1].opening_before, 20.0)  # the part lies 20 across the jaws
    with pytest.raises(ExportError, match=r"the planners do not avoid it\): step 2 \(squeeze"):
        check_stroke(pb, plan, Stroke(min_opening=25.0))
    with pytest.raises(ExportError, match=r"^the part does not fit the gripper's stroke: step 1"):
        check_stroke(pb, plan, Stroke(min_opening=32.0))


@pytest.mark.parametrize(
    ("lo", "hi", "match"),
    [
        (-1.0, 5.0, r"`min_opening` must be a finite number >= 0"),
        (math.nan, 5.0, r"`min_opening` must be a finite number >= 0"),
        (0.0, 0.0, r"`max_opening` must be a number > 0"),
        (0.0, math.nan, r"`max_opening` must be a number > 0"),
        (6.0, 5.0, r"`min_opening` must be less than `max_opening`"),
    ],
)
def test_bad_stroke(lo: float, hi: float, match: str) -> None:
    with pytest.raises(ExportError, match=match):
        Stroke(lo, hi)


def test_stroke_on_a_later_state_is_found_by_brute_force() -> None:
    """The first state outside the stroke, against the widths the simulated parts reach."""
    pbs = _problems(("house", "key"), ("squeeze",), None)
    pol = plan_policy(pbs, "width", 3)
    m = policy_machine(pbs, pol)
    later = [s for s in m.states if s.state > 1]
    assert later
    # a least opening just above a later state's narrowest closing refuses that state
    target = min(later, key=lambda s: s.width_after_min)
    first_ok = min(s.width_after_min for s in m.states if s.state < target.state)
    if target.width_after_min < first_ok:
        why = stroke_violation(m, Stroke(min_opening=target.width_after_min + 1e-6))
        assert why is not None and why.startswith(f"step {target.state} ")


# -- the command line -----------------------------------------------------------------------


def test_cli_sense_export(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["plan", "house", "--sense", "width", "--also", "key", "--export", "r.csv"]) == 0
    pbs = _problems(("house", "key"), ("squeeze",), None)
    want = machine_csv(policy_machine(pbs, plan_policy(pbs, "width", 3)))
    assert Path("r.csv").read_text(encoding="utf-8") == want
    assert main(["plan", "house", "--sense", "width", "--export", "r.csv"]) == 2
    assert "exists; use --force" in capsys.readouterr().err
    assert main(["plan", "house", "--sense", "width", "--export", "r.csv", "--force"]) == 0
    assert read_machine_csv(Path("r.csv").read_text(encoding="utf-8"))[1][0]["action"] == "squeeze"
    assert main(["plan", "house", "--sense", "width", "--export", "r.txt"]) == 2
    assert "must end in .csv or .json" in capsys.readouterr().err
    assert main(["plan", "house", "key", "--sense", "width:0.3,0.1", "--export", "r.json"]) == 0
    doc = json.loads(Path("r.json").read_text(encoding="utf-8"))
    assert doc["schema"] == ROBOT_POLICY_SCHEMA and doc["parts"] == ["house", "key"]
    capsys.readouterr()
    assert main(["plan", "house", "--sense", "width", "--json", "--export", "s.json"]) == 0
    assert json.loads(capsys.readouterr().out)["schema"] == "bayesgrasp.policy/1"
    assert Path("s.json").exists()


def test_cli_stroke(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "r.csv"
    assert main(["plan", "house", "--max-opening", "50", "--export", str(out)]) == 2
    err = capsys.readouterr().err
    assert "step 1 (squeeze, gripper at 0 deg) needs the jaws open to 61.98 mm" in err
    assert not out.exists()  # refused before writing
    assert main(["plan", "house", "--sense", "width", "--min-opening", "41"]) == 2
    assert "state 1 (squeeze" in capsys.readouterr().err
    assert main(["plan", "house", "--max-opening", "62", "--min-opening", "40"]) == 0
    assert "Bayes plan" in capsys.readouterr().out
    assert main(["plan", "house", "--min-opening", "80", "--max-opening", "70"]) == 2
    assert "less than `max_opening`" in capsys.readouterr().err
    # Several parts: a part outside the stroke gets its error line, the others their plans.
    assert main(["plan", "house", "key", "--max-opening", "50"]) == 2
    lines = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert "error" in lines[0] and "61.98 mm" in lines[0]["error"]
    assert lines[1]["part"]["name"] == "key" and "error" not in lines[1]
    assert main(["plan", "key", "--turn-noise", "normal:2", "--max-opening", "30"]) == 2
    assert "needs the jaws open to 38.74 mm" in capsys.readouterr().err


@pytest.mark.parametrize(
    "name",
    ["triangle", "rectangle", "ic-chip", "house", "example", "allen-wrench", "tuning-fork", "key"],
)
def test_the_first_squeeze_decides_the_stroke(name: str) -> None:
    """Squeezes under a prior of full support: the first action needs the whole stroke.

    It sees every orientation (the widest opening) and reaches every stable orientation
    (the narrowest closing), so no later step of any squeeze strategy needs more: a stroke
    that refuses a strategy refuses the part (why the command line calls it bad input).
    """
    (pb,) = _problems((name,), ("squeeze",), None)
    for m in (
        plan_machine(pb, plan_exact(pb).bayes_plan),
        policy_machine(pb, plan_policy(pb, "width:0,0.5", 2)),
    ):
        first = m.states[0]
        assert_allclose(first.width_after_min, float(np.min(pb.widths)), rtol=1e-12)
        for s in m.states:
            assert s.opening_before <= first.opening_before
            assert s.width_after_min >= first.width_after_min


def test_a_noisy_policys_widths_hold_for_parts_turned_with_error() -> None:
    """Under a uniform turn error the file's openings and widths bound every simulated part.

    Each turn errs by e ~ U[-A, A] (the noise model's relative turn error); the part's
    orientation is followed in the current gripper frame and read by the file's own rows.
    The noise-free reading of the same policy is too narrow: some part exceeds its opening.
    """
    import dataclasses

    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy_policy import plan_noisy_policy

    a = math.radians(6.0)
    (pb,) = _problems(("key",), ("squeeze",), None)
    pol = plan_noisy_policy(pb, "width:0.5,0.1", 2, NoiseModel(TurnNoise("uniform", a)))
    noisy = read_machine_csv(machine_csv(policy_machine(pb, pol)))
    exact = read_machine_csv(machine_csv(policy_machine(pb, dataclasses.replace(pol, noise=None))))
    gen = np.random.default_rng(7)
    beyond_exact = 0
    for local in sample_prior(pb.prior, 4000, gen).tolist():
        state, first = 1, True
        while True:
            rows = noisy[state]
            turn = 0.0 if first else float(rows[0]["turn_deg"])
            local = local - math.radians(turn) - (0.0 if first else gen.uniform(-a, a))
            before = float(pb.diameter(local))
            if not first:
                assert before <= float(rows[0]["opening_before"]) * (1 + 1e-9)
                beyond_exact += before > float(exact[state][0]["opening_before"]) * (1 + 1e-9)
            local = float(pb.transfer("squeeze")(np.array([local]))[0])
            width = float(pb.diameter(local))
            lo, hi = float(rows[0]["width_after_min"]), float(rows[0]["width_after_max"])
            assert lo * (1 - 1e-9) <= width <= hi * (1 + 1e-9)
            row = _row_of(rows, float(pol.sensor.read(np.array([width]), gen)[0]))
            if row["outcome"] != "next":
                break
            state, first = int(row["next_state"]), False
    assert beyond_exact > 0  # the noise-free file would understate the opening
