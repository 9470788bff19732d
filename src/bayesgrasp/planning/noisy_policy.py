"""Policies under noisy actions: jaw-width sensing and turn errors together (the paper, section 6).

The paper lists both extensions: branching on noisy jaw-width readings (section 6.2) and
noisy actions modelled by a conditional distribution (section 6.4). Here they combine. Under
a :class:`~bayesgrasp.model.noise.NoiseModel` (turn error, contact asynchrony) an action of
kind ``t`` turned by ``alpha`` is the row-stochastic matrix ``M_t(alpha)``
(:meth:`~bayesgrasp.model.noise.NoisyTransitions.matrices`; several candidate parts: the
block-diagonal matrix of each part's), and the first action at world angle ``a`` leaves the
prior convolved with its error (:meth:`~bayesgrasp.model.noise.NoisyTransitions.initial`).
A belief ``q`` (over the states, or (part, orientation) pairs) after the last reading becomes

    q -> q M_t(alpha) -> post(q M_t(alpha), b)

(Bayes' rule with the sensor's reading bins, :mod:`bayesgrasp.model.sensing`). The cost
semantics are those of :mod:`bayesgrasp.planning.policy`: a cycle pays its actions and, at a
declaring leaf, the verification; a failed or rejected cycle pays the retry overhead; the
policy minimises ``R = c / P``.

What is optimal, what is bounded
--------------------------------
1. *Exact programme over a candidate set.* At every node the candidate turns of kind ``t``
   are the middles of the noise-free action classes of ``t``
   (:meth:`~bayesgrasp.model.problem.Problem.transition`; several parts: their common
   refinement; with a gripper accuracy, the classes it keeps), as the noisy linear planner
   seeds its hyperstate search (:mod:`.noisy`). With contact asynchrony they also include
   the middles of the common refinement of the classes of every way a squeeze may go (the
   squeeze and the push-grasps from either side): with exact turns ``M_t(alpha)`` is
   constant on each of those classes, so under contact noise alone the candidates hold
   every matrix a turn can give and the programme is exact over all turns. The first
   angle is chosen as the noise-free planner chooses it (any angle under the uniform
   prior). Over the policies of at most ``max_actions`` actions that use only those
   turns, the programme of :mod:`.policy` (Dinkelbach's parametric search, a dynamic
   programme over beliefs, its exact bounds: the pi-pair bound stays valid because the
   turn error and the contact events are symmetric under a turn by pi) finds the least
   ``R``, up to the ``1e-12`` of the belief memo and of the leaf rule. Beliefs that
   coincide to ``2^-40`` count once. (A gripper ``accuracy`` restricts these candidates
   as it restricts the noise-free classes; the refinement below does not keep to it: the
   noise model says what errors do.)
2. *Known policies.* The noise-free Bayes policy (:func:`.policy.plan_policy`) and, for one
   part, the noise-aware sensorless Bayes plan (:func:`.noisy.plan_noisy` within
   ``max_actions``, a policy that never branches) are evaluated under the noise too; the
   returned policy is the least costly of the three after refinement, so it is never worse
   than either (both exactly evaluated under the same noise).
3. *Turn refinement* (bounded, not optimal). With the tree's structure fixed (its actions,
   reading branches and leaves) the value ``c - lambda P`` is linear in the belief entering
   any node, ``f(alpha) = left M_t(alpha) r`` with ``left`` the (unnormalised) belief that
   reaches the node and ``r`` the per-state value of what follows. Each turn after the
   first is optimised in turn over the whole circle at ``lambda = R`` of the current tree,
   as :mod:`.noisy` refines a plan's turns: exactly for a uniform error (``f`` is
   piecewise linear: its kinks) and for exact turns with contact noise (``f`` is constant
   between critical turns); for a normal error on a grid of step ``h = sigma / 6`` near the
   critical turns, then ``h / 32`` about the best point, so that the best grid point is
   within ``eps = |f''|max h^2 / 8`` of the turn's best with
   ``|f''| <= 2 phi(1) / sigma^2 * mass * span(r)``
   (:attr:`~bayesgrasp.model.noise.TurnNoise.curvature_bound`). A node whose
   ``mass * span(r)`` (the most any turn can change its value by) is below the grid bound
   of the heaviest node is not searched: its bound is that product. A new turn is taken
   only if the matrices the evaluation uses confirm the gain. Sweeps repeat (at most
   :data:`MAX_SWEEPS`) while the ratio falls (a lower value at ``lambda = R`` is a lower
   ratio: Dinkelbach's step). :attr:`Policy.refinement_bound` is the largest bound over the
   nodes in the last sweep: no single turn, the rest kept, lowers ``c - lambda P`` (at that
   sweep's ``lambda``, the ratio before it) by more. Not guaranteed: the best over all
   turns at once, or over turns outside the candidate set in the programme (a multimodal
   problem, as for noisy plans); the tests compare the policy with an exhaustive search
   over a 0.5 deg turn grid at depth 2.
4. *Exact figures.* The returned policy's branch probabilities, leaf success
   probabilities, success probability, cycle cost, expected cost, expected actions and
   expected entropy after each level are recomputed on the returned tree by propagating
   the beliefs of every reading history through each node's matrix and the reading
   likelihoods (:func:`evaluate_policy`); nothing is sampled. With a non-uniform prior the
   first action's average over its own error is a 512-node Gauss-Legendre rule (as for
   plans).

With no noise at all, :func:`plan_noisy_policy` returns :func:`.policy.plan_policy`'s policy.

Bounds: the programme keeps the images of every belief it acts on (with their reading masses
and bounds); ``max_memory_mb`` bounds their size and ``time_limit_s`` the seconds of the
search (the noise-free policy, the sensorless plan and the programme; the refinement after
them runs to its end). Noisy actions make almost every belief new (the memo of the
noise-free programme helps little), so the work grows like ``(A B)^(K - 1)`` beliefs for
``A`` candidate turns, ``B`` reading bins and ``K`` actions, less what the bounds prune.
Past either bound the search answers as the exact policy search does
(:func:`~bayesgrasp.planning.search_bounds.deepest_within_bounds`): it plans again one
action deeper at a time from one, within the same bounds once more, and returns the deepest
policy that finished, with :attr:`Policy.stopped` saying why, ``requested_actions`` and a
``lower_bound`` on the cost of every policy of the requested depth (``c_first / U + v`` of
the noisy first beliefs, :func:`~bayesgrasp.planning.policy.lower_bound`); with
``best_so_far=False`` it raises :class:`~bayesgrasp.planning.search_bounds.SearchStopped`.
Payoff (the paper, section 6.4; :mod:`bayesgrasp.model.payoff`, one part): the value
``u_j`` in [0, 1] of ending in state ``j`` replaces the goal. A declaring leaf then stops,
verifies and earns the payoff of the state the part is in: per unit mass it costs
``v + rho (1 - q . u)`` and succeeds ``q . u`` (the leaf names the state of most
``q_j u_j``). The policy minimises the expected cost per unit payoff,
``E[cycle cost] / E[payoff]``, as :func:`.noisy.plan_noisy` does for plans (for a 0/1
payoff that is today's cost); a payoff needs no noise. The pi-pair bound is not used
(both states of a pair may pay).

Examples
--------
>>> import math
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.model.noise import NoiseModel, TurnNoise
>>> rect = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
>>> noise = NoiseModel(TurnNoise("normal", math.radians(2)))
>>> pol = plan_noisy_policy(rect, "width", 2, noise)
>>> round(pol.success_probability, 6), round(pol.expected_cost, 4)
(0.5, 4.0)
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
from collections.abc import Iterable, Sequence
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PlanningError
from ..model.noise import NoiseModel
from ..model.payoff import Payoff, as_vector
from ..model.problem import Problem
from ..model.sensing import StateSpace, WidthSensor, parse_sensor
from .noisy import plan_noisy
from .noisy_model import (
    MutableNode,
    NoisyModel,
    exact_figures,
    first_of_each_matrix,
    linear_tree,
    mutable_tree,
    tree_nodes,
)
from .noisy_refine import MAX_SWEEPS, refine_turns
from .policy import (
    DEFAULT_MAX_ACTIONS,
    best_policy_within,
    candidate_first_angles,
    lower_bound,
    plan_policy,
    policy_space,
    search_root,
    start_ratio,
)
from .policy_tree import Policy
from .programme import DEFAULT_PRUNE, Solver, make_solver
from .search_bounds import (
    DEFAULT_MAX_MEMORY_MB,
    check_deadline,
    deepest_within_bounds,
    memory_bytes,
    time_seconds,
)

__all__ = ["MAX_SWEEPS", "evaluate_policy", "plan_noisy_policy"]

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]


def plan_noisy_policy(
    problems: Problem | Iterable[Problem],
    sensor: str | WidthSensor = "width",
    max_actions: int = DEFAULT_MAX_ACTIONS,
    noise: NoiseModel | None = None,
    *,
    payoff: Payoff | ArrayLike | None = None,
    part_prior: str | Sequence[float] | None = None,
    max_first_angles: int = 512,
    max_iterations: int = 50,
    max_memory_mb: float = DEFAULT_MAX_MEMORY_MB,
    time_limit_s: float | None = None,
    refine: bool = True,
    sensorless: bool = True,
    best_so_far: bool = True,
    _always: bool = False,
) -> Policy:
    """The Bayes policy under noisy actions (see the module notes for what is optimal).

    Parameters
    ----------
    problems : Problem or iterable of Problem
        One problem, or one per candidate part (as :func:`.policy.plan_policy`).
    sensor : str or WidthSensor
        ``"width"`` (exact), ``"width:SIGMA,RES"`` (part units), or a :class:`WidthSensor`.
    max_actions : int
        At most this many actions on any path (>= 1; default 3).
    noise : NoiseModel, optional
        The action noise; ``None`` or no noise (and no payoff): :func:`.policy.plan_policy`'s
        policy.
    payoff : Payoff or array_like of shape (K,), optional
        One part only: the value in [0, 1] of each final state
        (:mod:`bayesgrasp.model.payoff`). A declaring leaf then stops and earns the payoff
        of the state the part is in, and the policy minimises the expected cost per unit
        payoff (see the module notes).
    part_prior : str or sequence of float, optional
        Prior weights of the candidate parts (default equal).
    max_first_angles : int
        Largest number of candidate first angles tried exhaustively.
    max_iterations : int
        Most parametric steps.
    max_memory_mb : float
        About the most memory (MB) the programme's kept beliefs may take (their images,
        reading masses and bounds; > 0).
    time_limit_s : float or None
        Most seconds the search may take (``None``: no bound; the refinement after the
        search runs to its end).
    best_so_far : bool
        When the search reaches either bound: ``True`` (default) plans again, one action
        more at a time from one, within the same bounds once more, and returns the deepest
        policy that finished, with :attr:`Policy.stopped` saying why and
        :attr:`Policy.lower_bound` how little any policy of ``max_actions`` could cost (so
        the search may take up to twice ``time_limit_s``); ``False`` raises
        :class:`~bayesgrasp.planning.search_bounds.SearchStopped`.
    refine : bool
        Refine the turns (see the module notes); ``False`` keeps the candidate turns.
    sensorless : bool
        Also plan the noise-aware sensorless plan (one part): reported as
        ``Policy.sensorless_cost`` and one of the known policies.

    Returns
    -------
    Policy
        Its figures exact under the noise; ``noise`` and ``refinement_bound`` set.

    Raises
    ------
    PlanningError
        As :func:`.policy.plan_policy`, or a ``max_memory_mb`` or ``time_limit_s`` not
        above 0.
    SearchStopped
        A bound was reached and no shorter search finished either (or ``best_so_far`` is
        false).
    SensorError
        On a bad sensor or part prior.

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
    >>> noise = NoiseModel(TurnNoise("uniform", math.radians(3)))
    >>> pol = plan_noisy_policy(tri, "width", 2, noise)
    >>> pol.expected_cost <= plan_policy(tri, "width", 2).expected_cost + 1e-9
    True
    """
    sens = parse_sensor(sensor)
    max_bytes = memory_bytes(max_memory_mb)  # a bad bound: refused before any work
    seconds = time_seconds(time_limit_s)
    if noise is not None and not isinstance(noise, NoiseModel):
        raise PlanningError(f"`noise` must be a NoiseModel; got {type(noise).__name__}")
    if payoff is None and (noise is None or (noise.exact and not _always)):
        return plan_policy(
            problems,
            sens,
            max_actions,
            part_prior=part_prior,
            max_first_angles=max_first_angles,
            max_iterations=max_iterations,
            sensorless=sensorless,
            max_memory_mb=max_memory_mb,
            time_limit_s=time_limit_s,
            best_so_far=best_so_far,
        )
    noise = noise or NoiseModel()
    space = policy_space(problems, part_prior, max_actions)
    main = space.problems[0]
    model = NoisyModel(space, sens, noise)
    u: FloatArray | None = None
    if payoff is not None:
        if space.n_parts > 1:
            raise PlanningError("a payoff is for one part; got several candidate parts")
        u = as_vector(payoff, main.states)
        model.payoff = u
    turns: list[tuple[FloatArray, FloatArray, FloatArray]] = []  # each kind's, made once

    def noisy_solver(deadline: float) -> Solver:
        """The programme over the candidate turns' noisy matrices (see the module notes)."""
        solver = make_solver(space, sens, DEFAULT_PRUNE)
        if u is not None:
            # Stopping earns ``q . u``: the programme's success is that one row (no pi-pair
            # bound: both states of a pair may pay; the payoff is at most 1, so the bound
            # ``U = total`` holds).
            solver.goal = cast(Any, u[None, :])
            solver.goal_is_identity = False
            solver.use_pairs = False
        solver.max_bytes = max_bytes
        solver.deadline, solver.time_limit = deadline, seconds
        if not turns:
            turns.extend(candidate_turns(model, solver, main.accuracy))
        for k, (mid, half, mats) in zip(solver.kinds, turns, strict=True):
            k.mid, k.half_width = mid, half
            k.classes = np.arange(len(mid), dtype=np.intp)
            k.transfer = np.zeros((len(mid), space.n_states), dtype=np.intp)  # unused: matrices
            k.matrices = mats
        return solver

    angles, angles_exact = candidate_first_angles(space, main.action_kinds, max_first_angles)
    kinds = [a.name for a in main.actions]  # the order of the programme's kinds
    roots = np.array([model.initial(k, a) for k in kinds for a in angles])  # (R, N)
    root_kind = [ti for ti in range(len(kinds)) for _ in angles]
    root_angle = [a for _ in kinds for a in angles]
    sensorless_plan = (
        plan_noisy(main, noise, u, max_actions=max_actions)
        if sensorless and space.n_parts == 1
        else None
    )
    sensorless_cost = (
        None if sensorless_plan is None else sensorless_plan.bayes_plan.option.expected_cost
    )

    def attempt(depth: int, deadline: float) -> Policy:
        """The best policy within ``depth`` actions; raises SearchStopped past a bound."""
        solver = noisy_solver(deadline)
        model.check = functools.partial(check_deadline, deadline, seconds)
        # Known policies: their exact ratios under the noise start the parametric search.
        known: list[tuple[MutableNode, float, str]] = []
        free_space = policy_space(list(space.problems), list(space.part_prior), depth)
        free_angles, free_exact = candidate_first_angles(
            free_space, main.action_kinds, max_first_angles
        )
        free = best_policy_within(
            free_space,
            sens,
            free_angles,
            depth,
            deadline,
            angles_exact=free_exact,
            max_iterations=max_iterations,
            max_bytes=max_bytes,
            seconds=seconds,
        )
        known.append((mutable_tree(free.root, model), free.root.step.alpha, "noise-free policy"))
        if sensorless_plan is not None:
            res = sensorless_plan if depth == max_actions else plan_noisy(main, noise, u, depth)
            check_deadline(deadline, seconds)
            opt = res.bayes_plan
            kinds_ = [s.kind for s in opt.option.steps]
            alphas = [s.alpha for s in opt.option.steps]
            final = opt.evaluation.final_state
            known.append((linear_tree(model, kinds_, alphas, final), alphas[0], "sensorless"))
        lam = start_ratio(solver, roots, root_kind)
        evaluated = [
            (exact_figures(model, t, a).expected_cost, t, a, label) for t, a, label in known
        ]
        for c, *_ in evaluated:
            if math.isfinite(c):
                lam = min(lam, c)
        root, _, it = search_root(
            solver, roots, root_kind, root_angle, lam, depth, max_iterations, sens.sigma > 0
        )
        dp = mutable_tree(root, model)
        cands = [
            (exact_figures(model, dp, root.step.alpha).expected_cost, dp, root.step.alpha, "dp")
        ]
        cands += evaluated
        # Refinement (the dominant work) for the programme's policy, and for a known one only
        # if it is already better than that.
        out: list[tuple[float, float, int, MutableNode, float, str]] = []
        for order, (c, tree, a, label) in enumerate(cands):
            eps = 0.0
            if refine and math.isfinite(c) and (order == 0 or c < out[0][0]):
                c, eps = refine_turns(model, tree, a, c)
            out.append((c, eps, order, tree, a, label))
        c, eps, _, tree, a, label = min(out, key=lambda x: (x[0], x[2]))
        logger.debug("noisy policy: %s, ratio %.12g", label, c)
        for node, first in tree_nodes(tree):
            node.margin = math.inf if first else 0.0
        ev = exact_figures(model, tree, a)
        return Policy(
            ev.strategy,
            space.names,
            tuple(float(w) for w in space.part_prior),
            sens,
            depth,
            ev.expected_cost,
            ev.success_probability,
            ev.cycle_cost,
            ev.reject_probability,
            ev.expected_actions,
            ev.expected_entropy,
            sensorless_cost,
            it,
            len(solver.memo),
            angles_exact,
            main.part.units,
            solver.searched,
            None if noise.exact else noise,
            eps,
            None if u is None else tuple(float(x) for x in u),
        )

    try:
        return deepest_within_bounds(
            attempt,
            max_actions,
            seconds,
            lambda: lower_bound(noisy_solver(math.inf), roots, root_kind),
            best_so_far=best_so_far,
        )
    finally:
        model.check = None


def candidate_turns(
    model: NoisyModel, solver: Solver, accuracy: float
) -> list[tuple[FloatArray, FloatArray, FloatArray]]:
    """Each kind's candidate turns, their half widths and (A, N, N) matrices, widest first.

    The noise-free classes of ``solver``'s kinds and, with contact asynchrony, the classes
    of every way the action may go (:meth:`NoisyModel.candidates`); with a gripper
    ``accuracy`` only the turns that keep their class under it; a turn whose matrix a wider
    candidate has already is dropped (the same action).
    """
    out = []
    for k in solver.kinds:
        mid, half = model.candidates(k.name, np.asarray(k.mid), np.asarray(k.half_width))
        if accuracy > 0:  # only turns that keep their class under the accuracy
            keep = half >= accuracy
            mid, half = mid[keep], half[keep]
        mats = model.matrices(k.name, mid)
        if model.noise.contact > 0:
            # A turn whose matrix an earlier (wider) candidate has already is the same
            # action: under exact turns, the middle of a noise-free class lies in a class
            # of the refinement (where the matrix is constant), whose middle is a candidate
            # too. (Without contact noise the candidates are the noise-free classes, each
            # its own action.)
            once = first_of_each_matrix(mats)
            mid, half, mats = mid[once], half[once], mats[once]
        out.append((mid, half, np.ascontiguousarray(mats)))
    return out


def evaluate_policy(
    problems: Problem | Iterable[Problem],
    policy: Policy,
    noise: NoiseModel | None = None,
) -> Policy:
    """A policy's figures recomputed exactly under a noise model (its tree unchanged).

    Every reading history's belief is propagated through each node's noisy matrix and the
    reading likelihoods of its branches (see the module notes); the branch and leaf
    probabilities are those under the noise.

    Parameters
    ----------
    problems : Problem or iterable of Problem
        The candidate parts, in the policy's order.
    policy : Policy
    noise : NoiseModel, optional
        Default: exact actions.

    Returns
    -------
    Policy

    Examples
    --------
    >>> import math
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
    >>> pol = plan_policy(tri, "width", 2)
    >>> abs(evaluate_policy(tri, pol).expected_cost - pol.expected_cost) < 1e-12
    True
    """
    noise = noise or NoiseModel()
    space = StateSpace.build(problems, list(policy.part_prior))
    model = NoisyModel(space, policy.sensor, noise)
    if policy.payoff is not None:
        model.payoff = np.asarray(policy.payoff, dtype=np.float64)
    tree = mutable_tree(policy.root, model)
    ev = exact_figures(model, tree, policy.root.step.alpha)
    return dataclasses.replace(
        policy,
        root=ev.strategy,
        expected_cost=ev.expected_cost,
        success_probability=ev.success_probability,
        cycle_cost=ev.cycle_cost,
        reject_probability=ev.reject_probability,
        expected_actions=ev.expected_actions,
        expected_entropy=ev.expected_entropy,
        noise=None if noise.exact else noise,
    )
