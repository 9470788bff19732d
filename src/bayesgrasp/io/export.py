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
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ExportError  # defined in errors.py; importable from here as before
from ..model.problem import Problem, nearest_state
from ..planning.result import PlanOption
from .plans import json_float, part_document

__all__ = [
    "EXPORT_FORMATS",
    "ROBOT_SCHEMA",
    "RobotStep",
    "robot_csv",
    "robot_document",
    "robot_steps",
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
class RobotStep:
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

    @property
    def turn_deg(self) -> float:
        """:attr:`turn_rad` in degrees."""
        return math.degrees(self.turn_rad)

    @property
    def gripper_deg(self) -> float:
        """:attr:`gripper_rad` in degrees, in ``(-180, 180]``."""
        return math.degrees(self.gripper_rad)


def _wrap(angle: float) -> float:
    """An angle in ``(-pi, pi]``."""
    out = math.remainder(angle, 2.0 * math.pi)
    return math.pi if out <= -math.pi else out


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


def write_robot(
    path: str | Path,
    problem: Problem,
    option: PlanOption,
    metadata: Mapping[str, Any] | None = None,
) -> Path:
    """Write a plan for a robot: CSV or JSON by the file's ending (``.csv``, ``.json``).

    ``metadata`` (JSON-ready values, such as the noise model the plan was made for): in the
    JSON document as more members, in the CSV as ``# KEY: JSON`` lines above the header.

    Raises
    ------
    ExportError
        Another ending, or the file cannot be written.
    """
    target = Path(path)
    kind = target.suffix.lstrip(".").lower()
    if kind not in EXPORT_FORMATS:
        raise ExportError(f"the robot file must end in .csv or .json; got {target.name!r}")
    meta = dict(metadata or {})
    if kind == "csv":
        head = "".join(f"# {k}: {json.dumps(v, allow_nan=False)}\n" for k, v in meta.items())
        text = head + robot_csv(problem, option)
    else:
        doc = robot_document(problem, option) | meta
        text = json.dumps(doc, indent=2, allow_nan=False) + "\n"
    try:
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ExportError(f"cannot write {str(target)!r} ({exc.strerror or exc})") from None
    return target
