"""The routes of plans: plans, policies, robot files, simulations (and jobs), figures."""

from __future__ import annotations

import math
from typing import Any, Literal

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse, Response

from .common import API, TIMEOUT
from .documents import check_simulation
from .models import (
    ERRORS,
    ErrorBody,
    ExportRequest,
    FigureRequest,
    PlanRequest,
    PolicyRequest,
    SimulateJobRequest,
    SimulateRequest,
)
from .service import run_work, service_of
from .workers import LimitError

__all__ = ["robot_file", "router"]

router = APIRouter(prefix=API, tags=["plans"])

FigureName = Literal["part", "diameter", "transfer", "plan"]
FigureFormat = Literal["png", "svg"]


@router.post("/plan", responses=ERRORS)
async def plan(req: PlanRequest, request: Request, timeout: float | None = TIMEOUT) -> Response:
    """The best plan of every length, Bayes and most certain (``bayesgrasp plan --json``).

    With ``turn_noise``, ``contact_noise`` or ``payoff``: the noise-aware Bayes plan
    (``plan --turn-noise ... --json``), in the heavy lane. With ``max_opening`` or
    ``min_opening``: a Bayes plan outside the gripper's stroke is refused (422), and with
    ``within_stroke`` only plans within it are planned (``plan --max-opening W ...``).
    """
    return await service_of(request).answer("plan", req, timeout)


@router.post("/policy", responses=ERRORS)
async def policy(req: PolicyRequest, request: Request, timeout: float | None = TIMEOUT) -> Response:
    """The Bayes policy that branches on jaw widths (``plan --sense ... --json``)."""
    return await service_of(request).answer("policy", req, timeout)


EXPORT_ANSWER: dict[int | str, dict[str, Any]] = {
    200: {
        "content": {"text/csv": {}, "application/json": {}},
        "description": "The robot file, as an attachment named PART-plan.FORMAT "
        "(PART-policy.FORMAT with `sense`).",
    },
    **ERRORS,
}


@router.post("/export", response_class=Response, responses=EXPORT_ANSWER)
async def export(req: ExportRequest, request: Request, timeout: float | None = TIMEOUT) -> Response:
    """The robot file of ``bayesgrasp plan ... --export FILE.csv|json``, byte for byte.

    The Bayes plan, one row a step (with the noise options: the noise-aware plan and its
    noise model); with ``sense``: the policy's state machine. Exact plans' files are made in
    the quick lane, policies' and noise-aware plans' in the heavy lane.
    """
    return await robot_file(service_of(request), req, timeout)


async def robot_file(service: Any, req: ExportRequest, timeout: float | None) -> Response:
    """The answer of ``export``: the robot file as an attachment with its name."""
    name, data = await service.run("export", req, timeout=timeout)
    media = "text/csv" if req.format == "csv" else "application/json"
    return Response(
        data,
        media_type=media,
        headers={"Content-Disposition": f'attachment; filename="{name}"'},
    )


@router.post("/simulate", responses=ERRORS)
async def simulate(
    req: SimulateRequest, request: Request, timeout: float | None = TIMEOUT
) -> Response:
    """Kinematic executions of a plan (``bayesgrasp simulate --engine kinematic --json``)."""
    return await service_of(request).answer("simulate", req, timeout)


@router.post(
    "/simulate/jobs",
    status_code=202,
    responses={202: {"description": "The job is queued: its id and where to read it."}, **ERRORS},
)
async def simulate_job(req: SimulateJobRequest, request: Request) -> JSONResponse:
    """Start a simulation job (``simulate --engine mujoco|kinematic --json``); poll it."""
    service = service_of(request)
    jobs = request.app.state.jobs
    lim = service.limits
    total = check_simulation(lim, req)  # a request it cannot run is answered now, not failed
    lane = service.lane("heavy")
    if lane.full():
        raise LimitError(
            503,
            f"the queue is full ({lane.queue} requests waiting for the heavy lane); "
            "try again later",
            kind="queue-full",
            retry_after=max(1, math.ceil(min(lim.time_limit, 60))),
        )

    async def run(job: Any) -> dict[str, Any]:
        return await lane.run(  # type: ignore[no-any-return]
            run_work,
            ("simulate", lim, req),
            lim.job_time_limit,
            progress=job.tick,
            on_start=job.start,
        )

    job = jobs.submit(total, run)
    doc = job.document()
    doc["url"] = f"{API}/simulate/jobs/{job.id}"
    return JSONResponse(doc, status_code=202, headers={"Location": doc["url"]})


@router.get(
    "/simulate/jobs/{job_id}",
    responses={
        404: {"model": ErrorBody, "description": "No such job (or no longer kept)."},
        422: ERRORS[422],
    },
)
async def simulate_job_status(job_id: str, request: Request) -> dict[str, Any]:
    """A simulation job: status, progress (trials done) and, when done, the document."""
    job = request.app.state.jobs.get(job_id)
    if job is None:
        raise LimitError(
            404,
            f"no job {job_id!r} (finished jobs are kept while there is room)",
            kind="not-found",
        )
    return job.document()  # type: ignore[no-any-return]


@router.post(
    "/figures/{name}.{fmt}",
    response_class=Response,
    responses={200: {"content": {"image/png": {}, "image/svg+xml": {}}}, **ERRORS},
)
async def figures(
    name: FigureName,
    fmt: FigureFormat,
    req: FigureRequest,
    request: Request,
    timeout: float | None = TIMEOUT,
) -> Response:
    """A figure of ``bayesgrasp plot``: part, diameter, transfer or plan; PNG or SVG."""
    data = await service_of(request).run("figure", req, name, fmt, timeout=timeout)
    media = "image/png" if fmt == "png" else "image/svg+xml"
    return Response(data, media_type=media)
