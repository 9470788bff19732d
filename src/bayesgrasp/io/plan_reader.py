"""Plan documents read back: a plan, the part it was made for, and how it was made.

:func:`read_plan` (and :func:`read_plan_document`, the plan alone) reads a ``plan/1`` or
``plan/2`` document, a bare option object or a ``simulate/1`` document's plan, from a parsed
document or a file read within bounds (:func:`load_document`); :func:`prior_from_document`
rebuilds the prior its provenance records.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import BayesGraspError, SimulationError
from ..model.actions import ACTIONS, SQUEEZE
from ..model.prior import HistogramPrior, Prior, SamplePrior, UniformPrior
from .plan_documents import PLAN_SCHEMAS, SIMULATE_SCHEMA

if TYPE_CHECKING:
    from ..planning.result import PlanOption, PlanStep

__all__ = [
    "MAX_PLAN_STEPS",
    "PlanSource",
    "load_document",
    "prior_from_document",
    "read_plan",
    "read_plan_document",
]

#: Which plan of a document to read: the key of its index (``"guaranteed"`` is an option).
_PLAN_INDEX = {"bayes": "bayes", "most-certain": "most_certain"}


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
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.io.part_identity import same_part
    >>> from bayesgrasp.io.plan_documents import plan_document
    >>> rect = Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)], name="rectangle")
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> src = read_plan(plan_document(plan_exact(Problem.build(rect))))
    >>> same_part(src.part, rect), src.provenance["goal"], src.prior.name
    (True, 'single', 'uniform')
    """
    if isinstance(source, str | os.PathLike):
        doc = load_document(source, "plan file")
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


def load_document(source: Any, what: str) -> Any:
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
