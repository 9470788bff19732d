"""Robot-ready output: a plan as the gripper angles and jaw widths a controller needs.

A plan (design.md) is a first gripper angle in the world frame and then turns relative to
the previous action. A controller wants absolute angles, so step ``j`` gets

    gamma_1 = alpha_1,    gamma_j = gamma_{j-1} + alpha_j     (world frame, radians),

wrapped to ``(-pi, pi]``, and what the jaws should measure, from the diameter function
``d`` (the seed, section 2; Appendix A): before closing the part can lie across the jaws at
any orientation it may have there, so the jaws must open wider than the largest ``d`` of
those (``opening_before``; the part's largest width before the first action); after closing
the part is in a stable orientation ``theta`` and the jaws read ``d(theta)``. Over the starts
that end in the goal, ``width_after`` is the prior-weighted mean of that reading and
``width_after_min`` / ``width_after_max`` its range (one value once those starts have been
collapsed; at the last action the reading the verification expects). Widths are in the
part's units.

Two files: :func:`robot_csv` (one row a step) and :func:`robot_document`
(``bayesgrasp.robot/1``), chosen by :func:`write_robot` from the file name.

Sensing policies
----------------
A policy branches on the jaw width read after each action, so its robot file is a state
machine (:mod:`bayesgrasp.io.machine`, schema ``bayesgrasp.robot-policy/1``): a row for each
reading interval ``[lo, hi)`` of each state, leading to the next state, a declaration (part
and final orientation) or a rejection, with the state's absolute gripper angle (deg and
rad) and jaw opening; units in the ``#`` lines that head the CSV and in the JSON's
``units``. :func:`write_robot` writes it when given a policy::

    $ bayesgrasp plan house --sense width --export house-robot.csv
    $ cut -c 1-88 house-robot.csv
    # bayesgrasp.robot-policy/1; parts: house
    # units: lengths (opening_before, width_after_min, width_after_max, reading_lo, reading_
    # start: state 1; after the state's action a reading r takes its row with reading_lo <=
    state,action,turn_deg,gripper_deg,gripper_rad,opening_before,width_after_min,width_after
    1,squeeze,0,0,0,61.97576623,40,58.66,-inf,48.26729625,0.5,declare,,house,0,0,0,0
    1,squeeze,0,0,0,61.97576623,40,58.66,48.26729625,57.59729625,0.2908144585,next,2,,,,,
    1,squeeze,0,0,0,61.97576623,40,58.66,57.59729625,inf,0.2091855415,declare,,house,270,4.7
    2,squeeze,34.59407923,34.59407923,0.6037805843,60.95643911,40,58.66,-inf,57.59729625,0.5
    2,squeeze,34.59407923,34.59407923,0.6037805843,60.95643911,40,58.66,57.59729625,inf,0.5,

After the first squeeze (gripper at 0 deg) a reading below 48.27 mm declares the house at
0 deg; one in ``[48.27, 57.60)`` goes to state 2, which turns the gripper to 34.59 deg in the
world frame, squeezes and declares.

A linear plan is the same machine with one row a state (:func:`~.machine.plan_machine`;
its angles and openings are this module's), but ``write_robot`` keeps the step table above
for plans.

Gripper stroke
--------------
A gripper opens to at most ``max_opening`` and closes to at least ``min_opening`` (part
units, :class:`Stroke`). A step needs the jaws open wider than the part can lie across them
(``opening_before``) and closes them to the width of the orientation the part reaches
(``width_after_min`` is the narrowest, over every orientation it may reach there, not only
the successful ones). :func:`check_stroke` refuses a strategy with a step outside the
stroke and names the first such step. The first action sees the part in every orientation,
so its opening is the largest any step of any strategy needs: a part wider than
``max_opening`` fits no strategy. The planners do not take the stroke into account; the
check only refuses what they return.

Examples
--------
>>> from bayesgrasp.geometry.polygon import Part
>>> from bayesgrasp.model.problem import Problem
>>> from bayesgrasp.planning import plan_exact
>>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
>>> steps = robot_steps(pb, plan_exact(pb).bayes_plan)
>>> [(s.action, round(s.gripper_deg, 2), round(s.width_after, 3)) for s in steps]
[('squeeze', 0.0, 24.012), ('squeeze', -45.0, 20.0)]
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ExportError  # defined in errors.py; importable from here as before
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption
from .gripper import GripperAngles, wrap_angle
from .plans import json_float, part_document

if TYPE_CHECKING:  # the policy machinery (and scipy) only when a policy is written
    from ..planning.policy import Policy
    from .machine import RobotMachine

__all__ = [
    "EXPORT_FORMATS",
    "ROBOT_SCHEMA",
    "RobotStep",
    "Stroke",
    "check_stroke",
    "robot_csv",
    "robot_document",
    "robot_steps",
    "stroke_violation",
    "wrap_angle",
    "write_robot",
]

ROBOT_SCHEMA = "bayesgrasp.robot/1"
EXPORT_FORMATS = ("csv", "json")
"""File name endings :func:`write_robot` knows."""

CSV_COLUMNS = (
    "step",
    "action",
    "turn_deg",
    "gripper_deg",
    "gripper_rad",
    "opening_before",
    "width_after",
    "width_after_min",
    "width_after_max",
)


@dataclass(frozen=True, slots=True)
class RobotStep(GripperAngles):
    """One action of a plan as a controller executes it.

    Attributes
    ----------
    step : int
        1 for the first action.
    action : str
        The action's name (``squeeze``, ``push-grasp``...).
    turn_rad : float
        The plan's ``alpha``: the world angle for the first action, else the turn from the
        previous action's gripper angle.
    gripper_rad : float
        The gripper's absolute angle in the world frame, in ``(-pi, pi]``.
    opening_before : float
        The widest the part can be across the jaws before they close (part units).
    width_after, width_after_min, width_after_max : float
        The jaw reading after closing, over the starts that end in the goal: prior-weighted
        mean, least and largest (NaN when no start succeeds).
    """

    step: int
    action: str
    turn_rad: float
    gripper_rad: float
    opening_before: float
    width_after: float
    width_after_min: float
    width_after_max: float


_wrap = wrap_angle


def robot_steps(problem: Problem, option: PlanOption) -> list[RobotStep]:
    """The steps of a plan with absolute gripper angles and the jaw widths to expect.

    The first action sends each of its basins to a stable orientation (state ``i``, with the
    prior mass of the basin, :meth:`Problem.state_distribution`); each further action moves
    every state on (``theta' = s(theta - alpha)``), so the orientations, and the widths
    ``d``, are known at every step for every start.

    Raises
    ------
    ExportError
        A step whose action the problem does not have.
    """
    for st in option.steps:
        if st.kind not in problem.transfers:
            raise ExportError(f"the plan uses {st.kind!r} actions; the problem has no such action")
    d = problem.diameter
    first = option.steps[0]
    mass = problem.state_distribution(first.alpha, first.kind)  # (K,) after the first action
    reach = mass > 0
    thetas = [problem.states.stable]  # orientation of each start after each action
    for st in option.steps[1:]:
        thetas.append(np.mod(problem.transfers[st.kind](thetas[-1] - st.alpha), 2 * math.pi))
    final = nearest_state(problem.states, thetas[-1])
    succeed = reach & problem.success_states(option.final_orientation)[final]
    widest = float(np.max(d(d.maxima))) if len(d.maxima) else float(np.max(problem.widths))
    out: list[RobotStep] = []
    gamma = 0.0
    for j, st in enumerate(option.steps):
        gamma += st.alpha
        before = widest if j == 0 else float(np.max(d(thetas[j - 1][reach] - st.alpha)))
        w = d(thetas[j])[succeed]  # (S,) readings of the starts that succeed
        m = mass[succeed]
        mean = float(np.dot(w, m) / m.sum()) if m.sum() > 0 else math.nan
        lo, hi = (float(w.min()), float(w.max())) if len(w) else (math.nan, math.nan)
        out.append(RobotStep(j + 1, st.kind, st.alpha, _wrap(gamma), before, mean, lo, hi))
    return out


def robot_document(problem: Problem, option: PlanOption) -> dict[str, Any]:
    """The ``bayesgrasp.robot/1`` document of a plan (JSON-ready)."""
    steps = robot_steps(problem, option)
    return {
        "schema": ROBOT_SCHEMA,
        "part": part_document(problem.part),
        "units": problem.part.units,
        "frame": (
            "gripper_rad: the gripper's angle in the part's world frame, counter-clockwise, "
            "jaws closing along the gripper's x-axis; widths in the part's units"
        ),
        "final_orientation_rad": option.final_orientation,
        "success_probability": json_float(option.success_probability),
        "expected_cost": json_float(option.expected_cost),
        "tolerance_rad": json_float(option.tolerance),
        "steps": [
            {
                "step": s.step,
                "action": s.action,
                "turn_rad": s.turn_rad,
                "turn_deg": s.turn_deg,
                "gripper_rad": s.gripper_rad,
                "gripper_deg": s.gripper_deg,
                "opening_before": s.opening_before,
                "width_after": json_float(s.width_after),
                "width_after_min": json_float(s.width_after_min),
                "width_after_max": json_float(s.width_after_max),
            }
            for s in steps
        ],
    }


def robot_csv(problem: Problem, option: PlanOption) -> str:
    """One CSV row a step (:data:`CSV_COLUMNS`), angles in degrees and radians."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for s in robot_steps(problem, option):
        row = [s.step, s.action, s.turn_deg, s.gripper_deg, s.gripper_rad, s.opening_before]
        row += [s.width_after, s.width_after_min, s.width_after_max]
        writer.writerow([f"{x:.10g}" if isinstance(x, float) else x for x in row])
    return buf.getvalue()


@dataclass(frozen=True, slots=True)
class Stroke:
    """The jaws' stroke: the narrowest and the widest they open to (part units).

    Raises
    ------
    ExportError
        A bound that is not a number, a negative ``min_opening``, a ``max_opening`` that is
        not positive, or ``min_opening >= max_opening``.

    Examples
    --------
    >>> Stroke(max_opening=50.0)
    Stroke(min_opening=0.0, max_opening=50.0)
    """

    min_opening: float = 0.0
    max_opening: float = math.inf

    def __post_init__(self) -> None:
        lo, hi = self.min_opening, self.max_opening
        if not (isinstance(lo, int | float) and math.isfinite(lo) and lo >= 0):
            raise ExportError(f"`min_opening` must be a finite number >= 0; got {lo!r}")
        if not (isinstance(hi, int | float) and hi > 0 and not math.isnan(hi)):
            raise ExportError(f"`max_opening` must be a number > 0; got {hi!r}")
        if lo >= hi:
            raise ExportError(
                f"`min_opening` must be less than `max_opening`; got {lo!r} and {hi!r}"
            )
        object.__setattr__(self, "min_opening", float(lo))
        object.__setattr__(self, "max_opening", float(hi))


_STROKE_RTOL = 1e-9  # an opening this close to a bound is within it (rounding)


def stroke_violation(machine: RobotMachine, stroke: Stroke, kind: str = "step") -> str | None:
    """Why the first step of a strategy outside the stroke is, or ``None`` if all fit.

    Steps in order (state order for a policy: parents before children). ``kind`` names a
    step in the message (``step`` for plans, ``state`` for policies).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> from bayesgrasp.io.machine import plan_machine
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], units="mm"))
    >>> m = plan_machine(pb, plan_exact(pb).bayes_plan)
    >>> print(stroke_violation(m, Stroke(max_opening=40.0)))
    None
    >>> print(stroke_violation(m, Stroke(max_opening=30.0)))
    step 1 (squeeze, gripper at 0 deg) needs the jaws open to 36.89 mm, more than the \
largest opening 30 mm
    >>> print(stroke_violation(m, Stroke(min_opening=21.0)))
    step 1 (squeeze, gripper at 0 deg) may close the jaws to 20 mm, less than the least \
opening 21 mm
    """
    found = _outside(machine, stroke, kind)
    return None if found is None else found[1]


def _outside(machine: RobotMachine, stroke: Stroke, kind: str) -> tuple[int, str] | None:
    """The first state outside the stroke and why (:func:`stroke_violation`)."""
    units = f" {machine.units}" if machine.units else ""
    for s in machine.states:
        where = f"{kind} {s.state} ({s.action}, gripper at {s.gripper_deg:.4g} deg)"
        hi = stroke.max_opening
        if s.opening_before > hi * (1 + _STROKE_RTOL):
            return s.state, (
                f"{where} needs the jaws open to {s.opening_before:.4g}{units}, more than the "
                f"largest opening {hi:g}{units}"
            )
        lo = stroke.min_opening
        if s.width_after_min < lo * (1 - _STROKE_RTOL):
            return s.state, (
                f"{where} may close the jaws to {s.width_after_min:.4g}{units}, less than the "
                f"least opening {lo:g}{units}"
            )
    return None


def check_stroke(
    problems: Problem | Sequence[Problem], strategy: PlanOption | Policy, stroke: Stroke
) -> None:
    """Refuse a plan or policy with a step outside the gripper's stroke.

    Raises
    ------
    ExportError
        Naming the first step (the plan's step, the policy's state) outside the stroke. At
        the first step the part itself does not fit: that action sees every orientation
        and, for squeezes under a prior of full support, reaches every stable one, so it
        needs the widest opening and the narrowest closing of any strategy. A later step
        could be avoidable: the planners do not take the stroke into account.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> check_stroke(pb, plan_exact(pb).bayes_plan, Stroke(10.0, 40.0))
    """
    machine = _machine(problems, strategy)
    kind = "step" if isinstance(strategy, PlanOption) else "state"
    found = _outside(machine, stroke, kind)
    if found is None:
        return
    state, why = found
    if state == 1:  # the first action sees every orientation: no strategy would fit
        raise ExportError(f"the part does not fit the gripper's stroke: {why}")
    raise ExportError(
        f"the gripper's stroke cannot run this strategy (the planners do not avoid it): {why}"
    )


def _machine(problems: Problem | Sequence[Problem], strategy: PlanOption | Policy) -> RobotMachine:
    from .machine import plan_machine, policy_machine

    if not isinstance(strategy, PlanOption):
        return policy_machine(problems, strategy)
    pb = problems if isinstance(problems, Problem) else problems[0]
    return plan_machine(pb, strategy)


def write_robot(
    path: str | Path,
    problem: Problem | Sequence[Problem],
    option: PlanOption | Policy,
    metadata: Mapping[str, Any] | None = None,
) -> Path:
    """Write a plan or a policy for a robot: CSV or JSON by the file's ending.

    A plan: one row a step (:func:`robot_csv`, :func:`robot_document`). A policy (with its
    problems, one per candidate part): the state machine of :mod:`bayesgrasp.io.machine`.
    ``metadata`` (JSON-ready values, such as the noise model the strategy was made for): in
    the JSON document as more members, in the CSV as ``# KEY: JSON`` lines above the header.

    Raises
    ------
    ExportError
        Another ending than ``.csv`` or ``.json``, or the file cannot be written.
    """
    target = Path(path)
    kind = target.suffix.lstrip(".").lower()
    if kind not in EXPORT_FORMATS:
        raise ExportError(f"the robot file must end in .csv or .json; got {target.name!r}")
    meta = dict(metadata or {})
    if not isinstance(option, PlanOption):
        from .machine import machine_csv, machine_document, policy_machine

        machine = policy_machine(problem, option)
        if kind == "csv":
            text = machine_csv(machine)
        else:
            text = json.dumps(machine_document(machine) | meta, indent=2, allow_nan=False) + "\n"
    else:
        pb = problem if isinstance(problem, Problem) else problem[0]
        if kind == "csv":
            text = robot_csv(pb, option)
        else:
            text = json.dumps(robot_document(pb, option) | meta, indent=2, allow_nan=False) + "\n"
    if kind == "csv":
        head = "".join(f"# {k}: {json.dumps(v, allow_nan=False)}\n" for k, v in meta.items())
        text = head + text
    try:
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ExportError(f"cannot write {str(target)!r} ({exc.strerror or exc})") from None
    return target
