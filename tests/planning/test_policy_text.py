"""The policy's text form: readings worded for a person, and small branches folded."""

from __future__ import annotations

import re

import pytest

from bayesgrasp import shapes
from bayesgrasp.errors import PlanningError
from bayesgrasp.model import Problem
from bayesgrasp.planning.policy import Policy, PolicyNode, plan_policy, policy_text


@pytest.fixture(scope="module")
def noisy() -> Policy:
    return plan_policy(Problem.build(shapes.load("house")), "width:0.5,0.1", 2)


def shown_and_folded(node: PolicyNode, t: float) -> tuple[int, int]:
    """Branches the text should print, and those it should fold, walking shown nodes only."""
    shown = folded = 0
    for b in node.branches:
        if b.probability < t:
            folded += 1
            continue
        shown += 1
        if isinstance(b.next, PolicyNode):
            s, f = shown_and_folded(b.next, t)
            shown, folded = shown + s, folded + f
    return shown, folded


@pytest.mark.parametrize("t", [0.0, 1e-6, 0.01, 0.2])
def test_folding_prints_exactly_the_branches_above_the_threshold(noisy: Policy, t: float) -> None:
    text = policy_text(noisy, min_probability=t)
    shown, folded = shown_and_folded(noisy.root, t)
    assert sum(line.lstrip().startswith("if ") for line in text.splitlines()) == shown
    counts = [int(m) for m in re.findall(r"\((\d+) more reading intervals?", text)]
    assert sum(counts) == folded
    if t == 0.0:
        assert folded == 0 and "more reading" not in text
    else:
        assert folded > 0  # the noisy tree has bins of tiny probability


def test_no_nonzero_probability_reads_as_zero(noisy: Policy) -> None:
    text = policy_text(noisy)
    assert "p = 0.00)" not in text
    assert re.search(r"p = \d\.\de-\d\d\)", text)  # small ones in two significant digits


def test_unbounded_readings_are_worded() -> None:
    text = policy_text(plan_policy(Problem.build(shapes.load("rectangle")), "width", 2))
    assert "inf" not in text
    assert re.search(r"reads below [\d.]+ mm", text) and re.search(r"reads [\d.]+ mm or more", text)


@pytest.mark.parametrize("t", [-0.1, 1.5, float("nan")])
def test_bad_threshold_is_a_clear_error(noisy: Policy, t: float) -> None:
    with pytest.raises(PlanningError, match="min_probability"):
        policy_text(noisy, min_probability=t)


def test_candidate_parts_in_different_units_are_refused() -> None:
    from bayesgrasp.geometry import Part
    from bayesgrasp.model.sensing import StateSpace

    tri = [(0.0, 0.0), (4.0, 0.0), (1.0, 3.0)]
    mm = Problem.build(Part.from_points(tri, name="a", units="mm"))
    inch = Problem.build(Part.from_points(tri, name="b", units="in"))
    bare = Problem.build(Part.from_points(tri, name="c"))
    with pytest.raises(PlanningError, match=r"mm \(a\), in \(b\)"):
        plan_policy([mm, inch], "width", 1)
    with pytest.raises(PlanningError, match="'c' has no units"):  # never mixed silently
        StateSpace.build([mm, bare])
    assert StateSpace.build([bare, bare]).n_parts == 2  # no units at all: one scale


def test_plan_sense_folds_the_printed_tree(capsys: pytest.CaptureFixture[str]) -> None:
    from bayesgrasp.cli import main

    pol = plan_policy(Problem.build(shapes.load("house")), "width:0.5,0.1", 2)
    argv = ["plan", "house", "--sense", "width:0.5,0.1", "--max-actions", "2"]
    for given, t in (([], 0.01), (["--fold-below", "0"], 0.0), (["--fold-below", "0.2"], 0.2)):
        assert main([*argv, *given]) == 0
        tree = capsys.readouterr().out.rsplit("\n", 2)[0]  # without the figures' line
        assert tree == policy_text(pol, min_probability=t)
    assert main([*argv, "--fold-below", "1.5"]) == 2


def test_huge_part_weights_are_normalised_without_overflow() -> None:
    from bayesgrasp.geometry import Part

    tri = Problem.build(Part.from_points([(0.0, 0.0), (4.0, 0.0), (1.0, 3.0)], name="a"))
    rect = Problem.build(Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1)], name="b"))
    big = plan_policy([tri, rect], "width", 2, part_prior="1e308,1e308")
    assert big.part_prior == (0.5, 0.5)
    assert big.expected_cost == plan_policy([tri, rect], "width", 2).expected_cost
