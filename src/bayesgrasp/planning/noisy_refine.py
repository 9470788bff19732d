"""Refinement of a noisy policy's turns: coordinate descent over the turns, tree fixed.

With the tree's structure fixed (its actions, reading branches and leaves) the value
``c - lambda P`` is linear in the belief entering any node, ``f(alpha) = left M_t(alpha) r``
with ``left`` the (unnormalised) belief that reaches the node and ``r`` the per-state value
of what follows (:func:`node_values`). :func:`refine_turns` optimises each turn after the
first in turn over the whole circle (:func:`best_turn`), as :mod:`bayesgrasp.planning.noisy`
refines a plan's turns, for at most :data:`MAX_SWEEPS` sweeps while the ratio falls; what
is exact and what is bounded is in the notes of :mod:`bayesgrasp.planning.noisy_policy`.

Examples
--------
>>> import math
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.model.noise import NoiseModel, TurnNoise
>>> from bayesgrasp.model.sensing import StateSpace, parse_sensor
>>> from bayesgrasp.planning.noisy_model import NoisyModel, exact_figures, linear_tree
>>> rect = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
>>> noise = NoiseModel(TurnNoise("uniform", math.radians(3)))
>>> model = NoisyModel(StateSpace.build(rect), parse_sensor("width"), noise)
>>> tree = linear_tree(model, ["squeeze", "squeeze"], [0.0, 0.3], 0)
>>> before = exact_figures(model, tree, 0.0).expected_cost
>>> after, eps = refine_turns(model, tree, 0.0, before)  # exact for a uniform error: eps 0
>>> round(before, 2), round(after, 2), eps
(20.33, 8.51, 0.0)
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from .noisy_model import MutableNode, NoisyModel, exact_figures
from .policy_tree import Declare, Reject
from .turns import FLAT_SIGMAS, GRID_PER_SIGMA, free_arcs, margin, turn_grid

__all__ = ["MAX_SWEEPS", "best_turn", "node_values", "refine_turns"]

FloatArray = NDArray[np.float64]

MAX_SWEEPS = 4
"""Most refinement sweeps over the turns of a policy."""
_GAIN_TOL = 1e-12


def node_values(model: NoisyModel, root: MutableNode, lam: float) -> dict[int, FloatArray]:
    """Per-state value (``c - lambda P``, per unit mass) of each node's readings and after.

    ``out[id(node)][j]``: the part is in state ``j`` after the node's action. One pass from
    the leaves up.
    """
    v, rho = model.cost.verify, model.cost.retry
    out: dict[int, FloatArray] = {}

    def walk(node: MutableNode) -> FloatArray:
        cols = []
        for nxt in node.children:
            if isinstance(nxt, Reject):
                cols.append(np.full(model.n, rho))
            elif isinstance(nxt, Declare):
                g = model.earned(nxt)
                cols.append(v + rho - (lam + rho) * g)
            else:
                below = walk(nxt)
                m = model.matrix(nxt.kind, nxt.alpha)
                cols.append(model.cost.action_cost(nxt.kind) + m @ below)
        r = np.asarray((node.lik * np.stack(cols, axis=1)).sum(axis=1), dtype=np.float64)
        out[id(node)] = r
        return r

    walk(root)
    return out


def best_turn(
    model: NoisyModel, kind: str, left: FloatArray, right: FloatArray, current: float
) -> tuple[float, float, float]:
    """The turn of least ``left M(alpha) right`` over the circle, its value, and ``eps``.

    ``eps`` bounds how much lower the true least value may be (the grid bound; 0 where the
    search is exact). Minimises by maximising ``left M (-right)``, as :mod:`.noisy` does.
    """
    turn = model.noise.turn
    neg = -right
    f0 = float(model.line(kind, left, neg, np.array([current]))[0])
    crit = model.critical(kind, left, neg)
    period = TWO_PI
    if len(crit) == 0:
        return current, -f0, 0.0
    eps = 0.0
    on_edge = False
    if turn.exact:
        # f is constant between critical turns, so between every boundary of every state the
        # node may hold (a refinement of them): the middle of each such arc, the widest of the
        # best, keeps the turn farthest from the unstable equilibria (arcs of a rounding's
        # width are not turns a gripper can make). A turn now on a boundary must move: its
        # value is one side's, not what the squeeze does there.
        edges = model.boundaries(kind, left)
        _, pts, half = free_arcs(edges, period, 1e-9)
        vals = np.where(half > 5e-10, model.line(kind, left, neg, pts), -np.inf)
        top = np.flatnonzero(vals >= vals.max() - _GAIN_TOL * max(1.0, abs(float(vals.max()))))
        i = int(top[np.argmax(half[top])])
        best, fb = float(pts[i]), float(vals[i])
        on_edge = margin(current, edges, period) < 1e-9
    elif turn.kind == "uniform":
        raw = (crit[:, None] + np.array([-turn.scale, turn.scale])).ravel()
        kinks = np.unique(np.mod(raw + period / 2, period)) - period / 2
        vals = model.line(kind, left, neg, kinks)
        i = int(np.argmax(vals))
        best, fb = float(kinks[i]), float(vals[i])
    else:
        h = turn.scale / GRID_PER_SIGMA
        grid = turn_grid(crit, period, h, FLAT_SIGMAS * turn.scale)
        vals = model.line(kind, left, neg, grid)
        i = int(np.argmax(vals))
        best, fb = float(grid[i]), float(vals[i])
        fine = best + h * np.linspace(-1.0, 1.0, 65)
        fv = model.line(kind, left, neg, fine)
        j = int(np.argmax(fv))
        if fv[j] > fb:
            best, fb = float(fine[j]), float(fv[j])
        span = float(right.max() - right.min())
        eps = turn.curvature_bound * h * h / 8.0 * float(left.sum()) * span
    if on_edge:
        best = float(math.remainder(best, TWO_PI))
        return best, float(left @ model.matrix(kind, best) @ right), eps
    if fb > f0 + _GAIN_TOL * max(1.0, abs(f0)):
        # Checked with the matrix the evaluation uses (the line's sums are arranged
        # differently, and may round differently right at a critical turn).
        best = float(math.remainder(best, TWO_PI))
        f_new = float(left @ model.matrix(kind, best) @ right)
        f_old = float(left @ model.matrix(kind, current) @ right)
        if f_new < f_old - _GAIN_TOL * max(1.0, abs(f_old)):
            return best, f_new, eps
    return current, -f0, eps


def refine_turns(
    model: NoisyModel, root: MutableNode, first_angle: float, ratio: float
) -> tuple[float, float]:
    """Coordinate descent over the turns (see the module notes); the new ratio and ``eps``.

    A node whose ``mass * span(r)`` (the most any turn can change its value by) is below
    the grid bound of the heaviest node is left as it is: its bound is that product, no
    larger than the reported ``eps``.
    """
    turn = model.noise.turn
    # eps = factor * mass * span on the grid (normal error); 0 where the search is exact.
    factor = 0.0
    if not turn.exact and turn.kind == "normal":
        h = turn.scale / GRID_PER_SIGMA
        factor = turn.curvature_bound * h * h / 8.0
    eps = 0.0

    def weights(node: MutableNode, left: FloatArray, rights: dict[int, FloatArray]) -> float:
        """The largest ``mass * span(r)`` over the nodes below (``left``: after the action)."""
        top = 0.0
        for j, nxt in enumerate(node.children):
            if isinstance(nxt, MutableNode):
                q = left * node.lik[:, j]
                r = rights[id(nxt)]
                top = max(top, float(q.sum()) * float(r.max() - r.min()))
                top = max(top, weights(nxt, q @ model.matrix(nxt.kind, nxt.alpha), rights))
        return top

    def sweep(
        node: MutableNode, left: FloatArray, rights: dict[int, FloatArray], tau: float
    ) -> bool:
        """Refine the nodes below ``node`` (``left``: the belief after its action)."""
        nonlocal eps
        moved = False
        for j, nxt in enumerate(node.children):
            if not isinstance(nxt, MutableNode):
                continue
            q = left * node.lik[:, j]
            r = rights[id(nxt)]
            weight = float(q.sum()) * float(r.max() - r.min())
            if weight > 0 and weight > tau:
                new, _, e = best_turn(model, nxt.kind, q, r, nxt.alpha)
                eps = max(eps, e)
                if new != nxt.alpha:
                    nxt.alpha, moved = new, True
            else:
                eps = max(eps, weight)
            moved |= sweep(nxt, q @ model.matrix(nxt.kind, nxt.alpha), rights, tau)
        return moved

    q0 = model.initial(root.kind, first_angle)
    for _ in range(MAX_SWEEPS):
        eps = 0.0
        rights = node_values(model, root, ratio)
        tau = max(factor * weights(root, q0, rights), 1e-15)
        moved = sweep(root, q0, rights, tau)
        new_ratio = exact_figures(model, root, first_angle).expected_cost
        done = not moved or new_ratio >= ratio * (1.0 - 1e-13)
        ratio = new_ratio
        if done:
            break
    return ratio, eps


# -- the planner -----------------------------------------------------------------------------
