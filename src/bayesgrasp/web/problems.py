"""From a request's options to the problem the command line would build.

:func:`problem_spec` makes the :class:`~bayesgrasp.runs.specs.ProblemSpec` of ``plan``'s
options, :func:`build_problem` the problem (with an inline histogram or sample prior),
:func:`chosen_option` the plan ``--plan`` names (:func:`noisy_option` under the noise),
:func:`given_option` the plan of a plan document, :func:`stroke_of` the gripper's stroke.
Options the command line would refuse are refused here with its reasons (422).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ..errors import NoPlanError
from .models import NoiseOptions, PartRequest, ProblemOptions, StrokeOptions
from .workers import LimitError

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..io.export import Stroke
    from ..model.problem import Problem
    from ..planning.result import PlanOption

__all__ = [
    "build_problem",
    "check_within_stroke",
    "chosen_option",
    "exact_method",
    "given_option",
    "noisy_option",
    "prior_string",
    "problem_spec",
    "stroke_of",
]


def prior_string(opts: PartRequest | ProblemOptions) -> str:
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
    """The :class:`~bayesgrasp.runs.specs.ProblemSpec` the command line makes of these options."""
    from ..model.actions import get_action
    from ..runs.specs import GoalKind, Method, ProblemSpec

    for name in (*opts.costs, *opts.first_costs):
        get_action(name)  # an unknown action: PlanningError naming the known ones
    given = {k for k in ("prior", "goal") if k in opts.model_fields_set}
    if opts.prior_histogram is not None or opts.prior_sample is not None:
        given.add("prior")
    if isinstance(opts.actions, str):
        actions = [a.strip() for a in opts.actions.split(",") if a.strip()]
    else:
        actions = [a.strip() for a in opts.actions if a.strip()]
    return ProblemSpec(
        prior=prior_string(opts),
        costs=dict(opts.costs),
        first=dict(opts.first_costs),
        verify=opts.verify_cost,
        retry=opts.retry_cost,
        goal=GoalKind(opts.goal),
        actions=tuple(dict.fromkeys(actions)),
        accuracy_deg=opts.accuracy,
        method=Method(opts.method),
        max_actions=opts.max_actions,
        given=frozenset(given),
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
    from ..runs.specs import PLAN_NAMES, guaranteed_plan

    problem = build_problem(part, opts, spec)
    if which == "guaranteed":
        found = guaranteed_plan(problem)
        if isinstance(found, str):
            raise NoPlanError(found)
        return problem, found.option, PLAN_NAMES[which]
    result = spec.plan(problem)
    plan = result.bayes_plan if which == "bayes" else result.most_certain_plan
    return problem, plan, PLAN_NAMES[which]


def noisy_option(
    which: str, opts: NoiseOptions, part: Part, spec: Any
) -> tuple[Problem, PlanOption, str]:
    """The problem and the plan ``which`` names under the request's noise and payoff.

    The plans ``plan`` gives with the same options (:func:`bayesgrasp.planning.solve`):
    ``bayes`` and ``most-certain`` of the noise-aware planner, ``guaranteed`` the plan
    guaranteed under a bounded turn error (a normal error bounds none: 422). Their success
    probabilities and costs are those under the noise.
    """
    from ..planning.noisy import NoisyPlanResult
    from ..planning.robust import UNBOUNDED_GUARANTEE
    from ..planning.strategy import solve
    from ..runs.specs import PLAN_NAMES

    exact_method(opts)
    noise = opts.noise_model()
    sure = which == "guaranteed"
    if sure and not noise.turn.exact and noise.turn.kind == "normal":
        raise LimitError(422, f"`plan`: guaranteed: {UNBOUNDED_GUARANTEE}")
    pb = build_problem(part, opts, spec)
    result = solve(
        pb, noise=noise, payoff=opts.payoff_model(), max_actions=spec.max_actions, guaranteed=sure
    )
    src = result.source
    assert isinstance(src, NoisyPlanResult)
    if sure:
        if result.guaranteed is None:
            raise NoPlanError(result.guaranteed_missing or "no guaranteed plan")
        return pb, result.guaranteed.option, "noise-aware guaranteed"  # as plot names it
    option = src.options[src.bayes if which == "bayes" else src.most_certain].option
    return pb, option, PLAN_NAMES[which]


def given_option(
    doc: Mapping[str, Any], opts: ProblemOptions, part: Part, spec: Any
) -> tuple[Problem, PlanOption]:
    """The problem and the plan of a plan document or option object (``--plan FILE.json``).

    A document made for another part is refused (the command line's ``--force`` has no
    counterpart here); the document's goal and prior apply unless the request gave its own
    (:func:`~bayesgrasp.runs.specs.spec_for_plan`).
    """
    from ..io.plans import part_id, read_plan, same_part
    from ..runs.specs import spec_for_plan

    src = read_plan(doc)
    if same_part(src.part, part) is False:
        theirs = src.part or {}
        raise LimitError(
            422,
            f"`plan`: the plan document is for part {theirs.get('name', '?')!r} "
            f"({theirs.get('id', 'other vertices')}), not {part.name!r} ({part_id(part)})",
        )
    spec, prior = spec_for_plan(src, spec)
    problem = build_problem(part, opts, spec) if prior is None else spec.build(part, (), prior)
    return problem, src.option


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


def exact_method(req: ProblemOptions) -> None:
    """Refuse a planner ``method`` beside the noise options (the noise-aware planner is exact)."""
    if req.method != "exact":
        raise LimitError(
            422, "`method`: the noise-aware planner seeds from the exact planner; drop `method`"
        )
