"""The FastAPI application of ``bayesgrasp serve``: the JSON API, the page, the gallery.

Every API answer is the document the command line prints with ``--json``, built by the same
library calls (:class:`~bayesgrasp.cli.specs.ProblemSpec`,
:func:`bayesgrasp.io.plans.plan_document`, :mod:`bayesgrasp.report`). Bad input is a 422
whose ``detail`` is the command line's one-line message; a body over
:attr:`Limits.max_body_bytes` is a 413 and a part over :attr:`Limits.max_vertices` vertices
a 422, each naming the limit; work runs in a pool of threads under :attr:`Limits.time_limit`
seconds (then a 503; the server keeps serving). Noise-aware plans, which can take minutes,
run in threads of their own (:attr:`Limits.noisy_workers`), so that they never hold the
threads of the light requests.
"""

from __future__ import annotations

import asyncio
import base64
import binascii
import io
import json
import math
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, TypeVar

try:
    from fastapi import FastAPI, File, Form, Query, Request, UploadFile
    from fastapi.exceptions import RequestValidationError
    from fastapi.responses import FileResponse, JSONResponse, RedirectResponse, Response
    from fastapi.staticfiles import StaticFiles
    from pydantic import BaseModel, ValidationError
    from starlette.exceptions import HTTPException as StarletteHTTPException
except ImportError as exc:  # pragma: no cover - the extra is missing
    from ..errors import MissingExtraError

    raise MissingExtraError(exc.name or "fastapi", "web") from None

from ..errors import BayesGraspError, NoPlanError
from . import views
from .gallery import Gallery
from .models import (
    FigureRequest,
    PartIn,
    PartRequest,
    PlanRequest,
    PolicyRequest,
    ProblemOptions,
    SimulateRequest,
)

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
    from ..planning.result import PlanOption

__all__ = ["API", "Limits", "create_app"]

API = "/api/v1"
T = TypeVar("T")
FigureName = Literal["part", "diameter", "transfer", "plan"]
FigureFormat = Literal["png", "svg"]


@dataclass(frozen=True, slots=True)
class Limits:
    """What one request may ask of the server.

    Attributes
    ----------
    max_body_bytes : int
        Largest request body (larger: 413).
    max_vertices : int
        Most vertices (or outline points) of a part (more: 422).
    time_limit : float
        Seconds a request's work may take (longer: 503).
    max_trials : int
        Most simulation trials a request may ask for (more: 422).
    workers : int
        Threads doing the work.
    max_pending : int
        Requests at work or waiting for a thread (more: 503 at once).
    gallery_rows : int
        Rows the gallery keeps.
    noisy_workers : int
        Threads for noise-aware plans (``turn_noise``, ``contact_noise``, ``payoff``), apart
        from the others: such a plan can take minutes, and a thread past its time limit
        cannot be stopped, so these requests may hold only these threads (more at once: 503
        at once) and never keep the light requests waiting.
    """

    max_body_bytes: int = 1_000_000
    max_vertices: int = 2000
    time_limit: float = 10.0
    max_trials: int = 1_000_000
    workers: int = 4
    max_pending: int = 64
    gallery_rows: int = 500
    noisy_workers: int = 1


class LimitError(Exception):
    """A request over one of the server's limits."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


def _error(status: int, detail: str, kind: str) -> JSONResponse:
    return JSONResponse({"detail": detail, "error": kind, "status": status}, status_code=status)


class BodyLimit:
    """ASGI middleware: a request body over ``max_bytes`` is answered 413, unread past the limit."""

    def __init__(self, app: Any, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    def _too_large(self) -> JSONResponse:
        return _error(
            413,
            f"the request body is larger than the limit of {self.max_bytes} bytes",
            "body-too-large",
        )

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = dict(scope.get("headers") or [])
        length = headers.get(b"content-length")
        if length is not None:
            try:
                declared = int(length)
            except ValueError:
                declared = self.max_bytes + 1
            if declared > self.max_bytes:
                await self._too_large()(scope, receive, send)
                return
            await self.app(scope, receive, send)
            return
        # no length declared (chunked): read the body here, counting, then hand it on
        chunks: list[bytes] = []
        seen = 0
        while True:
            message = await receive()
            if message["type"] != "http.request":
                await self.app(scope, receive, send)  # the client went away
                return
            chunk = message.get("body", b"")
            seen += len(chunk)
            if seen > self.max_bytes:
                await self._too_large()(scope, receive, send)
                return
            chunks.append(chunk)
            if not message.get("more_body", False):
                break
        body = b"".join(chunks)
        replayed = False

        async def replay() -> Any:
            nonlocal replayed
            if replayed:
                return await receive()
            replayed = True
            return {"type": "http.request", "body": body, "more_body": False}

        await self.app(scope, replay, send)


def _one_line(exc: RequestValidationError | ValidationError) -> str:
    """The validation errors as one line: ``part.vertices.0: message; ...``."""
    parts = []
    for err in exc.errors():
        loc = ".".join(str(x) for x in err.get("loc", ()) if x != "body")
        parts.append(f"{loc or 'body'}: {err.get('msg', 'invalid')}")
    return "; ".join(parts) or "invalid request"


class Service:
    """What the endpoints share: limits, the worker threads, the gallery."""

    def __init__(self, limits: Limits, gallery: Gallery | None) -> None:
        self.limits = limits
        self.gallery = gallery
        self.pool = ThreadPoolExecutor(max_workers=limits.workers, thread_name_prefix="bg-web")
        self.noisy_pool = ThreadPoolExecutor(
            max_workers=limits.noisy_workers, thread_name_prefix="bg-web-noisy"
        )
        self.pending = 0
        self.noisy = 0  # noise-aware plans at work (a timed-out one until its thread ends)
        self.lock = threading.Lock()
        self.figure_lock = threading.Lock()

    async def run(self, work: Callable[[], T], noisy: bool = False) -> T:
        """Run ``work`` in a worker thread under the time limit (503 when over or busy).

        ``noisy``: a noise-aware plan, run in its own threads (:attr:`Limits.noisy_workers`).
        """
        with self.lock:
            if self.pending >= self.limits.max_pending:
                raise LimitError(
                    503, f"the server is busy ({self.limits.max_pending} requests at work)"
                )
            if noisy and self.noisy >= self.limits.noisy_workers:
                raise LimitError(
                    503,
                    f"the server is busy with noise-aware plans ({self.noisy} at work, the "
                    f"limit is {self.limits.noisy_workers}); try again later or ask for less "
                    "(a smaller max_actions)",
                )
            self.pending += 1
            self.noisy += noisy
        pool = self.noisy_pool if noisy else self.pool
        future = asyncio.get_running_loop().run_in_executor(pool, work)
        if noisy:
            future.add_done_callback(lambda _: self._noisy_done())
        try:
            return await asyncio.wait_for(asyncio.shield(future), self.limits.time_limit)
        except TimeoutError:
            raise LimitError(
                503,
                f"the request took longer than the time limit of {self.limits.time_limit:g} s; "
                "ask for less (a smaller max_actions, method exact, fewer trials)",
            ) from None
        finally:
            # a timed-out thread cannot be stopped: it counts as pending until it ends
            future.add_done_callback(lambda _: self._done())

    def _done(self) -> None:
        with self.lock:
            self.pending -= 1

    def _noisy_done(self) -> None:
        with self.lock:
            self.noisy -= 1

    # -- parts and problems ----------------------------------------------------------------

    def part(self, spec: PartIn) -> Part:
        """Read the part of a request (in memory), with its ``shape_tol`` (``--shape-tol``).

        See :func:`~bayesgrasp.geometry.curved.with_shape_tol`; as on the command line, the
        tolerance applies to any part (vertices, catalogue or file).
        """
        from ..geometry.curved import with_shape_tol

        return with_shape_tol(self._read(spec), spec.shape_tol)

    def _read(self, spec: PartIn) -> Part:
        """Read the part of a request (in memory), refusing more than ``max_vertices``."""
        from ..io import read_part_bytes
        from ..shapes import names

        given = [x for x in (spec.vertices, spec.catalogue, spec.file) if x is not None]
        if len(given) != 1:
            raise LimitError(422, "`part` needs exactly one of vertices, catalogue or file")
        limit = self.limits.max_vertices
        if spec.catalogue is not None:
            from ..cli.specs import PartSpec

            if spec.catalogue not in names():
                raise LimitError(
                    422,
                    f"{spec.catalogue!r} is not a catalogue part ({', '.join(names())})",
                )
            return PartSpec(spec.catalogue).load()
        if spec.vertices is not None:
            if len(spec.vertices) > limit:
                raise LimitError(
                    422, f"the part has {len(spec.vertices)} vertices; the limit is {limit}"
                )
            doc: dict[str, Any] = {"vertices": [list(v) for v in spec.vertices]}
            if spec.units is not None:
                doc["units"] = spec.units
            if spec.center_of_mass is not None:
                doc["center_of_mass"] = list(spec.center_of_mass)
            data = json.dumps(doc).encode()
            return read_part_bytes(data, "json", f"{spec.name}.json", max_points=limit)
        f = spec.file
        if f is None:  # unreachable: one of the three was given
            raise LimitError(422, "`part` needs exactly one of vertices, catalogue or file")
        try:
            data = base64.b64decode(f.data_base64, validate=True)
        except (binascii.Error, ValueError):
            raise LimitError(422, "`part.file.data_base64` is not valid base64") from None
        return self.read_file(data, f.format, spec.name, f.element, f.layer, f.flatten_tol)

    def read_file(
        self,
        data: bytes,
        fmt: str,
        name: str,
        element: str | None = None,
        layer: str | None = None,
        tolerance: float | None = None,
    ) -> Part:
        """A part from a file's bytes (never written to disk; ``name`` only labels it)."""
        from ..io import read_part_bytes

        limit = self.limits.max_vertices
        try:
            return read_part_bytes(
                data,
                fmt,
                f"{name}.{fmt}",
                element=element,
                layer=layer,
                tolerance=tolerance,
                max_points=limit,
            )
        except BayesGraspError as exc:
            if "too many points" in str(exc) or "max_points" in str(exc):
                raise LimitError(422, f"{exc} (the server's vertex limit is {limit})") from None
            raise


def _prior_string(opts: PartRequest | ProblemOptions) -> str:
    """The prior text, refusing the forms that read a file on the server."""
    kind = opts.prior.partition(":")[0].strip().lower()
    if kind in ("histogram", "sample"):
        raise LimitError(
            422,
            f"`prior`: {kind}:FILE reads a file, which the server does not do; give the "
            f"values in `prior_{kind}`",
        )
    return opts.prior


def problem_spec(opts: ProblemOptions) -> Any:
    """The :class:`~bayesgrasp.cli.specs.ProblemSpec` the command line makes of these options."""
    from ..cli.specs import GoalKind, Method, ProblemSpec
    from ..model.actions import get_action

    for name in (*opts.costs, *opts.first_costs):
        get_action(name)  # an unknown action: PlanningError naming the known ones
    if isinstance(opts.actions, str):
        actions = [a.strip() for a in opts.actions.split(",") if a.strip()]
    else:
        actions = [a.strip() for a in opts.actions if a.strip()]
    return ProblemSpec(
        prior=_prior_string(opts),
        costs=dict(opts.costs),
        first=dict(opts.first_costs),
        verify=opts.verify_cost,
        retry=opts.retry_cost,
        goal=GoalKind(opts.goal),
        actions=tuple(dict.fromkeys(actions)),
        accuracy_deg=opts.accuracy,
        method=Method(opts.method),
        max_actions=opts.max_actions,
    )


def build_problem(part: Part, opts: ProblemOptions, spec: Any) -> Problem:
    """``spec.build(part)``, or with the inline histogram or sample prior of the request."""
    if opts.prior_histogram is None and opts.prior_sample is None:
        return spec.build(part)  # type: ignore[no-any-return]
    import numpy as np

    from ..model.cost import CostModel
    from ..model.goal import Goal
    from ..model.prior import HistogramPrior, Prior, SamplePrior
    from ..model.problem import Problem

    if opts.prior_histogram is not None and opts.prior_sample is not None:
        raise LimitError(422, "give at most one of `prior_histogram` and `prior_sample`")
    if opts.prior != "uniform":
        raise LimitError(422, "`prior` must stay uniform with `prior_histogram`/`prior_sample`")
    prior: Prior
    if opts.prior_histogram is not None:
        prior = HistogramPrior(np.array(opts.prior_histogram, dtype=float), name="histogram")
    else:
        prior = SamplePrior(np.radians(np.array(opts.prior_sample, dtype=float)), name="sample")
    # the same construction as ProblemSpec.build, with the prior given as a value
    cost = CostModel(spec.costs or {}, spec.verify, spec.first or {}, spec.retry)
    return Problem.build(
        part,
        prior=prior,
        cost=cost,
        goal=Goal(spec.goal.value),
        actions=spec.actions,
        accuracy=math.radians(spec.accuracy_deg),
    )


def _chosen(
    which: str, opts: ProblemOptions, part: Part, spec: Any
) -> tuple[Problem, PlanOption, str]:
    """The problem and the plan ``which`` names (as ``--plan`` does)."""
    from ..cli.common import PLAN_NAMES
    from ..cli.specs import guaranteed_plan

    problem = build_problem(part, opts, spec)
    if which == "guaranteed":
        found = guaranteed_plan(problem)
        if isinstance(found, str):
            raise NoPlanError(found)
        return problem, found.option, PLAN_NAMES[which]
    result = spec.plan(problem)
    plan = result.bayes_plan if which == "bayes" else result.most_certain_plan
    return problem, plan, PLAN_NAMES[which]


# -- the documents (each the CLI's --json output) ---------------------------------------------


def squeeze_document(service: Service, req: PartRequest) -> dict[str, Any]:
    """``bayesgrasp squeeze PART --prior P --json``."""
    from .. import report
    from ..geometry.curved import squeeze_model
    from ..model.prior import parse_prior

    p = service.part(req.part)
    pr = parse_prior(_prior_string(req))
    return report.squeeze_json(p, squeeze_model(p)[1], pr)  # a curved part's exact model


def push_document(service: Service, req: PartRequest) -> dict[str, Any]:
    """``bayesgrasp push PART --prior P --json``."""
    from .. import report
    from ..geometry.curved import push_model
    from ..model.prior import parse_prior

    p = service.part(req.part)
    pr = parse_prior(_prior_string(req))
    return report.push_json(p, *push_model(p), pr)


def plan_result_document(service: Service, req: PlanRequest) -> dict[str, Any]:
    """``bayesgrasp plan PART [options] [--guaranteed] --json``."""
    from ..cli.specs import guaranteed_plan, run_inputs
    from ..io.plans import plan_document

    spec = problem_spec(req)
    part = service.part(req.part)
    pb = build_problem(part, req, spec)
    if req.noisy:
        doc = noisy_plan_document(pb, req, run_inputs(None, spec))
    else:
        result = spec.plan(pb)
        found = guaranteed_plan(pb) if req.guaranteed else None
        sure, missing = (None, found) if isinstance(found, str) else (found, None)
        inputs = run_inputs(None, spec)  # the provenance the command line writes
        doc = plan_document(result, guaranteed=sure, guaranteed_missing=missing, inputs=inputs)
    if service.gallery is not None:
        options = req.model_dump(exclude={"part"}, exclude_defaults=True)
        bayes = doc["options"][doc["bayes"]] if doc["options"] else {}
        service.gallery.add(part.name, doc["part"]["vertices"], options, bayes)
    return doc


def noisy_plan_document(
    pb: Problem, req: PlanRequest, inputs: dict[str, Any] | None = None
) -> dict[str, Any]:
    """``bayesgrasp plan PART --turn-noise ... --contact-noise ... --payoff FILE --json``.

    The command line's run (:class:`bayesgrasp.cli.noisy.NoisyRun`: the noise-aware plans,
    and with ``guaranteed`` the guaranteed plan under a bounded turn error), with the payoff
    given inline; ``inputs`` the provenance the command line writes.
    """
    from ..cli.noisy import NoisyRun
    from ..planning.robust import UNBOUNDED_GUARANTEE

    _exact_method(req)
    noise = req.noise_model()
    if req.guaranteed and not noise.turn.exact and noise.turn.kind == "normal":
        raise LimitError(422, f"`guaranteed`: {UNBOUNDED_GUARANTEE}")
    run = NoisyRun(noise, req.payoff_model(), req.max_actions, False, req.guaranteed)
    return run.document(run.plan(pb), inputs)


def _exact_method(req: PlanRequest | SimulateRequest) -> None:
    if req.method != "exact":
        raise LimitError(
            422, "`method`: the noise-aware planner seeds from the exact planner; drop `method`"
        )


def policy_document_of(service: Service, req: PolicyRequest) -> dict[str, Any]:
    """``bayesgrasp plan PART [--also PART ...] --sense ... --json``: the Bayes policy.

    With the noise or payoff options, the policy under the noisy actions
    (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`), as the command line plans it.
    """
    from ..io.policies import policy_document
    from ..planning.noisy_policy import plan_noisy_policy
    from ..planning.policy import plan_policy

    spec = problem_spec(req)
    parts = [service.part(p) for p in (req.part, *req.also)]
    problems = [build_problem(p, req, spec) for p in parts]
    prior = None if req.part_prior is None else ",".join(map(repr, req.part_prior))
    if not req.noisy:
        pol = plan_policy(problems, sensor=req.sense, max_actions=req.max_actions, part_prior=prior)
        return policy_document(pol)
    if req.payoff is not None and len(problems) > 1:
        raise LimitError(422, "`payoff`: a payoff is for one part: drop `also`")
    pol = plan_noisy_policy(
        problems,
        req.sense,
        req.max_actions,
        req.noise_model(),
        payoff=req.payoff_model(),
        part_prior=prior,
    )
    return policy_document(pol)


def simulate_document(service: Service, req: SimulateRequest) -> dict[str, Any]:
    """``bayesgrasp simulate PART [options] --engine kinematic --json``."""
    from .. import report
    from ..model.noise import NoiseModel, TurnNoise
    from ..model.payoff import as_vector
    from ..sim.kinematic import simulate_kinematic

    if req.trials > service.limits.max_trials:
        raise LimitError(422, f"`trials` is {req.trials}; the limit is {service.limits.max_trials}")
    spec = problem_spec(req)
    p = service.part(req.part)
    if req.turn_noise is not None and (req.noise > 0 or req.noise_kind != "normal"):
        raise LimitError(
            422, "`noise`, `noise_kind`: the older spelling of `turn_noise`; give one of them"
        )
    noise = req.noise_model()
    deg, kind = req.noise, req.noise_kind
    if req.turn_noise is None:
        noise = NoiseModel(TurnNoise(req.noise_kind, math.radians(req.noise)), noise.contact)
    else:
        deg, kind = float(req.turn_noise.partition(":")[2]), noise.turn.kind
    pay = req.payoff_model()
    if (not noise.exact or pay is not None) and req.plan != "guaranteed":
        _exact_method(req)
        from ..planning.noisy import plan_noisy

        pb = spec.build(p)
        res_n = plan_noisy(pb, noise, pay, spec.max_actions)
        option = res_n.options[res_n.bayes if req.plan == "bayes" else res_n.most_certain].option
    else:
        pb, option, _ = _chosen(req.plan, req, p, spec)
    u = None if pay is None else as_vector(pay, pb.states)
    res = simulate_kinematic(pb, option, req.trials, noise, rng=req.seed, payoff=u)
    from ..cli.common import simulate_inputs
    from ..cli.specs import run_inputs
    from ..io.plans import provenance

    doc = report.simulate_json(res, p)  # with the provenance the command line writes
    how = simulate_inputs("kinematic", req.plan, req.seed, req.trials, deg, kind)
    how["contact_noise"] = req.contact_noise
    how["payoff"] = None if req.payoff is None else "request"
    doc["provenance"] = provenance(pb, None, **how, **run_inputs(None, spec))
    return doc


def figure_bytes(service: Service, req: FigureRequest, name: str, fmt: str) -> bytes:
    """One of the figures ``bayesgrasp plot`` writes (``NAME.FMT``), as bytes."""
    from ..figures.plots import diameter_figure, evolution_figure, part_figure, transfer_figure
    from ..model.actions import PUSH_GRASP

    spec = problem_spec(req)
    p = service.part(req.part)
    pb, option, label = _chosen(req.plan, req, p, spec)
    with service.figure_lock:  # matplotlib's font cache and text engine are shared
        if name == "part":
            fig = part_figure(pb.part)
        elif name == "diameter":
            fig = diameter_figure(pb, option.first_angle)
        elif name == "transfer":
            fig = transfer_figure(pb, push_grasp=PUSH_GRASP.name in pb.action_kinds)
        else:
            fig = evolution_figure(pb, option, label)
        buf = io.BytesIO()
        meta = {"Software": None} if fmt == "png" else {"Date": None, "Creator": None}
        fig.savefig(buf, format=fmt, dpi=110, metadata=meta)
    return buf.getvalue()


def catalogue_document() -> dict[str, Any]:
    """The catalogue parts: name, description, outline and the ``part`` object."""
    from ..io.plans import part_document
    from ..shapes import entry, load, names

    parts = []
    for n in names():
        e = entry(n)
        parts.append(
            {
                "name": n,
                "description": e.description,
                "outline": [list(v) for v in e.vertices],
                "part": part_document(load(n)),
            }
        )
    return {"schema": "bayesgrasp.catalogue/1", "parts": parts}


# -- the application --------------------------------------------------------------------------


def create_app(data_dir: str | Path | None = None, limits: Limits | None = None) -> FastAPI:
    """The application: API under ``/api/v1``, OpenAPI at ``/openapi.json``, the page at ``/``.

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

    lim = limits or Limits()
    gallery = Gallery(data_dir, lim.gallery_rows) if data_dir is not None else None
    service = Service(lim, gallery)
    app = FastAPI(
        title="bayesgrasp",
        version=__version__,
        description=(
            "Bayesian squeeze and push-grasp plans for planar parts. Every answer is the "
            "JSON document `bayesgrasp COMMAND --json` prints. Limits: request bodies up to "
            f"{lim.max_body_bytes} bytes, parts up to {lim.max_vertices} vertices, "
            f"{lim.time_limit:g} s of work a request, {lim.max_trials} simulation trials, "
            f"{lim.noisy_workers} noise-aware plan(s) at a time."
        ),
    )
    app.state.service = service

    @app.exception_handler(BayesGraspError)
    async def _bad_input(request: Request, exc: BayesGraspError) -> JSONResponse:
        if isinstance(exc, NoPlanError):
            return _error(422, f"no plan: {exc}", "no-plan")
        return _error(422, str(exc), type(exc).__name__)

    @app.exception_handler(LimitError)
    async def _limit(request: Request, exc: LimitError) -> JSONResponse:
        kinds = {413: "too-large", 422: "limit", 503: "unavailable"}
        return _error(exc.status, str(exc), kinds.get(exc.status, "limit"))

    @app.exception_handler(StarletteHTTPException)
    async def _http(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        return _error(exc.status_code, str(exc.detail), "http")

    @app.exception_handler(RequestValidationError)
    async def _invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        return _error(422, _one_line(exc), "invalid-request")

    async def answer(work: Callable[[], dict[str, Any]], noisy: bool = False) -> JSONResponse:
        return JSONResponse(await service.run(work, noisy))

    @app.get(f"{API}/health", tags=["server"])
    async def health() -> dict[str, Any]:
        """The server is up; its version and limits."""
        return {"status": "ok", "version": __version__, "limits": _limits(lim)}

    @app.get(f"{API}/limits", tags=["server"])
    async def limits_() -> dict[str, Any]:
        """The limits a request must keep to."""
        return _limits(lim)

    @app.get(f"{API}/catalogue", tags=["parts"])
    async def catalogue() -> JSONResponse:
        """The catalogue parts (:func:`bayesgrasp.shapes.names`)."""
        return await answer(catalogue_document)

    @app.post(f"{API}/squeeze", tags=["parts"])
    async def squeeze(req: PartRequest) -> JSONResponse:
        """Stable orientations of a squeeze (``bayesgrasp squeeze --json``)."""
        return await answer(lambda: squeeze_document(service, req))

    @app.post(f"{API}/push", tags=["parts"])
    async def push(req: PartRequest) -> JSONResponse:
        """Stable orientations of a push and a push-grasp (``bayesgrasp push --json``)."""
        return await answer(lambda: push_document(service, req))

    @app.post(f"{API}/plan", tags=["plans"])
    async def plan(req: PlanRequest) -> JSONResponse:
        """The best plan of every length, Bayes and most certain (``bayesgrasp plan --json``).

        With ``turn_noise``, ``contact_noise`` or ``payoff``: the noise-aware Bayes plan
        (``plan --turn-noise ... --json``), in the server's threads for such plans.
        """
        return await answer(lambda: plan_result_document(service, req), req.noisy)

    @app.post(f"{API}/policy", tags=["plans"])
    async def policy(req: PolicyRequest) -> JSONResponse:
        """The Bayes policy that branches on jaw widths (``plan --sense ... --json``)."""
        return await answer(lambda: policy_document_of(service, req), req.noisy)

    @app.post(f"{API}/simulate", tags=["plans"])
    async def simulate(req: SimulateRequest) -> JSONResponse:
        """Kinematic executions of a plan (``bayesgrasp simulate --engine kinematic --json``)."""
        return await answer(lambda: simulate_document(service, req), req.noisy)

    @app.post(
        f"{API}/figures/{{name}}.{{fmt}}",
        tags=["plans"],
        response_class=Response,
        responses={200: {"content": {"image/png": {}, "image/svg+xml": {}}}},
    )
    async def figures(name: FigureName, fmt: FigureFormat, req: FigureRequest) -> Response:
        """A figure of ``bayesgrasp plot``: part, diameter, transfer or plan; PNG or SVG."""
        data = await service.run(lambda: figure_bytes(service, req, name, fmt))
        media = "image/png" if fmt == "png" else "image/svg+xml"
        return Response(data, media_type=media)

    @app.post(f"{API}/{{command}}/upload", tags=["parts"])
    async def upload(
        command: Literal["squeeze", "push", "plan", "policy", "simulate"],
        file: UploadFile = File(description="A part file (read in memory)."),  # noqa: B008
        format: str = Form(description="json, csv, wkt, geojson, svg or dxf."),
        options: str = Form("{}", description="The other members of the command's body, JSON."),
    ) -> JSONResponse:
        """A command on an uploaded part file (multipart): ``file``, ``format``, ``options``."""
        data = await file.read(lim.max_body_bytes + 1)
        try:
            extra = json.loads(options)
        except ValueError:
            raise LimitError(422, "`options` must be a JSON object") from None
        if not isinstance(extra, dict) or "part" in extra:
            raise LimitError(422, "`options` must be a JSON object without `part`")
        stem = Path(file.filename or "part").stem
        safe = "".join(c for c in stem if c.isalnum() or c in "_.- ")[:64] or "part"
        part = {
            "name": safe,
            "file": {"format": format, "data_base64": base64.b64encode(data).decode()},
        }
        models: dict[str, type[BaseModel]] = {
            "squeeze": PartRequest,
            "push": PartRequest,
            "plan": PlanRequest,
            "policy": PolicyRequest,
            "simulate": SimulateRequest,
        }
        model = models[command]
        try:
            req: Any = model.model_validate({**extra, "part": part})
        except ValidationError as exc:
            return _error(422, _one_line(exc), "invalid-request")
        work: dict[str, Callable[[], dict[str, Any]]] = {
            "squeeze": lambda: squeeze_document(service, req),
            "push": lambda: push_document(service, req),
            "plan": lambda: plan_result_document(service, req),
            "policy": lambda: policy_document_of(service, req),
            "simulate": lambda: simulate_document(service, req),
        }
        return await answer(work[command], bool(getattr(req, "noisy", False)))

    @app.get(f"{API}/gallery", tags=["server"])
    async def gallery_rows(limit: int = Query(50, ge=1, le=10_000)) -> dict[str, Any]:
        """The parts planned on this server, newest first."""
        rows = service.gallery.rows(limit) if service.gallery is not None else []
        return {"schema": "bayesgrasp.gallery/1", "rows": rows}

    app.include_router(views.router)
    static = resources.files("bayesgrasp.web") / "static"
    index = Path(str(static)) / "index.html"

    @app.get("/", include_in_schema=False)
    async def page() -> FileResponse:
        return FileResponse(index, media_type="text/html")

    @app.get("/index.html", include_in_schema=False)
    async def page_alias() -> RedirectResponse:
        return RedirectResponse("/")

    app.mount("/static", StaticFiles(directory=str(static)), name="static")
    app.add_middleware(BodyLimit, max_bytes=lim.max_body_bytes)
    return app


def _limits(lim: Limits) -> dict[str, Any]:
    return {
        "max_body_bytes": lim.max_body_bytes,
        "max_vertices": lim.max_vertices,
        "time_limit_s": lim.time_limit,
        "max_trials": lim.max_trials,
        "noisy_workers": lim.noisy_workers,
    }
