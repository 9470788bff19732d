"""The Bayes-policy planner against an independent exhaustive AND-OR search and simulation.

The reference search shares nothing with the planner but the model's transfer functions and
action classes (``Problem.transfer``, ``Problem.transition``): its own reading bins and
likelihoods (``scipy.stats.norm``), its own joint classes for several parts, and no
parametric search: it enumerates the Pareto front of (cycle cost, success) of every policy by
an AND-OR recursion (OR over leaves and action classes, AND over reading bins) and takes the
least ratio at the root.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Sequence

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.stats import norm

from bayesgrasp import shapes
from bayesgrasp.errors import BayesGraspError, PlanningError
from bayesgrasp.geometry import Part
from bayesgrasp.io.policies import POLICY_SCHEMA, policy_document
from bayesgrasp.model import CostModel, Goal, Problem
from bayesgrasp.model.problem import nearest_state
from bayesgrasp.model.sensing import SensorError, WidthSensor
from bayesgrasp.planning import plan_exact
from bayesgrasp.planning.policy import (
    Declare,
    Policy,
    PolicyNode,
    Reject,
    joint_transition,
    plan_policy,
    policy_text,
)

TWO_PI = 2.0 * math.pi
TRIANGLE = [(0.0, 0.0), (3.0, 0.0), (1.0, 2.0)]
QUAD = [(0.0, 0.0), (4.0, 0.0), (3.6, 2.2), (0.5, 2.6)]
SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
RECT = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]


# -- the independent reference ------------------------------------------------------------


def ref_bins(widths: np.ndarray, sigma: float, res: float) -> np.ndarray:
    """Likelihood (N, B) of the reading bins of ``width:sigma,res``, computed afresh."""
    n = len(widths)
    if sigma == 0 and res == 0:
        keys = np.round(widths, 9)
    elif sigma == 0:
        keys = np.rint(widths / res)
    else:
        k0 = math.floor((widths.min() - 8 * sigma) / res + 0.5)
        k1 = math.ceil((widths.max() + 8 * sigma) / res - 0.5)
        edges = res * (np.arange(k0, k1 + 2) - 0.5)
        cdf = norm.cdf((edges[None, :] - widths[:, None]) / sigma)
        cdf[:, 0], cdf[:, -1] = 0.0, 1.0
        return np.diff(cdf, axis=1)
    _, inv = np.unique(keys, return_inverse=True)
    lik = np.zeros((n, int(inv.max()) + 1))
    lik[np.arange(n), inv.ravel()] = 1.0
    return lik


def ref_classes(problems: Sequence[Problem], kind: str) -> np.ndarray:
    """Joint transfer (A, N): each part's transfer at the middle of every common class.

    With a gripper accuracy, only the classes at least twice as wide as it (a turn at their
    middle keeps its effect under any error below the accuracy).
    """
    period = problems[0].action(kind).gripper_period
    crit = np.unique(np.concatenate([np.mod(p.transition(kind).lo, period) for p in problems]))
    crit = crit[np.append(True, np.diff(crit) > 1e-9)]
    ends = np.append(crit[1:], crit[0] + period)
    mids = 0.5 * (crit + ends)[0.5 * (ends - crit) >= problems[0].accuracy]
    cols, offset = [], 0
    for p in problems:
        f = p.transfer(kind)
        after = f(p.states.stable[None, :] - mids[:, None])  # (A, K)
        cols.append(nearest_state(p.states, after) + offset)
        offset += p.n_states
    return np.concatenate(cols, axis=1)


def pareto(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The concave upper chain of the undominated (cost, success) points.

    Every policy's figures lie in the convex hull of the chain's points and below it, and the
    least ratio ``(c + rho (1 - s)) / s`` of a set (a linear-fractional function) is reached
    at a vertex of its hull that minimises ``c - mu s`` for some ``mu >= 0``: a point of this
    chain. Minkowski sums keep that (the hull of a sum is the sum of the hulls).
    """
    chain: list[tuple[float, float]] = []
    for c, s in sorted(points, key=lambda x: (x[0], -x[1])):
        if chain and s <= chain[-1][1]:
            continue  # dominated
        while len(chain) >= 2:
            (c1, s1), (c2, s2) = chain[-2], chain[-1]
            # Drop the middle point when it lies on or below the segment from c1 to c.
            if (s2 - s1) * (c - c1) <= (s - s1) * (c2 - c1):
                chain.pop()
            else:
                break
        chain.append((c, s))
    return chain


def minkowski(
    a: list[tuple[float, float]], b: list[tuple[float, float]]
) -> list[tuple[float, float]]:
    """The chain of the sums of points of two chains."""
    return pareto([(c1 + c2, s1 + s2) for c1, s1 in a for c2, s2 in b])


def reference_cost(
    problems: Sequence[Problem],
    sigma: float,
    res: float,
    max_actions: int,
    part_prior: Sequence[float] | None = None,
) -> float:
    """Least E[cost] over all policies of at most ``max_actions`` actions, by AND-OR search."""
    cost = problems[0].cost
    kinds = problems[0].action_kinds
    w = (
        np.full(len(problems), 1.0 / len(problems))
        if part_prior is None
        else np.asarray(part_prior)
    )
    w = w / w.sum()
    widths = np.concatenate([p.widths for p in problems])
    lik = ref_bins(widths, sigma, res)
    n = len(widths)
    succ = np.zeros((n, n))
    offset = 0
    for p in problems:
        for i, s in enumerate(p.states.stable):
            succ[offset + i, offset : offset + p.n_states] = p.success_states(float(s))
        offset += p.n_states
    trans = {k: ref_classes(problems, k) for k in kinds}
    memo: dict[tuple[bytes, int], list[tuple[float, float]]] = {}

    def after_action(m: np.ndarray, r: int) -> list[tuple[float, float]]:
        front = [(0.0, 0.0)]
        for b in range(lik.shape[1]):
            mb = m * lik[:, b]
            if mb.sum() > 0:
                front = minkowski(front, node(mb, r))
        return front

    def node(m: np.ndarray, r: int) -> list[tuple[float, float]]:
        key = (np.round(m, 14).tobytes(), r)
        if key in memo:
            return memo[key]
        total = float(m.sum())
        options = [(0.0, 0.0)] + [(cost.verify * total, float(s)) for s in succ @ m]
        if r > 0:
            for k in kinds:
                for row in trans[k]:
                    img = np.bincount(row, weights=m, minlength=n)
                    c = cost.action_cost(k) * total
                    options += [(c + x, s) for x, s in after_action(img, r - 1)]
        memo[key] = pareto(options)
        return memo[key]

    best = math.inf
    for k in kinds:
        parts = zip(w, problems, strict=True)
        root = np.concatenate([wj * p.state_distribution(0.0, k) for wj, p in parts])
        for c, s in after_action(root, max_actions - 1):
            if s > 0:
                best = min(best, (cost.action_cost(k, first=True) + c + cost.retry * (1 - s)) / s)
    return best


# -- simulation ---------------------------------------------------------------------------


def simulate_cycles(
    policy: Policy, problems: Sequence[Problem], n: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run ``n`` cycles: (cost of each, success of each, actions of each)."""
    cost = problems[0].cost
    w = np.asarray(policy.part_prior)
    parts = rng.choice(len(problems), size=n, p=w)
    theta = rng.uniform(0.0, TWO_PI, size=n)
    sensor = policy.sensor
    costs = np.zeros(n)
    ok = np.zeros(n, dtype=bool)
    acts = np.zeros(n)
    for t in range(n):
        pb = problems[parts[t]]
        th = theta[t]
        node: PolicyNode | Declare | Reject = policy.root
        first = True
        while isinstance(node, PolicyNode):
            step = node.step
            th = float(pb.transfer(step.kind)(th - step.alpha))
            costs[t] += cost.action_cost(step.kind, first=first)
            acts[t] += 1
            first = False
            reading = float(sensor.read(pb.diameter(np.array([th])), rng)[0])
            node = node.branch(reading).next
        if isinstance(node, Declare):
            costs[t] += cost.verify
            if node.part == parts[t]:
                mask = pb.success_states(node.orientation)
                ok[t] = bool(mask[nearest_state(pb.states, np.array([th]))[0]])
        if not ok[t]:
            costs[t] += cost.retry
    return costs, ok, acts


def check_replay(policy: Policy, problems: Sequence[Problem], n: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    costs, ok, acts = simulate_cycles(policy, problems, n, rng)
    p = policy.success_probability
    sd = math.sqrt(p * (1 - p) / n)
    assert abs(ok.mean() - p) <= 4.5 * sd + 1e-12
    c_sd = costs.std() / math.sqrt(n)
    assert abs(costs.mean() - policy.cycle_cost) <= 4.5 * c_sd + 1e-12
    a_sd = acts.std() / math.sqrt(n)
    assert abs(acts.mean() - policy.expected_actions) <= 4.5 * a_sd + 1e-12
    # The whole process: the ratio estimator and its delta-method standard error.
    ratio = costs.mean() / ok.mean()
    cov = np.cov(costs, ok.astype(float))
    var = (cov[0, 0] - 2 * ratio * cov[0, 1] + ratio**2 * cov[1, 1]) / (n * ok.mean() ** 2)
    assert abs(ratio - policy.expected_cost) <= 4.5 * math.sqrt(var) + 1e-9


def check_claims(policy: Policy) -> None:
    """The tree's own figures add up, and every node's branches tile the readings."""
    total = 0.0
    succ = 0.0
    for w, leaf in policy.leaves():
        total += w
        if isinstance(leaf, Declare):
            succ += w * leaf.success_probability
    assert_allclose(total, 1.0, atol=1e-12)
    assert_allclose(succ, policy.success_probability, atol=1e-12)
    assert_allclose(
        policy.expected_cost, policy.cycle_cost / policy.success_probability, atol=1e-12
    )
    assert policy.depth <= policy.max_actions

    def tiles(node: PolicyNode) -> None:
        bs = node.branches
        assert bs[0].lo == -math.inf and bs[-1].hi == math.inf
        assert all(a.hi == b.lo for a, b in itertools.pairwise(bs))
        assert_allclose(sum(b.probability for b in bs), 1.0, atol=1e-12)
        for b in bs:
            if isinstance(b.next, PolicyNode):
                tiles(b.next)

    tiles(policy.root)


def build(points: Sequence[tuple[float, float]], **kw: object) -> Problem:
    return Problem.build(Part.from_points(points), **kw)  # type: ignore[arg-type]


# -- the planner equals the reference -----------------------------------------------------

SENSORS = [(0.0, 0.0), (0.0, 0.25), (0.15, 0.25)]
CASES = [
    ("triangle", [TRIANGLE], ("squeeze",), None),
    ("quad", [QUAD], ("squeeze",), None),
    ("quad-push", [QUAD], ("push-grasp",), None),
    ("quad-both", [QUAD], ("squeeze", "push-grasp"), None),
    ("two-parts", [TRIANGLE, RECT], ("squeeze",), (0.3, 0.7)),
]


@pytest.mark.parametrize(("sigma", "res"), SENSORS, ids=["exact", "quantised", "noisy"])
@pytest.mark.parametrize(("name", "parts", "actions", "prior"), CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize(("depth", "accuracy_deg"), [(1, 0.0), (2, 0.0), (2, 3.0), (2, 12.0)])
def test_planner_equals_and_or_search(
    name: str,
    parts: list[list[tuple[float, float]]],
    actions: tuple[str, ...],
    prior: tuple[float, ...] | None,
    sigma: float,
    res: float,
    depth: int,
    accuracy_deg: float,
) -> None:
    """Also with a gripper accuracy: the reference keeps only the classes it allows."""
    acc = math.radians(accuracy_deg)
    problems = [build(p, actions=actions, accuracy=acc) for p in parts]
    pol = plan_policy(problems, WidthSensor(sigma, res), depth, part_prior=prior)
    ref = reference_cost(problems, sigma, res, depth, prior)
    assert_allclose(pol.expected_cost, ref, rtol=0, atol=1e-9)
    check_claims(pol)
    assert all(m >= acc for m in margins(pol.root))


@pytest.mark.slow
@pytest.mark.parametrize(("sigma", "res"), SENSORS, ids=["exact", "quantised", "noisy"])
@pytest.mark.parametrize(("name", "parts", "actions", "prior"), CASES, ids=[c[0] for c in CASES])
def test_planner_equals_and_or_search_depth_3(
    name: str,
    parts: list[list[tuple[float, float]]],
    actions: tuple[str, ...],
    prior: tuple[float, ...] | None,
    sigma: float,
    res: float,
) -> None:
    problems = [build(p, actions=actions) for p in parts]
    pol = plan_policy(problems, WidthSensor(sigma, res), 3, part_prior=prior)
    ref = reference_cost(problems, sigma, res, 3, prior)
    assert_allclose(pol.expected_cost, ref, rtol=0, atol=1e-9)
    check_claims(pol)


COSTS = [
    CostModel(verify=4.0),  # costly verification: rejecting can pay
    CostModel({"squeeze": 0.5}, verify=1.0, first={"squeeze": 3.0}, retry=0.7),
    CostModel({"squeeze": 2.0}, verify=0.2),
]


@pytest.mark.parametrize("cost", COSTS, ids=["verify", "first-retry", "cheap-verify"])
@pytest.mark.parametrize(("sigma", "res"), SENSORS[1:], ids=["quantised", "noisy"])
def test_planner_equals_reference_under_other_costs(
    cost: CostModel, sigma: float, res: float
) -> None:
    problems = [build(QUAD, cost=cost)]
    pol = plan_policy(problems, WidthSensor(sigma, res), 2)
    assert_allclose(pol.expected_cost, reference_cost(problems, sigma, res, 2), atol=1e-9)
    check_claims(pol)


def test_symmetry_goal_equals_reference() -> None:
    problems = [build(RECT, goal=Goal("symmetry"))]
    pol = plan_policy(problems, WidthSensor(0.2, 0.1), 2)
    assert_allclose(pol.expected_cost, reference_cost(problems, 0.2, 0.1, 2), atol=1e-9)
    # A 2-fold symmetric part with the goal counting both: exact readings orient it surely.
    exact = plan_policy(problems, "width", 1)
    assert_allclose(exact.success_probability, 1.0, atol=1e-12)


def test_rejecting_leaves_appear_when_verification_is_dear() -> None:
    pb = build(QUAD, cost=CostModel(verify=4.0))
    pol = plan_policy(pb, WidthSensor(0.3, 0.1), 2)
    assert pol.reject_probability > 0
    assert any(isinstance(leaf, Reject) for _, leaf in pol.leaves())
    check_claims(pol)


# -- replay by simulation -----------------------------------------------------------------

REPLAYS = [
    ("quad-noisy", [QUAD], ("squeeze",), WidthSensor(0.15, 0.1), 3, None, CostModel()),
    (
        "quad-both-quantised",
        [QUAD],
        ("squeeze", "push-grasp"),
        WidthSensor(0.0, 0.25),
        2,
        None,
        CostModel(),
    ),
    (
        "two-parts-noisy",
        [TRIANGLE, RECT],
        ("squeeze",),
        WidthSensor(0.1, 0.05),
        2,
        (0.4, 0.6),
        CostModel(verify=2.0, retry=0.5),
    ),
    ("reject", [QUAD], ("squeeze",), WidthSensor(0.3, 0.1), 2, None, CostModel(verify=4.0)),
]


@pytest.mark.parametrize(
    ("name", "parts", "actions", "sensor", "depth", "prior", "cost"),
    REPLAYS,
    ids=[r[0] for r in REPLAYS],
)
def test_replay_reaches_claims(
    name: str,
    parts: list[list[tuple[float, float]]],
    actions: tuple[str, ...],
    sensor: WidthSensor,
    depth: int,
    prior: tuple[float, ...] | None,
    cost: CostModel,
) -> None:
    problems = [build(p, actions=actions, cost=cost) for p in parts]
    pol = plan_policy(problems, sensor, depth, part_prior=prior)
    check_replay(pol, problems, 4000, seed=7)


@pytest.mark.slow
def test_replay_catalogue_recognition() -> None:
    problems = [Problem.build(shapes.load(n)) for n in ("rectangle", "tuning-fork", "ic-chip")]
    pol = plan_policy(problems, WidthSensor(0.5, 0.1), 3)
    check_replay(pol, problems, 20000, seed=11)


# -- limits -------------------------------------------------------------------------------


def test_no_information_gives_the_sensorless_bayes_plan() -> None:
    pb = build(QUAD)
    rep = plan_exact(pb)
    k = len(rep.options)
    d = float(pb.diameter.lengths.max())
    pol = plan_policy(pb, WidthSensor(1e6 * d, 1e6 * d), k)
    assert_allclose(pol.expected_cost, rep.bayes_plan.expected_cost, rtol=1e-6)
    assert pol.sensorless_cost == pytest.approx(rep.bayes_plan.expected_cost, abs=1e-12)


@pytest.mark.parametrize("name", ["triangle", "example", "allen-wrench", "key", "hand"])
@pytest.mark.parametrize("verify", [1.0, 2.5])
def test_exact_readings_of_distinct_widths_cost_one_squeeze(name: str, verify: float) -> None:
    pb = Problem.build(shapes.load(name), cost=CostModel(verify=verify))
    w = np.round(pb.widths, 6)
    k = pb.n_states
    assert len(set(w[: k // 2])) == k // 2  # distinct apart from the pi pairs
    pol = plan_policy(pb, "width", 4)
    assert_allclose(pol.expected_cost, (1 + verify) / 0.5, atol=1e-12)
    assert pol.depth == 1
    assert_allclose(pol.success_probability, 0.5, atol=1e-12)


def test_equal_widths_give_no_information() -> None:
    # A square: every stable orientation reads the same width; sensing cannot help.
    pb = build(SQUARE)
    rep = plan_exact(pb, max_actions=3)
    pol = plan_policy(pb, "width", 3)
    assert_allclose(pol.expected_cost, rep.bayes_plan.expected_cost, atol=1e-12)


def test_symmetric_part_with_two_widths() -> None:
    # The 2:1 rectangle (2-fold symmetric): the reading tells its two widths apart, only
    # the half turn remains.
    pol = plan_policy(build(RECT), "width", 3)
    assert_allclose(pol.expected_cost, 4.0, atol=1e-12)
    assert_allclose(pol.expected_entropy[0], 1.0, atol=1e-12)


@pytest.mark.parametrize("sensor", ["width", "width:0.1,0.05"])
def test_two_identical_parts_cannot_be_told_apart(sensor: str) -> None:
    one = plan_policy(build(QUAD), sensor, 2)
    a = Problem.build(Part.from_points(QUAD, name="a"))
    b = Problem.build(Part.from_points(QUAD, name="b"))
    two = plan_policy([a, b], sensor, 2)
    assert_allclose(two.success_probability, one.success_probability / 2, atol=1e-9)
    assert_allclose(two.expected_cost, 2 * one.expected_cost, atol=1e-9)
    skew = plan_policy([a, b], sensor, 2, part_prior=(1, 3))
    assert_allclose(skew.expected_cost, one.expected_cost / 0.75, atol=1e-9)


def test_recognition_of_catalogue_parts_sharing_widths() -> None:
    # Rectangle (31, 20) and tuning fork (20, 43.5) share the width 20.
    names = ("rectangle", "tuning-fork", "ic-chip")
    problems = [Problem.build(shapes.load(n)) for n in names]
    pol = plan_policy(problems, "width", 3)
    check_claims(pol)
    assert pol.parts == names
    assert 0 < pol.success_probability <= 0.5 + 1e-12
    declared = {leaf.part_name for _, leaf in pol.leaves() if isinstance(leaf, Declare)}
    assert declared == set(names)


def test_more_actions_never_cost_more() -> None:
    pb = build(QUAD)
    costs = [plan_policy(pb, "width:0.2,0.1", k).expected_cost for k in (1, 2, 3)]
    assert costs[0] >= costs[1] - 1e-12 >= costs[2] - 2e-12
    assert costs[2] <= plan_exact(pb, max_actions=3).bayes_plan.expected_cost + 1e-12


def test_entropy_falls_with_readings() -> None:
    pol = plan_policy(build(QUAD), "width:0.15,0.1", 3)
    ent = pol.expected_entropy
    assert len(ent) == pol.depth
    assert all(a >= b - 1e-12 for a, b in itertools.pairwise(ent))
    assert ent[-1] >= 1.0 - 1e-12  # the half turn is never resolved by squeezes


def test_non_uniform_prior_first_angle() -> None:
    from bayesgrasp.model import HistogramPrior

    prior = HistogramPrior([4.0, 1.0, 1.0, 2.0, 1.0, 1.0])
    pb = build(QUAD, prior=prior)
    pol = plan_policy(pb, "width:0.2,0.1", 2)
    assert pol.first_angle_exact
    # Any single first angle does no better than the search over all candidates.
    for a in np.linspace(0, TWO_PI, 13):
        assert (
            pol.expected_cost
            <= plan_policy(pb, "width:0.2,0.1", 2, first_angles=[a]).expected_cost + 1e-12
        )
    assert pol.expected_cost <= plan_exact(pb, max_actions=2).bayes_plan.expected_cost + 1e-12


# -- the joint classes, documents, text, errors -------------------------------------------


def test_joint_transition_refines_every_part() -> None:
    problems = [build(TRIANGLE), build(QUAD)]
    from bayesgrasp.model.sensing import StateSpace

    cl = joint_transition(StateSpace.build(problems), "squeeze")
    ref = ref_classes(problems, "squeeze")
    assert_allclose(cl.transfer, ref)


def test_policy_document_is_json() -> None:
    pol = plan_policy([build(TRIANGLE), build(RECT)], "width:0.1,0.05", 2)
    doc = json.loads(json.dumps(policy_document(pol), allow_nan=False))
    assert doc["schema"] == POLICY_SCHEMA == "bayesgrasp.policy/1"
    assert doc["sensor"] == {"kind": "width", "sigma": 0.1, "resolution": 0.05}
    assert doc["max_actions"] == 2
    assert_allclose(doc["expected_cost"], pol.expected_cost, atol=0)
    root = doc["root"]
    assert root["action"]["type"] == "squeeze"
    assert root["branches"][0]["reading"][0] is None
    assert root["branches"][-1]["reading"][1] is None
    assert_allclose(sum(b["probability"] for b in root["branches"]), 1.0, atol=1e-12)

    def leaves(node: dict) -> list[dict]:
        out = []
        for b in node["branches"]:
            nxt = b["next"]
            out += leaves(nxt) if "action" in nxt else [nxt]
        return out

    for leaf in leaves(root):
        assert leaf.get("reject") is True or {"orientation_rad", "part"} <= set(leaf["declare"])


def test_policy_text_reads_like_instructions() -> None:
    pb = Problem.build(shapes.load("rectangle"))
    text = policy_text(plan_policy(pb, "width", 2))
    assert text.splitlines()[0] == "squeeze with the gripper at 0.00 deg"
    assert "if the width reads below 25.50 mm" in text
    assert "declare" in text


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"max_actions": 0}, "max_actions"),
        ({"part_prior": "1,2"}, "one weight per part"),
        ({"sensor": "width:1"}, "width:SIGMA,RES"),
        ({"sensor": "width:-1,1"}, "sigma"),
        ({"sensor": "width:1,0"}, "needs a resolution"),
        ({"first_angles": []}, "first_angles"),
    ],
)
def test_bad_input_is_a_clear_error(kwargs: dict, match: str) -> None:
    with pytest.raises(BayesGraspError, match=match):
        plan_policy(build(QUAD), **{"sensor": "width", **kwargs})


def test_candidate_parts_must_share_the_accuracy() -> None:
    with pytest.raises(PlanningError, match="same gripper `accuracy`"):
        plan_policy([build(QUAD, accuracy=0.01), build(TRIANGLE)], "width")


def margins(node: PolicyNode) -> list[float]:
    """The margins of every node below the root (the root's first angle is not bounded)."""
    out: list[float] = []
    for b in node.branches:
        if isinstance(b.next, PolicyNode):
            out += [b.next.margin, *margins(b.next)]
    return out


def test_accuracy_restricts_the_search() -> None:
    """Not vacuous: on these parts an accuracy removes turns the exact policy would make."""
    exact, changed = 0, 0
    for _, parts, actions, prior in CASES:
        for sigma, res in SENSORS:
            costs = [
                plan_policy(
                    [build(p, actions=actions, accuracy=math.radians(a)) for p in parts],
                    WidthSensor(sigma, res),
                    2,
                    part_prior=prior,
                ).expected_cost
                for a in (0.0, 12.0)
            ]
            assert costs[1] >= costs[0] - 1e-12  # a restriction never helps
            exact += 1
            changed += costs[1] > costs[0] + 1e-9
    assert changed >= 3, (changed, exact)


def test_sensor_error_is_a_value_error() -> None:
    with pytest.raises(SensorError, match="width"):
        plan_policy(build(QUAD), "depth")
