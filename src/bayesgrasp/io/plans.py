"""Plan documents: the one module that writes and reads the JSON of plans.

A plan document is what ``bayesgrasp plan --json`` prints and ``bayesgrasp simulate --plan
FILE`` (or :func:`read_plan_document`) reads back. Two schemas:

- ``bayesgrasp.plan/1``: plans of squeezes only. Each option gives ``first_squeeze_rad``
  (the world gripper angle of the first squeeze) and ``actions_rad`` (the turns before the
  further squeezes).
- ``bayesgrasp.plan/2``: the plan/1 fields, and every option gains ``steps``
  (``[{"type": ACTION, "alpha_rad": ...}, ...]``, any registered action); written when a
  plan may use other actions than squeezes or a guaranteed plan was asked for
  (``"guaranteed"``: an option plus its ``period_rad``, or ``null`` and
  ``"guaranteed_missing"``, the reason none exists).

Both are read; so are a bare option object (as a document's ``options`` hold, or as
``bayesgrasp.simulate/1`` shows under ``"plan"``) and the older option without ``steps``.
Angles are radians; statistics a reader does not find are unknown (NaN).

Examples
--------
>>> from bayesgrasp.geometry.polygon import Part
>>> from bayesgrasp.model.problem import Problem
>>> from bayesgrasp.planning import plan_exact
>>> rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], name="rectangle")
>>> doc = plan_document(plan_exact(Problem.build(rect)))
>>> doc["schema"], len(doc["options"])
('bayesgrasp.plan/1', 2)
>>> read_plan_document(doc).n_actions  # the Bayes plan: two squeezes
2
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import SimulationError
from ..geometry.polygon import Part
from ..model.actions import ACTIONS, SQUEEZE
from ..model.problem import Problem
from ..planning.guaranteed import GuaranteedPlan
from ..planning.result import PlanOption, PlanReport, PlanStep

__all__ = [
    "PLAN_SCHEMA",
    "PLAN_SCHEMAS",
    "PLAN_SCHEMA_1",
    "PLAN_SCHEMA_2",
    "guaranteed_document",
    "json_float",
    "option_document",
    "part_document",
    "plan_document",
    "plan_schema",
    "read_plan_document",
]

PLAN_SCHEMA_1 = "bayesgrasp.plan/1"
PLAN_SCHEMA_2 = "bayesgrasp.plan/2"
PLAN_SCHEMA = PLAN_SCHEMA_2
"""The schema of plans that use any action (the newest)."""
PLAN_SCHEMAS = (PLAN_SCHEMA_1, PLAN_SCHEMA_2)
"""Every plan schema :func:`read_plan_document` reads."""

#: Which plan of a document to read: the key of its index (``"guaranteed"`` is an option).
_PLAN_INDEX = {"bayes": "bayes", "most-certain": "most_certain"}


def json_float(x: float | None) -> float | None:
    """A float for JSON: ``None`` for a missing or non-finite value (JSON has no NaN)."""
    if x is None or not math.isfinite(x):
        return None
    return float(x)


def part_document(part: Part) -> dict[str, Any]:
    """The ``part`` object that every bayesgrasp document embeds."""
    out: dict[str, Any] = {
        "name": part.name,
        "vertices": part.hull.vertices.tolist(),
        "n_sides": part.hull.n_sides,
        "symmetry_order": part.hull.symmetry_order,
    }
    if part.units is not None:
        out["units"] = part.units
    from ..report_curved import curved_document

    curved = curved_document(part)  # arcs, error bound, what it rests on (curved parts only)
    if curved is not None:
        out["curved"] = curved
    return out


def option_document(option: PlanOption) -> dict[str, Any]:
    """One plan as an option object (the plan/2 form, which holds the plan/1 fields)."""
    return {
        "squeezes": option.n_actions,
        "actions_rad": list(option.alphas),
        "steps": [{"type": s.kind, "alpha_rad": s.alpha} for s in option.steps],
        "first_squeeze_rad": option.first_angle,
        "final_orientation_rad": option.final_orientation,
        "success_probability": option.success_probability,
        "expected_cost": json_float(option.expected_cost),
        "tolerance_rad": json_float(option.tolerance),
    }


def guaranteed_document(plan: GuaranteedPlan) -> dict[str, Any]:
    """The ``"guaranteed"`` member of a plan/2 document: an option plus its period."""
    return {**option_document(plan.option), "period_rad": float(plan.period)}


def plan_schema(problem: Problem, guaranteed: bool = False) -> str:
    """The schema of a plan document: plan/1 for squeezes alone, else plan/2."""
    if guaranteed or any(name != SQUEEZE.name for name in problem.action_kinds):
        return PLAN_SCHEMA_2
    return PLAN_SCHEMA_1


def plan_document(
    result: PlanReport,
    schema: str | None = None,
    *,
    guaranteed: GuaranteedPlan | None = None,
    guaranteed_missing: str | None = None,
) -> dict[str, Any]:
    """The plan document of a planner's result (top-level fields follow the Bayes plan).

    Parameters
    ----------
    result : PlanReport
        The plans of every length (exact or breadth-first planner).
    schema : str, optional
        Default :func:`plan_schema`: plan/2 when the problem has other actions than the
        squeeze or a guaranteed plan was asked for.
    guaranteed : GuaranteedPlan, optional
        Written as ``"guaranteed"``.
    guaranteed_missing : str, optional
        A guaranteed plan was asked for and none exists, for this reason: ``"guaranteed"``
        is ``null`` and ``"guaranteed_missing"`` the reason.

    Returns
    -------
    dict
        JSON-ready (no NaN or infinity).
    """
    pb: Problem = result.problem
    asked = guaranteed is not None or guaranteed_missing is not None
    bayes = result.bayes_plan
    out: dict[str, Any] = {
        "schema": schema or plan_schema(pb, asked),
        "part": part_document(pb.part),
        "method": result.method,
        "stable_orientations_rad": pb.states.stable.tolist(),
        "stable_probabilities": pb.state_distribution(
            bayes.first_angle, bayes.steps[0].kind
        ).tolist(),
        "period_rad": float(pb.states.period),
        "first_squeeze_rad": bayes.first_angle,
        "options": [option_document(o) for o in result.options],
        "bayes": result.bayes,
        "most_certain": result.most_certain,
    }
    if result.nodes is not None:
        out["nodes"] = result.nodes
    if pb.accuracy > 0:
        out["accuracy_rad"] = pb.accuracy
    if guaranteed is not None:
        out["guaranteed"] = guaranteed_document(guaranteed)
    elif guaranteed_missing is not None:
        out["guaranteed"] = None
        out["guaranteed_missing"] = guaranteed_missing
    return out


def read_plan_document(
    source: Mapping[str, Any] | str | os.PathLike[str], which: str = "bayes"
) -> PlanOption:
    """A plan from a plan document (plan/1 or plan/2), an option object, or a file of either.

    Parameters
    ----------
    source : dict, str or Path
        A parsed document, or the path of a ``.json`` file holding one.
    which : {"bayes", "most-certain", "guaranteed"}, optional
        Which plan of a document with ``options`` (an option object is its own plan).

    Returns
    -------
    PlanOption
        Steps and final orientation as written; missing statistics are NaN, a missing
        tolerance ``None``, and the success arc unknown (NaN, NaN).

    Raises
    ------
    SimulationError
        The file cannot be read or parsed, the schema is not a plan schema, or the plan is
        incomplete (no steps, an unknown action, non-finite angles, no final orientation);
        for a file, the message starts with its name.

    Examples
    --------
    >>> read_plan_document({"first_squeeze_rad": 0.0, "actions_rad": [0.5],
    ...                     "final_orientation_rad": 1.0}).n_actions
    2
    """
    if isinstance(source, str | os.PathLike):
        path = Path(source)
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            reason = exc.strerror or exc
            raise SimulationError(f"plan file {str(path)!r} cannot be read ({reason})") from None
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            why = exc.msg if isinstance(exc, json.JSONDecodeError) else "not UTF-8"
            raise SimulationError(f"plan file {str(path)!r} is not valid JSON ({why})") from None
        try:
            return _read(doc, which)
        except SimulationError as exc:
            raise SimulationError(f"plan file {str(path)!r}: {exc}") from None
    return _read(source, which)


def _read(doc: Any, which: str) -> PlanOption:
    """A plan from a parsed document or option (see :func:`read_plan_document`)."""
    if which not in (*_PLAN_INDEX, "guaranteed"):
        raise SimulationError(f"`which` must be bayes, most-certain or guaranteed; got {which!r}")
    if not isinstance(doc, Mapping):
        raise SimulationError(f"a plan must be a JSON object; got {type(doc).__name__}")
    schema = doc.get("schema")
    if schema is not None and schema not in PLAN_SCHEMAS:
        raise SimulationError(
            f"schema {schema!r} is not a plan document; expected one of {', '.join(PLAN_SCHEMAS)}"
        )
    if "options" not in doc:
        return _read_option(doc)
    if which == "guaranteed":
        if not isinstance(doc.get("guaranteed"), Mapping):
            raise SimulationError("the plan document holds no guaranteed plan")
        return _read_option(doc["guaranteed"])
    opts, pick = doc["options"], doc.get(_PLAN_INDEX[which], 0)
    index_ok = isinstance(pick, int) and not isinstance(pick, bool)
    if not isinstance(opts, list) or not index_ok or not 0 <= pick < len(opts):
        key = _PLAN_INDEX[which]
        raise SimulationError(f"a plan document needs `options` and a valid `{key}` index")
    return _read_option(opts[pick])


def _read_option(doc: Any) -> PlanOption:
    """One option object: ``steps`` (plan/2) or ``first_squeeze_rad`` and ``actions_rad``."""
    if not isinstance(doc, Mapping):
        raise SimulationError(f"a plan must be a JSON object; got {type(doc).__name__}")
    steps: list[PlanStep] = []
    if "steps" in doc:
        raw = doc["steps"]
        if not isinstance(raw, list) or not raw:
            raise SimulationError("`steps` must be a non-empty list")
        for i, st in enumerate(raw, start=1):
            kind = st.get("type", SQUEEZE.name) if isinstance(st, Mapping) else None
            alpha = st.get("alpha_rad") if isinstance(st, Mapping) else None
            known = isinstance(kind, str) and kind in ACTIONS
            if not known or isinstance(alpha, bool) or not isinstance(alpha, int | float):
                names = " | ".join(f'"{n}"' for n in ACTIONS)
                raise SimulationError(
                    f'step {i} must be {{"type": {names}, "alpha_rad": number}}; got {st!r}'
                )
            steps.append(PlanStep(str(kind), float(alpha)))
    elif "first_squeeze_rad" in doc:
        try:
            angles = [float(doc["first_squeeze_rad"])]
            angles += [float(a) for a in doc.get("actions_rad", [])]
        except (TypeError, ValueError):
            raise SimulationError("`first_squeeze_rad` and `actions_rad` must be numbers") from None
        steps = [PlanStep(SQUEEZE.name, a) for a in angles]
    else:
        raise SimulationError("a plan needs `steps` or `first_squeeze_rad`")
    if not all(math.isfinite(s.alpha) for s in steps):
        raise SimulationError("plan angles must be finite")

    def number(key: str) -> float:
        value = doc.get(key)
        if isinstance(value, bool) or not isinstance(value, int | float):
            return math.nan
        return float(value)

    final = number("final_orientation_rad")
    if not math.isfinite(final):
        raise SimulationError("a plan needs a finite `final_orientation_rad` (its goal)")
    tol = number("tolerance_rad")
    return PlanOption(
        tuple(steps),
        final,
        number("success_probability"),
        number("expected_cost"),
        tol if math.isfinite(tol) else None,
        (math.nan, math.nan),
    )
