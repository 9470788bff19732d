"""The FastAPI application of ``bayesgrasp serve``: the JSON API, the page, the gallery.

Every API answer is the document the command line prints with ``--json``, built by the same
library calls (:class:`~bayesgrasp.runs.specs.ProblemSpec`,
:func:`bayesgrasp.io.plans.plan_document`, :mod:`bayesgrasp.report`). Every error is a JSON
body ``{detail, error, status}`` (:class:`~bayesgrasp.web.models.ErrorBody`): bad input is a
422 whose ``detail`` is the command line's one-line message; a body over
:attr:`Limits.max_body_bytes` is a 413 and a part over :attr:`Limits.max_vertices` vertices
a 422, each naming the limit.

The routes are in modules of their own: :mod:`~bayesgrasp.web.api_server` (health, limits,
the record of plans), :mod:`~bayesgrasp.web.api_parts` (catalogue, squeeze, push, uploads),
:mod:`~bayesgrasp.web.api_plans` (plans, policies, robot files, simulations, figures),
:mod:`~bayesgrasp.web.views` (the page's views and saved gallery) and
:mod:`~bayesgrasp.web.pages`; the documents they answer in
:mod:`~bayesgrasp.web.documents`.

The work runs in worker processes (:mod:`bayesgrasp.web.workers`), never on the server's
event loop: a quick lane (squeeze and push functions, plans), a lane for figures and a
heavy lane (policies, noise-aware plans, simulations and simulation jobs), each with a
bounded queue.
Work past its time limit (:attr:`Limits.time_limit`, or less if the request asks) is stopped
and its worker replaced; a full queue, a time limit or a worker's memory cap is a 503 that
says which, with a ``Retry-After`` header.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from pathlib import Path

try:
    from fastapi import FastAPI, Request
    from fastapi.exceptions import RequestValidationError
    from fastapi.responses import JSONResponse
    from starlette.exceptions import HTTPException as StarletteHTTPException
except ImportError as exc:  # pragma: no cover - the extra is missing
    from ..errors import MissingExtraError

    raise MissingExtraError(exc.name or "fastapi", "web") from None

from ..errors import BayesGraspError
from . import api_parts, api_plans, api_server, pages, views
from .common import API, BodyLimit, error_response, one_line
from .documents import plan_result_document
from .gallery import Gallery
from .limits import Limits
from .service import Service, lane_of
from .workers import LimitError, failure_of

__all__ = ["API", "Limits", "Service", "create_app", "lane_of", "plan_result_document"]


def create_app(data_dir: str | Path | None = None, limits: Limits | None = None) -> FastAPI:
    """The application: API under ``/api/v1``, OpenAPI at ``/openapi.json``, the page at ``/``.

    Planning runs in worker processes (:mod:`bayesgrasp.web.workers`): a quick lane (squeeze
    and push functions, plans), a figures lane and a heavy lane (policies, noise-aware plans,
    simulations), each with a bounded queue; work past its time limit is stopped.

    Parameters
    ----------
    data_dir : str or Path, optional
        Folder of the gallery database; ``None``: no gallery.
    limits : Limits, optional
        Default :class:`Limits`.

    Examples
    --------
    >>> app = create_app(limits=Limits(max_vertices=500))
    >>> "/api/v1/plan" in app.openapi()["paths"]
    True
    """
    from .. import __version__
    from .jobs import Jobs

    lim = limits or Limits()
    gallery = Gallery(data_dir, lim.gallery_rows) if data_dir is not None else None
    service = Service(lim, gallery)
    jobs = Jobs(lim.max_jobs)

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        await service.lane("quick").prestart()  # the quick lane is ready for the first request
        yield
        jobs.cancel_all()
        service.close()

    memory = "no memory cap" if lim.worker_memory is None else f"{lim.worker_memory} MB"
    app = FastAPI(
        title="bayesgrasp",
        version=__version__,
        description=(
            "Bayesian squeeze and push-grasp plans for planar parts. Every answer is the "
            "JSON document `bayesgrasp COMMAND --json` prints; every error a JSON body "
            "`{detail, error, status}`. Limits: request bodies up to "
            f"{lim.max_body_bytes} bytes, parts up to {lim.max_vertices} vertices, "
            f"{lim.time_limit:g} s of work a request, {lim.max_trials} simulation trials; "
            f"worker processes: {lim.quick_workers} quick (squeeze, push, plans), "
            f"{lim.figure_workers} for figures, {lim.workers} heavy (policies, noise, "
            f"simulations), {memory} each; {lim.queue} requests waiting in each lane."
        ),
        docs_url=None,
        redoc_url=None,
        lifespan=lifespan,
    )
    app.state.service = service
    app.state.jobs = jobs

    @app.exception_handler(BayesGraspError)
    async def _bad_input(request: Request, exc: BayesGraspError) -> JSONResponse:
        status, kind, reason = failure_of(exc)
        return error_response(status, reason, kind)

    @app.exception_handler(LimitError)
    async def _limit(request: Request, exc: LimitError) -> JSONResponse:
        return error_response(exc.status, str(exc), exc.kind, exc.retry_after)

    @app.exception_handler(StarletteHTTPException)
    async def _http(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        return error_response(exc.status_code, str(exc.detail), "http")

    @app.exception_handler(RequestValidationError)
    async def _invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        return error_response(422, one_line(exc), "invalid-request")

    @app.exception_handler(Exception)
    async def _internal(request: Request, exc: Exception) -> JSONResponse:
        status, kind, reason = failure_of(exc)
        return error_response(status, reason, kind)

    app.include_router(api_server.router)
    app.include_router(api_parts.router)
    app.include_router(api_plans.router)
    app.include_router(views.router)
    app.include_router(pages.router)
    pages.mount_static(app)
    app.add_middleware(BodyLimit, max_bytes=lim.max_body_bytes)
    return app
