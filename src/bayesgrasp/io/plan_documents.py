"""Plan documents written: ``bayesgrasp.plan/1`` and ``plan/2`` (the schema: :mod:`.plans`).

:func:`plan_document` is the one writer of a planner's plans (:func:`noisy_plan_document`
adds the figures under noise); the ``part`` object every document embeds
(:func:`part_document`) and the ``provenance`` that records how the plans were made
(:func:`provenance`, :func:`prior_document`) are written here too.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ..geometry.polygon import Part
from ..model.actions import SQUEEZE
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from .part_identity import part_id

if TYPE_CHECKING:  # the planners are imported by what reads plans, not by every document
    from ..model.problem import Problem
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.noisy import NoisyPlanResult
    from ..planning.result import PlanOption, PlanReport

__all__ = [
    "PLAN_SCHEMA",
    "PLAN_SCHEMAS",
    "PLAN_SCHEMA_1",
    "PLAN_SCHEMA_2",
    "SIMULATE_SCHEMA",
    "encode_json",
    "guaranteed_document",
    "json_float",
    "noisy_plan_document",
    "option_document",
    "part_document",
    "plan_document",
    "plan_document_json",
    "plan_schema",
    "prior_document",
    "provenance",
]

PLAN_SCHEMA_1 = "bayesgrasp.plan/1"
PLAN_SCHEMA_2 = "bayesgrasp.plan/2"
PLAN_SCHEMA = PLAN_SCHEMA_2
"""The schema of plans that use any action (the newest)."""
PLAN_SCHEMAS = (PLAN_SCHEMA_1, PLAN_SCHEMA_2)
"""Every plan schema :func:`read_plan_document` reads."""
SIMULATE_SCHEMA = "bayesgrasp.simulate/1"
"""A simulation's document; its ``"plan"`` is read as a plan."""


def plan_document(
    result: PlanReport,
    schema: str | None = None,
    *,
    guaranteed: GuaranteedPlan | None = None,
    guaranteed_missing: str | None = None,
    inputs: Mapping[str, Any] | None = None,
    memo: dict[str, Any] | None = None,
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
    inputs : mapping, optional
        More of how the plans were made, added to ``"provenance"`` (:func:`provenance`).
    memo : dict, optional
        Kept by the caller across the documents of one run (``plan --batch``): problems
        made with the same prior, cost model, goal and ``inputs`` (the same objects), and
        the same actions, accuracy, planner and curve error, share one ``"provenance"``
        object, made once (so it must not be changed).

    Returns
    -------
    dict
        JSON-ready (no NaN or infinity); the fields of the module's schema, in its order.
    """
    pb: Problem = result.problem
    asked = guaranteed is not None or guaranteed_missing is not None
    first = result.bayes_plan.steps[0]
    out: dict[str, Any] = {
        "schema": schema or plan_schema(pb, asked),
        "part": part_document(pb.part),
        "method": result.method,
        "stable_orientations_rad": pb.states.stable.tolist(),
        "stable_probabilities": pb.state_probabilities(first.alpha, first.kind),
        "period_rad": float(pb.states.period),
        "first_squeeze_rad": first.alpha,
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
    out["provenance"] = _shared_provenance(pb, result.method, inputs, memo)
    return out


def option_document(option: PlanOption) -> dict[str, Any]:
    """One plan as an option object (the plan/2 form, which holds the plan/1 fields)."""
    steps = option.steps
    return {
        "squeezes": len(steps),
        "actions_rad": [s.alpha for s in steps[1:]],
        "steps": [{"type": s.kind, "alpha_rad": s.alpha} for s in steps],
        "first_squeeze_rad": steps[0].alpha,
        "final_orientation_rad": option.final_orientation,
        "success_probability": option.success_probability,
        "expected_cost": json_float(option.expected_cost),
        "tolerance_rad": json_float(option.tolerance),
    }


def guaranteed_document(plan: GuaranteedPlan) -> dict[str, Any]:
    """The ``"guaranteed"`` member of a plan/2 document: an option plus its period."""
    return {**option_document(plan.option), "period_rad": float(plan.period)}


def part_document(part: Part) -> dict[str, Any]:
    """The ``part`` object that every bayesgrasp document embeds (with its :func:`part_id`)."""
    out: dict[str, Any] = {
        "name": part.name,
        "vertices": part.hull.vertices.tolist(),
        "n_sides": part.hull.n_sides,
        "symmetry_order": part.hull.symmetry_order,
    }
    if part.units is not None:
        out["units"] = part.units
    out["center_of_mass"] = part.center_of_mass.tolist()
    out["id"] = part_id(part)
    if type(part) is not Part:  # a polygon has no curved member (and needs no import)
        from ..report.curved import curved_document

        curved = curved_document(part)  # arcs, error bound, what it rests on (curved parts)
        if curved is not None:
            out["curved"] = curved
    return out


def provenance(problem: Problem, method: str | None = None, **more: Any) -> dict[str, Any]:
    """How a result was made: version, prior, cost model, goal, actions, accuracy, planner.

    ``more`` (the command line's part-file options, the longest plan asked for...) is added;
    ``None`` values (an option not given, its default applied) are left out, so the command
    line and the web service, which share no part-file options, write the same document.
    ``flatten_tolerance`` not given is the tolerance the reader flattened a curved part's
    non-arc curves with (its ``curve_error``), so a re-run with it gives the same numbers;
    a file of segments and arcs only has none (its arcs are exact).
    """
    from .._version import __version__

    out: dict[str, Any] = {
        "version": __version__,
        "prior": prior_document(problem.prior),
        "cost": problem.cost.to_json(),
        "goal": problem.goal.kind,
        "actions": list(problem.action_kinds),
        "accuracy_rad": float(problem.accuracy),
    }
    if method is not None:
        out["method"] = method
    used = getattr(problem.part, "curve_error", 0.0)  # a curved part's flattened curves
    if more.get("flatten_tolerance") is None and used:
        # not given: the reader's default, which a curved part keeps as its curve error
        more = {**more, "flatten_tolerance": float(used)}
    out.update({k: v for k, v in more.items() if v is not None})
    return out


def _shared_provenance(
    pb: Problem, method: str, inputs: Mapping[str, Any] | None, memo: dict[str, Any] | None
) -> dict[str, Any]:
    """:func:`provenance` of the problem, the memo's when it was made for the same inputs."""
    if memo is None:
        return provenance(pb, method, **dict(inputs or {}))
    same = (pb.prior, pb.cost, pb.goal, inputs)  # frozen values: compared as objects
    used = 0.0 if type(pb.part) is Part else getattr(pb.part, "curve_error", 0.0)
    alike = (pb.actions, pb.accuracy, method, used)
    last = memo.get("provenance")
    if last is not None:
        (prior, cost, goal, given), was, doc = last
        if prior is same[0] and cost is same[1] and goal is same[2] and given is inputs:
            if was == alike:
                return doc  # type: ignore[no-any-return]
    doc = provenance(pb, method, **dict(inputs or {}))
    memo["provenance"] = (same, alike, doc)
    return doc


def prior_document(prior: Prior) -> dict[str, Any]:
    """A prior as JSON that :func:`prior_from_document` rebuilds exactly.

    ``{"kind": "uniform"}``; a von Mises prior by its parameters (``mean_rad``, ``kappa``,
    ``bins``); any other histogram by its normalised ``weights``; a sample by its
    ``angles_rad``. (Not its display name, which names the file a prior was read from: the
    same prior given inline or from a file is the same document.)

    Examples
    --------
    >>> from bayesgrasp.model.prior import von_mises
    >>> prior_document(von_mises(0.5, 4.0))["kind"]
    'von-mises'
    >>> from bayesgrasp.io.plan_reader import prior_from_document
    >>> float(prior_from_document(prior_document(von_mises(0.5, 4.0))).mass(0.0, 1.0))
    ...  # doctest: +ELLIPSIS
    0.6...
    """
    if isinstance(prior, UniformPrior):
        return {"kind": "uniform"}
    if isinstance(prior, HistogramPrior):
        if prior.recipe:
            return dict(prior.recipe)
        return {"kind": "histogram", "weights": prior.weights.tolist()}
    if isinstance(prior, SamplePrior):
        return {"kind": "sample", "angles_rad": prior.angles.tolist()}
    return {"kind": type(prior).__name__, "name": prior.name}  # recorded, not rebuilt


def plan_schema(problem: Problem, guaranteed: bool = False) -> str:
    """The schema of a plan document: plan/1 for squeezes alone, else plan/2."""
    if guaranteed or any(name != SQUEEZE.name for name in problem.action_kinds):
        return PLAN_SCHEMA_2
    return PLAN_SCHEMA_1


def json_float(x: float | None) -> float | None:
    """A float for JSON: ``None`` for a missing or non-finite value (JSON has no NaN)."""
    if x is None or not math.isfinite(x):
        return None
    return float(x)


def noisy_plan_document(
    res: NoisyPlanResult,
    *,
    guaranteed: GuaranteedPlan | None = None,
    guaranteed_missing: str | None = None,
    inputs: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The plan document of a noise-aware result.

    :func:`plan_document`'s fields, then the Bayes plan's expected payoff and cost per unit
    payoff, the noise and payoff, and each option's figures under the noise
    (:meth:`NoisyPlanResult.to_json`).
    """
    doc = plan_document(
        res.plan_result(),
        guaranteed=guaranteed,
        guaranteed_missing=guaranteed_missing,
        inputs=inputs,
    )
    bayes = res.bayes_plan
    doc["expected_payoff"] = bayes.expected_payoff
    doc["expected_cost_per_unit_payoff"] = json_float(bayes.evaluation.expected_cost)
    doc.update(res.to_json())
    return doc


#: ``json.dumps(doc, allow_nan=False)`` on one line, without the check for circular
#: references (a document is a tree).
encode_json = json.JSONEncoder(allow_nan=False, check_circular=False).encode


def plan_document_json(
    result: PlanReport,
    *,
    guaranteed: GuaranteedPlan | None = None,
    guaranteed_missing: str | None = None,
    inputs: Mapping[str, Any] | None = None,
    memo: dict[str, Any] | None = None,
) -> str:
    """The plan document on one line: ``json.dumps(plan_document(...), allow_nan=False)``.

    What ``plan --batch`` writes for each part (``plan --json`` prints the same document
    indented). A value JSON cannot hold (NaN, an infinity) raises ``ValueError``, as
    ``json.dumps`` does.

    Examples
    --------
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> res = plan_exact(Problem.build(Part.from_points([(0, 0), (3, 0), (3, 2), (0, 2)])))
    >>> plan_document_json(res) == json.dumps(plan_document(res), allow_nan=False)
    True
    """
    doc = plan_document(
        result,
        guaranteed=guaranteed,
        guaranteed_missing=guaranteed_missing,
        inputs=inputs,
        memo=memo,
    )
    return str(encode_json(doc))
