"""``simulate`` under the model's noise vocabulary: turn error, contact asynchrony, payoff.

- the older spelling ``--noise DEG --noise-kind KIND`` writes the document ``--turn-noise
  KIND:DEG`` writes;
- under noise (or a payoff) the simulated plan is the one ``plan`` gives with the same
  options, and it is predicted with the exact noisy evaluation (checked here against
  :func:`~bayesgrasp.planning.noisy.evaluate_plan` and, for the contact draw, against a
  brute-force push-grasp of a fine grid of orientations);
- the trials agree with the prediction within binomial bounds, and the payoff's mean within
  its interval; a wrong prediction is called wrong.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from numpy.typing import NDArray

from bayesgrasp.angles import TWO_PI
from bayesgrasp.cli import main
from bayesgrasp.errors import SimulationError
from bayesgrasp.geometry.push import push_grasp_function
from bayesgrasp.model.noise import NoiseModel, NoisyTransitions, TurnNoise
from bayesgrasp.model.payoff import read_payoff
from bayesgrasp.model.problem import Problem
from bayesgrasp.model.states import nearest_state
from bayesgrasp.planning import PlanStep, plan_exact
from bayesgrasp.planning.noisy import evaluate_plan, plan_noisy
from bayesgrasp.shapes import load
from bayesgrasp.sim.kinematic import simulate_kinematic
from bayesgrasp.sim.noise import GripperNoise, noise_model
from bayesgrasp.sim.noisy import simulate_noise
from bayesgrasp.sim.result import with_prediction

DEG = math.pi / 180.0


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def doc_of(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, Any]:
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0, err
    doc: dict[str, Any] = json.loads(out)
    doc.pop("seconds")
    return doc


def binomial_ok(observed: NDArray[np.intp], predicted: NDArray[np.float64], n: int) -> None:
    """Every state's count within 5 standard deviations (and 3 trials for rare states)."""
    sd = np.sqrt(np.clip(predicted * (1 - predicted), 0.0, None) / n)
    assert np.all(np.abs(observed / n - predicted) < 5 * sd + 3 / n), (observed / n, predicted)


@pytest.fixture
def payoff_file(tmp_path: Path) -> Path:
    """A payoff on the key's states: its two goal orientations and the two beside them."""
    f = tmp_path / "payoff.json"
    f.write_text(
        json.dumps({"payoff": {"80.63": 1.0, "260.63": 0.8, "101.56": 0.5, "281.56": 0.5}}),
        encoding="utf-8",
    )
    return f


# -- one vocabulary ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("old", "new"),
    [
        (["--noise", "3"], ["--turn-noise", "normal:3"]),
        (["--noise", "3", "--noise-kind", "uniform"], ["--turn-noise", "uniform:3"]),
        (["--noise", "1.5", "--noise-kind", "uniform", "--plan", "guaranteed"],
         ["--turn-noise", "uniform:1.5", "--plan", "guaranteed"]),
    ],
)  # fmt: skip
def test_the_older_spelling_is_the_turn_noise(
    capsys: pytest.CaptureFixture[str], old: list[str], new: list[str]
) -> None:
    base = ["simulate", "triangle", "--trials", "5000", "--seed", "3"]
    a = doc_of(capsys, *base, *old)
    b = doc_of(capsys, *base, *new)
    assert a == b
    deg = float(new[1].partition(":")[2])
    assert a["provenance"]["noise_deg"] == deg
    assert a["provenance"]["noise_kind"] == new[1].partition(":")[0]
    assert_allclose(a["noise"]["turn"]["scale_rad"], math.radians(deg), rtol=1e-15)


def test_the_older_spelling_is_hidden(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "simulate", "--help")
    assert code == 0
    assert "--turn-noise" in out and "--contact-noise" in out and "--payoff" in out
    assert "--noise " not in out and "--noise-kind" not in out


# -- the plan simulated is plan's -------------------------------------------------------------


@pytest.mark.parametrize(
    ("part", "options"),
    [
        ("key", ["--turn-noise", "normal:2"]),
        ("triangle", ["--turn-noise", "uniform:3"]),
        ("house", ["--contact-noise", "0.3"]),
        ("key", ["--turn-noise", "normal:2", "--contact-noise", "0.1", "--payoff", "PAYOFF"]),
    ],
)
@pytest.mark.parametrize("which", ["bayes", "most-certain"])
def test_the_plan_under_noise_is_plans(
    capsys: pytest.CaptureFixture[str],
    payoff_file: Path,
    part: str,
    options: list[str],
    which: str,
) -> None:
    opts = [str(payoff_file) if o == "PAYOFF" else o for o in options]
    code, out, err = run(capsys, "plan", part, *opts, "--json")
    assert code == 0, err
    plan = json.loads(out)
    want = plan["options"][plan["bayes" if which == "bayes" else "most_certain"]]
    sim = doc_of(capsys, "simulate", part, *opts, "--plan", which, "--trials", "2000")
    assert sim["plan"]["steps"] == want["steps"]  # the same angles, to the last bit
    assert_allclose(sim["plan"]["success_probability"], want["success_probability"], rtol=1e-12)
    if "--payoff" in opts:
        noisy = plan["noisy_options"][plan["bayes" if which == "bayes" else "most_certain"]]
        assert_allclose(sim["payoff"]["predicted"], noisy["expected_payoff"], rtol=1e-12)
        assert_allclose(
            sim["cost_per_unit_payoff"]["predicted"], noisy["cost_per_unit_payoff"], rtol=1e-12
        )


def test_the_key_under_a_turn_error_runs_the_noise_aware_plan(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The noise-free Bayes plan (a 67.16 deg turn) is not what runs under normal:2."""
    sim = doc_of(capsys, "simulate", "key", "--turn-noise", "normal:2", "--trials", "1000")
    turn = math.degrees(sim["plan"]["steps"][1]["alpha_rad"])
    assert turn == pytest.approx(65.22, abs=0.005)
    assert sim["predicted_success"] == pytest.approx(0.3924, abs=5e-5)
    pb = Problem.build(load("key"))
    free = plan_exact(pb).bayes_plan
    assert math.degrees(free.steps[1].alpha) == pytest.approx(67.16, abs=0.005)


# -- predictions and their checks ---------------------------------------------------------------


NOISES = {
    "normal": NoiseModel(TurnNoise("normal", 2 * DEG)),
    "uniform": NoiseModel(TurnNoise("uniform", 3 * DEG)),
    "contact": NoiseModel(contact=0.3),
    "both": NoiseModel(TurnNoise("normal", 1.5 * DEG), 0.2),
}


def _cli_noise(noise: NoiseModel) -> list[str]:
    out = [] if noise.turn.exact else ["--turn-noise", noise.turn.spec()]
    return out + (["--contact-noise", f"{noise.contact:g}"] if noise.contact else [])


@pytest.mark.parametrize("part", ["key", "triangle", "example", "house"])
@pytest.mark.parametrize("name", list(NOISES))
def test_simulated_success_agrees_with_the_exact_prediction(
    capsys: pytest.CaptureFixture[str], part: str, name: str
) -> None:
    noise = NOISES[name]
    n = 100_000
    sim = doc_of(capsys, "simulate", part, *_cli_noise(noise), "--trials", str(n), "--seed", "5")
    pb = Problem.build(load(part))
    steps = [PlanStep(s["type"], s["alpha_rad"]) for s in sim["plan"]["steps"]]
    # The prediction is the exact noisy evaluation of the simulated plan.
    exact = evaluate_plan(pb, noise, steps).distribution
    rows = {round(r["orientation_rad"], 9): r for r in sim["per_orientation"]}
    for s, p in zip(pb.states.stable, exact, strict=True):
        r = rows.get(round(float(s), 9))
        assert_allclose(0.0 if r is None else r["predicted"], p, atol=1e-12)
    observed = np.array([rows[round(float(s), 9)]["count"] if round(float(s), 9) in rows else 0
                         for s in pb.states.stable])  # fmt: skip
    binomial_ok(observed, exact, n)
    lo, hi = sim["success_interval"]
    assert lo <= sim["predicted_success"] <= hi and sim["agrees"]
    assert sim["noise"] == noise.to_json()


def test_payoff_is_judged_by_its_mean(
    capsys: pytest.CaptureFixture[str], payoff_file: Path
) -> None:
    n = 200_000
    opts = ["--turn-noise", "normal:2", "--payoff", str(payoff_file)]
    sim = doc_of(capsys, "simulate", "key", *opts, "--trials", str(n), "--seed", "2")
    pb = Problem.build(load("key"))
    noise = NoiseModel(TurnNoise("normal", 2 * DEG))
    u = read_payoff(payoff_file).vector(pb.states)
    steps = [PlanStep(s["type"], s["alpha_rad"]) for s in sim["plan"]["steps"]]
    ev = evaluate_plan(pb, noise, steps, u)
    pay = sim["payoff"]
    assert_allclose(pay["predicted"], ev.expected_payoff, rtol=1e-12)
    # The observed mean is the counts weighted by the payoff, recomputed here.
    value = {round(float(s), 9): float(v) for s, v in zip(pb.states.stable, u, strict=True)}
    mean = sum(r["count"] * value[round(r["orientation_rad"], 9)] for r in sim["per_orientation"])
    assert_allclose(pay["observed"], mean / n, rtol=1e-12)
    sd = math.sqrt(float(ev.distribution @ u**2) - ev.expected_payoff**2) / math.sqrt(n)
    assert abs(pay["observed"] - ev.expected_payoff) < 5 * sd
    assert pay["interval"][0] <= pay["predicted"] <= pay["interval"][1] and sim["agrees"]
    # The interval covers at least the normal one of the sample (a mean in [0, 1]).
    lo, hi = pay["ci95"]
    assert hi - lo >= 2 * 1.959 * sd * 0.99
    # Success: a final state of positive payoff (not the one goal state).
    assert_allclose(sim["predicted_success"], ev.success_probability, rtol=1e-12)
    assert sum(r["goal"] for r in sim["per_orientation"]) == int(np.count_nonzero(u > 0))
    cost = sim["cost_per_unit_payoff"]
    assert_allclose(cost["predicted"], ev.expected_cost, rtol=1e-12)
    assert cost["ci95"][0] <= cost["observed"] <= cost["ci95"][1]
    code, out, _ = run(capsys, "simulate", "key", *opts, "--trials", "20000")
    assert code == 0
    assert "payoff: predicted E[payoff]" in out and "cost per unit payoff" in out
    assert "verdict: agrees" in out


def test_payoff_of_another_plan(capsys: pytest.CaptureFixture[str], payoff_file: Path) -> None:
    """A plan file or the guaranteed plan judged by a payoff (no noise)."""
    sim = doc_of(capsys, "simulate", "key", "--plan", "guaranteed", "--payoff", str(payoff_file),
                 "--trials", "20000")  # fmt: skip
    pb = Problem.build(load("key"))
    steps = [PlanStep(s["type"], s["alpha_rad"]) for s in sim["plan"]["steps"]]
    ev = evaluate_plan(pb, NoiseModel(), steps, read_payoff(payoff_file))
    assert_allclose(sim["payoff"]["predicted"], ev.expected_payoff, rtol=1e-12)
    assert sim["agrees"]


# -- the contact draw against the exact matrices ---------------------------------------------


def _brute_contact(pb: Problem, alpha: float, q: float, grid: int = 200_000) -> NDArray[np.float64]:
    """One squeeze at ``alpha`` with contact asynchrony ``q``, on a fine grid of starts.

    The uniform prior's starts, each sent by the squeeze (weight ``1 - q``), by a push-grasp
    from the ``-x`` side (``q / 2``) and from the ``+x`` side (``q / 2``): no sampling.
    """
    theta = (np.arange(grid) + 0.5) * TWO_PI / grid - alpha
    g = push_grasp_function(pb.part, pb.states)
    out = np.zeros(pb.n_states)
    for w, ends in (
        (1.0 - q, pb.transfer("squeeze")(theta)),
        (q / 2, g(theta)),
        (q / 2, g(theta - math.pi) + math.pi),
    ):
        idx = nearest_state(pb.states, np.mod(ends, TWO_PI))
        out += w * np.bincount(idx, minlength=pb.n_states) / grid
    return out


@pytest.mark.parametrize("part", ["key", "house", "triangle", "tuning-fork"])
@pytest.mark.parametrize("q", [0.3, 1.0])
def test_the_contact_draw_agrees_with_the_exact_matrices(part: str, q: float) -> None:
    pb = Problem.build(load(part))
    noise = NoiseModel(contact=q)
    # One squeeze: the exact matrices against the brute-force grid.
    exact1 = evaluate_plan(pb, noise, [PlanStep("squeeze", 0.3)]).distribution
    assert_allclose(exact1, _brute_contact(pb, 0.3, q), atol=2e-4)
    # A plan of three squeezes (two turns): the simulated draw against the matrices.
    steps = [PlanStep("squeeze", 0.3), PlanStep("squeeze", 0.7), PlanStep("squeeze", -0.4)]
    n = 200_000
    nt = NoisyTransitions(pb, noise)
    dist = nt.initial("squeeze", 0.3) @ nt.matrix("squeeze", 0.7) @ nt.matrix("squeeze", -0.4)
    counts = simulate_noise(pb, noise, steps, n, rng=11)
    binomial_ok(counts, dist, n)
    assert_allclose(evaluate_plan(pb, noise, steps).distribution, dist, atol=1e-12)


def test_contact_noise_leaves_a_push_grasp_alone() -> None:
    """A push-grasp pushes with one jaw on purpose: the contact events do not change it."""
    pb = Problem.build(load("house"), actions=("squeeze", "push-grasp"))
    steps = [PlanStep("push-grasp", 0.0), PlanStep("push-grasp", 0.6)]
    a = simulate_noise(pb, NoiseModel(contact=1.0), steps, 20_000, rng=4)
    b = simulate_noise(pb, NoiseModel(), steps, 20_000, rng=4)
    assert np.array_equal(a, b)


def test_without_contact_noise_the_draws_are_unchanged() -> None:
    """No contact draws without contact noise: a turn error alone draws what it always drew."""
    pb = Problem.build(load("triangle"))
    plan = plan_exact(pb).bayes_plan
    a = simulate_kinematic(pb, plan, 30_000, GripperNoise("normal", 3 * DEG), rng=2)
    b = simulate_kinematic(pb, plan, 30_000, NoiseModel(TurnNoise("normal", 3 * DEG)), rng=2)
    assert np.array_equal(a.final, b.final)
    assert_allclose(a.predicted, b.predicted, atol=0)
    assert a.noise == b.noise == noise_model(GripperNoise("normal", 3 * DEG))


# -- the verdict -------------------------------------------------------------------------------


def test_a_wrong_prediction_is_called_wrong() -> None:
    """The trials under a turn error judged against the noise-free prediction: disagree."""
    pb = Problem.build(load("triangle"))
    plan = plan_exact(pb).bayes_plan
    noise = NoiseModel(TurnNoise("normal", 3 * DEG))
    res = simulate_kinematic(pb, plan, 100_000, noise, rng=1)
    assert res.agrees
    wrong = with_prediction(res, pb, NoiseModel())
    assert not wrong.agrees and wrong.predicted_success == pytest.approx(0.5)
    assert_allclose(wrong.observed, res.observed, atol=0)


def test_a_turn_error_beyond_the_model_is_refused() -> None:
    pb = Problem.build(load("key"))
    plan = plan_exact(pb).bayes_plan
    with pytest.raises(SimulationError, match="no exact prediction"):
        simulate_kinematic(pb, plan, 10, GripperNoise("normal", 45 * DEG), rng=0)
    with pytest.raises(SimulationError, match="NoiseModel"):
        simulate_kinematic(pb, plan, 10, 0.1, rng=0)  # type: ignore[arg-type]


def test_mujoco_results_are_predicted_under_the_noise(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The MuJoCo path: the turn error reaches the engine; the prediction is the noisy one."""
    import bayesgrasp.sim

    seen: list[Any] = []

    def fake(pb: Any, option: Any, n: int, **kw: Any) -> Any:
        seen.append(kw["noise"])
        return simulate_kinematic(pb, option, n, kw["noise"], rng=kw["rng"])

    monkeypatch.setattr(bayesgrasp.sim, "simulate_mujoco", fake)
    argv = ["simulate", "key", "--engine", "mujoco", "--turn-noise", "normal:2", "--trials", "50"]
    sim = doc_of(capsys, *argv)
    assert seen == [GripperNoise("normal", math.radians(2))]
    pb = Problem.build(load("key"))
    bayes = plan_noisy(pb, NoiseModel(TurnNoise("normal", math.radians(2)))).bayes_plan
    assert [s["alpha_rad"] for s in sim["plan"]["steps"]] == [s.alpha for s in bayes.option.steps]
    assert_allclose(sim["predicted_success"], bayes.option.success_probability, rtol=1e-12)
    assert sim["noise"]["turn"]["kind"] == "normal"


# -- bad input ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--engine", "mujoco", "--contact-noise", "0.2"], "physics' own"),
        (["--noise", "45"], "beyond the noise model"),
        (["--turn-noise", "normal:2", "--noise-kind", "uniform"], "names its own"),
        (["--turn-noise", "normal:2", "--noise", "1"], "not both"),
        (["--turn-noise", "normal:50"], "scale"),
        (["--payoff", "missing.json"], "no such file"),
        (["--engine", "mujoco", "--contact-noise", "0.2", "--sense", "width"], "physics' own"),
        (["--payoff", "missing.json", "--sense", "width"], "no such file"),
        (["--turn-noise", "normal:1", "--method", "bfs"], "drop --method"),
        (["--units", "mm"], "mujoco only"),
        (["--sense", "width", "--plan", "most-certain"], "Bayes policy is planned"),
        (["--plan", "guaranteed", "--turn-noise", "normal:1"], "unbounded"),
    ],
)
def test_bad_options_exit_2(
    capsys: pytest.CaptureFixture[str], argv: list[str], match: str
) -> None:
    code, out, err = run(capsys, "simulate", "key", "--trials", "10", *argv)
    assert code == 2 and out == ""
    assert match in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_a_plan_file_made_under_noise_is_noted(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, payoff_file: Path
) -> None:
    code, out, _ = run(capsys, "plan", "key", "--turn-noise", "normal:2", "--payoff",
                       str(payoff_file), "--json")  # fmt: skip
    assert code == 0
    plan = tmp_path / "p.json"
    plan.write_text(out, encoding="utf-8")
    code, _, err = run(capsys, "simulate", "key", "--plan", str(plan), "--trials", "100")
    assert code == 0 and "--turn-noise normal:2 --payoff FILE" in err
    code, _, err = run(capsys, "simulate", "key", "--plan", str(plan), "--trials", "100",
                       "--turn-noise", "normal:2", "--payoff", str(payoff_file))  # fmt: skip
    assert code == 0 and err == ""


# -- invariants ----------------------------------------------------------------------------------


@settings(max_examples=25, deadline=None)
@given(
    kind=st.sampled_from(["normal", "uniform"]),
    deg=st.sampled_from([0.0]) | st.floats(1e-6, 30.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_a_gripper_error_is_its_turn_noise(kind: str, deg: float, seed: int) -> None:
    """The older form of a turn error draws and predicts exactly what the model's form does."""
    pb = Problem.build(load("key"))
    plan = plan_exact(pb).bayes_plan
    scale = math.radians(deg)
    a = simulate_kinematic(pb, plan, 500, GripperNoise(kind, scale), rng=seed)  # type: ignore[arg-type]
    b = simulate_kinematic(pb, plan, 500, NoiseModel(TurnNoise(kind, scale)), rng=seed)  # type: ignore[arg-type]
    assert np.array_equal(a.final, b.final) and np.array_equal(a.predicted, b.predicted)
    assert_allclose(a.predicted.sum(), 1.0, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(
    values=st.lists(st.sampled_from([0.0, 0.25, 0.5, 1.0]), min_size=8, max_size=8).filter(
        lambda v: any(x > 0 for x in v)
    ),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_payoff_interval_holds_the_mean(values: list[float], seed: int) -> None:
    """The payoff's intervals hold its observed mean, in [0, 1]; a 0/1 payoff's is success's."""
    pb = Problem.build(load("key"))
    plan = plan_exact(pb).bayes_plan
    u = np.array(values)
    res = simulate_kinematic(pb, plan, 300, NoiseModel(contact=0.2), rng=seed, payoff=u)
    for z in (1.959963984540054, 4.0):
        lo, hi = res.payoff_interval(z)
        assert 0.0 <= lo <= res.observed_payoff <= hi <= 1.0
    assert_allclose(res.predicted_payoff, float(res.predicted @ u), atol=0)
    assert_allclose(res.predicted_success, float(res.predicted[u > 0].sum()), atol=0)
    if set(values) <= {0.0, 1.0}:
        assert_allclose(res.payoff_interval(), res.ci95, atol=1e-12)
        assert_allclose(res.payoff_interval(4.0), res.success_interval, atol=1e-12)


def test_simulate_runs_the_guaranteed_plan_plan_gives_under_bounded_noise(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``simulate --plan guaranteed`` under a uniform turn error runs ``plan --guaranteed``'s
    plan for that error: its prediction is the plan's, the trials agree, and none jams."""
    assert main(["plan", "key", "--turn-noise", "uniform:1", "--guaranteed", "--json"]) == 0
    sure = json.loads(capsys.readouterr().out)["guaranteed"]
    args = ["simulate", "key", "--plan", "guaranteed", "--turn-noise", "uniform:1"]
    assert main([*args, "--trials", "20000", "--seed", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["plan"]["steps"] == sure["steps"]
    assert doc["predicted_success"] == pytest.approx(sure["success_probability"], abs=1e-12)
    assert doc["agrees"] and doc["jams"] == 0
