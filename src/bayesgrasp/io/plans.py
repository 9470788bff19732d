"""Documents: the one place that writes and reads the JSON of every strategy.

:func:`strategy_document` writes the document of any planner's result (a
:class:`~bayesgrasp.planning.strategy.StrategyResult`): the plan document of linear plans
(noise-free or noise-aware) and the policy document of a policy; :func:`read_strategy` reads
either back. The sections below give both schemas. The work is done by
:mod:`.plan_documents` (writing plan documents), :mod:`.plan_reader` (reading them),
:mod:`.part_identity` (the part a document names) and :mod:`.policies` (policy documents);
every name is importable from here.

*Plan documents.* A plan document is what ``bayesgrasp plan --json`` prints (``plan
--batch`` one a line, the web service's ``/plan`` too) and ``bayesgrasp simulate --plan FILE`` (or
:func:`read_plan_document`) reads back. :func:`plan_document` builds it, the only writer;
the standard ``json`` encoder writes its text. Its fields, in the order written (``?``: only
in some documents)::

    {
      "schema": "bayesgrasp.plan/1" | "bayesgrasp.plan/2",     plan_schema()
      "part": {                                                part_document()
        "name": str, "vertices": [[x, y], ...],                the hull, counter-clockwise
        "n_sides": int, "symmetry_order": int, "units"?: str,
        "center_of_mass": [x, y], "id": "sha256:...",          part_id()
        "curved"?: {...}                                       a curved part's arcs
      },
      "method": "exact" | "bfs",
      "stable_orientations_rad": [float, ...],
      "stable_probabilities": [float, ...],                    after the Bayes plan's first action
      "period_rad": float,
      "first_squeeze_rad": float,                              the Bayes plan's first angle
      "options": [OPTION, ...],                                the best plan of each length
      "bayes": int, "most_certain": int,                       indices into "options"
      "nodes"?: int,                                           breadth-first search
      "accuracy_rad"?: float,                                  when not 0
      "guaranteed"?: OPTION + {"period_rad": float} | null,    asked for (plan/2)
      "guaranteed_missing"?: str,                              why it is null
      "provenance": {                                          provenance()
        "version": str, "prior": PRIOR, "cost": {...}, "goal": str,
        "actions": [str, ...], "accuracy_rad": float, "method"?: str,
        ...: the command line's part-file options, the longest plan asked for
      }
    }
    OPTION = {                                                 option_document()
      "squeezes": int,                                         the number of steps
      "actions_rad": [float, ...],                             the turns before steps 2...
      "steps": [{"type": ACTION, "alpha_rad": float}, ...],
      "first_squeeze_rad": float, "final_orientation_rad": float,
      "success_probability": float,
      "expected_cost": float | null, "tolerance_rad": float | null
    }
    PRIOR = {"kind": "uniform"} | {"kind": "von-mises", "mean_rad", "kappa", "bins"}
          | {"kind": "histogram", "weights"} | {"kind": "sample", "angles_rad"}

Two schemas: ``bayesgrasp.plan/1`` for plans of squeezes only, read from
``first_squeeze_rad`` (the world gripper angle of the first squeeze) and ``actions_rad``;
``bayesgrasp.plan/2`` when a plan may use other actions or a guaranteed plan was asked for,
read from ``steps`` (any registered action). Both are read; so are a bare option object, a
``bayesgrasp.simulate/1`` document (its ``"plan"``), the older option without ``steps`` and
documents written before ``part`` and ``provenance``. Angles are radians; statistics a
reader does not find are unknown (NaN). JSON has no NaN: a missing or infinite cost or
tolerance is ``null``.

``part`` names the part (:func:`part_id`, a hash of the hull about the centre of mass
rounded to the part's symmetry tolerance), so a plan read for another part is noticed
(:func:`same_part`). ``provenance`` records how the plans were made, the prior in a form
that rebuilds it (:func:`prior_from_document`), so a re-run from the document gives the
same numbers.

Noise-aware plan documents (``plan --turn-noise / --contact-noise / --payoff``) add, after
``provenance``: ``expected_payoff`` and ``expected_cost_per_unit_payoff`` of the Bayes plan,
``noise``, ``payoff``, ``candidates``, ``refinement_bound``, ``payoff_bound`` and
``noisy_options`` (each option's figures under the noise, :func:`noisy_plan_document`).

*Policy documents.* The policy document ``bayesgrasp.policy/1`` (:func:`policy_document`,
read back by :func:`read_policy_document`): its fields are listed in
:mod:`bayesgrasp.io.policies`.

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

import os
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from .part_identity import part_id, same_part
from .plan_documents import (
    PLAN_SCHEMA,
    PLAN_SCHEMA_1,
    PLAN_SCHEMA_2,
    PLAN_SCHEMAS,
    SIMULATE_SCHEMA,
    encode_json,
    guaranteed_document,
    json_float,
    noisy_plan_document,
    option_document,
    part_document,
    plan_document,
    plan_document_json,
    plan_schema,
    prior_document,
    provenance,
)
from .plan_reader import (
    MAX_PLAN_STEPS,
    PlanSource,
    load_document,
    prior_from_document,
    read_plan,
    read_plan_document,
)
from .policies import POLICY_SCHEMA, PolicySource, policy_document, read_policy_document

if TYPE_CHECKING:
    from ..planning.strategy import StrategyResult

__all__ = [
    "MAX_PLAN_STEPS",
    "PLAN_SCHEMA",
    "PLAN_SCHEMAS",
    "PLAN_SCHEMA_1",
    "PLAN_SCHEMA_2",
    "POLICY_SCHEMA",
    "SIMULATE_SCHEMA",
    "PlanSource",
    "PolicySource",
    "guaranteed_document",
    "json_float",
    "noisy_plan_document",
    "option_document",
    "part_document",
    "part_id",
    "plan_document",
    "plan_document_json",
    "plan_schema",
    "policy_document",
    "prior_document",
    "prior_from_document",
    "provenance",
    "read_plan",
    "read_plan_document",
    "read_policy_document",
    "read_strategy",
    "same_part",
    "strategy_document",
    "strategy_document_json",
]


def strategy_document(
    result: StrategyResult,
    *,
    inputs: Mapping[str, Any] | None = None,
    memo: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The document of any planner's result: what ``plan ... --json`` prints.

    A policy: :func:`policy_document`; noise-aware plans: :func:`noisy_plan_document`; the
    exact, breadth-first or guaranteed planner's plans: :func:`plan_document`. The result's
    guaranteed plan (or the reason there is none) is written with the plans. ``inputs`` and
    ``memo``: as :func:`plan_document` (a policy document has no provenance).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import solve
    >>> pb = Problem.build(Part.from_points([(0, 0), (3, 0), (3, 2), (0, 2)], name="r"))
    >>> [strategy_document(solve(pb, sensor=s))["schema"] for s in (None, "width")]
    ['bayesgrasp.plan/1', 'bayesgrasp.policy/1']
    """
    from ..planning.noisy import NoisyPlanResult
    from ..planning.policy import Policy

    src = result.source
    if isinstance(src, Policy):
        return policy_document(src)
    sure, missing = result.guaranteed, result.guaranteed_missing
    if isinstance(src, NoisyPlanResult):
        return noisy_plan_document(src, guaranteed=sure, guaranteed_missing=missing, inputs=inputs)
    return plan_document(src, guaranteed=sure, guaranteed_missing=missing, inputs=inputs, memo=memo)


def strategy_document_json(
    result: StrategyResult,
    *,
    inputs: Mapping[str, Any] | None = None,
    memo: dict[str, Any] | None = None,
) -> str:
    """:func:`strategy_document` on one line (what ``plan --batch`` writes for a part)."""
    return str(encode_json(strategy_document(result, inputs=inputs, memo=memo)))


def read_strategy(
    source: Mapping[str, Any] | str | os.PathLike[str], which: str = "bayes"
) -> PlanSource | PolicySource:
    """Any strategy document: a :class:`PolicySource` for a policy, else a :class:`PlanSource`.

    ``which``: the plan of a plan document to read (see :func:`read_plan_document`).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import solve
    >>> pb = Problem.build(Part.from_points([(0, 0), (3, 0), (3, 2), (0, 2)], name="r"))
    >>> type(read_strategy(strategy_document(solve(pb)))).__name__
    'PlanSource'
    >>> type(read_strategy(strategy_document(solve(pb, sensor="width")))).__name__
    'PolicySource'
    """
    doc = load_document(source, "strategy file")
    if isinstance(doc, Mapping) and doc.get("schema") == POLICY_SCHEMA:
        return read_policy_document(doc)
    return read_plan(doc, which)
