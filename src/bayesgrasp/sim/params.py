"""Settings of the physics check, each with its default and the reason for it.

The defaults reproduce the frictionless squeeze model in MuJoCo 4.0.0; they come from the
feasibility runs of the first MuJoCo scenes and from the measurements of this module's
tests and benchmark (the accuracy study of the physics validation guide).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import BayesGraspError

__all__ = ["SimParams"]


class SimParamsError(BayesGraspError, ValueError):
    """A physics setting out of range."""


@dataclass(frozen=True, slots=True)
class SimParams:
    """Physical and numerical settings of a MuJoCo squeeze (SI units: m, kg, s, N, rad).

    Attributes
    ----------
    timestep : float
        2 ms: the largest step the contact time constant (4 ms, at least twice the step)
        allows. Chosen by the accuracy study of ``benchmarks/bench_simulate.py
        --accuracy`` (guide, "Physics validation"): against a reference of 0.5 ms steps and
        jaws closing at 5 mm/s, these defaults end in the reference's stable orientation in
        at least 99% of squeezes and push-grasps over the catalogue and curved examples.
    integrator : str
        ``implicitfast``: stable with the jaws' joint damping at this timestep.
    solver : str
        ``Newton``: the jaws settle; PGS with few iterations left 0.2-degree errors and
        jaws that never settled (notes).
    cone : str
        ``elliptic`` friction cones for the table contact (pyramidal also worked).
    solref_timeconst : float
        Contact time constant, 4 ms (at least twice the timestep, as MuJoCo advises); the
        notes used it.
    table_friction : float
        Sliding friction of the part on the table, 0.2 (a plastic part on a smooth metal
        plate). The notes' 6 g triangle agreed at 0.2 and 0.5, but 5 cm random polygons
        (10-15 g) squeezed with 0.5 N stalled at 0.5 where the couple ``force * |d'(theta)|``
        is small: 246/277 single squeezes agreed at 0.5, 270/277 at 0.2 (this module's
        measurement). The jaws are frictionless whatever this is.
    thickness : float
        The hull is extruded 1 cm: thin enough that the part does not tip, thick enough for
        robust side contacts.
    density : float
        1000 kg/m^3 (a plastic part): a 4 cm triangle weighs 6 g. With the jaw force
        proportional to the weight, the density does not change the outcome.
    edge_radius : float
        The jaws touch vertical capsules of radius 0.3 mm at the hull's vertices (see
        :mod:`bayesgrasp.sim.scene`): thin next to a part of a few centimetres, thick
        enough for robust contacts. It adds 0.6 mm to every width and moves no extremum.
    jaw_thickness : float
        4 mm plates.
    jaw_length : float
        16 cm plates (along y), or four times the part's size if that is longer: the part
        never slides off a jaw's end.
    jaw_mass : float
        0.1 kg per jaw (notes).
    force_ratio : float
        Each jaw's force limit is 8 times the part's weight (:meth:`squeeze_force`): 0.47 N
        for the notes' 6 g triangle, which they squeezed with 0.5 N. A fixed force does not
        fit every part: 0.5 N threw parts of 1-2 g out of the jaws (0/30 single squeezes
        agreed for a 1.2 cm random 10-gon, 8/30 at 1.6 cm, 61/100 for the 0.4 g
        ``ic-chip``), while scaled with the weight every size from 1.2 to 35 cm agreed in
        30/30. Against support friction the ratio is ``8 / table_friction`` = 40: the couple
        that turns the part, ``force * |d'(theta)|``, must beat the friction's moment.
    jaw_force : float
        The reference force, 0.5 N, for which ``jaw_kp`` and ``jaw_damping`` are given;
        both are scaled by ``squeeze_force / jaw_force``, so every part sees the same jaw
        motion and force ramp.
    jaw_damping : float
        Slide-joint damping, 10 N s/m at 0.5 N: with the force limit it caps a free jaw at
        5 cm/s (``jaw_force / jaw_damping``), the target speed, and damps the contact. At 20
        (a 2.5 cm/s cap) squeezes took half as long again, with the same agreement.
    jaw_kp : float
        Position gain, 1600 N/m at 0.5 N. The force limit, not the gain, sets the squeeze
        force; once a jaw is blocked its force ramps up at ``jaw_kp * jaw_speed``, so it
        reaches the limit 6 ms after contact (at the notes' 400 N/m: 25 ms; with the 10 ms
        settle, 1600 N/m cut the simulated time of a squeeze by a sixth and agreed with the
        reference in as many actions as 400, the accuracy study). A squeeze ends only once
        both jaws push with the full force.
    jaw_speed : float
        The jaw targets close at 5 cm/s (the notes found 1 and 5 cm/s to agree): still
        quasi-static for parts of a few centimetres (the accuracy study); 10 cm/s (with
        the damping halved again) lost 5% of the agreement.
    clearance : float
        Each jaw starts 1 mm outside the part's extent (the scene places the part exactly):
        short idle travel.
    settle_speed : float
        A squeeze ends when both jaws move slower than 0.1 mm/s ...
    settle_time : float
        ... for 0.01 s (five 2 ms steps), with both jaws at their force limit and the part
        at rest (``part_speed``, ``part_spin``): once that holds nothing is left to move
        the part. 0.02 s and the notes' 0.1 s changed no outcome in the accuracy study
        (0.1 s cost a third of a squeeze's time).
    max_time : float
        An action that has not settled 2 s (simulated) after its jaws could have crossed
        the whole opening at ``jaw_speed`` counts as a jam; a squeeze takes about 0.2 s.
    check_every : int
        Steps between two checks of the settling test and updates of the jaw targets in the
        stepped engine (:class:`~bayesgrasp.sim.engine.Squeezer`; 5: every 10 ms, the
        targets move 0.5 mm between updates). The batched engine checks every step.
    jam_tol : float
        A part that stops farther than 1 degree from every stable orientation jammed (the
        notes measured a median error of 0.011 degrees when it does not).
    push_distance : float
        For a push-grasp, the pushing (-x) jaw travels this far beyond first contact before
        the other jaw closes; 0 means twice the part's size (enough for the part to turn
        to a stable push orientation, which needs a travel of the order of its size).
    jaw_lag : float
        Contact asynchrony (the guide's "Noisy actions and payoffs"): in a squeeze one jaw's
        target starts closing this many seconds before the other's. The leading jaw touches
        first and pushes the part ``jaw_speed * jaw_lag / 2`` before the other meets it,
        while that is under ``clearance``; beyond, the pushed part reaches the lagging jaw
        before that jaw starts, and the push saturates at ``clearance``. 0 (the
        default): both jaws close together, the seed's pure squeeze. A push-grasp, which
        leads with one jaw on purpose, ignores it. The lag stands for any cause of one
        jaw touching first (an off-centre part is another, physics notes).
    lead_jaw : str
        Which jaw leads when ``jaw_lag > 0``: ``random`` (either, equally likely, drawn per
        squeeze: the model's contact asynchrony), ``-x`` or ``+x``.
    part_speed : float
        The part counts as at rest below 0.1 mm/s on the table (as the jaws' threshold) ...
    part_spin : float
        ... and 0.01 rad/s of yaw rate: in the 10 ms of ``settle_time`` it turns less than
        0.006 degrees, under a hundredth of ``jam_tol``.
    chunk_time : float
        The batched engine (:mod:`bayesgrasp.sim.rollout`) steps 20 ms at a time between
        its checks of which trials have settled (it finds the step within the chunk).
    retry_speed : float
        The batched engine runs an action that jammed at ``jaw_speed`` again with jaws at
        1 cm/s (the former speed, which agreed with the fine reference in every action of
        the accuracy study) and keeps that outcome, a safeguard: with sluggish jaws (0.1 kg
        whatever the part, ``scale_jaw_mass=False``) a 1.3 cm random 10-gon jammed in 12 of
        40 squeezes at 5 cm/s, in none at 1 cm/s. Jams are a few percent of actions, so
        the retry costs little. 0 (or not below ``jaw_speed``): no retry.
    scale_jaw_mass : bool
        The jaws' mass scales with their force, ``jaw_mass * squeeze_force / jaw_force``,
        as gain and damping do, so every part sees the same jaw motion (time constant
        ``jaw_mass / jaw_damping`` = 10 ms). With 0.1 kg jaws for every part, the jaws of a
        1 cm part (a force of 4 mN) took over a second to move and settle: its squeezes
        simulated 0.9 s instead of 0.13 s, and some stalled.

    Examples
    --------
    >>> SimParams().force_ratio
    8.0
    >>> SimParams(jaw_speed=0.01).jaw_speed
    0.01
    """

    timestep: float = 0.002
    integrator: str = "implicitfast"
    solver: str = "Newton"
    cone: str = "elliptic"
    solref_timeconst: float = 0.004
    table_friction: float = 0.2
    thickness: float = 0.01
    density: float = 1000.0
    edge_radius: float = 0.0003
    jaw_thickness: float = 0.004
    jaw_length: float = 0.16
    jaw_mass: float = 0.1
    jaw_damping: float = 10.0
    jaw_kp: float = 1600.0
    jaw_force: float = 0.5
    force_ratio: float = 8.0
    jaw_speed: float = 0.05
    clearance: float = 0.001
    settle_speed: float = 1e-4
    settle_time: float = 0.01
    max_time: float = 2.0
    check_every: int = 5
    jam_tol: float = math.radians(1.0)
    push_distance: float = 0.0
    jaw_lag: float = 0.0
    lead_jaw: str = "random"
    part_speed: float = 1e-4
    part_spin: float = 1e-2
    chunk_time: float = 0.02
    retry_speed: float = 0.01
    scale_jaw_mass: bool = True

    def squeeze_force(self, mass: float) -> float:
        """Force limit of each jaw for a part of the given mass (kg): ``force_ratio`` weights.

        Examples
        --------
        >>> round(SimParams().squeeze_force(0.006), 4), round(SimParams().squeeze_force(0.1), 3)
        (0.4709, 7.848)
        """
        return self.force_ratio * mass * 9.81

    def jaw_gains(self, mass: float) -> tuple[float, float, float]:
        """Force limit, position gain and joint damping of each jaw for a part of this mass.

        Examples
        --------
        >>> [round(x, 3) for x in SimParams().jaw_gains(0.006)]
        [0.471, 1506.816, 9.418]
        """
        force = self.squeeze_force(mass)
        k = force / self.jaw_force
        return force, self.jaw_kp * k, self.jaw_damping * k

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, str):
                continue
            nonneg = f.name in (
                "push_distance",
                "table_friction",
                "jaw_lag",
                "retry_speed",
                "scale_jaw_mass",
            )
            if not math.isfinite(value) or value < 0 or (value == 0 and not nonneg):
                want = ">= 0" if nonneg else "> 0"
                raise SimParamsError(
                    f"simulation setting `{f.name}` must be a finite number {want}; got {value!r}"
                )
        if self.integrator not in ("Euler", "RK4", "implicit", "implicitfast"):
            raise SimParamsError(
                "`integrator` must be Euler, RK4, implicit or implicitfast; "
                f"got {self.integrator!r}"
            )
        if self.solver not in ("PGS", "CG", "Newton"):
            raise SimParamsError(f"`solver` must be PGS, CG or Newton; got {self.solver!r}")
        if self.cone not in ("pyramidal", "elliptic"):
            raise SimParamsError(f"`cone` must be pyramidal or elliptic; got {self.cone!r}")
        if self.lead_jaw not in ("random", "-x", "+x"):
            raise SimParamsError(f"`lead_jaw` must be random, -x or +x; got {self.lead_jaw!r}")
