"""The work of one part, as a worker runs it: read, plan, optionally simulate, one row.

Nothing here imports Dask: a task is a plain function of plain values (a
:class:`PartSource` holds a path, or a path and the file's bytes; :class:`SweepOptions`
holds the planning options), so it runs the same in a Dask worker, a process pool or a
test. A part that cannot be read or planned is a row with its error class and message,
never an exception: one bad file must not stop a sweep of a catalogue.

The row's ``plan_json`` is the document ``bayesgrasp plan PATH --json`` prints with the
same options (:meth:`SweepOptions.plan_args` gives those options as command-line
arguments), and its error message is the one the command prints after
``bayesgrasp: error:``.
"""

from __future__ import annotations

import hashlib
import json
import math
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, cast

from ..errors import BayesGraspError
from ..model.prior import Prior, parse_prior
from .options import DEFAULT_TRIALS, ENGINES, GOALS, METHODS, SweepError, SweepOptions
from .rows import MAX_OUTLINE_POINTS, ROW_COLUMNS, PartSource, empty_row, error_row, part_id

if TYPE_CHECKING:
    from ..model.noise import NoiseModel
    from ..model.payoff import Payoff

__all__ = [
    "DEFAULT_TRIALS",
    "ENGINES",
    "GOALS",
    "MAX_OUTLINE_POINTS",
    "METHODS",
    "ROW_COLUMNS",
    "ChunkResult",
    "PartSource",
    "SweepError",
    "SweepOptions",
    "empty_row",
    "error_row",
    "error_rows",
    "part_id",
    "plan_part",
    "plan_part_rows",
    "run_chunk",
    "timeout_row",
]


def _read_bytes_part(path: str, data: bytes, options: SweepOptions) -> Any:
    """Read a part from its bytes, with the messages reading ``path`` would give.

    The bytes are written under the file's own name in a private folder and read there, so
    the part's name and the reader are those of the file; messages naming the temporary
    path are given back with ``path`` in its place.
    """
    from ..io import read_part

    with tempfile.TemporaryDirectory(prefix="bayesgrasp-sweep-") as tmp:
        local = Path(tmp) / (Path(path).name or "part")
        local.write_bytes(data)
        try:
            return read_part(local, layer=options.layer, tolerance=options.flatten_tol)
        except BayesGraspError as exc:
            text = str(exc).replace(str(local), path)
            if text == str(exc):
                raise
            err = type(exc).__new__(type(exc))
            Exception.__init__(err, text)
            raise err from None


def _read_part(source: PartSource, options: SweepOptions) -> tuple[Any, str]:
    """The part and the hash of the bytes it was read from."""
    from ..geometry.curved import with_shape_tol
    from ..io import resolve_part

    if source.data is not None:
        part = _read_bytes_part(source.path, source.data, options)
        return with_shape_tol(part, options.shape_tol), hashlib.sha256(source.data).hexdigest()
    try:
        with open(source.path, "rb") as f:
            digest = hashlib.file_digest(f, "sha256").hexdigest()
    except OSError:
        digest = ""  # the reader says why, in the CLI's words
    part = resolve_part(source.path, layer=options.layer, tolerance=options.flatten_tol)
    return with_shape_tol(part, options.shape_tol), digest


def _outline(part: Any) -> str:
    pts = part.outline
    if len(pts) > MAX_OUTLINE_POINTS:
        pts = pts[:: math.ceil(len(pts) / MAX_OUTLINE_POINTS)]
    return json.dumps([[round(float(x), 9), round(float(y), 9)] for x, y in pts])


def _plan(
    part: Any,
    options: SweepOptions,
    prior: Prior,
    payoff: Payoff | None = None,
    element: str | None = None,
) -> tuple[Any, dict[str, Any], str]:
    """Problem, plan report and plan document, as ``bayesgrasp plan --json`` makes them.

    ``element``: a mesh's pose, as ``--pose K`` records it.
    """
    from ..io.plans import plan_document
    from ..model.cost import CostModel
    from ..model.goal import Goal
    from ..model.problem import Problem
    from ..planning import plan_exact

    first = {
        name: c
        for name, c in (
            ("squeeze", options.first_squeeze_cost),
            ("push-grasp", options.first_push_grasp_cost),
        )
        if c is not None
    }
    cost = CostModel(
        {"squeeze": options.squeeze_cost, "push-grasp": options.push_grasp_cost},
        verify=options.verify_cost,
        first=first,
        retry=options.retry_cost,
    )
    pb = Problem.build(
        part,
        prior,
        cost,
        Goal(cast(Literal["single", "symmetry"], options.goal)),
        actions=options.actions,
        accuracy=math.radians(options.accuracy_deg),
    )
    given: dict[str, Any] = {"max_actions": options.max_actions, "layer": options.layer}
    given["flatten_tolerance"] = options.flatten_tol  # what the CLI records
    if element is not None:
        given["element"] = element
    if options.noisy:
        return _plan_noisy(pb, options, payoff, given)
    if options.method == "bfs":
        from ..planning.bfs import plan_bfs

        rep = plan_bfs(pb, max_actions=options.max_actions)
    else:
        rep = plan_exact(pb, max_actions=options.max_actions)
    sure, missing = None, None
    if options.guaranteed:
        from ..planning.guaranteed import plan_guaranteed

        found = plan_guaranteed(pb)
        if found.status == "ok":
            sure = found
        else:
            missing = str(found.reason or "no guaranteed plan")
    doc = plan_document(rep, guaranteed=sure, guaranteed_missing=missing, inputs=given)
    return rep, doc, "ok" if missing is None else "no-plan"


def _noise(options: SweepOptions) -> NoiseModel:
    """The noise model of ``turn_noise`` and ``contact_noise`` (none when not given)."""
    from ..model.noise import NoiseModel

    return NoiseModel.of(options.turn_noise, options.contact_noise)


def _read_payoff(options: SweepOptions, payoff: Payoff | None) -> Payoff | None:
    """``options.payoff``, read here unless the client has read it."""
    if payoff is None and options.payoff is not None:
        from ..model.payoff import read_payoff

        return read_payoff(options.payoff)
    return payoff


def _plan_noisy(
    pb: Any, options: SweepOptions, payoff: Payoff | None, given: dict[str, Any]
) -> tuple[Any, dict[str, Any], str]:
    """The noise-aware Bayes plan and ``plan --turn-noise ... --json``'s document.

    With ``guaranteed``, also the plan guaranteed under the (bounded) noise, as ``plan
    --turn-noise uniform:A --guaranteed`` (status ``no-plan`` when there is none).
    """
    from ..runs.noisy import NoisyRun

    run = NoisyRun(_noise(options), payoff, options.max_actions, False, options.guaranteed)
    done = run.plan(pb)
    return done[0], run.document(done, given), "no-plan" if isinstance(done[1], str) else "ok"


def _simulate(rep: Any, options: SweepOptions, element: str | None = None) -> dict[str, Any]:
    """The ``bayesgrasp.simulate/1`` document of the Bayes plan's execution.

    Under noise or a payoff ``rep`` is the noise-aware result: its Bayes plan runs under the
    noise and is predicted exactly under it (and judged by the payoff), as ``bayesgrasp
    simulate PATH --turn-noise ... --json`` does.
    """
    from .. import report
    from ..sim.kinematic import GripperNoise, simulate_kinematic

    pb, option = rep.problem, rep.bayes_plan
    noise: Any = GripperNoise(options.noise_kind, math.radians(options.noise_deg))  # type: ignore[arg-type]
    deg, kind, u, model = options.noise_deg, options.noise_kind, None, None
    if options.noisy:
        model, u, option = _noise(options), rep.payoff, rep.bayes_plan.option
        noise = GripperNoise.of(model.turn)
        kind = model.turn.kind
        deg = 0.0 if options.turn_noise is None else float(options.turn_noise.partition(":")[2])
    if options.simulate == "kinematic":
        res = simulate_kinematic(
            pb, option, options.n_trials, noise if model is None else model, rng=options.seed,
            payoff=u,
        )  # fmt: skip
    else:
        from ..sim import simulate_mujoco

        res = simulate_mujoco(
            pb,
            option,
            options.n_trials,
            offset=options.offset_mm / 1000.0,  # millimetres to metres
            noise=noise,
            rng=options.seed,
            workers=1,
        )
        if model is not None and (not model.exact or u is not None):
            from ..sim.result import with_prediction

            res = with_prediction(res, pb, model, u)  # MuJoCo drew the turn error
    from ..io.plans import provenance
    from ..runs.specs import simulate_inputs

    doc = report.simulate_json(res, pb.part)  # with the provenance `bayesgrasp simulate` writes
    how = simulate_inputs(
        str(options.simulate), "bayes", options.seed, options.n_trials, deg, kind,
        options.offset_mm, None, 1 if options.simulate == "mujoco" else None,
    )  # fmt: skip
    if options.noisy:
        how |= {"contact_noise": options.contact_noise, "payoff": options.payoff}
    given = {"max_actions": options.max_actions, "layer": options.layer}
    if element is not None:
        given["element"] = element
    doc["provenance"] = provenance(pb, None, **how, **given, flatten_tolerance=options.flatten_tol)
    return doc


def _policy(
    row: dict[str, Any], problem: Any, options: SweepOptions, payoff: Payoff | None = None
) -> None:
    """The ``policy_*`` columns: the part's Bayes sensing policy (``plan --sense --json``).

    Under noise or a payoff the policy is planned under the noisy actions (and judged by
    the payoff), as ``plan PATH --sense S --turn-noise ... --json``.
    """
    from ..io.policies import policy_document

    if options.noisy:
        from ..planning.noisy_policy import plan_noisy_policy

        noisy = options.turn_noise is not None or options.contact_noise is not None
        pol = plan_noisy_policy(
            [problem],
            str(options.sense),
            options.sense_max_actions,
            _noise(options) if noisy else None,
            payoff=payoff,
            part_prior=None,
        )
    else:
        from ..planning.policy import plan_policy

        pol = plan_policy(problem, sensor=str(options.sense), max_actions=options.sense_max_actions)
    doc = policy_document(pol)
    row.update(
        policy_cost=doc["expected_cost"],
        policy_success=doc["success_probability"],
        policy_actions=doc["expected_actions"],
        policy_json=json.dumps(doc, allow_nan=False, separators=(",", ":")),
    )


def _fill(row: dict[str, Any], part: Any, doc: dict[str, Any]) -> None:
    """The row's plan columns, all taken from the plan document."""
    info = doc["part"]
    bayes = doc["options"][doc["bayes"]]
    sure = doc["options"][doc["most_certain"]]
    row.update(
        name=info["name"],
        units=info.get("units"),
        sides=info["n_sides"],
        symmetry_order=info["symmetry_order"],
        states=len(doc["stable_orientations_rad"]),
        period_rad=doc["period_rad"],
        method=doc["method"],
        plans=len(doc["options"]),
        bayes_actions=bayes["squeezes"],
        bayes_cost=bayes["expected_cost"],
        bayes_probability=bayes["success_probability"],
        bayes_tolerance_rad=bayes["tolerance_rad"],
        bayes_first_rad=bayes["first_squeeze_rad"],
        bayes_final_rad=bayes["final_orientation_rad"],
        bayes_steps=json.dumps(bayes["steps"], separators=(",", ":")),
        most_certain_actions=sure["squeezes"],
        most_certain_probability=sure["success_probability"],
        guaranteed_missing=doc.get("guaranteed_missing"),
        outline=_outline(part),
        plan_json=json.dumps(doc, allow_nan=False, separators=(",", ":")),
    )
    if doc.get("guaranteed"):
        row["guaranteed_actions"] = doc["guaranteed"]["squeezes"]
    if "expected_payoff" in doc:
        row["bayes_payoff"] = doc["expected_payoff"]


def plan_part(
    source: PartSource | str,
    options: SweepOptions,
    prior: Prior | None = None,
    payoff: Payoff | None = None,
) -> dict[str, Any]:
    """Read, plan and optionally simulate one part: one row, never an exception.

    A mesh gives its most probable pose's row (:func:`plan_part_rows` gives them all).

    Parameters
    ----------
    source : PartSource or str
        The part file (a path, or a path and its bytes).
    options : SweepOptions
    prior : Prior, optional
        ``options.prior`` already parsed (the engine parses it once, on the client, so
        that a prior file need not exist on the workers).
    payoff : Payoff, optional
        ``options.payoff`` already read (the same way).

    Returns
    -------
    dict
        One value per column of :data:`ROW_COLUMNS`.

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "plate.wkt"
    >>> _ = f.write_text("POLYGON ((0 0, 4 0, 4 1, 1 1, 1 3, 0 3, 0 0))")
    >>> row = plan_part(str(f), SweepOptions())
    >>> row["status"], row["sides"], row["bayes_actions"]
    ('ok', 5, 3)
    >>> plan_part(str(f.with_name("missing.wkt")), SweepOptions())["error_class"]
    'PartFileError'
    """
    if isinstance(source, str):
        source = PartSource(source)
    return plan_part_rows(source, options, prior, payoff)[0]


def plan_part_rows(
    source: PartSource | str,
    options: SweepOptions,
    prior: Prior | None = None,
    payoff: Payoff | None = None,
) -> list[dict[str, Any]]:
    """The rows of one part file: one for a planar part, one per resting pose of a mesh.

    A mesh's rows are its poses' footprints, most probable first, as ``plan MESH --pose K
    --json`` plans them (the quasi-static poses of :func:`bayesgrasp.solid.parts.study_of`):
    ``part_id`` ends in ``#pose-K``, ``pose`` is K and ``pose_probability`` its
    probability. A mesh that cannot be read is one error row. ``simulate="mujoco"`` is
    refused for a mesh's rows (an error in each): the physics would squeeze the footprint
    extruded to a prism, not the solid, which may topple or rest otherwise.

    Examples
    --------
    >>> import tempfile, trimesh
    >>> f = Path(tempfile.mkdtemp()) / "brick.stl"
    >>> _ = trimesh.creation.box(extents=(1, 2, 4)).export(f)
    >>> rows = plan_part_rows(str(f), SweepOptions())
    >>> [(r["part_id"][-7:], r["pose"], round(r["pose_probability"], 4)) for r in rows][:3]
    [('#pose-0', 0, 0.3344), ('#pose-1', 1, 0.3344), ('#pose-2', 2, 0.131)]
    """
    if isinstance(source, str):
        source = PartSource(source)
    t0 = time.perf_counter()
    try:
        poses = _mesh_poses(source, options)
    except Exception as exc:  # an unreadable mesh is one error row
        row = empty_row(source.path, source.sha256, options)
        row["plan_seconds"] = time.perf_counter() - t0
        return [error_row(row, exc)]
    if poses is None:
        row = empty_row(source.path, source.sha256, options)
        try:
            part, digest = _read_part(source, options)
        except Exception as exc:  # a bad part is a row; a bug in it too, with its class
            row["plan_seconds"] = time.perf_counter() - t0
            return [error_row(row, exc)]
        if digest:
            row.update(sha256=digest, part_id=part_id(source.path, digest))
        return [_plan_row(row, part, options, prior, payoff, t0)]
    parts, probs, digest = poses
    rows = []
    for k, (part, prob) in enumerate(zip(parts, probs, strict=True)):
        t0 = time.perf_counter() if k else t0
        row = empty_row(source.path, digest, options)
        row.update(part_id=f"{part_id(source.path, digest)}#pose-{k}", pose=k)
        row["pose_probability"] = prob
        if options.simulate == "mujoco":
            row["plan_seconds"] = time.perf_counter() - t0
            rows.append(error_row(row, SweepError(MESH_MUJOCO)))
            continue
        rows.append(_plan_row(row, part, options, prior, payoff, t0, str(k)))
    return rows


#: Why a sweep does not simulate a mesh's poses in MuJoCo.
MESH_MUJOCO = (
    "simulate mujoco: a mesh's pose is planned as its footprint, and MuJoCo would squeeze "
    "that footprint extruded to a prism, not the solid (which may topple); use kinematic"
)


def _mesh_poses(
    source: PartSource, options: SweepOptions
) -> tuple[list[Any], list[float], str] | None:
    """A mesh's pose footprints, their probabilities and the file's hash; None: no mesh."""
    from ..errors import PartFileError
    from ..geometry.curved import with_shape_tol
    from ..solid.mesh import is_mesh, read_mesh_bytes
    from ..solid.parts import pose_part, study_of

    if not is_mesh(source.path):
        return None
    data = source.data
    if data is None:
        try:
            data = Path(source.path).read_bytes()
        except OSError:
            return None  # the part reader says why, in the CLI's words
    if options.layer is not None:
        raise PartFileError(f"{source.path}: a mesh has no layers (--layer is for DXF)")
    if options.flatten_tol is not None:
        raise PartFileError(f"{source.path}: a mesh has no curves to flatten (--flatten-tol)")
    kind = Path(source.path).suffix.lstrip(".").lower()
    solid = read_mesh_bytes(data, kind, source.path)
    study = study_of(solid)
    tol = options.shape_tol
    named = [
        pose_part(study, k, f"{solid.name}-pose-{k}", solid.units) for k in range(len(study.poses))
    ]
    parts = [with_shape_tol(p, tol) for p in named]
    return parts, [float(p.probability) for p in study.poses], hashlib.sha256(data).hexdigest()


def _plan_row(
    row: dict[str, Any],
    part: Any,
    options: SweepOptions,
    prior: Prior | None,
    payoff: Payoff | None,
    t0: float,
    element: str | None = None,
) -> dict[str, Any]:
    """Plan (and sense, and simulate) one read part into ``row`` (``element``: its pose)."""
    try:
        payoff = _read_payoff(options, payoff)
        parsed = prior or parse_prior(options.prior)
        rep, doc, status = _plan(part, options, parsed, payoff, element)
        _fill(row, part, doc)
        row["status"] = status
    except Exception as exc:  # a bad part is a row; a bug in it too, with its class
        row["plan_seconds"] = time.perf_counter() - t0
        return error_row(row, exc)
    if options.sense is not None:
        try:
            _policy(row, rep.problem, options, payoff)
        except Exception as exc:  # the plan columns stay; the message says which step failed
            error_row(row, exc)
            row["error_message"] = f"sensing policy: {row['error_message']}"
    row["plan_seconds"] = time.perf_counter() - t0
    if options.simulate is not None:
        t1 = time.perf_counter()
        try:
            sim = _simulate(rep, options, element)
            row.update(
                sim_engine=sim["engine"],
                sim_trials=sim["trials"],
                sim_predicted=sim["predicted_success"],
                sim_observed=sim["observed_success"],
                sim_ci_low=sim["ci95"][0],
                sim_ci_high=sim["ci95"][1],
                # physics: the success test, every trial counted (no states' chi-square)
                sim_p_value=sim.get("success_p_value", sim["p_value"]),
                sim_jams=sim["jams"],
                sim_json=json.dumps(sim, allow_nan=False, separators=(",", ":")),
            )
        except Exception as exc:
            error_row(row, exc)
        row["sim_seconds"] = time.perf_counter() - t1
    return row


def timeout_row(source: PartSource, options: SweepOptions, timeout: float) -> dict[str, Any]:
    """The error row of a part whose work took longer than ``timeout`` seconds."""
    row = empty_row(source.path, source.sha256, options)
    return error_row(
        row,
        TimeoutError(f"{source.path}: the part took longer than the timeout of {timeout:g} s"),
    )


@dataclass(frozen=True, slots=True)
class ChunkResult:
    """What a task gives back: the rows done and the parts it could not get to.

    Attributes
    ----------
    rows : list of dict
    pending : tuple of PartSource
        Parts left after a part timed out (its work may still be running: ``stuck``).
    stuck : bool
        A part's work outlived its timeout and still runs in this worker's process.
    worker : str
        Address of the Dask worker (``""`` outside Dask).
    """

    rows: list[dict[str, Any]]
    pending: tuple[PartSource, ...] = ()
    stuck: bool = False
    worker: str = ""


def _call_with_timeout(
    work: Callable[[], list[dict[str, Any]]], timeout: float
) -> list[dict[str, Any]] | None:
    """``work()`` in a thread, or ``None`` when it is not done in ``timeout`` seconds.

    Python threads cannot be killed; the engine restarts the worker whose thread is stuck.
    """
    box: list[list[dict[str, Any]]] = []
    t = threading.Thread(target=lambda: box.append(work()), daemon=True)
    t.start()
    t.join(timeout)
    return box[0] if box else None


def run_chunk(
    sources: Sequence[PartSource],
    options: SweepOptions,
    prior: Prior | None = None,
    timeout: float | None = None,
    payoff: Payoff | None = None,
) -> ChunkResult:
    """Plan a few parts (one task): a row each, stopping at the first that times out.

    Examples
    --------
    >>> run_chunk([PartSource("no-such-part.json")], SweepOptions()).rows[0]["status"]
    'error'
    """
    worker = ""
    try:  # the worker's address, to restart it when a part's work is stuck
        from distributed import get_worker

        worker = get_worker().address
    except (ImportError, ValueError):
        pass
    rows: list[dict[str, Any]] = []
    for i, src in enumerate(sources):
        if timeout is None:
            rows.extend(plan_part_rows(src, options, prior, payoff))
            continue
        got = _call_with_timeout(lambda s=src: plan_part_rows(s, options, prior, payoff), timeout)  # type: ignore[misc]
        if got is None:
            rows.append(timeout_row(src, options, timeout))
            return ChunkResult(rows, tuple(sources[i + 1 :]), True, worker)
        rows.extend(got)
    return ChunkResult(rows, (), False, worker)


def error_rows(
    sources: Sequence[PartSource], options: SweepOptions, exc: BaseException
) -> list[dict[str, Any]]:
    """Error rows for parts whose task failed as a whole (a worker died running it)."""
    return [error_row(empty_row(s.path, s.sha256, options), exc) for s in sources]
