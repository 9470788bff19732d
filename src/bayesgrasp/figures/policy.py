"""The policy figure: a sensing policy's tree, with the part drawn at each node.

Each action node shows the gripper's jaws and the part as it most likely lies when that
action ends (in the gripper's frame), labelled with the action and its turn; each edge the
reading interval that leads along it and its probability; each leaf the declared
orientation (and part) with its success probability, or a rejection. Where the part lies
is found by replaying the policy (:func:`node_orientations`) from a fine grid of starting
orientations weighted by the prior, reading each width without error: the drawing shows the
state that reaches the node most often.

Noisy sensors give many reading bins of small probability. Branches of a node less likely
than ``min_probability`` are drawn as one edge, "other readings", without their subtrees
(the text form, :func:`~bayesgrasp.planning.policy.policy_text`, and the JSON document keep
every branch).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..model.problem import Problem, nearest_state
from ..planning.policy import Declare, Policy, PolicyNode, Reject
from .canvas import FAIL_COLOR, GOAL_COLOR, JAW_COLOR, PART_COLOR, PART_EDGE, new_figure
from .part import place_part

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["node_orientations", "policy_figure"]

_GRID = 3600  # starting orientations replayed to place the part at each node


def node_orientations(
    problems: Sequence[Problem], policy: Policy, grid: int = _GRID
) -> dict[int, tuple[int, float, float]]:
    """The likeliest (part, orientation) at the end of each action node, by ``id(node)``.

    Replays the policy from ``grid`` evenly spaced starting orientations of every part,
    weighted by the orientation prior's mass around each and by the part prior, reading
    each width exactly. Returns ``id(node) -> (part, orientation, share)`` where ``share`` is
    the weight of that state among the starts that reach the node.
    """
    tally: dict[int, dict[tuple[int, int], float]] = {}
    edges = np.linspace(0.0, 2.0 * math.pi, grid + 1)
    starts = 0.5 * (edges[:-1] + edges[1:])
    for j, pb in enumerate(problems):
        cdf = pb.prior.cdf(edges)
        w = np.diff(cdf) * policy.part_prior[j]
        _walk(pb, j, policy.root, starts.copy(), w, tally)
    out: dict[int, tuple[int, float, float]] = {}
    for key, counts in tally.items():
        (j, i), best = max(counts.items(), key=lambda kv: kv[1])
        out[key] = (j, float(problems[j].states.stable[i]), best / sum(counts.values()))
    return out


def _walk(
    pb: Problem,
    j: int,
    node: PolicyNode,
    theta: Any,
    w: Any,
    tally: dict[int, dict[tuple[int, int], float]],
) -> None:
    th = pb.transfer(node.step.kind)(theta - node.step.alpha)
    states = nearest_state(pb.states, th)
    counts = tally.setdefault(id(node), {})
    for i in np.unique(states):
        counts[(j, int(i))] = counts.get((j, int(i)), 0.0) + float(w[states == i].sum())
    reading = pb.widths[states]
    his = np.array([b.hi for b in node.branches[:-1]])
    which = np.searchsorted(his, reading, side="right")
    for bi, br in enumerate(node.branches):
        m = which == bi
        if m.any() and isinstance(br.next, PolicyNode):
            _walk(pb, j, br.next, th[m], w[m], tally)


@dataclass(slots=True)
class _Box:
    """A drawn node: what it is, where, and its drawn children (edge label, box)."""

    item: PolicyNode | Declare | Reject | None  # None: "other readings"
    label: str
    children: list[tuple[str, _Box]]
    x: float = 0.0
    depth: int = 0


def _num(x: float) -> str:
    return "-inf" if x == -math.inf else "inf" if x == math.inf else f"{x:.3g}"


def _boxes(node: PolicyNode, first: bool, min_p: float, depth: int) -> _Box:
    ang = f"{math.degrees(node.step.alpha):.1f}°"
    label = f"{node.step.kind} at {ang}" if first else f"turn {ang}, {node.step.kind}"
    box = _Box(node, label, [], depth=depth)
    rare = 0.0
    for b in node.branches:
        if b.probability < min_p:
            rare += b.probability
            continue
        edge = f"[{_num(b.lo)}, {_num(b.hi)})\np = {b.probability:.2f}"
        if isinstance(b.next, PolicyNode):
            box.children.append((edge, _boxes(b.next, False, min_p, depth + 1)))
        else:
            box.children.append((edge, _leaf_box(b.next, depth + 1)))
    if rare > 0:
        box.children.append(
            (f"other readings\np = {rare:.2g}", _Box(None, "…", [], depth=depth + 1))
        )
    return box


def _leaf_box(leaf: Declare | Reject, depth: int) -> _Box:
    if isinstance(leaf, Reject):
        return _Box(leaf, "reject", [], depth=depth)
    return _Box(
        leaf,
        f"declare {math.degrees(leaf.orientation):.1f}°\nsuccess {leaf.success_probability:.2f}",
        [],
        depth=depth,
    )


def _layout(box: _Box, next_x: list[float]) -> None:
    if not box.children:
        box.x = next_x[0]
        next_x[0] += 1.0
        return
    for _, c in box.children:
        _layout(c, next_x)
    box.x = 0.5 * (box.children[0][1].x + box.children[-1][1].x)


def _all(box: _Box) -> list[_Box]:
    out = [box]
    for _, c in box.children:
        out += _all(c)
    return out


def _draw_part(
    ax: Axes, problems: Sequence[Problem], j: int, theta: float, x: float, y: float, jaws: bool
) -> None:
    from matplotlib.patches import Polygon as MplPolygon

    placed = place_part(problems[j].part, theta)
    size = max(float(np.ptp(p.part.hull.vertices, axis=0).max()) for p in problems) * 1.15
    s = 0.42 / size
    pts = placed.outline * s + (x, y)
    ax.add_patch(
        MplPolygon(pts, closed=True, fc=PART_COLOR, ec=PART_EDGE, lw=0.8, gid="policy-part")
    )
    if jaws:
        half = 0.5 * placed.width * s
        for sx in (-1, 1):
            ax.plot(
                [x + sx * half] * 2, [y - 0.3, y + 0.3], color=JAW_COLOR, lw=2.0, gid="policy-jaw"
            )


def policy_figure(
    problems: Problem | Sequence[Problem], policy: Policy, min_probability: float = 0.05
) -> Figure:
    """Draw the policy tree with the part at each node (see the module notes).

    Parameters
    ----------
    problems : Problem or sequence of Problem
        The problems the policy was planned for (one per candidate part).
    policy : Policy
    min_probability : float
        Branches less likely than this (given their node) are drawn as one "other
        readings" edge.

    Returns
    -------
    matplotlib.figure.Figure
    """
    pbs = [problems] if isinstance(problems, Problem) else list(problems)
    where = node_orientations(pbs, policy)
    root = _boxes(policy.root, True, min_probability, 0)
    _layout(root, [0.0])
    boxes = _all(root)
    n_leaves = sum(1 for b in boxes if not b.children)
    depth = max(b.depth for b in boxes)
    fig = new_figure(max(6.0, 1.5 * n_leaves), 2.0 + 2.1 * depth)
    ax = fig.add_subplot()
    ax.set_axis_off()
    several = len(pbs) > 1

    def y(b: _Box) -> float:
        return -1.6 * b.depth

    for b in boxes:
        for edge, c in b.children:
            ax.plot([b.x, c.x], [y(b) - 0.45, y(c) + 0.45], color="#999999", lw=0.8, zorder=0)
            # Nearer the child than the parent: a node's edges fan out, and their labels
            # must sit where the edges are as far apart as the children.
            t = 0.7
            ax.text(
                b.x + t * (c.x - b.x), y(b) - 0.45 + t * (y(c) - y(b) + 0.9), edge,
                ha="center", va="center",
                fontsize=6.5, bbox={"fc": "white", "ec": "none", "pad": 0.5}, gid="policy-edge",
            )  # fmt: skip
        if isinstance(b.item, PolicyNode):
            j, theta, _ = where.get(id(b.item), (0, 0.0, 0.0))
            _draw_part(ax, pbs, j, theta, b.x, y(b), True)
            ax.text(b.x + 0.3, y(b), b.label, ha="left", va="center", fontsize=7, gid="policy-node")
        elif isinstance(b.item, Declare):
            _draw_part(ax, pbs, b.item.part, b.item.orientation, b.x, y(b), False)
            text = b.label if not several else f"{b.item.part_name}\n{b.label}"
            ax.text(
                b.x,
                y(b) - 0.5,
                text,
                ha="center",
                va="top",
                fontsize=7,
                color=GOAL_COLOR,
                gid="policy-leaf",
            )
        else:
            color = FAIL_COLOR if isinstance(b.item, Reject) else "#777777"
            ax.text(
                b.x,
                y(b),
                b.label,
                ha="center",
                va="center",
                fontsize=8,
                color=color,
                gid="policy-leaf",
            )
    ax.set_xlim(-0.7, n_leaves - 0.3)
    ax.set_ylim(-1.6 * depth - 1.3, 1.0)
    ax.set_aspect("equal")
    sensor = policy.sensor.spec
    noise = "" if policy.noise is None else f"\nunder {policy.noise.describe()} (exact figures)"
    if policy.payoff is None:
        figures = f"{policy.expected_cost:.3f} (success {policy.success_probability:.3f} a cycle)"
    else:  # the cost is per unit payoff, the success the payoff a cycle earns
        figures = (
            f"{policy.expected_cost:.3f} per unit payoff (expected payoff "
            f"{policy.success_probability:.3f} a cycle)"
        )
    ax.set_title(
        f"{' or '.join(policy.parts)}: Bayes policy, {sensor}, expected cost {figures}{noise}",
        fontsize=9,
    )
    return fig
