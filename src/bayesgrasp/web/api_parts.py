"""The routes of parts: the catalogue, squeeze and push functions, commands on uploads."""

from __future__ import annotations

import asyncio
import base64
import functools
import json
from pathlib import Path
from typing import Any, Literal

from fastapi import APIRouter, File, Form, Request, UploadFile
from fastapi.responses import JSONResponse, Response
from pydantic import BaseModel, ValidationError

from .api_plans import robot_file
from .common import TIMEOUT, error_response, one_line
from .documents import catalogue_document
from .models import (
    ERRORS,
    ExportRequest,
    PartRequest,
    PlanRequest,
    PolicyRequest,
    PosesRequest,
    SimulateRequest,
)
from .service import service_of
from .workers import LimitError

__all__ = ["router"]

router = APIRouter(prefix="/api/v1", tags=["parts"])


@functools.cache
def cached_catalogue() -> dict[str, Any]:
    """:func:`~bayesgrasp.web.documents.catalogue_document`, made once."""
    return catalogue_document()


@router.get("/catalogue")
async def catalogue() -> JSONResponse:
    """The catalogue parts (:func:`bayesgrasp.shapes.names`)."""
    return JSONResponse(await asyncio.to_thread(cached_catalogue))


@router.post("/squeeze", responses=ERRORS)
async def squeeze(req: PartRequest, request: Request, timeout: float | None = TIMEOUT) -> Response:
    """Stable orientations of a squeeze (``bayesgrasp squeeze --json``)."""
    return await service_of(request).answer("squeeze", req, timeout)


@router.post("/push", responses=ERRORS)
async def push(req: PartRequest, request: Request, timeout: float | None = TIMEOUT) -> Response:
    """Stable orientations of a push and a push-grasp (``bayesgrasp push --json``)."""
    return await service_of(request).answer("push", req, timeout)


@router.post("/poses", responses=ERRORS)
async def poses(req: PosesRequest, request: Request, timeout: float | None = TIMEOUT) -> Response:
    """The resting poses of a mesh part and their probabilities (``bayesgrasp poses --json``).

    A pose's index is the `pose` (and `goal_pose`) of the other endpoints.
    """
    return await service_of(request).answer("poses", req, timeout)


#: The request body of each command on an uploaded part.
UPLOAD_MODELS: dict[str, type[BaseModel]] = {
    "squeeze": PartRequest,
    "push": PartRequest,
    "plan": PlanRequest,
    "policy": PolicyRequest,
    "simulate": SimulateRequest,
    "export": ExportRequest,
    "poses": PosesRequest,
}


UPLOAD_ANSWER: dict[int | str, dict[str, Any]] = {
    200: {
        "content": {"application/json": {}, "text/csv": {}},
        "description": "The command's JSON document; with `export`, the robot file as an "
        "attachment (CSV or JSON).",
    },
    **ERRORS,
}


@router.post("/{command}/upload", responses=UPLOAD_ANSWER)
async def upload(
    command: Literal["squeeze", "push", "plan", "policy", "simulate", "export", "poses"],
    request: Request,
    file: UploadFile = File(description="A part file (read in memory)."),  # noqa: B008
    format: str = Form(description="json, csv, wkt, geojson, svg, dxf, stl, obj, ply, 3mf or glb."),
    options: str = Form("{}", description="The other members of the command's body, JSON."),
    timeout: float | None = TIMEOUT,
) -> Response:
    """A command on an uploaded part file (multipart): ``file``, ``format``, ``options``.

    A mesh's ``pose`` (of ``part.file``) may be given in ``options``.

    ``export`` answers the robot file (``options`` holds its ``format``, csv or json), the
    others the JSON document of the command.
    """
    service = service_of(request)
    data = await file.read(service.limits.max_body_bytes + 1)
    try:
        extra = json.loads(options)
    except ValueError:
        raise LimitError(422, "`options` must be a JSON object") from None
    if not isinstance(extra, dict) or "part" in extra:
        raise LimitError(422, "`options` must be a JSON object without `part`")
    stem = Path(file.filename or "part").stem
    safe = "".join(c for c in stem if c.isalnum() or c in "_.- ")[:64] or "part"
    file_in: dict[str, Any] = {"format": format, "data_base64": base64.b64encode(data).decode()}
    if "pose" in extra:  # a mesh's pose is the file's: `options` may carry it
        file_in["pose"] = extra.pop("pose")
    part = {"name": safe, "file": file_in}
    try:
        req: Any = UPLOAD_MODELS[command].model_validate({**extra, "part": part})
    except ValidationError as exc:
        return error_response(422, one_line(exc), "invalid-request")
    if command == "export":
        return await robot_file(service, req, timeout)
    return await service.answer(command, req, timeout)
