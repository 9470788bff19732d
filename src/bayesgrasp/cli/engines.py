"""The simulation engines' settings the command line makes of its options (``--jaw-lag``).

``simulate`` and ``simulate --sense`` (:mod:`.sensing`) both take them from here.
"""

from __future__ import annotations

from typing import Any

import typer

__all__ = ["lagged_params"]


def lagged_params(lag: float, part: Any, units: str | None) -> Any:
    """The MuJoCo settings of ``--jaw-lag``: the lag, and room for the push it makes.

    The leading jaw pushes ``jaw_speed * lag / 2`` before the other touches; the clearance is
    raised to that push + 1 mm (as :func:`~bayesgrasp.sim.asynchrony.measure_asynchrony`
    does) so the push does not saturate. A push of more than twice the part's size (the
    travel of a push-grasp, ``SimParams.push_distance``) is refused: it adds nothing but time.
    """
    from dataclasses import replace

    from ..sim.params import SimParams
    from ..sim.scene import units_scale

    # The lag is in seconds of jaws closing at 1 cm/s (the push it makes is its meaning),
    # whatever the default jaw speed.
    base = replace(SimParams(), jaw_speed=0.01)
    push = base.jaw_speed * lag / 2.0
    size = part.hull.size * units_scale(units if units is not None else part.units)
    if push > 2.0 * size:
        most = 4.0 * size / base.jaw_speed
        raise typer.BadParameter(
            f"a lag of {lag:g} s pushes the part {push * 1000:.4g} mm, more than twice its "
            f"size ({size * 1000:.4g} mm from its centroid to its farthest vertex): give at "
            f"most {most:.4g} s",
            param_hint="--jaw-lag",
        )
    return replace(base, jaw_lag=lag, clearance=max(base.clearance, push + 0.001))
