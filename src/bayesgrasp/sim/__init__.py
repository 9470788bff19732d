"""Physics execution of plans (optional extra ``sim``: MuJoCo, pinned to 4.0.0).

MuJoCo is imported only inside the functions that run it; without it they raise
:class:`~bayesgrasp.errors.MissingExtraError`.
"""

from .engine import ActionOutcome, Squeezer, require_mujoco, simulate_mujoco
from .params import SimParams
from .scene import Prism, part_inertia, prism, scene_xml, units_scale

__all__ = [
    "ActionOutcome",
    "Prism",
    "SimParams",
    "Squeezer",
    "part_inertia",
    "prism",
    "require_mujoco",
    "scene_xml",
    "simulate_mujoco",
    "units_scale",
]
