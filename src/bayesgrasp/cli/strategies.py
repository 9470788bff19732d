"""``plan``'s one way through every planner: plan, print, check the stroke, write the files.

A :class:`StrategyRun` holds the options of a ``plan`` run, parsed once for all its parts;
:meth:`StrategyRun.solve` plans a part (or a policy's candidates) through the planners' one
front door (:func:`~bayesgrasp.planning.strategy.solve`) and returns one
:class:`~bayesgrasp.planning.strategy.StrategyResult`, whatever the strategy: the exact,
breadth-first or guaranteed planner's plans, the noise-aware plans (``--turn-noise``,
``--contact-noise``, ``--payoff``) or a sensing policy (``--sense``). Every surface of
``plan`` then takes the result alike: :func:`document` (``--json``, ``--batch`` lines),
:func:`text` (the table), :func:`check_stroke` (``--max-opening``, ``--min-opening``) and
:func:`write_outputs` (``--plot``, ``--export``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..runs.strategies import check_stroke, document, robot_metadata

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.noise import NoiseModel
    from ..model.payoff import Payoff
    from ..model.problem import Problem
    from ..model.sensing import WidthSensor
    from ..planning.noisy import NoisyPlanResult
    from ..planning.strategy import StrategyResult
    from .outputs import PartOutputs
    from .specs import ProblemSpec, SenseSpec

__all__ = ["StrategyRun", "check_stroke", "document", "noisy_text", "text", "write_outputs"]


@dataclass(frozen=True)
class StrategyRun:
    """What a ``plan`` run asks of the planners (the options, parsed and checked).

    Attributes
    ----------
    spec : ProblemSpec
        The problem options (prior, costs, goal, actions, accuracy, method, longest plan).
    best_only : bool
        ``--only best``.
    guaranteed : bool
        ``--guaranteed``.
    noise : NoiseModel or None
        The action noise (``None``: exact actions and no noise-aware planner, unless
        ``noisy``).
    payoff : Payoff or None
    noisy : bool
        Whether a noise or payoff option was given (the noise-aware planner then plans).
    sensing : SenseSpec or None
        ``--sense`` and its options: a policy is planned.
    stroke : (float, float) or None
        ``--within-stroke``: ``(min_opening, max_opening)``, plans only of actions within it.
    """

    spec: ProblemSpec
    best_only: bool = False
    guaranteed: bool = False
    noise: NoiseModel | None = None
    payoff: Payoff | None = None
    noisy: bool = False
    sensing: SenseSpec | None = None
    stroke: tuple[float, float] | None = None

    def solve(
        self, problems: Problem | list[Problem], sensor: WidthSensor | None = None
    ) -> StrategyResult:
        """The strategy of a problem (a policy: of its candidates' problems).

        ``sensor`` replaces the ``--sense`` sensor (MuJoCo's reading error).
        """
        from ..model.noise import NoiseModel
        from ..planning.strategy import solve

        sensing = self.sensing
        if sensing is not None:
            from .common import with_progress

            exact = self.noise is None and self.payoff is None  # the time-bounded search
            return with_progress(  # type: ignore[no-any-return]
                "policy search (seconds of --time-limit)",
                math.ceil(sensing.time_limit_s),
                lambda progress: solve(
                    problems,
                    sensor=sensing.sense if sensor is None else sensor,
                    noise=self.noise,
                    payoff=self.payoff,
                    max_actions=sensing.max_actions,
                    part_prior=sensing.part_prior,
                    max_memory_mb=sensing.max_memory_mb,
                    time_limit_s=sensing.time_limit_s,
                    progress=progress if exact else None,
                ),
            )
        spec = self.spec
        noise = (self.noise or NoiseModel()) if self.noisy else None
        return solve(
            problems,
            method=spec.method.value,
            noise=noise,
            payoff=self.payoff,
            max_actions=spec.max_actions,
            best_only=self.best_only,
            guaranteed=self.guaranteed,
            stroke=self.stroke,
        )

    def solve_parts(self, parts: list[Part], sensor: WidthSensor | None = None) -> StrategyResult:
        """:meth:`solve` of parts (each built into its problem by the problem options)."""
        problems = [self.spec.build(p) for p in parts]
        return self.solve(problems if self.sensing is not None else problems[0], sensor)


def text(result: StrategyResult, max_actions: int | None = None, fold_below: float = 0.0) -> str:
    """The result as ``plan`` prints it without ``--json``.

    Plans: the table (with noise, each plan's payoff and noise-free probability), then the
    guaranteed plan or why there is none. A policy: its tree (leaving out the branches below
    ``fold_below`` at their node) and its figures.
    """
    from .. import report
    from ..planning.noisy import NoisyPlanResult
    from ..planning.policy import Policy

    src = result.source
    if isinstance(src, Policy):
        return _policy_text(src, result.problem.part.units, fold_below)
    if isinstance(src, NoisyPlanResult):
        lines = [noisy_text(src)]
    else:
        lines = [report.plan_table(src, max_actions)]
    if result.guaranteed is not None:
        lines.append(report.guaranteed_text(result.guaranteed))
        if isinstance(src, NoisyPlanResult) and not src.noise.exact:
            lines.append(f"(guaranteed under {src.noise.describe()})")
    if result.guaranteed_missing is not None:
        lines.append(f"Guaranteed plan: none ({result.guaranteed_missing})")
    return "\n".join(lines)


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


def _policy_text(pol: Any, units: str | None, fold_below: float) -> str:
    """A policy's tree and figures, as ``plan --sense`` prints them."""
    from ..planning.policy import policy_text

    lines = [policy_text(pol, units=units, min_probability=fold_below)]
    entropy = ", ".join(f"{h:.3f}" for h in pol.expected_entropy)
    blind = pol.sensorless_cost
    under = "" if pol.noise is None else " under the noise"
    versus = "" if blind is None else f" (sensorless Bayes plan{under} {blind:.4f})"
    lines.append(
        f"expected cost {pol.expected_cost:.4f}{versus}, "
        f"success {pol.success_probability:.4f} a cycle, "
        f"{pol.expected_actions:.3f} actions a cycle; expected entropy after each level "
        f"(bits): {entropy}"
    )
    if not pol.complete:
        lines.append(
            f"search stopped: {pol.stopped}. This is the best policy of at most "
            f"{_actions(pol.max_actions)} (the deepest search that finished); no policy of "
            f"{_actions(pol.requested_actions)} costs less than {pol.lower_bound:.4f}"
        )
    if pol.payoff is not None:
        lines.append("payoff: success is the expected payoff earned, the cost is per unit payoff")
    if pol.noise is not None:
        lines.append(
            f"noise: {pol.noise.describe()}; every figure is exact under it; no single turn "
            f"lowers the cost's value by more than {pol.refinement_bound:.2g}"
        )
    return "\n".join(lines)


def _actions(n: int) -> str:
    return f"{n} action" if n == 1 else f"{n} actions"


def exit_code(result: StrategyResult) -> int:
    """1 when a guaranteed plan was asked for and none exists, else 0."""
    return 0 if result.guaranteed_missing is None else 1


def write_outputs(
    outputs: PartOutputs, index: int, result: StrategyResult, fold: float | None = None
) -> None:
    """Write a part's ``--plot`` and ``--export`` files, whatever its strategy.

    The figure: the plan figure (under the noise, with noise), or a policy's tree as ``plot
    --sense`` draws it (``fold``: its ``min_probability``, default the figure's own). The
    robot file: the Bayes plan, or the policy's state machine, with the noise and payoff.
    """
    from ..io.export import write_robot
    from ..planning.noisy import NoisyPlanResult
    from ..planning.policy import Policy

    src = result.source
    problems: Problem | list[Problem] = result.problem

    def figure() -> Any:
        if isinstance(src, Policy):
            from ..figures.policy import policy_figure

            if fold is None:
                return policy_figure(list(result.problems), src)
            return policy_figure(list(result.problems), src, min_probability=fold)
        from ..figures.plans import noisy_plan_figure, plan_figure

        if isinstance(src, NoisyPlanResult):
            return noisy_plan_figure(src)
        return plan_figure(src)

    if isinstance(src, Policy):
        problems = list(result.problems)

    def robot(path: Path) -> None:
        write_robot(path, problems, result.robot_strategy, robot_metadata(result))

    outputs.write(result.problem.part.name, index, figure, robot)
