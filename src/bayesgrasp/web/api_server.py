"""The server's own routes: health and limits."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Request

from .limits import limits_document

__all__ = ["router"]

router = APIRouter(prefix="/api/v1", tags=["server"])


@router.get("/health")
async def health(request: Request) -> dict[str, Any]:
    """The server is up; its version, limits and worker lanes."""
    from .. import __version__

    service = request.app.state.service
    return {
        "status": "ok",
        "version": __version__,
        "limits": limits_document(service.limits),
        "lanes": service.lanes_status(),
    }


@router.get("/limits")
async def limits(request: Request) -> dict[str, Any]:
    """The limits a request must keep to."""
    return limits_document(request.app.state.service.limits)
