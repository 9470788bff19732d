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

from .plans import POLICY_SCHEMA, policy_document, read_policy_document

__all__ = ["POLICY_SCHEMA", "policy_document", "read_policy_document"]
