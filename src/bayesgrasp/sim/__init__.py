"""Execution of plans by simulation: the kinematic Monte Carlo and physics (MuJoCo).

- :mod:`~bayesgrasp.sim.kinematic`: :func:`simulate_kinematic` runs a plan on the model's
  transfer functions from initial orientations drawn from the prior (:func:`sample_prior`).
- :mod:`~bayesgrasp.sim.engine`: :func:`simulate_mujoco` runs it in MuJoCo (optional extra
  ``sim``, pinned to 4.0.0; :mod:`~bayesgrasp.sim.scene` and :mod:`~bayesgrasp.sim.params`
  build the scene). MuJoCo is imported only inside the functions that run it; without it
  they raise :class:`~bayesgrasp.errors.MissingExtraError`.
- :mod:`~bayesgrasp.sim.noise`: :class:`GripperNoise`, the error added to gripper angles.
- :mod:`~bayesgrasp.sim.result`: :class:`SimulationResult`, what both return, built by
  :func:`summarize` against the exact :func:`predicted_distribution`.
- :mod:`~bayesgrasp.sim.stats`: :func:`wilson_interval`, :func:`goodness_of_fit`.
- :mod:`~bayesgrasp.sim.asynchrony`: :func:`measure_asynchrony`, the contact-noise ``q`` a
  jaw lag (``SimParams.jaw_lag``) gives in MuJoCo (:class:`AsynchronyResult`).

Bad settings raise :class:`~bayesgrasp.errors.SimulationError`.
"""

from .asynchrony import AsynchronyResult, measure_asynchrony
from .engine import ActionOutcome, Squeezer, require_mujoco, simulate_mujoco
from .kinematic import sample_prior, simulate_kinematic
from .noise import GripperNoise
from .params import SimParams
from .result import (
    DEFAULT_BOUNDARY_MARGIN,
    SimulationResult,
    boundary_distance,
    predicted_distribution,
    summarize,
)
from .scene import Prism, part_inertia, prism, scene_xml, units_scale
from .stats import goodness_of_fit, wilson_interval

__all__ = [
    "DEFAULT_BOUNDARY_MARGIN",
    "ActionOutcome",
    "AsynchronyResult",
    "GripperNoise",
    "Prism",
    "SimParams",
    "SimulationResult",
    "Squeezer",
    "boundary_distance",
    "goodness_of_fit",
    "measure_asynchrony",
    "part_inertia",
    "predicted_distribution",
    "prism",
    "require_mujoco",
    "sample_prior",
    "scene_xml",
    "simulate_kinematic",
    "simulate_mujoco",
    "summarize",
    "units_scale",
    "wilson_interval",
]
