"""Documents: the one module that writes and reads the JSON of every strategy.

:func:`strategy_document` writes the document of any planner's result (a
:class:`~bayesgrasp.planning.strategy.StrategyResult`): the plan document of linear plans
(noise-free or noise-aware) and the policy document of a policy; :func:`read_strategy` reads
either back. The sections below give both schemas.

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

import hashlib
import json
import math
import os
from array import array
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import BayesGraspError, SimulationError
from ..geometry.polygon import ConvexPolygon, Part
from ..model.actions import ACTIONS, SQUEEZE
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from ..sizes import SMALL

if TYPE_CHECKING:  # the planners are imported by what reads plans, not by every document
    from ..model.noise import NoiseModel
    from ..model.problem import Problem
    from ..model.sensing import WidthSensor
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.noisy import NoisyPlanResult
    from ..planning.policy import Declare, Policy, PolicyNode, Reject
    from ..planning.result import PlanOption, PlanReport, PlanStep
    from ..planning.strategy import StrategyResult

__all__ = [
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

PLAN_SCHEMA_1 = "bayesgrasp.plan/1"
PLAN_SCHEMA_2 = "bayesgrasp.plan/2"
PLAN_SCHEMA = PLAN_SCHEMA_2
"""The schema of plans that use any action (the newest)."""
PLAN_SCHEMAS = (PLAN_SCHEMA_1, PLAN_SCHEMA_2)
"""Every plan schema :func:`read_plan_document` reads."""
SIMULATE_SCHEMA = "bayesgrasp.simulate/1"
"""A simulation's document; its ``"plan"`` is read as a plan."""
POLICY_SCHEMA = "bayesgrasp.policy/1"
"""The schema of a policy document."""

#: Which plan of a document to read: the key of its index (``"guaranteed"`` is an option).
_PLAN_INDEX = {"bayes": "bayes", "most-certain": "most_certain"}


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


# json.dumps(doc, allow_nan=False) without its argument checks (documents are trees).
_encode = json.JSONEncoder(allow_nan=False, check_circular=False).encode


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
    return str(_encode(doc))


# The part's identity


def _grid(hull: ConvexPolygon) -> float:
    """The rounding step of a part's identity: its symmetry tolerance (``symmetry * size``)."""
    return hull.tol.symmetry_for(hull.size)


def part_id(part: Part) -> str:
    """The identity of a part for plans: ``"sha256:"`` and 16 hex digits.

    A plan's angles hold for the part's hull and centre of mass in the user's coordinates,
    whatever the translation (design.md). So the hash is of the hull's vertices relative to
    the centre of mass, counter-clockwise from the lexicographically least, rounded to the
    part's symmetry tolerance ``tol.symmetry * size`` (:class:`~bayesgrasp.tolerance.
    Tolerance`): the same part read from another file, moved, or rounded to 7 digits has the
    same id, a rotated or different part another. Two parts a rounding step apart can hash
    differently; :func:`same_part` then compares the vertices themselves.

    Examples
    --------
    >>> a = Part.from_points([(0, 0), (3, 0), (0, 1)])
    >>> b = Part.from_points([(10, 5), (10, 6), (13, 5)])  # moved, another vertex order
    >>> part_id(a) == part_id(b), part_id(a) == part_id(Part.from_points([(0, 0), (1, 0), (0, 3)]))
    (True, False)
    """
    q = _grid(part.hull)
    data = _small_id_bytes(part, q) if len(part.hull.vertices) <= SMALL else None
    if data is None:
        ints = np.rint((part.hull.vertices - part.center_of_mass) / q).astype(np.int64)  # (N, 2)
        start = min(range(len(ints)), key=lambda i: (int(ints[i, 0]), int(ints[i, 1])))
        data = np.roll(ints, -start, axis=0).tobytes()
    return "sha256:" + hashlib.sha256(data).hexdigest()[:16]


def _small_id_bytes(part: Part, q: float) -> bytes | None:
    """The bytes :func:`part_id` hashes, on Python floats (a hull of at most ``SMALL`` vertices).

    The same subtraction and division as numpy's, then ``round`` (halves to even, as
    ``np.rint``), and the int64 values in the machine's byte order, as ``ndarray.tobytes``
    (``array("q")``: long long, 8 bytes). ``None`` (numpy decides) for a value ``round``
    refuses (not finite) or beyond int64, which ``array`` refuses; every rounded value it
    takes is an integral float within int64, which numpy's cast keeps exactly.
    """
    cx, cy = part.center_of_mass.tolist()
    units: list[float] = []  # x0, y0, x1, y1, ... in rounding steps from the centre of mass
    for x, y in zip(*part.hull._coords()):  # noqa: B905 (as long; strict= costs)
        units += ((x - cx) / q, (y - cy) / q)
    try:  # round() by the method itself: half round()'s cost, which looks the method up
        flat = [*map(float.__round__, units)]
    except (OverflowError, ValueError):  # an infinity, NaN
        return None
    start = 2 * _least(flat)
    try:
        return array("q", flat[start:] + flat[:start]).tobytes()
    except OverflowError:
        return None


def _least(flat: list[int]) -> int:
    """The index of the first lexicographically least (x, y) pair of ``[x0, y0, x1, ...]``.

    (A function of its own: a closure in :func:`_small_id_bytes` would make cells of its
    variables at every call, ties or not.)
    """
    xs = flat[0::2]
    least = min(xs)
    if xs.count(least) == 1:
        return xs.index(least)
    return min(range(len(xs)), key=lambda i: (xs[i], flat[2 * i + 1]))


def same_part(doc: Any, part: Part) -> bool | None:
    """Whether a document's ``part`` object is ``part`` (``None``: it names no part).

    The same :func:`part_id`, or else the same number of hull vertices, each within the
    part's symmetry tolerance of its counterpart after both hulls are moved to their area
    centroids, and the centre of mass (when the document has one) as near its place.
    """
    if not isinstance(doc, Mapping) or "vertices" not in doc:
        return None
    if isinstance(doc.get("id"), str) and doc["id"] == part_id(part):
        return True
    try:
        other = ConvexPolygon.from_points(doc["vertices"])
    except (BayesGraspError, TypeError, ValueError):
        return False
    q = _grid(part.hull)
    a = part.hull.vertices - part.hull.centroid  # (N, 2)
    b = other.vertices - other.centroid
    if len(a) != len(b):
        return False
    if not any(np.max(np.hypot(*(a - np.roll(b, k, axis=0)).T)) <= q for k in range(len(b))):
        return False
    com = doc.get("center_of_mass")
    if com is None:
        return True
    try:
        there = np.asarray(com, dtype=np.float64).reshape(2) - other.centroid
    except (TypeError, ValueError):
        return False
    return bool(np.hypot(*(there - (part.center_of_mass - part.hull.centroid))) <= q)


def prior_from_document(doc: Any) -> Prior:
    """The prior of :func:`prior_document` (``SimulationError`` for a form it cannot rebuild)."""
    from ..model.prior import von_mises

    if not isinstance(doc, Mapping):
        raise SimulationError(f"a prior must be a JSON object; got {type(doc).__name__}")
    kind, name = doc.get("kind"), doc.get("name", doc.get("kind"))
    try:
        if kind == "uniform":
            return UniformPrior()
        if kind == "von-mises":
            return von_mises(float(doc["mean_rad"]), float(doc["kappa"]), int(doc["bins"]))
        if kind == "histogram":
            return HistogramPrior(np.asarray(doc["weights"], dtype=np.float64), name=str(name))
        if kind == "sample":
            return SamplePrior(np.asarray(doc["angles_rad"], dtype=np.float64), name=str(name))
    except (KeyError, TypeError, ValueError, OverflowError, BayesGraspError) as exc:
        raise SimulationError(f"the {kind} prior of the document is malformed ({exc})") from None
    raise SimulationError(f"a prior of kind {kind!r} ({name}) cannot be rebuilt from a document")


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
    return read_plan(source, which).option


@dataclass(frozen=True, slots=True)
class PlanSource:
    """A plan read from a document, with what the document says about it.

    Attributes
    ----------
    option : PlanOption
        The plan (see :func:`read_plan_document`).
    part : mapping or None
        The document's ``part`` object (check it with :func:`same_part`).
    provenance : mapping
        The document's ``"provenance"`` (empty for older documents and bare options).
    """

    option: PlanOption
    part: Mapping[str, Any] | None = None
    provenance: Mapping[str, Any] = field(default_factory=dict)

    @property
    def prior(self) -> Prior | None:
        """The prior the plan was made under, when the document records one."""
        doc = self.provenance.get("prior")
        return None if doc is None else prior_from_document(doc)

    @property
    def goal(self) -> str | None:
        """The goal the plan was made for, when the document records one."""
        goal = self.provenance.get("goal")
        return goal if isinstance(goal, str) else None


def read_plan(
    source: Mapping[str, Any] | str | os.PathLike[str], which: str = "bayes"
) -> PlanSource:
    """A plan with its document's part and provenance (see :func:`read_plan_document`).

    Examples
    --------
    >>> rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], name="rectangle")
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> src = read_plan(plan_document(plan_exact(Problem.build(rect))))
    >>> same_part(src.part, rect), src.provenance["goal"], src.prior.name
    (True, 'single', 'uniform')
    """
    if isinstance(source, str | os.PathLike):
        doc = _load(source, "plan file")
        try:
            return _read_source(doc, which)
        except SimulationError as exc:
            raise SimulationError(f"plan file {str(Path(source))!r}: {exc}") from None
    return _read_source(source, which)


def _read_source(doc: Any, which: str) -> PlanSource:
    """The plan, part and provenance of a parsed document (see :func:`read_plan`)."""
    option = _read(doc, which)
    part = doc.get("part")
    prov = doc.get("provenance")
    return PlanSource(
        option,
        part if isinstance(part, Mapping) else None,
        prov if isinstance(prov, Mapping) else {},
    )


def _read(doc: Any, which: str) -> PlanOption:
    """A plan from a parsed document or option (see :func:`read_plan_document`)."""
    if which not in (*_PLAN_INDEX, "guaranteed"):
        raise SimulationError(f"`which` must be bayes, most-certain or guaranteed; got {which!r}")
    if not isinstance(doc, Mapping):
        raise SimulationError(f"a plan must be a JSON object; got {type(doc).__name__}")
    schema = doc.get("schema")
    if schema == SIMULATE_SCHEMA:
        return _read_option(doc.get("plan"))
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


#: Most steps a plan file may hold (planners make plans of tens of actions).
MAX_PLAN_STEPS = 10_000


def _read_option(doc: Any) -> PlanOption:
    """One option object: ``steps`` (plan/2) or ``first_squeeze_rad`` and ``actions_rad``."""
    from ..planning.result import PlanOption, PlanStep

    if not isinstance(doc, Mapping):
        raise SimulationError(f"a plan must be a JSON object; got {type(doc).__name__}")
    steps: list[PlanStep] = []
    if "steps" in doc:
        raw = doc["steps"]
        if not isinstance(raw, list) or not raw:
            raise SimulationError("`steps` must be a non-empty list")
        if len(raw) > MAX_PLAN_STEPS:
            raise SimulationError(
                f"a plan of {len(raw):,} steps; a plan file holds at most {MAX_PLAN_STEPS:,}"
            )
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
        raw = doc.get("actions_rad", [])
        if isinstance(raw, list) and len(raw) >= MAX_PLAN_STEPS:
            raise SimulationError(
                f"a plan of {len(raw) + 1:,} steps; a plan file holds at most {MAX_PLAN_STEPS:,}"
            )
        try:
            angles = [float(doc["first_squeeze_rad"])]
            angles += [float(a) for a in raw]
        except (TypeError, ValueError, OverflowError):
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


# Every strategy's document


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
    return str(_encode(strategy_document(result, inputs=inputs, memo=memo)))


def _end(x: float) -> float | None:
    return None if math.isinf(x) else float(x)


def _policy_node(node: PolicyNode) -> dict[str, Any]:
    return {
        "action": {
            "type": node.step.kind,
            "alpha_rad": node.step.alpha,
            "margin_rad": _end(node.margin),
        },
        "branches": [
            {
                "reading": [_end(b.lo), _end(b.hi)],
                "probability": b.probability,
                "next": _policy_next(b.next),
            }
            for b in node.branches
        ],
    }


def _policy_next(x: PolicyNode | Declare | Reject) -> dict[str, Any]:
    from ..planning.policy import PolicyNode, Reject

    if isinstance(x, PolicyNode):
        return _policy_node(x)
    if isinstance(x, Reject):
        return {"reject": True}
    return {
        "declare": {"orientation_rad": x.orientation, "part": x.part_name},
        "success_probability": x.success_probability,
    }


def policy_document(policy: Policy) -> dict[str, Any]:
    """The ``bayesgrasp.policy/1`` document of a policy (see the module notes).

    Examples
    --------
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)], name="rect"))
    >>> doc = policy_document(plan_policy(pb, "width", 1))
    >>> doc["schema"], doc["parts"], doc["root"]["branches"][0]["reading"]
    ('bayesgrasp.policy/1', ['rect'], [None, 1.5])
    """
    doc: dict[str, Any] = {
        "schema": POLICY_SCHEMA,
        "parts": list(policy.parts),
        "part_prior": list(policy.part_prior),
        "sensor": policy.sensor.to_json(),
        "max_actions": policy.max_actions,
        "expected_cost": policy.expected_cost,
        "success_probability": policy.success_probability,
        "expected_actions": policy.expected_actions,
        "cycle_cost": policy.cycle_cost,
        "reject_probability": policy.reject_probability,
        "expected_total_actions": policy.expected_total_actions,
        "expected_entropy_bits": list(policy.expected_entropy),
        "sensorless_cost": policy.sensorless_cost,
        "first_angle_exact": policy.first_angle_exact,
    }
    if policy.noise is not None:
        doc["noise"] = policy.noise.to_json()
        doc["refinement_bound"] = policy.refinement_bound
    if policy.payoff is not None:
        doc["payoff"] = list(policy.payoff)
    doc["root"] = _policy_node(policy.root)
    return doc


@dataclass(frozen=True, slots=True)
class PolicySource:
    """A policy read from its document (:func:`read_policy_document`).

    Attributes
    ----------
    root : PolicyNode
        The tree, as written (its probabilities the document's).
    parts : tuple of str
        The candidate parts' names, in order (a declaration's ``part`` indexes them).
    part_prior : tuple of float
    sensor : WidthSensor
    max_actions : int
    noise : NoiseModel or None
        The action noise it was planned under (``None``: exact actions).
    payoff : tuple of float or None
    figures : mapping
        The document's figures (``expected_cost``, ``success_probability``, ...).
    """

    root: PolicyNode
    parts: tuple[str, ...]
    part_prior: tuple[float, ...]
    sensor: WidthSensor
    max_actions: int
    noise: NoiseModel | None
    payoff: tuple[float, ...] | None
    figures: Mapping[str, Any]


_POLICY_FIGURES = (
    "expected_cost",
    "success_probability",
    "expected_actions",
    "cycle_cost",
    "reject_probability",
    "expected_total_actions",
    "expected_entropy_bits",
    "sensorless_cost",
    "first_angle_exact",
    "refinement_bound",
)


def read_policy_document(source: Mapping[str, Any] | str | os.PathLike[str]) -> PolicySource:
    """A policy from its ``bayesgrasp.policy/1`` document, or a file of one.

    The inverse of :func:`policy_document`: the tree, its candidates, sensor, noise and
    payoff, so that :func:`~bayesgrasp.planning.strategy.evaluate` can check its figures.

    Raises
    ------
    SimulationError
        The file cannot be read, is not a policy document, or a node, branch or leaf is
        malformed (the message says where).

    Examples
    --------
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)], name="rect"))
    >>> pol = plan_policy(pb, "width", 2)
    >>> read_policy_document(policy_document(pol)).root == pol.root
    True
    """
    from ..model.noise import NoiseModel, TurnNoise
    from ..model.sensing import WidthSensor

    doc = _load(source, "policy file")
    if not isinstance(doc, Mapping) or doc.get("schema") != POLICY_SCHEMA:
        got = doc.get("schema") if isinstance(doc, Mapping) else type(doc).__name__
        raise SimulationError(f"expected a {POLICY_SCHEMA} document; got {got!r}")
    try:
        parts = tuple(str(p) for p in doc["parts"])
        prior = tuple(float(w) for w in doc["part_prior"])
        sensor = WidthSensor(float(doc["sensor"]["sigma"]), float(doc["sensor"]["resolution"]))
        depth = int(doc["max_actions"])
        noise = None
        if doc.get("noise") is not None:
            turn = doc["noise"]["turn"]
            noise = NoiseModel(
                TurnNoise(turn["kind"], float(turn["scale_rad"])), float(doc["noise"]["contact"])
            )
        payoff = None if doc.get("payoff") is None else tuple(float(u) for u in doc["payoff"])
    except (KeyError, TypeError, ValueError, BayesGraspError) as exc:
        raise SimulationError(f"the policy document is malformed ({exc!r})") from None
    root = _read_policy_node(doc.get("root"), parts, "root")
    figures = {k: doc[k] for k in _POLICY_FIGURES if k in doc}
    return PolicySource(root, parts, prior, sensor, depth, noise, payoff, figures)


def _read_policy_node(doc: Any, parts: tuple[str, ...], where: str) -> PolicyNode:
    """One node of a policy document (``where``: its path, for the message)."""
    from ..planning.policy import Branch, Declare, PolicyNode, Reject
    from ..planning.result import PlanStep

    def num(x: Any, end: float) -> float:
        if x is None:
            return end
        if isinstance(x, bool) or not isinstance(x, int | float):
            raise SimulationError(f"{where}: expected a number; got {x!r}")
        return float(x)

    try:
        action, raw = doc["action"], doc["branches"]
        kind = action["type"]
        if kind not in ACTIONS:
            raise SimulationError(f"{where}: unknown action {kind!r}")
        step = PlanStep(str(kind), num(action["alpha_rad"], math.nan))
        margin = num(action.get("margin_rad"), math.inf)
        branches = []
        for i, b in enumerate(raw):
            lo, hi = b["reading"]
            nxt_doc = b["next"]
            here = f"{where}.branches[{i}]"
            nxt: PolicyNode | Declare | Reject
            if "action" in nxt_doc:
                nxt = _read_policy_node(nxt_doc, parts, here + ".next")
            elif nxt_doc.get("reject") is True:
                nxt = Reject()
            else:
                name = nxt_doc["declare"]["part"]
                nxt = Declare(
                    parts.index(name),
                    str(name),
                    float(nxt_doc["declare"]["orientation_rad"]),
                    float(nxt_doc["success_probability"]),
                )
            branches.append(
                Branch(num(lo, -math.inf), num(hi, math.inf), float(b["probability"]), nxt)
            )
    except SimulationError:
        raise
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise SimulationError(f"{where}: malformed policy node ({exc!r})") from None
    if not branches or not math.isfinite(step.alpha):
        raise SimulationError(f"{where}: a node needs a finite alpha_rad and branches")
    return PolicyNode(step, tuple(branches), margin)


def read_strategy(
    source: Mapping[str, Any] | str | os.PathLike[str], which: str = "bayes"
) -> PlanSource | PolicySource:
    """Any strategy document: a :class:`PolicySource` for a policy, else a :class:`PlanSource`.

    ``which``: the plan of a plan document to read (see :func:`read_plan_document`).

    Examples
    --------
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import solve
    >>> pb = Problem.build(Part.from_points([(0, 0), (3, 0), (3, 2), (0, 2)], name="r"))
    >>> type(read_strategy(strategy_document(solve(pb)))).__name__
    'PlanSource'
    >>> type(read_strategy(strategy_document(solve(pb, sensor="width")))).__name__
    'PolicySource'
    """
    doc = _load(source, "strategy file")
    if isinstance(doc, Mapping) and doc.get("schema") == POLICY_SCHEMA:
        return read_policy_document(doc)
    return read_plan(doc, which)


def _load(source: Any, what: str) -> Any:
    """A parsed document, or the JSON of the file ``source`` names (read within bounds).

    The file is read as :mod:`bayesgrasp.files` reads every input: a regular file of at most
    ``MAX_BYTES``, UTF-8, numbers within a float's range and nesting within ``MAX_NESTING``.
    """
    if not isinstance(source, str | os.PathLike):
        return source
    from ..files import decode_text, load_json, read_bytes

    path = Path(source)
    label = f"{what} {str(path)!r}"
    try:
        data = read_bytes(path, SimulationError, what)
    except SimulationError as exc:  # "<path>: <reason>": say which file it is
        reason = str(exc).removeprefix(f"{path}: ")
        raise SimulationError(f"{label} cannot be read ({reason})") from None
    return load_json(label, decode_text(label, data, SimulationError), SimulationError)
