"""The FastAPI application of ``bayesgrasp serve``: the JSON API, the page, the gallery.

Every API answer is the document the command line prints with ``--json``, built by the same
library calls (:class:`~bayesgrasp.cli.specs.ProblemSpec`,
:func:`bayesgrasp.io.plans.plan_document`, :mod:`bayesgrasp.report`). Every error is a JSON
body ``{detail, error, status}`` (:class:`~bayesgrasp.web.models.ErrorBody`): bad input is a
422 whose ``detail`` is the command line's one-line message; a body over
:attr:`Limits.max_body_bytes` is a 413 and a part over :attr:`Limits.max_vertices` vertices
a 422, each naming the limit.

The work runs in worker processes (:mod:`bayesgrasp.web.workers`), never on the server's
event loop: a quick lane (squeeze and push functions, plans), a lane for figures and a
heavy lane (policies, noise-aware plans, simulations and simulation jobs), each with a
bounded queue.
Work past its time limit (:attr:`Limits.time_limit`, or less if the request asks) is stopped
and its worker replaced; a full queue, a time limit or a worker's memory cap is a 503 that
says which, with a ``Retry-After`` header.
"""

from __future__ import annotations

import asyncio
import base64
import binascii
import functools
import io
import json
import math
import threading
from collections.abc import AsyncIterator, Callable
from contextlib import asynccontextmanager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

try:
    from fastapi import FastAPI, File, Form, Query, Request, UploadFile
    from fastapi.exceptions import RequestValidationError
    from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
    from fastapi.responses import (
        FileResponse,
        HTMLResponse,
        JSONResponse,
        RedirectResponse,
        Response,
    )
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
    ERRORS,
    ErrorBody,
    ExportRequest,
    FigureRequest,
    PartIn,
    PartRequest,
    PlanRequest,
    PolicyRequest,
    ProblemOptions,
    SimulateJobRequest,
    SimulateRequest,
    StrokeOptions,
)
from .workers import Lane, LimitError, failure_of

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..io.export import Stroke
    from ..model.problem import Problem
    from ..planning.result import PlanOption
    from ..planning.strategy import StrategyResult

__all__ = ["API", "Limits", "create_app"]

API = "/api/v1"
FigureName = Literal["part", "diameter", "transfer", "plan"]
FigureFormat = Literal["png", "svg"]
LaneName = Literal["quick", "figures", "heavy"]


@dataclass(frozen=True, slots=True)
class Limits:
    """What one request may ask of the server, and the server's workers.

    Attributes
    ----------
    max_body_bytes : int
        Largest request body (larger: 413).
    max_vertices : int
        Most vertices (or outline points) of a part (more: 422).
    time_limit : float
        Seconds a request's work may take, waiting in the queue included (then its worker
        is killed and the answer is a 503). A request may ask for less (``?timeout=S``).
    max_trials : int
        Most kinematic simulation trials a request may ask for (more: 422).
    workers : int
        Worker processes of the heavy lane: policies, noise-aware plans, simulations and
        simulation jobs.
    quick_workers : int
        Worker processes of the quick lane: squeeze and push functions, plans.
    figure_workers : int
        Worker processes drawing figures (about a second each; apart, so that the quick
        lane stays quick).
    queue : int
        Requests that may wait for a worker, in each lane (more: 503 at once).
    worker_memory : int or None
        Memory a worker may take beyond its libraries, MB (``RLIMIT_AS``; more: 503 and the
        worker is replaced). ``None``: no cap.
    gallery_rows : int
        Rows the gallery keeps.
    job_time_limit : float
        Seconds a simulation job may take (then it is stopped and marked failed).
    max_jobs : int
        Simulation jobs kept (queued, running or finished; the oldest finished go first).
    max_mujoco_trials : int
        Most MuJoCo trials a job may ask for (more: 422).
    """

    max_body_bytes: int = 1_000_000
    max_vertices: int = 2000
    time_limit: float = 10.0
    max_trials: int = 1_000_000
    workers: int = 2
    quick_workers: int = 2
    figure_workers: int = 1
    queue: int = 16
    worker_memory: int | None = 2048
    gallery_rows: int = 500
    job_time_limit: float = 600.0
    max_jobs: int = 100
    max_mujoco_trials: int = 2000

    def __post_init__(self) -> None:
        counts = {
            "workers": self.workers,
            "quick_workers": self.quick_workers,
            "figure_workers": self.figure_workers,
            "max_jobs": self.max_jobs,
        }
        for name, value in counts.items():
            if value < 1:
                raise ValueError(f"Limits.{name} must be at least 1; got {value}")
        if self.queue < 0:
            raise ValueError(f"Limits.queue must be at least 0; got {self.queue}")
        if not (self.time_limit > 0 and self.job_time_limit > 0):
            raise ValueError("Limits.time_limit and Limits.job_time_limit must be positive")
        if self.worker_memory is not None and self.worker_memory < 1:
            raise ValueError(
                f"Limits.worker_memory must be at least 1 MB or None; got {self.worker_memory}"
            )


def _error(status: int, detail: str, kind: str, retry_after: int | None = None) -> JSONResponse:
    headers = {"Retry-After": str(retry_after)} if retry_after is not None else None
    return JSONResponse(
        {"detail": detail, "error": kind, "status": status}, status_code=status, headers=headers
    )


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
    """What the endpoints share: limits, the gallery, the lanes of worker processes.

    The lanes (:class:`~bayesgrasp.web.workers.Lane`) start when first used; a worker builds
    its own ``Service(limits, None)`` to read parts.
    """

    def __init__(self, limits: Limits, gallery: Gallery | None) -> None:
        self.limits = limits
        self.gallery = gallery
        self.figure_lock = threading.Lock()
        self._lanes: dict[str, Lane] = {}

    def lane(self, name: LaneName) -> Lane:
        """The lane ``name`` (``quick``, ``figures`` or ``heavy``), started on first use."""
        if name not in self._lanes:
            lim = self.limits
            size = {"quick": lim.quick_workers, "figures": lim.figure_workers}.get(
                name, lim.workers
            )
            # the other lanes' workers are niced: the quick lane keeps the processor
            nice = {"quick": 0, "figures": 5}.get(name, 19)
            self._lanes[name] = Lane(name, size, lim.queue, lim.worker_memory, nice)
        return self._lanes[name]

    def timeout(self, asked: float | None) -> float:
        """The time limit of a request that asks for ``asked`` seconds (at most the server's)."""
        if asked is None:
            return self.limits.time_limit
        if asked > self.limits.time_limit:
            raise LimitError(
                422,
                f"`timeout` is {asked:g} s; the server's time limit is "
                f"{self.limits.time_limit:g} s",
            )
        return asked

    async def run(self, name: str, req: Any, *extra: Any, timeout: float | None = None) -> Any:
        """The work ``name`` (a key of :data:`WORK`) on ``req`` in a worker of its lane."""
        lane = self.lane(lane_of(name, req))
        return await lane.run(_work, (name, self.limits, req, *extra), self.timeout(timeout))

    async def answer(self, name: str, req: Any, timeout: float | None = None) -> Response:
        """The JSON answer of the work ``name`` on ``req`` (a plan is added to the gallery)."""
        lane = self.lane(lane_of(name, req))
        args = (name, self.limits, req)
        body, entry = await lane.run(_work_json, args, self.timeout(timeout))
        if entry is not None and self.gallery is not None:
            await asyncio.to_thread(self.gallery.add, *entry)  # off the event loop
        return Response(body, media_type="application/json")

    def lanes_status(self) -> dict[str, Any]:
        """Each started lane's workers and queue."""
        return {name: lane.status() for name, lane in self._lanes.items()}

    def close(self) -> None:
        """Stop the workers."""
        for lane in self._lanes.values():
            lane.close()
        self._lanes.clear()

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


def chosen_option(
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
    """``bayesgrasp plan PART [options] [--guaranteed] [--max-opening W ...] --json``."""
    from ..cli.specs import run_inputs
    from ..cli.strategies import document

    spec = problem_spec(req)
    result = plan_strategy(service, req, spec)
    doc = document(result, run_inputs(None, spec))
    if service.gallery is not None:
        remember_plan(service.gallery, req, doc)
    return doc


def stroke_of(req: StrokeOptions) -> Stroke | None:
    """The gripper's stroke of ``max_opening`` and ``min_opening`` (``None``: neither given)."""
    if req.max_opening is None and req.min_opening is None:
        return None
    from ..io.export import Stroke

    hi = math.inf if req.max_opening is None else req.max_opening
    return Stroke(req.min_opening or 0.0, hi)


def check_within_stroke(req: StrokeOptions, stroke: Stroke | None, policy: bool) -> None:
    """Refuse ``within_stroke`` where it cannot plan (the command line's reasons)."""
    if not req.within_stroke:
        return
    why = None
    if stroke is None:
        why = "needs the stroke: `max_opening` and/or `min_opening`"
    elif policy:
        why = "plans linear plans; a policy is checked against the stroke (drop `within_stroke`)"
    elif req.noisy:
        why = (
            "searches noise-free plans; a noise-aware plan is checked against the stroke "
            "(drop `within_stroke`)"
        )
    elif req.method != "exact":
        why = "is its own planner; drop `method`"
    elif req.accuracy:
        why = "takes exact turns; drop `accuracy`"
    if why is not None:
        raise LimitError(422, f"`within_stroke`: {why}")


def plan_strategy(service: Service, req: PlanRequest, spec: Any) -> StrategyResult:
    """The plans of ``plan`` (:func:`bayesgrasp.planning.solve`, as the command line plans).

    The noise-aware plans with the noise or payoff options; with ``within_stroke`` only plans
    the stroke allows; with ``max_opening`` or ``min_opening`` a Bayes plan outside the stroke
    is refused (:func:`~bayesgrasp.cli.strategies.check_stroke`).
    """
    from ..cli.strategies import check_stroke
    from ..planning.strategy import solve

    stroke = stroke_of(req)
    check_within_stroke(req, stroke, policy=False)
    pb = build_problem(service.part(req.part), req, spec)
    if req.noisy:
        from ..planning.robust import UNBOUNDED_GUARANTEE

        _exact_method(req)
        noise = req.noise_model()
        if req.guaranteed and not noise.turn.exact and noise.turn.kind == "normal":
            raise LimitError(422, f"`guaranteed`: {UNBOUNDED_GUARANTEE}")
        result = solve(
            pb,
            noise=noise,
            payoff=req.payoff_model(),
            max_actions=spec.max_actions,
            guaranteed=req.guaranteed,
        )
    else:
        within = None if stroke is None or not req.within_stroke else stroke
        result = solve(
            pb,
            method=spec.method.value,
            max_actions=spec.max_actions,
            guaranteed=req.guaranteed,
            stroke=None if within is None else (within.min_opening, within.max_opening),
        )
    check_stroke(result, stroke)
    return result


def remember_plan(gallery: Gallery, req: PlanRequest, doc: dict[str, Any]) -> None:
    """Add a planned part to the gallery (its name, outline, options and Bayes plan)."""
    gallery.add(*gallery_entry(req, doc))


def gallery_entry(req: PlanRequest, doc: dict[str, Any]) -> tuple[Any, ...]:
    """The arguments of :meth:`Gallery.add` for a plan: name, outline, options, Bayes plan."""
    options = req.model_dump(exclude={"part"}, exclude_defaults=True)
    bayes = doc["options"][doc["bayes"]] if doc.get("options") else {}
    return doc["part"]["name"], doc["part"]["vertices"], options, bayes


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
    from ..cli.strategies import document

    return document(policy_strategy(service, req))


def policy_strategy(service: Service, req: PolicyRequest) -> StrategyResult:
    """The Bayes policy of ``policy`` as a strategy; refused if outside the stroke given."""
    from ..cli.strategies import check_stroke
    from ..planning.noisy_policy import plan_noisy_policy
    from ..planning.policy import Policy, plan_policy
    from ..planning.strategy import StrategyResult

    stroke = stroke_of(req)
    check_within_stroke(req, stroke, policy=True)
    spec = problem_spec(req)
    parts = [service.part(p) for p in (req.part, *req.also)]
    problems = [build_problem(p, req, spec) for p in parts]
    prior = None if req.part_prior is None else ",".join(map(repr, req.part_prior))
    pol: Policy
    if not req.noisy:
        pol = plan_policy(problems, sensor=req.sense, max_actions=req.max_actions, part_prior=prior)
    else:
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
    result = StrategyResult(tuple(problems), pol)
    check_stroke(result, stroke)
    return result


def export_file(service: Service, req: ExportRequest) -> tuple[str, bytes]:
    """``bayesgrasp plan PART [options] --export FILE.csv|json``: the file's name and bytes.

    The Bayes plan (or with ``sense`` the policy's state machine) for a robot, written by the
    command line's own writer (:func:`bayesgrasp.io.export.write_robot`, with the noise and
    payoff of :func:`bayesgrasp.cli.strategies.robot_metadata`); the name is
    ``PART-plan.FORMAT`` or ``PART-policy.FORMAT``.
    """
    import tempfile

    from ..cli.strategies import robot_metadata
    from ..io.export import write_robot

    result = export_strategy(service, req)
    problems: Any = result.problem if result.kind == "plan" else list(result.problems)
    name = f"{result.problem.part.name}-{result.kind}.{req.format}"
    with tempfile.TemporaryDirectory(prefix="bayesgrasp-export-") as tmp:
        path = write_robot(
            Path(tmp) / f"robot.{req.format}",
            problems,
            result.robot_strategy,
            robot_metadata(result),
        )
        return name, path.read_bytes()


def export_strategy(service: Service, req: ExportRequest) -> StrategyResult:
    """The strategy an export writes: the plans of ``plan``, or with ``sense`` the policy."""
    if req.sense is None:
        if req.also or req.part_prior is not None:
            raise LimitError(422, "`also` and `part_prior` need `sense`")
        return plan_strategy(service, req, problem_spec(req))
    if req.guaranteed:
        raise LimitError(422, "`sense` plans a policy; it takes no `guaranteed`")
    if req.method != "exact":
        raise LimitError(422, "`sense` plans a policy; it takes no `method`")
    body = req.model_dump(exclude={"format", "guaranteed"}, exclude_none=True)
    body.setdefault("max_actions", 3)
    try:
        policy = PolicyRequest.model_validate(body)
    except ValidationError as exc:
        raise LimitError(422, _one_line(exc)) from None
    return policy_strategy(service, policy)


def simulate_document(
    service: Service,
    req: SimulateRequest,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """``bayesgrasp simulate PART [options] --engine ENGINE --json``.

    A :class:`~bayesgrasp.web.models.SimulateJobRequest` may ask for ``engine`` ``mujoco``
    (and an ``offset_mm``); ``progress(done, total)`` is called as trials end.
    """
    from .. import report
    from ..model.noise import NoiseModel, TurnNoise
    from ..model.payoff import as_vector

    engine = getattr(req, "engine", "kinematic")
    offset_mm = float(getattr(req, "offset_mm", 0.0))
    trials = req.trials if req.trials is not None else (200 if engine == "mujoco" else 100_000)
    most = service.limits.max_mujoco_trials if engine == "mujoco" else service.limits.max_trials
    if trials > most:
        raise LimitError(422, f"`trials` is {trials}; the limit is {most}")
    spec = problem_spec(req)
    p = service.part(req.part)
    if req.turn_noise is not None and (req.noise > 0 or req.noise_kind != "normal"):
        raise LimitError(
            422, "`noise`, `noise_kind`: the older spelling of `turn_noise`; give one of them"
        )
    if engine == "mujoco" and req.contact_noise is not None:
        raise LimitError(
            422,
            "`contact_noise`: applies to the kinematic engine only (in MuJoCo the jaws' "
            "contacts are the physics' own)",
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
        pb, option, _ = chosen_option(req.plan, req, p, spec)
    u = None if pay is None else as_vector(pay, pb.states)
    if engine == "mujoco":
        res = _mujoco(pb, option, trials, noise, req.seed, offset_mm, u, progress)
    else:
        from ..sim.kinematic import simulate_kinematic

        res = simulate_kinematic(
            pb, option, trials, noise, rng=req.seed, payoff=u, progress=progress
        )
    from ..cli.common import simulate_inputs
    from ..cli.specs import run_inputs
    from ..io.plans import provenance

    doc = report.simulate_json(res, p)  # with the provenance the command line writes
    how = simulate_inputs(engine, req.plan, req.seed, trials, deg, kind, offset_mm)
    how["contact_noise"] = req.contact_noise
    how["payoff"] = None if req.payoff is None else "request"
    doc["provenance"] = provenance(pb, None, **how, **run_inputs(None, spec))
    return doc


def _mujoco(
    pb: Problem,
    option: PlanOption,
    trials: int,
    noise: Any,
    seed: int,
    offset_mm: float,
    payoff: Any,
    progress: Callable[[int, int], None] | None,
) -> Any:
    """The MuJoCo trials of ``simulate --engine mujoco`` (one process: the job's worker)."""
    from ..sim import simulate_mujoco
    from ..sim.noise import GripperNoise
    from ..sim.result import with_prediction

    if offset_mm > 0 and offset_mm / 1000.0 >= pb.part.hull.size:
        raise LimitError(
            422,
            f"`offset_mm`: {offset_mm:g} mm is not less than the part's size "
            f"({pb.part.hull.size * 1000:.4g} mm from its centroid to its farthest vertex)",
        )
    res = simulate_mujoco(
        pb,
        option,
        trials,
        offset=offset_mm / 1000.0,
        noise=GripperNoise.of(noise.turn),
        rng=seed,
        workers=1,
        progress=progress,
    )
    exact = noise.exact and payoff is None
    return res if exact else with_prediction(res, pb, noise, payoff)


def figure_bytes(service: Service, req: FigureRequest, name: str, fmt: str) -> bytes:
    """One of the figures ``bayesgrasp plot`` writes (``NAME.FMT``), as bytes."""
    from ..figures.plots import diameter_figure, evolution_figure, part_figure, transfer_figure
    from ..model.actions import PUSH_GRASP

    spec = problem_spec(req)
    p = service.part(req.part)
    pb, option, label = chosen_option(req.plan, req, p, spec)
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


# -- the work the workers do ------------------------------------------------------------------

#: The work a worker may be asked for, by name: ``f(service, request, *extra)``.
WORK: dict[str, Callable[..., Any]] = {
    "squeeze": squeeze_document,
    "push": push_document,
    "plan": plan_result_document,
    "policy": policy_document_of,
    "simulate": simulate_document,
    "figure": figure_bytes,
    "export": export_file,
    "functions": lambda service, req: views.function_samples(service, req),
}


def _work(name: str, limits: Limits, req: Any, *extra: Any, **kwargs: Any) -> Any:
    """Run ``WORK[name]`` in a worker process (with a service of its own, no gallery)."""
    return WORK[name](Service(limits, None), req, *extra, **kwargs)


def _work_json(name: str, limits: Limits, req: Any) -> tuple[bytes, tuple[Any, ...] | None]:
    """``WORK[name]``'s document as JSON bytes, and for a plan its gallery entry.

    The document is encoded in the worker, as the server's JSON answers are encoded, so that
    the server's event loop only passes the bytes on.
    """
    doc = _work(name, limits, req)
    body = json.dumps(doc, ensure_ascii=False, allow_nan=False, separators=(",", ":")).encode()
    return body, (gallery_entry(req, doc) if name == "plan" else None)


def lane_of(name: str, req: Any) -> LaneName:
    """The lane of the work ``name`` on ``req``.

    ``heavy``: policies, simulations, noise-aware plans and the ``bfs`` method; ``figures``:
    figures (about a second of drawing each); ``quick``: the rest.
    """
    if name in ("policy", "simulate") or getattr(req, "sense", None) is not None:
        return "heavy"
    if bool(getattr(req, "noisy", False)) or getattr(req, "method", "exact") != "exact":
        return "heavy"
    return "figures" if name == "figure" else "quick"


TIMEOUT = Query(
    None,
    ge=0.01,
    le=86_400,
    description="Seconds this request's work may take (at most the server's time limit, "
    "the default).",
)


# -- the application --------------------------------------------------------------------------


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
        return _error(status, reason, kind)

    @app.exception_handler(LimitError)
    async def _limit(request: Request, exc: LimitError) -> JSONResponse:
        return _error(exc.status, str(exc), exc.kind, exc.retry_after)

    @app.exception_handler(StarletteHTTPException)
    async def _http(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        return _error(exc.status_code, str(exc.detail), "http")

    @app.exception_handler(RequestValidationError)
    async def _invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        return _error(422, _one_line(exc), "invalid-request")

    @app.exception_handler(Exception)
    async def _internal(request: Request, exc: Exception) -> JSONResponse:
        status, kind, reason = failure_of(exc)
        return _error(status, reason, kind)

    async def answer(name: str, req: Any, timeout: float | None) -> Response:
        return await service.answer(name, req, timeout)

    @app.get(f"{API}/health", tags=["server"])
    async def health() -> dict[str, Any]:
        """The server is up; its version, limits and worker lanes."""
        return {
            "status": "ok",
            "version": __version__,
            "limits": _limits(lim),
            "lanes": service.lanes_status(),
        }

    @app.get(f"{API}/limits", tags=["server"])
    async def limits_() -> dict[str, Any]:
        """The limits a request must keep to."""
        return _limits(lim)

    @app.get(f"{API}/catalogue", tags=["parts"])
    async def catalogue() -> JSONResponse:
        """The catalogue parts (:func:`bayesgrasp.shapes.names`)."""
        return JSONResponse(await asyncio.to_thread(_catalogue))

    @app.post(f"{API}/squeeze", tags=["parts"], responses=ERRORS)
    async def squeeze(req: PartRequest, timeout: float | None = TIMEOUT) -> Response:
        """Stable orientations of a squeeze (``bayesgrasp squeeze --json``)."""
        return await answer("squeeze", req, timeout)

    @app.post(f"{API}/push", tags=["parts"], responses=ERRORS)
    async def push(req: PartRequest, timeout: float | None = TIMEOUT) -> Response:
        """Stable orientations of a push and a push-grasp (``bayesgrasp push --json``)."""
        return await answer("push", req, timeout)

    @app.post(f"{API}/plan", tags=["plans"], responses=ERRORS)
    async def plan(req: PlanRequest, timeout: float | None = TIMEOUT) -> Response:
        """The best plan of every length, Bayes and most certain (``bayesgrasp plan --json``).

        With ``turn_noise``, ``contact_noise`` or ``payoff``: the noise-aware Bayes plan
        (``plan --turn-noise ... --json``), in the heavy lane.
        """
        return await answer("plan", req, timeout)

    @app.post(f"{API}/policy", tags=["plans"], responses=ERRORS)
    async def policy(req: PolicyRequest, timeout: float | None = TIMEOUT) -> Response:
        """The Bayes policy that branches on jaw widths (``plan --sense ... --json``)."""
        return await answer("policy", req, timeout)

    @app.post(
        f"{API}/export",
        tags=["plans"],
        response_class=Response,
        responses={
            200: {
                "content": {"text/csv": {}, "application/json": {}},
                "description": "The robot file, as an attachment named PART-plan.FORMAT "
                "(PART-policy.FORMAT with `sense`).",
            },
            **ERRORS,
        },
    )
    async def export(req: ExportRequest, timeout: float | None = TIMEOUT) -> Response:
        """The robot file of ``bayesgrasp plan ... --export FILE.csv|json``, byte for byte.

        The Bayes plan, one row a step (with the noise options: the noise-aware plan and its
        noise model); with ``sense``: the policy's state machine.
        """
        name, data = await service.run("export", req, timeout=timeout)
        media = "text/csv" if req.format == "csv" else "application/json"
        return Response(
            data,
            media_type=media,
            headers={"Content-Disposition": f'attachment; filename="{name}"'},
        )

    @app.post(f"{API}/simulate", tags=["plans"], responses=ERRORS)
    async def simulate(req: SimulateRequest, timeout: float | None = TIMEOUT) -> Response:
        """Kinematic executions of a plan (``bayesgrasp simulate --engine kinematic --json``)."""
        return await answer("simulate", req, timeout)

    @app.post(
        f"{API}/simulate/jobs",
        tags=["plans"],
        status_code=202,
        responses={
            202: {"description": "The job is queued: its id and where to read it."},
            **ERRORS,
        },
    )
    async def simulate_job(req: SimulateJobRequest) -> JSONResponse:
        """Start a simulation job (``simulate --engine mujoco|kinematic --json``); poll it."""
        lane = service.lane("heavy")
        if lane.full():
            raise LimitError(
                503,
                f"the queue is full ({lane.queue} requests waiting for the heavy lane); "
                "try again later",
                kind="queue-full",
                retry_after=max(1, math.ceil(min(lim.time_limit, 60))),
            )
        total = req.trials or (200 if req.engine == "mujoco" else 100_000)

        async def run(job: Any) -> dict[str, Any]:
            return await lane.run(  # type: ignore[no-any-return]
                _work,
                ("simulate", lim, req),
                lim.job_time_limit,
                progress=job.tick,
                on_start=job.start,
            )

        job = jobs.submit(total, run)
        doc = job.document()
        doc["url"] = f"{API}/simulate/jobs/{job.id}"
        return JSONResponse(doc, status_code=202, headers={"Location": doc["url"]})

    @app.get(
        f"{API}/simulate/jobs/{{job_id}}",
        tags=["plans"],
        responses={
            404: {"model": ErrorBody, "description": "No such job (or no longer kept)."},
            422: ERRORS[422],
        },
    )
    async def simulate_job_status(job_id: str) -> dict[str, Any]:
        """A simulation job: status, progress (trials done) and, when done, the document."""
        job = jobs.get(job_id)
        if job is None:
            raise LimitError(
                404,
                f"no job {job_id!r} (finished jobs are kept while there is room)",
                kind="not-found",
            )
        return job.document()

    @app.post(
        f"{API}/figures/{{name}}.{{fmt}}",
        tags=["plans"],
        response_class=Response,
        responses={200: {"content": {"image/png": {}, "image/svg+xml": {}}}, **ERRORS},
    )
    async def figures(
        name: FigureName, fmt: FigureFormat, req: FigureRequest, timeout: float | None = TIMEOUT
    ) -> Response:
        """A figure of ``bayesgrasp plot``: part, diameter, transfer or plan; PNG or SVG."""
        data = await service.run("figure", req, name, fmt, timeout=timeout)
        media = "image/png" if fmt == "png" else "image/svg+xml"
        return Response(data, media_type=media)

    @app.post(f"{API}/{{command}}/upload", tags=["parts"], responses=ERRORS)
    async def upload(
        command: Literal["squeeze", "push", "plan", "policy", "simulate"],
        file: UploadFile = File(description="A part file (read in memory)."),  # noqa: B008
        format: str = Form(description="json, csv, wkt, geojson, svg or dxf."),
        options: str = Form("{}", description="The other members of the command's body, JSON."),
        timeout: float | None = TIMEOUT,
    ) -> Response:
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
        try:
            req: Any = models[command].model_validate({**extra, "part": part})
        except ValidationError as exc:
            return _error(422, _one_line(exc), "invalid-request")
        return await answer(command, req, timeout)

    @app.get(f"{API}/gallery", tags=["server"], responses={422: {"model": ErrorBody}})
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

    @app.get("/docs", include_in_schema=False)
    async def swagger() -> HTMLResponse:
        return get_swagger_ui_html(
            openapi_url="/openapi.json",
            title="bayesgrasp API",
            swagger_js_url=f"{VENDOR}/swagger-ui-bundle.js",
            swagger_css_url=f"{VENDOR}/swagger-ui.css",
            swagger_favicon_url=f"{VENDOR}/favicon-32x32.png",
        )

    @app.get("/redoc", include_in_schema=False)
    async def redoc() -> HTMLResponse:
        return get_redoc_html(
            openapi_url="/openapi.json",
            title="bayesgrasp API",
            redoc_js_url=f"{VENDOR}/redoc.standalone.js",
            redoc_favicon_url=f"{VENDOR}/favicon-32x32.png",
            with_google_fonts=False,
        )

    app.mount("/static", StaticFiles(directory=str(static)), name="static")
    app.add_middleware(BodyLimit, max_bytes=lim.max_body_bytes)
    return app


VENDOR = "/static/vendor"


@functools.cache
def _catalogue() -> dict[str, Any]:
    return catalogue_document()


def _limits(lim: Limits) -> dict[str, Any]:
    return {
        "max_body_bytes": lim.max_body_bytes,
        "max_vertices": lim.max_vertices,
        "time_limit_s": lim.time_limit,
        "max_trials": lim.max_trials,
        "workers": lim.workers,
        "quick_workers": lim.quick_workers,
        "figure_workers": lim.figure_workers,
        "queue": lim.queue,
        "worker_memory_mb": lim.worker_memory,
        "job_time_limit_s": lim.job_time_limit,
        "max_jobs": lim.max_jobs,
        "max_mujoco_trials": lim.max_mujoco_trials,
    }
