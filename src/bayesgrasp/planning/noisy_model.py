"""The noisy model of a policy's state space, and the mutable trees its refinement turns.

What the noise-aware policy planner (:mod:`bayesgrasp.planning.noisy_policy`) computes with:

- :class:`NoisyModel`: the joint noisy transition matrices ``M_t(alpha)`` of every candidate
  part (block-diagonal), the first actions' beliefs, the reading likelihoods of the sensor,
  the candidate turns of each kind and the lines ``left M(alpha) right`` the refinement
  maximises;
- :class:`MutableNode`: a policy tree whose turns can change (:func:`mutable_tree`,
  :func:`linear_tree`), and :func:`exact_figures`, its exact figures under the model by the
  evaluator of every strategy (:func:`~bayesgrasp.planning.evaluation.evaluate_tree`).

Examples
--------
>>> import math
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.model.noise import TurnNoise
>>> from bayesgrasp.model.sensing import parse_sensor
>>> rect = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
>>> model = NoisyModel(
...     StateSpace.build(rect), parse_sensor("width"), NoiseModel(TurnNoise("normal", 0.05))
... )
>>> tree = linear_tree(model, ["squeeze", "squeeze"], [0.0, 0.3], 0)
>>> ev = exact_figures(model, tree, 0.0)
>>> round(ev.success_probability, 4), ev.expected_actions
(0.1475, 2.0)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.noise import NoiseModel, NoisyTransitions
from ..model.sensing import StateSpace, WidthSensor
from ..model.states import nearest_state
from .evaluation import Evaluation, evaluate_tree
from .policy_tree import Branch, Declare, PolicyNode, Reject
from .result import PlanStep

__all__ = [
    "MutableNode",
    "NoisyModel",
    "exact_figures",
    "first_of_each_matrix",
    "first_of_each_turn",
    "linear_tree",
    "mutable_tree",
    "tree_nodes",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

# -- the noisy model of a state space -------------------------------------------------------


_SAME_TURN = 1e-9
"""Candidate turns closer than this (radians, modulo 2 pi) are one turn."""


def first_of_each_turn(turns: FloatArray, tol: float) -> IntArray:
    """Indices of the first of each group of turns within ``tol`` of each other, mod 2 pi.

    In the order of ``turns`` (the first of a group is kept, the others dropped).

    Examples
    --------
    >>> first_of_each_turn(np.array([math.pi, 0.5, -math.pi, 0.5 + 1e-12, 1.0]), 1e-9).tolist()
    [0, 1, 4]
    """
    if len(turns) < 2:
        return np.arange(len(turns), dtype=np.intp)
    k = np.mod(turns, TWO_PI)
    srt = np.argsort(k, kind="stable")
    ks = k[srt]
    group = np.cumsum(np.append(True, np.diff(ks) > tol)) - 1
    if ks[0] + TWO_PI - ks[-1] <= tol:  # the groups at 0 and just below 2 pi are one
        group[group == group[-1]] = 0
    ids = np.empty_like(group)
    ids[srt] = group
    _, first = np.unique(ids, return_index=True)
    return np.sort(first).astype(np.intp)


def first_of_each_matrix(mats: FloatArray) -> IntArray:
    """Indices of the first of each group of equal matrices ``mats`` (A, N, N), in order.

    Examples
    --------
    >>> m = np.array([np.eye(2), np.ones((2, 2)) / 2, np.eye(2)])
    >>> first_of_each_matrix(m).tolist()
    [0, 1]
    """
    if len(mats) < 2:
        return np.arange(len(mats), dtype=np.intp)
    _, first = np.unique(mats.reshape(len(mats), -1), axis=0, return_index=True)
    return np.sort(first).astype(np.intp)


class NoisyModel:
    """Joint noisy matrices, first actions and reading likelihoods of a state space."""

    def __init__(self, space: StateSpace, sensor: WidthSensor, noise: NoiseModel) -> None:
        self.space = space
        self.noise = noise
        self.nts = [NoisyTransitions(p, noise) for p in space.problems]
        self.bins = space.bins(sensor)
        self.goal = space.success_matrix()
        self.payoff: FloatArray | None = None  # one part's payoff vector, if any
        self.cost = space.problems[0].cost
        self.n = space.n_states
        self.blocks = [
            (int(o), int(o) + p.n_states)
            for o, p in zip(space.offsets[: space.n_parts], space.problems, strict=True)
        ]
        self._one: dict[tuple[str, float], FloatArray] = {}
        # called as an exact evaluation goes (it may raise: a planner's time bound)
        self.check: Callable[[], None] | None = None

    def matrix(self, kind: str, alpha: float) -> FloatArray:
        """The (N, N) matrix of one turn (kept: refinement asks for the same turns often)."""
        key = (kind, float(alpha))
        hit = self._one.get(key)
        if hit is None:
            hit = self._one[key] = self.matrices(kind, np.array([alpha]))[0]
        return hit

    def matrices(self, kind: str, alphas: FloatArray) -> FloatArray:
        """Block-diagonal (A, N, N) matrices of turns ``alphas``."""
        out = np.zeros((len(alphas), self.n, self.n))
        for (lo, hi), nt in zip(self.blocks, self.nts, strict=True):
            out[:, lo:hi, lo:hi] = nt.matrices(kind, alphas)
        return out

    def candidates(
        self, kind: str, mid: FloatArray, half: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """The candidate turns of ``kind`` and their half widths, widest first.

        The noise-free classes' middles ``mid`` (half widths ``half``); with contact
        asynchrony also the middles of the common refinement of the classes of every way
        the action may go (each turn at which some state's basin changes in one of them):
        with exact turns ``M(alpha)`` is constant on each such class. A turn is a candidate
        once: a noise-free class that no other way of the action splits is also a class of
        the refinement, and a middle at pi is one at -pi; the widest class of a turn is kept.
        """
        comps = [(nt, c) for nt in self.nts for c in nt.components(kind)]
        if len(comps) == len(self.nts):  # one way to go: the noise-free classes
            return mid, half
        crit = np.concatenate(
            [(nt.stable[:, None] - c.offset - c.hi[None, :]).ravel() for nt, c in comps]
        )
        c = np.unique(np.mod(crit, TWO_PI))
        widths = np.diff(np.append(c, c[0] + TWO_PI))
        keep = widths > 1e-9
        c, widths = c[keep], widths[keep]
        more = np.mod(c + widths / 2 + math.pi, TWO_PI) - math.pi
        mids = np.concatenate([mid, more])
        halves = np.concatenate([half, widths / 2])
        order = np.argsort(-halves, kind="stable")
        mids, halves = mids[order], halves[order]
        once = first_of_each_turn(mids, _SAME_TURN)
        return np.asarray(mids[once]), np.asarray(halves[once])

    def initial(self, kind: str, angle: float) -> FloatArray:
        """Joint distribution after the first action at world angle ``angle``."""
        return np.concatenate(
            [
                w * nt.initial(kind, angle)
                for w, nt in zip(self.space.part_prior, self.nts, strict=True)
            ]
        )

    def line(
        self, kind: str, left: FloatArray, right: FloatArray, alphas: FloatArray
    ) -> FloatArray:
        """``left M(alpha) right`` for many turns."""
        out = np.zeros(len(alphas))
        for (lo, hi), nt in zip(self.blocks, self.nts, strict=True):
            if np.any(left[lo:hi] > 0):
                out += nt.line(kind, left[lo:hi], right[lo:hi], alphas)
        return out

    def boundaries(self, kind: str, left: FloatArray) -> FloatArray:
        """Turns that put a state of positive ``left`` mass on a basin boundary of ``kind``.

        Every way the action may go counts, whether or not both sides of the boundary are
        worth the same: a squeeze at an unstable equilibrium goes either way, or jams.
        """
        pts = [
            nt.boundary_turns(kind, np.flatnonzero(left[lo:hi] > 0))
            for (lo, hi), nt in zip(self.blocks, self.nts, strict=True)
            if np.any(left[lo:hi] > 0)
        ]
        return np.concatenate(pts) if pts else np.zeros(0)

    def critical(self, kind: str, left: FloatArray, right: FloatArray) -> FloatArray:
        """Turns where ``left M(alpha) right`` may change with exact turns."""
        pts = [
            nt.critical(kind, left[lo:hi], right[lo:hi])
            for (lo, hi), nt in zip(self.blocks, self.nts, strict=True)
            if np.any(left[lo:hi] > 0)
        ]
        return np.concatenate(pts) if pts else np.zeros(0)

    def branch_bins(self, branches: Sequence[Branch]) -> list[IntArray]:
        """The reading bins of each branch (a branch's interval is a union of bins)."""
        lo, hi = self.bins.lo, self.bins.hi
        return [np.flatnonzero((lo >= b.lo) & (hi <= b.hi)) for b in branches]

    def earned(self, leaf: Declare) -> FloatArray:
        """What a declaring leaf earns in each state: the payoff, or its goal's success set."""
        if self.payoff is not None:
            return self.payoff
        return np.asarray(self.goal[self.state(leaf)], dtype=np.float64)

    def state(self, leaf: Declare) -> int:
        """The joint state a declaration names."""
        pb = self.space.problems[leaf.part]
        i = int(nearest_state(pb.states, np.array([leaf.orientation]))[0])
        return int(self.space.offsets[leaf.part]) + i


# -- a mutable tree for refinement and evaluation ------------------------------------------


@dataclass(slots=True)
class MutableNode:
    """A policy node whose turn ``alpha`` may change, with each branch's reading likelihood."""

    kind: str
    alpha: float
    branches: list[Branch]  # lo, hi, and (probability, next) refreshed by evaluation
    bins: list[IntArray]
    children: list[MutableNode | Declare | Reject]
    margin: float
    lik: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))  # (N, branches)


def mutable_tree(node: PolicyNode, model: NoisyModel) -> MutableNode:
    """The tree of ``node`` as mutable nodes (each branch's bins and likelihoods computed)."""
    bins = model.branch_bins(node.branches)
    kids: list[MutableNode | Declare | Reject] = [
        mutable_tree(b.next, model) if isinstance(b.next, PolicyNode) else b.next
        for b in node.branches
    ]
    lik = np.stack([model.bins.likelihood[:, ix].sum(axis=1) for ix in bins], axis=1)
    return MutableNode(
        node.step.kind, node.step.alpha, list(node.branches), bins, kids, node.margin, lik
    )


def tree_nodes(node: MutableNode, first: bool = True) -> list[tuple[MutableNode, bool]]:
    """Every node of the tree, depth first, and whether it is the root (``first``)."""
    out = [(node, first)]
    for k in node.children:
        if isinstance(k, MutableNode):
            out += tree_nodes(k, False)
    return out


def _frozen(node: MutableNode, model: NoisyModel) -> PolicyNode:
    """A subtree no history reaches (probabilities 0)."""
    kids = [_frozen(k, model) if isinstance(k, MutableNode) else k for k in node.children]
    return PolicyNode(
        PlanStep(node.kind, node.alpha),
        tuple(Branch(b.lo, b.hi, 0.0, k) for b, k in zip(node.branches, kids, strict=True)),
        node.margin,
    )


def exact_figures(model: NoisyModel, root: MutableNode, first_angle: float) -> Evaluation:
    """Exact figures of a tree: :func:`.evaluation.evaluate_tree` under the model's matrices.

    The model's ``check`` (if any) is called as the evaluation goes (a time bound).
    """
    tree = _frozen(root, model)
    tree = dataclasses.replace(tree, step=PlanStep(tree.step.kind, first_angle))
    return evaluate_tree(model.space, tree, model, model.bins, model.payoff, model.check)


def linear_tree(
    model: NoisyModel, kinds: Sequence[str], angles: Sequence[float], final: int
) -> MutableNode:
    """A plan as a tree: one branch on every reading, then declare state ``final``."""
    part, theta = model.space.stable(final)
    leaf: MutableNode | Declare = Declare(part, model.space.names[part], float(theta), 0.0)
    whole = Branch(-math.inf, math.inf, 1.0, Reject())
    bins = model.branch_bins([whole])
    lik = np.ones((model.n, 1))
    for t, a in zip(kinds[::-1], angles[::-1], strict=True):
        leaf = MutableNode(t, float(a), [whole], bins, [leaf], 0.0, lik)
    if not isinstance(leaf, MutableNode):  # pragma: no cover - a plan has a step
        raise PlanningError("internal error: an empty plan")
    return leaf
