"""The request bodies of the API (pydantic models; the OpenAPI schema is made from them).

A part is given one way: ``vertices`` (an outline or point list, read exactly as a JSON part
file), ``catalogue`` (a name of :func:`bayesgrasp.shapes.names`) or ``file`` (the contents of a
part file of any format the command line reads, base64-encoded; parsed in memory). The
problem options are those of ``bayesgrasp plan``, by the same names without the dashes.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator
from pydantic_core import PydanticCustomError

from ..solid.mesh import MESH_FORMATS as _MESH_FORMATS

__all__ = [
    "MESH_FORMATS",
    "ErrorBody",
    "ExportRequest",
    "FigureRequest",
    "FileIn",
    "FunctionsRequest",
    "PartIn",
    "PartRequest",
    "PayoffIn",
    "PlanRequest",
    "PolicyRequest",
    "PosesRequest",
    "ProblemOptions",
    "SimulateJobRequest",
    "SimulateRequest",
    "StrokeOptions",
]

Cost = Annotated[float, Field(ge=0, le=1e12)]
Name = Annotated[str, Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_. -]+$")]
Format = Literal["json", "csv", "wkt", "geojson", "svg", "dxf", "stl", "obj", "ply", "3mf", "glb"]
#: ``--goal-pose`` and ``--pose-prior`` of a policy over a mesh's poses (policy, export).
GoalPose = Annotated[
    str | None,
    Field(
        max_length=16,
        pattern=r"^\s*([0-9]+|any)\s*$",
        description="A mesh part: the policy is over its resting poses; only pose K may be "
        "declared (default 0), `any`: every pose may (--goal-pose).",
    ),
]
PosePrior = Annotated[
    str | None,
    Field(
        max_length=64,
        description="A mesh part: the poses' prior, the quasi-static estimate (default) or the "
        "perturbed one (--pose-prior; drops:N and poses files are the command line's).",
    ),
]
MESH_FORMATS = _MESH_FORMATS
"""The formats of :data:`Format` that are triangle meshes (a solid; one pose is planned)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class FileIn(_Strict):
    """The contents of a part file."""

    format: Format = Field(description="Format of the file (there is no extension to go by).")
    data_base64: str = Field(description="The file's bytes, base64-encoded.")
    element: str | None = Field(
        None, max_length=200, description="Which outline when the file has several (--element)."
    )
    layer: str | None = Field(None, max_length=200, description="DXF: only this layer (--layer).")
    flatten_tol: float | None = Field(
        None, gt=0, description="Chordal tolerance of curve flattening (--flatten-tol)."
    )
    pose: int | None = Field(
        None,
        ge=0,
        le=100_000,
        description="A mesh (stl, obj, ply, 3mf, glb): the resting pose whose footprint is the "
        "part, as `poses` lists them (--pose; default 0, the most probable).",
    )


def _one_way(schema: dict[str, Any], cls: type) -> None:
    """The part's schema: exactly one of vertices, catalogue and file (``oneOf``).

    ``null`` is read as "not given"; the schema states the three ways without it.
    """
    for key in ("vertices", "catalogue", "file"):
        prop = schema["properties"][key]
        kept = [x for x in prop.pop("anyOf", []) if x.get("type") != "null"]
        prop.pop("default", None)
        if len(kept) == 1:
            prop.update(kept[0])
    schema["oneOf"] = [{"required": [key]} for key in ("vertices", "catalogue", "file")]


class PartIn(_Strict):
    """A part: give exactly one of ``vertices``, ``catalogue`` and ``file``."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, json_schema_extra=_one_way)

    vertices: list[tuple[float, float]] | None = Field(
        None,
        description="Outline (or point list) [[x, y], ...], read as a JSON part file is.",
    )
    catalogue: str | None = Field(None, max_length=64, description="A catalogue part's name.")
    file: FileIn | None = None
    name: Name = Field("part", description="The part's name (a label only).")
    units: str | None = Field(None, max_length=16, description="Units of the vertices.")
    center_of_mass: tuple[float, float] | None = Field(
        None, description="Centre of mass of a vertices part (default: its centroid)."
    )
    shape_tol: float = Field(
        0.0,
        ge=0,
        le=1e12,
        description="Manufacturing tolerance of the part, in its units (--shape-tol): minima "
        "of the width it could lose are not stable orientations.",
    )


class PartRequest(_Strict):
    """The body of ``squeeze`` and ``push``."""

    part: PartIn
    prior: str = Field("uniform", max_length=200, description="uniform | vonmises:MEAN_DEG,KAPPA")


class PosesRequest(_Strict):
    """The body of ``poses``: a mesh part (``bayesgrasp poses MESH --json``)."""

    part: PartIn


class ProblemOptions(_Strict):
    """The problem and planner options of ``bayesgrasp plan``."""

    part: PartIn
    prior: str = Field(
        "uniform",
        max_length=200,
        description="uniform | vonmises:MEAN_DEG,KAPPA (histogram and sample priors: "
        "`prior_histogram`, `prior_sample`).",
    )
    prior_histogram: list[Annotated[float, Field(ge=0)]] | None = Field(
        None, max_length=3600, description="Bin weights over [0, 360) deg (--prior histogram:)."
    )
    prior_sample: list[float] | None = Field(
        None, max_length=100_000, description="Observed orientations, deg (--prior sample:)."
    )
    costs: dict[str, Cost] = Field(
        default_factory=dict, description="Cost of each action by name (--NAME-cost; default 1)."
    )
    first_costs: dict[str, Cost] = Field(
        default_factory=dict, description="Cost of an action when first (--first-NAME-cost)."
    )
    verify_cost: Cost = 1.0
    retry_cost: Cost = 0.0
    goal: Literal["single", "symmetry"] = "single"
    actions: list[str] | str = Field(
        "squeeze", description="Action kinds, a list or comma-separated (--actions)."
    )
    accuracy: float = Field(0.0, ge=0, le=180, description="Gripper accuracy, deg (--accuracy).")
    method: Literal["exact", "bfs"] = "exact"
    max_actions: int | None = Field(
        None, ge=1, le=1000, description="Longest plan to consider (--max-actions)."
    )
    jaw_height: float | None = Field(
        None,
        ge=0,
        le=1e12,
        description="A mesh part: height of the jaws' contact above the table, in the mesh's "
        "units (--jaw-height). A pose a squeeze at this height may topple is refused (with "
        "`sense`, every pose of positive weight).",
    )


Unit = Annotated[float, Field(ge=0, le=1)]


class PayoffIn(_Strict):
    """A payoff, as a payoff file holds it: ``{"payoff": {"80.63": 1.0}, "default": 0.0}``.

    ``payoff`` maps orientations in degrees (the stable orientations ``plan`` prints) to
    values in [0, 1], as an object or a list of ``{"orientation_deg": DEG, "value": V}``;
    states not listed get ``default``.
    """

    payoff: dict[str, Any] | list[Any] = Field(
        description="Orientation (deg) to payoff in [0, 1]: an object "
        '{"DEG": V, ...} or a list [{"orientation_deg": DEG, "value": V}, ...].',
    )
    default: Unit = Field(0.0, description="Payoff of every state not listed.")

    @field_validator("payoff", mode="before")
    @classmethod
    def _entries(cls, v: object) -> object:
        def bad(message: str) -> PydanticCustomError:
            return PydanticCustomError("payoff", message)  # no context: braces stay as they are

        if not isinstance(v, dict | list):
            raise bad(f"must be an object or a list; got {type(v).__name__}")
        if len(v) > 3600:
            raise bad(f"at most 3600 orientations; got {len(v)}")
        pairs: list[tuple[object, object, str]] = []
        if isinstance(v, dict):
            pairs = [(k, x, f"the value of {k}") for k, x in v.items()]
        else:
            for i, item in enumerate(v):
                if not isinstance(item, dict) or set(item) != {"orientation_deg", "value"}:
                    raise bad(f'entry #{i + 1} must be {{"orientation_deg": DEG, "value": V}}')
                pairs.append((item["orientation_deg"], item["value"], f"entry #{i + 1}"))
        for key, value, where in pairs:
            try:
                ok = not isinstance(key, bool) and math.isfinite(float(key))  # type: ignore[arg-type]
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise bad(f"{key!r} is not an orientation in degrees")
            number = isinstance(value, int | float) and not isinstance(value, bool)
            if not (number and 0 <= value <= 1):  # type: ignore[operator]  # NaN fails too
                raise bad(f"{where} must be a number in [0, 1]; got {value!r}")
        return v

    def entries(self) -> tuple[list[float], list[float]]:
        """The orientations (deg) and their values."""
        if isinstance(self.payoff, dict):
            return [float(k) for k in self.payoff], [float(x) for x in self.payoff.values()]
        degs = [float(e["orientation_deg"]) for e in self.payoff]
        return degs, [float(e["value"]) for e in self.payoff]


class NoiseOptions(ProblemOptions):
    """The action noise and payoff options (``--turn-noise``, ``--contact-noise``, ``--payoff``)."""

    turn_noise: str | None = Field(
        None,
        max_length=64,
        description="Gripper turns executed as alpha + e: `normal:SIGMA_DEG` or `uniform:A_DEG` "
        "(--turn-noise).",
    )
    contact_noise: float | None = Field(
        None,
        ge=0,
        le=1,
        description="Probability that a squeeze's jaws touch one after the other "
        "(--contact-noise).",
    )
    payoff: PayoffIn | None = Field(
        None, description="Payoff of final orientations (the contents of a --payoff file)."
    )

    @field_validator("turn_noise")
    @classmethod
    def _turn_noise(cls, v: str | None) -> str | None:
        if v is not None:
            from ..errors import PlanningError
            from ..model.noise import parse_turn_noise

            try:
                parse_turn_noise(v)
            except PlanningError:
                raise PydanticCustomError(
                    "turn_noise",
                    "must be normal:SIGMA_DEG or uniform:A_DEG with a number of degrees >= 0; "
                    "got '{v}'",
                    {"v": v},
                ) from None
        return v

    @property
    def noisy(self) -> bool:
        """Whether the noise or payoff options are given (the noise-aware planners)."""
        return not (self.turn_noise is None and self.contact_noise is None and self.payoff is None)

    def noise_model(self) -> Any:
        """The :class:`~bayesgrasp.model.noise.NoiseModel` of the options."""
        from ..model.noise import NoiseModel

        return NoiseModel.of(self.turn_noise, self.contact_noise)

    def payoff_model(self) -> Any:
        """The :class:`~bayesgrasp.model.payoff.Payoff` given inline, or ``None``."""
        if self.payoff is None:
            return None
        import numpy as np

        from ..model.payoff import Payoff

        degs, values = self.payoff.entries()
        return Payoff(np.radians(degs), np.array(values), self.payoff.default, "request")


class StrokeOptions(NoiseOptions):
    """The gripper's stroke (``--max-opening``, ``--min-opening``, ``--within-stroke``)."""

    max_opening: float | None = Field(
        None,
        ge=0,
        le=1e12,
        description="The widest the gripper opens, in the part's units (--max-opening): a plan "
        "or policy with a step that needs the jaws open wider is refused (422).",
    )
    min_opening: float | None = Field(
        None,
        ge=0,
        le=1e12,
        description="The narrowest the gripper closes, in the part's units (--min-opening): a "
        "plan or policy with a step that may close the jaws narrower is refused (422).",
    )
    within_stroke: bool = Field(
        False,
        description="Plan only actions the stroke allows (--within-stroke): the best plan of "
        "each length whose every step fits (noise-free plans of one part, exact method, no "
        "accuracy).",
    )


class PlanRequest(StrokeOptions):
    """The body of ``plan``.

    With ``turn_noise``, ``contact_noise`` or ``payoff``: the noise-aware Bayes plan
    (``plan --turn-noise ... --contact-noise ... --payoff FILE``).
    """

    guaranteed: bool = Field(False, description="Also the shortest guaranteed plan.")


class SimulateRequest(NoiseOptions):
    """The body of ``simulate`` (kinematic engine).

    ``noise`` and ``noise_kind`` are the older spelling of ``turn_noise``
    (``noise_kind:noise``); with the noise or payoff options the plan run is the one ``plan``
    gives under them, as ``bayesgrasp simulate`` runs it.
    """

    plan: Literal["bayes", "most-certain", "guaranteed"] | dict[str, Any] = Field(
        "bayes",
        description="The plan to run: `bayes`, `most-certain`, `guaranteed`, or a plan itself "
        "(--plan FILE.json): one of `plan`'s `options` (or its `guaranteed`), or a whole plan "
        "document, whose part must be this one and whose goal and prior apply unless given "
        "here.",
    )
    trials: int = Field(100_000, ge=1, description="Executions (bounded by the server's limit).")
    noise: float = Field(
        0.0,
        ge=0,
        lt=90,
        description="Gripper angle error, deg (the older spelling of `turn_noise`: "
        "`noise_kind:noise`; an error of 90 deg or more hides every orientation).",
    )
    noise_kind: Literal["normal", "uniform"] = "normal"
    seed: int = Field(0, ge=0, le=2**63 - 1)


class FigureRequest(NoiseOptions):
    """The body of ``figures``: the figures ``plot`` makes.

    With ``turn_noise``, ``contact_noise`` or ``payoff``: the plan is the one ``plan`` gives
    under them, and the plan figure draws the exact distributions after each step under the
    noise (``plot --turn-noise ...``).
    """

    plan: Literal["bayes", "most-certain", "guaranteed"] = "bayes"


class FunctionsRequest(NoiseOptions):
    """The body of ``views/functions``: the part's functions and the chosen plan's beliefs.

    With ``turn_noise``, ``contact_noise`` or ``payoff``: the plan is the noise-aware one
    ``plan`` gives under them (``guaranteed``: the plan guaranteed under a bounded turn error)
    and the beliefs are the exact distributions under the noise.
    """

    plan: Literal["bayes", "most-certain", "guaranteed"] = "bayes"


class PolicyRequest(StrokeOptions):
    """The body of ``policy``: ``bayesgrasp plan PART [--also PART ...] --sense ...``.

    With ``turn_noise`` or ``contact_noise`` (or ``payoff``, one part): the Bayes policy
    under the noisy actions (``--sense ... --turn-noise ...``).
    """

    sense: str = Field(
        "width",
        max_length=64,
        description="The jaw-width sensor: `width` (exact readings) or `width:SIGMA,RES` in "
        "the part's units (--sense).",
    )
    also: list[PartIn] = Field(
        default_factory=list,
        max_length=3,
        description="More candidate parts to tell apart (--also); each given as `part` is.",
    )
    part_prior: list[Annotated[float, Field(ge=0)]] | None = Field(
        None, max_length=4, description="Weights of the candidate parts (--part-prior)."
    )
    goal_pose: GoalPose = None
    pose_prior: PosePrior = None
    max_actions: int = Field(
        3,
        ge=1,
        le=4,
        description="Deepest policy: actions on any path (--max-actions; the server takes at "
        "most 4, and at most 4 candidate parts: a request past its time limit keeps a "
        "worker busy until it ends).",
    )


class ExportRequest(PlanRequest):
    """The body of ``export``: the robot file ``plan ... --export FILE.csv|json`` writes.

    The members of ``plan``; with ``sense`` (and ``also``, ``part_prior``) those of
    ``policy``, whose state machine is written instead of the Bayes plan.
    """

    format: Literal["csv", "json"] = Field(
        description="The robot file's format (the ending of --export FILE)."
    )
    sense: str | None = Field(
        None,
        max_length=64,
        description="Export the Bayes policy that branches on jaw widths (as `policy`): "
        "`width` or `width:SIGMA,RES` (--sense).",
    )
    also: list[PartIn] = Field(
        default_factory=list, max_length=3, description="With `sense`: more candidate parts."
    )
    part_prior: list[Annotated[float, Field(ge=0)]] | None = Field(
        None, max_length=4, description="With `sense`: weights of the candidate parts."
    )
    goal_pose: GoalPose = None
    pose_prior: PosePrior = None


class SimulateJobRequest(SimulateRequest):
    """The body of ``simulate/jobs``: a simulation run as a job (``simulate --engine ...``).

    As ``simulate``, with the engine to use: ``mujoco`` runs the plan in the physics engine
    (``simulate --engine mujoco``; the ``sim`` extra), ``kinematic`` the model's transfer
    functions.
    """

    engine: Literal["kinematic", "mujoco"] = Field(
        "mujoco", description="kinematic: the model's transfer functions; mujoco: physics."
    )
    trials: int | None = Field(  # type: ignore[assignment]
        None,
        ge=1,
        description="Executions (default: 200 mujoco, 100,000 kinematic; bounded by the "
        "server's limits).",
    )
    offset_mm: float = Field(
        0.0,
        ge=0,
        le=1e6,
        description="mujoco: the part's centre is this far off the gripper centre (--offset).",
    )
    jaw_lag_s: float = Field(
        0.0,
        ge=0,
        le=1e4,
        description="mujoco: contact asynchrony (--jaw-lag): in each squeeze one jaw (either, "
        "equally likely) starts closing this many seconds early and pushes the part 5 mm a "
        "second of lag before the other touches.",
    )


class ErrorBody(BaseModel):
    """Every error answer: the reason in one line, its kind and the HTTP status."""

    detail: str = Field(description="The reason, one line (the command line's message).")
    error: str = Field(
        description="The kind: invalid-request, limit, no-plan, queue-full, timeout, "
        "memory-limit, body-too-large, http, or the name of the library's error."
    )
    status: int = Field(description="The HTTP status again.")


#: The error answers every POST (and every endpoint with parameters) declares.
ERRORS: dict[int | str, dict[str, Any]] = {
    413: {"model": ErrorBody, "description": "The request body is over the server's limit."},
    422: {
        "model": ErrorBody,
        "description": "Bad input or over a limit of the request (vertices, trials, "
        "timeout): `detail` is the command line's one-line message.",
    },
    503: {
        "model": ErrorBody,
        "description": "The queue is full, the work timed out (its worker was stopped) or "
        "reached the worker's memory limit; a `Retry-After` header says when to try again.",
        "headers": {
            "Retry-After": {"description": "Seconds to wait.", "schema": {"type": "integer"}}
        },
    },
}
