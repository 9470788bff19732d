"""The work of one part, as a worker runs it: read, plan, optionally simulate, one row.

Nothing here imports Dask: a task is a plain function of plain values (a
:class:`PartSource` holds a path, or a path and the file's bytes; :class:`SweepOptions`
holds the planning options), so it runs the same in a Dask worker, a process pool or a
test. A part that cannot be read or planned is a row with its error class and message,
never an exception: one bad file must not stop a sweep of a catalogue.

The row's ``plan_json`` is the document ``bayesgrasp plan PATH --json`` prints with the
same options (:meth:`SweepOptions.plan_args` gives those options as command-line
arguments), and its error message is the one the command prints after
``bayesgrasp: error:``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import socket
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, cast

from ..errors import BayesGraspError
from ..model.prior import Prior, parse_prior

if TYPE_CHECKING:
    from ..model.noise import NoiseModel
    from ..model.payoff import Payoff

__all__ = [
    "ENGINES",
    "GOALS",
    "METHODS",
    "ROW_COLUMNS",
    "ChunkResult",
    "PartSource",
    "SweepError",
    "SweepOptions",
    "error_rows",
    "part_id",
    "plan_part",
    "run_chunk",
    "timeout_row",
]

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


@dataclass(frozen=True, slots=True)
class PartSource:
    """One part file as the client sends it: its path, and its bytes or not.

    Attributes
    ----------
    path : str
        The path as the sweep found it (relative paths are relative to the client's working
        directory); the row's ``path`` and the name in error messages.
    sha256 : str
        Hex digest of the bytes the client hashed (``""`` when it could not read them).
    data : bytes, optional
        The file's bytes (for workers that do not share the client's file system); without
        them the worker reads ``path``.
    """

    path: str
    sha256: str = ""
    data: bytes | None = field(default=None, repr=False)

    @property
    def size(self) -> int:
        """Bytes sent (0 for a path)."""
        return 0 if self.data is None else len(self.data)


def part_id(path: str, sha256: str) -> str:
    """The stable id of a part: its path and the first 16 hex digits of its hash.

    Examples
    --------
    >>> part_id("parts/a.json", "0123456789abcdef0123")
    'parts/a.json#0123456789abcdef'
    """
    return f"{path}#{sha256[:16]}"


#: The columns of a row, in order, with their types (``str``, ``int``, ``float``, ``bool``);
#: every column may be missing (``None``), as for a part that failed.
ROW_COLUMNS: tuple[tuple[str, type], ...] = (
    ("part_id", str),
    ("path", str),
    ("sha256", str),
    ("options_key", str),
    ("status", str),  # ok | no-plan (no guaranteed plan: `plan` exits 1) | error
    ("error_class", str),
    ("error_message", str),
    ("name", str),
    ("units", str),
    ("sides", int),
    ("symmetry_order", int),
    ("states", int),
    ("period_rad", float),
    ("method", str),
    ("plans", int),
    ("bayes_actions", int),
    ("bayes_cost", float),
    ("bayes_probability", float),
    ("bayes_tolerance_rad", float),
    ("bayes_first_rad", float),
    ("bayes_final_rad", float),
    ("bayes_steps", str),  # JSON: [{"type": ..., "alpha_rad": ...}, ...]
    ("most_certain_actions", int),
    ("most_certain_probability", float),
    ("guaranteed_actions", int),
    ("guaranteed_missing", str),
    ("sim_engine", str),
    ("sim_trials", int),
    ("sim_predicted", float),
    ("sim_observed", float),
    ("sim_ci_low", float),
    ("sim_ci_high", float),
    ("sim_p_value", float),
    ("sim_jams", int),
    ("sim_seconds", float),
    ("plan_seconds", float),
    ("policy_cost", float),  # with `sense`: the Bayes policy's expected cost
    ("policy_success", float),
    ("policy_actions", float),  # expected actions a cycle
    ("policy_json", str),  # the document `bayesgrasp plan PATH --sense ... --json` prints
    ("outline", str),  # JSON: the outline's points (for the report's drawings)
    ("plan_json", str),  # the document `bayesgrasp plan PATH --json` prints
    ("sim_json", str),  # the document `bayesgrasp simulate PATH --json` prints
    ("worker", str),
    # last, so that results files written before them still resume
    ("turn_noise", str),  # `normal:SIGMA_DEG` / `uniform:A_DEG`, as given
    ("contact_noise", float),
    ("payoff", str),  # the payoff file
    ("bayes_payoff", float),  # the Bayes plan's expected payoff (with noise or a payoff)
)

#: Most outline points a row keeps for drawing (evenly spaced beyond that).
MAX_OUTLINE_POINTS = 2000


def _empty_row(path: str, sha256: str, options: SweepOptions) -> dict[str, Any]:
    row: dict[str, Any] = dict.fromkeys(name for name, _ in ROW_COLUMNS)
    row.update(
        part_id=part_id(path, sha256),
        path=path,
        sha256=sha256 or None,  # None: the bytes could not be read
        options_key=options.key,
        worker=f"{socket.gethostname()}:{os.getpid()}",
        turn_noise=options.turn_noise,
        contact_noise=options.contact_noise,
        payoff=options.payoff,
    )
    return row


def _error(row: dict[str, Any], exc: BaseException) -> dict[str, Any]:
    """Fill the error columns: the class and the message the CLI prints, on one line."""
    row["status"] = "error"
    row["error_class"] = type(exc).__name__
    text = " ".join(str(exc).split("\n")).strip() or repr(exc)
    row["error_message"] = text
    return row


def _read_bytes_part(path: str, data: bytes, options: SweepOptions) -> Any:
    """Read a part from its bytes, with the messages reading ``path`` would give.

    The bytes are written under the file's own name in a private folder and read there, so
    the part's name and the reader are those of the file; messages naming the temporary
    path are given back with ``path`` in its place.
    """
    from ..io import read_part

    with tempfile.TemporaryDirectory(prefix="bayesgrasp-sweep-") as tmp:
        local = Path(tmp) / (Path(path).name or "part")
        local.write_bytes(data)
        try:
            return read_part(local, layer=options.layer, tolerance=options.flatten_tol)
        except BayesGraspError as exc:
            text = str(exc).replace(str(local), path)
            if text == str(exc):
                raise
            err = type(exc).__new__(type(exc))
            Exception.__init__(err, text)
            raise err from None


def _read_part(source: PartSource, options: SweepOptions) -> tuple[Any, str]:
    """The part and the hash of the bytes it was read from."""
    from ..geometry.curved import with_shape_tol
    from ..io import resolve_part

    if source.data is not None:
        part = _read_bytes_part(source.path, source.data, options)
        return with_shape_tol(part, options.shape_tol), hashlib.sha256(source.data).hexdigest()
    try:
        with open(source.path, "rb") as f:
            digest = hashlib.file_digest(f, "sha256").hexdigest()
    except OSError:
        digest = ""  # the reader says why, in the CLI's words
    part = resolve_part(source.path, layer=options.layer, tolerance=options.flatten_tol)
    return with_shape_tol(part, options.shape_tol), digest


def _outline(part: Any) -> str:
    pts = part.outline
    if len(pts) > MAX_OUTLINE_POINTS:
        pts = pts[:: math.ceil(len(pts) / MAX_OUTLINE_POINTS)]
    return json.dumps([[round(float(x), 9), round(float(y), 9)] for x, y in pts])


def _plan(
    part: Any, options: SweepOptions, prior: Prior, payoff: Payoff | None = None
) -> tuple[Any, dict[str, Any], str]:
    """Problem, plan report and plan document, as ``bayesgrasp plan --json`` makes them."""
    from ..io.plans import plan_document
    from ..model.cost import CostModel
    from ..model.goal import Goal
    from ..model.problem import Problem
    from ..planning import plan_exact

    first = {
        name: c
        for name, c in (
            ("squeeze", options.first_squeeze_cost),
            ("push-grasp", options.first_push_grasp_cost),
        )
        if c is not None
    }
    cost = CostModel(
        {"squeeze": options.squeeze_cost, "push-grasp": options.push_grasp_cost},
        verify=options.verify_cost,
        first=first,
        retry=options.retry_cost,
    )
    pb = Problem.build(
        part,
        prior,
        cost,
        Goal(cast(Literal["single", "symmetry"], options.goal)),
        actions=options.actions,
        accuracy=math.radians(options.accuracy_deg),
    )
    given: dict[str, Any] = {"max_actions": options.max_actions, "layer": options.layer}
    given["flatten_tolerance"] = options.flatten_tol  # what the CLI records
    if options.noisy:
        return _plan_noisy(pb, options, payoff, given)
    if options.method == "bfs":
        from ..planning.bfs import plan_bfs

        rep = plan_bfs(pb, max_actions=options.max_actions)
    else:
        rep = plan_exact(pb, max_actions=options.max_actions)
    sure, missing = None, None
    if options.guaranteed:
        from ..planning.guaranteed import plan_guaranteed

        found = plan_guaranteed(pb)
        if found.status == "ok":
            sure = found
        else:
            missing = str(found.reason or "no guaranteed plan")
    doc = plan_document(rep, guaranteed=sure, guaranteed_missing=missing, inputs=given)
    return rep, doc, "ok" if missing is None else "no-plan"


def _noise(options: SweepOptions) -> NoiseModel:
    """The noise model of ``turn_noise`` and ``contact_noise`` (none when not given)."""
    from ..model.noise import NoiseModel

    return NoiseModel.of(options.turn_noise, options.contact_noise)


def _read_payoff(options: SweepOptions, payoff: Payoff | None) -> Payoff | None:
    """``options.payoff``, read here unless the client has read it."""
    if payoff is None and options.payoff is not None:
        from ..model.payoff import read_payoff

        return read_payoff(options.payoff)
    return payoff


def _plan_noisy(
    pb: Any, options: SweepOptions, payoff: Payoff | None, given: dict[str, Any]
) -> tuple[Any, dict[str, Any], str]:
    """The noise-aware Bayes plan and ``plan --turn-noise ... --json``'s document.

    With ``guaranteed``, also the plan guaranteed under the (bounded) noise, as ``plan
    --turn-noise uniform:A --guaranteed`` (status ``no-plan`` when there is none).
    """
    from ..runs.noisy import NoisyRun

    run = NoisyRun(_noise(options), payoff, options.max_actions, False, options.guaranteed)
    done = run.plan(pb)
    return done[0], run.document(done, given), "no-plan" if isinstance(done[1], str) else "ok"


def _simulate(rep: Any, options: SweepOptions) -> dict[str, Any]:
    """The ``bayesgrasp.simulate/1`` document of the Bayes plan's execution.

    Under noise or a payoff ``rep`` is the noise-aware result: its Bayes plan runs under the
    noise and is predicted exactly under it (and judged by the payoff), as ``bayesgrasp
    simulate PATH --turn-noise ... --json`` does.
    """
    from .. import report
    from ..sim.kinematic import GripperNoise, simulate_kinematic

    pb, option = rep.problem, rep.bayes_plan
    noise: Any = GripperNoise(options.noise_kind, math.radians(options.noise_deg))  # type: ignore[arg-type]
    deg, kind, u, model = options.noise_deg, options.noise_kind, None, None
    if options.noisy:
        model, u, option = _noise(options), rep.payoff, rep.bayes_plan.option
        noise = GripperNoise.of(model.turn)
        kind = model.turn.kind
        deg = 0.0 if options.turn_noise is None else float(options.turn_noise.partition(":")[2])
    if options.simulate == "kinematic":
        res = simulate_kinematic(
            pb, option, options.n_trials, noise if model is None else model, rng=options.seed,
            payoff=u,
        )  # fmt: skip
    else:
        from ..sim import simulate_mujoco

        res = simulate_mujoco(
            pb,
            option,
            options.n_trials,
            offset=options.offset_mm / 1000.0,  # millimetres to metres
            noise=noise,
            rng=options.seed,
            workers=1,
        )
        if model is not None and (not model.exact or u is not None):
            from ..sim.result import with_prediction

            res = with_prediction(res, pb, model, u)  # MuJoCo drew the turn error
    from ..io.plans import provenance
    from ..runs.specs import simulate_inputs

    doc = report.simulate_json(res, pb.part)  # with the provenance `bayesgrasp simulate` writes
    how = simulate_inputs(
        str(options.simulate), "bayes", options.seed, options.n_trials, deg, kind,
        options.offset_mm, None, 1 if options.simulate == "mujoco" else None,
    )  # fmt: skip
    if options.noisy:
        how |= {"contact_noise": options.contact_noise, "payoff": options.payoff}
    given = {"max_actions": options.max_actions, "layer": options.layer}
    doc["provenance"] = provenance(pb, None, **how, **given, flatten_tolerance=options.flatten_tol)
    return doc


def _policy(
    row: dict[str, Any], problem: Any, options: SweepOptions, payoff: Payoff | None = None
) -> None:
    """The ``policy_*`` columns: the part's Bayes sensing policy (``plan --sense --json``).

    Under noise or a payoff the policy is planned under the noisy actions (and judged by
    the payoff), as ``plan PATH --sense S --turn-noise ... --json``.
    """
    from ..io.policies import policy_document

    if options.noisy:
        from ..planning.noisy_policy import plan_noisy_policy

        noisy = options.turn_noise is not None or options.contact_noise is not None
        pol = plan_noisy_policy(
            [problem],
            str(options.sense),
            options.sense_max_actions,
            _noise(options) if noisy else None,
            payoff=payoff,
            part_prior=None,
        )
    else:
        from ..planning.policy import plan_policy

        pol = plan_policy(problem, sensor=str(options.sense), max_actions=options.sense_max_actions)
    doc = policy_document(pol)
    row.update(
        policy_cost=doc["expected_cost"],
        policy_success=doc["success_probability"],
        policy_actions=doc["expected_actions"],
        policy_json=json.dumps(doc, allow_nan=False, separators=(",", ":")),
    )


def _fill(row: dict[str, Any], part: Any, doc: dict[str, Any]) -> None:
    """The row's plan columns, all taken from the plan document."""
    info = doc["part"]
    bayes = doc["options"][doc["bayes"]]
    sure = doc["options"][doc["most_certain"]]
    row.update(
        name=info["name"],
        units=info.get("units"),
        sides=info["n_sides"],
        symmetry_order=info["symmetry_order"],
        states=len(doc["stable_orientations_rad"]),
        period_rad=doc["period_rad"],
        method=doc["method"],
        plans=len(doc["options"]),
        bayes_actions=bayes["squeezes"],
        bayes_cost=bayes["expected_cost"],
        bayes_probability=bayes["success_probability"],
        bayes_tolerance_rad=bayes["tolerance_rad"],
        bayes_first_rad=bayes["first_squeeze_rad"],
        bayes_final_rad=bayes["final_orientation_rad"],
        bayes_steps=json.dumps(bayes["steps"], separators=(",", ":")),
        most_certain_actions=sure["squeezes"],
        most_certain_probability=sure["success_probability"],
        guaranteed_missing=doc.get("guaranteed_missing"),
        outline=_outline(part),
        plan_json=json.dumps(doc, allow_nan=False, separators=(",", ":")),
    )
    if doc.get("guaranteed"):
        row["guaranteed_actions"] = doc["guaranteed"]["squeezes"]
    if "expected_payoff" in doc:
        row["bayes_payoff"] = doc["expected_payoff"]


def plan_part(
    source: PartSource | str,
    options: SweepOptions,
    prior: Prior | None = None,
    payoff: Payoff | None = None,
) -> dict[str, Any]:
    """Read, plan and optionally simulate one part: one row, never an exception.

    Parameters
    ----------
    source : PartSource or str
        The part file (a path, or a path and its bytes).
    options : SweepOptions
    prior : Prior, optional
        ``options.prior`` already parsed (the engine parses it once, on the client, so
        that a prior file need not exist on the workers).
    payoff : Payoff, optional
        ``options.payoff`` already read (the same way).

    Returns
    -------
    dict
        One value per column of :data:`ROW_COLUMNS`.

    Examples
    --------
    >>> import tempfile
    >>> f = Path(tempfile.mkdtemp()) / "plate.wkt"
    >>> _ = f.write_text("POLYGON ((0 0, 4 0, 4 1, 1 1, 1 3, 0 3, 0 0))")
    >>> row = plan_part(str(f), SweepOptions())
    >>> row["status"], row["sides"], row["bayes_actions"]
    ('ok', 5, 3)
    >>> plan_part(str(f.with_name("missing.wkt")), SweepOptions())["error_class"]
    'PartFileError'
    """
    if isinstance(source, str):
        source = PartSource(source)
    row = _empty_row(source.path, source.sha256, options)
    t0 = time.perf_counter()
    try:
        part, digest = _read_part(source, options)
        if digest:
            row.update(sha256=digest, part_id=part_id(source.path, digest))
        payoff = _read_payoff(options, payoff)
        rep, doc, status = _plan(part, options, prior or parse_prior(options.prior), payoff)
        _fill(row, part, doc)
        row["status"] = status
    except Exception as exc:  # a bad part is a row; a bug in it too, with its class
        row["plan_seconds"] = time.perf_counter() - t0
        return _error(row, exc)
    if options.sense is not None:
        try:
            _policy(row, rep.problem, options, payoff)
        except Exception as exc:  # the plan columns stay; the message says which step failed
            _error(row, exc)
            row["error_message"] = f"sensing policy: {row['error_message']}"
    row["plan_seconds"] = time.perf_counter() - t0
    if options.simulate is not None:
        t1 = time.perf_counter()
        try:
            sim = _simulate(rep, options)
            row.update(
                sim_engine=sim["engine"],
                sim_trials=sim["trials"],
                sim_predicted=sim["predicted_success"],
                sim_observed=sim["observed_success"],
                sim_ci_low=sim["ci95"][0],
                sim_ci_high=sim["ci95"][1],
                # physics: the success test, every trial counted (no states' chi-square)
                sim_p_value=sim.get("success_p_value", sim["p_value"]),
                sim_jams=sim["jams"],
                sim_json=json.dumps(sim, allow_nan=False, separators=(",", ":")),
            )
        except Exception as exc:
            _error(row, exc)
        row["sim_seconds"] = time.perf_counter() - t1
    return row


def timeout_row(source: PartSource, options: SweepOptions, timeout: float) -> dict[str, Any]:
    """The error row of a part whose work took longer than ``timeout`` seconds."""
    row = _empty_row(source.path, source.sha256, options)
    return _error(
        row,
        TimeoutError(f"{source.path}: the part took longer than the timeout of {timeout:g} s"),
    )


@dataclass(frozen=True, slots=True)
class ChunkResult:
    """What a task gives back: the rows done and the parts it could not get to.

    Attributes
    ----------
    rows : list of dict
    pending : tuple of PartSource
        Parts left after a part timed out (its work may still be running: ``stuck``).
    stuck : bool
        A part's work outlived its timeout and still runs in this worker's process.
    worker : str
        Address of the Dask worker (``""`` outside Dask).
    """

    rows: list[dict[str, Any]]
    pending: tuple[PartSource, ...] = ()
    stuck: bool = False
    worker: str = ""


def _call_with_timeout(work: Callable[[], dict[str, Any]], timeout: float) -> dict[str, Any] | None:
    """``work()`` in a thread, or ``None`` when it is not done in ``timeout`` seconds.

    Python threads cannot be killed; the engine restarts the worker whose thread is stuck.
    """
    box: list[dict[str, Any]] = []
    t = threading.Thread(target=lambda: box.append(work()), daemon=True)
    t.start()
    t.join(timeout)
    return box[0] if box else None


def run_chunk(
    sources: Sequence[PartSource],
    options: SweepOptions,
    prior: Prior | None = None,
    timeout: float | None = None,
    payoff: Payoff | None = None,
) -> ChunkResult:
    """Plan a few parts (one task): a row each, stopping at the first that times out.

    Examples
    --------
    >>> run_chunk([PartSource("no-such-part.json")], SweepOptions()).rows[0]["status"]
    'error'
    """
    worker = ""
    try:  # the worker's address, to restart it when a part's work is stuck
        from distributed import get_worker

        worker = get_worker().address
    except (ImportError, ValueError):
        pass
    rows: list[dict[str, Any]] = []
    for i, src in enumerate(sources):
        if timeout is None:
            rows.append(plan_part(src, options, prior, payoff))
            continue
        row = _call_with_timeout(lambda s=src: plan_part(s, options, prior, payoff), timeout)  # type: ignore[misc]
        if row is None:
            rows.append(timeout_row(src, options, timeout))
            return ChunkResult(rows, tuple(sources[i + 1 :]), True, worker)
        rows.append(row)
    return ChunkResult(rows, (), False, worker)


def error_rows(
    sources: Sequence[PartSource], options: SweepOptions, exc: BaseException
) -> list[dict[str, Any]]:
    """Error rows for parts whose task failed as a whole (a worker died running it)."""
    return [_error(_empty_row(s.path, s.sha256, options), exc) for s in sources]
