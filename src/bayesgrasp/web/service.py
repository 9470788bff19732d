"""The server's service: its limits, its gallery, its lanes of worker processes, the work.

A :class:`Service` reads the parts of requests (in memory, within the limits) and runs the
work of a request (:data:`WORK`, by name) in a worker of the request's lane
(:func:`lane_of`): a quick lane (squeeze and push functions, exact plans and their robot
files), a lane for figures and a heavy lane (policies, noise-aware plans, simulations).
"""

from __future__ import annotations

import base64
import binascii
import json
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Literal

from fastapi.responses import Response

from ..errors import BayesGraspError
from . import documents, views
from .limits import Limits
from .models import MESH_FORMATS, PartIn
from .workers import Lane, LimitError

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..solid.mesh import Solid
    from ..solid.poses import PoseStudy
    from .gallery import Gallery

__all__ = ["WORK", "LaneName", "Service", "lane_of", "run_work", "service_of", "work_json"]

LaneName = Literal["quick", "figures", "heavy"]


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
        return await lane.run(run_work, (name, self.limits, req, *extra), self.timeout(timeout))

    async def answer(self, name: str, req: Any, timeout: float | None = None) -> Response:
        """The JSON answer of the work ``name`` on ``req``.

        Nothing is recorded: the gallery keeps only the views a user saves.
        """
        lane = self.lane(lane_of(name, req))
        body = await lane.run(work_json, (name, self.limits, req), self.timeout(timeout))
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
            from ..runs.specs import PartSpec

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
        data = self.file_bytes(spec)
        element = f.element
        if f.format in MESH_FORMATS:  # a solid: the footprint of one resting pose
            if f.pose is not None and f.element is not None:
                raise LimitError(422, "give the pose once: `pose` (not `element`)")
            element = f.element if f.pose is None else str(f.pose)
        elif f.pose is not None:
            raise LimitError(
                422, f"`pose`: for a mesh part ({', '.join(MESH_FORMATS)}); this one is {f.format}"
            )
        return self.read_file(data, f.format, spec.name, element, f.layer, f.flatten_tol)

    def file_bytes(self, spec: PartIn) -> bytes:
        """The bytes of a part given as ``file`` (base64-decoded)."""
        if spec.file is None:
            raise LimitError(422, "`part` needs a `file` here")
        try:
            return base64.b64decode(spec.file.data_base64, validate=True)
        except (binascii.Error, ValueError):
            raise LimitError(422, "`part.file.data_base64` is not valid base64") from None

    def solid(self, spec: PartIn, what: str = "this") -> tuple[Solid, PoseStudy]:
        """The solid of a mesh part and its quasi-static resting poses.

        The same reading as the command line's (:meth:`~bayesgrasp.runs.specs.PartSpec.load_solid`
        and :func:`~bayesgrasp.solid.parts.study_of`), from the file's bytes in memory.
        """
        from ..solid.mesh import read_mesh_bytes
        from ..solid.parts import study_of

        f = spec.file
        if f is None or f.format not in MESH_FORMATS:
            raise LimitError(
                422, f"{what} needs a mesh part: a `file` of format {', '.join(MESH_FORMATS)}"
            )
        if f.layer is not None or f.flatten_tol is not None:
            raise LimitError(422, "a mesh has no layers or curves: drop `layer`, `flatten_tol`")
        solid = read_mesh_bytes(self.file_bytes(spec), f.format, f"{spec.name}.{f.format}")
        return solid, study_of(solid)

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


#: The work a worker may be asked for, by name: ``f(service, request, *extra)``.
WORK: dict[str, Callable[..., Any]] = {
    "squeeze": documents.squeeze_document,
    "push": documents.push_document,
    "plan": documents.plan_result_document,
    "policy": documents.policy_document_of,
    "simulate": documents.simulate_document,
    "figure": documents.figure_bytes,
    "export": documents.export_file,
    "functions": lambda service, req: views.function_samples(service, req),
    "poses": documents.poses_document_of,
}


def run_work(name: str, limits: Limits, req: Any, *extra: Any, **kwargs: Any) -> Any:
    """Run ``WORK[name]`` in a worker process (with a service of its own, no gallery).

    A request's mesh options are checked first (:func:`~.documents.check_mesh_options`).
    """
    service = Service(limits, None)
    documents.check_mesh_options(service, req)
    return WORK[name](service, req, *extra, **kwargs)


def work_json(name: str, limits: Limits, req: Any) -> bytes:
    """``WORK[name]``'s document as JSON bytes.

    The document is encoded in the worker, as the server's JSON answers are encoded, so that
    the server's event loop only passes the bytes on.
    """
    doc = run_work(name, limits, req)
    body = json.dumps(doc, ensure_ascii=False, allow_nan=False, separators=(",", ":")).encode()
    return body


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


def service_of(request: Any) -> Service:
    """The :class:`Service` of the application serving ``request``."""
    service: Service = request.app.state.service
    return service
