"""Figures and animations of parts, their functions and plans (optional extra ``plot``).

Matplotlib is imported only inside the functions that draw; without it they raise
:class:`~bayesgrasp.errors.MissingExtraError`.
"""

from .plots import (
    PlanAnimation,
    diameter_figure,
    evolution_figure,
    part_figure,
    plan_animation,
    plan_figure,
    save_animation,
    transfer_figure,
    write_figures,
)

__all__ = [
    "PlanAnimation",
    "diameter_figure",
    "evolution_figure",
    "part_figure",
    "plan_animation",
    "plan_figure",
    "save_animation",
    "transfer_figure",
    "write_figures",
]
