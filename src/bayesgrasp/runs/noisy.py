"""The noise-aware plans of a problem (turn and contact noise, a payoff) and their document.

:class:`NoisyRun` holds the noise options of a run, parsed once for all its parts, and plans
each problem through the planners' front door (:func:`~bayesgrasp.planning.strategy.solve`);
the command line (``plan --turn-noise ...``), the web service and sweeps make the same run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..model.noise import NoiseModel
    from ..model.payoff import Payoff
    from ..model.problem import Problem
    from ..planning.guaranteed import GuaranteedPlan
    from ..planning.noisy import NoisyPlanResult
    from ..planning.strategy import StrategyResult

__all__ = ["NoisyRun", "Planned"]

#: A noise-aware plan and its guaranteed plan (or the reason there is none, or not asked).
Planned = tuple["NoisyPlanResult", "GuaranteedPlan | str | None"]


@dataclass(frozen=True, slots=True)
class NoisyRun:
    """The noise options of a run, parsed once for all its parts.

    Attributes
    ----------
    noise : NoiseModel
        The action noise the plans are made for.
    payoff : Payoff or None
        The payoff of each final orientation (``None``: the goal's success).
    max_actions : int or None
        The longest plan.
    best_only : bool
        Only the Bayes and the most certain plans.
    guaranteed : bool
        Also the plan guaranteed under the noise (or why there is none).
    """

    noise: NoiseModel
    payoff: Payoff | None
    max_actions: int | None
    best_only: bool
    guaranteed: bool

    def solve(self, pb: Problem) -> StrategyResult:
        """The noise-aware plans of a problem, and its guaranteed plan under the noise."""
        from ..planning.strategy import solve

        return solve(
            pb,
            noise=self.noise,
            payoff=self.payoff,
            max_actions=self.max_actions,
            best_only=self.best_only,
            guaranteed=self.guaranteed,
        )

    def plan(self, pb: Problem) -> Planned:
        """:meth:`solve` as the pair (noise-aware plans, guaranteed plan or why none)."""
        from ..planning.noisy import NoisyPlanResult

        res = self.solve(pb)
        if not isinstance(res.source, NoisyPlanResult):  # solve() with noise plans noisily
            raise TypeError(f"expected noise-aware plans; got {type(res.source).__name__}")
        found = res.guaranteed if res.guaranteed_missing is None else res.guaranteed_missing
        return res.source, found

    def document(
        self, done: Planned | StrategyResult, inputs: dict[str, Any] | None = None
    ) -> dict[str, Any]:
        """The plan document (``plan --json``) of a planned part."""
        from ..io.plans import noisy_plan_document, strategy_document

        if isinstance(done, tuple):
            res, found = done
            sure, missing = (None, found) if isinstance(found, str) else (found, None)
            return noisy_plan_document(
                res, guaranteed=sure, guaranteed_missing=missing, inputs=inputs
            )
        return strategy_document(done, inputs=inputs)

    def robot_metadata(self, res: NoisyPlanResult) -> dict[str, Any]:
        """What a robot file of the plan says about the noise it was planned for."""
        meta: dict[str, Any] = {"noise": self.noise.to_json()}
        if res.payoff is not None:
            meta["payoff"] = res.payoff.tolist()
        return meta
