"""Guaranteed plans under bounded noise: every execution ends on the goal's orbit.

A guaranteed plan (:mod:`bayesgrasp.planning.guaranteed`, Goldberg 1993) sends every
initial orientation to one final orientation up to the period ``T``. Under a noise model
(:mod:`bayesgrasp.model.noise`) a guarantee must hold for every error the noise can make:

- *Uniform turn error* of half-width ``A``: a guaranteed plan whose turns tolerate ``A``
  (its tolerance, the margin each image keeps inside the next arc, is at least ``A``) still
  guarantees; the first action's error does not matter, since the plan orients every
  initial orientation. This is the guaranteed planner with a gripper accuracy of
  ``max(A, problem.accuracy)``.
- *Normal turn error*: unbounded, so every turn after the first may land anywhere and the
  last action may end in any of its stable orientations; no plan of two or more actions
  guarantees (:data:`UNBOUNDED_GUARANTEE`).
- *Contact noise* ``q > 0``: every squeeze may act as a push-grasp from either side (each
  with probability ``q / 2``). A guarantee must hold for every such event; which events can
  happen does not depend on the value of ``q`` (for ``0 < q < 1``; at ``q = 1`` the
  simultaneous squeeze is gone), so neither does the plan.

With contact noise the arcs of the guaranteed planner no longer apply (a noisy squeeze is
not one monotone map), so the plan comes from Goldberg's original formulation, a
breadth-first search over *sets* of states (:func:`support_search`): after the first action
the part can be in any state its transition reaches from some orientation; an action at
turn ``alpha`` sends a set ``S`` to the union of the supports of the rows of ``S`` of its
exact transition matrix under the noise (:class:`~bayesgrasp.model.noise.NoisyTransitions`).
That support is constant between the *critical turns* ``S_i - o - B_b +- A`` (state ``S_i``
of ``S``, contact offset ``o``, basin boundary ``B_b``), so the middle of each interval
between consecutive critical turns stands for all of it, and the search over those middles
is exhaustive: the first level with a set inside one orbit gives the shortest plan (then
the cheapest, then the one of widest intervals). A turn may err by ``A`` plus half its
interval's width and the sets stay the same: that is the plan's tolerance. A gripper
accuracy (``Problem.accuracy``) larger than ``A`` is searched as the error's half-width.

The tests hold the two methods together: without contact noise the set search finds plans
of the guaranteed planner's length, and every plan's executions, simulated with the noise
drawn, all end on the orbit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.noise import NoiseModel, NoisyTransitions, TurnNoise
from ..model.prior import UniformPrior
from ..model.problem import Problem, nearest_state
from .arcs import period_cap
from .guaranteed import GuaranteedPlan, plan_guaranteed
from .result import PlanOption, PlanStep, max_plan_length

__all__ = ["MAX_SETS", "UNBOUNDED_GUARANTEE", "SetPlan", "plan_guaranteed_noisy", "support_search"]

BoolArray = NDArray[np.bool_]

UNBOUNDED_GUARANTEE = (
    "no plan of two or more actions can guarantee under normal turn noise: its error is "
    "unbounded, so every turn may err by any angle (give uniform:A_DEG for a bounded error)"
)
"""Why :func:`plan_guaranteed_noisy` refuses a normal turn error."""

MAX_SETS = 20_000
"""Most sets of states :func:`support_search` visits before it gives up."""
_SUPPORT = 1e-12  # a transition probability above this is a possible outcome
_CHUNK = 1 << 21  # matrix entries computed at once


@dataclass(frozen=True, slots=True)
class SetPlan:
    """A plan found by :func:`support_search`.

    Attributes
    ----------
    kinds : tuple of str
    angles : tuple of float
        The first action's world angle (0: any angle orients every orientation), then the
        turns, each the middle of its interval of turns.
    margin : float
        The least half-width of those intervals (the tolerance beyond ``error``).
    error : float
        The turn error searched for: the larger of the uniform error's half-width and the
        problem's gripper accuracy.
    final : ndarray of bool, shape (K,)
        The states the part can end in (all on one orbit).
    """

    kinds: tuple[str, ...]
    angles: tuple[float, ...]
    margin: float
    error: float
    final: BoolArray


def _orbits(problem: Problem, period: float) -> NDArray[np.intp]:
    """The orbit of each state under turns by ``period``: the least state index in it."""
    stable = problem.states.stable
    copies = max(1, round(TWO_PI / period))
    out = np.arange(len(stable))
    for m in range(1, copies):
        out = np.minimum(out, nearest_state(problem.states, stable + m * period))
    return np.asarray(out, dtype=np.intp)


def support_search(
    problem: Problem, noise: NoiseModel, max_actions: int | None = None, max_sets: int = MAX_SETS
) -> SetPlan | str:
    """The shortest plan whose every execution under the noise ends on one goal orbit.

    Breadth-first over the sets of states the part can be in (see the module notes); the
    orbit is that of the guaranteed planner's period (:func:`~.arcs.period_cap`).

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel
        Exact or uniform turn error; any contact noise.
    max_actions : int, optional
        Longest plan (default :func:`~.result.max_plan_length`).
    max_sets : int
        Most sets visited.

    Returns
    -------
    SetPlan or str
        The plan, or why there is none.

    Raises
    ------
    PlanningError
        A normal turn error (:data:`UNBOUNDED_GUARANTEE`).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> found = support_search(pb, NoiseModel(contact=0.1))
    >>> len(found.kinds), [round(math.degrees(a), 1) for a in found.angles]
    (2, [0.0, -45.0])
    """
    turn = noise.turn
    if not turn.exact and turn.kind == "normal":
        raise PlanningError(UNBOUNDED_GUARANTEE)
    # The gripper accuracy is a bounded turn error too: the larger of the two is searched.
    width = max(0.0 if turn.exact else turn.scale, problem.accuracy)
    if width > 0 and (turn.exact or width > turn.scale):
        noise = NoiseModel(TurnNoise("uniform", width), noise.contact)
    period = period_cap(problem)
    orbit = _orbits(problem, period)
    everywhere = _uniform(problem)
    nt = NoisyTransitions(everywhere, noise)
    limit = max_plan_length(problem) if max_actions is None else max_actions
    tol = 1e3 * problem.states.angle_tol
    # A squeeze's gripper turned by pi is the same gripper (its frame turned by pi): turns
    # in (-g/2, g/2] for gripper period g (later turns range over their own periods).
    periods = {t: problem.action(t).gripper_period for t in problem.action_kinds}

    def done(s: BoolArray) -> bool:
        return len(np.unique(orbit[s])) == 1

    # A node: (set, kinds, angles, margin); level 1 is each first action from everywhere.
    level: list[tuple[BoolArray, tuple[str, ...], tuple[float, ...], float]] = []
    seen: set[bytes] = set()
    for t in problem.action_kinds:
        s = nt.initial(t, 0.0) > _SUPPORT
        level.append((s, (t,), (0.0,), math.inf))
        seen.add(s.tobytes())
    for k in range(1, limit + 1):
        goals = [node for node in level if done(node[0])]
        if goals:
            cost = problem.cost.attempt_cost
            s, kinds, angles, margin = min(goals, key=lambda n: (cost(n[1]), -n[3]))
            return SetPlan(kinds, angles, 0.0 if k == 1 else margin, width, s)
        if k == limit:
            break
        nxt = []
        for s, kinds, angles, margin in level:
            rows = np.flatnonzero(s)
            for t in problem.action_kinds:
                mids, half = _intervals(nt, t, rows, width, tol, periods[t])
                if len(mids) == 0:
                    continue
                image = _images(nt, t, mids, rows)
                for i in np.argsort(-half, kind="stable"):  # widest first: kept on ties
                    key = image[i].tobytes()
                    if key in seen:
                        continue
                    seen.add(key)
                    m = min(margin, float(half[i]))
                    nxt.append((image[i], (*kinds, t), (*angles, float(mids[i])), m))
                if len(seen) > max_sets:
                    return f"the search stopped after {max_sets} sets of states"
        if not nxt:  # every set the plans can reach has been seen
            return (
                f"every set of states that plans can leave the part in ({len(seen)}, searched "
                "to the end) spans more than one orbit"
            )
        level = nxt
    return f"no set of states that plans of up to {limit} actions reach lies on one orbit"


def _images(
    nt: NoisyTransitions, kind: str, alphas: NDArray[np.float64], rows: NDArray[np.intp]
) -> BoolArray:
    """The states reachable from ``rows`` at each turn: shape (N, K), in chunks of turns."""
    step = max(1, _CHUNK // max(1, len(rows) * nt.k))
    out = [
        (nt.matrices(kind, alphas[i : i + step], rows) > _SUPPORT).any(axis=1)
        for i in range(0, len(alphas), step)
    ]
    return np.asarray(np.concatenate(out), dtype=np.bool_)


def _uniform(problem: Problem) -> Problem:
    """The problem with a uniform prior: every initial orientation possible."""
    if isinstance(problem.prior, UniformPrior):
        return problem
    return Problem.build(
        problem.part,
        prior=UniformPrior(),
        cost=problem.cost,
        goal=problem.goal,
        actions=problem.actions,
        accuracy=problem.accuracy,
    )


def _intervals(
    nt: NoisyTransitions,
    kind: str,
    rows: NDArray[np.intp],
    width: float,
    tol: float,
    period: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Middles and half-widths of the intervals of turns between critical turns.

    Critical turns of the rows: ``S_i - o - B_b +- width`` over ``(-period/2, period/2]``;
    intervals narrower than ``2 tol`` are left out (no turn in them keeps a margin).
    """
    stable = nt.stable[rows]
    crit = [(stable[:, None] - c.offset - c.hi[None, :]).ravel() for c in nt.components(kind)]
    c = np.concatenate(crit)
    c = np.concatenate([c - width, c + width]) if width > 0 else c
    half = period / 2
    c = np.unique(np.mod(c + half, period) - half)
    gaps = np.diff(np.append(c, c[0] + period))
    keep = gaps > 2 * tol
    mids = np.mod(c[keep] + gaps[keep] / 2 + half, period) - half
    return np.asarray(mids, dtype=np.float64), np.asarray(gaps[keep] / 2, dtype=np.float64)


def plan_guaranteed_noisy(
    problem: Problem, noise: NoiseModel, max_actions: int | None = None
) -> GuaranteedPlan:
    """The shortest plan that orients every orientation (up to the period) under a noise.

    Without contact noise: the guaranteed planner with a gripper accuracy of the uniform
    error's half-width (the plan of largest tolerance among the cheapest shortest). With
    contact noise: :func:`support_search`. See the module notes for what a guarantee under
    each noise means. With a plan, its success probability and expected cost are those under
    the noise for the problem's prior and goal, exact
    (:func:`~bayesgrasp.planning.noisy.evaluate_plan`).

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel
    max_actions : int, optional
        As :func:`~bayesgrasp.planning.guaranteed.plan_guaranteed`.

    Returns
    -------
    GuaranteedPlan
        Status ``"ok"`` with the plan, or ``"no-plan"`` and the reason.

    Raises
    ------
    PlanningError
        A normal turn error (:data:`UNBOUNDED_GUARANTEE`).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.noise import TurnNoise
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> g = plan_guaranteed_noisy(pb, NoiseModel(TurnNoise("uniform", math.radians(5))))
    >>> g.status, g.n_actions, g.option.tolerance >= math.radians(5)
    ('ok', 2, True)
    >>> g = plan_guaranteed_noisy(pb, NoiseModel(TurnNoise("uniform", math.radians(30))))
    >>> g.status, g.reason.split(" deg:")[0]
    ('no-plan', 'no plan guarantees under turn error uniform:30')
    """
    from .noisy import PlanEvaluator

    turn = noise.turn
    if not turn.exact and turn.kind == "normal":
        raise PlanningError(UNBOUNDED_GUARANTEE)
    bound = 0.0 if turn.exact else turn.scale
    where = "" if turn.exact else f" under turn error {turn.spec()} deg"
    if noise.contact == 0:
        pb = problem if bound <= problem.accuracy else dataclasses.replace(problem, accuracy=bound)
        found = dataclasses.replace(plan_guaranteed(pb, max_actions), problem=problem)
        if found.status != "ok" and not turn.exact:
            reason = f"no plan guarantees{where}: {found.reason}"
            return dataclasses.replace(found, reason=reason)
        if noise.exact or found.status != "ok":
            return found
        option = found.option
    else:
        period = period_cap(problem)
        got = support_search(problem, noise, max_actions)
        if isinstance(got, str):
            reason = f"no plan guarantees{where} with contact noise {noise.contact:g}: {got}"
            return GuaranteedPlan(
                problem, (), 0, 0, "guaranteed", status="no-plan", reason=reason,
                period=period, widths=(),
            )  # fmt: skip
        steps = tuple(PlanStep(t, a) for t, a in zip(got.kinds, got.angles, strict=True))
        tolerance = None if len(steps) == 1 else got.error + got.margin
        first = problem.transfer(steps[0].kind)
        lo = float(first.basin_lo[0])
        option = PlanOption(steps, 0.0, 0.0, math.inf, tolerance, (lo, lo + TWO_PI))
        found = GuaranteedPlan(
            problem, (option,), 0, 0, "guaranteed", period=period, widths=()
        )  # fmt: skip
        # The final orientation: the state of the orbit the problem's prior favours.
        q = PlanEvaluator(problem, noise, None).forward(got.kinds, got.angles)[-1]
        j = int(np.argmax(np.where(got.final, q, -1.0)))
        option = dataclasses.replace(option, final_orientation=float(problem.states.stable[j]))
    kinds, angles = option.kinds, [s.alpha for s in option.steps]
    final = int(nearest_state(problem.states, np.array([option.final_orientation]))[0])
    e = PlanEvaluator(problem, noise, None).evaluate(kinds, angles, final)
    opt = dataclasses.replace(
        option, success_probability=e.success_probability, expected_cost=e.expected_cost
    )
    return dataclasses.replace(found, options=(opt,))
