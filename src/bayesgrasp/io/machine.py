"""Robot state machines: any strategy (a plan or a sensing policy) as states a controller runs.

A sensing policy (:mod:`bayesgrasp.planning.policy`) is a tree; a robot program wants a
table. :func:`policy_machine` numbers the tree's action nodes depth first (the root is state
1) and gives each state

- the action and the gripper's *absolute* angle in the world frame: the turns along the path
  from the root summed, ``gamma = alpha_root + alpha_2 + ... + alpha_j``, wrapped to
  ``(-pi, pi]`` (as :func:`bayesgrasp.io.export.robot_steps` does for a plan);
- the jaw widths: ``opening_before``, the widest the part can lie across the jaws before they
  close (the largest diameter ``d`` over the orientations the part may be in there; the
  part's widest at the first action, which sees every orientation), and
  ``width_after_min`` / ``width_after_max``, the narrowest and widest the jaws can close to
  (``d`` of the stable orientations the part may reach);
- one *transition* per reading interval ``[lo, hi)`` (part units; the first starts at
  ``-inf``, the last ends at ``inf``, together they cover every reading): to another state,
  to a declaration (the part and its final orientation, then verify), or to a rejection.

"May be in" is exact on the model: each candidate part's states after the first action that
carry prior mass, moved on through the transfer functions by the commanded turns, and kept on
a branch when the sensor model gives them a reading in its interval with positive
probability (every reading of a noisy sensor has some). A policy planned under noisy
actions (:attr:`Policy.noise`) is followed through the noise model's transition matrices
instead: the states each action reaches with positive probability (a normal turn error cut
at 12 sigma, as in :mod:`bayesgrasp.model.noise`), and the opening before an action the
widest over the turn error's support. A linear plan is the same machine
with one transition a state (:func:`plan_machine`): its angles and openings are those of
:func:`~bayesgrasp.io.export.robot_steps`.

A declared orientation is given in the frame of the last action (``orientation``, in
``[0, 2 pi)``, as the policy and plan documents give it) and in the world frame
(``world_orientation = orientation + gamma``, wrapped to ``(-pi, pi]``).

The files (:func:`machine_csv`, :func:`machine_document`; schema ``bayesgrasp.robot-policy/1``)
-----------------------------------------------------------------------------------------------
CSV: lines starting with ``#`` first (the schema, the units, the start state), then one row a
transition, in state order::

    # bayesgrasp.robot-policy/1; parts: house
    # units: lengths (opening_before, width_after_min, width_after_max, reading_lo, ...
    # start: state 1; after the state's action a reading r takes its row with ...
    state,action,turn_deg,gripper_deg,gripper_rad,opening_before,width_after_min,...
    1,squeeze,0,0,0,61.97576623,40,58.66,-inf,48.26729625,0.5,declare,,house,0,0,0,0
    1,squeeze,0,0,0,61.97576623,40,58.66,48.26729625,57.59729625,0.2908144585,next,2,,,,,

The columns after the state's own (``state`` ... ``width_after_max``) are ``reading_lo``,
``reading_hi``, ``probability`` (of the interval, given that the state is reached),
``outcome`` (``next``, ``declare`` or ``reject``), ``next_state``, ``part``,
``orientation_deg``, ``orientation_rad``, ``world_orientation_deg`` and
``world_orientation_rad``; the ones an outcome does not use are empty. ``pandas.read_csv(path,
comment="#")`` reads it. JSON: the same states, each with its ``branches``, a ``units``
object, and the strategy's figures; unbounded reading ends are ``null``.

Examples
--------
>>> from bayesgrasp.geometry import Part
>>> from bayesgrasp.model import Problem
>>> from bayesgrasp.planning.policy import plan_policy
>>> pb = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)], name="tri"))
>>> m = policy_machine(pb, plan_policy(pb, "width", max_actions=2))
>>> [(s.state, s.action, round(s.gripper_deg, 1), round(s.opening_before, 3)) for s in m.states]
[(1, 'squeeze', 0.0, 3.0)]
>>> [(t.outcome, round(t.lo, 3), t.part) for t in m.states[0].transitions]
[('declare', -inf, 'tri'), ('declare', 2.061, 'tri'), ('declare', 2.402, 'tri')]
>>> print(machine_csv(m).splitlines()[3])
state,action,turn_deg,gripper_deg,gripper_rad,opening_before,width_after_min,width_after_max,\
reading_lo,reading_hi,probability,outcome,next_state,part,orientation_deg,orientation_rad,\
world_orientation_deg,world_orientation_rad
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from scipy.special import ndtr

from ..errors import ExportError
from ..model.noise import NoiseModel, NoisyTransitions
from ..model.problem import Problem, nearest_state
from ..model.sensing import WidthSensor
from ..planning.policy import Branch, Policy, PolicyNode, Reject
from ..planning.result import PlanOption
from .gripper import GripperAngles, wrap_angle
from .plans import json_float

__all__ = [
    "MACHINE_COLUMNS",
    "ROBOT_POLICY_SCHEMA",
    "MachineState",
    "RobotMachine",
    "Transition",
    "machine_csv",
    "machine_document",
    "plan_machine",
    "policy_machine",
]

ROBOT_POLICY_SCHEMA = "bayesgrasp.robot-policy/1"

MACHINE_COLUMNS = (
    "state",
    "action",
    "turn_deg",
    "gripper_deg",
    "gripper_rad",
    "opening_before",
    "width_after_min",
    "width_after_max",
    "reading_lo",
    "reading_hi",
    "probability",
    "outcome",
    "next_state",
    "part",
    "orientation_deg",
    "orientation_rad",
    "world_orientation_deg",
    "world_orientation_rad",
)
"""The columns of :func:`machine_csv`, one row a transition."""

FloatArray = NDArray[np.float64]
Outcome = Literal["next", "declare", "reject"]


@dataclass(frozen=True, slots=True)
class Transition:
    """Readings in ``[lo, hi)`` (part units) and what follows them.

    Attributes
    ----------
    lo, hi : float
        The reading interval (``-inf`` / ``inf`` at the ends).
    probability : float
        Probability of a reading in the interval, given that the state is reached.
    outcome : {"next", "declare", "reject"}
    next_state : int or None
        The state to go to (``outcome == "next"``).
    part : str or None
        The declared part (``outcome == "declare"``).
    orientation_rad : float
        The declared orientation in the frame of the last action, ``[0, 2 pi)`` (NaN unless
        declaring).
    world_orientation_rad : float
        The declared orientation in the world frame, ``(-pi, pi]`` (NaN unless declaring).
    success_probability : float
        Probability that the declaration is right, given the transition (NaN unless
        declaring).
    """

    lo: float
    hi: float
    probability: float
    outcome: Outcome
    next_state: int | None = None
    part: str | None = None
    orientation_rad: float = math.nan
    world_orientation_rad: float = math.nan
    success_probability: float = math.nan


@dataclass(frozen=True, slots=True)
class MachineState(GripperAngles):
    """One action of a strategy as a controller runs it.

    Attributes
    ----------
    state : int
        1 for the first action.
    action : str
    turn_rad : float
        The strategy's turn: the world angle at state 1, else the turn from the previous
        state's gripper angle (radians).
    gripper_rad : float
        The gripper's absolute angle in the world frame, in ``(-pi, pi]``.
    opening_before : float
        The widest the part can lie across the jaws before they close (part units; NaN if
        the model gives the state no orientation).
    width_after_min, width_after_max : float
        The narrowest and widest the jaws can close to (part units).
    transitions : tuple of Transition
        In increasing reading order, covering every reading.
    """

    state: int
    action: str
    turn_rad: float
    gripper_rad: float
    opening_before: float
    width_after_min: float
    width_after_max: float
    transitions: tuple[Transition, ...]

    def transition(self, reading: float) -> Transition:
        """The transition a reading takes (``lo <= reading < hi``)."""
        for t in self.transitions:
            if reading < t.hi:
                return t
        return self.transitions[-1]


@dataclass(frozen=True, slots=True)
class RobotMachine:
    """A strategy as a state machine (see the module notes); state ``k`` is ``states[k - 1]``.

    Attributes
    ----------
    states : tuple of MachineState
    parts : tuple of str
        The candidate parts' names.
    units : str or None
        The parts' length units.
    figures : dict
        The strategy's figures for the documents (expected cost, success probability...).
    """

    states: tuple[MachineState, ...]
    parts: tuple[str, ...]
    units: str | None
    figures: dict[str, Any]


# -- building ------------------------------------------------------------------------------


Support = list[FloatArray]  # per candidate part: orientations (current gripper frame)


def _first_support(
    problems: Sequence[Problem], weights: Sequence[float], node: PolicyNode
) -> Support:
    """Each part's stable orientations that the first action reaches with positive mass."""
    out = []
    for pb, w in zip(problems, weights, strict=True):
        if w <= 0:
            out.append(np.empty(0))
            continue
        mass = pb.state_distribution(node.step.alpha, node.step.kind)
        out.append(np.asarray(pb.states.stable[mass > 0], dtype=np.float64))
    return out


def _widest(problems: Sequence[Problem], weights: Sequence[float]) -> float:
    """The largest width of any candidate part (the first action's opening)."""
    best = -math.inf
    for pb, w in zip(problems, weights, strict=True):
        if w <= 0:
            continue
        d = pb.diameter
        best = max(best, float(np.max(d(d.maxima))) if len(d.maxima) else float(np.max(pb.widths)))
    return best


def _reaches(sensor: WidthSensor, widths: FloatArray, lo: float, hi: float) -> NDArray[np.bool_]:
    """Which true widths give a reading in ``[lo, hi)`` with positive probability."""
    if sensor.sigma == 0:
        r = sensor.read(widths)
        return np.asarray((r >= lo) & (r < hi))
    res = sensor.resolution
    # Readings RES k in [lo, hi): d + e in [RES (k_lo - 1/2), RES (k_hi + 1/2)).
    k_lo = -math.inf if math.isinf(lo) else math.ceil(lo / res - 1e-9)
    k_hi = math.inf if math.isinf(hi) else math.ceil(hi / res - 1e-9) - 1
    if k_lo > k_hi:
        return np.zeros(len(widths), dtype=bool)
    a = (res * (k_lo - 0.5) - widths) / sensor.sigma
    b = (res * (k_hi + 0.5) - widths) / sensor.sigma
    # The upper tail where it is small keeps its relative precision (as the reading bins).
    p = np.where(a >= 0, ndtr(-a) - ndtr(-b), ndtr(b) - ndtr(a))
    return np.asarray(p > 0)


@dataclass(slots=True)
class _Walk:
    problems: Sequence[Problem]
    weights: Sequence[float]
    sensor: WidthSensor
    states: list[MachineState | None]
    noisy: Sequence[NoisyTransitions] | None = None  # the actions' noise, if any

    def visit(self, node: PolicyNode, before: Support | None, gamma: float) -> int:
        """Number ``node`` and its subtree; ``before`` the support in the previous frame."""
        sid = len(self.states) + 1
        self.states.append(None)  # reserve the number: depth first, parent before children
        step = node.step
        gamma += step.alpha
        if before is None:  # the first action: every orientation
            opening = _widest(self.problems, self.weights)
            if self.noisy is None:
                after = _first_support(self.problems, self.weights, node)
            else:
                after = [
                    nt.stable[nt.initial(step.kind, step.alpha) > 0] if w > 0 else np.empty(0)
                    for nt, w in zip(self.noisy, self.weights, strict=True)
                ]
        elif self.noisy is None:
            moved = [th - step.alpha for th in before]
            opening = _max_of(pb.diameter(th) for pb, th in zip(self.problems, moved, strict=True))
            after = [
                np.mod(pb.transfer(step.kind)(th), 2 * math.pi) if len(th) else th
                for pb, th in zip(self.problems, moved, strict=True)
            ]
        else:
            opening = _max_of(
                _widest_turned(pb, th - step.alpha, nt.noise.turn.support)
                for pb, th, nt in zip(self.problems, before, self.noisy, strict=True)
            )
            after = [
                _noisy_after(nt, th, step.kind, step.alpha)
                for th, nt in zip(before, self.noisy, strict=True)
            ]
        widths = [pb.diameter(th) for pb, th in zip(self.problems, after, strict=True)]
        rows = tuple(self.transition(b, after, widths, gamma) for b in node.branches)
        w_lo = -_max_of(-w for w in widths)
        self.states[sid - 1] = MachineState(
            sid, step.kind, step.alpha, wrap_angle(gamma), opening, w_lo, _max_of(widths), rows
        )
        return sid

    def transition(
        self, b: Branch, after: Support, widths: list[FloatArray], gamma: float
    ) -> Transition:
        nxt = b.next
        if isinstance(nxt, PolicyNode):
            kept = [
                th[_reaches(self.sensor, w, b.lo, b.hi)]
                for th, w in zip(after, widths, strict=True)
            ]
            return Transition(b.lo, b.hi, b.probability, "next", self.visit(nxt, kept, gamma))
        if isinstance(nxt, Reject):
            return Transition(b.lo, b.hi, b.probability, "reject")
        world = wrap_angle(nxt.orientation + gamma)
        return Transition(
            b.lo,
            b.hi,
            b.probability,
            "declare",
            part=nxt.part_name,
            orientation_rad=nxt.orientation,
            world_orientation_rad=world,
            success_probability=nxt.success_probability,
        )


def _noisy_after(nt: NoisyTransitions, before: FloatArray, kind: str, alpha: float) -> FloatArray:
    """The states an action under noise reaches with positive probability from ``before``.

    Positive in the noise model's own transition matrix (a normal turn error is cut at 12
    sigma, as everywhere in :mod:`bayesgrasp.model.noise`).
    """
    if not len(before):
        return before
    rows = nearest_state(nt.problem.states, before)
    reach = nt.matrix(kind, alpha)[rows].sum(axis=0) > 0
    return np.asarray(nt.stable[reach], dtype=np.float64)


def _widest_turned(pb: Problem, theta: FloatArray, err: float) -> FloatArray:
    """Each orientation's widest opening over a turn error in ``[-err, err]``.

    ``d`` is largest on an interval at an end or at one of its maxima inside.
    """
    if not len(theta) or err <= 0:
        return np.asarray(pb.diameter(theta), dtype=np.float64)
    d = pb.diameter
    best = np.maximum(d(theta - err), d(theta + err))
    peaks = np.asarray(d.maxima, dtype=np.float64)
    if len(peaks):
        # A maximum m (period pi) inside [theta - err, theta + err].
        off = np.mod(peaks[None, :] - (theta[:, None] - err), math.pi)
        inside = off <= 2 * err
        vals = np.where(inside, d(peaks)[None, :], -np.inf)
        best = np.maximum(best, vals.max(axis=1))
    return np.asarray(best, dtype=np.float64)


def _max_of(arrays: Iterable[FloatArray]) -> float:
    """The largest value over arrays (NaN when all are empty)."""
    best = -math.inf
    for a in arrays:
        if len(a):
            best = max(best, float(np.max(a)))
    return best if best > -math.inf else math.nan


def _problems(problems: Problem | Iterable[Problem], n_parts: int) -> tuple[Problem, ...]:
    pbs = (problems,) if isinstance(problems, Problem) else tuple(problems)
    if len(pbs) != n_parts:
        raise ExportError(f"the strategy tells {n_parts} part(s) apart; got {len(pbs)} problem(s)")
    return pbs


def _check_kinds(pbs: Sequence[Problem], node: PolicyNode) -> None:
    for pb in pbs:
        if node.step.kind not in pb.transfers:
            raise ExportError(
                f"the strategy uses {node.step.kind!r} actions; the problem has no such action"
            )
    for b in node.branches:
        if isinstance(b.next, PolicyNode):
            _check_kinds(pbs, b.next)


def _build(
    pbs: Sequence[Problem],
    root: PolicyNode,
    weights: Sequence[float],
    sensor: WidthSensor,
    figures: dict[str, Any],
    noise: NoiseModel | None = None,
) -> RobotMachine:
    _check_kinds(pbs, root)
    noisy = None
    if noise is not None and not noise.exact:
        noisy = [NoisyTransitions(pb, noise) for pb in pbs]
    walk = _Walk(pbs, weights, sensor, [], noisy)
    walk.visit(root, None, 0.0)
    states = tuple(s for s in walk.states if s is not None)
    names = tuple(pb.part.name for pb in pbs)
    return RobotMachine(states, names, pbs[0].part.units, figures)


def policy_machine(problems: Problem | Iterable[Problem], policy: Policy) -> RobotMachine:
    """A sensing policy as a state machine (see the module notes).

    Parameters
    ----------
    problems : Problem or iterable of Problem
        The problems the policy was planned for, one per candidate part, in order.
    policy : Policy

    Returns
    -------
    RobotMachine

    Raises
    ------
    ExportError
        Problems that do not match the policy.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)], name="rect"))
    >>> m = policy_machine(pb, plan_policy(pb, "width", 1))
    >>> [(t.outcome, t.hi) for t in m.states[0].transitions]
    [('declare', 1.5), ('declare', inf)]
    """
    pbs = _problems(problems, len(policy.parts))
    figures = {
        "sensor": policy.sensor.to_json(),
        "part_prior": list(policy.part_prior),
        "max_actions": policy.max_actions,
        "expected_cost": json_float(policy.expected_cost),
        "success_probability": json_float(policy.success_probability),
        "cycle_cost": json_float(policy.cycle_cost),
        "reject_probability": json_float(policy.reject_probability),
        "expected_actions": json_float(policy.expected_actions),
    }
    return _build(pbs, policy.root, policy.part_prior, policy.sensor, figures, policy.noise)


def plan_machine(problem: Problem, option: PlanOption) -> RobotMachine:
    """A linear plan as a state machine: one transition a state (every reading), then declare.

    Its gripper angles and openings are those of :func:`~bayesgrasp.io.export.robot_steps`.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> m = plan_machine(pb, plan_exact(pb).bayes_plan)
    >>> [(s.state, round(s.gripper_deg, 2), s.transitions[0].outcome) for s in m.states]
    [(1, 0.0, 'next'), (2, -45.0, 'declare')]
    """
    figures = {
        "expected_cost": json_float(option.expected_cost),
        "success_probability": json_float(option.success_probability),
    }
    from ..planning.strategy import plan_strategy

    root = plan_strategy(problem, option)
    return _build((problem,), root, (1.0,), WidthSensor(), figures)


# -- the files -----------------------------------------------------------------------------


def _units_text(units: str | None) -> str:
    return units if units else "the part's units"


def _num(x: float | int | str | None) -> str:
    if x is None:
        return ""
    if isinstance(x, float):
        return "" if math.isnan(x) else f"{x:.10g}"
    return str(x)


def machine_csv(machine: RobotMachine) -> str:
    """The machine as CSV: ``#`` lines with the schema and units, then one row a transition."""
    buf = io.StringIO()
    buf.write(f"# {ROBOT_POLICY_SCHEMA}; parts: {', '.join(machine.parts)}\n")
    buf.write(
        "# units: lengths (opening_before, width_after_min, width_after_max, reading_lo, "
        f"reading_hi) in {_units_text(machine.units)}; angles in deg (*_deg) and rad (*_rad), "
        "counter-clockwise; gripper and world_orientation in the world frame, orientation in "
        "the frame of the state's action\n"
    )
    buf.write(
        "# start: state 1; after the state's action a reading r takes its row with "
        "reading_lo <= r < reading_hi\n"
    )
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(MACHINE_COLUMNS)
    for s in machine.states:
        head: list[float | int | str | None] = [
            s.state,
            s.action,
            s.turn_deg,
            s.gripper_deg,
            s.gripper_rad,
            s.opening_before,
        ]
        head += [s.width_after_min, s.width_after_max]
        for t in s.transitions:
            o, w = t.orientation_rad, t.world_orientation_rad
            row: list[float | int | str | None] = [
                *head,
                t.lo,
                t.hi,
                t.probability,
                t.outcome,
                t.next_state,
                t.part,
            ]
            row += [math.degrees(o), o, math.degrees(w), w]
            writer.writerow([_num(x) for x in row])
    return buf.getvalue()


def _end(x: float) -> float | None:
    return None if math.isinf(x) else float(x)


def _branch(t: Transition) -> dict[str, Any]:
    out: dict[str, Any] = {"reading": [_end(t.lo), _end(t.hi)], "probability": t.probability}
    if t.outcome == "next":
        out["next_state"] = t.next_state
    elif t.outcome == "reject":
        out["reject"] = True
    else:
        out["declare"] = {
            "part": t.part,
            "orientation_rad": t.orientation_rad,
            "orientation_deg": math.degrees(t.orientation_rad),
            "world_orientation_rad": t.world_orientation_rad,
            "world_orientation_deg": math.degrees(t.world_orientation_rad),
        }
        out["success_probability"] = json_float(t.success_probability)
    return out


def machine_document(machine: RobotMachine) -> dict[str, Any]:
    """The ``bayesgrasp.robot-policy/1`` document of a machine (JSON-ready)."""
    return {
        "schema": ROBOT_POLICY_SCHEMA,
        "parts": list(machine.parts),
        "units": {
            "length": machine.units,
            "angle": "fields *_rad in radians, *_deg in degrees",
            "lengths": "opening_before, width_after_min, width_after_max and reading",
        },
        "frame": (
            "gripper and world_orientation: the part's world frame, counter-clockwise, jaws "
            "closing along the gripper's x-axis; orientation: the frame of the state's action"
        ),
        "start_state": 1,
        **machine.figures,
        "states": [
            {
                "state": s.state,
                "action": s.action,
                "turn_rad": s.turn_rad,
                "turn_deg": s.turn_deg,
                "gripper_rad": s.gripper_rad,
                "gripper_deg": s.gripper_deg,
                "opening_before": json_float(s.opening_before),
                "width_after_min": json_float(s.width_after_min),
                "width_after_max": json_float(s.width_after_max),
                "branches": [_branch(t) for t in s.transitions],
            }
            for s in machine.states
        ],
    }
