"""What the noise-aware planner returns: the best plan of each length under the noise.

:class:`NoisyPlanResult` (of :func:`~bayesgrasp.planning.noisy.plan_noisy`) holds a
:class:`NoisyOption` per length, each a plan with its exact evaluation under the noise
(:class:`~bayesgrasp.planning.noisy_evaluation.NoisyEvaluation`), and reads as a
:class:`~bayesgrasp.planning.result.PlanResult` for tables, files and simulation.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..model.noise import NoiseModel
from ..model.problem import Problem
from .noisy_evaluation import NoisyEvaluation
from .result import PlanOption, PlanResult

__all__ = ["NoisyOption", "NoisyPlanResult"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class NoisyOption:
    """The best plan of one length under the noise.

    Attributes
    ----------
    option : PlanOption
        Its steps and final orientation; ``success_probability`` and ``expected_cost``
        (per unit payoff) under the noise; ``tolerance``: with exact turns (contact noise
        alone) the plan's margin, the least distance of a turn to a basin boundary of a
        state of positive probability before it (see the module notes; ``None`` for one
        action), ``None`` under a turn error (the noise is in the probability already);
        ``success_arc`` the noise-free one of its steps.
    evaluation : NoisyEvaluation
    noise_free_probability : float
        The same steps' success probability with exact actions (same target).
    source : str
        Where the plan came from: ``"exact"``, ``"accuracy"`` (a robust exact plan),
        ``"search"`` (hyperstate search), with ``"+refined"`` if refinement moved it
        (or a turn was moved off an unstable equilibrium).
    """

    option: PlanOption
    evaluation: NoisyEvaluation
    noise_free_probability: float
    source: str

    @property
    def expected_payoff(self) -> float:
        """Expected payoff of one attempt."""
        return self.evaluation.expected_payoff


@dataclass(frozen=True, slots=True, eq=False)
class NoisyPlanResult:
    """What :func:`~bayesgrasp.planning.noisy.plan_noisy` found: the best plan of each length.

    Attributes
    ----------
    problem : Problem
    noise : NoiseModel
    payoff : ndarray of shape (K,) or None
        The payoff of each state (``None``: the problem's goal).
    options : tuple of NoisyOption
        ``options[k - 1]``: the best plan of ``k`` actions found.
    bayes, most_certain : int
        Least cost per unit payoff; highest expected payoff.
    candidates : int
        Plans evaluated exactly.
    refinement_bound : float
        ``eps``: no single turn of a refined plan can gain more expected payoff.
    payoff_bound : float
        The highest expected payoff any plan can reach, used to stop the length search.
    """

    problem: Problem
    noise: NoiseModel
    payoff: FloatArray | None
    options: tuple[NoisyOption, ...]
    bayes: int
    most_certain: int
    candidates: int
    refinement_bound: float
    payoff_bound: float

    @property
    def bayes_plan(self) -> NoisyOption:
        """The plan of least expected cost per unit payoff."""
        return self.options[self.bayes]

    def plan_result(self) -> PlanResult:
        """As a :class:`PlanResult` (method ``"noisy"``) for tables, files and simulation."""
        return PlanResult(
            self.problem,
            tuple(o.option for o in self.options),
            self.bayes,
            self.most_certain,
            "noisy",
        )

    def best_only(self) -> NoisyPlanResult:
        """The same result with only the Bayes and the most certain plans (in length order).

        As :meth:`~bayesgrasp.planning.result.PlanResult.best_only`: one plan when they are
        the same.

        Examples
        --------
        >>> from bayesgrasp.geometry.polygon import Part
        >>> from bayesgrasp.model.noise import TurnNoise
        >>> from bayesgrasp.planning.noisy import plan_noisy
        >>> rect = Part.from_points([(0, 0), (1.55, 0), (1.55, 1), (0, 1)])
        >>> res = plan_noisy(Problem.build(rect), NoiseModel(TurnNoise("uniform", 0.05)))
        >>> best = res.best_only()
        >>> [o.option.n_actions for o in best.options], best.bayes, best.most_certain
        ([2], 0, 0)
        """
        keep = sorted({self.bayes, self.most_certain})
        return dataclasses.replace(
            self,
            options=tuple(self.options[i] for i in keep),
            bayes=keep.index(self.bayes),
            most_certain=keep.index(self.most_certain),
        )

    def to_json(self) -> dict[str, Any]:
        """The noise-specific part of a plan document."""
        return {
            "noise": self.noise.to_json(),
            "payoff": None if self.payoff is None else self.payoff.tolist(),
            "candidates": self.candidates,
            "refinement_bound": self.refinement_bound,
            "payoff_bound": self.payoff_bound,
            "noisy_options": [
                {
                    "expected_payoff": o.expected_payoff,
                    "cost_per_unit_payoff": _json_float(o.evaluation.expected_cost),
                    "success_probability": o.evaluation.success_probability,
                    "noise_free_probability": o.noise_free_probability,
                    "final_distribution": o.evaluation.distribution.tolist(),
                    "source": o.source,
                }
                for o in self.options
            ],
        }


def _json_float(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None
