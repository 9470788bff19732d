"""What a policy simulation returns: observed cycles beside the policy's claims.

:class:`PolicySimulation` holds the cycles of :func:`~bayesgrasp.sim.policy.simulate_policy`
or :func:`~bayesgrasp.sim.policy.simulate_policy_mujoco` with their intervals (see
:mod:`bayesgrasp.sim.policy` for the statistics); :func:`policy_simulation_text` and
:func:`policy_simulation_json` present it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..planning.policy import Policy
from .stats import wilson_interval

__all__ = ["PolicySimulation", "policy_simulation_json", "policy_simulation_text"]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

_Z = 4.0  # the intervals' half-width in standard errors (about 1 in 16,000 two-sided)


@dataclass(frozen=True, slots=True, eq=False)
class PolicySimulation:
    """Observed cycles of a policy beside its claims (see the module notes).

    Attributes
    ----------
    engine : str
        ``"kinematic"`` or ``"mujoco"``.
    policy : Policy
    cycles, successes, rejects, jams : int
        Cycles run; those whose declaration was right; those that rejected; those with an
        action that did not settle or stopped away from every stable orientation (MuJoCo;
        a jammed cycle fails unless its declaration happens to hold).
    cycle_costs, actions : ndarray of shape (cycles,)
        Cost of each cycle (retry overhead included) and its number of actions.
    success : ndarray of bool, shape (cycles,)
    reading_errors : ndarray
        ``reading - d(sigma)`` of every reading (part units), ``sigma`` the stable state
        nearest to where the part ended (MuJoCo: of the actions that did not jam).
    seconds : float
        Wall time.
    jaw_lag : float
        MuJoCo: seconds by which one jaw of each squeeze led
        (:attr:`~bayesgrasp.sim.params.SimParams.jaw_lag`; 0: together).
    """

    engine: str
    policy: Policy
    cycles: int
    successes: int
    rejects: int
    jams: int
    cycle_costs: FloatArray
    actions: FloatArray
    success: BoolArray
    reading_errors: FloatArray
    seconds: float
    jaw_lag: float = 0.0

    @property
    def observed_success(self) -> float:
        """Share of cycles that succeeded."""
        return self.successes / self.cycles

    @property
    def success_interval(self) -> tuple[float, float]:
        """Wilson score interval of the success probability, ``z = 4``."""
        from scipy.stats import norm

        return wilson_interval(self.successes, self.cycles, float(1 - 2 * norm.sf(_Z)))

    def _mean_interval(self, x: FloatArray) -> tuple[float, float, float]:
        m = float(x.mean())
        se = float(x.std(ddof=1)) / math.sqrt(len(x)) if len(x) > 1 else math.inf
        return m, m - _Z * se, m + _Z * se

    @property
    def cycle_cost(self) -> tuple[float, float, float]:
        """Mean cycle cost and its CLT interval (``z = 4``)."""
        return self._mean_interval(self.cycle_costs)

    @property
    def mean_actions(self) -> tuple[float, float, float]:
        """Mean number of actions a cycle and its CLT interval."""
        return self._mean_interval(self.actions)

    @property
    def cost_per_success(self) -> tuple[float, float, float]:
        """Total cost over the parts oriented, with the delta method's interval.

        ``inf`` (and an unbounded interval) when no cycle succeeded.
        """
        if self.successes == 0:
            return math.inf, math.inf, math.inf
        s = self.success.astype(np.float64)
        ratio = float(self.cycle_costs.sum() / s.sum())
        resid = self.cycle_costs - ratio * s
        n = self.cycles
        se = float(resid.std(ddof=1)) / math.sqrt(n) / float(s.mean()) if n > 1 else math.inf
        # At least the relative uncertainty of the success probability (Wilson): when no
        # cycle failed the sample variance is 0 but the success rate is not known exactly.
        lo, hi = self.success_interval
        se = max(se, ratio * (hi - lo) / (2.0 * _Z * self.observed_success))
        return ratio, ratio - _Z * se, ratio + _Z * se

    @property
    def agrees(self) -> bool:
        """Every claim of the policy lies in its interval (success, cycle cost, actions, cost)."""
        pol = self.policy
        lo, hi = self.success_interval
        checks = [
            (pol.success_probability, (0.0, lo, hi)),
            (pol.cycle_cost, self.cycle_cost),
            (pol.expected_actions, self.mean_actions),
            (pol.expected_cost, self.cost_per_success),
        ]
        slack = 1e-9
        return all(
            c[1] - slack * (1 + abs(v)) <= v <= c[2] + slack * (1 + abs(v)) for v, c in checks
        )


# -- the kinematic engine -------------------------------------------------------------------


# -- presentation ---------------------------------------------------------------------------


def _figures(sim: PolicySimulation) -> list[tuple[str, float, tuple[float, float, float]]]:
    pol = sim.policy
    lo, hi = sim.success_interval
    return [
        ("success a cycle", pol.success_probability, (sim.observed_success, lo, hi)),
        ("cost a cycle", pol.cycle_cost, sim.cycle_cost),
        ("actions a cycle", pol.expected_actions, sim.mean_actions),
        ("cost per oriented part", pol.expected_cost, sim.cost_per_success),
    ]


def policy_simulation_text(sim: PolicySimulation, title: str = "") -> str:
    """Predicted against observed figures, one line each, with the intervals (``z = 4``)."""
    units = sim.policy.units or "part units"
    e = sim.reading_errors if len(sim.reading_errors) else np.zeros(1)
    lines = [
        f"{title}{sim.cycles} cycles ({sim.engine}), sensor {sim.policy.sensor.spec}, "
        f"{sim.seconds:.2f} s",
        f"{'':24s}{'predicted':>11s}{'observed':>11s}   interval (z = 4)",
    ]
    for name, pred, (obs, lo, hi) in _figures(sim):
        inside = "" if lo - 1e-9 <= pred <= hi + 1e-9 else "   OUTSIDE"
        lines.append(f"{name:24s}{pred:11.4f}{obs:11.4f}   [{lo:.4f}, {hi:.4f}]{inside}")
    lines.append(
        f"rejected cycles {sim.rejects}, jammed cycles {sim.jams}; reading - d(sigma) "
        f"({units}): mean {e.mean():.4g}, sd {e.std():.4g}, largest {np.abs(e).max():.4g}"
    )
    lines.append("every claim within its interval" if sim.agrees else "NOT every claim agrees")
    return "\n".join(lines)


def policy_simulation_json(sim: PolicySimulation) -> dict[str, Any]:
    """``bayesgrasp.policy-simulation/1``: predicted and observed figures with intervals.

    An interval that one cycle cannot bound (or a figure of no cycle) is ``null``.

    A policy planned under noisy actions adds ``noise`` (the model its figures are exact
    under, :meth:`~bayesgrasp.model.noise.NoiseModel.to_json`); a MuJoCo run with a jaw lag
    adds ``jaw_lag_s``.
    """
    e = sim.reading_errors if len(sim.reading_errors) else np.full(1, math.nan)
    keys = ["success_probability", "cycle_cost", "expected_actions", "expected_cost"]

    def num(x: float) -> float | None:  # JSON has no infinity: an unbounded end is null
        return float(x) if math.isfinite(x) else None

    figs = {
        k: {"predicted": num(pred), "observed": num(obs), "interval": [num(lo), num(hi)]}
        for k, (_, pred, (obs, lo, hi)) in zip(keys, _figures(sim), strict=True)
    }
    return {
        "schema": "bayesgrasp.policy-simulation/1",
        "engine": sim.engine,
        "parts": list(sim.policy.parts),
        "sensor": sim.policy.sensor.to_json(),
        **({} if sim.policy.noise is None else {"noise": sim.policy.noise.to_json()}),
        **({"jaw_lag_s": sim.jaw_lag} if sim.jaw_lag > 0 else {}),
        "cycles": sim.cycles,
        "successes": sim.successes,
        "rejects": sim.rejects,
        "jams": sim.jams,
        "z": _Z,
        **figs,
        "reading_error": {
            "mean": num(float(e.mean())),
            "sd": num(float(e.std())),
            "max_abs": num(float(np.abs(e).max())),
            "readings": len(sim.reading_errors),
        },
        "agrees": sim.agrees,
        "seconds": sim.seconds,
    }
