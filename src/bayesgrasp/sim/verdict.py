"""The verdict on a simulation: whether the prediction lies in the observed intervals.

:func:`verdict_lines` prints it under a simulation's table and :func:`verdict_document`
adds it to the simulation's JSON document; both read a
:class:`~bayesgrasp.sim.result.SimulationResult`, whose :attr:`agrees
<bayesgrasp.sim.result.SimulationResult.agrees>` compares the predicted success (and
expected payoff) with the intervals at ``z =`` :data:`VERDICT_Z`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .result import SimulationResult

__all__ = ["VERDICT_Z", "confidence", "verdict_document", "verdict_lines"]

VERDICT_Z = 4.0
"""Standard deviations of the intervals the verdict reads (as the policy simulation's)."""


def verdict_document(res: SimulationResult) -> dict[str, Any]:
    """The fields a simulation document adds for its noise, payoff and verdict.

    ``noise`` (the model the prediction is exact under), ``success_interval`` (Wilson, at
    ``z``), ``agrees`` and, with a payoff, ``payoff`` (predicted, observed mean, its 95%
    and ``z`` intervals, the values) and ``cost_per_unit_payoff``. Infinities are null.

    Examples
    --------
    >>> import numpy as np
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning.result import PlanOption, PlanStep
    >>> from bayesgrasp.sim.result import summarize
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> opt = PlanOption((PlanStep("squeeze", 0.0),), 0.0, 0.25, 8.0, None, (0.0, 1.0))
    >>> r = summarize("kinematic", pb, opt, np.zeros(4), np.zeros(4, bool), np.zeros(4, bool),
    ...               1.0, 1e-6, payoff=np.array([1.0, 0.5, 0.0, 0.0]))
    >>> d = verdict_document(r)
    >>> round(d["payoff"]["predicted"], 4), d["payoff"]["observed"], d["agrees"]
    (0.3238, 1.0, True)
    """
    lo, hi = res.success_interval
    out: dict[str, Any] = {
        "noise": res.noise.to_json(),
        "z": VERDICT_Z,
        "success_interval": [lo, hi],
    }
    if res.payoff is not None:
        u = res.payoff
        pred, obs, clo, chi = res.cost_per_unit_payoff()
        out["payoff"] = {
            "predicted": res.predicted_payoff,
            "observed": res.observed_payoff,
            "ci95": list(res.payoff_interval()),
            "interval": list(res.payoff_interval(VERDICT_Z)),
            "values": [
                {"orientation_rad": float(res.orientations[i]), "value": float(u[i])}
                for i in np.flatnonzero(u > 0)
            ],
        }
        out["cost_per_unit_payoff"] = {
            "predicted": _finite(pred),
            "observed": _finite(obs),
            "ci95": [_finite(clo), _finite(chi)],
        }
    if res.engine != "kinematic":
        out["ci95"] = list(res.ci95)
        out["prediction_interval95"] = list(res.prediction_interval)
        out["success_p_value"] = res.success_p_value
        out["assumption_flags"] = res.assumption_flags
    out["agrees"] = res.agrees
    return out


def verdict_lines(res: SimulationResult) -> list[str]:
    """The payoff comparison (with a payoff) and the verdict, for the simulation's table.

    Examples
    --------
    >>> from bayesgrasp.geometry.polygon import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> from bayesgrasp.planning import plan_exact
    >>> from bayesgrasp.sim.kinematic import simulate_kinematic
    >>> pb = Problem.build(Part.from_points([(0, 0), (31, 0), (31, 20), (0, 20)]))
    >>> verdict_lines(simulate_kinematic(pb, plan_exact(pb).bayes_plan, 1000, rng=0))
    ['verdict: agrees: predicted success 0.5000 within [0.4127, 0.5381] (z = 4)']
    """
    lines = []
    claims = [("success", res.predicted_success, res.success_interval)]
    if res.payoff is not None:
        lo, hi = res.payoff_interval()
        pred, obs, clo, chi = res.cost_per_unit_payoff()
        lines += [
            f"payoff: predicted E[payoff] {res.predicted_payoff:.4f}, observed mean "
            f"{res.observed_payoff:.4f}, 95% interval [{lo:.4f}, {hi:.4f}]",
            f"cost per unit payoff: predicted {pred:.4g}, observed {obs:.4g}, "
            f"95% interval [{clo:.4g}, {chi:.4g}]",
        ]
        claims.insert(0, ("E[payoff]", res.predicted_payoff, res.payoff_interval(VERDICT_Z)))
    said = "; ".join(
        f"predicted {name} {v:.4f} {'within' if lo - 1e-9 <= v <= hi + 1e-9 else 'outside'} "
        f"[{lo:.4f}, {hi:.4f}]"
        for name, v, (lo, hi) in claims
    )
    word = "agrees" if res.agrees else "DISAGREES"
    if res.engine != "kinematic":
        lo, hi = res.ci95
        plo, phi = res.prediction_interval
        lines.append(
            f"success, every trial counted (a jam is a failure): observed "
            f"{res.observed_success:.4f} ({res.successes}/{res.trials}), 95% interval "
            f"[{lo:.4f}, {hi:.4f}]; predicted {res.predicted_success:.4f}, 95% of runs of "
            f"{res.trials} trials in [{plo:.4f}, {phi:.4f}]; p = {res.success_p_value:.3g}"
        )
        lines += [f"model assumptions break: {f}" for f in res.assumption_flags]
    lines.append(f"verdict: {word}: {said} (z = {VERDICT_Z:g})")
    return lines


def confidence(z: float) -> float:
    """The two-sided coverage of ``+- z`` standard deviations.

    Examples
    --------
    >>> round(confidence(1.959963984540054), 6)
    0.95
    """
    return math.erf(z / math.sqrt(2.0))


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None
