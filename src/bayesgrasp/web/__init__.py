"""The web page and the HTTP API of ``bayesgrasp serve`` (the ``web`` extra).

:func:`create_app` builds the FastAPI application: the JSON API under ``/api/v1`` (every
answer the same document the command line prints with ``--json``), its OpenAPI schema at
``/openapi.json`` (Swagger UI at ``/docs``, ReDoc at ``/redoc``, served from local files),
the page at ``/`` and the gallery of planned parts (SQLite). The planning runs in worker
processes (:mod:`bayesgrasp.web.workers`) stopped at a time limit; simulations can run as
jobs (:mod:`bayesgrasp.web.jobs`). Nothing here is imported by the library's core.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__all__ = ["Limits", "create_app"]

if TYPE_CHECKING:
    from .app import Limits, create_app


def __getattr__(name: str) -> Any:
    if name in __all__:
        from . import app

        return getattr(app, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
