"""``plan --turn-noise / --contact-noise / --payoff``: the Bayes plan under noise (and a payoff).

The options are declared in :mod:`.options` (``plan`` and ``simulate`` load this module only
when they are given); this module parses them, calls
:func:`~bayesgrasp.planning.noisy.plan_noisy` and prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from .common import emit_json

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.noise import NoiseModel, TurnNoise
    from ..planning.noisy import NoisyPlanResult
    from .specs import ProblemSpec


def asked(turn: str | None, contact: float | None, payoff: Path | None) -> bool:
    """Whether any of the noise or payoff options was given."""
    return turn is not None or contact is not None or payoff is not None


def turn_noise(spec: str | None) -> TurnNoise:
    """The turn error of ``--turn-noise`` (none when not given); bad text is exit 2."""
    from ..errors import PlanningError
    from ..model.noise import TurnNoise, parse_turn_noise

    if spec is None:
        return TurnNoise()
    try:
        return parse_turn_noise(spec)
    except PlanningError as exc:
        raise typer.BadParameter(str(exc), param_hint="--turn-noise") from None


def noise_model(turn: str | None, contact: float | None) -> NoiseModel:
    """The noise model of the options."""
    from ..model.noise import NoiseModel

    return NoiseModel(turn_noise(turn), contact or 0.0)


def noisy_document(res: NoisyPlanResult) -> dict[str, Any]:
    """The plan document of a noisy result: the usual fields plus the noise and payoff."""
    from ..io.plans import json_float, plan_document

    doc = plan_document(res.plan_result())
    bayes = res.bayes_plan
    doc["expected_payoff"] = bayes.expected_payoff
    doc["expected_cost_per_unit_payoff"] = json_float(bayes.evaluation.expected_cost)
    doc.update(res.to_json())
    return doc


def noisy_text(res: NoisyPlanResult) -> str:
    """The plan table, then the payoff and noise-free probability of each plan."""
    from .. import report

    lines = [report.plan_table(res.plan_result())]
    lines.append(
        f"noise: {res.noise.describe()}; P(success) and E[cost] are exact under it"
        + ("" if res.payoff is None else "; E[cost] is per unit payoff")
    )
    lines.append("no noise: the same steps' E[payoff] with exact actions")
    lines.append(f"{'k':>3} {'E[payoff]':>10} {'no noise':>10}  source")
    for o in res.options:
        lines.append(
            f"{o.option.n_actions:>3} {o.expected_payoff:10.4f} "
            f"{o.noise_free_probability:10.4f}  {o.source}"
        )
    lines.append(
        f"{res.candidates} plans evaluated; no single turn of a refined plan gains more than "
        f"{res.refinement_bound:.2g} in E[payoff]"
    )
    return "\n".join(lines)


def plan_noisy_command(
    part: Part,
    spec: ProblemSpec,
    turn: str | None,
    contact: float | None,
    payoff: Path | None,
    as_json: bool,
) -> None:
    """``plan`` with the noise and payoff options: plan, print."""
    from ..model.payoff import read_payoff
    from ..planning.noisy import plan_noisy

    if spec.method.value != "exact":
        raise typer.BadParameter(
            "the noise-aware planner seeds from the exact planner; drop --method",
            param_hint="--method",
        )
    noise = noise_model(turn, contact)
    pb = spec.build(part)
    u = read_payoff(payoff) if payoff is not None else None
    res = plan_noisy(pb, noise, u, spec.max_actions)
    if as_json:
        emit_json(noisy_document(res))
    else:
        typer.echo(noisy_text(res))
