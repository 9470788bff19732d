"""The seed's breadth-first planner: agreement with the exact planner, and its own checks."""

from __future__ import annotations

import itertools
import json
import math
import tracemalloc
from collections import deque
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.errors import PartError, PlanningError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.transfer import transfer_from_extrema
from bayesgrasp.model.actions import PUSH_GRASP, SQUEEZE
from bayesgrasp.model.prior import HistogramPrior, Prior, UniformPrior, von_mises
from bayesgrasp.model.problem import CostModel, Goal, Problem
from bayesgrasp.planning import PlanReport, bfs, execute_plan, hyperstates, plan_bfs, plan_exact
from bayesgrasp.planning.bfs import BfsResult, search_bfs
from bayesgrasp.planning.hyperstates import HyperstateSearch, make_roots
from bayesgrasp.planning.result import PlanStep
from bayesgrasp.shapes import load, names

TWO_PI = 2.0 * math.pi
RECTANGLE = [(0, 0), (1.55, 0), (1.55, 1), (0, 1)]


def regular_polygon(n: int, phase: float) -> np.ndarray:
    a = phase + TWO_PI * np.arange(n) / n
    return np.column_stack([np.cos(a), np.sin(a)])


def random_parts(rng: np.random.Generator, count: int) -> list[Part]:
    """The seed's random polygons: hulls of 10 uniform points in the unit square."""
    return [Part.from_points(rng.uniform(size=(10, 2))) for _ in range(count)]


def symmetric_parts(rng: np.random.Generator, count: int) -> list[Part]:
    """Random centrally symmetric hexagons (symmetry order 2) and regular polygons."""
    out = []
    for _ in range(count):
        ang = np.sort(rng.uniform(0, math.pi, size=3))
        rad = rng.uniform(0.5, 1.5, size=3)
        half = np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])
        out.append(Part.from_points(np.vstack([half, -half])))
    out += [Part.from_points(regular_polygon(n, phase=0.1 * n)) for n in (3, 4, 5, 6, 7)]
    return out


def probabilities(rep: PlanReport) -> list[float]:
    return [o.success_probability for o in rep.options]


def assert_agree(problem: Problem) -> bool:
    """Exact and breadth-first plans have the same probabilities (and costs) for every k."""
    res = search_bfs(problem)
    if not res.stats.completed:
        return False
    exact = plan_exact(problem)
    n = len(res.report.options)
    # The search stops at the most certain depth (the seed's rule). With action types of
    # different costs the exact planner may add one longer, cheaper plan after that depth,
    # which then is its Bayes plan; the per-depth rows must agree all the same.
    assert len(exact.options) in (n, n + 1)
    head = exact.options[:n]
    assert_allclose(probabilities(res.report), [o.success_probability for o in head], atol=1e-9)
    assert_allclose(
        [o.expected_cost for o in res.report.options],
        [o.expected_cost for o in head],
        rtol=1e-9,
    )
    assert res.report.most_certain == exact.most_certain
    if len(exact.options) == n:
        assert res.report.bayes == exact.bayes
    else:
        assert len(problem.action_kinds) > 1
        assert exact.bayes == n
        assert exact.bayes_plan.expected_cost < res.report.bayes_plan.expected_cost
    return True


def test_agrees_with_exact_on_random_polygons(rng: np.random.Generator) -> None:
    done = sum(assert_agree(Problem.build(p)) for p in random_parts(rng, 200))
    assert done >= 190  # the seed: about 1% pass the node limit


@pytest.mark.parametrize("name", names())
def test_agrees_with_exact_on_catalogue(name: str) -> None:
    assert assert_agree(Problem.build(load(name)))


@pytest.mark.parametrize("goal", ["single", "symmetry"])
def test_agrees_with_exact_on_symmetric_parts(rng: np.random.Generator, goal: str) -> None:
    parts = symmetric_parts(rng, 25)
    done = sum(assert_agree(Problem.build(p, goal=Goal(goal))) for p in parts)  # type: ignore[arg-type]
    assert done >= len(parts) - 1


def test_symmetry_goal_orients_square_with_certainty() -> None:
    square = Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)])
    assert probabilities(plan_bfs(Problem.build(square))) == [0.25]
    assert probabilities(plan_bfs(Problem.build(square, goal=Goal("symmetry")))) == [1.0]


@pytest.mark.parametrize(
    "prior", [von_mises(1.0, 4.0), HistogramPrior([5, 1, 3, 1, 0.5, 2, 1])], ids=["vm", "hist"]
)
def test_agrees_with_exact_under_peaked_prior_and_costs(
    rng: np.random.Generator, prior: Prior
) -> None:
    cost = CostModel(retry=0.5, first={"squeeze": 2.5})
    parts = random_parts(rng, 30)
    done = sum(assert_agree(Problem.build(p, prior=prior, cost=cost)) for p in parts)
    assert done >= 25  # several roots (first angles) share the node limit


def test_first_angle_grid_never_beats_exact(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 10):
        pb = Problem.build(part, prior=von_mises(2.0, 6.0))
        grid = np.linspace(0, TWO_PI, 24, endpoint=False)
        res = search_bfs(pb, first_angles=grid)
        exact = plan_exact(pb)
        n = min(len(res.report.options), len(exact.options))
        assert np.all(
            np.array(probabilities(res.report))[:n] <= np.array(probabilities(exact))[:n] + 1e-9
        )


def fake_push_grasp(problem: Problem, offset: int) -> Problem:
    """A second action kind (period 2 pi) that merges the basins of states in pairs."""
    s = problem.states
    i = (np.arange(0, s.n_states, 2) + offset) % s.n_states
    pg = transfer_from_extrema("push-grasp", s.stable[i], s.basin_lo[i], s.angle_tol, 1e-9)
    return Problem(
        problem.part,
        s,
        problem.diameter,
        problem.prior,
        (SQUEEZE, PUSH_GRASP),
        {"squeeze": s, "push-grasp": pg},
        problem.cost,
        problem.goal,
    )


@pytest.mark.parametrize("pg_cost", [0.4, 1.0, 2.5])
def test_agrees_with_exact_with_two_action_kinds(rng: np.random.Generator, pg_cost: float) -> None:
    done = eligible = 0
    for j, part in enumerate(random_parts(rng, 30)):
        pb = Problem.build(part, cost=CostModel({"push-grasp": pg_cost}))
        if pb.n_states < 6:
            continue
        eligible += 1
        done += assert_agree(fake_push_grasp(pb, j % 2))
    # Two kinds double the branching: more searches pass the node limit.
    assert eligible >= 15 and done >= 0.6 * eligible


def replay_probability(problem: Problem, steps: tuple[PlanStep, ...], final: float) -> float:
    """Mass of initial orientations that end at ``final`` (or a symmetric copy)."""
    f = problem.transfers[steps[0].kind]
    first = steps[0].alpha
    # Every orientation of a basin of the first action does the same: test its middle.
    mid = 0.5 * (f.basin_lo + f.basin_hi) + first
    mass = np.asarray(problem.prior.mass(f.basin_lo + first, f.basin_hi + first))
    out = execute_plan(problem, steps, mid)
    g = problem.goal_group
    period = TWO_PI / g
    d = np.abs(np.mod(out - final + period / 2, period) - period / 2)
    return float(mass[d < 1e-7].sum())


def test_plans_replay_to_their_probability_within_tolerance(rng: np.random.Generator) -> None:
    parts = random_parts(rng, 30) + symmetric_parts(rng, 5)
    checked = 0
    for j, part in enumerate(parts):
        prior = UniformPrior() if j % 2 else von_mises(0.3 * j, 3.0)
        goal = Goal("symmetry" if j % 3 == 0 else "single")
        pb = Problem.build(part, prior=prior, goal=goal)
        for opt in plan_bfs(pb).options:
            p = replay_probability(pb, opt.steps, opt.final_orientation)
            assert_allclose(p, opt.success_probability, atol=1e-9)
            lo, hi = opt.success_arc
            inside = np.linspace(lo, hi, 50)[1:-1]
            mass = float(np.asarray(prior.mass(lo, hi)))
            assert mass <= opt.success_probability + 1e-9
            ends = execute_plan(pb, opt.steps, inside)
            period = TWO_PI / pb.goal_group
            dist = np.abs(np.mod(ends - opt.final_orientation + period / 2, period) - period / 2)
            assert np.all(dist < 1e-7)
            if opt.tolerance is None:
                continue
            for sign in (-1.0, 1.0):  # every relative rotation off by 0.95 of the margin
                off = sign * 0.95 * opt.tolerance
                moved = (opt.steps[0], *(PlanStep(s.kind, s.alpha + off) for s in opt.steps[1:]))
                p_moved = replay_probability(pb, moved, opt.final_orientation)
                assert_allclose(p_moved, opt.success_probability, atol=1e-9)
            checked += 1
    assert checked > 20


def brute_force_best(problem: Problem, depth: int) -> list[float]:
    """Best probability of every plan length up to ``depth``, over all class sequences."""
    cl = problem.classes("squeeze")
    alphas = [float(a) for a in cl.mid]
    best = []
    for k in range(1, depth + 1):
        top = 0.0
        for seq in itertools.product(alphas, repeat=k - 1):
            steps = (PlanStep("squeeze", 0.0), *(PlanStep("squeeze", a) for a in seq))
            f = problem.states
            mid = 0.5 * (f.basin_lo + f.basin_hi)
            out = np.round(np.mod(execute_plan(problem, steps, mid), TWO_PI), 7) % round(TWO_PI, 7)
            masses = np.asarray(problem.prior.mass(f.basin_lo, f.basin_hi))
            totals: dict[float, float] = {}
            for o, m in zip(out.tolist(), masses.tolist(), strict=True):
                totals[o] = totals.get(o, 0.0) + m
            top = max(top, max(totals.values()))
        best.append(top)
    return best


def test_brute_force_over_action_sequences(rng: np.random.Generator) -> None:
    """Small parts: every sequence of class midpoints, replayed, against the search."""
    checked = 0
    for n in (3, 4, 5):
        for _ in range(6):
            part = Part.from_points(rng.uniform(size=(n, 2)))
            pb = Problem.build(part)
            if len(pb.classes("squeeze").mid) > 16:
                continue
            rep = plan_bfs(pb, max_actions=3)
            want = brute_force_best(pb, len(rep.options))
            assert_allclose(probabilities(rep), want, atol=1e-9)
            checked += 1
    assert checked >= 10


def naive_tree_count(problem: Problem, target: float) -> int:
    """A literal breadth-first search that merges nothing: nodes until the first goal."""
    cl = problem.classes("squeeze")
    root = problem.state_distribution(0.0)
    count = 1
    if root.max() >= target - 1e-12:
        return count
    queue = deque([root])
    while queue:
        p = queue.popleft()
        for row in cl.transfer:
            child = np.bincount(row, weights=p, minlength=problem.n_states)
            count += 1
            if child.max() >= target - 1e-12:
                return count
            queue.append(child)
    raise AssertionError("unreachable")


def test_tree_count_matches_literal_unmerged_search(rng: np.random.Generator) -> None:
    checked = 0
    for part in random_parts(rng, 40):
        pb = Problem.build(part)
        res = search_bfs(pb)
        tree = res.stats.tree_nodes
        if tree is None or tree > 3000:
            continue
        assert tree == naive_tree_count(pb, res.stats.target)
        assert tree >= res.stats.nodes
        unmerged = search_bfs(pb, merge=False, node_limit=10_000)
        assert unmerged.stats.nodes == tree
        assert_allclose(probabilities(unmerged.report), probabilities(res.report), atol=1e-9)
        checked += 1
    assert checked >= 30


def test_node_limit_runs_best_first_fallback(rng: np.random.Generator) -> None:
    fell_back = 0
    for part in random_parts(rng, 30):
        pb = Problem.build(part)
        exact = plan_exact(pb)
        res = search_bfs(pb, node_limit=3)
        if res.stats.completed:
            continue
        fell_back += 1
        assert res.stats.bfs_nodes == 3
        assert res.stats.fallback_nodes > 0
        assert res.stats.nodes == res.stats.bfs_nodes + res.stats.fallback_nodes
        assert res.report.nodes == res.stats.nodes
        assert res.stats.tree_nodes is None
        assert res.stats.reached
        # The fallback reaches the best probability, maybe with a longer plan.
        assert_allclose(
            res.report.most_certain_plan.success_probability,
            exact.most_certain_plan.success_probability,
            atol=1e-9,
        )
        assert len(res.report.options) >= len(exact.options)
        found = probabilities(res.report)
        want = probabilities(exact) + [probabilities(exact)[-1]] * len(found)
        assert np.all(np.array(found) <= np.array(want[: len(found)]) + 1e-9)
    assert fell_back >= 10


def test_max_actions_stops_the_search(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 20):
        pb = Problem.build(part)
        rep = plan_bfs(pb, max_actions=2)
        exact = plan_exact(pb, max_actions=2)
        assert len(rep.options) == len(exact.options) <= 2
        assert_allclose(probabilities(rep), probabilities(exact), atol=1e-9)


def test_report_fields() -> None:
    pb = Problem.build(Part.from_points(RECTANGLE))
    rep = plan_bfs(pb)
    assert rep.method == "bfs"
    assert rep.nodes == 2
    assert [round(o.expected_cost, 1) for o in rep.options] == [6.3, 6.0]
    assert rep.options[0].tolerance is None
    assert rep.options[1].tolerance is not None and rep.options[1].tolerance > 0
    assert all(-math.pi / 2 < s.alpha <= math.pi / 2 for o in rep.options for s in o.steps)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"max_actions": 0}, "`max_actions` must be an integer >= 1; got 0"),
        ({"node_limit": 0}, "`node_limit` and `fallback_limit` must be at least 1"),
        ({"first_angles": []}, "`first_angles` must be a non-empty list"),
        ({"first_angles": [math.nan]}, "`first_angles` must be a non-empty list"),
    ],
)
def test_bad_arguments(kwargs: dict[str, object], match: str) -> None:
    pb = Problem.build(Part.from_points(RECTANGLE))
    with pytest.raises(PlanningError, match=match):
        search_bfs(pb, **kwargs)  # type: ignore[arg-type]


@settings(max_examples=40)
@given(
    pts=hnp.arrays(
        np.float64, (7, 2), elements=st.floats(0, 1, allow_nan=False, allow_subnormal=False)
    ),
    beta=st.floats(-math.pi, math.pi),
)
def test_property_agreement_and_rotation_invariance(pts: np.ndarray, beta: float) -> None:
    """Exact and breadth-first agree; turning the part changes no probability."""
    assume(len(np.unique(np.round(pts, 3), axis=0)) >= 3)
    try:
        part = Part.from_points(pts)
    except PartError:
        assume(False)
        return
    assume(part.hull.area > 1e-3)
    c, s = math.cos(beta), math.sin(beta)
    turned = Part.from_points(pts @ np.array([[c, s], [-s, c]]))
    a, b = search_bfs(Problem.build(part)), search_bfs(Problem.build(turned))
    if a.stats.completed and b.stats.completed:
        assert_allclose(probabilities(a.report), probabilities(b.report), atol=1e-7)
        assert_allclose(
            probabilities(a.report), probabilities(plan_exact(a.report.problem)), atol=1e-9
        )
    for opt in a.report.options:
        assert 0.0 < opt.success_probability <= 0.5 + 1e-12


def test_cli_plan_with_bfs(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", "rectangle", "--method", "bfs", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["method"] == "bfs" and doc["nodes"] == 2
    assert [round(o["expected_cost"], 1) for o in doc["options"]] == [6.3, 6.0]
    assert main(["plan", "triangle", "--method", "bfs", "--max-squeezes", "2"]) == 0
    assert "breadth-first nodes generated" in capsys.readouterr().out


def circle_part(n: int) -> Part:
    """``n`` random points on the unit circle: a part of about ``n`` states (K ~ 0.9 n)."""
    t = np.sort(np.random.default_rng(5).uniform(0, TWO_PI, n))
    return Part.from_points(np.column_stack([np.cos(t), np.sin(t)]))


def fingerprint(res: BfsResult) -> tuple[object, ...]:
    """Every number of a search's result: its statistics and each option's floats."""
    rep = res.report
    options = tuple(
        (
            tuple((st.kind, st.alpha) for st in o.steps),
            o.final_orientation,
            o.success_probability,
            o.expected_cost,
            o.tolerance,
            o.success_arc,
        )
        for o in rep.options
    )
    return res.stats, options, rep.bayes, rep.most_certain, rep.nodes


# Recorded from the search before it made children a block at a time (d0eb3ad): the
# statistics, the success probabilities and each plan's gripper angles, to the last bit.
CIRCLES = {
    20: (
        (1386, 1000, 386, False, True, 8, 0.5000000000000001, None),
        [
            0.09901386447742311,
            0.18881623964373895,
            0.26510177444446725,
            0.33349958172483596,
            0.37277502929198003,
            0.4242664952699051,
            0.4242664952699051,
            0.49999999999999994,
        ],
        [-0.2574890478137162, 0.14710629909225892, *[-0.2574890478137162] * 5],
    ),
    40: (
        (2000, 1000, 1000, False, False, 5, 0.5000000000000002, None),
        [
            0.09250443262138208,
            0.14469830435598918,
            0.16149259100972024,
            0.18388299353140175,
            0.25237155920350196,
        ],
        [-0.7371111302263484, 0.7167749419465812, -1.2431654178388754, 0.7167749419465812],
    ),
    65: (
        (2000, 1000, 1000, False, False, 3, 0.5000000000000006, None),
        [0.0655335745633221, 0.10709342945312228, 0.12791525191089165],
        [0.14727327821721548, 0.14727327821721548],
    ),
    130: (
        (2000, 1000, 1000, False, False, 2, 0.5000000000000001, None),
        [0.03994637045133925, 0.06423056401754668],
        [0.12091505632872834],
    ),
}


@pytest.mark.parametrize("n", sorted(CIRCLES))
def test_results_on_circles_as_recorded(n: int) -> None:
    stats, probs, alphas = CIRCLES[n]
    res = search_bfs(Problem.build(circle_part(n)))
    assert tuple(getattr(res.stats, f) for f in res.stats.__slots__) == stats
    assert probabilities(res.report) == probs
    assert [st.alpha for st in res.report.options[-1].steps] == [0.0, *alphas]


def block_cases(rng: np.random.Generator) -> list[tuple[Problem, dict[str, object]]]:
    """Searches that take every path: fallback, padding, two kinds, roots, the tree count."""
    parts = random_parts(rng, 6)
    cases: list[tuple[Problem, dict[str, object]]] = []
    for j, part in enumerate(parts):
        pb = Problem.build(part)
        cases += [(pb, {}), (pb, {"node_limit": 5, "fallback_limit": 40})]
        cases.append((pb, {"merge": False, "node_limit": 200, "max_actions": 3}))
        cases.append((Problem.build(part, goal=Goal("symmetry")), {}))
        cases.append((Problem.build(part, prior=von_mises(0.5 * j, 3.0)), {}))
        push = Problem.build(part, actions=("push-grasp",))  # padded with push-grasps
        cases += [(push, {}), (push, {"node_limit": 5, "fallback_limit": 60})]
        if pb.n_states >= 6:
            two = fake_push_grasp(Problem.build(part, cost=CostModel({"push-grasp": 0.7})), j % 2)
            cases.append((two, {}))
    cases += [(Problem.build(p), {}) for p in symmetric_parts(rng, 3)]
    # Plans padded with push-grasps of the most certain class (found by seed).
    padded = random_parts(np.random.default_rng(1), 11)
    for part in (padded[1], padded[10]):
        push = Problem.build(part, actions=("push-grasp",))
        cases += [(push, {}), (push, {"node_limit": 2, "fallback_limit": 200})]
    return cases


@pytest.mark.parametrize("block", [1, 97])
def test_children_blocks_change_no_result(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch, block: int
) -> None:
    """Children made a row at a time, or 97 entries at a time, give the same bits."""
    cases = block_cases(rng)
    whole = [fingerprint(search_bfs(pb, **kw)) for pb, kw in cases]  # type: ignore[arg-type]
    assert any(len(pb.classes("squeeze").mid) * pb.n_states > block for pb, _ in cases)
    monkeypatch.setattr(hyperstates, "_BLOCK", block)
    for (pb, kw), want in zip(cases, whole, strict=True):
        assert fingerprint(search_bfs(pb, **kw)) == want  # type: ignore[arg-type]


@pytest.mark.parametrize("block", [1, 29])
def test_padding_class_is_the_first_most_certain(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch, block: int
) -> None:
    """Padding with push-grasps (not the squeeze): the first class of the highest success."""
    monkeypatch.setattr(hyperstates, "_BLOCK", block)
    checked = 0
    for part in random_parts(rng, 10):
        pb = Problem.build(part, actions=("push-grasp",))
        s = HyperstateSearch(pb, make_roots(pb, None, None))
        for dist in (s.dist[s.add_root(0)], rng.dirichlet(np.ones(s.k))):
            probs = np.concatenate([s.goal_prob(ch) for _, ch in s.blocks(dist, 0)])
            assert bfs._pad_class(s, 0, dist) == int(np.argmax(probs))
            checked += int(np.argmax(probs) >= s.rows)  # not in the first block
    assert checked >= 5


def test_memory_of_a_part_with_174_states() -> None:
    """The class table is made a block at a time; the search keeps O(K) a node.

    Before, the table took an (A, K, K) array (A = 7569 classes: 1.8 GB) and the search
    several (A, K) arrays at once.
    """
    pb = Problem.build(circle_part(200))
    k = pb.n_states
    assert k == 174
    tracemalloc.start()
    try:
        table = pb.classes("squeeze").transfer
        build_peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.reset_peak()
        before = tracemalloc.get_traced_memory()[0]
        res = search_bfs(pb)
        search_peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    assert table.shape == (7569, k)
    assert build_peak < table.nbytes + 8e6  # 16.5 MB, the table 10.5 MB
    assert res.stats.nodes == 2000
    assert search_peak < 6 * res.stats.nodes * k * 8 + 4e6  # 12 MB of 20.7 MB


def test_table_limit() -> None:
    pb = Problem.build(circle_part(40))
    k = pb.n_states
    entries = len(pb.classes("squeeze").mid) * k
    assert search_bfs(pb, table_limit=entries).stats.nodes == 2000
    with pytest.raises(PlanningError, match=rf"tables need {entries} entries .*use the exact"):
        search_bfs(pb, table_limit=entries - 1)
    with pytest.raises(PlanningError, match=rf"{k * k} critical angles, more than `table_limit`"):
        search_bfs(pb, table_limit=k * k - 1)


def test_cli_bfs_on_a_part_too_large_says_so(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A 700-point circle (K = 724) would need 724 MiB of tables: one error line, no kill."""
    batch = tmp_path / "parts.jsonl"
    big = {"name": "circle-700", "vertices": circle_part(700).hull.vertices.tolist()}
    batch.write_text(f'{json.dumps(big)}\n"rectangle"\n')
    code = main(["plan", "--batch", str(batch), "--method", "bfs", "--only", "best"])
    out, err = capsys.readouterr()
    docs = [json.loads(x) for x in out.splitlines()]
    assert code == 2 and err == "" and len(docs) == 2
    assert docs[0]["exit_code"] == 2
    assert "724 states), more than `table_limit`" in docs[0]["error"]
    assert "(use the exact planner)" in docs[0]["error"]
    assert "error" not in docs[1] and docs[1]["method"] == "bfs"
