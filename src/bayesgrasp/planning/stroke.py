"""Plans that keep to the gripper's stroke: no action needs an opening it cannot make.

A gripper opens to at most ``max_opening`` and closes to no less than ``min_opening`` (part
units). Before an action the jaws must open wider than the part lies across them: the
largest diameter ``d(theta_i - alpha)`` over the orientations ``theta_i`` the part may be in
(the stable orientations that carry prior mass, moved on by the actions so far), turned by
the action's ``alpha``; at the first action, which sees every orientation, the part's widest.
After it they close to ``d`` of the stable orientation reached, at least the least of those
the part may reach. (The same figures as a robot file's ``opening_before`` and
``width_after_min``: :mod:`bayesgrasp.io.machine`.)

:func:`plan_within_stroke` finds the best plan of each length among those whose every step
fits, with exact turns. The search is the paper's breadth-first search over hyperstates
(distributions over the stable orientations), level by level with equal distributions
merged within a level (:mod:`.bfs`), whose children are the action classes
(:meth:`~bayesgrasp.model.problem.Problem.classes`: every turn of a class sends every state
to the same state); a class is a child only where it fits:

- *closing*: the least width of the states it sends the reachable states to is at least
  ``min_opening`` (the same for every turn of the class);
- *opening*: the turns of the class at which ``max_i d(theta_i - alpha) <= max_opening``.
  On a piece of the diameter function ``d(theta) = l |cos(theta - phi)|``, ``d > H`` exactly
  on ``|theta - phi| < arccos(H / l)`` (none when ``l <= H``), so the turns that make a
  state ``theta_i`` too wide are the arcs ``theta_i - {d > H}`` (period pi), and the turns
  that fit are the class interval less their union over the reachable states. The plan
  turns by the middle of the widest such sub-interval; its half-width is the step's margin,
  and the plan's ``tolerance`` the least margin of its turns (every turn may err by less
  than it, all at once, and every state still goes where the plan says, within the stroke).

So the search is exact over the turns after the first action, for plans of up to
``max_actions`` actions (every class of every node is tried; a turn's outcome and fit depend
only on its class and sub-interval), and its plan of each length is the one of highest
success probability (ties: least expected cost, then the widest tolerance). The first
action's angle: 0 under the uniform prior (it does not matter); else the exact planner's
first angles and, under a prior of partial support (a sample, a histogram with empty bins),
one angle in each arc of first angles that reaches another set of states, so every set of
first states is tried (the placement of the first angle on a non-uniform prior is not
optimised over the continuum: there the probabilities are a lower bound, as the
breadth-first baseline's). Polygons only (the diameter function's pieces are sinusoids).

Which constraint can bind: the first action sees every orientation, so it needs the part's
widest opening; a part wider than ``max_opening`` does not fit at all (``status``
``"no-plan"``), and one that fits never needs more later. Under a prior of full support and
one action kind the first action also reaches every stable orientation, the narrowest among
them, so nothing later can close narrower. The search chooses where a choice exists: under
a prior of partial support (the first angle decides which states are reached), and with
several action kinds (a push-grasp reaches fewer states than a squeeze).

Examples
--------
The key under a prior of three sample orientations: one squeeze orients it for sure, but
closes the jaws to 24.26 (part units); a gripper that closes to no less than 24.3 needs two.

>>> import numpy as np
>>> from bayesgrasp.io import resolve_part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.model.prior import SamplePrior
>>> pb = Problem.build(resolve_part("key"), prior=SamplePrior(np.array([0.1, 0.2, 1.3])))
>>> res = plan_within_stroke(pb, min_opening=24.3, max_actions=2)
>>> res.method, [round(o.success_probability, 4) for o in res.options]
('stroke', [0.6667, 1.0])
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI
from ..errors import PlanningError
from ..geometry.diameter import DiameterFunction
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from ..model.problem import Problem
from .result import (
    PlanOption,
    PlanResult,
    check_max_actions,
    choose_indices,
    plan_actions,
    short_turns,
)

__all__ = ["DEFAULT_MAX_ACTIONS", "fitting_turns", "plan_within_stroke", "too_wide"]

FloatArray = NDArray[np.float64]

DEFAULT_MAX_ACTIONS = 4
"""The longest plan searched when none is given."""
_RTOL = 1e-9  # an opening this close to a bound is within it (as the robot files' check)
_TINY = 1e-9  # sub-intervals narrower than this (radians) are no turn


def too_wide(d: DiameterFunction, limit: float) -> list[tuple[float, float]]:
    """The open arcs of orientations (within one period, pi) where ``d > limit``.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import ConvexPolygon
    >>> from bayesgrasp.geometry.diameter import diameter_function
    >>> d = diameter_function(ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> [tuple(round(math.degrees(x), 4) for x in arc) for arc in too_wide(d, 2.0)]
    [(0.0, 53.1301), (126.8699, 180.0)]
    """
    breaks, lengths, phases = d.breaks, d.lengths, d.phases
    ends = np.append(breaks[1:], breaks[0] + math.pi)
    out = []
    for lo, hi, ln, ph in zip(breaks, ends, lengths, phases, strict=True):
        if ln <= limit * (1 + _RTOL):
            continue
        beta = math.acos(limit * (1 + _RTOL) / ln)
        a, b = max(float(lo), ph - beta), min(float(hi), ph + beta)
        if b > a:
            out.append((a, b))
    return out


def fitting_turns(
    lo: float, hi: float, thetas: FloatArray, wide: Sequence[tuple[float, float]]
) -> tuple[float, float] | None:
    """The widest sub-interval of turns ``(lo, hi)`` at which no ``thetas - alpha`` is in ``wide``.

    ``wide``: arcs of orientations (period pi) too wide for the jaws (:func:`too_wide`).
    Returns the sub-interval ``(a, b)``, or ``None`` if no turn of ``(lo, hi)`` fits.

    Examples
    --------
    >>> fitting_turns(0.0, 3.0, np.array([0.0]), [(0.5, 1.0)])  # theta - alpha in (0.5, 1)
    (0.0, 2.141592653589793)
    """
    # alpha is too wide where theta - alpha in (a, b) + k pi: alpha in (theta - b, theta - a) + k pi
    cuts: list[tuple[float, float]] = []
    for th in np.asarray(thetas, dtype=np.float64).tolist():
        for a, b in wide:
            x, y = th - b, th - a
            k0 = math.floor((lo - y) / math.pi)
            k1 = math.ceil((hi - x) / math.pi)
            for k in range(k0, k1 + 1):
                s, e = x + k * math.pi, y + k * math.pi
                if e > lo and s < hi:
                    cuts.append((max(s, lo), min(e, hi)))
    cuts.sort()
    best: tuple[float, float] | None = None
    start = lo
    for s, e in [*cuts, (hi, hi)]:
        if s - start > _TINY and (best is None or s - start > best[1] - best[0]):
            best = (start, s)
        start = max(start, e)
    return best


@dataclass(slots=True)
class _Node:
    q: FloatArray  # the distribution over the states, in the frame of the last action
    kinds: tuple[str, ...]
    angles: tuple[float, ...]
    margin: float  # least half-width of the fitting sub-intervals of the turns so far


def plan_within_stroke(
    problem: Problem,
    min_opening: float = 0.0,
    max_opening: float = math.inf,
    max_actions: int | None = None,
) -> PlanResult:
    """The best plan of each length whose every step fits the stroke (see the module notes).

    Parameters
    ----------
    problem : Problem
        A polygon's problem (exact turns: its ``accuracy`` must be 0).
    min_opening, max_opening : float
        The stroke, in the part's units.
    max_actions : int, optional
        The longest plan (default :data:`DEFAULT_MAX_ACTIONS`).

    Returns
    -------
    PlanResult
        Method ``"stroke"``: ``options[k - 1]`` the best plan of ``k`` actions that fits (the
        lengths stop where no plan fits); ``status`` ``"no-plan"`` when even the first action
        cannot fit (the part is wider than ``max_opening``, or its every first action may
        close the jaws below ``min_opening``).

    Raises
    ------
    PlanningError
        A curved part, a gripper accuracy, or a bad stroke or ``max_actions``.
    """
    check_max_actions(max_actions)
    most = DEFAULT_MAX_ACTIONS if max_actions is None else max_actions
    d = problem.diameter
    if not isinstance(d, DiameterFunction):
        raise PlanningError("planning within the stroke needs a polygon (a curved part's widths)")
    if problem.accuracy > 0:
        raise PlanningError("planning within the stroke takes exact turns (no accuracy)")
    if not (0 <= min_opening < max_opening) or math.isnan(max_opening):
        raise PlanningError(
            f"the stroke must have 0 <= min_opening < max_opening; got {min_opening!r} and "
            f"{max_opening!r}"
        )
    widest = float(np.max(d(d.maxima))) if len(d.maxima) else float(np.max(problem.widths))
    if widest > max_opening * (1 + _RTOL):
        return _none(problem, f"the part's widest ({widest:.4g}) is beyond the largest opening")
    widths = np.asarray(problem.widths, dtype=np.float64)
    stable = np.asarray(problem.states.stable, dtype=np.float64)
    masks = np.array([problem.success_states(float(s)) for s in stable], dtype=np.float64)
    wide = too_wide(d, max_opening) if math.isfinite(max_opening) else []
    low = min_opening * (1 - _RTOL)

    level: dict[bytes, _Node] = {}
    for kind in problem.action_kinds:
        for angle in _first_angles(problem, kind):
            q = np.asarray(problem.state_distribution(angle, kind), dtype=np.float64)
            if np.min(widths[q > 0]) < low:
                continue
            _keep(level, _Node(q, (kind,), (angle,), math.inf))
    if not level:
        return _none(problem, "every first action may close the jaws below the least opening")
    options: list[PlanOption] = []
    for depth in range(1, most + 1):
        if depth > 1:
            level = _expand(problem, level, widths, stable, wide, low)
            if not level:
                break
        options.append(_best(problem, list(level.values()), masks, stable))
    bayes, certain = choose_indices(tuple(options))
    return PlanResult(problem, tuple(options), bayes, certain, "stroke")


def _first_angles(problem: Problem, kind: str) -> list[float]:
    """The first action's angles to try (see the module notes).

    0 under the uniform prior; else the exact planner's first angles and, for a prior
    of partial support (a sample, a histogram with empty bins), the middle of each arc of
    first angles between the angles at which a basin boundary of the action crosses an end
    of the support (within an arc the first action reaches the same states).
    """
    prior = problem.prior
    if isinstance(prior, UniformPrior):
        return [0.0]
    from .exact import plan_exact

    out = {o.steps[0].alpha for o in plan_exact(problem).options}
    ends = _support_ends(prior)
    if len(ends):
        f = problem.transfer(kind)
        crit = np.unique(np.mod(ends[:, None] - np.asarray(f.basin_hi)[None, :], TWO_PI))
        gaps = np.diff(np.append(crit, crit[0] + TWO_PI))
        out |= set((crit[gaps > _TINY] + gaps[gaps > _TINY] / 2).tolist())
    return sorted(out)


def _support_ends(prior: Prior) -> FloatArray:
    """The ends of the arcs where a prior has no mass (none for a prior of full support)."""
    if isinstance(prior, SamplePrior):
        return np.asarray(prior.angles, dtype=np.float64)
    if isinstance(prior, HistogramPrior):
        w = np.asarray(prior.weights) > 0
        if w.all():
            return np.zeros(0)
        edges = np.arange(len(w)) * (TWO_PI / len(w))
        return np.asarray(edges[w != np.roll(w, 1)], dtype=np.float64)
    return np.zeros(0)


def _keep(level: dict[bytes, _Node], node: _Node) -> None:
    """Add a node to its level; of equal distributions, the one of widest margin stays."""
    key = np.round(node.q, 12).tobytes()
    was = level.get(key)
    if was is None or node.margin > was.margin:
        level[key] = node


def _expand(
    problem: Problem,
    level: dict[bytes, _Node],
    widths: FloatArray,
    stable: FloatArray,
    wide: list[tuple[float, float]],
    low: float,
) -> dict[bytes, _Node]:
    """Every child of a level that fits the stroke, merged."""
    out: dict[bytes, _Node] = {}
    for node in level.values():
        reach = np.flatnonzero(node.q > 0)
        for kind in problem.action_kinds:
            cl = problem.classes(kind)
            for c in range(cl.n_classes):
                to = cl.transfer[c]
                if np.min(widths[to[reach]]) < low:
                    continue
                fit = fitting_turns(float(cl.lo[c]), float(cl.hi[c]), stable[reach], wide)
                if fit is None:
                    continue
                a, b = fit
                q = np.bincount(to, weights=node.q, minlength=len(stable)).astype(np.float64)
                margin = min(node.margin, (b - a) / 2)
                child = _Node(q, (*node.kinds, kind), (*node.angles, (a + b) / 2), margin)
                _keep(out, child)
    return out


def _best(
    problem: Problem, nodes: list[_Node], masks: FloatArray, stable: FloatArray
) -> PlanOption:
    """The best plan of one level: highest success, then least cost, then widest margin."""
    vals = masks @ np.array([n.q for n in nodes]).T  # (K goals, nodes)
    p = vals.max(axis=0)
    cost = np.array(
        [problem.cost.expected_cost(n.kinds, float(pi)) for n, pi in zip(nodes, p, strict=True)]
    )
    tol = problem.part.hull.tol.probability
    order = sorted(range(len(nodes)), key=lambda i: (-round(p[i] / tol), cost[i], -nodes[i].margin))
    i = order[0]
    node = nodes[i]
    goal = int(np.argmax(vals[:, i]))
    members = np.flatnonzero(masks[goal] > 0)
    final = int(members[np.argmax(node.q[members])])
    steps, carry = short_turns(plan_actions(problem, node.kinds), node.angles)
    return PlanOption(
        tuple(steps),
        float(np.mod(stable[final] + carry, 2 * math.pi)),
        float(p[i]),
        float(cost[i]),
        None if len(steps) == 1 else float(node.margin),
        (math.nan, math.nan),
    )


def _none(problem: Problem, reason: str) -> PlanResult:
    return PlanResult(problem, (), 0, 0, "stroke", status="no-plan", reason=reason)
