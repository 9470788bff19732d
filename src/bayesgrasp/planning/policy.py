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

import logging
import math
from collections.abc import Callable, Collection, Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.prior import SamplePrior, UniformPrior
from ..model.problem import Problem
from ..model.sensing import StateSpace, WidthSensor, parse_sensor
from .policy_builder import PolicyBuilder, finish_policy
from .policy_tree import Branch, Declare, Leaf, Policy, PolicyNode, Reject, policy_text
from .programme import DEFAULT_PRUNE, EPS, ActionKind, Memo, Solver, joint_transition, make_solver
from .search_bounds import (
    DEFAULT_MAX_MEMORY_MB,
    DEFAULT_TIME_LIMIT_S,
    SearchStopped,
    deepest_within_bounds,
    memory_bytes,
    time_seconds,
)

__all__ = [
    "DEFAULT_MAX_ACTIONS",
    "DEFAULT_MAX_MEMORY_MB",
    "DEFAULT_PRUNE",
    "DEFAULT_TIME_LIMIT_S",
    "Branch",
    "Declare",
    "Leaf",
    "Policy",
    "PolicyBuilder",
    "PolicyNode",
    "Reject",
    "SearchStopped",
    "best_policy_within",
    "candidate_first_angles",
    "joint_transition",
    "lower_bound",
    "make_solver",
    "memory_bytes",
    "plan_policy",
    "policy_space",
    "policy_text",
    "root_beliefs",
    "search_policy",
    "search_root",
    "start_ratio",
    "time_seconds",
]

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]
DEFAULT_MAX_ACTIONS = 3


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

    sensorless_cost = sensorless_within(max_actions)

    def attempt(depth: int, deadline: float) -> Policy:
        return best_policy_within(
            space,
            sens,
            angles,
            depth,
            deadline,
            known=sensorless_cost if depth == max_actions else sensorless_within(depth),
            sensorless_cost=sensorless_cost,
            angles_exact=angles_exact,
            max_iterations=max_iterations,
            max_bytes=max_bytes,
            seconds=seconds,
            progress=progress,
            prune=_prune,
        )

    return deepest_within_bounds(
        attempt,
        max_actions,
        seconds,
        lambda: _lower_bound(space, sens, angles),
        best_so_far=best_so_far,
        complete_bound=lambda pol: pol.expected_cost,  # a finished search: the optimum
    )


def best_policy_within(
    space: StateSpace,
    sens: WidthSensor,
    angles: Sequence[float],
    depth: int,
    deadline: float,
    *,
    known: float | None = None,
    sensorless_cost: float | None = None,
    angles_exact: bool = True,
    max_iterations: int = 50,
    max_bytes: int = 0,
    seconds: float = math.inf,
    progress: Callable[[int, int], None] | None = None,
    prune: Collection[str] = DEFAULT_PRUNE,
) -> Policy:
    """The best policy of at most ``depth`` actions with exact actions (one search).

    The first action at one of ``angles``; ``known``: a known policy's cost (it may start
    the parametric search); ``sensorless_cost``, ``angles_exact``: as the policy reports
    them. Raises :class:`SearchStopped` past ``deadline`` (``time.monotonic()``; the bound
    of ``seconds``) or ``max_bytes`` of kept beliefs (0: no bound).
    """
    solver = make_solver(space, sens, prune)
    solver.max_bytes, solver.deadline, solver.time_limit = max_bytes, deadline, seconds
    solver.progress = progress if math.isfinite(seconds) else None
    roots, root_kind, root_angle = root_beliefs(space, solver.kinds, angles)
    # A known policy's ratio starts the parametric search: one action then declare the
    # likeliest state on every reading, or the sensorless Bayes plan (one part).
    lam = start_ratio(solver, roots, root_kind)
    if known is not None and math.isfinite(known):
        lam = min(lam, known)
    deepen = "deepen" in prune and sens.sigma > 0
    root, builder, it = search_root(
        solver, roots, root_kind, root_angle, lam, depth, max_iterations, deepen
    )
    return finish_policy(builder, root, space, sens, depth, sensorless_cost, it, angles_exact)


def search_root(
    solver: Solver,
    roots: FloatArray,
    root_kind: Sequence[int],
    root_angle: Sequence[float],
    lam: float,
    depth: int,
    max_iterations: int,
    deepen: bool,
) -> tuple[PolicyNode, PolicyBuilder, int]:
    """The parametric search from ``lam`` (:func:`search_policy`) and the tree it found.

    Returns the root of the best policy of at most ``depth`` actions, its builder (with the
    tallied figures) and the number of parametric steps.
    """
    best_pick, it = search_policy(solver, roots, root_kind, lam, depth, max_iterations, deepen)
    builder = PolicyBuilder(solver, depth)
    k = solver.kinds[root_kind[best_pick]]
    root = builder.node(
        k, root_angle[best_pick], math.inf, roots[best_pick], 1.0, depth - 1, 0.0, 1, True
    )
    return root, builder, it


def root_beliefs(
    space: StateSpace, kinds: Sequence[ActionKind], angles: Sequence[float]
) -> tuple[FloatArray, list[int], list[float]]:
    """The beliefs after each first action (kind-major over ``angles``), its kind and angle.

    Exact actions: the prior mass of each state's basins (:meth:`StateSpace.initial`).
    """
    roots = np.array([space.initial(k.name, a) for k in kinds for a in angles])  # (R, N)
    root_kind = [ti for ti in range(len(kinds)) for _ in angles]
    root_angle = [a for _ in kinds for a in angles]
    return roots, root_kind, root_angle


def lower_bound(solver: Solver, roots: FloatArray, root_kind: Sequence[int]) -> float:
    """A lower bound on the expected cost of every policy from the first beliefs ``roots``.

    However many actions it takes: a cycle pays its first action ``c_first`` and, when it
    declares, the verification ``v``; it succeeds with probability ``P <= U``
    (:meth:`~bayesgrasp.planning.programme.Solver.bound` of the belief after the first
    action; 1 without pi pairs), and ``E[cost] >= E[C] / P >= c_first / U + v``.
    ``roots[i]`` is the belief after a first action of kind ``root_kind[i]``.
    """
    u, _ = solver.bound(roots)
    first = np.array([solver.kinds[ti].first_cost for ti in root_kind])
    with np.errstate(divide="ignore"):
        return float(np.min(first / u)) + solver.verify


def _lower_bound(space: StateSpace, sens: WidthSensor, angles: Sequence[float]) -> float:
    """:func:`lower_bound` of the exact actions' first beliefs at ``angles``."""
    solver = make_solver(space, sens)
    roots, root_kind, _ = root_beliefs(space, solver.kinds, angles)
    return lower_bound(solver, roots, root_kind)


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


def start_ratio(solver: Solver, roots: FloatArray, root_kind: Sequence[int]) -> float:
    """The least ratio of "one action, then declare the likeliest state on every reading"."""
    joint = solver.joint(roots)  # (R, B, N)
    s, _ = solver.success(joint)
    p_succ = s.sum(axis=1)
    c = np.array([solver.kinds[ti].first_cost for ti in root_kind]) + solver.verify
    ratios = (c + solver.retry * (1 - p_succ)) / p_succ
    return float(np.min(ratios))


def search_policy(
    solver: Solver,
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

        Only policies of value below ``above - EPS`` are looked for (pick -1: none).
        """
        solver.set_price(lam)
        h, pick, ratio = above, -1, math.inf
        for ri in range(len(roots)):
            k = kinds[root_kind[ri]]
            val, i, c, p = solver.best_act(root_preps[ri], k.first_cost, depth - 1, h)
            if i >= 0:
                h, pick, ratio = val, ri, (c / p if p > 0 else math.inf)
        return h, pick, ratio

    def dinkelbach(lam: float, depth: int) -> tuple[float, float, int, Memo, int]:
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
            # that finds none below ``-EPS max(1, |lam|)`` has shown ``h >=`` that, which is
            # the stopping rule.
            scale = max(1.0, abs(lam))
            if it == 1:
                h, pick, ratio = solve(lam, 1e-9 * scale if solver.cut else math.inf, depth)
                if pick < 0:
                    h, pick, ratio = solve(lam, math.inf, depth)
            else:
                h, pick, ratio = solve(lam, EPS - EPS * scale if solver.cut else math.inf, depth)
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
            if h >= -EPS * scale or not improved:
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
