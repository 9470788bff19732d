"""The problem model (problem.py): cost model, goal, problem set-up and action classes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from bayesgrasp import CostError, CostModel, Goal, Part, PlanningError, Problem, von_mises
from bayesgrasp.model import problem as problem_module
from bayesgrasp.model.prior import UniformPrior
from bayesgrasp.model.problem import action_classes, critical_angles, nearest_state
from bayesgrasp.shapes import load
from reference import regular_polygon

TWO_PI = 2.0 * math.pi
RECTANGLE = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]


def random_part(rng: np.random.Generator, n: int = 10) -> Part:
    return Part.from_points(rng.uniform(size=(n, 2)))


# --------------------------------------------------------------------------------------
# Cost model
# --------------------------------------------------------------------------------------


def test_cost_model_defaults_are_the_seeds() -> None:
    c = CostModel()
    assert c.attempt_cost(("squeeze",) * 3) == 4.0
    assert c.expected_cost(("squeeze", "squeeze"), 0.5) == 6.0
    assert c.expected_cost(("squeeze",), 0.0) == math.inf


@pytest.mark.parametrize("p", [0.1, 0.25, 0.5, 1.0])
def test_expected_cost_formula(p: float) -> None:
    c = CostModel(
        {"squeeze": 2.0, "push-grasp": 4.0}, verify=3.0, retry=0.7, first={"squeeze": 5.0}
    )
    kinds = ("squeeze", "push-grasp", "squeeze")
    attempt = 5.0 + 4.0 + 2.0 + 3.0
    assert c.attempt_cost(kinds) == attempt
    # Repeating until success: 1 / p attempts, 1 / p - 1 of them failures paying the retry.
    assert_allclose(c.expected_cost(kinds, p), attempt / p + 0.7 * (1 / p - 1), rtol=1e-15)
    # A first push-grasp is not a first squeeze.
    assert c.attempt_cost(("push-grasp", "squeeze")) == 4.0 + 2.0 + 3.0


def test_expected_cost_by_simulation(rng: np.random.Generator) -> None:
    """Run the retry loop literally and average its cost."""
    c = CostModel({"squeeze": 1.5}, verify=0.5, retry=2.0, first={"squeeze": 3.0})
    kinds = ("squeeze", "squeeze")
    p = 0.3
    attempts = rng.geometric(p, size=200_000)
    total = attempts * c.attempt_cost(kinds) + (attempts - 1) * c.retry
    se = total.std() / math.sqrt(len(total))
    assert abs(total.mean() - c.expected_cost(kinds, p)) < 5 * se


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"actions": {"squeeze": -1.0}}, r"cost `squeeze` must be a finite number >= 0; got -1.0"),
        ({"verify": math.nan}, r"cost `verify` must be a finite number >= 0; got nan"),
        ({"retry": math.inf}, r"cost `retry` must be a finite number >= 0; got inf"),
        ({"first": {"squeeze": -0.5}}, r"cost `first squeeze` must be .*; got -0.5"),
        ({"actions": {"push-grasp": "1"}}, r"cost `push-grasp` must be a finite .*; got '1'"),
        ({"actions": {"squeeze": True}}, r"cost `squeeze` must be a finite number >= 0; got True"),
        ({"actions": [1.0]}, r"`actions` must map action names to costs; got \[1.0\]"),
        ({"first": {3: 1.0}}, r"`first` must map action names to costs; got key 3"),
    ],
)
def test_cost_model_rejects_bad_costs(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(CostError, match=match):
        CostModel(**kwargs)  # type: ignore[arg-type]


def test_cost_model_by_action_name() -> None:
    """Costs are looked up by name: an action the model does not name costs 1 (the seed)."""
    assert CostModel().action_cost("poke") == 1.0
    assert CostModel({"poke": 3.0}).action_cost("poke") == 3.0
    assert CostModel({"squeeze": 1.0}) == CostModel()  # one spelling of each model
    assert CostModel(first={"push-grasp": 7.0}).attempt_cost(("push-grasp",)) == 8.0


def test_plans_that_cost_nothing_are_refused() -> None:
    part = Part.from_points(RECTANGLE)
    with pytest.raises(CostError, match=r"at least one of the costs .* must be positive"):
        Problem.build(part, cost=CostModel({"squeeze": 0.0}, verify=0.0))
    # Any positive cost of the actions used is enough.
    Problem.build(part, cost=CostModel({"squeeze": 0.0}, verify=0.0, retry=1.0))
    Problem.build(part, cost=CostModel({"squeeze": 0.0}, verify=0.0, first={"squeeze": 1.0}))
    # A push-grasp cost does not count for squeeze-only plans.
    with pytest.raises(
        CostError, match="`verify`, `retry`, `squeeze` must be positive; got all zero"
    ):
        Problem.build(part, cost=CostModel({"squeeze": 0.0, "push-grasp": 5.0}, verify=0.0))


# --------------------------------------------------------------------------------------
# Goal and problem set-up
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_goal_group(n: int) -> None:
    part = Part.from_points(regular_polygon(n))
    assert Problem.build(part).goal_group == 1
    pb = Problem.build(part, goal=Goal("symmetry"))
    assert pb.goal_group == n
    assert pb.goal_group == n  # cached, same answer
    assert Goal("symmetry").group_order(1) == 1


def test_build_defaults_and_actions() -> None:
    pb = Problem.build(Part.from_points(RECTANGLE))
    assert pb.action_kinds == ("squeeze",)
    assert pb.prior.name == "uniform"
    assert pb.cost == CostModel()
    assert pb.goal == Goal()
    assert pb.states is pb.transfers["squeeze"]
    assert pb.n_states == 4
    pb2 = Problem.build(Part.from_points(RECTANGLE), actions=("squeeze", "squeeze"))
    assert pb2.action_kinds == ("squeeze",)


@pytest.mark.parametrize(
    ("actions", "match"),
    [
        ((), "at least one action type is needed"),
        (("poke",), "unknown action 'poke'; expected one of 'squeeze', 'push-grasp'"),
    ],
)
def test_build_rejects_bad_actions(actions: tuple[str, ...], match: str) -> None:
    with pytest.raises(PlanningError, match=match):
        Problem.build(Part.from_points(RECTANGLE), actions=actions)


def test_state_distribution_against_grid(rng: np.random.Generator) -> None:
    """The prior mass of each basin, against initial orientations pushed through s."""
    n = 1 << 16
    theta = (np.arange(n) + 0.5) * (TWO_PI / n)
    for part in [load("triangle"), random_part(rng), random_part(rng)]:
        for mean, kappa in [(0.0, 0.0), (1.0, 3.0), (4.0, 8.0)]:
            pb = Problem.build(part, von_mises(mean, kappa))
            w = np.exp(kappa * np.cos(theta - mean))
            for a in [0.0, 0.7, -2.0]:
                dist = pb.state_distribution(a)
                end = pb.states(theta - a)
                idx = nearest_state(pb.states, end)
                grid = np.bincount(idx, weights=w, minlength=pb.n_states) / w.sum()
                assert_allclose(dist.sum(), 1.0, atol=1e-12)
                point = w.max() / w.sum()
                assert_allclose(dist, grid, atol=(pb.n_states + 1) * point + 1e-5)


def test_state_distribution_uniform_is_basin_widths(rng: np.random.Generator) -> None:
    pb = Problem.build(random_part(rng))
    assert_allclose(pb.state_distribution(1.234), pb.states.widths / TWO_PI, atol=1e-12)


@pytest.mark.parametrize("prior", [None, von_mises(1.0, 3.0)], ids=["uniform", "von-mises"])
def test_state_probabilities_are_the_distributions_floats(
    rng: np.random.Generator, prior: object, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The list is the array's values, bit for bit; the few-states path is numpy's too."""
    kw = {} if prior is None else {"prior": prior}
    parts = [load("triangle"), load("house"), random_part(rng), random_part(rng)]
    cases = [(Problem.build(p, **kw), a) for p in parts for a in (0.0, 0.7, -2.0, 9.5)]
    got = [(pb.state_probabilities(a), pb.state_distribution(a)) for pb, a in cases]
    for (pb, a), (floats, dist) in zip(cases, got, strict=True):
        assert type(floats) is list and all(type(x) is float for x in floats)
        assert floats == dist.tolist()
        assert np.array(floats).tobytes() == dist.tobytes()  # -0.0 and NaN alike too
        assert pb.state_probabilities(a, "squeeze") == floats
    monkeypatch.setattr(Problem, "_small_distribution", lambda *_: None)  # numpy only
    for (pb, a), (floats, _) in zip(cases, got, strict=True):
        assert pb.state_distribution(a).tobytes() == np.array(floats).tobytes()


def test_nearest_state() -> None:
    pb = Problem.build(Part.from_points(RECTANGLE))
    s = pb.states.stable
    assert_array_equal(nearest_state(pb.states, s + 1e-3), np.arange(4))
    assert_array_equal(nearest_state(pb.states, np.array([TWO_PI - 1e-9])), [0])


# --------------------------------------------------------------------------------------
# Action classes (the seed, 4.4)
# --------------------------------------------------------------------------------------


def test_action_classes_against_squeezing(rng: np.random.Generator) -> None:
    for _ in range(30):
        part = random_part(rng, int(rng.integers(4, 12)))
        pb = Problem.build(part)
        cls = pb.classes("squeeze")
        assert pb.classes("squeeze") is cls
        # At most n^2 classes (the seed), tiling the gripper's half turn.
        assert len(cls.lo) <= part.hull.n_sides**2
        assert_allclose(np.sum(cls.hi - cls.lo), math.pi, atol=1e-12)
        assert np.all(cls.hi > cls.lo)
        # Any turn inside a class sends each state where the table says.
        for a in range(len(cls.lo)):
            alpha = rng.uniform(cls.lo[a], cls.hi[a], size=5)
            end = pb.states(pb.states.stable[None, :] - alpha[:, None])
            assert_array_equal(nearest_state(pb.states, end), np.tile(cls.transfer[a], (5, 1)))


def test_action_classes_of_a_square() -> None:
    pb = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    cls = action_classes(pb.states, pb.states, math.pi)
    # Stable at multiples of 90 deg, boundaries at 45 + 90 m: classes change at 45 and 135.
    assert_allclose(np.degrees(cls.lo), [45.0, 135.0], atol=1e-9)
    assert_array_equal(cls.transfer[0], [3, 0, 1, 2])
    assert_array_equal(cls.transfer[1], [2, 3, 0, 1])


@pytest.mark.parametrize("block", [1, 50, 1 << 16])
def test_action_classes_in_blocks_equal_the_whole_table(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch, block: int
) -> None:
    """Made a block of classes at a time (a large part's way), the table is the same.

    The reference is nearest_state on all (A, K) orientations at once: an (A, K, K) array,
    the old way (30 MB for the 60-point circle, K = 58).
    """
    t = np.sort(rng.uniform(0, TWO_PI, 60))
    parts = [random_part(rng) for _ in range(5)]
    parts += [Part.from_points(np.column_stack([np.cos(t), np.sin(t)]))]
    parts += [Part.from_points(regular_polygon(12, 0.1))]
    monkeypatch.setattr(problem_module, "_BLOCK", block)
    for part in parts:
        pb = Problem.build(part, actions=("squeeze", "push-grasp"))
        for f, period in ((pb.states, math.pi), (pb.transfer("push-grasp"), TWO_PI)):
            cls = action_classes(pb.states, f, period)
            s = pb.states.stable
            whole = nearest_state(pb.states, f(s[None, :] - cls.mid[:, None]))
            assert_array_equal(cls.transfer, whole)
            assert_array_equal(cls.lo, critical_angles(pb.states, f, period))


def test_defaults_are_shared_and_equal_to_fresh_ones() -> None:
    from bayesgrasp.model.prior import UniformPrior

    part = Part.from_points([(0, 0), (2, 0), (2.2, 1), (0, 1.1)])
    a, b = Problem.build(part), Problem.build(part)
    assert a.cost is b.cost and a.cost == CostModel()
    assert a.goal == Goal() and a.prior == UniformPrior()
    assert a._cache is not b._cache  # each problem its own derived values
    given = Problem.build(part, cost=CostModel(), goal=Goal(), prior=UniformPrior())
    assert given.n_states == a.n_states and given.cost == a.cost
    with pytest.raises(CostError):  # a given cost is still checked
        Problem.build(part, cost=CostModel({"squeeze": 0.0}, verify=0.0))


def test_action_kinds_are_made_once_and_follow_the_actions() -> None:
    part = Part.from_points([(0, 0), (2, 0), (2.2, 1), (0, 1.1)])
    pb = Problem.build(part, actions=("push-grasp", "squeeze"))
    assert pb.action_kinds == ("push-grasp", "squeeze")
    assert pb.action_kinds is pb.action_kinds
    assert Problem.build(part, actions=["squeeze"]).action_kinds == ("squeeze",)
    assert Problem.build(part, actions="squeeze").action_kinds == ("squeeze",)
    assert pb.goal_group == 1 and Problem.build(part, goal=Goal("symmetry")).goal_group == 1
    rect = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    assert Problem.build(rect, goal=Goal("symmetry")).goal_group == 2


def test_replace_gives_a_fresh_cache() -> None:
    """Derived values are not carried over to a problem made by dataclasses.replace."""
    import dataclasses

    from bayesgrasp.model.actions import PUSH_GRASP

    pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    assert pb.action_kinds == ("squeeze",)
    other = dataclasses.replace(pb, actions=(PUSH_GRASP,))
    assert other.action_kinds == ("push-grasp",)


def test_build_sets_the_fields_the_dataclass_would() -> None:
    """Problem.build's own construction (the slots' setters) against the dataclass __init__."""
    import dataclasses

    part = Part.from_points([(0, 0), (2, 0), (2.2, 1), (0, 1.1)])
    pb = Problem.build(part, accuracy=0.01)
    names = [f.name for f in dataclasses.fields(Problem) if f.init]
    again = Problem(*(getattr(pb, name) for name in names))
    for name in names:
        assert getattr(again, name) is getattr(pb, name)
    assert pb._cache == {} and again._cache == {} and pb._cache is not again._cache
    assert repr(again) == repr(pb)
    assert pb.transfers["squeeze"] is pb.states and pb.accuracy == 0.01
    assert type(Problem.build(part, accuracy=1).accuracy) is float


def test_build_of_a_subclass_is_the_subclass() -> None:
    class Mine(Problem):
        __slots__ = ()

    part = Part.from_points([(0, 0), (2, 0), (2.2, 1), (0, 1.1)])
    pb = Mine.build(part)
    assert type(pb) is Mine and pb.n_states == Problem.build(part).n_states


@pytest.mark.parametrize("bad", [True, -0.1, math.nan, math.inf, -math.inf, "0.1", None])
def test_build_rejects_bad_accuracy(bad: object) -> None:
    part = Part.from_points([(0, 0), (2, 0), (2.2, 1), (0, 1.1)])
    with pytest.raises(PlanningError, match="`accuracy` must be a finite number"):
        Problem.build(part, accuracy=bad)  # type: ignore[arg-type]


def test_shared_defaults_replace_only_equal_inputs() -> None:
    """Inputs equal to build's defaults become its shared objects; others are kept as given."""
    from bayesgrasp.model import problem as problem_module
    from bayesgrasp.model.problem import shared_defaults

    given = {"prior": UniformPrior(), "cost": CostModel(), "goal": Goal(), "accuracy": 0.0}
    out = shared_defaults(given)
    assert out["prior"] is problem_module._DEFAULT_PRIOR
    assert out["cost"] is problem_module._DEFAULT_COST
    assert out["goal"] is problem_module._DEFAULT_GOAL
    assert out["accuracy"] == 0.0 and given["cost"] is not out["cost"]  # the input is kept
    other = {"cost": CostModel(retry=-0.0), "prior": von_mises(1.0, 2.0), "goal": None}
    assert shared_defaults(other) == other  # -0.0 is written otherwise than 0.0
    assert shared_defaults(other)["cost"] is other["cost"]
    sq = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    a, b = Problem.build(sq, **out), Problem.build(sq)
    assert (a.prior, a.cost, a.goal) == (b.prior, b.cost, b.goal)
    with pytest.raises(CostError):  # a cost that is not the default is still checked
        Problem.build(sq, **shared_defaults({"cost": CostModel({"squeeze": 0.0}, verify=0.0)}))
