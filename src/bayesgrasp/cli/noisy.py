"""``plan --turn-noise / --contact-noise / --payoff``: the Bayes plan under noise (and a payoff).

The options are declared in :mod:`.options` (``plan`` and ``simulate`` load this module only
when they are given); this module parses them (:meth:`NoisyRun.of`), calls
:func:`~bayesgrasp.planning.noisy.plan_noisy` and prints. ``plan`` gives every one of its
surfaces the noise-aware plan: the table or ``--json``, ``--only best``, ``--guaranteed``
(:func:`~bayesgrasp.planning.robust.plan_guaranteed_noisy`), ``--plot`` (the distributions
under the noise), ``--export`` (the robot file, with the noise model in its header) and
several parts or ``--batch`` (:func:`~bayesgrasp.cli.batch.run_batch`, one document a line),
all through :mod:`.strategies` (:func:`strategy_run`). :class:`NoisyRun` is the run of
:mod:`bayesgrasp.runs.noisy` (the plot command, the web service and sweeps make the same),
with the command line's parsing and files.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..io.plans import noisy_plan_document
from ..runs import noisy as runs
from ..runs.noisy import Planned
from .strategies import StrategyRun, noisy_text

noisy_document = noisy_plan_document  # the document is written by io.plans

if TYPE_CHECKING:
    from ..model.noise import NoiseModel, TurnNoise
    from ..model.problem import Problem
    from ..planning.noisy import NoisyPlanResult
    from ..runs.specs import ProblemSpec
    from .outputs import PartOutputs

__all__ = [
    "NoisyRun",
    "Planned",
    "asked",
    "noise_model",
    "noisy_document",
    "noisy_text",
    "strategy_run",
    "turn_noise",
]


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


def strategy_run(
    spec: ProblemSpec,
    turn: str | None,
    contact: float | None,
    payoff: Path | None,
    best_only: bool = False,
    guaranteed: bool = False,
) -> StrategyRun:
    """The run of ``plan``'s options (:class:`~.strategies.StrategyRun`).

    The noise-aware planner when a noise or payoff option was given (checked by
    :meth:`NoisyRun.of`), else the problem's own planner.
    """
    if asked(turn, contact, payoff):
        return NoisyRun.of(spec, turn, contact, payoff, best_only, guaranteed).strategy_run(spec)
    return StrategyRun(spec, best_only, guaranteed)


def noise_model(turn: str | None, contact: float | None) -> NoiseModel:
    """The noise model of the options."""
    from ..model.noise import NoiseModel

    return NoiseModel(turn_noise(turn), contact or 0.0)


@dataclass(frozen=True, slots=True)
class NoisyRun(runs.NoisyRun):
    """The noise options of a ``plan`` run, parsed once for all its parts.

    :class:`bayesgrasp.runs.noisy.NoisyRun` (planning, documents), made from the command
    line's options (:meth:`of`) and writing its files (:meth:`write_outputs`).
    """

    @classmethod
    def of(
        cls,
        spec: ProblemSpec,
        turn: str | None,
        contact: float | None,
        payoff: Path | None,
        best_only: bool = False,
        guaranteed: bool = False,
    ) -> NoisyRun:
        """Parse and check the options before any work (bad input: exit 2, one line).

        ``--guaranteed`` under a normal turn error is refused: no plan of two or more
        actions can guarantee under an unbounded error
        (:data:`~bayesgrasp.planning.robust.UNBOUNDED_GUARANTEE`).
        """
        from ..model.payoff import read_payoff
        from ..planning.robust import UNBOUNDED_GUARANTEE

        if spec.method.value != "exact":
            raise typer.BadParameter(
                "the noise-aware planner seeds from the exact planner; drop --method",
                param_hint="--method",
            )
        noise = noise_model(turn, contact)
        if guaranteed and not noise.turn.exact and noise.turn.kind == "normal":
            raise typer.BadParameter(UNBOUNDED_GUARANTEE, param_hint="--guaranteed")
        u = read_payoff(payoff) if payoff is not None else None
        return cls(noise, u, spec.max_actions, best_only, guaranteed)

    def strategy_run(self, spec: ProblemSpec) -> StrategyRun:
        """The run of these options (:class:`~.strategies.StrategyRun`, the noise-aware planner)."""
        return StrategyRun(
            spec, self.best_only, self.guaranteed, self.noise, self.payoff, noisy=True
        )

    def write_outputs(
        self, outputs: PartOutputs, index: int, pb: Problem, res: NoisyPlanResult
    ) -> None:
        """Write the part's ``--plot`` (under the noise) and ``--export`` files."""
        from ..figures.plans import noisy_plan_figure
        from ..io.export import write_robot

        def robot(path: Path) -> None:
            write_robot(path, pb, res.bayes_plan.option, self.robot_metadata(res))

        outputs.write(pb.part.name, index, lambda: noisy_plan_figure(res), robot)
