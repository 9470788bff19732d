"""The seed's planner (section 5): breadth-first search over hyperstates, kept as a baseline.

A *hyperstate* is a probability vector over the states (the stable orientations of the
squeeze function, ``problem.states.stable``) in the frame of the last action. The root is
the distribution after the first action; each node has one child per action class
(:meth:`~bayesgrasp.model.problem.Problem.classes`, for every kind in ``problem.action_kinds``):
class ``a`` sends the mass of state ``i`` to state ``transfer[a, i]``. The search goes level
by level and stops at the first node that reaches the highest attainable success
probability; after ``node_limit`` nodes (the seed's 1000) it gives up and runs a second,
best-first search that always expands the node of highest success probability (the seed:
"a best-first heuristic that hillclimbed on the node with the maximal probability").

Choices the seed leaves open, and what this module does:

- *Merging duplicates.* The seed calls the search space a tree of distributions. Here a
  hyperstate already generated (at any depth) is not generated again: its subtree would
  repeat one already searched. "Identical" means the same distribution of the part
  relative to the *physical* gripper: a squeeze gripper turned by pi is the same gripper, so
  two distributions that differ by a shift of pi are merged when every action kind has
  gripper period pi (:attr:`~bayesgrasp.model.actions.Action.gripper_period`: squeezes; a
  push-grasp has a pushing side, so then only equal vectors merge). Without
  merging, most random hexagons would pass 1000 nodes at depth 3, against the seed's 1%;
  :func:`search_bfs` also reports the count a search *without* merging would reach
  (``tree_nodes``), computed exactly by finding the first goal node of the unmerged tree in
  breadth-first order.
- *Node count.* ``nodes`` counts distinct hyperstates generated, roots included, up to and
  including the first one that reaches the target.
- *Highest attainable probability.* From a root distribution ``q``: the largest mass of
  states inside an open arc of length ``cap`` (the largest transfer-function period, or
  ``2 pi / g`` for a goal counting ``g`` symmetric copies as one), after folding the
  distribution modulo ``2 pi / g``. With the uniform prior and one goal this is
  ``period / (2 pi)`` (the seed's 0.5).
- *The first action.* Under the uniform prior its angle does not matter and the root is made
  at angle 0 (the seed). Under another prior the angle is a continuous choice that the seed
  never had to make: by default the search gets one root per distinct first angle of the
  exact planner's plans (so it searches everything after the first action); pass
  ``first_angles`` to search a grid instead.
- *The best k-action plan.* Any action keeps or raises the success probability (a
  deterministic action moves all the mass of the goal state to one state), so the best plan
  of k actions is the best node at depth at most k, padded with actions that keep its
  distribution (a squeeze in the class of ``alpha = 0``). Below the final depth the least
  expected cost wins; at the final depth the highest probability, then the least cost
  (as :func:`~bayesgrasp.planning.exact.plan_exact` does). With one action kind that
  is just the highest probability at every depth.
- *Angles and tolerance.* Each action is the midpoint of its class interval; a squeeze
  angle is turned by pi into ``(-pi/2, pi/2]`` when needed (the same gripper; the final
  orientation follows; :func:`~bayesgrasp.planning.result.short_turns`). The reported
  tolerance is the *class margin*: half the width of the narrowest chosen class. Within it
  every state, not only the goal's, goes where the plan says, so it is a lower bound on the
  exact planner's tolerance.
"""

from __future__ import annotations

import heapq
import logging
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
    PlanOption,
    PlanResult,
    check_max_actions,
    choose_indices,
    plan_actions,
    short_turns,
)

__all__ = ["BfsResult", "SearchStats", "plan_bfs", "search_bfs"]

logger = logging.getLogger(__name__)

_QUANT = float(2**40)  # distributions are compared after rounding to multiples of 2**-40
_BLOCK = 1 << 16  # entries of the (classes, K) blocks of children made at a time
TABLE_LIMIT = 1 << 25  # default `table_limit`: 256 MiB of action-class table (intp)
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True)
class SearchStats:
    """What the search did.

    Attributes
    ----------
    nodes : int
        Distinct hyperstates generated, both searches together.
    bfs_nodes : int
        Generated by the breadth-first search (at most ``node_limit``).
    fallback_nodes : int
        Generated by the best-first fallback (0 when it did not run).
    completed : bool
        The breadth-first search ended without reaching the node limit (it reached the
        target, or the depth limit ``max_actions``); its plans are then optimal.
    reached : bool
        A node reached the target probability (in either search).
    depth : int
        Length of the longest reported plan.
    target : float
        Highest attainable success probability from the roots.
    tree_nodes : int or None
        Nodes a breadth-first search that merges nothing would generate up to and
        including its first node at the target (``None`` when not computed: the search did
        not complete, or ``tree_count=False``).
    """

    nodes: int
    bfs_nodes: int
    fallback_nodes: int
    completed: bool
    reached: bool
    depth: int
    target: float
    tree_nodes: int | None


@dataclass(frozen=True, slots=True, eq=False)
class BfsResult:
    """The plan report of the search and its statistics."""

    report: PlanResult
    stats: SearchStats


@dataclass(frozen=True, slots=True)
class _Root:
    kind: str
    angle: float
    masses: FloatArray  # (K_t,) prior mass of each basin of the first action's transfer
    atom_state: IntArray  # (K_t,) state index of each of its stable orientations


class _Search:
    """Node store and the operations both searches share."""

    def __init__(self, problem: Problem, roots: list[_Root]) -> None:
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
        self.orbit = _orbits(states.stable, g, states)  # (K,) orbit id of each state
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
        root = self.roots[r]
        dist = np.asarray(
            np.bincount(root.atom_state, weights=root.masses, minlength=self.k), dtype=np.float64
        )
        p = float(self.goal_prob(dist))
        return self._add(dist, root.atom_state, -1, (-1, r), r, 1, p, (root.kind,))

    def add_child(self, u: int, ti: int, a: int, dist: FloatArray, p: float) -> int:
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


def _check_tables(problem: Problem, limit: int) -> None:
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


def _orbits(stable: FloatArray, group: int, states: TransferFunction) -> IntArray:
    """Orbit id of each state under rotations by ``2 pi / group`` (0.. in order)."""
    k = len(stable)
    if group == 1:
        return np.arange(k, dtype=np.intp)
    shifted = stable[None, :] + TWO_PI * np.arange(group)[:, None] / group  # (g, K)
    rep = nearest_state(states, shifted).min(axis=0)  # (K,) smallest index in the orbit
    _, ids = np.unique(rep, return_inverse=True)
    return np.asarray(ids, dtype=np.intp)


def _make_roots(
    problem: Problem, max_actions: int | None, first_angles: Sequence[float] | None
) -> list[_Root]:
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
        roots.append(_Root(kind, angle, masses, atom_state))
    return roots


def search_bfs(
    problem: Problem,
    max_actions: int | None = None,
    *,
    node_limit: int = 1000,
    fallback_limit: int = 1000,
    first_angles: Sequence[float] | None = None,
    tree_count: bool = True,
    merge: bool = True,
    table_limit: int = TABLE_LIMIT,
) -> BfsResult:
    """The seed's breadth-first search, with its node limit and best-first fallback.

    See the module notes for the choices the seed leaves open.

    Parameters
    ----------
    problem : Problem
    max_actions : int, optional
        Search no deeper than this many actions.
    node_limit : int
        Hyperstates the breadth-first search may generate (the seed: 1000).
    fallback_limit : int
        Hyperstates the best-first fallback may generate.
    first_angles : sequence of float, optional
        World gripper angles of the first action to search from (one root each; default:
        0 under the uniform prior, else the exact planner's first angles).
    tree_count : bool
        Also count the nodes of a search that merges no duplicates (``tree_nodes``).
    merge : bool
        Merge identical hyperstates (default). ``False`` searches the literal tree: every
        node is kept, also in the fallback.
    table_limit : int
        Entries the action-class tables may hold (``A x K`` summed over the action kinds,
        8 bytes each; default ``2**25``, 256 MiB). A squeeze has up to ``K^2 / 4`` classes,
        so the tables grow as ``K^3``: about 8 MB at K = 100, 45 MB at K = 282, past the
        default near K = 500.

    Returns
    -------
    BfsResult

    Raises
    ------
    PlanningError
        If ``max_actions``, ``node_limit`` or ``fallback_limit`` is less than 1, the
        problem has a gripper ``accuracy`` (the baseline assumes exact turns), or its
        action-class tables would pass ``table_limit`` (the exact planner needs none).

    Notes
    -----
    Memory: the tables (at most ``table_limit`` entries), a block of ``2**16`` child
    entries at a time, and ``O(K)`` for each node generated: both searches together keep
    at most ``node_limit + fallback_limit`` nodes (plus the roots). The count of the
    unmerged tree (``tree_nodes``) is a number, not a tree: it is found by a depth-first
    walk that remembers the hyperstates (at a depth) that lead to no goal, hyperstates the
    completed merged search has already met, and holds one block of children per depth.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
    >>> res = search_bfs(Problem.build(rect))
    >>> [round(o.expected_cost, 1) for o in res.report.options], res.stats.nodes
    ([6.3, 6.0], 2)
    """
    check_max_actions(max_actions)
    if problem.accuracy > 0:
        # Its action classes assume exact turns; a class margin is only a lower bound on a
        # plan's tolerance, so filtering on it would lose plans the exact planner finds.
        raise PlanningError(
            "the breadth-first baseline assumes exact gripper turns: the problem's "
            f"`accuracy` must be 0; got {problem.accuracy:.6g} rad = "
            f"{math.degrees(problem.accuracy):g} deg (use the exact planner)"
        )
    if node_limit < 1 or fallback_limit < 1:
        raise PlanningError(
            f"`node_limit` and `fallback_limit` must be at least 1; got {node_limit} and "
            f"{fallback_limit}"
        )
    _check_tables(problem, table_limit)
    s = _Search(problem, _make_roots(problem, max_actions, first_angles))
    target = max(s.attainable(r) for r in range(len(s.roots)))
    several_kinds = len(s.kinds) > 1

    # Breadth-first search. With one action kind a hyperstate met again is never better
    # than its first visit (same distribution, no cheaper, no shorter); with several kinds a
    # later visit is kept when its actions cost less than the first visit's padded with
    # squeezes (cost matters, not only depth).
    pad_cost = problem.cost.action_cost(s.kinds[_pad_kind(s)])
    seen: dict[bytes, list[tuple[int, float]]] = {}

    def is_new(key: bytes, depth: int, attempt: float) -> bool:
        if not merge:
            return True
        if key not in seen:
            seen[key] = [(depth, attempt)]
            return True
        if not several_kinds or any(
            d0 <= depth and c0 + (depth - d0) * pad_cost <= attempt + 1e-9 for d0, c0 in seen[key]
        ):
            return False
        seen[key].append((depth, attempt))
        return True

    level: list[int] = []
    found: int | None = None
    for r in range(len(s.roots)):
        v = s.add_root(r)
        if not is_new(s.keys(s.dist[v])[0], 1, s.attempt[v]):
            continue
        level.append(v)
        if found is None and s.prob[v] >= target - s.eps:
            found = v
    bfs_nodes = len(level)
    limit_hit = False
    depth = 1
    stop = False  # the level ends early: the node limit, or the target with one action kind
    while found is None and level and (max_actions is None or depth < max_actions):
        nxt: list[int] = []
        for u in level:
            for ti in range(len(s.kinds)):
                attempt = s.attempt[u] + s.step_cost[ti]
                for start, ch in s.blocks(s.dist[u], ti):
                    probs = s.goal_prob(ch)
                    for j, key in enumerate(s.keys(ch)):
                        if not is_new(key, depth + 1, attempt):
                            continue
                        v = s.add_child(u, ti, start + j, ch[j], float(probs[j]))
                        nxt.append(v)
                        bfs_nodes += 1
                        if probs[j] >= target - s.eps and (
                            found is None or s.prob[v] > s.prob[found]
                        ):
                            found = v
                        if found is not None and not several_kinds:
                            stop = True
                            break
                        if found is None and bfs_nodes >= node_limit:
                            limit_hit = stop = True
                            break
                    if stop:
                        break
                if stop:
                    break
            if stop:
                break
        level = nxt
        depth += 1
        if limit_hit:
            break
    completed = not limit_hit

    # Best-first fallback: a second search that always expands the most probable node.
    fallback_nodes = 0
    if limit_hit:
        seen2: set[bytes] = set()
        heap: list[tuple[float, int, int]] = []
        for v in range(len(s.roots)):  # the roots are nodes 0..R-1
            key = s.keys(s.dist[v])[0]
            if key not in seen2 or not merge:
                seen2.add(key)
                fallback_nodes += 1
                heapq.heappush(heap, (-s.prob[v], s.depth[v], v))
        while heap and found is None and fallback_nodes < fallback_limit:
            _, d, u = heapq.heappop(heap)
            if max_actions is not None and d >= max_actions:
                continue
            for ti in range(len(s.kinds)):
                for start, ch in s.blocks(s.dist[u], ti):
                    probs = s.goal_prob(ch)
                    for j, key in enumerate(s.keys(ch)):
                        if key in seen2 and merge:
                            continue
                        seen2.add(key)
                        v = s.add_child(u, ti, start + j, ch[j], float(probs[j]))
                        fallback_nodes += 1
                        heapq.heappush(heap, (-s.prob[v], s.depth[v], v))
                        if s.prob[v] >= target - s.eps:
                            found = v
                            break
                        if fallback_nodes >= fallback_limit:
                            break
                    if found is not None or fallback_nodes >= fallback_limit:
                        break
                if found is not None or fallback_nodes >= fallback_limit:
                    break
        logger.debug("best-first fallback generated %d nodes", fallback_nodes)

    # The depth of the most certain plan reported.
    if found is not None:
        final_depth = s.depth[found]
    elif max_actions is not None and completed:
        final_depth = max(s.depth)
    else:
        best_p = max(s.prob)
        final_depth = min(d for d, p in zip(s.depth, s.prob, strict=True) if p >= best_p - s.eps)
    # For a fixed sequence of action kinds the expected cost falls as the probability
    # rises: only the most probable node of each sequence can be a best plan.
    leaders: dict[tuple[str, ...], int] = {}
    for v, kinds in enumerate(s.kinds_of):
        if kinds not in leaders or s.prob[v] > s.prob[leaders[kinds]]:
            leaders[kinds] = v
    options = tuple(
        _best_option(s, list(leaders.values()), k, k == final_depth)
        for k in range(1, final_depth + 1)
    )
    bayes, most = choose_indices(options, s.eps)
    n_nodes = bfs_nodes + fallback_nodes
    report = PlanResult(problem, options, bayes, most, "bfs", n_nodes)
    tree = None
    if not merge and completed and found is not None:
        tree = n_nodes
    elif tree_count and completed and found is not None:
        tree = _tree_nodes(s, s.depth[found], target)
    stats = SearchStats(
        n_nodes,
        bfs_nodes,
        fallback_nodes,
        completed,
        found is not None,
        final_depth,
        target,
        tree,
    )
    return BfsResult(report, stats)


def plan_bfs(problem: Problem, max_actions: int | None = None) -> PlanResult:
    """Best plans of every length by the seed's breadth-first search (a baseline).

    Same report as :func:`~bayesgrasp.planning.exact.plan_exact`, with ``method="bfs"``
    and ``nodes`` set; see :func:`search_bfs` for the options and the statistics.
    The tolerance of each plan is its class margin (half the width of the narrowest
    action class used), a lower bound on the exact tolerance.

    Parameters
    ----------
    problem : Problem
    max_actions : int, optional
        Search no deeper than this many actions.

    Returns
    -------
    PlanResult

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> tri = Part.from_points([(0, 0), (3, 0), (1, 2)])
    >>> rep = plan_bfs(Problem.build(tri))
    >>> rep.method, rep.nodes, [round(o.success_probability, 4) for o in rep.options]
    ('bfs', 9, [0.1988, 0.375, 0.5])
    """
    return search_bfs(problem, max_actions).report


def _best_option(s: _Search, candidates: list[int], k: int, final: bool) -> PlanOption:
    """The best plan of ``k`` actions among nodes at depth <= k (padded to k actions)."""
    cost = s.problem.cost
    pad = s.kinds[_pad_kind(s)]
    best: tuple[float, float] | None = None
    pick = -1
    for v in candidates:
        d, p = s.depth[v], s.prob[v]
        if d > k:
            continue
        c = cost.expected_cost(s.kinds_of[v] + (pad,) * (k - d), p)
        score = (-round(p, 12), c) if final else (c, -p)
        if best is None or score < best:
            best, pick = score, v
    return _option(s, pick, k)


def _keeps_states(s: _Search, ti: int) -> bool:
    """Whether action kind ``ti`` is the squeeze itself: its transfer function is the states'.

    Made with the gripper unturned it leaves every state where it is.
    """
    return s.problem.transfers[s.kinds[ti]] is s.problem.states


def _pad_kind(s: _Search) -> int:
    """Kind index used to pad a plan: the squeeze if allowed, else the first kind."""
    return next((ti for ti in range(len(s.kinds)) if _keeps_states(s, ti)), 0)


def _pad_class(s: _Search, ti: int, dist: FloatArray) -> int:
    """A class that keeps the distribution's success probability (or raises it most)."""
    cl = s.classes[ti]
    if _keeps_states(s, ti):
        # The class holding alpha = 0 (mod the gripper period): every state stays put (or
        # turns by pi).
        inside = np.mod(-cl.lo, s.actions[ti].gripper_period) < cl.hi - cl.lo
        if np.any(inside):
            return int(np.flatnonzero(inside)[0])
    best, pick = -math.inf, 0
    for start, ch in s.blocks(dist, ti):
        probs = s.goal_prob(ch)
        j = int(np.argmax(probs))
        if probs[j] > best:  # strictly: the first class of the highest, as one argmax
            best, pick = float(probs[j]), start + j
    return pick


def _option(s: _Search, v: int, k: int) -> PlanOption:
    """Concrete plan for node ``v``, padded to ``k`` actions."""
    root = s.roots[s.root_of[v]]
    path = s.path(v)
    dist = s.dist[v]
    mapping = s.mapping[v]
    ti_pad = _pad_kind(s)
    for _ in range(k - s.depth[v]):
        a = _pad_class(s, ti_pad, dist)
        dist = s.children(dist, ti_pad, a, a + 1)[0]
        mapping = s.classes[ti_pad].transfer[a][mapping]
        path.append((ti_pad, a))
    kinds = [root.kind]
    angles = [root.angle]
    margins = []
    for ti, a in path:
        cl = s.classes[ti]
        kinds.append(s.kinds[ti])
        angles.append(float(cl.mid[a]))
        margins.append(0.5 * float(cl.hi[a] - cl.lo[a]))
    steps, turned = short_turns(plan_actions(s.problem, kinds), angles)
    p = float(s.goal_prob(dist))
    goal = s.goal_state(dist)
    final = math.fmod(float(s.problem.states.stable[goal]) + turned + TWO_PI, TWO_PI)
    c = s.problem.cost.expected_cost(tuple(kinds), p)
    arc = _success_arc(s.problem, root, mapping, goal)
    return PlanOption(tuple(steps), final, p, c, min(margins) if margins else None, arc)


def _success_arc(
    problem: Problem, root: _Root, mapping: IntArray, goal: int
) -> tuple[float, float]:
    """Arc of initial world orientations sent to ``goal``: the preimage basins, joined."""
    f = problem.transfers[root.kind]
    idx = np.flatnonzero(mapping == goal)
    if len(idx) == 0:  # pragma: no cover - the goal state always has a preimage
        return (root.angle, root.angle)
    n = len(mapping)
    gaps = np.diff(np.append(idx, idx[0] + n))
    j = int(np.argmax(gaps))  # the run ends at idx[j] and starts at idx[j + 1]
    first, last = int(idx[(j + 1) % len(idx)]), int(idx[j])
    lo = float(f.basin_lo[first])
    hi = float(f.basin_hi[last]) + (TWO_PI if last < first or len(idx) == n else 0.0)
    return (lo + root.angle, hi + root.angle)


def _tree_nodes(s: _Search, depth: int, target: float) -> int:
    """Nodes a search merging nothing generates up to its first node at the target.

    The unmerged tree has ``R`` roots and ``A`` children per node (all classes of all
    kinds, in order); breadth-first order within a level is the order of the action
    sequences read as base-``A`` numbers. The first goal node at ``depth`` is found by a
    depth-first search in that order, remembering hyperstates (at a depth) that lead to no
    goal there.
    """
    a_total = sum(len(cl.mid) for cl in s.classes)
    n_roots = len(s.roots)
    dead: set[tuple[bytes, int]] = set()

    def first(dist: FloatArray, d: int) -> int | None:
        """Position of the first goal leaf below a node at depth d (None if there is none)."""
        key = (s.keys(dist)[0], d)
        if key in dead:
            return None
        offset = 0  # children are numbered over all kinds, in order
        for ti in range(len(s.kinds)):
            for start, ch in s.blocks(dist, ti):
                if d + 1 == depth:
                    hits = np.flatnonzero(s.goal_prob(ch) >= target - s.eps)
                    if len(hits):
                        return offset + start + int(hits[0])
                    continue
                below = int(a_total ** (depth - d - 1))
                for j in range(len(ch)):
                    pos = first(ch[j], d + 1)
                    if pos is not None:
                        return (offset + start + j) * below + pos
            offset += len(s.classes[ti].mid)
        dead.add(key)
        return None

    pos: int | None = None
    for r in range(n_roots):
        root_dist = s.dist[r]  # roots are nodes 0..R-1
        if depth == 1:
            if s.prob[r] >= target - s.eps:
                pos = r
                break
            continue
        sub = first(root_dist, 1)
        if sub is not None:
            pos = r * int(a_total ** (depth - 1)) + sub
            break
    if pos is None:  # pragma: no cover - the merged search found one at this depth
        raise PlanningError("internal error: no goal node in the unmerged tree")
    logger.debug("unmerged tree count: %d dead ends remembered", len(dead))
    before = sum(n_roots * int(a_total ** (d - 1)) for d in range(1, depth))
    return before + pos + 1
