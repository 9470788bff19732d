"""The policy document ``bayesgrasp.policy/1``: written and read by :mod:`bayesgrasp.io.plans`.

This module keeps the names it had (:func:`policy_document`, :data:`POLICY_SCHEMA`); the
schema is described in :mod:`bayesgrasp.io.plans`, the one module of documents.

Examples
--------
>>> from bayesgrasp.io import plans
>>> policy_document is plans.policy_document
True
"""

from __future__ import annotations

from .plans import POLICY_SCHEMA, policy_document, read_policy_document

__all__ = ["POLICY_SCHEMA", "policy_document", "read_policy_document"]
