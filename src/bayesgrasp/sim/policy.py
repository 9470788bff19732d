"""Executing a sensing policy: cycles on the model or in MuJoCo, against the policy's claims.

A policy (:mod:`bayesgrasp.planning.policy`) claims, per *cycle* (one run of the tree on a
fresh part), a success probability ``P``, a cycle cost ``c = E[C] + rho (1 - P)`` (actions
on the path, verification at a declaring leaf, the retry overhead ``rho`` when the cycle
fails or rejects) and a number of actions; and, over the whole process (cycles repeat until
one succeeds), the expected cost ``E = c / P``.

A simulation runs ``n`` cycles back to back. Each draws a part from the part prior and a
world orientation from the orientation prior (:func:`~bayesgrasp.sim.kinematic.sample_prior`),
then follows the tree: at a node it turns the gripper (plus an optional gripper error,
:class:`~bayesgrasp.sim.noise.GripperNoise`), acts, reads the jaw width and takes the branch
the reading falls in; at a leaf it verifies (a declaration is right when the part and the
final orientation are the declared ones under the goal) or rejects. A failed or rejected
cycle is followed by the next one, as the cost semantics say, so the parts oriented are the
cycles that succeed and the observed cost per oriented part is the renewal-reward ratio
``sum of cycle costs / successes`` (it converges to ``E``).

- :func:`simulate_policy` runs on the model's transfer functions and draws each reading
  from the sensor model, ``RES round((d(sigma) + e) / RES)``, ``e ~ Normal(0, SIGMA^2)``
  (:meth:`~bayesgrasp.model.sensing.WidthSensor.read`).
- :func:`simulate_policy_mujoco` runs every action in MuJoCo
  (:class:`~bayesgrasp.sim.engine.Squeezer`) and reads the real jaw separation at the end
  of each squeeze or push-grasp (:attr:`~bayesgrasp.sim.engine.ActionOutcome.width`),
  quantised at the sensor's resolution. The physics' own error is the sensor error; the
  model's normal error can be added on top (``add_sensor_error``).

Intervals (:class:`PolicySimulation`): the success count is binomial (Wilson score
interval); the mean cycle cost and actions are means of independent cycles (central limit
theorem, ``z`` sample standard errors); the cost per success is a ratio of means, whose
standard error is the delta method's ``sqrt(Var(C - E S) / n) / mean(S)`` with ``S`` the
success indicator (at least the relative half-width of the success interval, so that a run
without failures still has an honest interval).

How far MuJoCo's readings stray from ``d(sigma)``: with the default
:class:`~bayesgrasp.sim.params.SimParams`, settled squeezes of the catalogue parts (mm,
3-7 cm across) read 0.07-0.12 mm *below* the width at the stable orientation reached, with a
spread of 0.02-0.03 mm and at most 0.16 mm (house, rectangle, key, triangle, tuning fork,
IC chip); the jaws' force presses the soft contacts in (``solref`` 4 ms).
:data:`MUJOCO_SIGMA` = 0.2 mm, about twice that bias, is the default SIGMA of a policy
executed in MuJoCo (:func:`mujoco_sensor`), with RES = 0.1 mm.
"""

from __future__ import annotations

import math
import multiprocessing
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..angles import TWO_PI, circle_distance
from ..errors import SimulationError
from ..geometry.polygon import Part
from ..geometry.push import push_grasp_function
from ..model.actions import SQUEEZE, get_action
from ..model.noise import NoiseModel
from ..model.problem import Problem, nearest_state
from ..model.sensing import WidthSensor
from ..planning.policy import Declare, Policy, PolicyNode, Reject
from .kinematic import sample_prior, with_contacts
from .noise import GripperNoise, as_generator
from .params import SimParams
from .policy_result import PolicySimulation, policy_simulation_json, policy_simulation_text
from .result import Progress, check_trials

__all__ = [
    "MUJOCO_RESOLUTION",
    "MUJOCO_SIGMA",
    "PolicySimulation",
    "mujoco_sensor",
    "policy_simulation_json",
    "policy_simulation_text",
    "simulate_policy",
    "simulate_policy_mujoco",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
BoolArray = NDArray[np.bool_]

#: Default reading error of MuJoCo's jaw separation (metres): about twice the largest
#: stray measured (see the module notes).
MUJOCO_SIGMA = 2e-4
#: Default resolution of MuJoCo's readings (metres).
MUJOCO_RESOLUTION = 1e-4


def mujoco_sensor(part: Part, scale: float) -> WidthSensor:
    """The default sensor of a policy run in MuJoCo, in the part's units.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> mujoco_sensor(Part.from_points([(0, 0), (40, 0), (10, 30)]), 0.001).spec
    'width:0.2,0.1'
    """
    return WidthSensor(MUJOCO_SIGMA / scale, MUJOCO_RESOLUTION / scale)


@dataclass(slots=True)
class _Run:
    """Per-cycle state of a vectorised kinematic run."""

    problems: tuple[Problem, ...]
    sensor: WidthSensor
    noise: GripperNoise
    gen: np.random.Generator
    part: IntArray
    theta: FloatArray
    cost: FloatArray
    acts: FloatArray
    ok: BoolArray
    rejected: BoolArray
    errors: list[FloatArray]
    contact: float = 0.0  # probability that a squeeze's jaws touch one after the other
    payoff: FloatArray | None = None  # the policy's payoff of each state, if it has one
    pushes: dict[int, Any] = field(default_factory=dict)  # each part's push-grasp function

    def act(self, j: int, kind: str, x: FloatArray) -> FloatArray:
        """Part ``j`` at ``x`` in the gripper frame after action ``kind`` (contact events drawn).

        With contact asynchrony a squeeze may act as a push-grasp from either side
        (:func:`~bayesgrasp.sim.kinematic.with_contacts`).
        """
        pb = self.problems[j]
        out = np.asarray(pb.transfer(kind)(x), dtype=np.float64)
        if self.contact <= 0 or kind != SQUEEZE.name:
            return out
        if j not in self.pushes:
            self.pushes[j] = push_grasp_function(pb.part, pb.states)
        return with_contacts(out, x, self.pushes[j], self.gen.random(len(x)), self.contact)

    def node(self, node: PolicyNode, idx: IntArray, first: bool) -> None:
        """Run the cycles ``idx`` through ``node`` and what follows it."""
        step = node.step
        cost = self.problems[0].cost
        err = self.noise.draw((len(idx),), self.gen)
        th = self.theta[idx] - (step.alpha + err)
        width = np.empty(len(idx))
        truth = np.empty(len(idx))
        parts = self.part[idx]
        for j in np.unique(parts):
            m = parts == j
            pb = self.problems[int(j)]
            th[m] = self.act(int(j), step.kind, th[m])
            width[m] = pb.diameter(th[m])
            truth[m] = pb.widths[nearest_state(pb.states, th[m])]
        self.theta[idx] = th
        self.cost[idx] += cost.action_cost(step.kind, first=first)
        self.acts[idx] += 1
        reading = self.sensor.read(width, self.gen)
        self.errors.append(reading - truth)
        his = np.array([b.hi for b in node.branches[:-1]])
        which = np.searchsorted(his, reading, side="right")
        for bi, br in enumerate(node.branches):
            sub = idx[which == bi]
            if len(sub) == 0:
                continue
            if isinstance(br.next, PolicyNode):
                self.node(br.next, sub, False)
            else:
                self.leaf(br.next, sub)

    def leaf(self, leaf: Declare | Reject, idx: IntArray) -> None:
        cost = self.problems[0].cost
        if isinstance(leaf, Declare):
            self.cost[idx] += cost.verify
            pb = self.problems[leaf.part]
            mine = idx[self.part[idx] == leaf.part]
            state = nearest_state(pb.states, self.theta[mine])
            if self.payoff is not None:
                # a payoff u: the cycle succeeds with probability u of the state reached
                # (so the successes count the payoff earned, in expectation)
                self.ok[mine] = self.gen.random(len(mine)) < self.payoff[state]
            else:
                self.ok[mine] = pb.success_states(leaf.orientation)[state]
        else:
            self.rejected[idx] = True
        failed = idx[~self.ok[idx]]
        self.cost[failed] += cost.retry


def _problems(problems: Problem | Iterable[Problem], policy: Policy) -> tuple[Problem, ...]:
    pbs = (problems,) if isinstance(problems, Problem) else tuple(problems)
    if len(pbs) != len(policy.parts):
        raise SimulationError(
            f"the policy tells {len(policy.parts)} part(s) apart; got {len(pbs)} problem(s)"
        )
    for pb in pbs:
        missing = set(_kinds(policy.root)) - set(pb.action_kinds)
        if missing:
            raise SimulationError(
                f"the policy uses {', '.join(sorted(missing))} actions but the problem of "
                f"{pb.part.name!r} has only {', '.join(pb.action_kinds)}"
            )
    return pbs


def _kinds(node: PolicyNode) -> Iterator[str]:
    yield node.step.kind
    for b in node.branches:
        if isinstance(b.next, PolicyNode):
            yield from _kinds(b.next)


def simulate_policy(
    problems: Problem | Iterable[Problem],
    policy: Policy,
    cycles: int,
    noise: GripperNoise | NoiseModel | None = None,
    rng: np.random.Generator | int | None = None,
    chunk: int = 1 << 16,
    progress: Progress | None = None,
) -> PolicySimulation:
    """Run ``cycles`` cycles of a policy on the model, readings drawn from its sensor.

    Parameters
    ----------
    problems : Problem or iterable of Problem
        The problems the policy was planned for (one per candidate part, in order); the
        first one's prior and cost model are used.
    policy : Policy
    cycles : int
    noise : GripperNoise or NoiseModel, optional
        Error added to every commanded gripper angle (default none; each node's
        ``margin`` bounds the error that changes nothing). A
        :class:`~bayesgrasp.model.noise.NoiseModel` also draws its contact asynchrony
        (a policy of :func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy` claims its
        figures under that noise).
    rng : numpy.random.Generator or int or None
    chunk : int
        Cycles per vectorised batch.
    progress : callable, optional
        ``progress(done, total)`` after each batch.

    Returns
    -------
    PolicySimulation

    Raises
    ------
    SimulationError
        Bad ``cycles`` or ``chunk``, or problems that do not match the policy.

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> tri = Problem.build(Part.from_points([(0, 0), (3, 0), (1, 2)]))
    >>> pol = plan_policy(tri, "width:0.1,0.05", 2)
    >>> sim = simulate_policy(tri, pol, 20000, rng=0)
    >>> sim.agrees, round(pol.success_probability, 3), round(sim.observed_success, 2)
    (True, 0.449, 0.44)
    """
    check_trials(cycles)
    if chunk < 1:
        raise SimulationError(f"`chunk` must be >= 1; got {chunk}")
    pbs = _problems(problems, policy)
    gen = as_generator(rng)
    contact = 0.0
    if isinstance(noise, NoiseModel):
        contact = noise.contact
        noise = GripperNoise(noise.turn.kind, noise.turn.scale)
    noise = noise or GripperNoise()
    out: dict[str, list[Any]] = {k: [] for k in ("cost", "acts", "ok", "rej", "err")}
    t0 = time.perf_counter()
    done = 0
    while done < cycles:
        m = min(chunk, cycles - done)
        run = _Run(
            pbs,
            policy.sensor,
            noise,
            gen,
            np.asarray(gen.choice(len(pbs), size=m, p=np.asarray(policy.part_prior)), np.intp),
            sample_prior(pbs[0].prior, m, gen),
            np.zeros(m),
            np.zeros(m),
            np.zeros(m, dtype=bool),
            np.zeros(m, dtype=bool),
            [],
            contact,
            None if policy.payoff is None else np.asarray(policy.payoff, dtype=np.float64),
        )
        run.node(policy.root, np.arange(m), True)
        out["cost"].append(run.cost)
        out["acts"].append(run.acts)
        out["ok"].append(run.ok)
        out["rej"].append(run.rejected)
        out["err"].extend(run.errors)
        done += m
        if progress is not None:
            progress(done, cycles)
    ok = np.concatenate(out["ok"])
    return PolicySimulation(
        "kinematic",
        policy,
        cycles,
        int(ok.sum()),
        int(np.concatenate(out["rej"]).sum()),
        0,
        np.concatenate(out["cost"]),
        np.concatenate(out["acts"]),
        ok,
        np.concatenate(out["err"]),
        time.perf_counter() - t0,
    )


# -- MuJoCo ---------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Cycle:
    part: int
    theta0: float  # world orientation
    angle_err: tuple[float, ...]  # gripper error of each action (radians)
    offsets: tuple[float, ...]  # signed offset of each action (metres)
    reading_err: tuple[float, ...]  # the model's sensor error of each reading (part units)
    leads: tuple[int | None, ...] = ()  # leading jaw of each lagged squeeze (jaw_lag > 0)


@dataclass(frozen=True, slots=True)
class _CycleOut:
    cost: float
    actions: int
    success: bool
    rejected: bool
    jammed: bool
    errors: tuple[float, ...]
    sim_time: float


_CTX: dict[str, Any] = {}
#: Cycles a batched round: progress is reported after each.
_BATCH = 1024


def _init_mujoco(
    problems: tuple[Problem, ...], policy: Policy, scales: tuple[float, ...], params: SimParams
) -> None:
    _CTX.clear()
    _CTX.update(problems=problems, policy=policy, scales=scales, params=params, squeezers={})


def _squeezer(j: int) -> Any:
    from .squeezer import Squeezer

    sq = _CTX["squeezers"]
    if j not in sq:
        pb = _CTX["problems"][j]
        sq[j] = Squeezer(pb.part, _CTX["scales"][j], _CTX["params"])
    return sq[j]


def _run_cycle(c: _Cycle) -> _CycleOut:
    problems: tuple[Problem, ...] = _CTX["problems"]
    policy: Policy = _CTX["policy"]
    params: SimParams = _CTX["params"]
    sensor = policy.sensor
    pb = problems[c.part]
    scale = _CTX["scales"][c.part]
    sq = _squeezer(c.part)
    cost = pb.cost
    yaw = c.theta0
    node: PolicyNode | Declare | Reject = policy.root
    total, acts, jammed, t_sim = 0.0, 0, False, 0.0
    errors: list[float] = []
    leads = c.leads or (None,) * len(c.angle_err)
    while isinstance(node, PolicyNode):
        step = node.step
        start = float(np.mod(yaw - step.alpha - c.angle_err[acts], TWO_PI))
        res = sq.act(
            start, c.offsets[acts], get_action(step.kind).pushes_first, leads[acts],
            pb.states.stable,
        )  # fmt: skip
        t_sim += res.sim_time
        total += cost.action_cost(step.kind, first=acts == 0)
        yaw = res.end
        state = int(nearest_state(pb.states, np.array([yaw]))[0])
        stuck = (not res.settled) or float(
            circle_distance(yaw, pb.states.stable[state])
        ) > params.jam_tol
        jammed |= stuck
        width = res.width / scale + c.reading_err[acts]
        reading = float(WidthSensor(0.0, sensor.resolution).read(np.array([width]))[0])
        if not stuck:  # a jammed part is at no state: its reading strays by construction
            errors.append(reading - float(pb.widths[state]))
        acts += 1
        node = node.branch(reading).next
    ok = False
    if isinstance(node, Declare):
        total += cost.verify
        if node.part == c.part:
            state = int(nearest_state(pb.states, np.array([yaw]))[0])
            ok = bool(pb.success_states(node.orientation)[state])
    if not ok:
        total += cost.retry
    return _CycleOut(total, acts, ok, isinstance(node, Reject), jammed, tuple(errors), t_sim)


def _run_cycles_batched(
    init: tuple[Any, ...], cycles: Sequence[_Cycle], nthread: int
) -> list[_CycleOut]:
    """Every cycle, the actions of cycles at the same policy node batched in C threads.

    A policy branches on the width read, so the next action of a cycle is known only once
    its previous action has ended. At each round the cycles still running are grouped by
    part and policy node (the same action, from their own yaws) and each group is one call
    of :meth:`~bayesgrasp.sim.rollout.BatchSqueezer.act`; then each cycle reads its width and
    follows its branch, exactly as :func:`_run_cycle` does one cycle at a time.
    """
    from .rollout import BatchSqueezer

    problems: tuple[Problem, ...] = init[0]
    policy: Policy = init[1]
    scales: tuple[float, ...] = init[2]
    params: SimParams = init[3]
    sensor = policy.sensor
    n = len(cycles)
    node: list[PolicyNode | Declare | Reject] = [policy.root] * n
    yaw = [c.theta0 for c in cycles]
    total, acts = [0.0] * n, [0] * n
    jammed, t_sim = [False] * n, [0.0] * n
    errors: list[list[float]] = [[] for _ in range(n)]
    batchers: dict[int, BatchSqueezer] = {}
    try:
        while True:
            groups: dict[tuple[int, int], list[int]] = {}
            for i in range(n):
                nd = node[i]
                if isinstance(nd, PolicyNode):
                    groups.setdefault((cycles[i].part, id(nd)), []).append(i)
            if not groups:
                break
            for (j, _), idx in groups.items():
                if j not in batchers:
                    batchers[j] = BatchSqueezer(problems[j].part, scales[j], params, nthread)
                pb, scale = problems[j], scales[j]
                step = node[idx[0]].step  # type: ignore[union-attr]
                start = np.array([yaw[i] - step.alpha - cycles[i].angle_err[acts[i]] for i in idx])
                off = np.array([cycles[i].offsets[acts[i]] for i in idx])
                lagged = bool(cycles[idx[0]].leads)
                lead = np.array([cycles[i].leads[acts[i]] for i in idx]) if lagged else None
                res = batchers[j].act(
                    np.mod(start, TWO_PI), off, get_action(step.kind).pushes_first, lead,
                    pb.states.stable,
                )  # fmt: skip
                states = nearest_state(pb.states, res.end)
                for b, i in enumerate(idx):
                    c, a = cycles[i], acts[i]
                    t_sim[i] += float(res.sim_time[b])
                    total[i] += pb.cost.action_cost(step.kind, first=a == 0)
                    yaw[i] = float(res.end[b])
                    state = int(states[b])
                    stuck = (not res.settled[b]) or float(
                        circle_distance(yaw[i], pb.states.stable[state])
                    ) > params.jam_tol
                    jammed[i] |= stuck
                    width = float(res.width[b]) / scale + c.reading_err[a]
                    reading = float(WidthSensor(0.0, sensor.resolution).read(np.array([width]))[0])
                    if not stuck:
                        errors[i].append(reading - float(pb.widths[state]))
                    acts[i] = a + 1
                    node[i] = node[i].branch(reading).next  # type: ignore[union-attr]
    finally:
        for bs in batchers.values():
            bs.close()
    outs = []
    for i, c in enumerate(cycles):
        pb, nd, total_i = problems[c.part], node[i], total[i]
        ok = False
        if isinstance(nd, Declare):
            total_i += pb.cost.verify
            if nd.part == c.part:
                state = int(nearest_state(pb.states, np.array([yaw[i]]))[0])
                ok = bool(pb.success_states(nd.orientation)[state])
        if not ok:
            total_i += pb.cost.retry
        outs.append(
            _CycleOut(
                total_i, acts[i], ok, isinstance(nd, Reject), jammed[i], tuple(errors[i]),
                t_sim[i],
            )
        )  # fmt: skip
    return outs


def _map_cycles(
    init: tuple[Any, ...], cycles: Sequence[_Cycle], workers: int
) -> Iterator[_CycleOut]:
    if workers <= 1:
        _init_mujoco(*init)
        for c in cycles:
            yield _run_cycle(c)
        return
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    chunk = max(1, min(8, len(cycles) // (4 * workers)))
    with ctx.Pool(workers, initializer=_init_mujoco, initargs=init) as pool:
        yield from pool.imap(_run_cycle, cycles, chunksize=chunk)


def simulate_policy_mujoco(
    problems: Problem | Iterable[Problem],
    policy: Policy,
    cycles: int,
    params: SimParams | None = None,
    offset: float = 0.0,
    noise: GripperNoise | None = None,
    rng: np.random.Generator | int | None = None,
    workers: int = 1,
    scale: float | None = None,
    add_sensor_error: bool = False,
    progress: Progress | None = None,
    method: str = "rollout",
) -> PolicySimulation:
    """Run ``cycles`` cycles of a policy in MuJoCo, acting on the real jaw separation.

    Each reading is the jaw separation at the end of the action, less the vertex capsules'
    diameter (:meth:`~bayesgrasp.sim.engine.Squeezer.width`), in the part's units, quantised
    at the sensor's resolution (``add_sensor_error``: plus the sensor model's normal error).

    Parameters
    ----------
    problems : Problem or iterable of Problem
    policy : Policy
    cycles : int
    params : SimParams, optional
        The physics settings. With ``jaw_lag > 0`` one jaw of every squeeze starts that
        many seconds early (contact asynchrony, :class:`~bayesgrasp.sim.params.SimParams`);
        with ``lead_jaw="random"`` the leading jaw of each action is drawn from ``rng``
        with the other draws, so a run does not depend on ``workers``.
    offset : float
        Distance (metres) of the part's centre from the gripper centre at each action, on a
        random side.
    noise : GripperNoise, optional
        Error added to every commanded gripper angle.
    rng : numpy.random.Generator or int or None
    workers : int
        ``rollout``: C threads of MuJoCo's rollout; ``stepped``: processes (1: run here).
        The results do not depend on it.
    scale : float, optional
        Metres per unit of the parts' coordinates (default from each part's units).
    add_sensor_error : bool
        Also add ``e ~ Normal(0, SIGMA^2)`` of the policy's sensor to every reading.
    progress : callable, optional
    method : {"rollout", "stepped"}
        ``rollout`` (default): the cycles at the same policy node act together, batched in
        MuJoCo's C rollout threads (:class:`~bayesgrasp.sim.rollout.BatchSqueezer`);
        ``stepped``: one cycle at a time from Python.

    Returns
    -------
    PolicySimulation
        With ``engine="mujoco"``.

    Raises
    ------
    MissingExtraError
        MuJoCo is not installed (extra ``sim``).
    SimulationError
        Bad ``cycles``, ``workers`` or ``offset``, or problems that do not match the policy.
    """
    from .scene import units_scale
    from .squeezer import SIZE_RANGE, require_mujoco

    require_mujoco()
    check_trials(cycles)
    if method not in ("rollout", "stepped"):
        raise SimulationError(f"`method` must be rollout or stepped; got {method!r}")
    if not isinstance(workers, int | np.integer) or workers < 1:
        raise SimulationError(f"`workers` must be an integer >= 1; got {workers!r}")
    if not (math.isfinite(offset) and offset >= 0):
        raise SimulationError(f"`offset` must be a finite distance >= 0 (metres); got {offset!r}")
    pbs = _problems(problems, policy)
    params = params or SimParams()
    noise = noise or GripperNoise()
    scales = tuple(units_scale(p.part.units) if scale is None else scale for p in pbs)
    for pb, sc in zip(pbs, scales, strict=True):
        across = 2.0 * pb.part.hull.size * sc
        if not SIZE_RANGE[0] <= across <= SIZE_RANGE[1]:
            raise SimulationError(
                f"{pb.part.name!r} measures {across:.3g} m across at {sc:g} m per unit; the "
                f"physics settings suit parts of {SIZE_RANGE[0] * 1000:g} mm to "
                f"{SIZE_RANGE[1] * 100:g} cm: give the part's units"
            )
    gen = as_generator(rng)
    k = policy.max_actions
    parts = gen.choice(len(pbs), size=cycles, p=np.asarray(policy.part_prior))
    theta0 = sample_prior(pbs[0].prior, cycles, gen)
    errs = noise.draw((cycles, k), gen)
    signs = np.where(gen.random((cycles, k)) < 0.5, -1.0, 1.0) * offset
    sig = policy.sensor.sigma if add_sensor_error else 0.0
    read_err = gen.normal(0.0, 1.0, (cycles, k)) * sig
    tasks = [
        _Cycle(int(parts[i]), float(theta0[i]), tuple(errs[i].tolist()),
               tuple(signs[i].tolist()), tuple(read_err[i].tolist()))
        for i in range(cycles)
    ]  # fmt: skip
    if params.jaw_lag > 0 and params.lead_jaw == "random":  # drawn last: the rest as unlagged
        leads = np.where(gen.random((cycles, k)) < 0.5, -1, 1)
        tasks = [replace(t, leads=tuple(leads[i].tolist())) for i, t in enumerate(tasks)]
    t0 = time.perf_counter()
    outs: list[_CycleOut] = []
    init = (pbs, policy, scales, params)
    if method == "stepped":
        for o in _map_cycles(init, tasks, workers):
            outs.append(o)
            if progress is not None:
                progress(len(outs), cycles)
    else:
        for lo in range(0, cycles, _BATCH):
            outs += _run_cycles_batched(init, tasks[lo : lo + _BATCH], workers)
            if progress is not None:
                progress(len(outs), cycles)
    ok = np.array([o.success for o in outs], dtype=bool)
    return PolicySimulation(
        "mujoco",
        policy,
        cycles,
        int(ok.sum()),
        sum(o.rejected for o in outs),
        sum(o.jammed for o in outs),
        np.array([o.cost for o in outs]),
        np.array([float(o.actions) for o in outs]),
        ok,
        np.array([e for o in outs for e in o.errors], dtype=np.float64),
        time.perf_counter() - t0,
        params.jaw_lag,
    )
