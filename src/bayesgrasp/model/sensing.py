"""Jaw-width sensing: the sensor model, reading bins, Bayes' rule, and recognition states.

The seed's section 6.2: "a parallel-jaw gripper knows its jaw separation after every
squeeze", so a plan can branch on what it reads. Every action that ends with the jaws
closed (squeeze, push-grasp) yields one reading: the diameter ``d(sigma)`` of the part at the
stable orientation ``sigma`` it ends in (part units), plus sensor error.

Sensor model ``width:SIGMA,RES`` (:func:`parse_sensor`, :class:`WidthSensor`): the reading is
``RES * round((d(sigma) + e) / RES)`` with ``e ~ Normal(0, SIGMA^2)``.

- ``SIGMA = 0, RES = 0`` (``width``): exact readings; two states are told apart when their
  widths differ by more than the part's length tolerance.
- ``SIGMA = 0, RES > 0``: a deterministic quantised encoder.
- ``SIGMA > 0`` needs ``RES > 0``; the likelihood of reading ``RES k`` in state ``i`` is the
  exact normal-CDF difference ``Phi((RES (k + 1/2) - d_i) / SIGMA) - Phi((RES (k - 1/2) - d_i)
  / SIGMA)``.

:meth:`WidthSensor.bins` turns the widths of the states into finitely many *reading bins*:
half-open intervals ``[lo, hi)`` of readings that tile the real line (the first starts at
``-inf``, the last ends at ``+inf``), each with the likelihood ``P(bin | state)`` of every
state (a (N, B) matrix whose rows sum to one). A policy branches on bins. With noise, the
bins are the quantisation cells ``RES k`` for readings within ``tail`` (default 8) standard
deviations of some width; the cells beyond are lumped into the two unbounded end bins, and a
cell that no state reaches with probability ``min_likelihood`` (default 1e-15) is lumped with
its lower neighbour. Lumping keeps every likelihood exact (the lumped cells' probabilities are
added); it only means a policy treats those readings alike (they have probability below
about ``1e-15`` each).

Recognition (:class:`StateSpace`): with several candidate parts the state is (part,
orientation), the states of all parts concatenated in the order given, with a prior over the
parts (default equal) times each part's distribution after the first action. Every part
responds to the same gripper turns with its own transfer functions and reads its own width.

Examples
--------
>>> s = parse_sensor("width:0.5,0.1")
>>> s.sigma, s.resolution, s.kind
(0.5, 0.1, 'noisy')
>>> b = parse_sensor("width").bins(np.array([1.0, 2.0, 1.0]))
>>> b.lo.tolist(), b.hi.tolist(), b.likelihood.tolist()
([-inf, 1.5], [1.5, inf], [[1.0, 0.0], [0.0, 1.0], [1.0, 0.0]])
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtr

from ..errors import BayesGraspError, PlanningError
from ..tolerance import DEFAULT_TOLERANCE
from .problem import Problem

__all__ = [
    "EXACT",
    "ReadingBins",
    "SensorError",
    "StateSpace",
    "WidthSensor",
    "entropy_bits",
    "parse_part_prior",
    "parse_sensor",
    "update_belief",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

MAX_CELLS_PER_STATE = 4096
"""Most quantisation cells one state's readings may fall in (within ``tail`` SIGMA of its
width): a step finer than ``SIGMA / 500`` tells a policy nothing more, and every cell is a
branch the policy search visits."""
MAX_CELLS = 1 << 16
"""Most quantisation cells between the smallest and the largest width (plus the tails)."""


class SensorError(BayesGraspError, ValueError):
    """A sensor specification or part prior that cannot be used; the message says why."""


@dataclass(frozen=True, slots=True)
class ReadingBins:
    """Reading intervals ``[lo[b], hi[b])`` tiling the real line, and their likelihoods.

    Attributes
    ----------
    lo, hi : ndarray of shape (B,)
        Interval ends (part units); ``lo[0] = -inf``, ``hi[-1] = inf``, ``hi[b] = lo[b + 1]``.
    likelihood : ndarray of shape (N, B)
        ``P(reading in bin b | state i)``; each row sums to one.
    """

    lo: FloatArray
    hi: FloatArray
    likelihood: FloatArray

    @property
    def n_bins(self) -> int:
        """Number of bins ``B``."""
        return len(self.lo)

    def index(self, readings: ArrayLike) -> IntArray:
        """Bin of each reading (vectorised).

        Examples
        --------
        >>> b = parse_sensor("width").bins(np.array([1.0, 2.0]))
        >>> b.index([0.0, 1.5, 7.0]).tolist()
        [0, 1, 1]
        """
        r = np.asarray(readings, dtype=np.float64)
        return np.asarray(np.searchsorted(self.hi[:-1], r, side="right"), dtype=np.intp)


@dataclass(frozen=True, slots=True)
class WidthSensor:
    """The jaw-width sensor ``width:SIGMA,RES`` (see the module notes).

    Parameters
    ----------
    sigma : float
        Standard deviation of the reading error (part units, >= 0).
    resolution : float
        Quantisation step of the readings (part units, >= 0; > 0 when ``sigma > 0``).
    tail : float
        Readings further than ``tail * sigma`` from every width are lumped into the end bins.
    min_likelihood : float
        A quantisation cell less likely than this in every state is lumped with a neighbour.

    Raises
    ------
    SensorError
        On a negative or non-finite ``sigma`` or ``resolution``, or ``sigma > 0`` with
        ``resolution = 0``.

    Examples
    --------
    >>> WidthSensor(0.0, 0.5).kind, WidthSensor().kind
    ('quantised', 'exact')
    >>> WidthSensor(0.0, 0.5).read(np.array([1.2, 1.3]), rng=0).tolist()
    [1.0, 1.5]
    """

    sigma: float = 0.0
    resolution: float = 0.0
    tail: float = 8.0
    min_likelihood: float = 1e-15

    def __post_init__(self) -> None:
        for name in ("sigma", "resolution"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise SensorError(f"sensor `{name}` must be a finite number >= 0; got {v!r}")
            if v < 0:
                raise SensorError(f"sensor `{name}` must be >= 0; got {v!r}")
            object.__setattr__(self, name, float(v))
        if self.sigma > 0 and self.resolution == 0:
            raise SensorError(
                f"a noisy sensor (SIGMA = {self.sigma!r} > 0) needs a resolution RES > 0; got "
                "RES = 0 (write width:SIGMA,RES)"
            )
        if not (self.tail > 0 and math.isfinite(self.tail)):
            raise SensorError(f"sensor `tail` must be a finite number > 0; got {self.tail!r}")

    @property
    def kind(self) -> Literal["exact", "quantised", "noisy"]:
        """``"exact"``, ``"quantised"`` (deterministic encoder) or ``"noisy"``."""
        if self.sigma > 0:
            return "noisy"
        return "quantised" if self.resolution > 0 else "exact"

    @property
    def spec(self) -> str:
        """The specification string (``width`` or ``width:SIGMA,RES``)."""
        if self.kind == "exact":
            return "width"
        return f"width:{self.sigma:g},{self.resolution:g}"

    def to_json(self) -> dict[str, Any]:
        """The sensor as a JSON object (``bayesgrasp.policy/1``'s ``sensor``)."""
        return {"kind": "width", "sigma": self.sigma, "resolution": self.resolution}

    def read(self, widths: ArrayLike, rng: np.random.Generator | int | None = None) -> FloatArray:
        """Simulated readings of parts whose true widths are ``widths`` (vectorised)."""
        d = np.asarray(widths, dtype=np.float64)
        if self.kind == "exact":
            return d.copy()
        if self.sigma > 0:
            d = d + np.random.default_rng(rng).normal(0.0, self.sigma, size=d.shape)
        return np.asarray(self.resolution * np.round(d / self.resolution), dtype=np.float64)

    def bins(self, widths: ArrayLike, length_tol: float | None = None) -> ReadingBins:
        """Reading bins and the likelihood of each for states of the given widths.

        Parameters
        ----------
        widths : array_like of shape (N,)
            The width ``d`` at each state (part units).
        length_tol : float, optional
            Exact readings: widths closer than this are one reading (default: the default
            relative length tolerance times the largest width).

        Returns
        -------
        ReadingBins

        Examples
        --------
        >>> b = WidthSensor(0.0, 1.0).bins(np.array([1.2, 2.9, 1.4]))
        >>> b.lo.tolist(), b.hi.tolist(), b.likelihood.argmax(axis=1).tolist()
        ([-inf, 2.5], [2.5, inf], [0, 1, 0])
        >>> WidthSensor(1.0, 1.0).bins(np.array([0.0])).likelihood.sum().round(12)
        np.float64(1.0)
        """
        d = np.asarray(widths, dtype=np.float64)
        if d.ndim != 1 or len(d) == 0 or not np.all(np.isfinite(d)):
            raise PlanningError(
                f"`widths` must be a non-empty 1-d array of finite numbers; got {d}"
            )
        tol = (
            DEFAULT_TOLERANCE.length_for(float(np.max(np.abs(d))))
            if length_tol is None
            else float(length_tol)
        )
        if self.kind == "exact":
            return _exact_bins(d, tol)
        self._check_scale(d, tol)
        if self.kind == "quantised":
            cell = np.rint(d / self.resolution).astype(np.int64)
            return _cell_bins(cell, self.resolution)
        return _noisy_bins(d, self.sigma, self.resolution, self.tail, self.min_likelihood)

    def _check_scale(self, d: FloatArray, tol: float) -> None:
        """Refuse a sensor whose readings would only see rounding, or too many cells.

        Widths closer than the length tolerance ``tol`` are one width (the geometry cannot
        tell them apart), so a reading step or error below it would "read" rounding errors:
        between ``theta`` and ``theta + pi`` the widths differ by about ``1e-15``, and a step
        that fine would claim to separate orientations no squeeze separates.
        """
        for name, v in (("reading step RES", self.resolution), ("reading error SIGMA", self.sigma)):
            if 0 < v < tol:
                raise SensorError(
                    f"sensor {self.spec}: the {name} ({v:g}) is below the length tolerance of "
                    f"these parts ({tol:.3g}): widths that close are one width; use at least "
                    f"{tol:.3g}"
                )
        if self.sigma == 0:
            return
        per_state = 2.0 * self.tail * self.sigma / self.resolution + 1.0
        total = (float(d.max() - d.min()) + 2.0 * self.tail * self.sigma) / self.resolution + 1.0
        if per_state > MAX_CELLS_PER_STATE or total > MAX_CELLS:
            least = max(
                2.0 * self.tail * self.sigma / (MAX_CELLS_PER_STATE - 1),
                (float(d.max() - d.min()) + 2.0 * self.tail * self.sigma) / (MAX_CELLS - 1),
            )
            raise SensorError(
                f"sensor {self.spec}: a reading step of {self.resolution:g} cuts the readings "
                f"into {min(per_state, total):.3g} cells within {self.tail:g} SIGMA of the widths "
                f"(at most {MAX_CELLS_PER_STATE} a width, {MAX_CELLS} in all): use a step RES of "
                f"at least {least:.3g}"
            )


EXACT = WidthSensor()
"""Exact width readings (``--sense width``)."""


def _exact_bins(d: FloatArray, tol: float) -> ReadingBins:
    """One bin per group of widths within ``tol`` of the next; split halfway between groups."""
    order = np.argsort(d, kind="stable")
    ds = d[order]
    group_sorted = np.concatenate([[0], np.cumsum(np.diff(ds) > tol)])
    n_groups = int(group_sorted[-1]) + 1
    group = np.empty(len(d), dtype=np.intp)
    group[order] = group_sorted
    first = np.searchsorted(group_sorted, np.arange(n_groups), side="left")
    last = np.searchsorted(group_sorted, np.arange(n_groups), side="right") - 1
    cuts = 0.5 * (ds[last[:-1]] + ds[first[1:]])
    lo = np.concatenate([[-math.inf], cuts])
    hi = np.concatenate([cuts, [math.inf]])
    lik = np.zeros((len(d), n_groups))
    lik[np.arange(len(d)), group] = 1.0
    return ReadingBins(lo, hi, lik)


def _cell_bins(cell: NDArray[np.int64], res: float) -> ReadingBins:
    """Deterministic cells: one bin per cell reached; unreached cells join the cell below."""
    cells, inv = np.unique(cell, return_inverse=True)
    cuts = res * (cells[1:] - 0.5)
    lo = np.concatenate([[-math.inf], cuts])
    hi = np.concatenate([cuts, [math.inf]])
    lik = np.zeros((len(cell), len(cells)))
    lik[np.arange(len(cell)), inv.ravel()] = 1.0
    return ReadingBins(lo, hi, lik)


def _noisy_bins(
    d: FloatArray, sigma: float, res: float, tail: float, min_lik: float
) -> ReadingBins:
    """Quantisation cells within ``tail`` sigmas of a width, tails and rare cells lumped."""
    k_lo = math.floor((float(d.min()) - tail * sigma) / res + 0.5)
    k_hi = math.ceil((float(d.max()) + tail * sigma) / res - 0.5)
    ks = np.arange(k_lo, k_hi + 1)
    # Cell k holds readings RES k, i.e. d + e in [RES (k - 1/2), RES (k + 1/2)).
    edges = res * (np.append(ks, k_hi + 1) - 0.5)
    edges[0], edges[-1] = -math.inf, math.inf
    z = (edges[None, :] - d[:, None]) / sigma  # (N, C + 1)
    # Differences of the upper tail where it is small keep their relative precision.
    upper = ndtr(-z)
    lower = ndtr(z)
    lik = np.where(z[:, :-1] >= 0, upper[:, :-1] - upper[:, 1:], lower[:, 1:] - lower[:, :-1])
    lik = np.maximum(lik, 0.0)
    keep = lik.max(axis=0) >= min_lik
    keep[0] = True  # the lowest cell absorbs rare cells at the bottom
    owner = np.cumsum(keep) - 1  # (C,) kept bin of each cell
    n_b = int(owner[-1]) + 1
    merged = np.zeros((len(d), n_b))
    np.add.at(merged.T, owner, lik.T)
    merged /= merged.sum(axis=1, keepdims=True)
    first_cell = np.flatnonzero(keep)
    lo = edges[first_cell]
    hi = np.append(lo[1:], math.inf)
    return ReadingBins(lo, hi, merged)


def update_belief(belief: ArrayLike, likelihood: ArrayLike) -> tuple[FloatArray, float]:
    """Bayes' rule: the posterior over states after a reading, and the reading's probability.

    Parameters
    ----------
    belief : array_like of shape (N,)
        Prior probability of each state (need not be normalised).
    likelihood : array_like of shape (N,)
        ``P(reading | state)`` (a column of :attr:`ReadingBins.likelihood`).

    Returns
    -------
    posterior : ndarray of shape (N,)
        Normalised (all zeros when the reading is impossible).
    evidence : float
        ``sum_i belief_i likelihood_i``.

    Examples
    --------
    >>> post, ev = update_belief([0.5, 0.25, 0.25], [1.0, 0.0, 1.0])
    >>> post.round(4).tolist(), ev
    ([0.6667, 0.0, 0.3333], 0.75)
    """
    joint = np.asarray(belief, dtype=np.float64) * np.asarray(likelihood, dtype=np.float64)
    ev = float(joint.sum())
    return (joint / ev if ev > 0 else np.zeros_like(joint)), ev


def entropy_bits(belief: ArrayLike) -> float:
    """Shannon entropy (bits) of a distribution over states (normalised first).

    Examples
    --------
    >>> entropy_bits([0.5, 0.5, 0.0])
    1.0
    """
    p = np.asarray(belief, dtype=np.float64)
    total = float(p.sum())
    if total <= 0:
        return 0.0
    p = p[p > 0] / total
    return float(-(p * np.log2(p)).sum())


_SPEC = re.compile(r"^\s*width\s*(?::\s*(?P<sigma>[^,\s]+)\s*,\s*(?P<res>[^,\s]+)\s*)?$")


def parse_sensor(spec: str | WidthSensor, units: str = "part units") -> WidthSensor:
    """A sensor from ``width`` or ``width:SIGMA,RES`` (in ``units``: the part's by default).

    ``units`` only words the message of a malformed specification (the sensing study reads
    SIGMA and RES as fractions of each part's largest diameter).

    Raises
    ------
    SensorError
        On a malformed specification or bad values (see :class:`WidthSensor`).

    Examples
    --------
    >>> parse_sensor("width").kind, parse_sensor("width:0,0.1").kind
    ('exact', 'quantised')
    >>> parse_sensor("width:-1,1")
    Traceback (most recent call last):
    ...
    bayesgrasp.model.sensing.SensorError: sensor `sigma` must be >= 0; got -1.0
    """
    if isinstance(spec, WidthSensor):
        return spec
    m = _SPEC.match(spec) if isinstance(spec, str) else None
    if m is None:
        raise SensorError(
            f"sensor must be written `width` or `width:SIGMA,RES` ({units}); got {spec!r}"
        )
    if m.group("sigma") is None:
        return EXACT
    try:
        sigma, res = float(m.group("sigma")), float(m.group("res"))
    except ValueError:
        raise SensorError(
            f"sensor SIGMA and RES must be numbers (`width:SIGMA,RES`); got {spec!r}"
        ) from None
    return WidthSensor(sigma, res)


def parse_part_prior(spec: str | Sequence[float] | None, n_parts: int) -> FloatArray:
    """Normalised prior over ``n_parts`` candidate parts from ``W1,W2,...`` (default equal).

    Raises
    ------
    SensorError
        If the weights are not numbers, not ``n_parts`` of them, negative, non-finite or all
        zero.

    Examples
    --------
    >>> parse_part_prior("1,3", 2).tolist()
    [0.25, 0.75]
    >>> parse_part_prior(None, 4).tolist()
    [0.25, 0.25, 0.25, 0.25]
    >>> parse_part_prior("1e308,1e308", 2).tolist()
    [0.5, 0.5]
    """
    if n_parts < 1:
        raise SensorError(f"at least one part is needed; got {n_parts}")
    if spec is None:
        return np.full(n_parts, 1.0 / n_parts)
    try:
        items = spec.split(",") if isinstance(spec, str) else list(spec)
        w = np.array([float(x) for x in items], dtype=np.float64)
    except (TypeError, ValueError):
        raise SensorError(f"the part prior must be numbers W1,W2,...; got {spec!r}") from None
    if len(w) != n_parts:
        raise SensorError(
            f"the part prior needs one weight per part ({n_parts}); got {len(w)} in {spec!r}"
        )
    if not np.all(np.isfinite(w)) or np.any(w < 0) or w.max() <= 0:
        raise SensorError(
            f"the part prior's weights must be finite, >= 0 and not all zero; got {spec!r}"
        )
    w = w / w.max()  # weights near the largest float must not overflow their sum
    return np.asarray(w / w.sum(), dtype=np.float64)


@dataclass(frozen=True, slots=True, eq=False)
class StateSpace:
    """The states (part, orientation) over one or several candidate parts.

    The states of part ``j`` are its problem's stable orientations, at indices
    ``offsets[j] .. offsets[j + 1] - 1`` of the joint space.

    Attributes
    ----------
    problems : tuple of Problem
        One per candidate part; they share the action kinds (and should share prior and cost:
        :meth:`build` uses the first problem's cost and goal for everything).
    part_prior : ndarray of shape (P,)
    offsets : ndarray of shape (P + 1,)
    widths : ndarray of shape (N,)
        The width read at each joint state.
    part_of : ndarray of shape (N,)
        The part of each joint state.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> square = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    >>> sp = StateSpace.build([square, square], "1,3")
    >>> sp.n_states, sp.initial("squeeze").round(4).tolist()
    (8, [0.0625, 0.0625, 0.0625, 0.0625, 0.1875, 0.1875, 0.1875, 0.1875])
    """

    problems: tuple[Problem, ...]
    part_prior: FloatArray
    offsets: IntArray
    widths: FloatArray
    part_of: IntArray
    _cache: dict[Any, Any] = field(default_factory=dict, repr=False)

    @classmethod
    def build(
        cls, problems: Problem | Iterable[Problem], part_prior: str | Sequence[float] | None = None
    ) -> StateSpace:
        """The joint state space of one problem or several (one per candidate part).

        Raises
        ------
        SensorError
            On a bad part prior (see :func:`parse_part_prior`).
        PlanningError
            If the problems do not share their action kinds, two parts are in different
            units (:func:`bayesgrasp.units.convert` converts one), or some have units and
            some do not (their widths could not be compared).
        """
        pbs = (problems,) if isinstance(problems, Problem) else tuple(problems)
        if not pbs or not all(isinstance(p, Problem) for p in pbs):
            raise PlanningError("`problems` must be one Problem or a non-empty list of them")
        kinds = pbs[0].action_kinds
        if any(p.action_kinds != kinds for p in pbs):
            raise PlanningError(
                "every candidate part must have the same actions; got "
                + "; ".join(",".join(p.action_kinds) for p in pbs)
            )
        known = {p.part.units for p in pbs} - {None}
        if len(known) > 1:
            raise PlanningError(
                "the candidate parts' widths are read in one unit, but the parts are in "
                + ", ".join(f"{p.part.units} ({p.part.name})" for p in pbs if p.part.units)
                + ": convert them to one (bayesgrasp.units.convert; the command line does)"
            )
        if known and any(p.part.units is None for p in pbs):
            bare = next(p.part.name for p in pbs if p.part.units is None)
            raise PlanningError(
                f"part {bare!r} has no units and the other candidates are in "
                f"{next(iter(known))}: their widths cannot be compared; give the units in "
                "every part file"
            )
        w = parse_part_prior(part_prior, len(pbs))
        sizes = [p.n_states for p in pbs]
        offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)
        widths = np.concatenate([p.widths for p in pbs])
        part_of = np.repeat(np.arange(len(pbs)), sizes).astype(np.intp)
        for a in (w, offsets, widths, part_of):
            a.setflags(write=False)
        return cls(pbs, w, offsets, widths, part_of)

    @property
    def n_parts(self) -> int:
        """Number of candidate parts ``P``."""
        return len(self.problems)

    @property
    def n_states(self) -> int:
        """Number of joint states ``N``."""
        return int(self.offsets[-1])

    @property
    def names(self) -> tuple[str, ...]:
        """The part names, in order."""
        return tuple(p.part.name for p in self.problems)

    @property
    def length_tol(self) -> float:
        """Widths closer than this are one exact reading (the largest part's length tolerance)."""
        return max(p.part.hull.tol.length_for(p.part.hull.size) for p in self.problems)

    def memo(self, key: Hashable, build: Callable[[], Any]) -> Any:
        """A value derived from the space, computed by ``build()`` on first use and kept."""
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def bins(self, sensor: WidthSensor) -> ReadingBins:
        """The reading bins of ``sensor`` over the joint states (computed once per sensor)."""
        return cast(
            ReadingBins,
            self.memo(("bins", sensor), lambda: sensor.bins(self.widths, self.length_tol)),
        )

    def initial(self, kind: str = "squeeze", first_angle: float = 0.0) -> FloatArray:
        """Joint distribution after the first action at world gripper angle ``first_angle``."""
        parts = [
            w * p.state_distribution(first_angle, kind)
            for w, p in zip(self.part_prior, self.problems, strict=True)
        ]
        return np.asarray(np.concatenate(parts), dtype=np.float64)

    def stable(self, state: int) -> tuple[int, float]:
        """The part index and the stable orientation (radians) of a joint state."""
        j = int(self.part_of[state])
        return j, float(self.problems[j].states.stable[state - int(self.offsets[j])])

    def success_matrix(self) -> NDArray[np.bool_]:
        """``G[i, j]``: declaring state ``i``'s part and orientation succeeds in state ``j``.

        Block diagonal: each part's block is its goal's success set
        (:meth:`Problem.success_states`).
        """
        if "success" not in self._cache:
            g = np.zeros((self.n_states, self.n_states), dtype=bool)
            for j, p in enumerate(self.problems):
                o = int(self.offsets[j])
                for i, s in enumerate(p.states.stable):
                    g[o + i, o : o + p.n_states] = p.success_states(float(s))
            g.setflags(write=False)
            self._cache["success"] = g
        return np.asarray(self._cache["success"])
