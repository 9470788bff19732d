"""The request bodies of the API (pydantic models; the OpenAPI schema is made from them).

A part is given one way: ``vertices`` (an outline or point list, read exactly as a JSON part
file), ``catalogue`` (a name of :func:`bayesgrasp.shapes.names`) or ``file`` (the contents of a
part file of any format the command line reads, base64-encoded; parsed in memory). The
problem options are those of ``bayesgrasp plan``, by the same names without the dashes.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

__all__ = [
    "FigureRequest",
    "FileIn",
    "PartIn",
    "PartRequest",
    "PlanRequest",
    "PolicyRequest",
    "ProblemOptions",
    "SimulateRequest",
]

Cost = Annotated[float, Field(ge=0, le=1e12)]
Name = Annotated[str, Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_. -]+$")]
Format = Literal["json", "csv", "wkt", "geojson", "svg", "dxf"]


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


class PartIn(_Strict):
    """A part: give exactly one of ``vertices``, ``catalogue`` and ``file``."""

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
        None, ge=1, le=1000, description="Longest plan to consider (--max-squeezes)."
    )


class PlanRequest(ProblemOptions):
    """The body of ``plan``."""

    guaranteed: bool = Field(False, description="Also the shortest guaranteed plan.")


class SimulateRequest(ProblemOptions):
    """The body of ``simulate`` (kinematic engine)."""

    plan: Literal["bayes", "most-certain", "guaranteed"] = "bayes"
    trials: int = Field(100_000, ge=1, description="Executions (bounded by the server's limit).")
    noise: float = Field(0.0, ge=0, le=180, description="Gripper angle error, deg.")
    noise_kind: Literal["normal", "uniform"] = "normal"
    seed: int = Field(0, ge=0, le=2**63 - 1)


class FigureRequest(ProblemOptions):
    """The body of ``figures``: the figures ``plot`` makes."""

    plan: Literal["bayes", "most-certain", "guaranteed"] = "bayes"


class PolicyRequest(ProblemOptions):
    """The body of ``policy``: ``bayesgrasp plan PART [--also PART ...] --sense ...``."""

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
    max_actions: int = Field(
        3,
        ge=1,
        le=4,
        description="Deepest policy: actions on any path (--max-actions; the server takes at "
        "most 4, and at most 4 candidate parts: a request past its time limit keeps a "
        "worker busy until it ends).",
    )
