"""The policy document ``bayesgrasp.policy/1``: written and read by :mod:`bayesgrasp.io.plans`.

This module keeps the names it had (:func:`policy_document`, :data:`POLICY_SCHEMA`).

Fields (angles in radians, readings in the parts' units)::

    {
      "schema": "bayesgrasp.policy/1",
      "parts": [NAME, ...],            candidate parts, in order
      "part_prior": [W, ...],          prior probability of each part (sums to 1)
      "sensor": {"kind": "width", "sigma": S, "resolution": R},
                                       reading = R round((d + e) / R), e ~ N(0, S^2);
                                       S = R = 0: exact readings
      "max_actions": K,                no path has more actions
      "expected_cost": C,              E[cost until a cycle succeeds] = cycle_cost / P
      "success_probability": P,        a cycle declares the true orientation (and part)
      "expected_actions": A,           expected actions in one cycle
      "cycle_cost": c,                 E[cost of one cycle], retry overhead included
      "reject_probability": r,         a cycle ends in a rejection
      "expected_total_actions": A / P, expected actions until success
      "expected_entropy_bits": [H1, ...],
                                       expected entropy (bits) of the belief over the
                                       states after the reading of action 1, 2, ...
                                       (paths that ended keep their last belief)
      "sensorless_cost": C0 | null,    the sensorless Bayes plan's expected cost (one part)
      "first_angle_exact": bool,       every first angle that can be optimal was tried
      "noise": {"turn": {"kind": "normal" | "uniform", "scale_rad": s}, "contact": q},
                                       only for a policy planned under noisy actions
                                       (plan --sense --turn-noise / --contact-noise): every
                                       figure and probability is exact under that noise
      "refinement_bound": eps,         with "noise": no single turn, the rest kept, lowers
                                       cycle_cost - expected_cost * P by more
      "payoff": [U, ...],              only for a policy with a payoff (plan --sense
                                       --payoff FILE): the value of each stable state; a
                                       declaring leaf stops and earns the payoff of the state
                                       reached, P is the expected payoff of a cycle and C
                                       the expected cost per unit payoff
      "stopped": why, "requested_actions": n, "lower_bound": L,
                                       only when the search reached its time or memory
                                       bound: the policy is then the best of max_actions
                                       actions (the deepest search that finished), and no
                                       policy of n actions costs less than L
      "root": NODE
    }
    NODE = {"action": {"type": "squeeze" | "push-grasp", "alpha_rad": a, "margin_rad": m},
            "branches": [{"reading": [lo, hi], "probability": p, "next": NODE | LEAF}]}
    LEAF = {"declare": {"orientation_rad": t, "part": NAME}, "success_probability": q}
         | {"reject": true}

``alpha_rad`` is the world gripper angle at the root and the turn relative to the previous
action below it; ``margin_rad`` is how far that turn may err without changing any state's
outcome (``null`` at the root; 0 under noisy actions, whose error is in the figures).
``reading`` is the half-open interval ``[lo, hi)``, ``null`` for an unbounded end; the
branches of a node tile every reading in increasing order, and ``probability`` is that of
the branch given that the node is reached. A declared ``orientation_rad`` is in the frame of
the last action, in ``[0, 2 pi)``; ``q`` is the probability that the declaration is right
given that the leaf is reached.

Examples
--------
>>> from bayesgrasp.io import plans
>>> policy_document is plans.policy_document
True
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..errors import BayesGraspError, SimulationError
from ..model.actions import ACTIONS
from .plan_reader import load_document

if TYPE_CHECKING:
    from ..model.noise import NoiseModel
    from ..model.sensing import WidthSensor
    from ..planning.policy import Declare, Policy, PolicyNode, Reject

__all__ = ["POLICY_SCHEMA", "PolicySource", "policy_document", "read_policy_document"]

POLICY_SCHEMA = "bayesgrasp.policy/1"
"""The schema of a policy document."""


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
    """The ``bayesgrasp.policy/1`` document of a policy (its fields: the module notes).

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
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
    if policy.stopped:
        doc["stopped"] = policy.stopped
        doc["requested_actions"] = policy.requested_actions
        doc["lower_bound"] = policy.lower_bound
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
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model import Problem
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)], name="rect"))
    >>> pol = plan_policy(pb, "width", 2)
    >>> read_policy_document(policy_document(pol)).root == pol.root
    True
    """
    from ..model.noise import NoiseModel, TurnNoise
    from ..model.sensing import WidthSensor

    doc = load_document(source, "policy file")
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
