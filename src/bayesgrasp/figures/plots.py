"""The figures' former single module, kept so that old imports keep working.

Import from :mod:`bayesgrasp.figures` instead: the figures now live in :mod:`.part`,
:mod:`.functions`, :mod:`.plans`, :mod:`.animation` and :mod:`.files`.
"""

from .animation import PlanAnimation, plan_animation, save_animation
from .files import write_figures
from .functions import diameter_figure, nearest_state_mod_pi, transfer_figure
from .part import part_figure
from .plans import evolution_figure, plan_figure, step_distributions

__all__ = [
    "PlanAnimation",
    "diameter_figure",
    "evolution_figure",
    "nearest_state_mod_pi",
    "part_figure",
    "plan_animation",
    "plan_figure",
    "save_animation",
    "step_distributions",
    "transfer_figure",
    "write_figures",
]
