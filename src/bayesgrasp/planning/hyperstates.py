"""Hyperstates of the breadth-first baseline: the node store of its search, and its roots.

A hyperstate is a probability vector over the states (see :mod:`bayesgrasp.planning.bfs`);
:class:`HyperstateSearch` holds the nodes, their keys (duplicates merged), their children
under each action class and the highest probability a root can reach; :func:`make_roots`
makes one root per first action kind and angle; :func:`check_tables` refuses parts whose
action-class tables would not fit.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..geometry.transfer import TransferFunction
from ..model.prior import UniformPrior
from ..model.problem import Problem, critical_angles, nearest_state
from .result import (
    plan_actions,
)

__all__ = ["HyperstateSearch", "Root", "check_tables", "make_roots", "orbits"]

_QUANT = float(2**40)  # distributions are compared after rounding to multiples of 2**-40
_BLOCK = 1 << 16  # entries of the (classes, K) blocks of children made at a time
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True)
class Root:
    """One root of the search: the first action kind and angle, and what it does to the prior."""

    kind: str
    angle: float
    masses: FloatArray  # (K_t,) prior mass of each basin of the first action's transfer
    atom_state: IntArray  # (K_t,) state index of each of its stable orientations


class HyperstateSearch:
    """Node store and the operations both searches share (breadth-first and best-first)."""

    def __init__(self, problem: Problem, roots: list[Root]) -> None:
        self.problem = problem
        self.kinds = problem.action_kinds
        self.actions = plan_actions(problem, self.kinds)
        # Probability tolerance of "reached the target" (as the exact planner).
        self.eps = problem.part.hull.tol.probability
        states = problem.states
        self.k = states.n_states
        self.classes = [problem.classes(a) for a in self.actions]
        self.rows = max(1, _BLOCK // self.k)  # children made at a time
        self.roots = roots
        # Goal: fold states that the goal counts as one (orbits under 2 pi / g).
        g = problem.goal_group
        self.group = g
        self.orbit = orbits(states.stable, g, states)  # (K,) orbit id of each state
        self.n_orbits = int(self.orbit.max()) + 1
        self.onehot = (
            None if g == 1 else np.eye(self.n_orbits)[self.orbit]  # (K, O)
        )
        # Merge distributions that differ by a turn of the gripper by pi: when every
        # action's gripper turned by pi is the same gripper (squeezes).
        half = self.k // 2
        self.shift = 0
        if (
            all(math.isclose(a.gripper_period, math.pi) for a in self.actions)
            and self.k % 2 == 0
            and np.allclose(
                states.stable[half:] - states.stable[:half], math.pi, atol=1e3 * states.angle_tol
            )
        ):
            self.shift = half
        self.turn = np.roll(np.arange(self.k), self.shift)  # state order after a turn by pi
        # Node store (parallel lists).
        self.dist: list[FloatArray] = []
        self.mapping: list[IntArray] = []  # state of each root atom
        self.parent: list[int] = []
        self.step: list[tuple[int, int]] = []  # (kind index, class index); (-1, r) for roots
        self.root_of: list[int] = []
        self.depth: list[int] = []
        self.prob: list[float] = []
        self.kinds_of: list[tuple[str, ...]] = []  # action kinds from the root to the node
        self.attempt: list[float] = []  # cost of one attempt of the node's plan
        self.step_cost = [problem.cost.action_cost(t) for t in self.kinds]

    # -- distributions ------------------------------------------------------------------
    def goal_prob(self, dist: FloatArray) -> FloatArray:
        """Success probability of each distribution (rows of ``dist``, or one vector)."""
        folded = dist if self.onehot is None else dist @ self.onehot
        return np.asarray(folded.max(axis=-1), dtype=np.float64)

    def goal_state(self, dist: FloatArray) -> int:
        """The state the verification accepts: the most probable of the best orbit."""
        if self.onehot is None:
            return int(np.argmax(dist))
        best = int(np.argmax(dist @ self.onehot))
        members = np.flatnonzero(self.orbit == best)
        return int(members[np.argmax(dist[members])])

    def keys(self, dist: FloatArray) -> list[bytes]:
        """Hashable keys of distributions (rows), equal for identical hyperstates."""
        q = np.rint(np.atleast_2d(dist) * _QUANT).astype(np.int64)
        row = np.dtype((np.void, 8 * self.k))
        plain = cast(list[bytes], np.ascontiguousarray(q).view(row).ravel().tolist())
        if not self.shift:
            return plain
        alt = cast(list[bytes], np.ascontiguousarray(q[:, self.turn]).view(row).ravel().tolist())
        return [min(a, b) for a, b in zip(plain, alt, strict=True)]

    def children(
        self, dist: FloatArray, ti: int, start: int = 0, stop: int | None = None
    ) -> FloatArray:
        """Distributions after classes ``start:stop`` of action kind ``ti``: shape (B, K).

        Each row is the bincount of the state masses in state order, the same sums whatever
        rows are made together.
        """
        t = self.classes[ti].transfer[start:stop]  # (B, K)
        b = t.shape[0]
        idx = (t + self.k * np.arange(b)[:, None]).ravel()
        w = np.broadcast_to(dist, t.shape).ravel()
        out = np.bincount(idx, weights=w, minlength=b * self.k).reshape(b, self.k)
        return np.asarray(out, dtype=np.float64)

    def blocks(self, dist: FloatArray, ti: int) -> Iterator[tuple[int, FloatArray]]:
        """The children of action kind ``ti`` a block at a time: (first class, (B, K) rows).

        A is up to K^2 / 4 for a squeeze: all children at once, with their keys, would take
        several A K floats (280 MB at K = 282) where a block takes ``_BLOCK``.
        """
        n = len(self.classes[ti].mid)
        for start in range(0, n, self.rows):
            yield start, self.children(dist, ti, start, start + self.rows)

    # -- nodes --------------------------------------------------------------------------
    def add_root(self, r: int) -> int:
        """Add the node of root ``r`` (its prior folded onto the states); its index."""
        root = self.roots[r]
        dist = np.asarray(
            np.bincount(root.atom_state, weights=root.masses, minlength=self.k), dtype=np.float64
        )
        p = float(self.goal_prob(dist))
        return self._add(dist, root.atom_state, -1, (-1, r), r, 1, p, (root.kind,))

    def add_child(self, u: int, ti: int, a: int, dist: FloatArray, p: float) -> int:
        """Add the child of node ``u`` by class ``a`` of action kind ``ti``; its index."""
        mapping = self.classes[ti].transfer[a][self.mapping[u]]
        kinds = (*self.kinds_of[u], self.kinds[ti])
        # A copy: a row of a block is a view that would keep the whole block alive.
        return self._add(
            dist.copy(), mapping, u, (ti, a), self.root_of[u], self.depth[u] + 1, p, kinds
        )

    def _add(
        self,
        dist: FloatArray,
        mapping: IntArray,
        parent: int,
        step: tuple[int, int],
        root: int,
        depth: int,
        p: float,
        kinds: tuple[str, ...],
    ) -> int:
        self.dist.append(dist)
        self.mapping.append(mapping)
        self.parent.append(parent)
        self.step.append(step)
        self.root_of.append(root)
        self.depth.append(depth)
        self.prob.append(p)
        self.kinds_of.append(kinds)
        self.attempt.append(
            self.problem.cost.attempt_cost(kinds)
            if parent < 0
            else self.attempt[parent] + self.step_cost[step[0]]
        )
        return len(self.dist) - 1

    def path(self, v: int) -> list[tuple[int, int]]:
        """Actions (kind index, class index) from the root to ``v``, first first."""
        out = []
        while self.parent[v] >= 0:
            out.append(self.step[v])
            v = self.parent[v]
        return out[::-1]

    def attainable(self, r: int) -> float:
        """Highest success probability reachable from root ``r`` (see the module notes)."""
        root = self.roots[r]
        dist = np.bincount(root.atom_state, weights=root.masses, minlength=self.k)
        transfers = self.problem.transfers
        circ = TWO_PI / self.group
        cap = min(max(transfers[t].period for t in self.kinds), circ)
        stable = self.problem.states.stable
        # Fold onto [0, circ): one point per orbit carrying the orbit's mass.
        folded = np.bincount(self.orbit, weights=dist, minlength=self.n_orbits)
        pos = np.zeros(self.n_orbits)
        pos[self.orbit] = np.mod(stable, circ)
        order = np.argsort(pos)
        x = pos[order]
        m = folded[order]
        n = len(x)
        ext_x = np.concatenate([x, x + circ])
        cum = np.concatenate([[0.0], np.cumsum(np.concatenate([m, m]))])
        tol = self.problem.states.angle_tol
        # Run of points starting at i with span strictly below cap: an open arc holds it.
        last = np.searchsorted(ext_x, x + cap - tol, side="left") - 1
        last = np.minimum(last, np.arange(n) + n - 1)
        return float(np.max(cum[last + 1] - cum[np.arange(n)]))


def check_tables(problem: Problem, limit: int) -> None:
    """Raise a PlanningError if the action-class tables would hold more than ``limit`` entries.

    Counts the classes from the critical angles (K K_t floats) without making the tables,
    unless the critical angles alone pass the limit.
    """
    k = problem.states.n_states
    entries = 0
    for action in plan_actions(problem, problem.action_kinds):
        f = problem.transfers[action.name]
        if k * f.n_states > limit:
            raise PlanningError(
                f"the breadth-first baseline cannot plan this part: {k} states and "
                f"{f.n_states} {action.name} basins make {k * f.n_states} critical angles, "
                f"more than `table_limit` = {limit} (use the exact planner)"
            )
        n_classes = len(critical_angles(problem.states, f, action.gripper_period))
        entries += n_classes * k
        if entries > limit:
            raise PlanningError(
                f"the breadth-first baseline cannot plan this part: its action-class tables "
                f"need {entries} entries ({entries * 8 / 2**20:.0f} MiB; {n_classes} "
                f"{action.name} classes x {k} states), more than `table_limit` = {limit} "
                "(use the exact planner)"
            )


def orbits(stable: FloatArray, group: int, states: TransferFunction) -> IntArray:
    """Orbit id of each state under rotations by ``2 pi / group`` (0.. in order)."""
    k = len(stable)
    if group == 1:
        return np.arange(k, dtype=np.intp)
    shifted = stable[None, :] + TWO_PI * np.arange(group)[:, None] / group  # (g, K)
    rep = nearest_state(states, shifted).min(axis=0)  # (K,) smallest index in the orbit
    _, ids = np.unique(rep, return_inverse=True)
    return np.asarray(ids, dtype=np.intp)


def make_roots(
    problem: Problem, max_actions: int | None, first_angles: Sequence[float] | None
) -> list[Root]:
    """One root per (first action kind, first angle)."""
    pairs: list[tuple[str, float]]
    if first_angles is not None:
        angles = [float(a) for a in first_angles]
        if not angles or not all(math.isfinite(a) for a in angles):
            raise PlanningError(
                f"`first_angles` must be a non-empty list of finite angles; got {first_angles!r}"
            )
        pairs = [(t, a) for t in problem.action_kinds for a in angles]
    elif isinstance(problem.prior, UniformPrior):
        pairs = [(t, 0.0) for t in problem.action_kinds]
    else:
        from .exact import plan_exact

        exact = plan_exact(problem, max_actions=max_actions)
        pairs = [(o.steps[0].kind, o.first_angle) for o in exact.options]
    roots = []
    for kind, angle in dict.fromkeys(pairs):
        f = problem.transfers[kind]
        masses = np.asarray(
            problem.prior.mass(f.basin_lo + angle, f.basin_hi + angle), dtype=np.float64
        )
        atom_state = (
            np.arange(f.n_states, dtype=np.intp)
            if f is problem.states  # the squeeze: its stable orientations are the states
            else nearest_state(problem.states, f.stable)
        )
        roots.append(Root(kind, angle, masses, atom_state))
    return roots
