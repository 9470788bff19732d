"""Noisy actions: the transfer as a conditional distribution (the seed, section 6.4).

The seed: "We could extend the Bayesian framework to handle noisy actions ... by modelling
the transfer function with a conditional probability distribution". Two deviations from the
ideal squeeze are modelled here, each giving *exact* row-stochastic (K, K) transition
matrices over the states (no sampling):

Turn error (:class:`TurnNoise`)
    Every commanded gripper angle ``alpha`` (the first action's world angle and every turn
    after it) is executed as ``alpha + e``, with ``e ~ Normal(0, sigma^2)`` or ``e`` uniform
    on ``[-A, A]``, independent between actions. An action of transfer function ``F`` sends
    state ``i`` (stable orientation ``S_i``) to ``F(S_i - alpha - e)``: to state ``j`` exactly
    when ``S_i - alpha - e`` falls in a basin ``(lo_b, hi_b)`` of ``F`` whose stable
    orientation is ``S_j``. So

        M_ij(alpha) = sum over basins b of F ending in j of P(e in (x_i - hi_b, x_i - lo_b)),

    with ``x_i = S_i - alpha``, the interval taken on the circle (``e`` is wrapped mod
    ``2 pi``): differences of the normal CDF (``scipy.special.ndtr``) or interval overlaps
    for the uniform error. The basins tile the circle, so every row sums to one; with no
    error the interval holds 0 for exactly one basin (half-open intervals: an orientation
    exactly on a boundary falls to one side) and ``M`` is the one-hot matrix of today's
    action classes (:meth:`~bayesgrasp.model.problem.ActionClasses.matrix`).

Contact asynchrony (``contact = q``)
    The seed's pure squeeze assumes both jaws touch at once. With probability ``q`` one jaw
    touches first (either, equally likely) and the squeeze acts as a push-grasp from that
    side: from the gripper's ``-x`` side it is the push-grasp function ``g`` of
    :func:`~bayesgrasp.geometry.push.push_grasp_function`; from the ``+x`` side it is the
    push-grasp of the gripper turned by pi, ``theta -> g(theta - pi) + pi``. So a noisy
    squeeze is the mixture

        M_squeeze(alpha) = (1 - q) M_s(alpha) + q/2 M_g(alpha) + q/2 M_g(alpha + pi)

    (each term with the turn error too). A push-grasp pushes with one jaw on purpose: it is
    not affected. Both ``g`` and ``s`` end in squeeze-stable orientations, the states.

The first action: the part's world orientation ``theta`` is drawn from the prior and the
gripper is at ``a + e``, so state ``j`` collects ``P(theta - e in basin + a)``, the prior
convolved with the error. Under the uniform prior that is the basin width over ``2 pi``
whatever the error (exact); under another prior the expectation over ``e`` is a composite
Gauss-Legendre rule (:data:`QUADRATURE_NODES` nodes, 16 a panel, over the error's support;
the one place that is not closed form, checked against a fine trapezoid rule in the tests).

Lipschitz constants (used by :mod:`bayesgrasp.planning.noisy` for its bounds): for any
vector ``r`` with entries in [0, 1] and any distribution ``l``, ``f(alpha) = l M(alpha) r``
is ``E[rho(x - e)]`` for a step function ``rho`` with values in [0, 1], so
``|f'| <= sup density of e`` (:attr:`TurnNoise.peak_density`) and, for the normal error,
``|f''| <= integral of |g''| / 2 = 2 phi(1) / sigma^2`` (:attr:`TurnNoise.curvature_bound`);
a mixture over contact events keeps both bounds.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ndtr

from ..angles import TWO_PI
from ..errors import PlanningError
from ..model.prior import UniformPrior
from .states import nearest_state

if TYPE_CHECKING:  # pragma: no cover
    from ..geometry.transfer import TransferFunction
    from .problem import Problem

__all__ = [
    "MAX_NORMAL_SIGMA",
    "MIN_SCALE",
    "QUADRATURE_NODES",
    "NoiseModel",
    "NoisyTransitions",
    "TurnNoise",
    "parse_turn_noise",
]

FloatArray = NDArray[np.float64]

MAX_NORMAL_SIGMA = math.radians(30.0)
"""Largest standard deviation of a normal turn error (beyond it the turn is a guess)."""
_NORMAL_SUPPORT = 12.0  # the normal error is taken as 0 beyond 12 sigma (mass 4e-33)
MIN_SCALE = 1e-12
"""Smallest non-zero turn error (radians): below it every turn is exact to rounding (angles
carry errors of about 1e-15 rad), and the refinement's bound ``1 / sigma^2`` overflows."""
QUADRATURE_NODES = 512
"""Nodes of the rule that averages a non-uniform prior over the first action's error."""


@functools.lru_cache(maxsize=4)
def _gauss_legendre(n: int) -> tuple[FloatArray, FloatArray]:
    """A composite Gauss-Legendre rule of ``n`` nodes on [-1, 1]: ``n / 16`` panels of 16."""
    x, w = np.polynomial.legendre.leggauss(16)
    panels = max(1, n // 16)
    mid = -1.0 + (2.0 * np.arange(panels) + 1.0) / panels  # (P,) panel middles
    half = 1.0 / panels
    nodes = (mid[:, None] + half * x[None, :]).ravel()
    weights = np.broadcast_to(half * w, (panels, 16)).ravel()
    return np.asarray(nodes, dtype=np.float64), np.asarray(weights, dtype=np.float64)


@dataclass(frozen=True, slots=True)
class TurnNoise:
    """The error of every commanded gripper angle (radians).

    Parameters
    ----------
    kind : {"normal", "uniform"}
        ``normal``: ``e ~ Normal(0, scale^2)``; ``uniform``: ``e`` uniform on
        ``[-scale, scale]``.
    scale : float
        Standard deviation (at most :data:`MAX_NORMAL_SIGMA`) or bound (at most pi);
        0 means exact turns.

    Raises
    ------
    PlanningError
        An unknown kind or a scale out of range.

    Examples
    --------
    >>> n = TurnNoise("uniform", 0.1)
    >>> float(n.interval_prob(-0.05, 0.2)), float(n.interval_prob(0.2, 0.3))
    (0.75, 0.0)
    >>> round(float(TurnNoise("normal", 0.1).interval_prob(-0.1, 0.1)), 4)
    0.6827
    """

    kind: Literal["normal", "uniform"] = "normal"
    scale: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in ("normal", "uniform"):
            raise PlanningError(
                f"turn noise `kind` must be 'normal' or 'uniform'; got {self.kind!r}"
            )
        top = MAX_NORMAL_SIGMA if self.kind == "normal" else math.pi
        if (
            isinstance(self.scale, bool)
            or not isinstance(self.scale, int | float)
            or not math.isfinite(self.scale)
            or not 0.0 <= self.scale <= top
        ):
            raise PlanningError(
                f"turn noise `scale` must be a number of radians in [0, {top:.6g}] for "
                f"{self.kind!r} noise; got {self.scale!r}"
            )
        if 0.0 < self.scale < MIN_SCALE:
            raise PlanningError(
                f"turn noise `scale` {math.degrees(self.scale):.3g} deg is below "
                f"{math.degrees(MIN_SCALE):.2g} deg, where every turn is exact to rounding: "
                "give 0 for exact turns"
            )
        object.__setattr__(self, "scale", float(self.scale))

    @property
    def exact(self) -> bool:
        """Whether every turn is exact (scale 0)."""
        return self.scale == 0.0

    @property
    def support(self) -> float:
        """Half-width of the error's support (12 sigma for the normal)."""
        return self.scale * (_NORMAL_SUPPORT if self.kind == "normal" else 1.0)

    @property
    def peak_density(self) -> float:
        """Sup of the error's density, ``1 / (sigma sqrt(2 pi))`` or ``1 / (2 A)``; inf if exact."""
        if self.exact:
            return math.inf
        if self.kind == "normal":
            return 1.0 / (self.scale * math.sqrt(TWO_PI))
        return 1.0 / (2.0 * self.scale)

    @property
    def curvature_bound(self) -> float:
        """Bound on ``|f''|`` for ``f = E[rho(x - e)]``, ``rho`` in [0, 1] (normal only).

        ``integral of (g'')^+ = 2 sup |g'| = 2 phi(1) / sigma^2`` for the normal density
        ``g``; infinite for the uniform error (``f`` is piecewise linear, with kinks).
        """
        if self.exact or self.kind == "uniform":
            return math.inf
        return 2.0 * math.exp(-0.5) / math.sqrt(TWO_PI) / self.scale**2

    def cdf(self, x: ArrayLike) -> FloatArray:
        """``P(e <= x)`` of the unwrapped error (a step at 0 when exact)."""
        y = np.asarray(x, dtype=np.float64)
        if self.exact:
            return (y >= 0.0).astype(np.float64)
        if self.kind == "normal":
            return np.asarray(ndtr(y / self.scale), dtype=np.float64)
        return np.asarray(np.clip((y + self.scale) / (2.0 * self.scale), 0.0, 1.0))

    def lifted(self, y: ArrayLike) -> FloatArray:
        """``D(y) = E[floor((y - e) / 2 pi)]``, so that ``P(e in (a, b]) = D(b) - D(a)``.

        ``#{m : a < e + 2 pi m <= b} = floor((b - e) / 2 pi) - floor((a - e) / 2 pi)`` counts
        the copies of ``e`` in ``(a, b]``: one or none when ``b - a < 2 pi``. Writing
        ``y = 2 pi n + r`` with ``r`` in ``[-pi, pi)``,
        ``D(y) = n - [r < 0] + sum_m c(r + 2 pi m)`` with ``c(z) = P(e <= z) - [z >= 0]``,
        which vanishes outside the error's support: the CDF is evaluated only there.
        """
        y = np.asarray(y, dtype=np.float64)
        shape = y.shape
        y = y.reshape(-1) if y.ndim == 0 else y
        n = np.floor((y + math.pi) / TWO_PI)
        r = y - TWO_PI * n
        out = n - (r < 0.0)
        if self.exact:
            return np.asarray(out, dtype=np.float64).reshape(shape)
        w = self.support
        # r + 2 pi m is at least pi from 0 for m != 0: only m = 0 meets a support below pi.
        top = 0 if w < math.pi else math.ceil((w + math.pi) / TWO_PI)
        for m in range(-top, top + 1):
            z = r + TWO_PI * m if m else r
            near = np.abs(z) < w
            if np.any(near):
                zn = z[near]
                out[near] += self.cdf(zn) - (zn >= 0.0)
        return np.asarray(out, dtype=np.float64).reshape(shape)

    def interval_prob(self, a: ArrayLike, b: ArrayLike) -> FloatArray:
        """``P(e in (a, b])`` on the circle (``e`` wrapped mod 2 pi), ``0 <= b - a <= 2 pi``.

        Vectorised over broadcast ``a`` and ``b`` (see :meth:`lifted`).
        """
        a, b = np.broadcast_arrays(np.asarray(a, np.float64), np.asarray(b, np.float64))
        return np.asarray(self.lifted(b) - self.lifted(a), dtype=np.float64)

    def spec(self) -> str:
        """The command-line form, ``normal:SIGMA_DEG`` or ``uniform:A_DEG``."""
        return f"{self.kind}:{math.degrees(self.scale):g}"

    def to_json(self) -> dict[str, Any]:
        """The turn error as a JSON object."""
        return {"kind": self.kind, "scale_rad": self.scale}


def parse_turn_noise(spec: str) -> TurnNoise:
    """A turn error from ``normal:SIGMA_DEG`` or ``uniform:A_DEG`` (degrees).

    Raises
    ------
    PlanningError
        A malformed text or a scale out of range.

    Examples
    --------
    >>> n = parse_turn_noise("normal:2")
    >>> n.kind, round(math.degrees(n.scale), 9)
    ('normal', 2.0)
    """
    kind, sep, arg = str(spec).partition(":")
    kind = kind.strip().lower()
    try:
        deg = float(arg)
    except ValueError:
        deg = math.nan
    if not sep or kind not in ("normal", "uniform") or not math.isfinite(deg) or deg < 0:
        raise PlanningError(
            f"`--turn-noise` must be normal:SIGMA_DEG or uniform:A_DEG with a number of "
            f"degrees >= 0; got {spec!r}"
        )
    return TurnNoise(kind, math.radians(deg))  # type: ignore[arg-type]


@dataclass(frozen=True, slots=True)
class NoiseModel:
    """The noise of a gripper: turn error and contact asynchrony.

    Parameters
    ----------
    turn : TurnNoise
        Error of every commanded angle (default: exact turns).
    contact : float
        Probability ``q`` in [0, 1] that a squeeze's jaws do not touch at once (one of them,
        either equally likely, touches first: a push-grasp from that side).

    Raises
    ------
    PlanningError
        A ``contact`` outside [0, 1].

    Examples
    --------
    >>> NoiseModel(TurnNoise("normal", 0.02), 0.1).to_json()["contact"]
    0.1
    """

    turn: TurnNoise = field(default_factory=TurnNoise)
    contact: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.turn, TurnNoise):
            raise PlanningError(f"`turn` must be a TurnNoise; got {type(self.turn).__name__}")
        q = self.contact
        if (
            isinstance(q, bool)
            or not isinstance(q, int | float)
            or not math.isfinite(q)
            or not 0.0 <= q <= 1.0
        ):
            raise PlanningError(f"`contact` noise must be a probability in [0, 1]; got {q!r}")
        object.__setattr__(self, "contact", float(q))

    @classmethod
    def of(cls, turn: str | None = None, contact: float | None = None) -> NoiseModel:
        """The model of the options ``--turn-noise TURN`` and ``--contact-noise CONTACT``.

        Either may be ``None`` (not given: exact turns, simultaneous contacts).

        Raises
        ------
        PlanningError
            A malformed turn error or a contact probability outside [0, 1].

        Examples
        --------
        >>> NoiseModel.of("uniform:2", 0.1).describe()
        'turn error uniform:2 deg, contact asynchrony q=0.1'
        >>> NoiseModel.of().exact
        True
        """
        return cls(TurnNoise() if turn is None else parse_turn_noise(turn), contact or 0.0)

    @property
    def exact(self) -> bool:
        """Whether the model adds no noise at all."""
        return self.turn.exact and self.contact == 0.0

    def to_json(self) -> dict[str, Any]:
        """The noise model as a JSON object."""
        return {"turn": self.turn.to_json(), "contact": self.contact}

    def describe(self) -> str:
        """One line for tables."""
        parts = []
        if not self.turn.exact:
            parts.append(f"turn error {self.turn.spec()} deg")
        if self.contact > 0:
            parts.append(f"contact asynchrony q={self.contact:g}")
        return ", ".join(parts) or "no noise"


@dataclass(frozen=True, slots=True, eq=False)
class _Component:
    """One way an action may go: weight, transfer function and its extra turn (0 or pi)."""

    weight: float
    hi: FloatArray  # (B,) upper ends of the basins; basin b starts at hi[b - 1] (tiling)
    onehot: FloatArray  # (B, K) state each basin ends in
    offset: float


class NoisyTransitions:
    """The exact transition matrices of a problem's actions under a noise model.

    Parameters
    ----------
    problem : Problem
    noise : NoiseModel

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model.problem import Problem
    >>> pb = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]))
    >>> nt = NoisyTransitions(pb, NoiseModel(TurnNoise("normal", 0.1)))
    >>> m = nt.matrices("squeeze", [0.0, np.pi / 4])
    >>> m.shape, np.allclose(m.sum(axis=-1), 1.0)
    ((2, 4, 4), True)
    """

    def __init__(self, problem: Problem, noise: NoiseModel) -> None:
        self.problem = problem
        self.noise = noise
        self.stable = np.asarray(problem.states.stable, dtype=np.float64)
        self.k = problem.n_states
        self._components: dict[str, tuple[_Component, ...]] = {}
        self._initial: dict[tuple[str, float], FloatArray] = {}

    def _component(self, f: TransferFunction, weight: float, offset: float) -> _Component:
        # A push from the +x side (offset pi) ends pi further round in the gripper frame.
        idx = nearest_state(self.problem.states, np.asarray(f.stable) + offset)
        onehot = np.zeros((f.n_states, self.k))
        onehot[np.arange(f.n_states), idx] = 1.0
        lo, hi = np.asarray(f.basin_lo), np.asarray(f.basin_hi)
        gaps = np.append(lo[1:] - hi[:-1], lo[0] + TWO_PI - hi[-1])
        if np.any(np.abs(gaps) > 1e3 * f.angle_tol):  # pragma: no cover - a bug
            raise PlanningError("internal error: the basins of a transfer do not tile the circle")
        return _Component(weight, hi, onehot, offset)

    def components(self, kind: str) -> tuple[_Component, ...]:
        """The ways action ``kind`` may go, with their probabilities."""
        if kind not in self._components:
            from ..geometry.push import push_grasp_function
            from .actions import SQUEEZE

            f = self.problem.transfer(kind)
            q = self.noise.contact
            if kind == SQUEEZE.name and q > 0:
                g = push_grasp_function(self.problem.part, self.problem.states)
                comps = [
                    self._component(f, 1.0 - q, 0.0),
                    self._component(g, q / 2, 0.0),
                    self._component(g, q / 2, math.pi),
                ]
                comps = [c for c in comps if c.weight > 0]
            else:
                comps = [self._component(f, 1.0, 0.0)]
            self._components[kind] = tuple(comps)
        return self._components[kind]

    def matrices(self, kind: str, alphas: ArrayLike, rows: ArrayLike | None = None) -> FloatArray:
        """Transition matrices for the turns ``alphas``: shape (N, R, K).

        ``rows`` picks the states to start from (default all K: R = K); entry
        ``[n, r, j]`` is the probability that state ``rows[r]`` ends in state ``j`` after
        turning by ``alphas[n]`` (plus the error) and acting.
        """
        al = np.atleast_1d(np.asarray(alphas, dtype=np.float64))
        start = self.stable if rows is None else self.stable[np.asarray(rows, dtype=np.intp)]
        out = np.zeros((len(al), len(start), self.k))
        turn = self.noise.turn
        for c in self.components(kind):
            x = start[None, :, None] - al[:, None, None] - c.offset  # (N, R, 1)
            d_hi = turn.lifted(x - c.hi)  # (N, R, B)
            # Basin b is (hi[b - 1], hi[b]); basin 0 starts at hi[-1] - 2 pi: D shifts by 1.
            d_lo = np.concatenate([d_hi[..., -1:] + 1.0, d_hi[..., :-1]], axis=-1)
            out += c.weight * ((d_lo - d_hi) @ c.onehot)
        return out

    def line(self, kind: str, left: FloatArray, right: FloatArray, alphas: ArrayLike) -> FloatArray:
        """``left M(alpha) right`` for many turns, shape (N,), without forming ``M``.

        For each way the action may go, with ``rho_b`` the value of ending in basin ``b``
        (``right`` at its state), ``sum_b rho_b (D(x - lo_b) - D(x - hi_b))`` telescopes to
        ``rho_0 + sum_b (rho_{b+1} - rho_b) D(x - hi_b)`` (:meth:`TurnNoise.lifted`; basin
        ``b + 1`` starts where ``b`` ends): only boundaries between basins of different
        value count.
        """
        al = np.atleast_1d(np.asarray(alphas, dtype=np.float64))
        rows = np.flatnonzero(left > 0)
        lv = left[rows]
        out = np.zeros(len(al))
        for c in self.components(kind):
            rho = c.onehot @ right  # (B,)
            jump = np.append(rho[1:], rho[0]) - rho
            w = lv[:, None] * jump[None, :]  # (R, B)
            keep = w != 0.0
            pts = (self.stable[rows][:, None] - c.offset - c.hi[None, :])[keep]  # (T,)
            d = self.noise.turn.lifted(pts[None, :] - al[:, None])  # (N, T)
            out += c.weight * (d @ w[keep] + rho[0] * lv.sum())
        return out

    def critical(self, kind: str, left: FloatArray, right: FloatArray) -> FloatArray:
        """Turns at which ``left M(alpha) right`` may change with exact turns (see :meth:`line`)."""
        rows = np.flatnonzero(left > 0)
        pts = []
        for c in self.components(kind):
            rho = c.onehot @ right
            jump = np.append(rho[1:], rho[0]) - rho
            keep = (left[rows][:, None] * jump[None, :]) != 0.0
            pts.append((self.stable[rows][:, None] - c.offset - c.hi[None, :])[keep])
        return np.concatenate(pts)

    def boundary_turns(self, kind: str, rows: ArrayLike | None = None) -> FloatArray:
        """Turns that put a state of ``rows`` (default all) on a basin boundary of ``kind``.

        ``S_i - B - o`` for every state ``S_i`` of ``rows``, every way the action may go
        (offset ``o``) and every boundary ``B`` of its transfer function, unwrapped: the
        unstable equilibria a turn must keep away from, whether or not both sides are worth
        the same.
        """
        s = self.stable if rows is None else self.stable[np.asarray(rows, dtype=np.intp)]
        return np.concatenate(
            [(s[:, None] - c.offset - c.hi[None, :]).ravel() for c in self.components(kind)]
        )

    def matrix(self, kind: str, alpha: float) -> FloatArray:
        """The (K, K) transition matrix of one turn."""
        return np.asarray(self.matrices(kind, [alpha])[0], dtype=np.float64)

    def initial(self, kind: str, angle: float) -> FloatArray:
        """Distribution over the states after the first action at world angle ``angle``.

        The prior convolved with the turn error (see the module notes): exact under the
        uniform prior, a Gauss-Legendre rule over the error otherwise.
        """
        key = (kind, float(angle))
        if key in self._initial:
            return self._initial[key].copy()
        prior = self.problem.prior
        turn = self.noise.turn
        out = np.zeros(self.k)
        if isinstance(prior, UniformPrior) or turn.exact:
            nodes, weights = np.zeros(1), np.ones(1)
        else:
            w = turn.support
            x, wt = _gauss_legendre(QUADRATURE_NODES)
            nodes = w * x
            dens = (
                np.exp(-0.5 * (nodes / turn.scale) ** 2)
                if turn.kind == "normal"
                else np.ones_like(nodes)
            )
            weights = wt * dens / np.sum(wt * dens)
        for c in self.components(kind):
            shift = angle + c.offset + nodes[:, None]  # (Q, 1)
            lo = np.append(c.hi[-1] - TWO_PI, c.hi[:-1])
            mass = prior.mass(lo[None, :] + shift, c.hi[None, :] + shift)  # (Q, B)
            out += c.weight * (weights @ np.asarray(mass)) @ c.onehot
        self._initial[key] = out
        return out.copy()
