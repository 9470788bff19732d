"""Calibrating contact asynchrony: the ``q`` a jaw lag produces in MuJoCo.

The noise model (:mod:`bayesgrasp.model.noise`) says a squeeze whose jaws do not touch
together acts, with probability ``q``, as a push-grasp from the side of the jaw that touches
first:

    M_squeeze(alpha) = (1 - q) M_s(alpha) + q/2 M_g(alpha) + q/2 M_g(alpha + pi).

Here MuJoCo squeezes with one jaw starting ``SimParams.jaw_lag`` seconds early (the leading
jaw drawn at random per squeeze) and each outcome is classified against the two
predictions for its start ``theta`` (gripper frame): the pure squeeze's ``s(theta)``
(:func:`~bayesgrasp.geometry.transfer.squeeze_function`) and the push-grasp's from the
leading side, ``g(theta)`` for the ``-x`` jaw and ``g(theta - pi) + pi`` for the ``+x`` jaw
(:func:`~bayesgrasp.geometry.push.push_grasp_function`). Only starts where the two differ
tell them apart, so only those are simulated: starts are drawn uniformly and kept when the
predictions differ and the start lies at least ``margin`` from every basin boundary of both
functions (starts near a boundary may jam, physics notes). The estimate is

    q_hat = n_push / (n_push + n_squeeze),

with the Wilson interval (:func:`~bayesgrasp.sim.stats.wilson_interval`); outcomes that match
neither (jams, or a push that stopped short of a push-stable orientation and then squeezed
into a third state) are counted apart: the mixture has no term for them.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from ..angles import TWO_PI, circle_distance
from ..errors import SimulationError
from ..geometry.polygon import Part
from ..geometry.push import push_grasp_function
from ..geometry.transfer import squeeze_function
from .noise import as_generator
from .params import SimParams
from .result import DEFAULT_BOUNDARY_MARGIN, boundary_distance
from .squeezer import Squeezer
from .stats import wilson_interval

__all__ = ["AsynchronyResult", "lagged_params", "measure_asynchrony"]


@dataclass(frozen=True, slots=True)
class AsynchronyResult:
    """Outcomes of lagged squeezes from starts where squeeze and push-grasp differ.

    Attributes
    ----------
    lag : float
        ``SimParams.jaw_lag`` (seconds).
    push_mm : float
        The leading jaw's push before the other jaw meets the part,
        ``jaw_speed * lag / 2``, in millimetres.
    trials : int
        Squeezes simulated (all from starts where the predictions differ).
    push, squeeze, other : int
        Outcomes within ``jam_tol`` of the push-grasp's prediction, of the squeeze's, or of
        neither.
    seconds : float
        Wall time of the simulations.
    """

    lag: float
    push_mm: float
    trials: int
    push: int
    squeeze: int
    other: int
    seconds: float

    @property
    def q(self) -> float:
        """``push / (push + squeeze)``; nan when no outcome matched either prediction."""
        n = self.push + self.squeeze
        return self.push / n if n else math.nan

    def interval(self, confidence: float = 0.95) -> tuple[float, float]:
        """Wilson interval of :attr:`q`."""
        return wilson_interval(self.push, self.push + self.squeeze, confidence)


def differing_starts(
    part: Part,
    n: int,
    rng: np.random.Generator,
    margin: float = DEFAULT_BOUNDARY_MARGIN,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``n`` uniform starts whose squeeze and leading-side push-grasp predictions differ.

    Returns
    -------
    starts, leads, squeezed, pushed : ndarray of shape (n,)
        Start yaws (gripper frame), leading jaw (-1: ``-x``, +1: ``+x``, each with
        probability 1/2) and the two predicted final yaws.

    Raises
    ------
    SimulationError
        If the part's squeeze and push-grasp agree from (almost) every start.
    """
    s = squeeze_function(part.hull)
    g = push_grasp_function(part, s)
    tol = 1e3 * s.angle_tol
    out: list[np.ndarray] = []
    have, drawn = 0, 0
    while have < n:
        if drawn > 1000 * max(n, 1):
            raise SimulationError(
                f"the squeeze and the push-grasp of {part.name or 'the part'} agree from "
                "almost every start: nothing to calibrate on"
            )
        th = rng.uniform(0.0, TWO_PI, 4 * n)
        lead = np.where(rng.random(4 * n) < 0.5, -1, 1)
        shift = np.where(lead > 0, math.pi, 0.0)  # the +x jaw: the gripper turned by pi
        sq = s(th)
        pg = np.mod(g(th - shift) + shift, TWO_PI)
        keep = (
            (circle_distance(sq, pg) > tol)
            & (boundary_distance(s.boundaries, th) >= margin)
            & (boundary_distance(g.boundaries, th - shift) >= margin)
        )
        out.append(np.stack([th, lead, sq, pg])[:, keep])
        have += int(keep.sum())
        drawn += 4 * n
    th, lead, sq, pg = np.concatenate(out, axis=1)[:, :n]
    return th, lead.astype(int), sq, pg


def measure_asynchrony(
    part: Part,
    scale: float,
    lag: float,
    trials: int,
    params: SimParams | None = None,
    rng: np.random.Generator | int | None = None,
    margin: float = DEFAULT_BOUNDARY_MARGIN,
) -> AsynchronyResult:
    """Squeeze ``trials`` times in MuJoCo with jaw lag ``lag`` and classify the outcomes.

    Parameters
    ----------
    part : Part
    scale : float
        Metres per unit of the part's coordinates.
    lag : float
        Seconds by which the leading jaw starts early (``SimParams.jaw_lag``).
    trials : int
        Squeezes, all from starts where the two predictions differ (:func:`differing_starts`).
    params : SimParams, optional
        Its ``jaw_lag`` is replaced by ``lag``, and its ``clearance`` raised to
        ``jaw_speed * lag / 2 + 1 mm`` if smaller: with less, the pushed part would reach the
        lagging jaw before that jaw starts and the push would saturate at ``clearance``.
    rng : numpy.random.Generator or int or None
    margin : float
        Starts at least this far (radians) from every basin boundary.

    Examples
    --------
    >>> tri = Part.from_points([(0, 0), (0.04, 0), (0.01, 0.03)])
    >>> r = measure_asynchrony(tri, 1.0, 0.0, 3, rng=1)
    >>> r.trials, r.push, r.squeeze + r.other
    (3, 0, 3)
    """
    if not isinstance(trials, int) or trials < 1:
        raise SimulationError(f"`trials` must be an integer >= 1; got {trials!r}")
    base = params or SimParams()
    push = base.jaw_speed * lag / 2.0
    sp = replace(base, jaw_lag=lag, clearance=max(base.clearance, push + 0.001))
    gen = as_generator(rng)
    th, lead, sq, pg = differing_starts(part, trials, gen, margin)
    squeezer = Squeezer(part, scale, sp)
    t0 = time.perf_counter()
    ends = np.array(
        [squeezer.act(float(t), lead=int(side)).end for t, side in zip(th, lead, strict=True)]
    )
    seconds = time.perf_counter() - t0
    near_s = circle_distance(ends, sq) <= sp.jam_tol
    near_g = circle_distance(ends, pg) <= sp.jam_tol
    return AsynchronyResult(
        lag,
        1000.0 * push,
        trials,
        int(near_g.sum()),
        int(near_s.sum()),
        int((~near_g & ~near_s).sum()),
        seconds,
    )


def lagged_params(lag: float, size: float) -> SimParams:
    """The MuJoCo settings of a jaw lag: the lag, and room for the push it makes.

    ``lag`` is in seconds of jaws closing at 1 cm/s (the push it makes is its meaning,
    whatever the default jaw speed): the leading jaw pushes ``jaw_speed * lag / 2`` (5 mm a
    second of lag) before the other touches. The clearance is raised to that push + 1 mm (as
    :func:`measure_asynchrony` does) so the push does not saturate. A push of more than twice
    the part's ``size`` (metres, centroid to farthest vertex: the travel of a push-grasp,
    ``SimParams.push_distance``) is refused (:class:`~bayesgrasp.errors.SimulationError`):
    it adds nothing but time.

    Examples
    --------
    >>> p = lagged_params(2.0, 0.03)
    >>> p.jaw_lag, round(p.clearance, 4)
    (2.0, 0.011)
    >>> lagged_params(20.0, 0.03)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.SimulationError: a lag of 20 s pushes the part 100 mm, more than twice...
    """
    base = replace(SimParams(), jaw_speed=0.01)
    push = base.jaw_speed * lag / 2.0
    if push > 2.0 * size:
        most = 4.0 * size / base.jaw_speed
        raise SimulationError(
            f"a lag of {lag:g} s pushes the part {push * 1000:.4g} mm, more than twice its "
            f"size ({size * 1000:.4g} mm from its centroid to its farthest vertex): give at "
            f"most {most:.4g} s"
        )
    return replace(base, jaw_lag=lag, clearance=max(base.clearance, push + 0.001))
