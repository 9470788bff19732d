"""The page's own endpoints: the views a user saves to the gallery, paged.

The automatic record of every plan (``GET /api/v1/gallery``) stays as it is; the page shows
only what the user saved with its *Save* button: the page's address fragment (the part and
every option, so the entry reproduces the view, costs included), the outline for a
thumbnail and the plan's numbers.
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Query, Request
from fastapi.responses import JSONResponse
from pydantic import BaseModel, ConfigDict, Field

__all__ = ["SaveRequest", "router"]

router = APIRouter(prefix="/api/v1/saved", tags=["server"])

Point = tuple[float, float]


class SaveRequest(BaseModel):
    """A view to keep: its name, address fragment, outline and plan numbers."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    name: str = Field(min_length=1, max_length=80)
    view: str = Field(min_length=1, max_length=200_000, description="The address fragment.")
    outline: list[Point] = Field(max_length=2000, description="Outline for the thumbnail.")
    summary: dict[str, float | int | str | None] = Field(
        default_factory=dict, max_length=20, description="The plan's numbers."
    )


def _no_gallery() -> JSONResponse:
    return JSONResponse(
        {"detail": "this server keeps no gallery (no data folder)", "error": "http", "status": 404},
        status_code=404,
    )


@router.post("")
async def save(req: SaveRequest, request: Request) -> Any:
    """Save a view to the gallery (saving it again refreshes its time)."""
    gallery = request.app.state.service.gallery
    if gallery is None:
        return _no_gallery()
    key = gallery.save(req.name, req.view, [list(p) for p in req.outline], req.summary)
    return {"id": key}


@router.get("")
async def saved(
    request: Request,
    page: Annotated[int, Query(ge=1, le=100_000)] = 1,
    per_page: Annotated[int, Query(ge=1, le=100)] = 12,
) -> Any:
    """One page of the saved views, newest first, with their total count."""
    gallery = request.app.state.service.gallery
    if gallery is None:
        return {"page": page, "per_page": per_page, "total": 0, "rows": []}
    return {"schema": "bayesgrasp.saved/1", **gallery.saved_page(page, per_page)}
