"""Building the Bayes policy's tree from the programme's decisions, and its figures.

After the parametric search (:func:`~bayesgrasp.planning.policy.search_policy`) the
programme (:class:`~bayesgrasp.planning.programme.Solver`) holds the decision of every
belief it reached at the best price. :class:`PolicyBuilder` walks them from the root: each
node acts, branches on the reading bins (the readings after which the programme stops are
settled together), and tallies the policy's figures (success, action and verification cost,
rejection, actions, entropy after each level) on the way; neighbouring readings that lead to
the same leaf or subtree are joined into one branch. :func:`finish_policy` turns the tally
into a :class:`~bayesgrasp.planning.policy_tree.Policy`.

Examples
--------
>>> a = Branch(-math.inf, 1.0, 0.5, Declare(0, "p", 0.0, 1.0))
>>> b = Branch(1.0, math.inf, 0.5, Declare(0, "p", 0.0, 0.5))
>>> [(m.lo, m.hi, m.next.success_probability) for m in merge_branches([a, b])]
[(-inf, inf, 0.75)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, wrap
from ..model.sensing import StateSpace, WidthSensor, entropy_bits
from .evaluation import entropies
from .policy_tree import Branch, Declare, Policy, PolicyNode, Reject, tree_depth
from .programme import EPS, TINY, ActionKind, Solver
from .result import PlanStep, short_turns

__all__ = ["PolicyBuilder", "finish_policy", "merge_branches"]

FloatArray = NDArray[np.float64]


@dataclass(slots=True)
class _Tally:
    """The figures of the tree built so far (unnormalised: masses times values)."""

    success: float = 0.0
    action_cost: float = 0.0
    verify_cost: float = 0.0
    reject: float = 0.0
    actions: float = 0.0
    entropy: list[float] = field(default_factory=list)

    def add_entropy(self, level: int, w: float, h: float) -> None:
        """Entropy ``h`` of a belief of mass ``w`` after ``level`` readings, acted on."""
        while len(self.entropy) < level:
            self.entropy.append(0.0)
        self.entropy[level - 1] += w * h


@dataclass(slots=True)
class PolicyBuilder:
    """Builds the tree of the programme's decisions from a root, tallying its figures."""

    solver: Solver
    max_actions: int
    tally: _Tally = field(default_factory=_Tally)
    leaves_at: list[tuple[int, float, float]] = field(default_factory=list)

    def turn(self, kind: ActionKind, alpha: float, carry: float) -> tuple[float, float]:
        """The turn to command and the carry it leaves: :func:`.result.short_turns`.

        A gripper with a pi-symmetric action turned by pi is the same gripper; the part then
        lies pi further round in its frame, which later turns and the declared orientation
        absorb.
        """
        steps, rest = short_turns([kind.action], [alpha + carry])
        return steps[0].alpha, rest

    def node(
        self,
        kind: ActionKind,
        alpha: float,
        margin: float,
        img: FloatArray,
        mass: float,
        r_after: int,
        carry: float,
        level: int,
        first: bool,
    ) -> PolicyNode:
        """An action node whose action leaves the (normalised) belief ``img``.

        The readings after which the programme stops (a leaf is no worse than the bound on
        acting again, as :meth:`Solver.best_act` settles them, or no actions are left) are
        handled together: their leaves, figures and entropies are computed for all bins at
        once, and neighbouring bins with the same leaf are one branch.
        """
        s = self.solver
        t = self.tally
        t.actions += mass
        t.action_cost += mass * (kind.first_cost if first else kind.cost)
        turn, carry = self.turn(kind, alpha, carry)
        joint = img[:, None] * s.bins.likelihood  # (N, B)
        p = joint.sum(axis=0)
        kept = np.flatnonzero(p > 0)
        pm = p[kept]
        q = joint[:, kept].T / pm[:, None]  # (M, N) belief after each reading
        if r_after > 0:
            leaf_q, act_q = s.leaf_value(q), s.act_bound(q)
            settled = (leaf_q <= act_q + EPS) | (pm * (leaf_q - act_q) < TINY)
        else:
            settled = np.ones(len(kept), dtype=bool)
        succ, state = s.success(q)
        declare = ((s.verify + s.retry) - (s.lam + s.retry) * succ <= s.retry + EPS) & (succ > 0)
        # Leaf key of each bin: the declared state, or -1 to reject, or -2 to act on.
        leaf_key = np.where(settled, np.where(declare, state, -1), -2)
        w = mass * pm
        lw = np.where(settled, w, 0.0)
        dw = np.where(settled & declare, w, 0.0)
        t.success += float((dw * succ).sum())
        t.verify_cost += float(dw.sum()) * s.verify
        t.reject += float(np.where(settled & ~declare, w, 0.0).sum())
        if settled.any():
            h = entropies(q[settled])
            mean_h = float((w[settled] * h).sum() / lw.sum())
            self.leaves_at.append((level, float(lw.sum()), mean_h))
        lo_all = s.bins.lo
        branches: list[Branch] = []
        i, m = 0, len(kept)
        while i < m:
            key = int(leaf_key[i])
            lo = -math.inf if i == 0 else float(lo_all[kept[i]])
            if key == -2:
                nxt = self.after(q[i], float(w[i]), r_after, carry, level)
                j = i + 1
                prob = float(pm[i])
            else:
                j = i + 1
                while j < m and leaf_key[j] == key:
                    j += 1
                prob = float(pm[i:j].sum())
                if key == -1:
                    nxt = Reject()
                else:
                    q_succ = float((pm[i:j] * succ[i:j]).sum()) / prob
                    nxt = self.declare(key, q_succ, carry)
            hi = math.inf if j == m else float(lo_all[kept[j]])
            branches.append(Branch(lo, hi, prob, nxt))
            i = j
        merged = merge_branches(branches)
        return PolicyNode(PlanStep(kind.name, turn), tuple(merged), margin)

    def declare(self, state: int, success: float, carry: float) -> Declare:
        """The leaf declaring joint state ``state`` (its orientation turned by ``carry``)."""
        part, theta = self.solver.space.stable(state)
        orientation = float(np.mod(theta + carry, TWO_PI))
        if orientation >= TWO_PI:  # pragma: no cover - rounding
            orientation = 0.0
        return Declare(part, self.solver.space.names[part], orientation, success)

    def after(
        self, q: FloatArray, mass: float, r: int, carry: float, level: int
    ) -> PolicyNode | Declare | Reject:
        """The subtree after a reading that leaves the belief ``q`` (mass ``mass``)."""
        s = self.solver
        h = entropy_bits(q)
        dec = s.decision(q, r)
        t = self.tally
        if dec[0] == "act":
            t.add_entropy(level, mass, h)
            kind = s.kinds[dec[1]]
            row = dec[2]
            if kind.matrices is not None:
                mapped = q @ kind.matrices[row]
            else:
                mapped = np.bincount(kind.transfer[row], weights=q, minlength=len(q))
            return self.node(
                kind,
                float(kind.mid[row]),
                float(kind.half_width[row]),
                np.asarray(mapped, dtype=np.float64),
                mass,
                r - 1,
                carry,
                level + 1,
                False,
            )
        self.leaves_at.append((level, mass, h))
        if dec[0] == "reject":
            t.reject += mass
            return Reject()
        o = int(dec[1])
        g = s.goal[o]
        # a payoff (noisy_policy) is one row of values; a goal, rows of success sets
        succ = float(q[g].sum()) if g.dtype == np.bool_ else float(q @ g)
        t.success += mass * succ
        t.verify_cost += mass * s.verify
        return self.declare(o, succ, carry)


def merge_branches(branches: list[Branch]) -> list[Branch]:
    """Join neighbouring branches that end in the same leaf, then those with the same subtree."""
    return _merge_subtrees(_merge_leaves(branches))


def _merge_leaves(branches: list[Branch]) -> list[Branch]:
    """Join neighbouring branches that end in the same leaf (same declaration, or reject)."""
    out: list[Branch] = []
    for b in branches:
        if out and _same_leaf(out[-1].next, b.next):
            prev = out[-1]
            p = prev.probability + b.probability
            nxt: PolicyNode | Declare | Reject = prev.next
            if isinstance(prev.next, Declare) and isinstance(b.next, Declare):
                q = (
                    prev.probability * prev.next.success_probability
                    + b.probability * b.next.success_probability
                ) / p
                nxt = Declare(prev.next.part, prev.next.part_name, prev.next.orientation, q)
            out[-1] = Branch(prev.lo, b.hi, p, nxt)
        else:
            out.append(b)
    return out


def _merge_subtrees(branches: list[Branch]) -> list[Branch]:
    """Join neighbouring branches that lead to the same policy (:func:`_same_next`).

    The joined branch's subtree is the same tree with its probabilities mixed by the weight
    of each reading, so the policy (and every figure of it) is unchanged; it is only told
    once.
    """
    out: list[Branch] = []
    for b in branches:
        if out and _same_next(out[-1].next, b.next):
            prev = out[-1]
            p = prev.probability + b.probability
            out[-1] = Branch(
                prev.lo, b.hi, p, _mix(prev.next, prev.probability, b.next, b.probability)
            )
        else:
            out.append(b)
    return out


def _same_next(a: object, b: object) -> bool:
    """The same leaf, or the same actions with the same branches down to the same leaves."""
    if isinstance(a, PolicyNode) and isinstance(b, PolicyNode):
        return (
            a.step.kind == b.step.kind
            and abs(a.step.alpha - b.step.alpha) < 1e-12
            and len(a.branches) == len(b.branches)
            and all(
                x.lo == y.lo and x.hi == y.hi and _same_next(x.next, y.next)
                for x, y in zip(a.branches, b.branches, strict=True)
            )
        )
    return _same_leaf(a, b)


def _mix(
    a: PolicyNode | Declare | Reject, wa: float, b: PolicyNode | Declare | Reject, wb: float
) -> PolicyNode | Declare | Reject:
    """The tree ``a`` (= ``b``) reached with weight ``wa + wb``, its probabilities mixed."""
    w = wa + wb
    if isinstance(a, Declare) and isinstance(b, Declare):
        q = (wa * a.success_probability + wb * b.success_probability) / w if w > 0 else 0.0
        return Declare(a.part, a.part_name, a.orientation, q)
    if isinstance(a, PolicyNode) and isinstance(b, PolicyNode):
        branches = []
        for x, y in zip(a.branches, b.branches, strict=True):
            px, py = wa * x.probability, wb * y.probability
            prob = (px + py) / w if w > 0 else 0.0
            branches.append(Branch(x.lo, x.hi, prob, _mix(x.next, px, y.next, py)))
        return PolicyNode(a.step, tuple(branches), min(a.margin, b.margin))
    return a


def _same_leaf(a: object, b: object) -> bool:
    if isinstance(a, Reject) and isinstance(b, Reject):
        return True
    if isinstance(a, Declare) and isinstance(b, Declare):
        return a.part == b.part and abs(wrap(a.orientation - b.orientation)) < 1e-12
    return False


# -- the planner ---------------------------------------------------------------------------


def finish_policy(
    builder: PolicyBuilder,
    root: PolicyNode,
    space: StateSpace,
    sensor: WidthSensor,
    max_actions: int,
    sensorless: float | None,
    iterations: int,
    angles_exact: bool,
) -> Policy:
    """The policy of ``root`` with the figures its builder tallied (see the module notes)."""
    t = builder.tally
    depth = tree_depth(root)
    ent = [0.0] * depth
    # Entropy after each level: paths that stopped earlier keep their last belief.
    level_mass = [0.0] * depth
    for lv, w, h in builder.leaves_at:
        for x in range(lv, depth + 1):
            ent[x - 1] += w * h
            level_mass[x - 1] += w
    for x, e in enumerate(t.entropy[:depth]):
        ent[x] += e
    p = t.success
    rho = space.problems[0].cost.retry
    cycle = t.action_cost + t.verify_cost + rho * (1.0 - p)
    expected = cycle / p if p > 0 else math.inf
    units = space.problems[0].part.units
    return Policy(
        root,
        space.names,
        tuple(float(w) for w in space.part_prior),
        sensor,
        max_actions,
        expected,
        p,
        cycle,
        t.reject,
        t.actions,
        tuple(ent),
        sensorless,
        iterations,
        len(builder.solver.memo),
        angles_exact,
        units,
        builder.solver.searched,
    )


# -- presentation --------------------------------------------------------------------------
