"""Actions as values (model/actions.py): the registry, parsing, and a new kind end to end."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp import CostModel, Goal, Part, PlanningError, Problem, plan_exact
from bayesgrasp.model.actions import (
    ACTIONS,
    PUSH_GRASP,
    SQUEEZE,
    Action,
    get_action,
    parse_actions,
    register_action,
    unregister_action,
)
from bayesgrasp.model.states import nearest_state
from bayesgrasp.shapes import load

HOUSE = load("house")


def test_builtin_actions() -> None:
    assert ACTIONS["squeeze"] is SQUEEZE
    assert ACTIONS["push-grasp"] is PUSH_GRASP
    assert (SQUEEZE.tag, SQUEEZE.gripper_period, SQUEEZE.pushes_first) == ("S", math.pi, False)
    assert (PUSH_GRASP.tag, PUSH_GRASP.gripper_period, PUSH_GRASP.pushes_first) == (
        "P",
        2 * math.pi,
        True,
    )
    assert SQUEEZE.reads == PUSH_GRASP.reads == "width"
    with pytest.raises(TypeError):
        ACTIONS["poke"] = SQUEEZE  # type: ignore[index]


def test_parse_actions() -> None:
    assert parse_actions("squeeze") == (SQUEEZE,)
    assert parse_actions(" push-grasp , squeeze,push-grasp") == (PUSH_GRASP, SQUEEZE)
    assert parse_actions([SQUEEZE, "push-grasp"]) == (SQUEEZE, PUSH_GRASP)
    assert get_action(SQUEEZE) is SQUEEZE
    with pytest.raises(PlanningError, match="at least one action type is needed"):
        parse_actions(" , ")
    with pytest.raises(PlanningError, match=r"unknown action 'poke'; expected one of 'squeeze'"):
        parse_actions("squeeze,poke")
    with pytest.raises(PlanningError, match=r"unknown action 3"):
        get_action(3)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"name": "Big Squeeze"}, r"`name` must be lower case without commas; got 'Big Squeeze'"),
        ({"name": "a,b"}, "without commas"),
        ({"tag": "SS"}, r"`tag` must be one character; got 'SS'"),
        ({"gripper_period": 1.0}, r"`gripper_period` must be pi or 2 pi; got 1.0"),
    ],
)
def test_action_validation(changes: dict[str, object], match: str) -> None:
    with pytest.raises(PlanningError, match=match):
        dataclasses.replace(SQUEEZE, **changes)  # type: ignore[arg-type]


def test_register_refuses_clashes() -> None:
    assert register_action(SQUEEZE) is SQUEEZE  # the same action again is fine
    with pytest.raises(PlanningError, match="an action named 'squeeze' with tag 'S'"):
        register_action(dataclasses.replace(SQUEEZE, description="another squeeze"))
    with pytest.raises(PlanningError, match="an action named 'push-grasp' with tag 'P'"):
        register_action(dataclasses.replace(PUSH_GRASP, name="push-grasp-2"))


def test_transition_matrices_are_row_stochastic_one_hot() -> None:
    pb = Problem.build(HOUSE, actions=("squeeze", "push-grasp"))
    for name in pb.action_kinds:
        cl = pb.transition(name)
        assert cl is pb.classes(name)  # computed once
        for a in range(cl.n_classes):
            m = cl.matrix(a)
            assert_allclose(m.sum(axis=1), 1.0, atol=0)
            assert set(np.unique(m)) <= {0.0, 1.0}
            # The matrix moves a distribution exactly as the class's index map does.
            p = np.random.default_rng(a).dirichlet(np.ones(pb.n_states))
            assert_allclose(p @ m, np.bincount(cl.transfer[a], p, pb.n_states), atol=1e-15)
        # Each class's matrix is what the transfer function does at the class's middle angle.
        f = pb.transfer(name)
        after = nearest_state(pb.states, f(pb.states.stable[None, :] - cl.mid[:, None]))
        assert (after == cl.transfer).all()


def test_goal_success_states_and_widths() -> None:
    rect = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    single = Problem.build(rect)
    sym = Problem.build(rect, goal=Goal("symmetry"))
    assert single.success_states(math.pi / 2).tolist() == [False, True, False, False]
    assert sym.success_states(math.pi / 2).tolist() == [False, True, False, True]
    assert_allclose(single.widths, [2.0, 1.0, 2.0, 1.0], atol=1e-12)
    with pytest.raises(PlanningError, match="`kind` of a goal must be one of 'single'"):
        Goal("pairs")  # type: ignore[arg-type]


def test_problem_refuses_wrong_types() -> None:
    with pytest.raises(PlanningError, match="`part` must be a Part; got list"):
        Problem.build([(0, 0), (1, 0), (0, 1)])  # type: ignore[arg-type]
    with pytest.raises(PlanningError, match="`cost` must be a CostModel; got dict"):
        Problem.build(HOUSE, cost={"squeeze": 1})  # type: ignore[arg-type]
    with pytest.raises(PlanningError, match="action 'push-grasp' is not one of this problem's"):
        Problem.build(HOUSE).transfer("push-grasp")


def test_a_new_action_kind_plans_end_to_end() -> None:
    """The README's worked example: a second, dearer gripper station is a new action kind.

    It squeezes like the first gripper, so plans that may use it are plans of squeezes with
    some actions renamed: the same success probabilities, and it is used only where cheaper.
    """
    station = Action(
        name="station-2-squeeze",
        tag="T",
        gripper_period=math.pi,
        pushes_first=False,
        reads="width",
        description="a squeeze by the gripper of the second station",
        build=lambda part, squeeze: squeeze,
    )
    register_action(station)
    try:
        both = ("squeeze", "station-2-squeeze")
        cheap = Problem.build(HOUSE, actions=both, cost=CostModel({"station-2-squeeze": 0.5}))
        dear = Problem.build(HOUSE, actions=both, cost=CostModel({"station-2-squeeze": 2.0}))
        ref = plan_exact(Problem.build(HOUSE))
        for pb, used in ((cheap, "station-2-squeeze"), (dear, "squeeze")):
            rep = plan_exact(pb)
            assert {s.kind for s in rep.bayes_plan.steps} == {used}
            n = rep.bayes_plan.n_actions
            assert_allclose(
                rep.bayes_plan.success_probability,
                ref.options[n - 1].success_probability,
                atol=1e-12,
            )
    finally:
        unregister_action("station-2-squeeze")
    assert "station-2-squeeze" not in ACTIONS
    with pytest.raises(PlanningError, match="the built-in action 'squeeze' cannot be removed"):
        unregister_action("squeeze")
