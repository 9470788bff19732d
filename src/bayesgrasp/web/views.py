"""The page's own endpoints: the views a user saves to the gallery, and the figures' data.

``POST /api/v1/views/functions`` samples the part's diameter, squeeze, radius, push and
push-grasp functions (the exact models of a curved part) and gives the belief over
orientations after each step of the chosen plan, for the page to draw; with the noise or
payoff options, of the noise-aware plan, under the noise.

The gallery keeps only what the user saved with the page's *Save* button: the page's address
fragment (the part and every option, so the entry reproduces the view, costs included), the
outline for a thumbnail and the plan's numbers.
"""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Query, Request
from fastapi.responses import JSONResponse
from pydantic import BaseModel, ConfigDict, Field

from .models import ERRORS, FunctionsRequest

__all__ = ["SaveRequest", "belief_steps", "chosen_beliefs", "function_samples", "router"]

router = APIRouter(prefix="/api/v1", tags=["server"])

Point = tuple[float, float]


class SaveRequest(BaseModel):
    """A view to keep: its name, address fragment, outline and plan numbers."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    name: str = Field(min_length=1, max_length=80)
    view: str = Field(min_length=1, max_length=200_000, description="The address fragment.")
    outline: list[Point] = Field(max_length=2000, description="Outline for the thumbnail.")
    summary: dict[str, float | int | str | None] = Field(
        default_factory=dict, max_length=20, description="The plan's numbers."
    )


def _no_gallery() -> JSONResponse:
    return JSONResponse(
        {"detail": "this server keeps no gallery (no data folder)", "error": "http", "status": 404},
        status_code=404,
    )


@router.post("/saved", responses=ERRORS)
async def save(req: SaveRequest, request: Request) -> Any:
    """Save a view to the gallery (saving it again refreshes its time)."""
    gallery = request.app.state.service.gallery
    if gallery is None:
        return _no_gallery()
    key = gallery.save(req.name, req.view, [list(p) for p in req.outline], req.summary)
    return {"id": key}


@router.get("/saved", responses=ERRORS)
async def saved(
    request: Request,
    page: Annotated[int, Query(ge=1, le=100_000)] = 1,
    per_page: Annotated[int, Query(ge=1, le=100)] = 12,
) -> Any:
    """One page of the saved views, newest first, with their total count."""
    gallery = request.app.state.service.gallery
    if gallery is None:
        return {"page": page, "per_page": per_page, "total": 0, "rows": []}
    return {"schema": "bayesgrasp.saved/1", **gallery.saved_page(page, per_page)}


def belief_steps(problem: Any, steps: Any) -> list[list[tuple[float, float]]]:
    """The belief after each step of a plan: ``(orientation, probability)`` atoms, radians.

    The first action sends every start in a basin ``[lo, hi)`` of its transfer function,
    shifted by the gripper angle ``alpha``, to that basin's stable orientation, with the
    prior's mass of the shifted basin; each later action moves every atom through its
    transfer function (Goldberg and Mason, *Bayesian Grasping*, section 3). Atoms that meet
    are merged.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning.result import PlanStep
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> (b,) = belief_steps(pb, [PlanStep("squeeze", 0.0)])
    >>> [(round(a, 4), round(p, 4)) for a, p in b]
    [(0.0, 0.1476), (1.5708, 0.3524), (3.1416, 0.1476), (4.7124, 0.3524)]
    """
    import math

    import numpy as np

    out: list[list[tuple[float, float]]] = []
    atoms: dict[float, float] = {}
    two_pi = 2 * math.pi
    for j, step in enumerate(steps):
        f = problem.transfer(step.kind)
        nxt: dict[float, float] = {}
        if j == 0:
            lo = np.asarray(f.basin_lo) + step.alpha
            hi = np.asarray(f.basin_hi) + step.alpha
            pairs = zip(np.asarray(f.stable), problem.prior.mass(lo, hi), strict=True)
        else:
            pts = np.array(list(atoms), dtype=float)
            pairs = zip(f(pts - step.alpha), atoms.values(), strict=True)
        for theta, p in pairs:
            t = float(np.mod(theta, two_pi))
            key = next((k for k in nxt if abs(math.remainder(k - t, two_pi)) < 1e-9), t)
            nxt[key] = nxt.get(key, 0.0) + float(p)
        atoms = nxt
        out.append(sorted(atoms.items()))
    return out


def chosen_beliefs(
    req: FunctionsRequest, part: Any, spec: Any
) -> tuple[Any, Any, str, list[list[tuple[float, float]]]]:
    """The problem, the plan ``req.plan`` names, its label, and the belief after each step.

    Without noise options: the noise-free plan (as ``plot --plan``) and its beliefs
    (:func:`belief_steps`). With them: the plan ``plan`` gives under the noise and payoff
    (:func:`~bayesgrasp.web.problems.noisy_option`) and the exact distribution over the
    stable orientations after each step under the noise
    (:func:`~bayesgrasp.planning.noisy.step_distributions_noisy`), whose mass at the goal
    after the last step is the plan's success probability.
    """
    import numpy as np

    from .problems import chosen_option, noisy_option

    if not req.noisy:
        pb, option, label = chosen_option(req.plan, req, part, spec)
        return pb, option, label, belief_steps(pb, option.steps)
    from ..planning.noisy import step_distributions_noisy

    pb, option, label = noisy_option(req.plan, req, part, spec)
    stable = np.asarray(pb.states.stable, dtype=float)
    qs = step_distributions_noisy(pb, req.noise_model(), option.steps)
    beliefs = [[(float(stable[k]), float(q[k])) for k in np.flatnonzero(q > 0)] for q in qs]
    return pb, option, label, beliefs


def function_samples(service: Any, req: FunctionsRequest, n: int = 721) -> dict[str, Any]:
    """The figures' data: functions sampled at ``n`` angles, the plan and its beliefs.

    ``plan.planner`` says which plan the beliefs follow: ``noise-aware`` (the plan ``plan``
    gives under the request's noise and payoff, its beliefs exact under the noise) or
    ``noise-free``; ``plan.success_probability`` is that plan's, under the noise.
    """
    import math

    import numpy as np

    from ..errors import BayesGraspError
    from ..geometry.curved import CurvedPart, curved_radius, push_model, squeeze_model
    from .problems import problem_spec

    spec = problem_spec(req)
    part = service.part(req.part)
    _, option, label, beliefs = chosen_beliefs(req, part, spec)
    theta = np.linspace(0.0, 2 * math.pi, n)
    deg = np.degrees

    def angles(f: Any) -> list[float]:
        return [round(float(x), 4) for x in deg(np.mod(f(theta), 2 * math.pi))]

    d, s = squeeze_model(part)
    funcs: dict[str, Any] = {
        "diameter": [round(float(x), 6) for x in d(theta)],
        "squeeze": angles(s),
    }
    stable: dict[str, Any] = {"squeeze": [round(float(x), 4) for x in deg(s.stable)]}
    try:
        r, p, g = push_model(part)
        radius = curved_radius(part) if isinstance(part, CurvedPart) else r
        funcs["radius"] = [round(float(x), 6) for x in radius(theta)]
        funcs["push"], funcs["push_grasp"] = angles(p), angles(g)
        stable["push"] = [round(float(x), 4) for x in deg(p.stable)]
        stable["push_grasp"] = [round(float(x), 4) for x in deg(g.stable)]
    except BayesGraspError:  # no stable push: the squeeze figures only
        pass
    return {
        "schema": "bayesgrasp.functions/1",
        "part": part.name,
        "theta_deg": [round(float(x), 4) for x in deg(theta)],
        "functions": funcs,
        "stable_deg": stable,
        "plan": {
            "label": label,
            "planner": "noise-aware" if req.noisy else "noise-free",
            "noise": req.noise_model().describe() if req.noisy else None,
            "payoff": req.payoff is not None,
            "steps": [{"type": st.kind, "alpha_deg": float(deg(st.alpha))} for st in option.steps],
            "final_deg": float(deg(option.final_orientation)),
            "success_probability": float(option.success_probability),
        },
        "belief": [
            [{"orientation_deg": float(deg(a)), "probability": p} for a, p in b] for b in beliefs
        ],
    }


@router.post("/views/functions", responses=ERRORS)
async def functions(req: FunctionsRequest, request: Request) -> Any:
    """The part's functions sampled over a turn and the belief after each step of the plan.

    With ``turn_noise``, ``contact_noise`` or ``payoff``: of the noise-aware plan, under the
    noise (in the heavy lane); ``plan.planner`` says which.
    """
    service = request.app.state.service
    return await service.answer("functions", req)  # in a worker of its lane
