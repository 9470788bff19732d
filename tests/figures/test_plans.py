"""Figure (d) and the plan figure, bayesgrasp.figures.plans: distributions agree with a
simulation; the goal and the labels are readable."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.errors import PlanningError
from bayesgrasp.figures import evolution_figure, plan_figure, step_distributions
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.model.goal import Goal
from bayesgrasp.model.problem import Problem, nearest_state
from bayesgrasp.planning import PlanStep, execute_plan, plan_exact
from bayesgrasp.shapes import load

ByGid = Callable[[Any, str], list[Any]]

PENTAGON = Part.from_points([(0, 0), (4, 0), (5, 2), (2, 4), (-1, 2)], name="pentagon")


def test_step_distributions_agree_with_a_simulation(
    bracket_problem: Problem, rng: np.random.Generator
) -> None:
    pb = bracket_problem
    option = plan_exact(pb).most_certain_plan
    start = rng.uniform(0, 2 * np.pi, 40_000)
    dists = step_distributions(pb, option.steps)
    assert len(dists) == option.n_actions
    for k, (where, probs) in enumerate(dists, start=1):
        final = execute_plan(pb, option.steps[:k], start)
        idx = nearest_state(pb.states, final)
        freq = np.bincount(idx, minlength=pb.n_states) / len(start)
        expected = np.zeros(pb.n_states)
        expected[nearest_state(pb.states, where)] = probs
        sigma = np.sqrt(expected * (1 - expected) / len(start))
        assert np.all(np.abs(freq - expected) <= 5 * sigma + 1e-12)
        assert_allclose(probs.sum(), 1.0, atol=1e-12)


def test_step_distribution_of_a_single_squeeze_is_the_basin_widths() -> None:
    pb = Problem.build(PENTAGON)
    [(where, probs)] = step_distributions(pb, [PlanStep("squeeze", 0.0)])
    assert_allclose(where, pb.states.stable)
    assert_allclose(probs, pb.states.widths / (2 * np.pi), atol=1e-12)


def test_evolution_figure_one_panel_per_step(bracket_problem: Problem, by_gid: ByGid) -> None:
    pb = bracket_problem
    rep = plan_exact(pb)
    for option in rep.options:
        fig = evolution_figure(pb, option, "test")
        axes = fig.axes
        assert len(axes) == option.n_actions + 1
        prior = by_gid(axes[0], "prior")[0]
        assert_allclose(np.sum(prior.get_data().values), 1.0, atol=1e-12)
        for ax in axes[1:]:
            stems = by_gid(ax, "distribution")[0].get_segments()
            heights = np.array([seg[1][1] for seg in stems])
            assert_allclose(heights.sum(), 1.0, atol=1e-12)
            labels = [float(t.get_text()) for t in by_gid(ax, "probability")]
            assert_allclose(labels, heights, atol=0.005)
        last = np.array([seg[1] for seg in by_gid(axes[-1], "distribution")[0].get_segments()])
        goal = math.degrees(option.final_orientation)
        at_goal = last[np.abs(last[:, 0] - goal) < 1e-6, 1]
        assert_allclose(at_goal, [option.success_probability], atol=1e-12)
        assert_allclose(by_gid(axes[-1], "goal")[0].get_xdata(), [goal, goal])


@pytest.mark.parametrize("actions", ["squeeze", "squeeze,push-grasp"])
def test_the_goal_at_0_degrees_is_inside_the_frame(actions: str, by_gid: ByGid) -> None:
    """Issue 15, item 11: the goal line at 0 deg hid on the axis edge."""
    pb = Problem.build(load("house"), actions=actions)
    option = plan_exact(pb).bayes_plan
    assert option.final_orientation == 0.0
    fig = evolution_figure(pb, option, "Bayes")
    fig.canvas.draw()
    last = fig.axes[-1]
    frame = last.get_window_extent()
    goal = by_gid(last, "goal")[0]
    x = last.transData.transform((0.0, 0.5))[0]
    assert frame.x0 + 5 < x < frame.x1  # pixels clear of the left spine
    assert goal.get_zorder() > by_gid(last, "distribution")[0].get_zorder()  # above the stem


def test_a_symmetry_goal_marks_its_copies(by_gid: ByGid) -> None:
    pb = Problem.build(load("rectangle"), goal=Goal("symmetry"))
    option = plan_exact(pb).bayes_plan
    fig = evolution_figure(pb, option, "Bayes")
    copies = [ln.get_xdata()[0] for ln in by_gid(fig.axes[-1], "goal-copies")]
    g = pb.goal_group
    expect = (math.degrees(option.final_orientation) + 360.0 * np.arange(1, g) / g) % 360.0
    assert_allclose(sorted(copies), sorted(expect), atol=1e-9)


def overlapping_labels(fig: Any, by_gid: ByGid) -> list[tuple[str, str]]:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    bad = []
    for ax in fig.axes:
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in by_gid(ax, "probability")]
        for (ta, a), (tb, b) in itertools.combinations(boxes, 2):
            if a.overlaps(b):
                bad.append((ta, tb))
    return bad


def test_value_labels_do_not_overlap(peanut_problem: Problem, by_gid: ByGid) -> None:
    """Issue 15, item 11: stable orientations 5 degrees apart wrote their labels on each other."""
    for option in plan_exact(peanut_problem).options:
        fig = evolution_figure(peanut_problem, option, "test")
        assert overlapping_labels(fig, by_gid) == []
    fig = plan_figure(plan_exact(peanut_problem), "most-certain")
    assert overlapping_labels(fig, by_gid) == []


def test_plan_figure_and_its_arguments(bracket_problem: Problem) -> None:
    rep = plan_exact(bracket_problem)
    fig = plan_figure(rep, "most-certain")
    top, bottom = fig.subfigs
    assert len(top.axes) == 3  # part, diameter and its histogram axis
    assert len(bottom.axes) == rep.most_certain_plan.n_actions + 1
    with pytest.raises(PlanningError, match="`which` must be 'bayes' or 'most-certain'"):
        plan_figure(rep, "best")
    with pytest.raises(PlanningError, match="at least one step"):
        step_distributions(bracket_problem, [])


@dataclass
class NoPlan:
    problem: Problem
    status: str = "no-plan"
    reason: str | None = "no plan reaches the goal within 2 actions"


def test_plan_figure_of_a_result_without_a_plan(bracket_problem: Problem) -> None:
    with pytest.raises(PlanningError, match="no plan to draw: no plan reaches the goal within 2"):
        plan_figure(NoPlan(bracket_problem))  # type: ignore[arg-type]


def test_evolution_figure_under_noise_is_the_bottom_of_the_noisy_plan_figure() -> None:
    """The distributions and note given draw the panels ``noisy_plan_figure`` draws."""
    from bayesgrasp.figures.plans import noise_note, noisy_plan_figure
    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy import plan_noisy, step_distributions_noisy

    pb = Problem.build(load("key"))
    noise = NoiseModel(TurnNoise("uniform", math.radians(4.0)))
    res = plan_noisy(pb, noise)
    option = res.bayes_plan.option
    qs = step_distributions_noisy(pb, noise, option.steps)
    alone = evolution_figure(pb, option, "Bayes", qs, noise_note(noise))
    below = noisy_plan_figure(res).subfigs[1]
    assert alone.get_suptitle() == below.get_suptitle()
    assert "exact under turn error uniform:4 deg" in alone.get_suptitle()
    assert len(alone.axes) == len(below.axes) == option.n_actions + 1
    for a, b in zip(alone.axes, below.axes, strict=True):
        assert a.get_title() == b.get_title()
        sa = [c.get_segments() for c in a.collections if c.get_gid() == "distribution"]
        sb = [c.get_segments() for c in b.collections if c.get_gid() == "distribution"]
        assert_allclose(np.asarray(sa, dtype=float), np.asarray(sb, dtype=float), atol=0)
    (stems,) = [c for c in alone.axes[-1].collections if c.get_gid() == "distribution"]
    tops = sorted(float(s[1][1]) for s in stems.get_segments())
    q = res.bayes_plan.evaluation.distribution
    assert_allclose(tops, np.sort(q[q > 0]), atol=1e-12)
