"""Guaranteed plans: shortest, correct by execution, equal to the exact planner's length."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import PartError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.geometry.transfer import TransferFunction
from bayesgrasp.model.prior import von_mises
from bayesgrasp.model.problem import Goal, Problem
from bayesgrasp.planning import execute_plan, plan_exact
from bayesgrasp.planning.guaranteed import GuaranteedPlan, plan_guaranteed, widest_arc
from bayesgrasp.planning.result import PlanStep
from bayesgrasp.shapes import load, names

TWO_PI = 2.0 * math.pi
SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]
EQUILATERAL = [(0, 0), (1, 0), (0.5, math.sqrt(3) / 2)]


def random_parts(rng: np.random.Generator, count: int, points: int = 10) -> list[Part]:
    """The seed's random polygons: the hull of uniform points in the unit square."""
    return [Part.from_points(rng.random((points, 2))) for _ in range(count)]


def near_regular(n: int, eps: float, rng: np.random.Generator) -> Part:
    """A regular n-gon with every vertex moved by up to ``eps`` (relative)."""
    t = TWO_PI * np.arange(n) / n
    pts = np.column_stack([np.cos(t), np.sin(t)]) + rng.uniform(-eps, eps, (n, 2))
    return Part.from_points(pts, name=f"near-regular {n}")


def thin(aspect: float, n: int, rng: np.random.Generator) -> Part:
    """A long thin convex part: n points on an ellipse of the given aspect, jittered."""
    t = np.sort(rng.uniform(0, TWO_PI, n))
    return Part.from_points(np.column_stack([np.cos(t), aspect * np.sin(t)]), name="thin")


def collapsed(pb: Problem, plan: GuaranteedPlan, theta: np.ndarray) -> np.ndarray:
    """Distance, modulo the period, of each final orientation from the plan's final one."""
    out = execute_plan(pb, plan.option.steps, theta)
    t = plan.period
    return np.abs(np.mod(out - plan.option.final_orientation + t / 2, t) - t / 2)


def shortest_by_search(pb: Problem, period: float) -> int:
    """Fewest actions sending every state to one orientation modulo ``period``.

    Forward breadth-first search over *sets* of states (no arcs, no widths): the first
    action, at any angle, leaves the part in any stable orientation of its transfer
    function; each action class maps the set through ``problem.classes(kind).transfer``.
    """
    stable = pb.states.stable

    def done(members: np.ndarray) -> bool:
        d = np.mod(stable[members] - stable[members[0]] + period / 2, period) - period / 2
        return bool(np.all(np.abs(d) < 1e-6))

    tables = [pb.classes(t).transfer for t in pb.action_kinds]
    k = pb.n_states
    frontier: dict[bytes, np.ndarray] = {}
    for t in pb.action_kinds:
        f = pb.transfers[t]
        members = np.unique(np.searchsorted(stable, f.stable))  # push-grasp lands on states
        assert_allclose(stable[members], np.unique(f.stable), atol=0)
        frontier[members.tobytes()] = members
    seen = set(frontier)
    for depth in range(1, 4 * pb.part.hull.n_sides + 9):
        if any(done(m) for m in frontier.values()):
            return depth
        nxt: dict[bytes, np.ndarray] = {}
        for members in frontier.values():
            for table in tables:
                img = table[:, members]  # (A, m)
                mask = np.zeros((len(table), k), dtype=bool)
                np.put_along_axis(mask, img, True, axis=1)
                for row in np.unique(mask, axis=0):
                    m = np.flatnonzero(row)
                    key = m.tobytes()
                    if key not in seen:
                        seen.add(key)
                        nxt[key] = m
        frontier = nxt
    raise AssertionError("no guaranteed plan found by search")  # pragma: no cover


def test_lengths_equal_exact_most_certain_on_random_polygons(rng: np.random.Generator) -> None:
    theta = rng.uniform(0, TWO_PI, 400)
    for part in random_parts(rng, 520):
        pb = Problem.build(part)
        g = plan_guaranteed(pb)
        assert g.n_actions == plan_exact(pb).most_certain_plan.n_actions
        assert g.n_actions <= 2 * part.hull.n_sides - 1  # Chen and Ierardi
        assert g.period == pytest.approx(math.pi, abs=1e-12)
        assert collapsed(pb, g, theta).max() < 1e-9
        assert g.option.success_probability == pytest.approx(0.5, abs=1e-12)
        # Squeeze angles are shown short: a squeeze gripper turned by pi is the same gripper.
        assert all(-math.pi / 2 < s.alpha <= math.pi / 2 for s in g.option.steps)


@pytest.mark.parametrize("name", names())
def test_catalogue(name: str) -> None:
    part = load(name)
    for actions in (("squeeze",), ("squeeze", "push-grasp")):
        pb = Problem.build(part, actions=actions)
        g = plan_guaranteed(pb)
        assert g.n_actions == plan_exact(pb).most_certain_plan.n_actions
        assert g.n_actions <= 2 * part.hull.n_sides - 1
        theta = np.linspace(0, TWO_PI, 3601)[:-1] + 1e-4
        assert collapsed(pb, g, theta).max() < 1e-9


def test_shortest_against_a_search_over_state_sets(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 60, points=7):
        for actions in (("squeeze",), ("squeeze", "push-grasp")):
            pb = Problem.build(part, actions=actions)
            g = plan_guaranteed(pb)
            assert g.n_actions == shortest_by_search(pb, g.period)


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4, 1e-5, 1e-7])
@pytest.mark.parametrize("n", [3, 4, 5, 6, 7, 8, 9, 11, 12, 21, 31])
def test_near_regular_polygons(n: int, eps: float, rng: np.random.Generator) -> None:
    """Adversarial: nearly equal basins. Within the symmetry tolerance a part counts as
    symmetric, and the plan collapses up to the symmetric period, up to that tolerance."""
    theta = rng.uniform(0, TWO_PI, 400)
    for _ in range(3):
        part = near_regular(n, eps, rng)
        pb = Problem.build(part)
        g = plan_guaranteed(pb)
        assert g.n_actions <= 2 * part.hull.n_sides - 1
        assert g.n_actions == plan_exact(pb).most_certain_plan.n_actions
        symmetric = g.period < math.pi - 1e-12  # the squeeze function's period test
        assert symmetric or eps >= 1e-5
        atol = 1e-9 if not symmetric else 10 * part.hull.tol.symmetry
        assert collapsed(pb, g, theta).max() < atol


@pytest.mark.parametrize("aspect", [0.1, 1e-2, 1e-3])
def test_long_thin_parts(aspect: float, rng: np.random.Generator) -> None:
    theta = rng.uniform(0, TWO_PI, 400)
    for n in (4, 8, 16, 30):
        try:
            part = thin(aspect, n, rng)
        except PartError:  # pragma: no cover - all points collinear within tolerance
            continue
        pb = Problem.build(part)
        g = plan_guaranteed(pb)
        assert g.n_actions <= 2 * part.hull.n_sides - 1
        assert g.n_actions == plan_exact(pb).most_certain_plan.n_actions
        assert collapsed(pb, g, theta).max() < 1e-9


def test_widths_grow_strictly_to_the_period(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 100):
        g = plan_guaranteed(Problem.build(part))
        w = np.array(g.widths)
        assert np.all(np.diff(w) > 0)
        assert w[-1] >= g.period - 1e-9
        assert np.all(w[:-1] < g.period - 1e-9)


def test_tolerance_is_honest(rng: np.random.Generator) -> None:
    """Every further gripper turn may err by up to the reported tolerance."""
    theta = rng.uniform(0, TWO_PI, 300)
    checked = 0
    for part in random_parts(rng, 100):
        pb = Problem.build(part)
        g = plan_guaranteed(pb)
        tol = g.option.tolerance
        if tol is None:
            continue
        for _ in range(4):
            errs = rng.uniform(-0.98, 0.98, g.n_actions - 1) * tol
            steps = [g.option.steps[0]] + [
                PlanStep(s.kind, s.alpha + e) for s, e in zip(g.option.steps[1:], errs, strict=True)
            ]
            out = execute_plan(pb, steps, theta)
            d = np.mod(out - out[0] + g.period / 2, g.period) - g.period / 2
            assert np.abs(d).max() < 1e-9
        checked += 1
    assert checked > 50


@pytest.mark.parametrize(("points", "period_deg"), [(SQUARE, 90.0), (EQUILATERAL, 60.0)])
def test_symmetric_parts_take_one_squeeze(
    points: list[tuple[float, float]], period_deg: float
) -> None:
    g = plan_guaranteed(Problem.build(Part.from_points(points)))
    assert g.n_actions == 1
    assert math.degrees(g.period) == pytest.approx(period_deg, abs=1e-9)


def test_push_grasps_orient_uniquely(rng: np.random.Generator) -> None:
    theta = rng.uniform(0, TWO_PI, 500)
    for part in random_parts(rng, 100):
        pb = Problem.build(part, actions=("squeeze", "push-grasp"))
        g = plan_guaranteed(pb)
        assert g.period == TWO_PI
        assert g.option.success_probability == pytest.approx(1.0, abs=1e-12)
        out = execute_plan(pb, g.option.steps, theta)
        assert_allclose(
            np.abs(np.mod(out - g.option.final_orientation + math.pi, TWO_PI) - math.pi),
            0.0,
            atol=1e-9,
        )
        assert g.n_actions == plan_exact(pb).most_certain_plan.n_actions


def test_cheapest_of_the_shortest(rng: np.random.Generator) -> None:
    """With push-grasps dearer, a guaranteed plan never costs more than another of its length."""
    from bayesgrasp.model.problem import CostModel

    for part in random_parts(rng, 60):
        cheap = plan_guaranteed(Problem.build(part, actions=("squeeze", "push-grasp")))
        pb = Problem.build(
            part, cost=CostModel({"push-grasp": 3.0}), actions=("squeeze", "push-grasp")
        )
        dear = plan_guaranteed(pb)
        assert dear.n_actions == cheap.n_actions
        attempt = pb.cost.attempt_cost
        assert attempt(dear.option.kinds) <= attempt(cheap.option.kinds) + 1e-12


def test_prior_places_the_first_action_only(rng: np.random.Generator) -> None:
    part = random_parts(rng, 1)[0]
    pb = Problem.build(part, prior=von_mises(math.radians(40.0), 4.0))
    g = plan_guaranteed(pb)
    assert g.n_actions == plan_guaranteed(Problem.build(part)).n_actions
    theta = rng.uniform(0, TWO_PI, 500)
    assert collapsed(pb, g, theta).max() < 1e-9
    # The prior's mass on the success arc is what the option reports.
    lo, hi = g.option.success_arc
    assert g.option.success_probability == pytest.approx(float(pb.prior.mass(lo, hi)), abs=1e-9)
    assert g.option.success_probability > 0.5


def test_symmetry_goal() -> None:
    rect = Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1)])
    g = plan_guaranteed(Problem.build(rect, goal=Goal("symmetry")))
    assert math.degrees(g.period) == pytest.approx(180.0, abs=1e-9)
    assert g.option.success_probability == pytest.approx(1.0, abs=1e-12)


def test_widest_arc_single_basin_and_full_circle() -> None:
    from bayesgrasp.geometry.transfer import squeeze_function

    s = squeeze_function(Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1)]).hull)
    one = widest_arc(s, 0.0, 1e-9)
    assert one.span == 0.0
    assert one.width == pytest.approx(s.widths.max(), abs=1e-12)
    assert one.width == pytest.approx(math.pi - 2 * math.atan(1 / 3), abs=1e-12)
    full = widest_arc(s, 10.0, 1e-9)
    assert full.width == pytest.approx(TWO_PI, abs=1e-12)


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    from bayesgrasp.cli import main

    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_guaranteed_json(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    code, out, err = run(capsys, "plan", "triangle", "--guaranteed", "--json")
    assert code == 0 and err == ""
    doc = json.loads(out)
    assert doc["schema"] == "bayesgrasp.plan/2"
    g = plan_guaranteed(Problem.build(load("triangle")))
    sure = doc["guaranteed"]
    assert sure["squeezes"] == g.n_actions
    assert [s["type"] for s in sure["steps"]] == ["squeeze"] * g.n_actions
    assert_allclose([s["alpha_rad"] for s in sure["steps"]], [s.alpha for s in g.option.steps])
    assert sure["period_rad"] == pytest.approx(math.pi)
    assert sure["final_orientation_rad"] == pytest.approx(g.option.final_orientation)
    assert sure["tolerance_rad"] == pytest.approx(g.option.tolerance)
    assert set(doc["options"][0]) <= set(sure)  # an option of the same form
    # Without --guaranteed (squeezes only) the document stays plan/1.
    code, out, _ = run(capsys, "plan", "triangle", "--json")
    assert json.loads(out)["schema"] == "bayesgrasp.plan/1" and "guaranteed" not in out


def test_cli_guaranteed_table(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "plan", "rectangle", "--guaranteed")
    assert code == 0 and err == ""
    assert "guaranteed plan: 2 action(s), first 0.00 deg, alphas (deg) [-45.00]" in out
    assert "modulo 180 deg" in out


def widest_by_pairs(f: TransferFunction, limit: float, tol: float) -> tuple[float, float]:
    """(width, span) of the widest arc by trying every (first basin, number of basins)."""
    k = f.n_states
    s = np.concatenate([f.stable, f.stable + TWO_PI])
    hi = np.concatenate([f.basin_hi, f.basin_hi + TWO_PI])
    best = (-1.0, 0.0)
    for i in range(k):
        for m in range(k):
            span = s[i + m] - s[i]
            if m and span >= limit - 2 * tol:
                break
            width = hi[i + m] - f.basin_lo[i]
            if width > best[0] + tol or (width >= best[0] - tol and span < best[1]):
                best = (max(width, best[0]), span)
    return best


def test_widest_arc_against_all_pairs(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 60):
        for f in Problem.build(part, actions=("squeeze", "push-grasp")).transfers.values():
            for limit in [0.0, *rng.uniform(0, TWO_PI + 0.5, 6)]:
                arc = widest_arc(f, limit, 1e-9)
                width, span = widest_by_pairs(f, limit, 1e-9)
                assert arc.width == pytest.approx(width, abs=1e-9)
                assert arc.span == pytest.approx(span, abs=1e-9)
                assert arc.span < limit - 2e-9 or arc.span == 0.0
