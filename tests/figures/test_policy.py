"""The policy figure: one node drawing per action and leaf, the part where the tree says."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bayesgrasp import shapes
from bayesgrasp.cli import main
from bayesgrasp.model import Problem
from bayesgrasp.planning.policy import Declare, PolicyNode, plan_policy
from bayesgrasp.sim.policy import simulate_policy

from .conftest import artists_by_gid


def count(node: PolicyNode) -> tuple[int, int]:
    acts, leaves = 1, 0
    for b in node.branches:
        if isinstance(b.next, PolicyNode):
            a, le = count(b.next)
            acts, leaves = acts + a, leaves + le
        else:
            leaves += 1
    return acts, leaves


def test_every_node_and_leaf_is_drawn() -> None:
    from bayesgrasp.figures.policy import policy_figure

    pb = Problem.build(shapes.load("house"))
    pol = plan_policy(pb, "width", 3)
    fig = policy_figure(pb, pol)
    ax = fig.axes[0]
    acts, leaves = count(pol.root)
    assert len(artists_by_gid(ax, "policy-node")) == acts
    assert len(artists_by_gid(ax, "policy-leaf")) == leaves
    assert len(artists_by_gid(ax, "policy-jaw")) == 2 * acts
    # a part at every action node and declaring leaf
    declares = sum(1 for _, leaf in pol.leaves() if isinstance(leaf, Declare))
    assert len(artists_by_gid(ax, "policy-part")) == acts + declares


def test_node_orientations_agree_with_simulation() -> None:
    """The part drawn at the root is the state the first squeeze leaves most often."""
    from bayesgrasp.figures.policy import node_orientations

    pb = Problem.build(shapes.load("house"))
    pol = plan_policy(pb, "width", 3)
    where = node_orientations([pb], pol)
    j, theta, share = where[id(pol.root)]
    dist = pb.state_distribution(0.0, "squeeze")
    assert j == 0
    assert math.isclose(share, float(dist.max()), rel_tol=1e-3)
    assert math.isclose(theta, float(pb.states.stable[int(np.argmax(dist))]))
    assert simulate_policy(pb, pol, 2000, rng=0).agrees


def test_rare_readings_are_one_edge() -> None:
    from bayesgrasp.figures.policy import policy_figure

    pb = Problem.build(shapes.load("house"))
    pol = plan_policy(pb, "width:0.5,0.1", 2)
    ax = policy_figure(pb, pol, min_probability=0.05).axes[0]
    texts = [t.get_text() for t in artists_by_gid(ax, "policy-edge")]
    assert any(t.startswith("other readings") for t in texts)
    assert len(texts) < len(pol.root.branches)


def test_cli_plot_sense(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "figs"
    argv = ["plot", "rectangle", "--also", "ic-chip", "--sense", "width", "--out", str(out)]
    assert main([*argv, "--image-formats", "png"]) == 0
    assert (out / "policy.png").stat().st_size > 1000
    assert main(["plot", "house", "--also", "key", "--out", str(out)]) == 2
    assert "need --sense" in capsys.readouterr().err


def test_a_payoff_policy_says_its_cost_is_per_unit_payoff() -> None:
    from bayesgrasp.figures.policy import policy_figure
    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy_policy import plan_noisy_policy

    pb = Problem.build(shapes.load("key"))
    states = pb.states.stable
    payoff = np.where(np.isclose(np.degrees(states), 80.63, atol=0.05), 1.0, 0.0)
    payoff[np.isclose(np.degrees(states), 260.63, atol=0.05)] = 0.5
    noise = NoiseModel(TurnNoise("normal", math.radians(2.0)))
    pol = plan_noisy_policy(pb, "width:0.5,0.1", 2, noise, payoff=payoff)
    title = policy_figure(pb, pol).axes[0].get_title()
    assert f"expected cost {pol.expected_cost:.3f} per unit payoff" in title
    assert f"(expected payoff {pol.success_probability:.3f} a cycle)" in title
    assert "under turn error normal:2 deg (exact figures)" in title
    plain = policy_figure(pb, plan_policy(pb, "width:0.5,0.1", 2)).axes[0].get_title()
    assert "payoff" not in plain and "(success " in plain
