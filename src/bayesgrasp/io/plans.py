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

Both are read; so are a bare option object (as a document's ``options`` hold), a
``bayesgrasp.simulate/1`` document (its ``"plan"``) and the older option without ``steps``.
Angles are radians; statistics a reader does not find are unknown (NaN).

Every document names its part: the ``part`` object holds the hull's vertices, the centre of
mass and ``id`` (:func:`part_id`, a hash of the hull about the centre of mass rounded to the
part's symmetry tolerance), so a plan read for another part is noticed
(:func:`same_part`). A plan document also records how it was made (``"provenance"``:
package version, prior, cost model, goal, actions, accuracy, planner; the command line adds
the part-file options such as the flattening tolerance), and the prior in a form that
rebuilds it (:func:`prior_document`, :func:`prior_from_document`), so a re-run from the
document gives the same numbers. Documents written before these fields are read as before.

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
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from operator import attrgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import orjson

from ..errors import BayesGraspError, SimulationError
from ..geometry.polygon import ConvexPolygon, Part
from ..model.actions import ACTIONS, SQUEEZE
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from ..sizes import SMALL

if TYPE_CHECKING:  # the planners are imported by what reads plans, not by every document
    from ..model.problem import Problem
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.result import PlanOption, PlanReport, PlanStep

__all__ = [
    "PLAN_SCHEMA",
    "PLAN_SCHEMAS",
    "PLAN_SCHEMA_1",
    "PLAN_SCHEMA_2",
    "SIMULATE_SCHEMA",
    "PlanSource",
    "guaranteed_document",
    "json_float",
    "option_document",
    "part_document",
    "part_id",
    "plan_document",
    "plan_document_json",
    "plan_schema",
    "prior_document",
    "prior_from_document",
    "provenance",
    "read_plan",
    "read_plan_document",
    "same_part",
]

PLAN_SCHEMA_1 = "bayesgrasp.plan/1"
PLAN_SCHEMA_2 = "bayesgrasp.plan/2"
PLAN_SCHEMA = PLAN_SCHEMA_2
"""The schema of plans that use any action (the newest)."""
PLAN_SCHEMAS = (PLAN_SCHEMA_1, PLAN_SCHEMA_2)
"""Every plan schema :func:`read_plan_document` reads."""
SIMULATE_SCHEMA = "bayesgrasp.simulate/1"
"""A simulation's document; its ``"plan"`` is read as a plan."""

#: Which plan of a document to read: the key of its index (``"guaranteed"`` is an option).
_PLAN_INDEX = {"bayes": "bayes", "most-certain": "most_certain"}


def json_float(x: float | None) -> float | None:
    """A float for JSON: ``None`` for a missing or non-finite value (JSON has no NaN)."""
    if x is None or not math.isfinite(x):
        return None
    return float(x)


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
        from ..report_curved import curved_document

        curved = curved_document(part)  # arcs, error bound, what it rests on (curved parts)
        if curved is not None:
            out["curved"] = curved
    return out


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


def provenance(problem: Problem, method: str | None = None, **more: Any) -> dict[str, Any]:
    """How a result was made: version, prior, cost model, goal, actions, accuracy, planner.

    ``more`` (the command line's part-file options, the longest plan asked for...) is added;
    ``None`` values (an option not given, its default applied) are left out, so the command
    line and the web service, which share no part-file options, write the same document.
    ``flatten_tolerance`` not given is the tolerance the reader flattened a curved part's
    non-arc curves with (its ``curve_error``), so a re-run with it gives the same numbers;
    a file of segments and arcs only has none (its arcs are exact).
    """
    from .. import __version__

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


def option_document(option: PlanOption) -> dict[str, Any]:
    """One plan as an option object (the plan/2 form, which holds the plan/1 fields)."""
    steps = option.steps  # (the fields of n_actions, alphas and first_angle, read once)
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


def plan_schema(problem: Problem, guaranteed: bool = False) -> str:
    """The schema of a plan document: plan/1 for squeezes alone, else plan/2."""
    kinds = problem.action_kinds
    if guaranteed or (kinds != _SQUEEZES and any(name != SQUEEZE.name for name in kinds)):
        return PLAN_SCHEMA_2
    return PLAN_SCHEMA_1


_SQUEEZES = (SQUEEZE.name,)


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
    out["provenance"] = _shared_provenance(pb, result.method, inputs, memo)
    return out


# json.dumps(doc, allow_nan=False) without its argument checks (documents are trees).
_encode = json.JSONEncoder(allow_nan=False, check_circular=False).encode
# What json.dumps writes a str with (ensure_ascii).
_text = json.encoder.encode_basestring_ascii


def plan_document_json(
    result: PlanReport,
    *,
    guaranteed: GuaranteedPlan | None = None,
    guaranteed_missing: str | None = None,
    inputs: Mapping[str, Any] | None = None,
    memo: dict[str, Any] | None = None,
) -> str:
    """``json.dumps(plan_document(...), allow_nan=False)``, written without the dicts.

    The same text, byte for byte (``plan --batch`` writes one a line), made from the
    result's values: every float by one orjson call that writes each as its ``repr``, as
    the encoder does (:func:`_float_texts`), the provenance shared through ``memo`` encoded
    once. A value the template does not know (a non-float where it writes floats, a curved
    part, a non-finite number the encoder refuses) makes :func:`plan_document` and the
    encoder decide, so their result or error is this one's.

    Examples
    --------
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> res = plan_exact(Problem.build(Part.from_points([(0, 0), (3, 0), (3, 2), (0, 2)])))
    >>> plan_document_json(res) == json.dumps(plan_document(res), allow_nan=False)
    True
    """
    try:
        text = _document_text(result, guaranteed, guaranteed_missing, inputs, memo)
    except TypeError:  # a value of another type than the template writes
        text = None
    if text is None:
        doc = plan_document(
            result,
            guaranteed=guaranteed,
            guaranteed_missing=guaranteed_missing,
            inputs=inputs,
            memo=memo,
        )
        return str(_encode(doc))
    return text


def _int(value: Any) -> str:
    """An int as JSON writes it (``TypeError`` for anything else, a bool too)."""
    if type(value) is not int:
        raise TypeError(f"not an int: {value!r}")
    return str(value)


def _float_texts(values: Sequence[Any]) -> list[str] | None:
    """``float.__repr__`` of each value (as ``json.dumps`` writes it), by one orjson call.

    ``None`` when a value is not a float (an int, a float subclass, anything else) or not
    finite (orjson's ``null``): the document then takes the general path, which writes or
    refuses it as the encoder does. When orjson spells a finite float otherwise than
    ``repr`` (:func:`_as_repr`), every text is the float's ``repr``, the encoder's own
    spelling (the study's documents holding a float below 1e-4: 11 of 2000).
    """
    if not {*map(type, values)} <= _FLOAT:
        return None
    text = orjson.dumps(values).decode()
    if not _as_repr(text):
        if "n" in text:  # null: NaN or an infinity
            return None
        return [*map(float.__repr__, values)]
    return text[1:-1].split(",") if values else []


_FLOAT = {float}


def _as_repr(text: str) -> bool:
    """Whether orjson's text of a list of floats is each float's ``repr`` (but the spaces).

    orjson writes a finite float with the shortest digits that read back to it, the digits
    ``repr`` writes (both are "shortest round-trip, nearest", Steele & White / Gay), but
    spells some differently: a magnitude below 1e-4 positionally (``0.00001`` for
    ``1e-05``), exponents without their zero (``1e-7``), and NaN and the infinities as
    ``null``. A text without an ``e``, ``n`` or ``0.0000`` holds none of these (no finite
    float's text has an ``n``; one written positionally below 1e-4 has four zeros after its
    point); test: ``tests/io/test_plan_json.py::test_orjson_float_text_is_repr``.

    Searched in the decoded text: ``bytes.__contains__`` first tries its argument as an int,
    and raises and clears a TypeError for each search (~1.7k instructions).
    """
    return not ("e" in text or "n" in text or "0.0000" in text)


def _options_floats(
    options: Sequence[PlanOption], values: list[Any]
) -> list[tuple[int, bool, bool]]:
    """Append the floats :func:`option_document` writes of each option to ``values``.

    For each option in turn: each step's angle, the success probability, the expected cost,
    the tolerance and the final orientation; 0.0 in place of a cost or tolerance that
    :func:`json_float` makes null (missing or not finite). Returns each option's (steps, has
    cost, has tolerance), for :func:`_options_text`. (One call for all the options: a call
    an option cost more than its work.)
    """
    layouts = []
    for option in options:
        steps = option.steps
        cost, tol = option.expected_cost, option.tolerance
        has_cost = cost is not None and math.isfinite(cost)
        has_tol = tol is not None and math.isfinite(tol)
        values += map(_ALPHA, steps)
        values += (
            option.success_probability,
            cost if has_cost else 0.0,
            tol if has_tol else 0.0,
            option.final_orientation,
        )
        layouts.append((len(steps), has_cost, has_tol))
    return layouts


def _options_text(
    options: Sequence[PlanOption],
    layouts: list[tuple[int, bool, bool]],
    texts: list[str],
    at: int,
) -> str:
    """The options as the JSON text of a list of :func:`option_document`.

    From the float texts of :func:`_options_floats`, ``texts[at:]`` starting with them.
    """
    written = []
    for option, (m, has_cost, has_tol) in zip(options, layouts):  # noqa: B905 (as long)
        alphas = texts[at : at + m]
        probability, cost, tol, end = texts[at + m : at + m + 4]
        at += m + 4
        steps = option.steps
        if {*map(_KIND, steps)} == _SQUEEZE_KIND:  # every step the same text but its angle
            walk = f"{_SQUEEZE_STEP}{_SQUEEZE_NEXT.join(alphas)}}}"
        else:
            pairs = zip(steps, alphas, strict=True)
            walk = ", ".join([f'{{"type": {_text(s.kind)}, "alpha_rad": {a}}}' for s, a in pairs])
        written.append(
            f'{{"squeezes": {m}, "actions_rad": [{", ".join(alphas[1:])}], '
            f'"steps": [{walk}], "first_squeeze_rad": {alphas[0]}, '
            f'"final_orientation_rad": {end}, "success_probability": {probability}, '
            f'"expected_cost": {cost if has_cost else "null"}, '
            f'"tolerance_rad": {tol if has_tol else "null"}}}'
        )
    return ", ".join(written)


# (attrgetter: no comprehension, which makes a function at every call)
_ALPHA, _KIND = attrgetter("alpha"), attrgetter("kind")
# A squeeze step's text but its angle: before the first angle, and between two angles.
_SQUEEZE_KIND = {SQUEEZE.name}
_SQUEEZE_STEP = f'{{"type": {_text(SQUEEZE.name)}, "alpha_rad": '
_SQUEEZE_NEXT = f"}}, {_SQUEEZE_STEP}"


def _document_text(
    result: PlanReport,
    guaranteed: GuaranteedPlan | None,
    guaranteed_missing: str | None,
    inputs: Mapping[str, Any] | None,
    memo: dict[str, Any] | None,
) -> str | None:
    """The text of :func:`plan_document_json`; ``None`` where the template does not apply.

    Every float of the document is written by one :func:`_float_texts` call, in this order:
    the hull's x and y coordinates, the centre of mass, the stable orientations, their
    probabilities, the period, the first angle, then each option's (:func:`_options_floats`),
    and the accuracy when it is written.
    Each is the float the general path writes: the hull's vertices as its Python floats
    (which its array is made of, or made from), the stable orientations as the states hold
    them, the probabilities by :meth:`~bayesgrasp.model.problem.Problem.state_probabilities`.
    """
    pb: Problem = result.problem
    part = pb.part
    if type(part) is not Part:  # a curved part's member: the general path
        return None
    asked = guaranteed is not None or guaranteed_missing is not None
    bayes = result.bayes_plan
    hull = part.hull
    units = "" if part.units is None else f', "units": {_text(part.units)}'
    xs, ys = hull._coords()
    n = len(xs)
    states = pb.states
    stable = states.values[0]
    k = len(stable)
    step = bayes.steps[0]  # (its angle is the plan's first_angle)
    probs = pb.state_probabilities(step.alpha, step.kind)
    values = [*xs, *ys, *part.center_of_mass.tolist(), *stable, *probs]
    values += [float(states.period), step.alpha]
    options = result.options
    layouts = _options_floats(options, values)
    if pb.accuracy > 0:
        values.append(pb.accuracy)
    texts = _float_texts(values)
    if texts is None:  # a value of another type, or not finite
        return None
    i = 2 * n + 2  # where the stable orientations start
    j = i + k + len(probs)  # where the probabilities end
    period, first = texts[j], texts[j + 1]
    written = _options_text(options, layouts, texts, j + 2)
    pairs = zip(texts[:n], texts[n : 2 * n])  # noqa: B905 (as long)
    vertices = "], [".join(map(", ".join, pairs))  # "x0, y0], [x1, y1], [..."
    cx, cy = texts[2 * n], texts[2 * n + 1]
    bayes_at, most_certain = result.bayes, result.most_certain
    if type(bayes_at) is not int or type(most_certain) is not int:  # (a bool, numpy's int)
        return None
    more = ""  # what only some documents have
    if result.nodes is not None:
        more += f', "nodes": {_int(result.nodes)}'
    if pb.accuracy > 0:
        more += f', "accuracy_rad": {texts[-1]}'
    if guaranteed is not None:
        more += f', "guaranteed": {_encode(guaranteed_document(guaranteed))}'
    elif guaranteed_missing is not None:
        more += f', "guaranteed": null, "guaranteed_missing": {_text(guaranteed_missing)}'
    provenance = _shared_provenance(pb, result.method, inputs, memo)
    if memo is None:
        shared = _encode(provenance)
    else:
        if memo.get("provenance_of") is not provenance:  # encoded once for the documents sharing it
            memo["provenance_of"], memo["provenance_text"] = provenance, _encode(provenance)
        shared = memo["provenance_text"]
    return (
        f'{{"schema": {_text(plan_schema(pb, asked))}, "part": {{"name": {_text(part.name)}, '
        f'"vertices": [[{vertices}]], "n_sides": {n}, '
        f'"symmetry_order": {hull.symmetry_order}{units}, '
        f'"center_of_mass": [{cx}, {cy}], "id": {_text(part_id(part))}}}, '
        f'"method": {_text(result.method)}, '
        f'"stable_orientations_rad": [{", ".join(texts[i : i + k])}], '
        f'"stable_probabilities": [{", ".join(texts[i + k : j])}], '
        f'"period_rad": {period}, "first_squeeze_rad": {first}, '
        f'"options": [{written}], "bayes": {bayes_at}, "most_certain": {most_certain}'
        f'{more}, "provenance": {shared}}}'
    )


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
            return _read_source(doc, which)
        except SimulationError as exc:
            raise SimulationError(f"plan file {str(path)!r}: {exc}") from None
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
