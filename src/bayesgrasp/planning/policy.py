"""Policies: branching plans that act on jaw-width readings, and the exact Bayes-policy planner.

The seed's section 6.2: with a jaw-width sensor "the resulting plans would have branches,
with different sensor values determining the actual path taken". A :class:`Policy` is a
tree. A :class:`PolicyNode` is an action (its kind and gripper angle: the root's angle is the
gripper's world angle, a later node's is the turn relative to the previous action, as in
linear plans); its :class:`Branch` es are half-open reading intervals ``[lo, hi)`` that
together cover every reading, each with its probability (given that the node is reached) and
its next node or leaf. A leaf :class:`Declare` s a final orientation (in the last gripper
frame; with several parts also which part) and then verifies, or :class:`Reject` s (the part
goes back to the feeder without a verification). No path has more than ``max_actions``
actions.

Cost semantics
--------------
One *cycle* runs the policy once on a fresh part (a fresh draw from the part prior and the
orientation prior). It pays the action costs on its path (the first action at its
``CostModel.first`` cost), plus the verification cost ``v`` at a declaring leaf. It succeeds
when the declared orientation (and part) is the true one under the problem's goal (with a
symmetry goal, any symmetric copy). A cycle that does not succeed (a failed verification or
a rejection) pays the retry overhead ``rho`` (``CostModel.retry``) and the next cycle starts.
Cycles are independent, so the number of cycles is geometric with mean ``1 / P`` and

    E[cost] = (E[C] + rho (1 - P)) / P = E[C] / P + rho (1 / P - 1),

where ``C`` is the cost of one cycle (actions and verification) and ``P`` the probability
that a cycle succeeds. For a linear plan this is :meth:`CostModel.expected_cost`, the seed's
``C / p``. The reported figures are per cycle (``cycle_cost = E[C] + rho (1 - P)``,
``success_probability = P``, ``reject_probability``, ``expected_actions`` = expected number
of actions in one cycle) and over the whole process (``expected_cost``,
``expected_total_actions = expected_actions / P``).

The planner (exact)
-------------------
The Bayes policy minimises ``R(pi) = c(pi) / P(pi)`` (``c = E[C] + rho (1 - P)``) over all
policies of at most ``max_actions`` actions. The ratio does not decompose over the tree, so
the planner runs Dinkelbach's parametric search: for a price ``lambda`` of success,

    h(lambda) = min over policies of  c(pi) - lambda P(pi),

is concave and decreasing, and ``R* = min R`` is its root. Starting from the ratio
``lambda_0`` of a known policy (the sensorless Bayes plan for one part, which is a policy
that ignores its readings, or "one action, then declare the likeliest state"), each step
solves ``h(lambda_n)`` exactly, takes its minimiser ``pi_n`` and sets ``lambda_{n+1} =
R(pi_n)``; the ratios fall strictly until ``h(lambda_n) = 0``, when ``lambda_n = R*`` (every
policy has ``c - lambda_n P >= 0``, i.e. ``R >= lambda_n``). The number of policies is
finite, so this ends; in practice after two to four steps. The programme of the best step
is kept (one memo per step), so no extra solve rebuilds the best tree. At every step a known
policy (the start's, or the last step's) has value about 0, so the step only looks for a
policy of value below ``-1e-12 max(1, lambda)`` (the stopping rule's threshold): the last
step, which confirms ``h = 0``, is cut off almost at once. With noisy readings the search
first runs within ``K - 1`` actions and starts the ``K``-action search from that ratio (a
known policy's: it has at most ``K`` actions), which saves a step or two of the large search.

For a fixed ``lambda`` the objective is additive over the leaves and ``h`` is a dynamic
programme over *beliefs* (distributions over the states, or (part, orientation) pairs, after
the last reading; :mod:`bayesgrasp.model.sensing`). Per unit of belief mass, with ``r``
actions left:

    V(q, 0) = min(rho,  v + rho - (lambda + rho) max_o s_o(q))       (reject | declare o)
    V(q, r) = min(V(q, 0),  min over kinds t and classes a of
                  c_t + sum_b P(b | q M_a) V(post(q M_a, b), r - 1))

where ``s_o(q)`` is the success probability of declaring state ``o`` (its goal set's mass),
``M_a`` the transition matrix of action class ``a`` (:meth:`Problem.transition`: finitely many
classes of gripper turns per kind; for several parts, the common refinement of every part's
classes) and ``post`` Bayes' rule with the reading bins of the sensor. The root must act:
``h = min over first kinds t (and first gripper angles) of c^first_t + sum_b P(b) V(q_b,
K - 1)``. Beliefs are memoised after rounding to multiples of ``2^-40`` (so values may carry
errors of about ``1e-12``; the reported figures are recomputed exactly on the returned tree).
A reading of probability ``p`` (given its node) whose leaf value exceeds the bound on acting
again by ``g`` ends in a leaf when ``p g < 1e-13``: the search gives up at most that much per
such reading.

The search is bounded by the depth and by branch and bound with an upper bound ``U(q)`` on
the success probability any continuation can reach: when every action is symmetric under a
turn of the gripper by pi (squeezes), the two states of a pi pair of one part have the same
width and the same future up to pi, so a policy never separates them and
``U(q) = sum over pairs max(q_i, q_i')`` (the sum when the goal counts both as one);
otherwise ``U = 1``. A node whose leaf value is no worse than ``c_min + min(rho, v + rho -
(lambda + rho) U(q))`` is a leaf; a class whose bound (its cost plus the children's bounds)
cannot beat the best found is skipped, and one is abandoned as soon as its exact children so
far plus the bounds of the rest cannot; its children are searched most above their bounds
first, so that a losing class is found out after one or two. Classes with the same effect on
the belief's support are one (the widest is kept: the most margin for the turn). Ties go to
fewer actions and to declaring over rejecting.

Two more bounds, each exact (they only skip work whose result could not change the answer):

- *Budgets.* A child searched inside a class matters only if its value is below ``beta =
  (best - total so far - bounds of the other children left) / P(reading)``: past that the
  class is abandoned anyway. The child is searched with the budget: its actions must beat
  ``min(leaf, beta)``, and when none does and its leaf is above ``beta`` it returns ``beta``
  as a lower bound instead of its value (a *cut*; memoised as such and searched again for a
  larger budget). The parent then abandons the class by the same comparison it would have
  made with the exact value (the comparison is monotone in the value), and if rounding
  says otherwise it asks for the exact value. The root's budget is the known policy's value.
- *Floors.* ``V(q, r)`` at price ``lambda`` is the least of ``c(pi) - lambda P(pi)`` over
  the continuations, each non-increasing in ``lambda`` (``P >= 0``), so ``V`` is too. The
  prices fall from step to step, so every value (or cut bound) found for a child at an
  earlier step is a lower bound at the later ones, and it replaces the weaker bound above
  where it is larger (kept per prepared belief and depth; dropped if a price ever rises).

With the same comparisons as the search without them, these change nothing but which of two
policies equal to about ``1e-12`` is returned (``plan_policy(..., _prune=())`` turns them
off; the tests compare the two).

Where the search grows: every reading bin of positive probability leads to its own belief,
and with noisy readings almost every such belief is new (the memo only helps where readings
are deterministic), so the programme visits up to ``(A B)^(K - 1)`` beliefs for ``A``
distinct class images and ``B`` bins a node. The last action's children are settled in one
vectorised step, the bounds prune the rest, and the per-belief work that does not depend on
``lambda`` (the images of each class, their reading masses and success masses, the bound's
``U`` and ``r``, computed by a matrix product over the pi pairs' common likelihoods) is kept
across the parametric steps; the effect pattern of each class on a support is kept too (a
belief's images are then one weighted count). What remains is about 0.1 ms of numpy per
searched belief. Noisy readings with push-grasps (no pi-pair bound) or with SIGMA large
against the width differences (many ambiguous bins) are the slow cases: see the
documentation's performance page. Neighbouring readings that lead to the same subtree are
joined into one branch of the returned tree (the policy is the same).

First gripper angle: under the uniform prior it does not matter (0). Otherwise the root
belief is linear in the angle between the angles where a basin boundary meets a breakpoint
of the prior, and ``h`` is concave in the root belief, so the best angle is one of those (or,
for a sample prior, a midpoint between them): the planner tries them all when there are at
most ``max_first_angles`` (exact), else those of the sensorless exact plans plus a grid of
360 (then ``Policy.first_angle_exact`` is False).

Each node's ``margin`` is half the width of its action class: how far the turn may err
without changing the effect on any state. With a gripper ``accuracy`` (``Problem.accuracy``,
the bound on the error of every turn after the first, as for plans) only classes of half
width at least ``accuracy`` are turns a later node may make: a turn at the class's middle
then has the class's effect under any error below ``accuracy``, so the policy, its readings
and its figures are exactly those of the model for every such error (the first action's
angle is in the world frame, as for plans, and is not bounded by it). The policy is the
best of those policies; ``accuracy = 0`` is the unrestricted search.

Noisy actions (turn error, contact asynchrony) and a payoff: :mod:`.noisy_policy` runs this
programme with the noisy transition matrices of candidate turns in place of the one-hot
classes, and refines the turns.

Examples
--------
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
>>> pol = plan_policy(tri, "width", max_actions=2)
>>> round(pol.expected_cost, 6), round(pol.success_probability, 6), pol.expected_actions
(4.0, 0.5, 1.0)
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from collections.abc import Callable, Collection, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, circle_distance, wrap
from ..errors import PlanningError
from ..model.actions import Action
from ..model.prior import SamplePrior, UniformPrior
from ..model.problem import ActionClasses, Problem, nearest_state
from ..model.sensing import (
    ReadingBins,
    StateSpace,
    WidthSensor,
    entropy_bits,
    parse_sensor,
)
from .result import PlanStep, short_turns

if TYPE_CHECKING:  # pragma: no cover
    from ..model.noise import NoiseModel

__all__ = [
    "Branch",
    "Declare",
    "Policy",
    "PolicyNode",
    "Reject",
    "SearchStopped",
    "joint_transition",
    "plan_policy",
    "policy_text",
]

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
_QUANT = float(2**40)  # beliefs are memoised after rounding to multiples of 2**-40
_EPS = 1e-12  # value comparisons (ties go to fewer actions)
_TINY = 1e-13  # a reading this unlikely times its most to gain by acting again ends in a leaf
DEFAULT_MAX_ACTIONS = 3
_Memo = dict[tuple[bytes, int], tuple[float, tuple[Any, ...] | None, float, float]]
_NO_FLOOR = -1e300  # no lower bound known (finite, so that 0 * it is 0)
# The exact search's prunings (each can be turned off to test it against the search without):
# budgets passed down ("cut"), values at higher prices as lower bounds ("floor"), and
# starting the parametric search from the best ratio one action shorter ("deepen").
DEFAULT_PRUNE = frozenset({"cut", "floor", "deepen"})


@dataclass(frozen=True, slots=True)
class Declare:
    """A leaf that declares a final state, then verifies.

    Attributes
    ----------
    part : int
        Index of the declared part among the candidates.
    part_name : str
    orientation : float
        The declared orientation of the part in the frame of the last action, ``[0, 2 pi)``.
    success_probability : float
        Probability that the declaration is right, given that the leaf is reached.
    """

    part: int
    part_name: str
    orientation: float
    success_probability: float


@dataclass(frozen=True, slots=True)
class Reject:
    """A leaf that sends the part back to the feeder without a verification."""


@dataclass(frozen=True, slots=True)
class Branch:
    """Readings in ``[lo, hi)`` (part units; ``-inf`` / ``inf`` at the ends) lead to ``next``.

    ``probability`` is the probability of such a reading given that the node is reached.
    """

    lo: float
    hi: float
    probability: float
    next: PolicyNode | Declare | Reject


@dataclass(frozen=True, slots=True)
class PolicyNode:
    """An action and its branches on the reading it yields.

    Attributes
    ----------
    step : PlanStep
        ``step.kind`` the action's name; ``step.alpha`` the world gripper angle (root) or the
        turn relative to the previous action (radians).
    branches : tuple of Branch
        In increasing reading order, tiling the real line.
    margin : float
        Half the width of the action's class of turns (radians): an error in ``alpha`` of
        less than this changes no state's outcome (the root's first angle: ``inf``).
    """

    step: PlanStep
    branches: tuple[Branch, ...]
    margin: float = math.inf

    def branch(self, reading: float) -> Branch:
        """The branch that a reading falls in."""
        for b in self.branches:
            if reading < b.hi:
                return b
        return self.branches[-1]


Leaf = Declare | Reject


@dataclass(frozen=True, slots=True, eq=False)
class Policy:
    """The Bayes policy of a problem and sensor, and its figures (see the module notes).

    Attributes
    ----------
    root : PolicyNode
    parts : tuple of str
        Names of the candidate parts.
    part_prior : tuple of float
    sensor : WidthSensor
    max_actions : int
    expected_cost : float
        ``cycle_cost / success_probability``: the expected cost until a cycle succeeds.
    success_probability : float
        ``P``, per cycle.
    cycle_cost : float
        ``E[C] + rho (1 - P)``: the expected cost of one cycle, retry overhead included.
    reject_probability : float
        Probability that a cycle ends in a rejection.
    expected_actions : float
        Expected number of actions in one cycle.
    expected_entropy : tuple of float
        ``expected_entropy[l]``: the expected entropy (bits) of the belief over the states
        after the reading of action ``l + 1`` (a path that ended earlier keeps its last
        belief), for ``l`` up to the policy's depth minus one.
    sensorless_cost : float or None
        The sensorless Bayes plan's expected cost within ``max_actions`` (one part, when
        asked for; else ``None``).
    iterations : int
        Parametric (Dinkelbach) steps taken (over both depths when deepening).
    beliefs : int
        Distinct (belief, actions left) pairs in the programme of the step whose policy is
        returned.
    searched : int
        (Belief, actions left) pairs searched over all the parametric steps (the search's
        work: a belief searched again with a larger budget counts again).
    first_angle_exact : bool
        Every first gripper angle that can be optimal was tried (see the module notes).
    units : str or None
        Units of the readings (the parts' units).
    noise : NoiseModel or None
        The action noise the policy was planned and evaluated under
        (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`; ``None``: exact
        actions).
    refinement_bound : float
        Noisy actions: no single turn of the policy, the rest kept, can lower the value at
        the policy's ratio by more than this (0 when exact; see
        :mod:`~bayesgrasp.planning.noisy_policy`).
    payoff : tuple of float or None
        With a payoff (:mod:`~bayesgrasp.planning.noisy_policy`), the value of each state:
        a declaring leaf stops and earns the payoff of the state the part is in (its
        ``success_probability`` is then the expected payoff, and ``success_probability``
        of the policy the expected payoff of a cycle).
    stopped : str
        Empty when the search finished. Otherwise why it stopped (its time or memory bound)
        before proving the best policy of ``requested_actions`` actions: the policy is then
        the best of at most ``max_actions`` actions (the deepest search that finished), and
        no policy of ``requested_actions`` costs less than ``lower_bound``.
    requested_actions : int
        The number of actions asked for (``max_actions`` unless the search stopped).
    lower_bound : float
        A lower bound on the expected cost of every policy of ``requested_actions`` actions
        (``c_first / U + v``: a cycle acts once and verifies what it declares, and succeeds
        with at most ``U``; see :func:`plan_policy`). A finished exact search gives its own
        cost (the optimum); ``nan`` where not known (noisy actions).
    """

    root: PolicyNode
    parts: tuple[str, ...]
    part_prior: tuple[float, ...]
    sensor: WidthSensor
    max_actions: int
    expected_cost: float
    success_probability: float
    cycle_cost: float
    reject_probability: float
    expected_actions: float
    expected_entropy: tuple[float, ...]
    sensorless_cost: float | None = None
    iterations: int = 1
    beliefs: int = 0
    first_angle_exact: bool = True
    units: str | None = None
    searched: int = 0
    noise: NoiseModel | None = None
    refinement_bound: float = 0.0
    payoff: tuple[float, ...] | None = None
    stopped: str = ""
    requested_actions: int = 0
    lower_bound: float = math.nan

    def __post_init__(self) -> None:
        if not self.requested_actions:
            object.__setattr__(self, "requested_actions", self.max_actions)

    @property
    def complete(self) -> bool:
        """Whether the search finished (the policy is the best of ``requested_actions``)."""
        return not self.stopped

    @property
    def expected_total_actions(self) -> float:
        """Expected number of actions until a cycle succeeds (``expected_actions / P``)."""
        p = self.success_probability
        return self.expected_actions / p if p > 0 else math.inf

    @property
    def depth(self) -> int:
        """Most actions on any path."""
        return _depth(self.root)

    def leaves(self) -> Iterator[tuple[float, Declare | Reject]]:
        """Every leaf with the probability of reaching it."""
        yield from _leaves(self.root, 1.0)


def _depth(node: PolicyNode) -> int:
    return 1 + max(
        (_depth(b.next) for b in node.branches if isinstance(b.next, PolicyNode)), default=0
    )


def _leaves(node: PolicyNode, p: float) -> Iterator[tuple[float, Declare | Reject]]:
    for b in node.branches:
        if isinstance(b.next, PolicyNode):
            yield from _leaves(b.next, p * b.probability)
        else:
            yield p * b.probability, b.next


# -- the joint transition ------------------------------------------------------------------


def joint_transition(space: StateSpace, kind: str) -> ActionClasses:
    """Classes of gripper turns of one action kind over the joint states of every part.

    One part: :meth:`Problem.transition`. Several: the common refinement of each part's
    classes (every part responds to the same turn with its own transfer function);
    ``transfer[a, i]`` is a joint state index.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> sq = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    >>> cl = joint_transition(StateSpace.build([sq, sq]), "squeeze")
    >>> cl.transfer.shape
    (2, 8)
    """
    return cast(ActionClasses, space.memo(("joint", kind), lambda: _joint(space, kind)))


def _joint(space: StateSpace, kind: str) -> ActionClasses:
    pbs = space.problems
    if len(pbs) == 1:
        return pbs[0].transition(kind)
    period = pbs[0].action(kind).gripper_period
    tol = max(p.states.angle_tol for p in pbs)
    crit = np.unique(np.concatenate([np.mod(p.transition(kind).lo, period) for p in pbs]))
    if len(crit) > 1:
        keep = np.append(True, np.diff(crit) > tol)
        if period - crit[-1] + crit[0] <= tol:
            keep[0] = False
        crit = crit[keep] if keep.any() else crit[:1]
    lo = crit
    hi = np.append(crit[1:], crit[0] + period)
    mid = 0.5 * (lo + hi)
    cols = []
    for j, p in enumerate(pbs):
        # Each part's transfer at the common class's turn (not at its own class's middle,
        # which may lie a gripper period away and so relabel the states by pi).
        after = p.transfer(kind)(p.states.stable[None, :] - mid[:, None])  # (A, K)
        cols.append(nearest_state(p.states, after) + int(space.offsets[j]))
    return ActionClasses(kind, lo, hi, mid, np.concatenate(cols, axis=1).astype(np.intp))


# -- the solver ----------------------------------------------------------------------------


@dataclass(slots=True)
class _Kind:
    action: Action
    name: str
    cost: float
    first_cost: float
    transfer: IntArray  # (A, N), classes ordered widest first
    classes: IntArray  # (A,) original class index of each row
    mid: FloatArray  # (A,)
    half_width: FloatArray  # (A,)
    pi_symmetric: bool
    patterns: dict[bytes, tuple[IntArray, IntArray, int]] = field(default_factory=dict)
    # Noisy actions (:mod:`.noisy_policy`): the (A, N, N) transition matrix of each row's
    # turn; ``None``: the one-hot ``transfer``.
    matrices: FloatArray | None = None


@dataclass(slots=True)
class _Prepared:
    """Images of a belief under one kind's classes and what does not depend on ``lambda``.

    ``mass[i, b]`` is the probability of reading bin ``b`` after image ``i``; ``success`` the
    best declaration's success mass there; ``bound`` the bound's ``U`` and ``r``
    (:meth:`_Solver.bound_of`) of those (image, reading) pairs, once asked for.

    ``floor[r][i, b]`` is a lower bound on ``V(post(i, b), r)`` (per unit mass): the value
    (or a cut's bound) found at this or an earlier, higher price of generation
    ``floor_gen``; ``_NO_FLOOR`` where none was found (:meth:`_Solver.floor`).
    """

    images: FloatArray  # (M, N)
    mass: FloatArray  # (M, B)
    success: FloatArray  # (M, B)
    bound: tuple[FloatArray, FloatArray] | None = None
    floor: dict[int, FloatArray] = field(default_factory=dict)
    floor_gen: int = 0


@dataclass(slots=True)
class _Solver:
    space: StateSpace
    bins: ReadingBins
    kinds: list[_Kind]
    verify: float
    retry: float
    goal: NDArray[np.bool_]  # (N, N) success matrix
    goal_is_identity: bool
    pair_a: IntArray
    pair_b: IntArray
    pair_both: NDArray[np.bool_]
    use_pairs: bool
    pair_likelihood: FloatArray  # (P, B): a reading's likelihood in either state of a pair
    lam: float = 0.0
    cut: bool = True  # children stop as soon as they cannot matter (see `value`)
    use_floor: bool = True  # values at earlier (higher) prices bound later ones from below
    floor_gen: int = 0
    searched: int = 0
    max_bytes: int = 0  # most memory (about) for prepared beliefs (0: no limit; `prepared`)
    prep_bytes: int = 0
    deadline: float = math.inf  # time.monotonic() past which the search stops (`prepared`)
    time_limit: float = math.inf  # the seconds that deadline allows (for the message)
    progress: Callable[[int, int], None] | None = None  # (seconds used, seconds allowed)
    shown: float = 0.0  # when progress was last called
    memo: _Memo = field(default_factory=dict)
    prep_cache: dict[tuple[bytes, int], tuple[_Prepared, IntArray]] = field(default_factory=dict)

    @property
    def c_min(self) -> float:
        return min(k.cost for k in self.kinds)

    # -- belief arithmetic (rows of unnormalised beliefs in the last axis) -----------
    def success(self, m: FloatArray) -> tuple[FloatArray, IntArray]:
        """Best declaration's success mass and its state, for beliefs ``m`` (..., N)."""
        s = m if self.goal_is_identity else m @ self.goal.T.astype(np.float64)
        return np.max(s, axis=-1), np.asarray(np.argmax(s, axis=-1), dtype=np.intp)

    def bound(self, m: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Bounds on what any continuation from beliefs ``m`` (..., N) can reach.

        Returns ``U``, the most success mass, and ``r``, the largest share of a pi pair's
        mass in its likelier state: a declaring leaf of mass ``w`` succeeds with at most
        ``r w`` (readings keep each pair's split, actions average splits).
        """
        total = np.asarray(m.sum(axis=-1), dtype=np.float64)
        if not self.use_pairs:
            return total, np.ones_like(total)
        a, b = m[..., self.pair_a], m[..., self.pair_b]
        pair = a + b
        top = np.where(self.pair_both, pair, np.maximum(a, b))
        share = top / np.maximum(pair, 1e-300)  # 0 where the pair holds no mass
        return np.asarray(top.sum(axis=-1)), np.asarray(share.max(axis=-1))

    def leaf_value(self, m: FloatArray) -> FloatArray:
        """Best leaf value (unnormalised) of beliefs ``m`` (..., N)."""
        total = m.sum(axis=-1)
        s, _ = self.success(m)
        lam, v, rho = self.lam, self.verify, self.retry
        return np.asarray(np.minimum(rho * total, (v + rho) * total - (lam + rho) * s))

    def act_bound(self, m: FloatArray) -> FloatArray:
        """Lower bound (unnormalised) on acting at least once more from beliefs ``m``.

        The leaves below hold the mass; those that declare hold ``D`` of it and succeed with
        ``S <= min(U, r D)``, the rest reject: the value is at least
        ``c_min + rho total + min over D of (v D - (lambda + rho) S)``
        ``= c_min + rho total + min(0, U (v / r - lambda - rho))``.
        """
        total = m.sum(axis=-1)
        u, r = self.bound(m)
        lam, v, rho = self.lam, self.verify, self.retry
        # r = 0 only where there is no mass (then u = 0 too); r >= 1/2 elsewhere.
        gain = u * (v / np.maximum(r, 0.5) - lam - rho)
        return np.asarray((self.c_min + rho) * total + np.minimum(0.0, gain))

    def images(self, q: FloatArray, kind: _Kind) -> tuple[FloatArray, IntArray]:
        """Distinct beliefs after each class of ``kind`` (M, N) and the row of each."""
        if kind.matrices is not None:
            return self.noisy_images(q, kind.matrices)
        pos = q > 0
        pattern = kind.patterns.get(pos.tobytes())
        if pattern is None:
            pattern = kind.patterns[pos.tobytes()] = self.pattern(pos, kind)
        first, idx, m = pattern
        w = np.broadcast_to(q[pos], (m, len(idx) // m)).ravel()
        out = np.bincount(idx, weights=w, minlength=m * self.space.n_states)
        return np.asarray(out.reshape(m, -1), dtype=np.float64), first

    def noisy_images(self, q: FloatArray, matrices: FloatArray) -> tuple[FloatArray, IntArray]:
        """Beliefs ``q M_a`` after each candidate turn (M, N), equal ones (to ``2^-40``) once."""
        imgs = np.asarray(np.tensordot(q, matrices, axes=([0], [1])), dtype=np.float64)
        _, first = np.unique(np.rint(imgs * _QUANT), axis=0, return_index=True)
        if len(first) == len(imgs):
            return imgs, np.arange(len(imgs), dtype=np.intp)
        first = np.sort(first)
        return np.ascontiguousarray(imgs[first]), np.asarray(first, dtype=np.intp)

    def pattern(self, pos: NDArray[np.bool_], kind: _Kind) -> tuple[IntArray, IntArray, int]:
        """The distinct effects of ``kind`` on a belief of support ``pos``.

        The class of each (widest first), the flat index of each (effect, state of the
        support) in the (M, N) images, and their number M (:meth:`images` adds the masses).
        """
        supp = np.flatnonzero(pos)
        t = kind.transfer[:, supp]  # (A, S)
        n = self.space.n_states
        if len(supp) * math.log2(max(n, 2)) < 62:  # each row as one integer in base n
            code = t @ (n ** np.arange(len(supp), dtype=np.int64))
            _, first = np.unique(code, return_index=True)
            first = np.sort(first)  # the widest class of each distinct effect, widest first
        else:
            seen: dict[bytes, int] = {}
            for ai, row in enumerate(t):
                seen.setdefault(row.tobytes(), ai)
            first = np.fromiter(seen.values(), dtype=np.intp, count=len(seen))
        rows = t[first]
        m = len(first)
        idx = (rows + n * np.arange(m)[:, None]).ravel()
        return np.asarray(first, dtype=np.intp), np.asarray(idx, dtype=np.intp), m

    def joint(self, imgs: FloatArray) -> FloatArray:
        """Joint (belief, reading) masses: (M, B, N)."""
        return np.asarray(imgs[:, None, :] * self.bins.likelihood.T[None, :, :])

    @staticmethod
    def key(q: FloatArray) -> bytes:
        return np.rint(q * _QUANT).astype(np.int64).tobytes()

    # -- the programme -----------------------------------------------------------------
    def prepare(self, imgs: FloatArray) -> _Prepared:
        """What :meth:`best_act` needs of images ``imgs`` (M, N) at any price ``lambda``."""
        j = self.joint(imgs)  # (M, B, N)
        s = j if self.goal_is_identity else j @ self.goal.T.astype(np.float64)
        return _Prepared(imgs, j.sum(axis=-1), np.max(s, axis=-1))

    def bound_of(self, prep: _Prepared) -> tuple[FloatArray, FloatArray]:
        """The bound's ``U`` and ``r`` (:meth:`bound`) of every (image, reading) pair: (M, B).

        The two states of a pi pair have the same width, so a reading scales both by the
        same likelihood ``L_p(b)``: the pair's split (``share``) is the image's, and ``U`` is
        a matrix product. ``L_p`` is the larger of the pair's two likelihoods (equal up to
        rounding), so ``U`` stays an upper bound. Computed once per prepared images.
        """
        if prep.bound is not None:
            return prep.bound
        if not self.use_pairs:
            out = (prep.mass, np.ones_like(prep.mass))
        else:
            imgs, lik = prep.images, self.pair_likelihood
            a, b = imgs[:, self.pair_a], imgs[:, self.pair_b]  # (M, P)
            pair = a + b
            top = np.where(self.pair_both, pair, np.maximum(a, b))
            share = top / np.maximum(pair, 1e-300)
            reach = (pair[:, :, None] > 0) & (lik[None, :, :] > 0)  # (M, P, B)
            r = np.max(np.where(reach, share[:, :, None], 0.0), axis=1)  # (M, B)
            out = (np.asarray(top @ lik), np.asarray(r))
        prep.bound = out
        return out

    def leaf_figures_of(self, total: FloatArray, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Cycle cost and success mass of the leaf chosen for masses ``total`` (best ``s``).

        ``s`` is the success mass of the best declaration. Declares unless rejecting is
        strictly better or nothing declared can succeed (as :meth:`value` decides).
        """
        lam, v, rho = self.lam, self.verify, self.retry
        # A tie goes to rejecting where no declaration can succeed (s = 0, verify 0).
        declare = ((v + rho) * total - (lam + rho) * s <= rho * total + _EPS * total) & (s > 0)
        c = np.where(declare, v * total + rho * (total - s), rho * total)
        return np.asarray(c), np.asarray(np.where(declare, s, 0.0))

    def best_act(
        self, prep: _Prepared, cost: float, r_after: int, best: float
    ) -> tuple[float, int, float, float]:
        """Least value of acting into each image (``cost + children``) if below ``best``.

        Returns the value, the image index (-1 when none beats ``best``), and the chosen
        continuation's cycle cost and success probability (per unit mass).
        """
        lam, v, rho = self.lam, self.verify, self.retry
        pm, s = prep.mass, prep.success
        leaf = np.minimum(rho * pm, (v + rho) * pm - (lam + rho) * s)  # (M, B): leaves
        ub = cost + leaf.sum(axis=1)
        if r_after == 0:
            i = int(np.argmin(ub))
            if ub[i] < best - _EPS:
                c, p = self.leaf_figures_of(pm[i], s[i])
                return float(ub[i]), i, cost + float(c.sum()), float(p.sum())
            return best, -1, math.nan, math.nan
        pick, pick_c, pick_p = -1, math.nan, math.nan
        # The bound on acting again (:meth:`act_bound`) of every (image, reading) pair.
        top, share = self.bound_of(prep)
        gain = top * (v / np.maximum(share, 0.5) - lam - rho)
        act = (self.c_min + rho) * pm + np.minimum(0.0, gain)
        lb_child = np.minimum(leaf, act)
        floor = self.floor(prep, r_after)
        if floor is not None:
            lb_child = np.maximum(lb_child, pm * floor)
        # A child whose leaf is no worse than acting's bound is a leaf (as `value` decides).
        settled = (leaf <= act + _EPS * pm) | (leaf - act < _TINY)
        # Each class's settled leaves, and the bounds of the rest (before any child).
        done_sum = (cost + np.where(settled, leaf, 0.0).sum(axis=1)).tolist()
        rest_sum = np.where(settled, 0.0, lb_child).sum(axis=1).tolist()
        lik_t = self.bins.likelihood.T  # (B, N)
        for i in np.argsort(ub, kind="stable").tolist():
            total, rest = done_sum[i], rest_sum[i]
            if total + rest >= best - _EPS:
                continue
            aborted = False
            img = prep.images[i]
            kids: list[tuple[float, float]] = []
            # The children most above their bounds first: the class is abandoned soonest.
            open_ = np.flatnonzero((pm[i] > 0) & ~settled[i])
            for b in open_[np.argsort(lb_child[i, open_] - leaf[i, open_], kind="stable")]:
                rest -= float(lb_child[i, b])
                pb = float(pm[i, b])
                q = img * lik_t[b] / pb
                # The child matters only if its value is below this (the class is
                # abandoned otherwise): it may stop as soon as it knows it is not.
                budget = (best - _EPS - total - rest) / pb if self.cut else math.inf
                val, cv, pv, exact = self.value(q, r_after, budget, True)
                if floor is None:
                    floor = np.full(pm.shape, _NO_FLOOR)
                    if self.use_floor:
                        prep.floor[r_after] = floor
                if not exact:
                    # ``val`` is a lower bound: abandon the class if that already tells,
                    # with the same arithmetic as below (it is monotone in ``val``).
                    floor[i, b] = max(floor[i, b], val)
                    if total + pb * val + rest >= best - _EPS:
                        aborted = True
                        break
                    val, cv, pv, exact = self.value(q, r_after, math.inf, True)
                floor[i, b] = val
                total += pb * val
                kids.append((pb * cv, pb * pv))
                if total + rest >= best - _EPS:
                    aborted = True
                    break
            if not aborted and total < best - _EPS:
                done = settled[i]
                lc, lp = self.leaf_figures_of(pm[i, done], s[i, done])
                c_sum, p_sum = cost + float(lc.sum()), float(lp.sum())
                for cv, pv in kids:
                    c_sum += cv
                    p_sum += pv
                best, pick, pick_c, pick_p = total, int(i), c_sum, p_sum
        return best, pick, pick_c, pick_p

    def floor(self, prep: _Prepared, r_after: int) -> FloatArray | None:
        """The lower bounds ``prep.floor[r_after]`` if still valid at this price, else None.

        ``V(q, r)`` is the least of ``c(pi) - lambda P(pi)`` over the continuations ``pi``,
        each non-increasing in ``lambda`` (``P >= 0``), so it is non-increasing too: a value
        (or a lower bound) found at a price is a lower bound at every lower price. The
        parametric steps lower the price; a step at a higher price starts a new generation
        (:meth:`set_price`) and the old bounds are dropped.
        """
        if not self.use_floor or prep.floor_gen != self.floor_gen:
            prep.floor = {}
            prep.floor_gen = self.floor_gen
        return prep.floor.get(r_after)

    def set_price(self, lam: float) -> None:
        """Solve at price ``lam`` next (a fresh memo; the floors stay if it is no higher)."""
        if lam > self.lam:
            self.floor_gen += 1
        self.lam = lam
        self.memo = {}

    def prepared(self, key: bytes, q: FloatArray, ti: int) -> tuple[_Prepared, IntArray]:
        """The images of belief ``q`` under kind ``ti``, prepared (kept across prices)."""
        hit = self.prep_cache.get((key, ti))
        if hit is None:
            if self.max_bytes and self.prep_bytes > self.max_bytes:
                raise SearchStopped(
                    f"its beliefs took more than {self.max_bytes / 2**20:,.0f} MB (the memory "
                    "bound: --max-memory MB, `max_memory_mb` in the library)"
                )
            now = time.monotonic()
            if self.progress is not None and now - self.shown > 0.25:
                self.shown = now
                used = self.time_limit - max(self.deadline - now, 0.0)
                self.progress(int(used), math.ceil(self.time_limit))
            if now > self.deadline:
                raise SearchStopped(
                    f"it ran for {self.time_limit:g} s (the time bound: --time-limit S, "
                    "`time_limit_s` in the library)"
                )
            imgs, rows = self.images(q, self.kinds[ti])
            hit = (self.prepare(imgs), rows)
            self.prep_cache[(key, ti)] = hit
            if self.max_bytes:  # the images, reading masses, successes, bounds and floors
                self.prep_bytes += imgs.nbytes + 6 * hit[0].mass.nbytes + 200
        return hit

    def value(
        self, q: FloatArray, r: int, budget: float = math.inf, unsettled: bool = False
    ) -> tuple[float, float, float, bool]:
        """``V(q, r)`` per unit mass (``q`` normalised), its cycle cost and success, exactly.

        With a finite ``budget`` the caller only needs the value if it is below ``budget``:
        the search may then stop early and return ``(bound, nan, nan, False)`` with
        ``V(q, r) >= bound >= budget`` (a cut). Otherwise the last item is True and the value
        is the one the unbudgeted search finds. Memoised with the decision that reaches it
        (a cut is memoised as its bound, and searched again for a larger budget).

        ``unsettled``: the caller (:meth:`best_act`) has found the leaf worse than the bound
        on acting (:meth:`act_bound`, from the images' figures), and any finite budget above
        that bound: the search acts without computing the bound again.
        """
        qk = self.key(q)
        k = (qk, r)
        hit = self.memo.get(k)
        if hit is not None:
            if hit[1] is not None:
                return hit[0], hit[2], hit[3], True
            if hit[0] >= budget:
                return hit[0], math.nan, math.nan, False
        self.searched += 1
        s, o = self.success(q)
        lam, v, rho = self.lam, self.verify, self.retry
        sf = float(s)
        declare = v + rho - (lam + rho) * sf
        best: float
        decision: tuple[Any, ...]
        if declare <= rho + _EPS and sf > 0:  # declaring what cannot succeed: reject
            best, decision, c, p = declare, ("declare", int(o)), v + rho * (1 - sf), sf
        else:
            best, decision, c, p = rho, ("reject",), rho, 0.0
        # An action must beat ``limit - _EPS`` to be taken: the leaf, or the budget when
        # that is lower (then only a value below the budget is of use).
        cutting = budget + _EPS < best
        limit = budget + _EPS if cutting else best
        if r > 0 and (unsettled or limit > float(self.act_bound(q)) + _EPS):
            for ti, kind in enumerate(self.kinds):
                if not len(kind.classes):  # an accuracy left no turn of this kind
                    continue
                prep, rows = self.prepared(qk, q, ti)
                val, i, ci, pi = self.best_act(prep, kind.cost, r - 1, limit)
                if i >= 0:
                    best, decision, c, p = val, ("act", ti, int(rows[i])), ci, pi
                    limit, cutting = val, False
        if cutting:
            self.memo[k] = (budget, None, math.nan, math.nan)
            return budget, math.nan, math.nan, False
        self.memo[k] = (best, decision, c, p)
        return best, c, p, True

    def decision(self, q: FloatArray, r: int) -> tuple[Any, ...]:
        k = (self.key(q), r)
        hit = self.memo.get(k)
        if hit is None or hit[1] is None:
            self.value(q, r)
        return cast(tuple[Any, ...], self.memo[k][1])


# -- building the tree and its figures -----------------------------------------------------


@dataclass(slots=True)
class _Tally:
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
    solver: _Solver
    max_actions: int
    tally: _Tally = field(default_factory=_Tally)
    leaves_at: list[tuple[int, float, float]] = field(default_factory=list)

    def turn(self, kind: _Kind, alpha: float, carry: float) -> tuple[float, float]:
        """The turn to command and the carry it leaves: :func:`.result.short_turns`.

        A gripper with a pi-symmetric action turned by pi is the same gripper; the part then
        lies pi further round in its frame, which later turns and the declared orientation
        absorb.
        """
        steps, rest = short_turns([kind.action], [alpha + carry])
        return steps[0].alpha, rest

    def node(
        self,
        kind: _Kind,
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
        acting again, as :meth:`_Solver.best_act` settles them, or no actions are left) are
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
            settled = (leaf_q <= act_q + _EPS) | (pm * (leaf_q - act_q) < _TINY)
        else:
            settled = np.ones(len(kept), dtype=bool)
        succ, state = s.success(q)
        declare = ((s.verify + s.retry) - (s.lam + s.retry) * succ <= s.retry + _EPS) & (succ > 0)
        # Leaf key of each bin: the declared state, or -1 to reject, or -2 to act on.
        leaf_key = np.where(settled, np.where(declare, state, -1), -2)
        w = mass * pm
        lw = np.where(settled, w, 0.0)
        dw = np.where(settled & declare, w, 0.0)
        t.success += float((dw * succ).sum())
        t.verify_cost += float(dw.sum()) * s.verify
        t.reject += float(np.where(settled & ~declare, w, 0.0).sum())
        if settled.any():
            h = _entropies(q[settled])
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
        merged = _merge_subtrees(_merge_leaves(branches))
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


def _entropies(q: FloatArray) -> FloatArray:
    """Shannon entropy (bits) of each row of normalised beliefs ``q`` (M, N)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(q > 0, q * np.log2(np.where(q > 0, q, 1.0)), 0.0)
    return np.asarray(-terms.sum(axis=1), dtype=np.float64)


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


def candidate_first_angles(
    space: StateSpace, kinds: Sequence[str], max_first_angles: int
) -> tuple[list[float], bool]:
    """Candidate world angles of the first action, and whether they are all that can matter."""
    prior = space.problems[0].prior
    if isinstance(prior, UniformPrior):
        return [0.0], True
    bp = np.mod(np.asarray(prior.breakpoints, dtype=np.float64), TWO_PI)
    bounds = np.concatenate([p.transfer(k).boundaries for p in space.problems for k in kinds])
    cand = np.unique(np.mod((bp[:, None] - bounds[None, :]).ravel(), TWO_PI))
    if isinstance(prior, SamplePrior) and len(cand):
        nxt = np.append(cand[1:], cand[0] + TWO_PI)
        cand = np.mod(0.5 * (cand + nxt), TWO_PI)
    if 0 < len(cand) <= max_first_angles:
        return [float(c) for c in cand], True
    from .exact import plan_exact

    angles = set(np.round(np.linspace(0.0, TWO_PI, 360, endpoint=False), 12).tolist())
    for p in space.problems:
        angles.update(o.first_angle for o in plan_exact(p).options)
    return sorted(float(a) for a in angles), False


def _pairs(space: StateSpace) -> tuple[IntArray, IntArray, NDArray[np.bool_], bool]:
    """The pi pairs of each part's states (each once), and whether they are all pairs."""
    pa: list[int] = []
    pb: list[int] = []
    ok = True
    for j, p in enumerate(space.problems):
        s = p.states.stable
        k = len(s)
        if k % 2 or not np.all(
            circle_distance(np.roll(s, -k // 2), s + math.pi) < 1e3 * p.states.angle_tol
        ):
            ok = False
            break
        o = int(space.offsets[j])
        pa.extend(o + i for i in range(k // 2))
        pb.extend(o + i + k // 2 for i in range(k // 2))
    a = np.asarray(pa, dtype=np.intp)
    b = np.asarray(pb, dtype=np.intp)
    both = space.success_matrix()[a, b] if ok else np.zeros(0, dtype=bool)
    return a, b, np.asarray(both, dtype=bool), ok


DEFAULT_MAX_MEMORY_MB = 2048.0
"""Default bound on the memory of the beliefs a policy search keeps (their images, readings)."""

DEFAULT_TIME_LIMIT_S = 60.0
"""Default bound on the seconds of a policy search (then once more for the fallback)."""


class SearchStopped(PlanningError):
    """A policy search reached its time or memory bound (``reason`` says which)."""

    def __init__(self, reason: str) -> None:
        super().__init__(
            f"the policy search stopped: {reason}; raise the bound, or plan fewer actions"
        )
        self.reason = reason


def time_seconds(time_limit_s: float | None) -> float:
    """The time bound in seconds (``None``: none), or a PlanningError.

    Examples
    --------
    >>> time_seconds(2), time_seconds(None)
    (2.0, inf)
    """
    if time_limit_s is None:
        return math.inf
    if (
        isinstance(time_limit_s, bool)
        or not isinstance(time_limit_s, int | float)
        or not 0 < time_limit_s < 1e9
    ):
        raise PlanningError(f"`time_limit_s` must be a number of seconds > 0; got {time_limit_s!r}")
    return float(time_limit_s)


def memory_bytes(max_memory_mb: float) -> int:
    """The bound in bytes of ``max_memory_mb`` (a number > 0), or a PlanningError.

    Examples
    --------
    >>> memory_bytes(1.5)
    1572864
    """
    if (
        isinstance(max_memory_mb, bool)
        or not isinstance(max_memory_mb, int | float)
        or not 0 < max_memory_mb < 2**40
    ):
        raise PlanningError(f"`max_memory_mb` must be a number of MB > 0; got {max_memory_mb!r}")
    return max(1, int(max_memory_mb * 2**20))


def make_solver(
    space: StateSpace, sens: WidthSensor, prune: Collection[str] = DEFAULT_PRUNE
) -> _Solver:
    """The programme of a state space and sensor (its kinds, bins, goal and bounds)."""
    main = space.problems[0]
    cost = main.cost
    kinds: list[_Kind] = []
    for action in main.actions:
        cl = joint_transition(space, action.name)
        order = np.argsort(-(cl.hi - cl.lo), kind="stable")
        # with an accuracy, only the turns that keep their effect under any error below it
        if main.accuracy > 0:
            order = order[0.5 * (cl.hi - cl.lo)[order] >= main.accuracy]
        kinds.append(
            _Kind(
                action,
                action.name,
                cost.action_cost(action.name),
                cost.action_cost(action.name, first=True),
                np.ascontiguousarray(cl.transfer[order]),
                np.asarray(order, dtype=np.intp),
                cl.mid[order],
                0.5 * (cl.hi - cl.lo)[order],
                math.isclose(action.gripper_period, math.pi),
            )
        )
    goal = space.success_matrix()
    pa, pb, both, paired = _pairs(space)
    bins = space.bins(sens)
    pair_lik = np.maximum(bins.likelihood[pa], bins.likelihood[pb]) if paired else np.zeros((0, 1))
    solver = _Solver(
        space,
        bins,
        kinds,
        cost.verify,
        cost.retry,
        goal,
        bool(np.array_equal(goal, np.eye(space.n_states, dtype=bool))),
        pa,
        pb,
        both,
        paired and all(k.pi_symmetric for k in kinds),
        np.ascontiguousarray(pair_lik),
        cut="cut" in prune,
        use_floor="floor" in prune,
    )
    return solver


def plan_policy(
    problems: Problem | Iterable[Problem],
    sensor: str | WidthSensor = "width",
    max_actions: int = DEFAULT_MAX_ACTIONS,
    *,
    part_prior: str | Sequence[float] | None = None,
    first_angles: Sequence[float] | None = None,
    max_first_angles: int = 512,
    max_iterations: int = 50,
    sensorless: bool = True,
    max_memory_mb: float = DEFAULT_MAX_MEMORY_MB,
    time_limit_s: float | None = DEFAULT_TIME_LIMIT_S,
    best_so_far: bool = True,
    progress: Callable[[int, int], None] | None = None,
    _prune: Collection[str] = DEFAULT_PRUNE,
) -> Policy:
    """The Bayes policy: least expected cost over all policies of at most ``max_actions``.

    See the module notes for the cost semantics and the algorithm.

    Parameters
    ----------
    problems : Problem or iterable of Problem
        One problem, or one per candidate part (recognition). The actions, the cost model,
        the orientation prior and the goal of the first are used for all (each part has its
        own states, transfers and widths).
    sensor : str or WidthSensor
        ``"width"`` (exact), ``"width:SIGMA,RES"`` (part units), or a :class:`WidthSensor`.
    max_actions : int
        At most this many actions on any path (>= 1; default 3).
    part_prior : str or sequence of float, optional
        Prior weights of the candidate parts (default equal).
    first_angles : sequence of float, optional
        World gripper angles to try for the first action (default: see the module notes).
    max_first_angles : int
        Largest number of candidate first angles tried exhaustively.
    max_iterations : int
        Most parametric steps.
    max_memory_mb : float
        Most memory (about, MB) the search may keep for the beliefs it acts on (default
        2048).
    time_limit_s : float or None
        Most seconds the search may take (default 60; ``None``: no bound).
    best_so_far : bool
        When the search reaches either bound: ``True`` (default) plans again, one action
        more at a time from one, within the same bounds once more, and returns the deepest
        policy that finished, with :attr:`Policy.stopped` saying why and
        :attr:`Policy.lower_bound` how little any policy of ``max_actions`` could cost (so
        the search may take up to twice ``time_limit_s``); ``False`` raises
        :class:`SearchStopped`.
    progress : callable, optional
        Called now and then with ``(seconds used, seconds allowed)`` of the time bound (a
        progress bar; with no time bound it is not called).
    sensorless : bool
        Also plan the sensorless Bayes plan (one part; :func:`plan_exact` within
        ``max_actions``): its cost is reported (``Policy.sensorless_cost``) and starts the
        parametric search. ``False`` skips it (faster when the caller has it already).

    Returns
    -------
    Policy

    Raises
    ------
    SensorError
        On a bad sensor or part prior.
    PlanningError
        If ``max_actions < 1``, the problems' actions differ, or their gripper accuracies
        differ (one gripper turns for every candidate part).
    SearchStopped
        A bound was reached and no shorter search finished either (or ``best_so_far`` is
        false).

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> sq = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    >>> round(plan_policy(sq, "width", 2).expected_cost, 6)  # all widths equal: no help
    8.0
    """
    sens = parse_sensor(sensor)
    space = policy_space(problems, part_prior, max_actions)
    main = space.problems[0]
    max_bytes = memory_bytes(max_memory_mb)
    seconds = time_seconds(time_limit_s)
    if first_angles is not None:
        angles = [float(a) for a in first_angles]
        if not angles or not all(math.isfinite(a) for a in angles):
            raise PlanningError(
                f"`first_angles` must be a non-empty list of finite angles; got {first_angles!r}"
            )
        angles_exact = False
    else:
        angles, angles_exact = candidate_first_angles(space, main.action_kinds, max_first_angles)

    def sensorless_within(depth: int) -> float | None:
        if not (sensorless and space.n_parts == 1):
            return None
        from .exact import plan_exact

        return plan_exact(main, max_actions=depth).bayes_plan.expected_cost

    def attempt(depth: int, known: float | None, deadline: float) -> Policy:
        """The best policy within ``depth`` actions; ``known``: a known plan's cost."""
        solver = make_solver(space, sens, _prune)
        solver.max_bytes, solver.deadline, solver.time_limit = max_bytes, deadline, seconds
        solver.progress = progress if math.isfinite(seconds) else None
        roots, root_kind, root_angle = _roots(space, solver.kinds, angles)
        # A known policy's ratio starts the parametric search: one action then declare the
        # likeliest state on every reading, or the sensorless Bayes plan (one part).
        lam = start_ratio(solver, roots, root_kind)
        if known is not None and math.isfinite(known):
            lam = min(lam, known)
        deepen = "deepen" in _prune and sens.sigma > 0
        best_pick, it = search_policy(solver, roots, root_kind, lam, depth, max_iterations, deepen)
        builder = PolicyBuilder(solver, depth)
        k = solver.kinds[root_kind[best_pick]]
        root = builder.node(
            k, root_angle[best_pick], math.inf, roots[best_pick], 1.0, depth - 1, 0.0, 1, True
        )
        return _finish(builder, root, space, sens, depth, sensorless_cost, it, angles_exact)

    sensorless_cost = sensorless_within(max_actions)
    try:
        pol = attempt(max_actions, sensorless_cost, time.monotonic() + seconds)
        return dataclasses.replace(pol, lower_bound=pol.expected_cost)  # it is the optimum
    except SearchStopped as exc:
        stop = exc
    if not best_so_far or max_actions == 1:
        raise stop
    # The best answer so far: the deepest search that finishes within the bounds again.
    deadline = time.monotonic() + seconds
    best: Policy | None = None
    for depth in range(1, max_actions):
        try:
            best = attempt(depth, sensorless_within(depth), deadline)
        except SearchStopped:
            break
    if best is None:
        raise SearchStopped(f"{stop.reason}, and so did the search of one action") from None
    return dataclasses.replace(
        best,
        stopped=stop.reason,
        requested_actions=max_actions,
        lower_bound=_lower_bound(space, sens, angles),
    )


def _roots(
    space: StateSpace, kinds: Sequence[_Kind], angles: Sequence[float]
) -> tuple[FloatArray, list[int], list[float]]:
    """The beliefs after each first action (kind-major over ``angles``), its kind and angle."""
    roots = np.array([space.initial(k.name, a) for k in kinds for a in angles])  # (R, N)
    root_kind = [ti for ti in range(len(kinds)) for _ in angles]
    root_angle = [a for _ in kinds for a in angles]
    return roots, root_kind, root_angle


def _lower_bound(space: StateSpace, sens: WidthSensor, angles: Sequence[float]) -> float:
    """A lower bound on the expected cost of every policy, however many actions it takes.

    A cycle pays its first action ``c_first`` and, when it declares, the verification ``v``;
    it succeeds with probability ``P <= U`` (:meth:`_Solver.bound` of the belief after the
    first action; 1 without pi pairs), and ``E[cost] >= E[C] / P >= c_first / U + v``.
    """
    solver = make_solver(space, sens)
    roots, root_kind, _ = _roots(space, solver.kinds, angles)
    u, _ = solver.bound(roots)
    first = np.array([solver.kinds[ti].first_cost for ti in root_kind])
    with np.errstate(divide="ignore"):
        return float(np.min(first / u)) + solver.verify


def policy_space(
    problems: Problem | Iterable[Problem],
    part_prior: str | Sequence[float] | None,
    max_actions: int,
) -> StateSpace:
    """The state space of the candidate parts, their inputs checked (see :func:`plan_policy`)."""
    if isinstance(max_actions, bool) or not isinstance(max_actions, int) or max_actions < 1:
        raise PlanningError(f"`max_actions` must be an integer >= 1; got {max_actions!r}")
    space = StateSpace.build(problems, part_prior)
    main = space.problems[0]
    if any(p.accuracy != main.accuracy for p in space.problems):
        raise PlanningError(
            "every candidate part's problem must have the same gripper `accuracy`; got "
            + ", ".join(f"{math.degrees(p.accuracy):g} deg" for p in space.problems)
        )
    return space


def start_ratio(solver: _Solver, roots: FloatArray, root_kind: Sequence[int]) -> float:
    """The least ratio of "one action, then declare the likeliest state on every reading"."""
    joint = solver.joint(roots)  # (R, B, N)
    s, _ = solver.success(joint)
    p_succ = s.sum(axis=1)
    c = np.array([solver.kinds[ti].first_cost for ti in root_kind]) + solver.verify
    ratios = (c + solver.retry * (1 - p_succ)) / p_succ
    return float(np.min(ratios))


def search_policy(
    solver: _Solver,
    roots: FloatArray,
    root_kind: Sequence[int],
    lam: float,
    max_actions: int,
    max_iterations: int,
    deepen: bool,
) -> tuple[int, int]:
    """The parametric search (see the module notes) from the known ratio ``lam``.

    ``roots[ri]`` is the belief after the first action of kind ``root_kind[ri]``. Leaves the
    programme of the best step in ``solver`` (its price and memo, which the builder reads) and
    returns the best root and the number of parametric steps. ``deepen``: first search
    within ``max_actions - 1`` actions (worth it with noisy readings).
    """
    kinds = solver.kinds
    root_preps = [solver.prepare(roots[ri : ri + 1]) for ri in range(len(roots))]

    def solve(lam: float, above: float, depth: int) -> tuple[float, int, float]:
        """``h(lambda)``, the best root, and the ratio of the policy that reaches it.

        Only policies of value below ``above - _EPS`` are looked for (pick -1: none).
        """
        solver.set_price(lam)
        h, pick, ratio = above, -1, math.inf
        for ri in range(len(roots)):
            k = kinds[root_kind[ri]]
            val, i, c, p = solver.best_act(root_preps[ri], k.first_cost, depth - 1, h)
            if i >= 0:
                h, pick, ratio = val, ri, (c / p if p > 0 else math.inf)
        return h, pick, ratio

    def dinkelbach(lam: float, depth: int) -> tuple[float, float, int, _Memo, int]:
        """The parametric search within ``depth`` actions from the known ratio ``lam``.

        Returns the best step's price, ratio, root and memo, and the steps taken.
        """
        best_lam, best_ratio, best_pick = lam, math.inf, -1
        best_memo = solver.memo
        it = 0
        for it in range(1, max_iterations + 1):
            # A known policy has ratio ``lam`` (the start's, or the last step's), so value
            # about 0 at this price: only a policy below it is of use, and the bound prunes
            # from the root down. The first step must return a policy (just above 0, or
            # unbounded if the known one lies outside the first angles tried); a later step
            # that finds none below ``-_EPS max(1, |lam|)`` has shown ``h >=`` that, which is
            # the stopping rule.
            scale = max(1.0, abs(lam))
            if it == 1:
                h, pick, ratio = solve(lam, 1e-9 * scale if solver.cut else math.inf, depth)
                if pick < 0:
                    h, pick, ratio = solve(lam, math.inf, depth)
            else:
                h, pick, ratio = solve(lam, _EPS - _EPS * scale if solver.cut else math.inf, depth)
                if pick < 0:
                    break
            logger.debug(
                "policy depth %d step %d: lambda %.12g, h %.3g, ratio %.12g, %d beliefs",
                depth,
                it,
                lam,
                h,
                ratio,
                len(solver.memo),
            )
            improved = ratio < best_ratio
            if improved:
                best_lam, best_ratio, best_pick, best_memo = lam, ratio, pick, solver.memo
            if h >= -_EPS * scale or not improved:
                break
            lam = ratio
        return best_lam, best_ratio, best_pick, best_memo, it

    # Deepening (noisy readings): the best ratio within K - 1 actions is a known policy's
    # within K, a much better start than the first one, and the programme's work at the
    # lower depth (the prepared images, the floors) is of use at the next. (With exact or
    # quantised readings the search is small and the extra solve does not pay.)
    it = 0
    first = max_actions - 1 if deepen else max_actions
    for depth in range(max(first, 1), max_actions + 1):
        best_lam, best_ratio, best_pick, best_memo, steps = dinkelbach(lam, depth)
        it += steps
        if math.isfinite(best_ratio):
            lam = min(lam, best_ratio)
    # The programme at the best price is kept, not solved again (the builder reads it).
    if best_lam > solver.lam:
        solver.floor_gen += 1  # the builder may solve more at this higher price
    solver.lam, solver.memo = best_lam, best_memo
    return best_pick, it


def _finish(
    builder: PolicyBuilder,
    root: PolicyNode,
    space: StateSpace,
    sensor: WidthSensor,
    max_actions: int,
    sensorless: float | None,
    iterations: int,
    angles_exact: bool,
) -> Policy:
    t = builder.tally
    depth = _depth(root)
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


def policy_text(
    policy: Policy, units: str | None = None, digits: int = 2, min_probability: float = 0.0
) -> str:
    """The policy as an indented tree a person can follow (angles in degrees).

    Each node says the action; each branch the readings that take it (``below a``,
    ``in [a, b)``, ``b or more``), the probability of such a reading where the node is
    reached, and what follows. With noisy readings a node has a bin for nearly every
    encoder step, most of them with a tiny probability; ``min_probability`` leaves out of the
    text the branches whose probability where their node is reached is below it (and so
    their subtrees), and says at each node how many were left out and their probability in
    all. The JSON document (:func:`bayesgrasp.io.policies.policy_document`) keeps every
    branch: a robot runs that, not the text.

    Parameters
    ----------
    policy : Policy
    units : str, optional
        Units of the readings (default: the policy's, else none).
    digits : int
        Decimals of readings and angles.
    min_probability : float
        Leave out the branches whose probability at their node is below this (default 0:
        every branch).

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> rect = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)], units="mm"))
    >>> print(policy_text(plan_policy(rect, "width", 2)))
    squeeze with the gripper at 0.00 deg
      if the width reads below 1.50 mm (p = 0.70): declare 90.00 deg (success 0.50)
      if the width reads 1.50 mm or more (p = 0.30): declare 0.00 deg (success 0.50)
    """
    if not 0.0 <= min_probability <= 1.0:
        raise PlanningError(f"min_probability must lie in [0, 1], got {min_probability!r}")
    u = policy.units if units is None else units
    unit = f" {u}" if u else ""
    lines: list[str] = []
    several = len(policy.parts) > 1

    def num(x: float) -> str:
        return f"{x:.{digits}f}"

    def prob(p: float) -> str:
        # Two significant digits below 10^-digits, so a small branch does not read "0.00".
        return f"{p:.{digits}f}" if p >= 10.0**-digits or p == 0.0 else f"{p:.1e}"

    def readings(b: Branch) -> str:
        if b.lo == -math.inf and b.hi == math.inf:
            return "any width"
        if b.lo == -math.inf:
            return f"the width reads below {num(b.hi)}{unit}"
        if b.hi == math.inf:
            return f"the width reads {num(b.lo)}{unit} or more"
        return f"the width reads in [{num(b.lo)}, {num(b.hi)}){unit}"

    def leaf(x: Declare | Reject) -> str:
        if isinstance(x, Reject):
            return "reject (back to the feeder)"
        if policy.payoff is not None:
            likeliest = f"{math.degrees(x.orientation):.{digits}f} deg"
            return (
                f"stop, verify (expected payoff {x.success_probability:.{digits}f}; most "
                f"valued at {likeliest})"
            )
        what = f"{math.degrees(x.orientation):.{digits}f} deg"
        if several:
            what = f"part {x.part_name!r} at {what}"
        return f"declare {what} (success {x.success_probability:.{digits}f})"

    def walk(node: PolicyNode, depth: int, first: bool) -> None:
        pad = "  " * depth
        ang = f"{math.degrees(node.step.alpha):.{digits}f} deg"
        if first:
            lines.append(f"{pad}{node.step.kind} with the gripper at {ang}")
        else:
            lines.append(f"{pad}turn {ang}, {node.step.kind}")
        left_out, left_p = 0, 0.0
        for b in node.branches:
            if b.probability < min_probability:
                left_out += 1
                left_p += b.probability
                continue
            cond = f"{pad}  if {readings(b)} (p = {prob(b.probability)})"
            if isinstance(b.next, PolicyNode):
                lines.append(cond + ":")
                walk(b.next, depth + 2, False)
            else:
                lines.append(f"{cond}: {leaf(b.next)}")
        if left_out:
            s = "" if left_out == 1 else "s"
            lines.append(
                f"{pad}  ({left_out} more reading interval{s}, p = {prob(left_p)} in all, "
                "left out here; the JSON document lists every branch)"
            )

    walk(policy.root, 0, True)
    return "\n".join(lines)
