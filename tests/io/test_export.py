"""Robot files (io/export.py): absolute gripper angles and jaw widths, checked by simulation.

The independent check: draw starts from the prior, run each through the transfer functions
step by step (the kinematic model, not the export's state bookkeeping), and compare the
gripper angles with the running sum of turns and the jaw readings (``d`` of each
orientation reached) with the exported widths.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp import Part, Problem, plan_exact, resolve_part
from bayesgrasp.cli import main
from bayesgrasp.io.export import (
    CSV_COLUMNS,
    ROBOT_SCHEMA,
    ExportError,
    robot_csv,
    robot_document,
    robot_steps,
    write_robot,
)
from bayesgrasp.model.prior import von_mises
from bayesgrasp.model.problem import nearest_state
from bayesgrasp.sim.kinematic import sample_prior

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

CASES = [
    ("house", ("squeeze",), None),
    ("house", ("squeeze", "push-grasp"), None),
    ("key", ("squeeze",), von_mises(2.0, 3.0)),
    ("example", ("push-grasp",), None),
]


@pytest.mark.parametrize(("name", "actions", "prior"), CASES)
def test_steps_agree_with_simulated_executions(name: str, actions: tuple, prior: object) -> None:
    kw = {"prior": prior} if prior is not None else {}
    pb = Problem.build(resolve_part(name), actions=actions, **kw)
    plan = plan_exact(pb).bayes_plan
    steps = robot_steps(pb, plan)
    assert [s.action for s in steps] == list(plan.kinds)
    # absolute angles: the running sum of the turns, wrapped to (-180, 180]
    gamma = np.cumsum([s.alpha for s in plan.steps])
    for s, g in zip(steps, gamma, strict=True):
        assert -math.pi < s.gripper_rad <= math.pi
        assert_allclose(math.remainder(s.gripper_rad - g, 2 * math.pi), 0.0, atol=1e-12)
        assert_allclose(s.gripper_deg, math.degrees(s.gripper_rad), rtol=1e-15)
    # simulate: world starts, each step in its own gripper frame
    theta = sample_prior(pb.prior, 20_000, rng=3)
    seen = []
    for st in plan.steps:
        theta = np.mod(pb.transfers[st.kind](theta - st.alpha), 2 * math.pi)
        seen.append(theta)
    ok = pb.success_states(plan.final_orientation)[nearest_state(pb.states, seen[-1])]
    assert_allclose(ok.mean(), plan.success_probability, atol=0.015)
    d = pb.diameter
    widest = float(np.max(d(np.linspace(0, math.pi, 20001))))
    assert steps[0].opening_before >= widest - 1e-6 * widest
    for j, s in enumerate(steps):
        w = d(seen[j][ok])
        assert s.width_after_min - 1e-9 <= w.min() and w.max() <= s.width_after_max + 1e-9
        assert_allclose(w.mean(), s.width_after, rtol=0.02)
        if j > 0:  # the jaws open wider than the part lies before they close
            assert float(np.max(d(seen[j - 1] - plan.steps[j].alpha))) <= s.opening_before + 1e-9
    last = steps[-1]
    assert_allclose(last.width_after_min, last.width_after_max, rtol=1e-9)
    assert_allclose(last.width_after, float(d(plan.final_orientation)), rtol=1e-9)


def test_rectangle_by_hand() -> None:
    rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], units="mm")
    pb = Problem.build(rect)
    plan = plan_exact(pb).bayes_plan
    rows = list(csv.DictReader(io.StringIO(robot_csv(pb, plan))))
    assert tuple(rows[0]) == CSV_COLUMNS
    widest = math.hypot(31, 20)
    assert_allclose(float(rows[0]["opening_before"]), widest, rtol=1e-9)
    assert [r["action"] for r in rows] == ["squeeze"] * plan.n_actions
    assert_allclose(float(rows[-1]["width_after"]), float(pb.diameter(plan.final_orientation)))
    doc = robot_document(pb, plan)
    assert doc["schema"] == ROBOT_SCHEMA and doc["units"] == "mm"
    json.dumps(doc, allow_nan=False)


def test_write_robot_and_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    pb = Problem.build(resolve_part("triangle"))
    plan = plan_exact(pb).bayes_plan
    with pytest.raises(ExportError, match=r"must end in \.csv or \.json"):
        write_robot(tmp_path / "r.txt", pb, plan)
    monkeypatch.chdir(tmp_path)
    assert main(["plan", "triangle", "--export", "r.json"]) == 0
    doc = json.loads(Path("r.json").read_text(encoding="utf-8"))
    assert len(doc["steps"]) == plan.n_actions
    assert main(["plan", "triangle", "--export", "r.json"]) == 2  # exists: --force
    assert main(["plan", "triangle", "--export", "r.csv"]) == 0
    assert main(["plan", "triangle", "--export", "r.txt"]) == 2
    err = capsys.readouterr().err
    assert "exists; use --force" in err and "must end in .csv or .json" in err
    assert main(["plan", "triangle", "--export", "r.csv", "--force"]) == 0


def test_export_error_lives_in_errors_and_is_still_importable_from_export() -> None:
    """Issue 15: every library error is defined in bayesgrasp.errors."""
    from bayesgrasp import errors

    assert errors.ExportError is ExportError and "ExportError" in errors.__all__
    assert issubclass(ExportError, errors.BayesGraspError) and issubclass(ExportError, ValueError)
