"""The exception hierarchy of bayesgrasp.

Every error the library raises on bad input is a :class:`BayesGraspError`; the command line
turns each into one line on stderr and exit code 2.

``BayesGraspError``
    ``PartError`` (also a ``ValueError``): a part that cannot be used (too few points,
    collinear points, NaN coordinates, a centre of mass outside the hull, ...).

    ``PartFileError`` (a ``PartError``): a part file that cannot be read; the message names
    the file.

    ``PriorError`` (also a ``ValueError``): a prior that is not a probability distribution.

    ``CostError`` (also a ``ValueError``): a cost model with negative or non-finite costs.

    ``PlanningError``: a planning problem that cannot be set up or solved.

    ``NoPlanError`` (a ``PlanningError``): no plan reaches the goal asked for (a guaranteed
    plan under a gripper accuracy no plan can honour); the command line exits with code 1.

    ``SimulationError`` (also a ``ValueError``): bad simulation settings (trials, noise,
    seed, plan).

    ``ExportError`` (also a ``ValueError``): a robot file that cannot be written (its name
    or its plan; ``plan --export``).

    ``MissingExtraError`` (also an ``ImportError``): an optional extra is not installed.
"""

from __future__ import annotations

__all__ = [
    "BayesGraspError",
    "CostError",
    "ExportError",
    "MissingExtraError",
    "NoPlanError",
    "PartError",
    "PartFileError",
    "PlanningError",
    "PriorError",
    "SimulationError",
]


class BayesGraspError(Exception):
    """Base class of every error bayesgrasp raises on purpose."""


class PartError(BayesGraspError, ValueError):
    """A part that cannot be used."""


class PartFileError(PartError):
    """A part file that cannot be read or holds no usable outline."""


class PriorError(BayesGraspError, ValueError):
    """A prior that is not a probability distribution over orientations."""


class CostError(BayesGraspError, ValueError):
    """A cost model that is not usable (negative, non-finite or zero total cost)."""


class PlanningError(BayesGraspError):
    """A planning problem that cannot be set up or solved."""


class NoPlanError(PlanningError):
    """No plan reaches the goal asked for; the message says why."""


class SimulationError(BayesGraspError, ValueError):
    """Bad simulation settings (trials, noise, plan)."""


class ExportError(BayesGraspError, ValueError):
    """A robot file that cannot be written (its name or its plan)."""


class MissingExtraError(BayesGraspError, ImportError):
    """An optional dependency is missing; the message names the extra to install."""

    def __init__(self, package: str, extra: str) -> None:
        super().__init__(
            f"this feature needs the optional package {package!r}; "
            f"install it with: pip install 'bayesgrasp[{extra}]'"
        )
