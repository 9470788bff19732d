"""The simulation engines' settings the command line makes of its options (``--jaw-lag``).

``simulate`` and ``simulate --sense`` (:mod:`.sensing`) both take them from here.
"""

from __future__ import annotations

from typing import Any

import typer

__all__ = ["lagged_params"]


def lagged_params(lag: float, part: Any, units: str | None) -> Any:
    """The MuJoCo settings of ``--jaw-lag`` (:func:`bayesgrasp.sim.asynchrony.lagged_params`)."""
    from ..errors import SimulationError
    from ..sim.asynchrony import lagged_params as params_of
    from ..sim.scene import units_scale

    size = part.hull.size * units_scale(units if units is not None else part.units)
    try:
        return params_of(lag, size)
    except SimulationError as exc:
        raise typer.BadParameter(str(exc), param_hint="--jaw-lag") from None
