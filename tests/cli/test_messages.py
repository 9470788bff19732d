"""What the text output says: the right action names, the right tags, degrees for people.

Each case is a line the issue found wrong (issue 15, item 6).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bayesgrasp import Part, Problem
from bayesgrasp.cli import main
from bayesgrasp.model.prior import parse_prior, von_mises
from bayesgrasp.planning.result import PlanOption, PlanStep
from bayesgrasp.report import simulate_json, simulate_table
from bayesgrasp.sim.result import PHYSICS_FIT, summarize, verdict_lines

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_push_grasp_plans_say_push_grasp_and_are_tagged(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, _ = run(capsys, "plan", "house", "--actions", "push-grasp")
    assert code == 0
    assert "squeeze" not in out
    assert "first push-grasp" in out and "each further push-grasp" in out
    assert "P = push-grasp" in out
    rows = [line for line in out.splitlines() if line.strip().startswith(("1 ", "2 "))]
    assert rows and all(" P" in r for r in rows)


def test_capped_plans_do_not_claim_most_certain(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run(capsys, "plan", "house", "--actions", "push-grasp", "--max-squeezes", "2")
    assert "C = the most certain of the plans of at most 2 action(s)" in out
    _, out, _ = run(capsys, "plan", "house", "--actions", "push-grasp")
    assert out.rstrip().endswith("C = most certain plan")  # not capped: it is
    _, out, _ = run(capsys, "plan", "house", "--actions", "push-grasp", "--max-squeezes", "9")
    assert out.rstrip().endswith("C = most certain plan")  # a cap that did not bind


def test_max_squeezes_help_says_every_action(capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run(capsys, "plan", "--help")
    assert "push-grasps too" in " ".join(out.split())


def test_von_mises_prior_in_degrees(capsys: pytest.CaptureFixture[str]) -> None:
    assert parse_prior("vonmises:135,6").name == "von-mises(135deg,6)"
    assert von_mises(math.pi / 2, 2.5).name == "von-mises(90deg,2.5)"
    _, out, _ = run(capsys, "plan", "house", "--prior", "vonmises:135,6")
    assert "prior von-mises(135deg,6)" in out and "2.35619" not in out


def test_fit_is_not_applicable_when_most_trials_jam() -> None:
    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    final = np.zeros(10)
    jammed = np.arange(10) < 8  # 8 of 10 jam
    res = summarize("mujoco", pb, opt, final, jammed, np.zeros(10, bool), 1.0, 1e-6)
    assert res.fit_unavailable == "8 of 10 trials jammed"
    assert math.isnan(res.p_value)
    text = simulate_table(res)
    assert "goodness of fit (chi-square over final orientations): n/a (8 of 10 trials" in text
    assert "p = 1" not in text
    doc = simulate_json(res)
    assert doc["p_value"] is None and doc["p_value_unavailable"] == "8 of 10 trials jammed"
    fine = summarize("mujoco", pb, opt, final, np.zeros(10, bool), np.zeros(10, bool), 1.0, 1e-6)
    # physics: no chi-square over states; the success test counts every trial
    assert fine.fit_unavailable == PHYSICS_FIT and "p = " not in simulate_table(fine)
    assert "p = " in "\n".join(verdict_lines(fine))


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["plan", "triangle", "--squeeze-cost", "nan"], "is not a number"),
        (["plan", "triangle", "--accuracy", "nan"], "is not a number"),
        (["plan", "triangle", "--accuracy", "2", "--method", "bfs"], "0.0349066 rad = 2 deg"),
    ],
)
def test_messages_name_the_problem(
    capsys: pytest.CaptureFixture[str], argv: list[str], words: str
) -> None:
    code, out, err = run(capsys, *argv)
    assert (code, out) == (2, "")
    assert words in err and "should be >= 0" not in err


@pytest.mark.parametrize("value", ["nan", "0", "-1", "inf"])
@pytest.mark.parametrize("command", [["plan", "house"], ["squeeze", "house"], ["sweep", "house"]])
def test_flattening_tolerance_is_checked_for_every_part(
    capsys: pytest.CaptureFixture[str], command: list[str], value: str
) -> None:
    # Polygon parts have no curves to flatten, but a nonsense tolerance is still refused
    # (as it is for SVG and DXF parts), not passed on.
    code, out, err = run(capsys, *command, "--flatten-tol", value)
    assert code == 2 and out == ""
    assert "--flatten-tol" in err and "> 0" in err and len(err.strip().splitlines()) == 1


def test_a_one_cycle_policy_simulation_is_valid_json(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    code, out, err = run(capsys, "simulate", "house", "--sense", "width", "--trials", "1", "--json")
    assert code == 0, err
    doc = json.loads(out)  # strict: no Infinity
    assert doc["cycles"] == 1
    assert doc["cycle_cost"]["interval"] == [None, None]  # one cycle bounds nothing
    assert doc["success_probability"]["predicted"] == pytest.approx(0.5)


@pytest.mark.parametrize("command", ["plan", "squeeze", "simulate"])
def test_an_empty_prior_is_refused_not_taken_as_uniform(
    capsys: pytest.CaptureFixture[str], command: str
) -> None:
    code, out, err = run(capsys, command, "house", "--prior", "")
    assert code == 2 and out == ""
    assert "prior is empty" in err


@pytest.mark.parametrize("option", ["--export", "--plot"])
def test_an_over_long_output_name_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path, option: str
) -> None:
    name = str(tmp_path / ("x" * 300 + (".csv" if option == "--export" else ".png")))
    code, out, err = run(capsys, "plan", "house", option, name)
    assert code == 2 and out == ""
    assert "cannot write" in err and "File name too long" in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("[" * 100_000 + "]" * 100_000, "nested deeper than the limit"),
        ('{"first_squeeze_rad": 1' + "0" * 400 + ', "final_orientation_rad": 0}', "too large"),
        (
            '{"squeezes": 1' + "0" * 400 + ', "first_squeeze_rad": 0, "final_orientation_rad": 0}',
            "too large",
        ),
        (
            '{"steps": ['
            + '{"type": "squeeze", "alpha_rad": 0.1}, ' * 20_001
            + '{"type": "squeeze", "alpha_rad": 0.1}], "final_orientation_rad": 0}',
            "at most 10,000",
        ),
    ],
    ids=["deep", "huge angle", "huge field", "too many steps"],
)
def test_a_plan_file_out_of_bounds_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path, text: str, says: str
) -> None:
    f = tmp_path / "plan.json"
    f.write_text(text, encoding="utf-8")
    code, out, err = run(capsys, "simulate", "house", "--plan", str(f), "--trials", "5")
    assert code == 2 and out == ""
    assert says in err and "plan.json" in err and len(err.strip().splitlines()) == 1


def test_a_folder_given_as_part_says_so(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    code, out, err = run(capsys, "plan", str(tmp_path))
    assert (code, out) == (2, "") and "is a folder, not a part file" in err


def test_a_huge_part_reports_only_what_a_user_reads(
    capsys: pytest.CaptureFixture[str], tmp_path
) -> None:
    import json

    from bayesgrasp.cli.plan import HUGE_STATES

    t = np.sort(np.random.default_rng(3).uniform(0, 2 * np.pi, 1200))
    f = tmp_path / "ring.json"
    f.write_text(json.dumps({"vertices": np.c_[50 * np.cos(t), 50 * np.sin(t)].tolist()}))
    code, out, err = run(capsys, "plan", str(f), "--json")
    doc = json.loads(out)
    assert code == 0 and "stable orientations: only the Bayes and the most certain" in err
    from bayesgrasp.io import read_part

    assert Problem.build(read_part(f)).n_states > HUGE_STATES
    short = len(doc["options"])
    assert short <= 2
    code, out, err = run(capsys, "plan", str(f), "--json", "--only", "all")
    assert code == 0 and err == ""
    full = json.loads(out)
    assert len(full["options"]) > short
    best = full["options"][full["bayes"]]
    assert doc["options"][doc["bayes"]]["expected_cost"] == pytest.approx(best["expected_cost"])


def test_the_von_mises_mean_is_echoed_in_degrees(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "plan", "house", "--prior", "vonmises:30,-1")
    assert code == 2 and "mean 30 deg, kappa -1" in err
