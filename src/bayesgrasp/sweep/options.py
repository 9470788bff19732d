"""The options of a sweep: what every part is planned (and checked) with.

:class:`SweepOptions` holds the options of ``plan`` and ``simulate`` a sweep applies to
every part; :meth:`SweepOptions.plan_args` gives them back as command-line arguments, and
:attr:`SweepOptions.key` names them in a results file (for resuming).
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass
from typing import Any

from ..errors import BayesGraspError

__all__ = ["DEFAULT_TRIALS", "ENGINES", "GOALS", "METHODS", "SweepError", "SweepOptions"]

#: Planners a sweep may use (the ``plan`` command's ``--method``).
METHODS = ("exact", "bfs")
#: Goals (the ``plan`` command's ``--goal``).
GOALS = ("single", "symmetry")
#: Execution checks of each part's Bayes plan (the ``simulate`` command's ``--engine``).
ENGINES = ("kinematic", "mujoco")
#: Default trials of each engine (as ``bayesgrasp simulate``).
DEFAULT_TRIALS = {"kinematic": 1_000_000, "mujoco": 200}


class SweepError(BayesGraspError, ValueError):
    """Bad sweep settings, or a results file that cannot be written or resumed."""


def _number(name: str, value: float | None, *, optional: bool = False) -> None:
    """Refuse a negative or non-finite option (``None`` allowed when ``optional``)."""
    if value is None and optional:
        return
    if not isinstance(value, int | float) or not math.isfinite(value) or value < 0:
        raise SweepError(f"`{name}` must be a finite number >= 0; got {value!r}")


@dataclass(frozen=True, slots=True)
class SweepOptions:
    """The options applied to every part of a sweep (those of ``plan`` and ``simulate``).

    Parameters
    ----------
    prior : str
        Prior on the initial orientation, as ``--prior`` (``uniform``,
        ``vonmises:MEAN_DEG,KAPPA``, ``histogram:FILE``, ``sample:FILE``).
    squeeze_cost, push_grasp_cost, verify_cost, retry_cost : float
        Costs of a squeeze, a push-grasp, the verification and a failed verification.
    first_squeeze_cost, first_push_grasp_cost : float, optional
        Cost of a squeeze or push-grasp that is the first action (default: as the others).
    goal : {"single", "symmetry"}
    actions : tuple of str
        Action names a plan may use (``("squeeze",)`` or ``("squeeze", "push-grasp")``).
    accuracy_deg : float
        Gripper accuracy in degrees (``--accuracy``).
    method : {"exact", "bfs"}
    max_actions : int, optional
        Longest plan to consider (``--max-actions``).
    guaranteed : bool
        Also plan the shortest guaranteed plan (``--guaranteed``); on by default, since a
        row reports its length.
    simulate : {"kinematic", "mujoco"}, optional
        Execute each part's Bayes plan ``trials`` times with this engine.
    trials : int, optional
        Default: 1,000,000 kinematic, 200 mujoco (as ``bayesgrasp simulate``).
    seed : int
        Seed of every part's simulation (each part uses the same seed, so its row equals
        ``bayesgrasp simulate PART --seed SEED``, whatever worker runs it and when).
    noise_deg : float
        Gripper angle error (standard deviation or bound), degrees.
    noise_kind : {"normal", "uniform"}
    offset_mm : float
        MuJoCo: the part's centre off the gripper centre along the squeeze axis (mm).
    layer : str, optional
        DXF: read only this layer.
    flatten_tol : float, optional
        Chordal tolerance of curve flattening, in each file's units.
    shape_tol : float
        Manufacturing tolerance of every part, in its units (``--shape-tol``): minima of the
        width it could lose are not states (0: none; left out of :meth:`to_json` then, so
        the keys of sweeps run before it existed still resume).
    sense : str, optional
        Also plan each part's Bayes sensing policy with this jaw-width sensor (``width`` or
        ``width:SIGMA,RES`` in each part's units, as ``plan --sense``); its cost, success
        and actions fill the ``policy_*`` columns. ``None`` (default): no policy, and left
        out of :meth:`to_json` like ``sense_max_actions``.
    sense_max_actions : int
        The policy's depth (``plan --sense ... --max-actions``).
    turn_noise : str, optional
        Error of every gripper turn, ``normal:SIGMA_DEG`` or ``uniform:A_DEG``
        (``plan --turn-noise``).
    contact_noise : float, optional
        Probability in [0, 1] that a squeeze's jaws touch one after the other
        (``plan --contact-noise``).
    payoff : str, optional
        A payoff file (``plan --payoff``), read once by the client.

        With any of these three, each part's plan is the noise-aware Bayes plan
        (:func:`~bayesgrasp.planning.noisy.plan_noisy`), its row ``plan_json`` the document
        ``plan PATH --turn-noise ... --json`` prints. That planner seeds from the exact
        planner, so ``method`` must be ``"exact"``. ``guaranteed`` asks for the plan that
        succeeds under every turn error within the bound
        (:func:`~bayesgrasp.planning.robust.plan_guaranteed_noisy`), refused under a normal
        turn error, which has no bound; turn it off for those. ``sense`` plans the policy
        under the noisy actions (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`,
        ``plan PATH --sense S --turn-noise ... --json``); ``simulate`` executes the
        noise-aware Bayes plan under the noise and predicts it exactly (``simulate PATH
        --turn-noise ... --json``; ``noise_deg`` stays 0, and MuJoCo takes no
        ``contact_noise``: its contacts are the physics' own). Left out of :meth:`to_json`
        when not given, so the keys of sweeps run before them still resume.

    Examples
    --------
    >>> o = SweepOptions(actions=("squeeze", "push-grasp"), accuracy_deg=1.0)
    >>> o.plan_args()
    ['--json', '--actions', 'squeeze,push-grasp', '--accuracy', '1.0', '--guaranteed']
    >>> len(o.key)
    16
    """

    prior: str = "uniform"
    squeeze_cost: float = 1.0
    push_grasp_cost: float = 1.0
    verify_cost: float = 1.0
    first_squeeze_cost: float | None = None
    first_push_grasp_cost: float | None = None
    retry_cost: float = 0.0
    goal: str = "single"
    actions: tuple[str, ...] = ("squeeze",)
    accuracy_deg: float = 0.0
    method: str = "exact"
    max_actions: int | None = None
    guaranteed: bool = True
    simulate: str | None = None
    trials: int | None = None
    seed: int = 0
    noise_deg: float = 0.0
    noise_kind: str = "normal"
    offset_mm: float = 0.0
    layer: str | None = None
    flatten_tol: float | None = None
    shape_tol: float = 0.0
    sense: str | None = None
    sense_max_actions: int = 3
    turn_noise: str | None = None
    contact_noise: float | None = None
    payoff: str | None = None

    def __post_init__(self) -> None:
        for name in ("squeeze_cost", "push_grasp_cost", "verify_cost", "retry_cost"):
            _number(name, getattr(self, name))
        _number("first_squeeze_cost", self.first_squeeze_cost, optional=True)
        _number("first_push_grasp_cost", self.first_push_grasp_cost, optional=True)
        _number("accuracy_deg", self.accuracy_deg)
        _number("noise_deg", self.noise_deg)
        _number("offset_mm", self.offset_mm)
        _number("flatten_tol", self.flatten_tol, optional=True)
        _number("shape_tol", self.shape_tol)
        if self.goal not in GOALS:
            raise SweepError(f"`goal` must be one of {', '.join(GOALS)}; got {self.goal!r}")
        if self.method not in METHODS:
            raise SweepError(f"`method` must be one of {', '.join(METHODS)}; got {self.method!r}")
        if isinstance(self.actions, str) or not self.actions:
            raise SweepError(
                f"`actions` must be a non-empty tuple of action names; got {self.actions!r}"
            )
        from ..model.actions import parse_actions

        parse_actions(self.actions)  # unknown names: PlanningError naming the known ones
        if self.simulate is not None and self.simulate not in ENGINES:
            raise SweepError(
                f"`simulate` must be None or one of {', '.join(ENGINES)}; got {self.simulate!r}"
            )
        if self.noise_kind not in ("normal", "uniform"):
            raise SweepError(f"`noise_kind` must be 'normal' or 'uniform'; got {self.noise_kind!r}")
        for name in ("max_actions", "trials"):
            v = getattr(self, name)
            if v is not None and (not isinstance(v, int) or isinstance(v, bool) or v < 1):
                raise SweepError(f"`{name}` must be None or an integer >= 1; got {v!r}")
        if self.offset_mm > 0 and self.simulate != "mujoco":
            raise SweepError("`offset_mm` applies to simulate='mujoco' only")
        v = self.sense_max_actions
        if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= 8:
            raise SweepError(f"`sense_max_actions` must be an integer in [1, 8]; got {v!r}")
        if self.sense is not None:
            from ..model.sensing import parse_sensor

            parse_sensor(self.sense)  # a malformed sensor: SensorError saying why
        self._check_noise()

    def _check_noise(self) -> None:
        """Refuse a malformed noise, and the options the noise-aware planner does not take."""
        if self.turn_noise is not None:
            from ..model.noise import parse_turn_noise

            parse_turn_noise(self.turn_noise)  # PlanningError naming the two forms
        q = self.contact_noise
        if q is not None and (
            isinstance(q, bool) or not isinstance(q, int | float) or not 0 <= q <= 1
        ):
            raise SweepError(f"`contact_noise` must be a probability in [0, 1]; got {q!r}")
        if self.payoff is not None and not isinstance(self.payoff, str):
            raise SweepError(f"`payoff` must be the path of a payoff file; got {self.payoff!r}")
        if not self.noisy:
            return
        if self.method != "exact":
            raise SweepError(
                "the noise-aware planner (turn_noise, contact_noise, payoff) seeds from the "
                "exact planner; drop method='bfs'"
            )
        if self.guaranteed and self.turn_noise is not None:
            from ..model.noise import parse_turn_noise
            from ..planning.robust import UNBOUNDED_GUARANTEE

            turn = parse_turn_noise(self.turn_noise)
            if not turn.exact and turn.kind == "normal":
                raise SweepError(f"`guaranteed`: {UNBOUNDED_GUARANTEE}")
        if self.noise_deg or self.noise_kind != "normal":
            raise SweepError(
                "`noise_deg` and `noise_kind` are the turn error of a simulation of the exact "
                "plan; the noise-aware plan is simulated under its own turn_noise"
            )
        if self.simulate == "mujoco" and self.contact_noise is not None:
            raise SweepError(
                "`contact_noise` applies to simulate='kinematic' only: in MuJoCo the jaws' "
                "contacts are the physics' own"
            )

    @property
    def noisy(self) -> bool:
        """Whether the parts are planned under noise or a payoff (the noise-aware planner)."""
        return not (self.turn_noise is None and self.contact_noise is None and self.payoff is None)

    @property
    def n_trials(self) -> int:
        """Trials of the simulation (0 without one)."""
        if self.simulate is None:
            return 0
        return self.trials or DEFAULT_TRIALS[self.simulate]

    def to_json(self) -> dict[str, Any]:
        """The options as a JSON object (recorded in the results' metadata)."""
        out = asdict(self)
        out["actions"] = list(self.actions)
        if not self.shape_tol:
            del out["shape_tol"]
        if self.sense is None:
            del out["sense"], out["sense_max_actions"]
        for name in ("turn_noise", "contact_noise", "payoff"):
            if out[name] is None:
                del out[name]
        return out

    @classmethod
    def from_json(cls, doc: dict[str, Any]) -> SweepOptions:
        """Options from :meth:`to_json`."""
        known = {k: v for k, v in doc.items() if k in cls.__dataclass_fields__}
        if "actions" in known:
            known["actions"] = tuple(known["actions"])
        return cls(**known)

    @property
    def key(self) -> str:
        """16 hex digits identifying the options (rows of other options are not resumed)."""
        text = json.dumps(self.to_json(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def plan_args(self) -> list[str]:
        """The ``bayesgrasp plan PART`` arguments that give the same plan document."""
        args = ["--json"]
        if self.prior != "uniform":
            args += ["--prior", self.prior]
        defaults = SweepOptions()
        flags = (
            ("squeeze_cost", "--squeeze-cost"),
            ("verify_cost", "--verify-cost"),
            ("first_squeeze_cost", "--first-squeeze-cost"),
            ("first_push_grasp_cost", "--first-push-grasp-cost"),
            ("retry_cost", "--retry-cost"),
            ("push_grasp_cost", "--push-grasp-cost"),
            ("goal", "--goal"),
            ("method", "--method"),
            ("max_actions", "--max-actions"),
            ("layer", "--layer"),
            ("flatten_tol", "--flatten-tol"),
            ("shape_tol", "--shape-tol"),
        )
        for name, flag in flags:
            v = getattr(self, name)
            if v != getattr(defaults, name):
                args += [flag, str(v)]
        if self.actions != defaults.actions:
            args += ["--actions", ",".join(self.actions)]
        if self.accuracy_deg:
            args += ["--accuracy", str(self.accuracy_deg)]
        if self.guaranteed:
            args.append("--guaranteed")
        for name, flag in (
            ("turn_noise", "--turn-noise"),
            ("contact_noise", "--contact-noise"),
            ("payoff", "--payoff"),
        ):
            v = getattr(self, name)
            if v is not None:
                args += [flag, str(v)]
        return args
