"""The server's own routes: health, limits and the record of planned parts."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Query, Request

from .limits import limits_document
from .models import ErrorBody

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


@router.get("/gallery", responses={422: {"model": ErrorBody}})
async def gallery_rows(request: Request, limit: int = Query(50, ge=1, le=10_000)) -> dict[str, Any]:
    """The parts planned on this server, newest first."""
    gallery = request.app.state.service.gallery
    rows = gallery.rows(limit) if gallery is not None else []
    return {"schema": "bayesgrasp.gallery/1", "rows": rows}
