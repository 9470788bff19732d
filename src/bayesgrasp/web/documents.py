"""The API's documents, each the one the command line prints with ``--json``.

Every function here is work a worker process runs (:data:`~bayesgrasp.web.service.WORK`):
it takes the worker's :class:`~bayesgrasp.web.service.Service` (to read parts within the
server's limits) and a request (:mod:`bayesgrasp.web.models`), and builds its answer with the
command line's own library calls (:class:`~bayesgrasp.runs.specs.ProblemSpec`,
:func:`bayesgrasp.planning.solve`, :func:`bayesgrasp.io.plans.strategy_document`,
:func:`bayesgrasp.io.export.write_robot`, :mod:`bayesgrasp.report`).
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pydantic import ValidationError

from .common import one_line
from .limits import Limits, engines
from .models import (
    MESH_FORMATS,
    ExportRequest,
    FigureRequest,
    PartRequest,
    PlanRequest,
    PolicyRequest,
    PosesRequest,
    SimulateRequest,
)
from .problems import (
    build_problem,
    check_within_stroke,
    chosen_option,
    exact_method,
    given_option,
    noisy_option,
    prior_string,
    problem_spec,
    stroke_of,
)
from .workers import LimitError

if TYPE_CHECKING:
    from ..model.problem import Problem
    from ..planning.result import PlanOption
    from ..planning.strategy import StrategyResult
    from .service import Service

__all__ = [
    "catalogue_document",
    "check_mesh_options",
    "check_simulation",
    "export_file",
    "export_strategy",
    "figure_bytes",
    "mujoco_result",
    "plan_result_document",
    "plan_strategy",
    "policy_document_of",
    "policy_strategy",
    "pose_inputs",
    "poses_document_of",
    "push_document",
    "simulate_document",
    "squeeze_document",
]


def squeeze_document(service: Service, req: PartRequest) -> dict[str, Any]:
    """``bayesgrasp squeeze PART --prior P --json``."""
    from .. import report
    from ..geometry.curved import squeeze_model
    from ..model.prior import parse_prior

    p = service.part(req.part)
    pr = parse_prior(prior_string(req))
    return report.squeeze_json(p, squeeze_model(p)[1], pr)  # a curved part's exact model


def push_document(service: Service, req: PartRequest) -> dict[str, Any]:
    """``bayesgrasp push PART --prior P --json``."""
    from .. import report
    from ..geometry.curved import push_model
    from ..model.prior import parse_prior

    p = service.part(req.part)
    pr = parse_prior(prior_string(req))
    return report.push_json(p, *push_model(p), pr)


def plan_result_document(service: Service, req: PlanRequest) -> dict[str, Any]:
    """``bayesgrasp plan PART [options] [--guaranteed] [--max-opening W ...] --json``."""
    from ..runs.specs import run_inputs
    from ..runs.strategies import document

    spec = problem_spec(req)
    result = plan_strategy(service, req, spec)
    return document(result, run_inputs(None, spec) | pose_inputs(req))


def plan_strategy(service: Service, req: PlanRequest, spec: Any) -> StrategyResult:
    """The plans of ``plan`` (:func:`bayesgrasp.planning.solve`, as the command line plans).

    The noise-aware plans with the noise or payoff options; with ``within_stroke`` only plans
    the stroke allows; with ``max_opening`` or ``min_opening`` a Bayes plan outside the stroke
    is refused (:func:`~bayesgrasp.runs.strategies.check_stroke`).
    """
    from ..planning.strategy import solve
    from ..runs.strategies import check_stroke

    stroke = stroke_of(req)
    check_within_stroke(req, stroke, policy=False)
    pb = build_problem(service.part(req.part), req, spec)
    if req.noisy:
        from ..planning.robust import UNBOUNDED_GUARANTEE

        exact_method(req)
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


def policy_document_of(service: Service, req: PolicyRequest) -> dict[str, Any]:
    """``bayesgrasp plan PART [--also PART ...] --sense ... --json``: the Bayes policy.

    With the noise or payoff options, the policy under the noisy actions
    (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`), as the command line plans it.
    """
    from ..runs.strategies import document

    return document(policy_strategy(service, req))


def policy_strategy(service: Service, req: PolicyRequest) -> StrategyResult:
    """The Bayes policy of ``policy`` as a strategy; refused if outside the stroke given."""
    from ..planning.noisy_policy import plan_noisy_policy
    from ..planning.policy import Policy, plan_policy
    from ..planning.strategy import StrategyResult
    from ..runs.strategies import check_stroke

    stroke = stroke_of(req)
    check_within_stroke(req, stroke, policy=True)
    spec = problem_spec(req)
    prior: str | None
    if is_mesh(req.part):  # as plan MESH --sense: the candidates are the resting poses
        parts, spec, prior = pose_candidates(service, req, spec)
    else:
        if req.goal_pose is not None or req.pose_prior is not None:
            raise LimitError(422, "`goal_pose`, `pose_prior`: for a mesh part (policy over poses)")
        if req.jaw_height is not None:
            raise LimitError(422, "`jaw_height` needs a mesh part")
        parts = [service.part(p) for p in (req.part, *req.also)]
        prior = None if req.part_prior is None else ",".join(map(repr, req.part_prior))
    problems = [build_problem(p, req, spec) for p in parts]
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


def is_mesh(part: Any) -> bool:
    """Whether a request's part is a mesh file (a solid, of resting poses)."""
    return part.file is not None and part.file.format in MESH_FORMATS


def pose_inputs(req: Any) -> dict[str, Any]:
    """The provenance of a mesh part's pose, as the command line records ``--pose K``."""
    f = req.part.file
    if not is_mesh(req.part) or (f.pose is None and f.element is None):
        return {}
    return {"element": f.element if f.pose is None else str(f.pose)}


def poses_document_of(service: Service, req: PosesRequest) -> dict[str, Any]:
    """``bayesgrasp poses MESH --json``: the resting poses and their probabilities."""
    from ..runs.poses import poses_document

    if req.part.file is not None and req.part.file.pose is not None:
        raise LimitError(422, "`pose`: `poses` lists every pose; give no pose")
    solid, study = service.solid(req.part, "`poses`")
    return poses_document(solid, study)


def check_mesh_options(service: Service, req: Any) -> None:
    """Refuse a request's ``jaw_height`` as the command line refuses ``--jaw-height``.

    Without ``sense``: the part must be a mesh and no squeeze at that height may topple its
    pose (the planar orientation is unknown, so a pose that some closing direction topples
    may be met at any gripper angle; :func:`bayesgrasp.solid.topple.toppling_report`). With
    ``sense`` the policy's own check applies (:func:`pose_candidates`). ``goal_pose`` and
    ``pose_prior`` need ``sense``.
    """
    if getattr(req, "sense", None) is not None or not hasattr(req, "part"):
        return
    if getattr(req, "goal_pose", None) is not None or getattr(req, "pose_prior", None):
        raise LimitError(422, "`goal_pose` and `pose_prior` plan a policy over poses: add `sense`")
    height = getattr(req, "jaw_height", None)
    if height is None:
        return
    if not is_mesh(req.part):
        raise LimitError(422, "`jaw_height` needs a mesh part")
    from ..runs.poses import PoseOptionError, pose_toppling
    from ..solid.parts import pose_index

    f = req.part.file
    _, study = service.solid(req.part)
    chosen = f.element if f.pose is None else f.pose
    k = pose_index(chosen, len(study.poses), f"{req.part.name}.{f.format}: pose")
    try:
        pose_toppling(study, k, height, "`pose`")
    except PoseOptionError as exc:
        raise LimitError(422, f"`jaw_height`: {exc}") from None


def pose_candidates(service: Service, req: PolicyRequest, spec: Any) -> tuple[Any, Any, str]:
    """A mesh part's policy: its pose footprints, their problems and prior weights.

    As ``plan MESH --sense S --goal-pose K|any --pose-prior P --jaw-height H``
    (:mod:`bayesgrasp.runs.poses`): the candidates are the footprints ``pose-0``,
    ``pose-1``, ...; poses other than the goal pose may not be declared.
    """
    import dataclasses

    from ..runs.poses import PoseOptionError, PoseProblems, pose_prior_weights, poses_toppling
    from ..runs.specs import ProblemSpec
    from ..solid.parts import pose_index, pose_parts

    if req.also or req.part_prior is not None:
        raise LimitError(
            422,
            "with a mesh part and `sense` the candidates are its poses: drop `also` and "
            "`part_prior` (`pose_prior` sets the poses' prior)",
        )
    if req.part.file is not None and req.part.file.pose is not None:
        raise LimitError(
            422,
            "`sense` plans a policy over every pose: choose the pose to orient with "
            "`goal_pose`, not `pose`",
        )
    kind = (req.pose_prior or "quasi-static").strip().lower()
    if kind.startswith("drops:"):
        raise LimitError(
            422,
            "`pose_prior` drops:N runs MuJoCo drops, longer than a request may take: give "
            "quasi-static or perturbed (drops:N is the command line's --pose-prior)",
        )
    if kind not in ("quasi-static", "perturbed"):
        raise LimitError(
            422,
            f"`pose_prior`: expected quasi-static or perturbed; got {req.pose_prior!r} (a "
            "poses FILE is the command line's: the server reads no files)",
        )
    solid, study = service.solid(req.part)
    n = len(study.poses)
    goal: int | None = 0
    if req.goal_pose is not None and req.goal_pose.strip().lower() == "any":
        goal = None
    elif req.goal_pose is not None:
        goal = pose_index(req.goal_pose, n, "`goal_pose`")
    try:
        weights = pose_prior_weights(kind, solid, study)
        if req.jaw_height is not None:
            poses_toppling(study, weights, req.jaw_height)
    except PoseOptionError as exc:
        raise LimitError(422, f"`{exc.option.lstrip('-').replace('-', '_')}`: {exc}") from None
    undeclared = frozenset(f"pose-{k}" for k in range(n) if goal is not None and k != goal)
    values = {f.name: getattr(spec, f.name) for f in dataclasses.fields(ProblemSpec)}
    problems = PoseProblems(**values, undeclared=undeclared)
    return pose_parts(study, solid.units), problems, ",".join(repr(w) for w in weights)


def export_file(service: Service, req: ExportRequest) -> tuple[str, bytes]:
    """``bayesgrasp plan PART [options] --export FILE.csv|json``: the file's name and bytes.

    The Bayes plan (or with ``sense`` the policy's state machine) for a robot, written by the
    command line's own writer (:func:`bayesgrasp.io.export.write_robot`, with the noise and
    payoff of :func:`bayesgrasp.runs.strategies.robot_metadata`); the name is
    ``PART-plan.FORMAT`` or ``PART-policy.FORMAT``.
    """
    import tempfile

    from ..io.export import write_robot
    from ..runs.strategies import robot_metadata

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
        raise LimitError(422, one_line(exc)) from None
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
    trials = check_simulation(service.limits, req)
    spec = problem_spec(req)
    p = service.part(req.part)
    noise = req.noise_model()
    deg, kind = req.noise, req.noise_kind
    if req.turn_noise is None:
        noise = NoiseModel(TurnNoise(req.noise_kind, math.radians(req.noise)), noise.contact)
    else:
        deg, kind = float(req.turn_noise.partition(":")[2]), noise.turn.kind
    pay = req.payoff_model()
    if not isinstance(req.plan, str):
        pb, option = given_option(req.plan, req, p, spec)
    elif (not noise.exact or pay is not None) and req.plan != "guaranteed":
        exact_method(req)
        from ..planning.noisy import plan_noisy

        pb = build_problem(p, req, spec)
        res_n = plan_noisy(pb, noise, pay, spec.max_actions)
        option = res_n.options[res_n.bayes if req.plan == "bayes" else res_n.most_certain].option
    else:
        pb, option, _ = chosen_option(req.plan, req, p, spec)
    u = None if pay is None else as_vector(pay, pb.states)
    lag = float(getattr(req, "jaw_lag_s", 0.0))
    if engine == "mujoco":
        res = mujoco_result(pb, option, trials, noise, req.seed, offset_mm, u, progress, lag)
    else:
        from ..sim.kinematic import simulate_kinematic

        res = simulate_kinematic(
            pb, option, trials, noise, rng=req.seed, payoff=u, progress=progress
        )
    from ..io.plans import provenance
    from ..runs.specs import run_inputs, simulate_inputs

    doc = report.simulate_json(res, p)  # with the provenance the command line writes
    which = req.plan if isinstance(req.plan, str) else "request"
    how = simulate_inputs(engine, which, req.seed, trials, deg, kind, offset_mm)
    how["contact_noise"] = req.contact_noise
    how["jaw_lag_s"] = lag or None
    how["payoff"] = None if req.payoff is None else "request"
    doc["provenance"] = provenance(pb, None, **how, **run_inputs(None, spec), **pose_inputs(req))
    return doc


def check_simulation(limits: Limits, req: SimulateRequest) -> int:
    """The trials a simulation request runs, or its refusal (422) before any work.

    A job's request is checked when it is posted, so that a request the server cannot run
    is answered at once rather than as a failed job.
    """
    engine = getattr(req, "engine", "kinematic")
    trials = req.trials if req.trials is not None else (200 if engine == "mujoco" else 100_000)
    most = limits.max_mujoco_trials if engine == "mujoco" else limits.max_trials
    if trials > most:
        raise LimitError(422, f"`trials` is {trials}; the limit is {most}")
    if req.turn_noise is not None and (req.noise > 0 or req.noise_kind != "normal"):
        raise LimitError(
            422, "`noise`, `noise_kind`: the older spelling of `turn_noise`; give one of them"
        )
    if engine == "kinematic" and getattr(req, "jaw_lag_s", 0.0) > 0:
        raise LimitError(
            422,
            "`jaw_lag_s`: applies to the mujoco engine only (the kinematic model's contact "
            "asynchrony is `contact_noise`)",
        )
    if engine == "kinematic" and getattr(req, "offset_mm", 0.0) > 0:
        raise LimitError(
            422,
            "`offset_mm`: applies to the mujoco engine only (the kinematic model has no positions)",
        )
    if engine == "mujoco":
        if req.contact_noise is not None:
            raise LimitError(
                422,
                "`contact_noise`: applies to the kinematic engine only (in MuJoCo the jaws' "
                "contacts are the physics' own)",
            )
        if "mujoco" not in engines():
            raise LimitError(
                422,
                "`engine`: mujoco is not installed on this server (the `sim` extra); "
                "use `kinematic`",
            )
    return trials


def mujoco_result(
    pb: Problem,
    option: PlanOption,
    trials: int,
    noise: Any,
    seed: int,
    offset_mm: float,
    payoff: Any,
    progress: Callable[[int, int], None] | None,
    jaw_lag: float = 0.0,
) -> Any:
    """The MuJoCo trials of ``simulate --engine mujoco`` (one process: the job's worker)."""
    from ..errors import SimulationError
    from ..sim import simulate_mujoco
    from ..sim.asynchrony import lagged_params
    from ..sim.noise import GripperNoise
    from ..sim.result import with_prediction
    from ..sim.scene import units_scale

    size = pb.part.hull.size * units_scale(pb.part.units)  # metres, as MuJoCo builds it
    if offset_mm > 0 and offset_mm / 1000.0 >= size:
        raise LimitError(
            422,
            f"`offset_mm`: {offset_mm:g} mm is not less than the part's size "
            f"({size * 1000:.4g} mm from its centroid to its farthest vertex)",
        )
    try:
        params = lagged_params(jaw_lag, size) if jaw_lag else None
    except SimulationError as exc:
        raise LimitError(422, f"`jaw_lag_s`: {exc}") from None
    res = simulate_mujoco(
        pb,
        option,
        trials,
        offset=offset_mm / 1000.0,
        noise=GripperNoise.of(noise.turn),
        rng=seed,
        workers=1,
        progress=progress,
        params=params,
    )
    exact = noise.exact and payoff is None
    return res if exact else with_prediction(res, pb, noise, payoff)


def figure_bytes(service: Service, req: FigureRequest, name: str, fmt: str) -> bytes:
    """One of the figures ``bayesgrasp plot`` writes (``NAME.FMT``), as bytes."""
    from ..figures.plots import diameter_figure, evolution_figure, part_figure, transfer_figure
    from ..model.actions import PUSH_GRASP

    spec = problem_spec(req)
    p = service.part(req.part)
    qs, note = None, None
    if req.noisy:  # as plot --turn-noise ...: the plan under the noise, its distributions
        from ..figures.plans import noise_note
        from ..planning.noisy import step_distributions_noisy

        pb, option, label = noisy_option(req.plan, req, p, spec)
        if name == "plan":
            qs = step_distributions_noisy(pb, req.noise_model(), option.steps)
            note = noise_note(req.noise_model(), req.payoff is not None)
    else:
        pb, option, label = chosen_option(req.plan, req, p, spec)
    with service.figure_lock:  # matplotlib's font cache and text engine are shared
        if name == "part":
            fig = part_figure(pb.part)
        elif name == "diameter":
            fig = diameter_figure(pb, option.first_angle, option.steps[0].kind)
        elif name == "transfer":
            fig = transfer_figure(pb, push_grasp=PUSH_GRASP.name in pb.action_kinds)
        else:
            fig = evolution_figure(pb, option, label, qs, note)
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
