"""Sweeps under noise or a payoff with a guaranteed plan, a sensing policy and a simulation.

Each row's documents are the CLI's for the same part: ``plan_json`` is ``plan PATH
--turn-noise ... [--guaranteed] --json``, ``policy_json`` is ``plan PATH --sense S
--turn-noise ... --json`` and ``sim_json`` is ``simulate PATH --turn-noise ... --seed S
--trials T --json``.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bayesgrasp.sweep import PartSource, SweepOptions, plan_part, read_results
from bayesgrasp.sweep.tasks import run_chunk

Check = Callable[[list[dict[str, Any]], list[str], SweepOptions], None]
CliRun = Callable[[list[str]], tuple[int, str, str]]


@pytest.fixture(scope="module")
def three(parts: list[str]) -> list[str]:
    """The triangle (no guaranteed plan under uniform:3 and contact noise), rectangle, key."""
    return parts[:3]


@pytest.fixture(scope="module")
def payoff_file(tmp_path_factory: pytest.TempPathFactory) -> str:
    u = tmp_path_factory.mktemp("payoff") / "u.csv"
    u.write_text("orientation_deg,value\n0,1\n90,0.5\n")  # the rectangle's 0 and 90 deg
    return str(u)


def noise_args(options: SweepOptions) -> list[str]:
    """The noise and payoff arguments of ``options``, as the CLI takes them."""
    args = options.plan_args()
    i = next(k for k, a in enumerate(args) if a in ("--turn-noise", "--contact-noise", "--payoff"))
    return args[i:]


def cli_doc(cli_run: CliRun, argv: list[str], codes: tuple[int, ...] = (0,)) -> dict[str, Any]:
    code, out, err = cli_run(argv)
    assert code in codes, err
    return dict(json.loads(out))


# -- --guaranteed ----------------------------------------------------------------------------

GUARANTEED = [
    {"turn_noise": "uniform:3"},
    {"turn_noise": "uniform:3", "contact_noise": 0.1},
    {"contact_noise": 0.2, "max_actions": 4},
    {"turn_noise": "uniform:1", "prior": "vonmises:30,2", "retry_cost": 0.5},
]


@pytest.mark.parametrize("kwargs", GUARANTEED)
def test_guaranteed_rows_equal_the_cli(
    three: list[str], rows_check: Check, kwargs: dict[str, Any]
) -> None:
    options = SweepOptions(guaranteed=True, **kwargs)
    assert "--guaranteed" in options.plan_args()
    rows = run_chunk([PartSource(p) for p in three], options).rows
    rows_check(rows, three, options)  # plan_json and status == `plan ... --guaranteed --json`
    for r in rows:
        doc = json.loads(r["plan_json"])
        assert doc["method"] == "noisy"
        if r["status"] == "ok":
            assert r["guaranteed_actions"] == doc["guaranteed"]["squeezes"] >= 1
            assert r["guaranteed_missing"] is None
        else:  # `plan` exits 1: the reason is the row's
            assert r["status"] == "no-plan" and r["guaranteed_actions"] is None
            assert r["guaranteed_missing"] == doc["guaranteed_missing"]
            assert "no plan guarantees" in r["guaranteed_missing"]


def test_guaranteed_plan_under_noise_holds_in_simulation(three: list[str]) -> None:
    # the independent check: the guaranteed plan's steps, executed 20,000 times under the
    # bounded noise, always leave the part on the final orientation's orbit (the states a
    # period of the width function apart, which no squeeze tells apart)
    from bayesgrasp.io import read_part
    from bayesgrasp.io.plans import read_plan
    from bayesgrasp.model.noise import NoiseModel, parse_turn_noise
    from bayesgrasp.model.problem import Problem
    from bayesgrasp.sim.kinematic import simulate_kinematic

    options = SweepOptions(guaranteed=True, turn_noise="uniform:3", contact_noise=0.1)
    row = plan_part(three[2], options)  # the key
    assert row["status"] == "ok", row["guaranteed_missing"]
    plan = read_plan(json.loads(row["plan_json"]), "guaranteed").option
    assert plan.n_actions == row["guaranteed_actions"]
    noise = NoiseModel(parse_turn_noise("uniform:3"), 0.1)
    res = simulate_kinematic(Problem.build(read_part(three[2])), plan, 20_000, noise, rng=5)
    assert res.jams == 0 and res.observed.sum() == 20_000
    period = json.loads(row["plan_json"])["period_rad"]
    gap = np.mod(res.orientations - plan.final_orientation + period / 2, period) - period / 2
    assert res.observed[np.abs(gap) > 1e-6].sum() == 0
    assert res.observed[np.abs(gap) <= 1e-6].sum() == 20_000


# -- --sense ---------------------------------------------------------------------------------

SENSED = [
    {"turn_noise": "normal:2"},
    {"turn_noise": "uniform:3", "contact_noise": 0.1, "sense_max_actions": 2},
    {"contact_noise": 0.2, "verify_cost": 2.0},
]


@pytest.mark.parametrize("kwargs", SENSED)
def test_policy_under_noise_equals_the_cli(
    three: list[str], rows_check: Check, cli_run: CliRun, kwargs: dict[str, Any]
) -> None:
    options = SweepOptions(guaranteed=False, sense="width:0.5,0.25", **kwargs)
    rows = run_chunk([PartSource(p) for p in three], options).rows
    rows_check(rows, three, options)
    depth = ["--max-actions", str(options.sense_max_actions)]
    for r in rows:
        argv = ["plan", r["path"], "--sense", "width:0.5,0.25", *depth, *noise_args(options)]
        if options.verify_cost != 1.0:
            argv += ["--verify-cost", str(options.verify_cost)]
        want = cli_doc(cli_run, [*argv, "--json"])
        assert json.loads(r["policy_json"]) == want
        assert (r["policy_cost"], r["policy_success"], r["policy_actions"]) == (
            want["expected_cost"],
            want["success_probability"],
            want["expected_actions"],
        )
        assert want["noise"] is not None


def test_policy_with_a_payoff_equals_the_cli(
    three: list[str], payoff_file: str, cli_run: CliRun
) -> None:
    options = SweepOptions(guaranteed=False, sense="width", payoff=payoff_file)
    row = plan_part(three[1], options)
    assert row["status"] == "ok", row["error_message"]
    want = cli_doc(
        cli_run, ["plan", three[1], "--sense", "width", "--payoff", payoff_file, "--json"]
    )
    assert json.loads(row["policy_json"]) == want
    # the noise-free policy and the payoff-free one differ: the payoff is used
    plain = plan_part(three[1], SweepOptions(guaranteed=False, sense="width"))
    assert plain["policy_json"] != row["policy_json"]


# -- --simulate ------------------------------------------------------------------------------

SIMULATED = [
    {"turn_noise": "normal:2"},
    {"turn_noise": "uniform:3", "contact_noise": 0.1},
    {"contact_noise": 0.3},
]


def same_simulation(row: dict[str, Any], want: dict[str, Any]) -> None:
    got = json.loads(row["sim_json"])
    got.pop("seconds"), want.pop("seconds")
    assert got == want
    assert row["sim_observed"] == want["observed_success"]
    assert row["sim_predicted"] == want["predicted_success"]


@pytest.mark.parametrize("kwargs", SIMULATED)
def test_kinematic_simulation_under_noise_equals_the_cli(
    three: list[str], cli_run: CliRun, kwargs: dict[str, Any]
) -> None:
    options = SweepOptions(guaranteed=False, simulate="kinematic", trials=20_000, seed=7, **kwargs)
    for r in run_chunk([PartSource(p) for p in three], options).rows:
        assert r["status"] == "ok", r["error_message"]
        argv = ["simulate", r["path"], *noise_args(options), "--seed", "7", "--trials", "20000"]
        want = cli_doc(cli_run, [*argv, "--json"])
        same_simulation(r, want)
        # the row simulates its own noise-aware Bayes plan, predicted exactly under the noise
        doc = json.loads(r["plan_json"])
        assert r["sim_predicted"] == pytest.approx(
            doc["options"][doc["bayes"]]["success_probability"]
        )
        assert abs(r["sim_observed"] - r["sim_predicted"]) < 4 * 0.5 / 20_000**0.5


@pytest.mark.parametrize(
    ("engine", "turn", "trials"),
    [
        ("kinematic", "normal:1", 10_000),
        pytest.param("mujoco", "uniform:2", 4, marks=pytest.mark.physics),
    ],
)
def test_simulation_with_a_payoff_equals_the_cli(
    three: list[str], payoff_file: str, cli_run: CliRun, engine: str, turn: str, trials: int
) -> None:
    # MuJoCo draws the turn error; both engines predict exactly under the noise and payoff
    options = SweepOptions(
        guaranteed=False, turn_noise=turn, payoff=payoff_file, simulate=engine, trials=trials,
        seed=3,
    )  # fmt: skip
    row = plan_part(three[1], options)
    assert row["status"] == "ok", row["error_message"]
    argv = ["simulate", three[1], "--engine", engine, *noise_args(options), "--seed", "3"]
    want = cli_doc(cli_run, [*argv, "--trials", str(trials), "--json"])
    same_simulation(row, want)
    assert want["provenance"]["payoff"] == payoff_file
    assert want["provenance"]["noise_kind"] == turn.split(":")[0]


# -- everything at once, through Dask and the command ----------------------------------------


@pytest.mark.dask
def test_local_cluster_sweep_with_noise_and_everything_equals_the_cli(
    three: list[str], tmp_path: Path, rows_check: Check, cli_run: CliRun
) -> None:
    from bayesgrasp.sweep import run_sweep

    options = SweepOptions(
        turn_noise="uniform:3", contact_noise=0.1, sense="width:0.5,0.25", sense_max_actions=2,
        simulate="kinematic", trials=5000, seed=4,
    )  # fmt: skip
    out = tmp_path / "r.parquet"
    s = run_sweep(three, out, options, workers=1, send="bytes")
    assert (s.ok, s.no_plan, s.errors) == (2, 1, 0)  # the triangle has no guaranteed plan
    rows = read_results(out)
    rows_check(rows, three, options)
    noise = noise_args(options)
    for r in rows:
        pol = ["plan", r["path"], "--sense", "width:0.5,0.25", "--max-actions", "2", *noise]
        assert json.loads(r["policy_json"]) == cli_doc(cli_run, [*pol, "--json"])
        sim = ["simulate", r["path"], *noise, "--seed", "4", "--trials", "5000", "--json"]
        same_simulation(r, cli_doc(cli_run, sim))


@pytest.mark.dask
def test_sweep_command_with_noise_guaranteed_sense_and_simulate(
    three: list[str], tmp_path: Path, cli_run: CliRun
) -> None:
    folder = tmp_path / "parts"
    folder.mkdir()
    for p in three[1:]:
        shutil.copy(p, folder)
    out = tmp_path / "rows.csv"
    noise = ["--turn-noise", "uniform:2", "--contact-noise", "0.05"]
    more = ["--guaranteed", "--sense", "width", "--simulate", "kinematic", "--trials", "3000"]
    argv = ["sweep", str(folder), "--out", str(out), "--workers", "1", *noise, *more, "--json"]
    code, text, err = cli_run(argv)
    assert code == 0, err
    assert json.loads(text)["ok"] == 2
    for r in read_results(out):
        plan = cli_doc(cli_run, ["plan", r["path"], *noise, "--guaranteed", "--json"])
        assert json.loads(r["plan_json"]) == plan
        assert r["guaranteed_actions"] == plan["guaranteed"]["squeezes"]
        policy = cli_doc(cli_run, ["plan", r["path"], "--sense", "width", *noise, "--json"])
        assert json.loads(r["policy_json"]) == policy
        sim = ["simulate", r["path"], *noise, "--seed", "0", "--trials", "3000", "--json"]
        same_simulation(r, cli_doc(cli_run, sim))


def test_report_of_noisy_rows_with_policies_and_simulations(three: list[str]) -> None:
    from bayesgrasp.sweep.report import report_html

    options = SweepOptions(
        turn_noise="uniform:3", contact_noise=0.1, sense="width", simulate="kinematic",
        trials=2000, seed=1,
    )  # fmt: skip
    rows = run_chunk([PartSource(p) for p in three], options).rows
    assert [r["status"] for r in rows] == ["no-plan", "ok", "ok"]
    page = report_html(rows)
    assert "<td>noise: turn_noise uniform:3, contact_noise 0.1</td><td>3</td>" in page
    assert "<td>no guaranteed plan</td><td>1</td>" in page
    assert "<td>simulated parts</td><td>3</td>" in page
    assert "sensing policy cost: mean" in page
