"""Executing sensing policies (bayesgrasp.sim.policy): cycles against the policies' claims.

Every policy the planner returns, replayed by simulation from prior samples with sensor
errors drawn from the model, must reach its claimed success per cycle, cost per cycle,
actions per cycle and cost per oriented part within ``z = 4`` standard errors (Wilson and
CLT intervals, fixed seeds). The planner computes its claims from reading bins and beliefs;
the simulation only follows the tree with the transfer functions and draws readings from
``WidthSensor.read``, so they share nothing but the model. In MuJoCo (marked ``physics``)
the policy acts on the real jaw separation.
"""

from __future__ import annotations

import importlib.util
import json
import math

import numpy as np
import pytest

from bayesgrasp import shapes
from bayesgrasp.cli import main
from bayesgrasp.errors import SimulationError
from bayesgrasp.geometry import Part
from bayesgrasp.model import CostModel, Goal, Problem
from bayesgrasp.model.prior import von_mises
from bayesgrasp.model.sensing import WidthSensor
from bayesgrasp.planning.policy import plan_policy
from bayesgrasp.sim.noise import GripperNoise
from bayesgrasp.sim.policy import (
    MUJOCO_SIGMA,
    mujoco_sensor,
    policy_simulation_json,
    policy_simulation_text,
    simulate_policy,
)

TRIANGLE = [(0.0, 0.0), (3.0, 0.0), (1.0, 2.0)]
QUAD = [(0.0, 0.0), (4.0, 0.0), (3.6, 2.2), (0.5, 2.6)]
RECT = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]
PENTA = [(0.0, 0.0), (3.0, 0.2), (3.4, 1.9), (1.2, 3.0), (-0.4, 1.5)]


def build(points: list[tuple[float, float]], **kw: object) -> Problem:
    return Problem.build(Part.from_points(points), **kw)  # type: ignore[arg-type]


CASES = [
    ("quad-exact", [QUAD], ("squeeze",), WidthSensor(), 3, None, {}),
    ("quad-quantised", [QUAD], ("squeeze",), WidthSensor(0.0, 0.4), 3, None, {}),
    ("quad-noisy", [QUAD], ("squeeze",), WidthSensor(0.15, 0.1), 3, None, {}),
    ("penta-noisy", [PENTA], ("squeeze",), WidthSensor(0.05, 0.05), 2, None, {}),
    ("quad-push", [QUAD], ("push-grasp",), WidthSensor(0.1, 0.1), 2, None, {}),
    ("quad-both", [QUAD], ("squeeze", "push-grasp"), WidthSensor(0.0, 0.25), 2, None, {}),
    (
        "tri-costs",
        [TRIANGLE],
        ("squeeze",),
        WidthSensor(0.1, 0.05),
        2,
        None,
        {"cost": CostModel(verify=2.0, retry=0.5)},
    ),
    (
        "reject",
        [QUAD],
        ("squeeze",),
        WidthSensor(0.3, 0.1),
        2,
        None,
        {"cost": CostModel(verify=4.0)},
    ),
    (
        "von-mises",
        [QUAD],
        ("squeeze",),
        WidthSensor(0.1, 0.1),
        2,
        None,
        {"prior": von_mises(1.0, 2.0)},
    ),
    (
        "symmetry-goal",
        [RECT],
        ("squeeze",),
        WidthSensor(0.1, 0.1),
        2,
        None,
        {"goal": Goal("symmetry")},
    ),
    ("two-parts", [TRIANGLE, RECT], ("squeeze",), WidthSensor(0.1, 0.05), 2, (0.4, 0.6), {}),
    ("three-parts", [TRIANGLE, RECT, QUAD], ("squeeze",), WidthSensor(), 3, None, {}),
]


@pytest.mark.parametrize(
    ("name", "parts", "actions", "sensor", "depth", "prior", "kw"), CASES, ids=[c[0] for c in CASES]
)
def test_every_policy_reaches_its_claims(
    name: str,
    parts: list[list[tuple[float, float]]],
    actions: tuple[str, ...],
    sensor: WidthSensor,
    depth: int,
    prior: tuple[float, ...] | None,
    kw: dict[str, object],
) -> None:
    problems = [build(p, actions=actions, **kw) for p in parts]
    pol = plan_policy(problems, sensor, depth, part_prior=prior)
    sim = simulate_policy(problems, pol, 40_000, rng=3)
    assert sim.agrees, policy_simulation_text(sim)
    # The drawn reading errors are the sensor's: mean 0, sd SIGMA (plus rounding, at most
    # RES / 2 away).
    e = sim.reading_errors
    assert np.all(np.abs(e) <= 10 * sensor.sigma + sensor.resolution / 2 + 1e-9)
    if sensor.kind == "noisy":
        assert (
            abs(e.std() - math.hypot(sensor.sigma, sensor.resolution / math.sqrt(12)))
            < 0.05 * sensor.sigma
        )


def test_catalogue_recognition_reaches_its_claims() -> None:
    problems = [Problem.build(shapes.load(n)) for n in ("rectangle", "tuning-fork", "ic-chip")]
    pol = plan_policy(problems, "width:0.5,0.1", 2)
    sim = simulate_policy(problems, pol, 60_000, rng=5)
    assert sim.agrees, policy_simulation_text(sim)


def test_a_wrong_claim_is_caught() -> None:
    """The check can fail: a policy whose claims are altered disagrees with its cycles."""
    import dataclasses

    pb = build(QUAD)
    pol = plan_policy(pb, "width:0.15,0.1", 2)
    liar = dataclasses.replace(pol, success_probability=pol.success_probability + 0.02)
    assert simulate_policy(pb, pol, 40_000, rng=1).agrees
    assert not simulate_policy(pb, liar, 40_000, rng=1).agrees


def test_gripper_error_within_the_margins_changes_nothing() -> None:
    pb = build(QUAD)
    pol = plan_policy(pb, "width:0.15,0.1", 3)
    margins = []

    def walk(node: object) -> None:
        from bayesgrasp.planning.policy import PolicyNode

        if isinstance(node, PolicyNode):
            if math.isfinite(node.margin):
                margins.append(node.margin)
            for b in node.branches:
                walk(b.next)

    walk(pol.root)
    small = 0.5 * min(margins)
    a = simulate_policy(pb, pol, 20_000, rng=2)
    b = simulate_policy(pb, pol, 20_000, GripperNoise("uniform", small), rng=2)
    assert a.agrees and b.agrees


def test_chunks_and_seed_are_reproducible() -> None:
    pb = build(QUAD)
    pol = plan_policy(pb, "width:0.15,0.1", 2)
    a = simulate_policy(pb, pol, 5000, rng=9, chunk=700)
    b = simulate_policy(pb, pol, 5000, rng=9, chunk=700)
    assert a.successes == b.successes and np.array_equal(a.cycle_costs, b.cycle_costs)


def test_mismatched_problems_are_refused() -> None:
    pol = plan_policy([build(TRIANGLE), build(RECT)], "width", 2)
    with pytest.raises(SimulationError, match="tells 2 part"):
        simulate_policy(build(TRIANGLE), pol, 10)
    mixed = plan_policy(build(QUAD, actions=("push-grasp",)), "width", 1)
    with pytest.raises(SimulationError, match="push-grasp"):
        simulate_policy(build(QUAD), mixed, 10)
    with pytest.raises(SimulationError, match="trials"):
        simulate_policy(build(TRIANGLE), plan_policy(build(TRIANGLE), "width", 1), 0)


def test_json_and_text() -> None:
    pb = build(QUAD)
    pol = plan_policy(pb, "width:0.15,0.1", 2)
    sim = simulate_policy(pb, pol, 2000, rng=0)
    doc = json.loads(json.dumps(policy_simulation_json(sim)))
    assert doc["schema"] == "bayesgrasp.policy-simulation/1"
    assert doc["success_probability"]["predicted"] == pol.success_probability
    lo, hi = doc["expected_cost"]["interval"]
    assert lo <= doc["expected_cost"]["observed"] <= hi
    assert "cost per oriented part" in policy_simulation_text(sim)


def test_cli_simulate_sense(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["simulate", "house", "--sense", "width:0.5,0.1", "--trials", "20000", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    pol = plan_policy(Problem.build(shapes.load("house")), "width:0.5,0.1", 3)
    assert doc["expected_cost"]["predicted"] == pytest.approx(pol.expected_cost, rel=1e-12)
    assert doc["agrees"] is True
    argv = ["simulate", "rectangle", "--also", "ic-chip", "--sense", "width", "--trials", "5000"]
    assert main(argv) == 0
    assert "every claim within its interval" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--sense", "width:0.1,0"], "needs a resolution RES > 0"),
        (["--also", "key"], "need --sense"),
        (["--sensor-error"], "need --sense"),
    ],
)
def test_cli_bad_input(argv: list[str], match: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "house", *argv]) == 2
    err = capsys.readouterr().err
    assert match in err and "Traceback" not in err


def test_mujoco_sensor_is_in_part_units() -> None:
    mm = mujoco_sensor(shapes.load("house"), 0.001)
    assert mm.sigma == pytest.approx(MUJOCO_SIGMA * 1000)


HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None


@pytest.mark.physics
@pytest.mark.skipif(
    not HAVE_MUJOCO, reason="MuJoCo is not installed: pip install 'bayesgrasp[sim]'"
)
def test_mujoco_policy_acts_on_the_jaw_separation() -> None:
    """In MuJoCo the readings stray from d(sigma) by well under the default SIGMA.

    The policy (planned for MuJoCo's default sensor) then succeeds as often as claimed: a
    cycle fails beyond the claim only where a squeeze jams near a basin boundary, so the
    observed success may fall short by at most the jammed share.
    """
    from bayesgrasp.sim.policy import simulate_policy_mujoco

    part = shapes.load("house")
    pb = Problem.build(part)
    pol = plan_policy(pb, mujoco_sensor(part, 0.001), 3)
    sim = simulate_policy_mujoco(pb, pol, 60, rng=4)
    e = sim.reading_errors
    assert len(e) > 60
    assert np.abs(e).max() < 0.2  # mm: MUJOCO_SIGMA
    assert abs(e.mean()) < 0.15
    lo, hi = sim.success_interval
    assert lo - sim.jams / sim.cycles <= pol.success_probability <= hi + 1e-9
    two = [Problem.build(shapes.load(n)) for n in ("rectangle", "key")]
    pol2 = plan_policy(two, mujoco_sensor(part, 0.001), 2)
    sim2 = simulate_policy_mujoco(two, pol2, 40, rng=5, workers=2)
    lo, hi = sim2.success_interval
    assert lo - sim2.jams / sim2.cycles <= pol2.success_probability <= hi + 1e-9


@pytest.mark.physics
@pytest.mark.skipif(
    not HAVE_MUJOCO, reason="MuJoCo is not installed: pip install 'bayesgrasp[sim]'"
)
def test_mujoco_runs_a_policy_planned_under_turn_noise() -> None:
    """A policy planned for a 3 deg turn error, run in MuJoCo with that error drawn.

    The claim is the exact figure under the noise; MuJoCo's cycles agree with it within their
    interval, up to the share of squeezes that jam near a basin boundary.
    """
    import math

    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy_policy import plan_noisy_policy
    from bayesgrasp.sim.noise import GripperNoise
    from bayesgrasp.sim.policy import simulate_policy_mujoco

    part = shapes.load("house")
    pb = Problem.build(part)
    turn = TurnNoise("normal", math.radians(3.0))
    pol = plan_noisy_policy(pb, mujoco_sensor(part, 0.001), 2, NoiseModel(turn))
    assert pol.noise is not None
    sim = simulate_policy_mujoco(pb, pol, 80, noise=GripperNoise.of(turn), rng=6, workers=2)
    lo, hi = sim.success_interval
    assert lo - sim.jams / sim.cycles <= pol.success_probability <= hi + 1e-9


@pytest.mark.physics
@pytest.mark.skipif(
    not HAVE_MUJOCO, reason="MuJoCo is not installed: pip install 'bayesgrasp[sim]'"
)
def test_mujoco_policy_takes_the_jaw_lag(monkeypatch: pytest.MonkeyPatch) -> None:
    """A jaw lag that makes a 20 mm push by the leading jaw reaches every squeeze of a policy.

    Each squeeze gets a leading jaw (-1 or +1) drawn from the seed with the other draws, so
    one worker and two give the same cycles. The check of the physics is the push-grasp's
    transfer function: where the pure squeeze and the push-grasp from the leading side
    predict different orientations, the lagged squeezes end at the push-grasp's, and the
    same cycles without the lag never do.
    """
    from bayesgrasp.angles import TWO_PI, circle_distance
    from bayesgrasp.geometry.push import push_grasp_function
    from bayesgrasp.geometry.transfer import squeeze_function
    from bayesgrasp.sim import engine
    from bayesgrasp.sim.params import SimParams
    from bayesgrasp.sim.policy import simulate_policy_mujoco

    part = shapes.load("house")
    pb = Problem.build(part)
    pol = plan_policy(pb, mujoco_sensor(part, 0.001), 2)
    acts: list[tuple[float, bool, int | None, float]] = []
    real = engine.Squeezer.act

    def recorded(self: object, theta: float, offset: float = 0.0, push: bool = False,
                 lead: int | None = None, stable: object = None) -> object:  # fmt: skip
        res = real(self, theta, offset, push, lead, stable)  # type: ignore[arg-type]
        acts.append((theta, push, lead, res.end))
        return res

    monkeypatch.setattr(engine.Squeezer, "act", recorded)
    lag = 2 * 0.020 / SimParams().jaw_speed  # the stepped engine's actions are recorded
    lagged = SimParams(jaw_lag=lag, clearance=SimParams().jaw_speed * lag / 2 + 0.001)
    one = simulate_policy_mujoco(pb, pol, 12, params=lagged, rng=7, method="stepped")
    lagged_acts = list(acts)
    leads = [lead for _, push, lead, _ in lagged_acts if not push]
    assert len(leads) >= 12 and set(leads) == {-1, 1}
    acts.clear()
    plain = simulate_policy_mujoco(
        pb, pol, 12, params=SimParams(clearance=lagged.clearance), rng=7, method="stepped"
    )
    assert {lead for _, _, lead, _ in acts} == {None}
    two = simulate_policy_mujoco(pb, pol, 12, params=lagged, rng=7, workers=2, method="stepped")
    np.testing.assert_array_equal(one.success, two.success)
    np.testing.assert_array_equal(one.cycle_costs, two.cycle_costs)
    np.testing.assert_allclose(one.reading_errors, two.reading_errors, rtol=0, atol=1e-9)

    s = squeeze_function(part.hull)
    g = push_grasp_function(part, s)

    def at_push_grasp(
        records: list[tuple[float, bool, int | None, float]], side: int
    ) -> list[bool]:
        """Per squeeze whose two predictions differ: did it end at the push-grasp's?"""
        out = []
        for theta, push, lead, end in records:
            if push:
                continue
            shift = math.pi if (lead or side) > 0 else 0.0
            sq = float(s(np.array([theta]))[0])
            pg = float(np.mod(g(np.array([theta - shift])) + shift, TWO_PI)[0])
            if circle_distance(sq, pg) > 1e-3:
                out.append(bool(circle_distance(end, pg) < math.radians(3.0)))
        return out

    pushed = at_push_grasp(lagged_acts, 0)
    assert len(pushed) >= 3 and sum(pushed) >= len(pushed) - 1, pushed
    for side in (-1, 1):
        assert not any(at_push_grasp(acts, side))
    assert plain.cycles == one.cycles == 12
    assert policy_simulation_json(one)["jaw_lag_s"] == lag
    assert "jaw_lag_s" not in policy_simulation_json(plain)


def test_cli_jaw_lag_reaches_the_policy_simulation(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``simulate --sense --engine mujoco --jaw-lag 2``: the lagged SimParams reach the run.

    As a plan's: the lag, and the clearance raised to the push (10 mm) + 1 mm; a lag that
    pushes a candidate more than twice its size is refused before any work (exit 2).
    """
    import bayesgrasp.sim.policy as sim_policy

    seen: list[object] = []

    def fake(problems: object, pol: object, n: int, **kw: object) -> object:
        seen.append(kw.get("params"))
        return simulate_policy(problems, pol, n, rng=0)  # type: ignore[arg-type]

    monkeypatch.setattr(sim_policy, "simulate_policy_mujoco", fake)
    args = ["simulate", "house", "--sense", "width", "--engine", "mujoco", "--trials", "20"]
    assert main([*args, "--jaw-lag", "2"]) == 0
    out = capsys.readouterr().out
    assert "jaw lag 2 s; " in out.splitlines()[0]
    (params,) = seen
    assert params.jaw_lag == 2.0 and params.lead_jaw == "random"  # type: ignore[attr-defined]
    assert params.clearance == pytest.approx(0.011)  # type: ignore[attr-defined]
    assert main(args) == 0 and seen[-1] is None
    assert "jaw lag" not in capsys.readouterr().out
    n = len(seen)
    assert main([*args, "--also", "triangle", "--jaw-lag", "100"]) == 2
    err = capsys.readouterr().err
    assert "more than twice its size" in err and len(err.strip().splitlines()) == 1
    assert len(seen) == n
    assert main([*args[:-4], "--trials", "20", "--jaw-lag", "1"]) == 2  # kinematic: no jaws
    assert "--engine mujoco only" in capsys.readouterr().err


@pytest.mark.physics
@pytest.mark.skipif(
    not HAVE_MUJOCO, reason="MuJoCo is not installed: pip install 'bayesgrasp[sim]'"
)
def test_batched_policy_cycles_equal_stepped_ones_whatever_the_threads() -> None:
    """Cycles grouped by policy node and batched in C threads follow the same branches."""
    from bayesgrasp.sim.policy import simulate_policy_mujoco

    part = shapes.load("house")
    pb = Problem.build(part)
    pol = plan_policy(pb, mujoco_sensor(part, 0.001), 3)
    a = simulate_policy_mujoco(pb, pol, 16, rng=9)
    b = simulate_policy_mujoco(pb, pol, 16, rng=9, workers=2)
    c = simulate_policy_mujoco(pb, pol, 16, rng=9, method="stepped")
    np.testing.assert_array_equal(a.success, b.success)
    np.testing.assert_array_equal(a.reading_errors, b.reading_errors)
    np.testing.assert_array_equal(a.success, c.success)
    np.testing.assert_array_equal(a.cycle_costs, c.cycle_costs)
    np.testing.assert_allclose(a.reading_errors, c.reading_errors, rtol=0, atol=0.02)
