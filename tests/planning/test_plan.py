"""One front door and one result type: ``plan(problem, method)``, PlanResult, the Plan
protocol, and the helpers every planner shares (short turns, the plan length bound)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bayesgrasp.errors import NoPlanError, PlanningError
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.actions import PUSH_GRASP, SQUEEZE, Action
from bayesgrasp.model.prior import von_mises
from bayesgrasp.model.problem import CostModel, Goal, Problem
from bayesgrasp.planning import (
    METHODS,
    GuaranteedPlan,
    Plan,
    PlanOption,
    PlanReport,
    PlanResult,
    PlanStep,
    execute_plan,
    max_plan_length,
    plan,
    plan_bfs,
    plan_exact,
    plan_guaranteed,
)
from bayesgrasp.planning.bfs import search_bfs
from bayesgrasp.planning.result import plan_actions, short_turns
from bayesgrasp.shapes import load

TWO_PI = 2.0 * math.pi
RECTANGLE = [(0, 0), (31, 0), (31, 20), (0, 20)]
TRIANGLE = [(0, 0), (3, 0), (1, 2)]
# A squeeze by another gripper: a new action kind of gripper period pi, not registered.
OTHER_SQUEEZE = Action(
    name="other-squeeze",
    tag="O",
    gripper_period=math.pi,
    pushes_first=False,
    reads="width",
    description="a squeeze by a second gripper",
    build=lambda part, squeeze: squeeze,
)


MIXED = Problem.build(
    Part.from_points([(0, 0), (3, 0), (1, 2), (-0.5, 1)]), actions=("squeeze", "push-grasp")
)


def random_parts(rng: np.random.Generator, count: int) -> list[Part]:
    """The seed's random polygons: hulls of 10 uniform points in the unit square."""
    return [Part.from_points(rng.random((10, 2))) for _ in range(count)]


def same_options(a: PlanResult, b: PlanResult) -> None:
    """Two results hold the same plans, bit for bit."""
    assert a.options == b.options
    assert (a.bayes, a.most_certain, a.method, a.nodes) == (
        b.bayes,
        b.most_certain,
        b.method,
        b.nodes,
    )
    assert (a.status, a.reason) == (b.status, b.reason)


# --------------------------------------------------------------------------------------
# The front door
# --------------------------------------------------------------------------------------


def test_plan_equals_each_planner(rng: np.random.Generator) -> None:
    for i, part in enumerate(random_parts(rng, 12)):
        prior = von_mises(1.0, 3.0) if i % 2 else None
        actions = ("squeeze", "push-grasp") if i % 3 == 0 else ("squeeze",)
        cost = CostModel({"push-grasp": 0.8}, first={"squeeze": 3.0}, retry=0.2)
        pb = Problem.build(part, prior=prior, cost=cost, actions=actions)
        for max_actions in (None, 2):
            same_options(plan(pb, "exact", max_actions), plan_exact(pb, max_actions))
            same_options(plan(pb, "bfs", max_actions), plan_bfs(pb, max_actions))
            same_options(plan(pb, "guaranteed", max_actions), plan_guaranteed(pb, max_actions))
        same_options(plan(pb), plan_exact(pb))


def test_every_method_returns_a_plan_result() -> None:
    pb = Problem.build(Part.from_points(RECTANGLE))
    for method in METHODS:
        res = plan(pb, method)
        assert isinstance(res, PlanResult) and res.ok
        assert (res.status, res.reason, res.method) == ("ok", None, method)
        assert isinstance(res.bayes_plan, Plan) and isinstance(res.most_certain_plan, Plan)
    g = plan(pb, "guaranteed")
    assert isinstance(g, GuaranteedPlan)
    assert g.options == (g.option,) and g.bayes == g.most_certain == 0
    assert g.n_actions == 2 and g.period == pytest.approx(math.pi)
    assert PlanReport is PlanResult


def test_plan_rejects_unknown_method_and_bad_length() -> None:
    pb = Problem.build(Part.from_points(TRIANGLE))
    with pytest.raises(PlanningError, match="`method` must be one of 'exact', 'bfs', 'guaranteed'"):
        plan(pb, "greedy")  # type: ignore[arg-type]
    for method in METHODS:
        with pytest.raises(PlanningError, match="`max_actions` must be an integer >= 1; got 0"):
            plan(pb, method, max_actions=0)


def test_bfs_refuses_accuracy_through_the_front_door() -> None:
    pb = Problem.build(Part.from_points(TRIANGLE), accuracy=0.01)
    with pytest.raises(PlanningError, match="`accuracy` must be 0"):
        plan(pb, "bfs")


# --------------------------------------------------------------------------------------
# No plan is a result
# --------------------------------------------------------------------------------------


def test_guaranteed_no_plan_under_accuracy_is_a_result() -> None:
    pb = Problem.build(load("key"), accuracy=math.radians(30.0))
    res = plan(pb, "guaranteed")
    assert isinstance(res, GuaranteedPlan)
    assert res.status == "no-plan" and not res.ok and res.options == ()
    assert res.reason is not None
    assert res.reason.startswith("no guaranteed plan for part 'key' with gripper accuracy 30 deg")
    assert f"short of the period {math.degrees(res.period):.6f} deg" in res.reason
    assert f"stops at {math.degrees(max(res.widths)):.6f} deg" in res.reason
    for name in ("option", "n_actions", "bayes_plan", "most_certain_plan"):
        with pytest.raises(NoPlanError, match="gripper accuracy 30 deg"):
            getattr(res, name)
    # The exact planner at the same accuracy still has plans.
    assert plan(pb).status == "ok"


def test_guaranteed_no_plan_within_max_actions() -> None:
    pb = Problem.build(Part.from_points(RECTANGLE))
    assert plan_guaranteed(pb).n_actions == 2
    res = plan(pb, "guaranteed", max_actions=1)
    assert isinstance(res, GuaranteedPlan) and len(res.widths) == 1
    assert res.status == "no-plan" and res.options == ()
    assert res.reason == (
        "no guaranteed plan within 1 actions for part 'part' (widest collapsible arc "
        f"{math.degrees(res.widths[-1]):.6f} deg, period 180.000000 deg)"
    )
    same = plan_guaranteed(pb, max_actions=2)
    assert same.status == "ok" and same.option == plan_guaranteed(pb).option


def test_guaranteed_widths_are_the_widest_of_each_length(rng: np.random.Generator) -> None:
    for part in random_parts(rng, 10):
        pb = Problem.build(part)
        g = plan_guaranteed(pb)
        exact = plan_exact(pb, max_actions=g.n_actions)
        # Uniform prior, one goal: p_k = W_k / 2 pi for every length below the guaranteed one.
        for o, w in zip(exact.options, g.widths, strict=False):
            assert_allclose(o.success_probability, min(w, g.period) / TWO_PI, atol=1e-12)


# --------------------------------------------------------------------------------------
# Shared helpers
# --------------------------------------------------------------------------------------


@given(
    st.lists(
        st.tuples(st.sampled_from([SQUEEZE, PUSH_GRASP]), st.floats(-10.0, 10.0)),
        min_size=1,
        max_size=6,
    )
)
def test_short_turns_are_the_same_plan(steps: list[tuple[Action, float]]) -> None:
    """Short turns execute like the raw ones, up to the carried turn of the final frame."""
    pb = MIXED
    actions = [a for a, _ in steps]
    angles = [x for _, x in steps]
    short, carry = short_turns(actions, angles)
    assert [s.kind for s in short] == [a.name for a in actions]
    for a, s in zip(actions, short, strict=True):
        assert -a.gripper_period / 2 < s.alpha <= a.gripper_period / 2
    assert math.remainder(carry, math.pi) == pytest.approx(0.0, abs=1e-12)
    if actions[-1] is PUSH_GRASP:  # a push-grasp has a pushing side: nothing to carry on
        assert carry == 0.0
    theta = np.linspace(0.0, TWO_PI, 181)
    raw = execute_plan(pb, [PlanStep(a.name, x) for a, x in steps], theta)
    got = execute_plan(pb, short, theta)
    d = np.mod(got - raw - carry + math.pi, TWO_PI) - math.pi
    # Orientations that start (or land) within rounding of a basin boundary may go either way.
    assert np.mean(np.abs(d) < 1e-6) > 0.97


def test_short_turns_squeeze_keeps_the_plan_exactly() -> None:
    """With squeezes only, the raw and short plans end in the same orientation up to carry."""
    pb = Problem.build(Part.from_points(TRIANGLE))
    theta = np.linspace(0.01, TWO_PI, 97)
    angles = [2.0, -3.0, 4.5, 1.6]
    short, carry = short_turns([SQUEEZE] * 4, angles)
    # Each turn is the raw one plus what the previous left over, reduced mod pi.
    left = 0.0
    for a, st_ in zip(angles, short, strict=True):
        assert -math.pi / 2 < st_.alpha <= math.pi / 2
        assert math.remainder(a + left - st_.alpha, math.pi) == pytest.approx(0.0, abs=1e-12)
        left = math.remainder(a + left, TWO_PI) - st_.alpha
    assert carry == pytest.approx(left, abs=1e-12)
    raw = execute_plan(pb, [PlanStep("squeeze", a) for a in angles], theta)
    got = execute_plan(pb, short, theta)
    assert_allclose(np.mod(got - raw - carry + math.pi, TWO_PI) - math.pi, 0.0, atol=1e-9)


def test_plan_actions_reads_the_problem() -> None:
    pb = Problem.build(Part.from_points(TRIANGLE), actions=("squeeze", OTHER_SQUEEZE))
    assert plan_actions(pb, ["other-squeeze", "squeeze"]) == (OTHER_SQUEEZE, SQUEEZE)
    with pytest.raises(PlanningError, match="action 'push-grasp' is not one of this problem's"):
        plan_actions(pb, ["push-grasp"])


def test_max_plan_length() -> None:
    assert max_plan_length(Problem.build(Part.from_points(TRIANGLE))) == 20
    assert max_plan_length(Problem.build(load("key"))) == 4 * load("key").hull.n_sides + 8


def test_plan_option_is_a_plan() -> None:
    o = PlanOption((PlanStep("squeeze", 0.0), PlanStep("squeeze", 0.5)), 1.0, 0.5, 6.0, 0.1, (0, 1))
    assert isinstance(o, Plan)
    assert (o.n_actions, o.final_orientation, o.tolerance) == (2, 1.0, 0.1)
    assert not isinstance(object(), Plan)


# --------------------------------------------------------------------------------------
# Planners read the action's attributes, not its name
# --------------------------------------------------------------------------------------


def test_a_new_kind_of_period_pi_plans_like_the_squeeze(rng: np.random.Generator) -> None:
    """A second squeeze gripper (gripper period pi): its turns are short and the baseline
    merges distributions a half turn apart, as for squeezes."""
    for part in random_parts(rng, 15):
        ref = Problem.build(part)
        other = Problem.build(part, actions=(OTHER_SQUEEZE,))
        for method in ("exact", "guaranteed"):
            a, b = plan(ref, method), plan(other, method)
            assert [o.success_probability for o in a.options] == [
                o.success_probability for o in b.options
            ]
            for o in b.options:
                assert o.kinds == ("other-squeeze",) * o.n_actions
                assert all(-math.pi / 2 < x <= math.pi / 2 for x in o.alphas)
                theta = np.linspace(o.success_arc[0], o.success_arc[1], 203)[1:-1]
                out = execute_plan(other, o.steps, theta)
                d = np.mod(out - o.final_orientation + math.pi, TWO_PI) - math.pi
                assert np.mean(np.abs(d) < 1e-9) > 0.98
        ra, rb = search_bfs(ref, tree_count=False), search_bfs(other, tree_count=False)
        assert rb.stats.nodes == ra.stats.nodes  # the half-turn merge applies to it too
        assert_allclose(
            [o.success_probability for o in rb.report.options],
            [o.success_probability for o in ra.report.options],
            atol=1e-12,
        )


def test_symmetry_goal_result_through_the_front_door() -> None:
    pb = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]), goal=Goal("symmetry"))
    for method in METHODS:
        res = plan(pb, method)
        assert res.most_certain_plan.success_probability == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("name", ["triangle", "house", "key", "example"])
def test_bayes_choice_does_not_depend_on_cost_units(name: str) -> None:
    """Scaling every cost by the same factor scales every expected cost: same Bayes plan."""
    from bayesgrasp.model.cost import CostModel
    from bayesgrasp.shapes import load

    def bayes(scale: float) -> int:
        cost = CostModel(
            {"squeeze": 1.0 * scale}, verify=0.7 * scale, first={"squeeze": 1.3 * scale}
        )
        return plan_exact(Problem.build(load(name), cost=cost)).bayes

    assert bayes(1e-13) == bayes(1.0) == bayes(1e250)


def test_all_infinite_costs_choose_the_fewest_actions() -> None:
    from bayesgrasp.planning.result import PlanOption, PlanStep, choose_indices

    opts = tuple(
        PlanOption((PlanStep("squeeze", 0.0),) * k, 0.0, 0.5, math.inf, None, (0.0, 1.0))
        for k in (1, 2)
    )
    assert choose_indices(opts) == (0, 0)
