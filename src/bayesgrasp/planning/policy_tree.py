"""Policies as trees: the type of a branching plan, its figures, and its text.

A :class:`Policy` is a tree (the paper, section 6.2: "the resulting plans would have
branches, with different sensor values determining the actual path taken"). A
:class:`PolicyNode` is an action (its kind and gripper angle: the root's angle is the
gripper's world angle, a later node's is the turn relative to the previous action, as in
linear plans); its :class:`Branch` es are half-open reading intervals ``[lo, hi)`` that
together cover every reading, each with its probability (given that the node is reached)
and its next node or leaf. A leaf :class:`Declare` s a final orientation (in the last
gripper frame; with several parts also which part) and then verifies, or :class:`Reject` s
(the part goes back to the feeder without a verification).

The cost semantics of the figures a :class:`Policy` carries, and how the planners find
one, are in :mod:`bayesgrasp.planning.policy`; :func:`policy_text` tells a policy as an
indented tree a person can follow.

Examples
--------
>>> from bayesgrasp.planning.result import PlanStep
>>> leaf = Declare(0, "part", 0.0, 1.0)
>>> node = PolicyNode(PlanStep("squeeze", 0.0), (Branch(-math.inf, math.inf, 1.0, leaf),))
>>> tree_depth(node), node.branch(3.0).next.orientation
(1, 0.0)
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import PlanningError
from ..model.sensing import WidthSensor
from .result import PlanStep

if TYPE_CHECKING:  # pragma: no cover
    from ..model.noise import NoiseModel

__all__ = [
    "Branch",
    "Declare",
    "Leaf",
    "Policy",
    "PolicyNode",
    "Reject",
    "policy_text",
    "tree_depth",
    "tree_leaves",
]


@dataclass(frozen=True, slots=True)
class Declare:
    """A leaf that declares a final state, then verifies.

    Attributes
    ----------
    part : int
        Index of the declared part among the candidates.
    part_name : str
    orientation : float
        The declared orientation of the part in the frame of the last action, ``[0, 2 pi)``.
    success_probability : float
        Probability that the declaration is right, given that the leaf is reached.
    """

    part: int
    part_name: str
    orientation: float
    success_probability: float


@dataclass(frozen=True, slots=True)
class Reject:
    """A leaf that sends the part back to the feeder without a verification."""


@dataclass(frozen=True, slots=True)
class Branch:
    """Readings in ``[lo, hi)`` (part units; ``-inf`` / ``inf`` at the ends) lead to ``next``.

    ``probability`` is the probability of such a reading given that the node is reached.
    """

    lo: float
    hi: float
    probability: float
    next: PolicyNode | Declare | Reject


@dataclass(frozen=True, slots=True)
class PolicyNode:
    """An action and its branches on the reading it yields.

    Attributes
    ----------
    step : PlanStep
        ``step.kind`` the action's name; ``step.alpha`` the world gripper angle (root) or the
        turn relative to the previous action (radians).
    branches : tuple of Branch
        In increasing reading order, tiling the real line.
    margin : float
        Half the width of the action's class of turns (radians): an error in ``alpha`` of
        less than this changes no state's outcome (the root's first angle: ``inf``).
    """

    step: PlanStep
    branches: tuple[Branch, ...]
    margin: float = math.inf

    def branch(self, reading: float) -> Branch:
        """The branch that a reading falls in."""
        for b in self.branches:
            if reading < b.hi:
                return b
        return self.branches[-1]


Leaf = Declare | Reject


@dataclass(frozen=True, slots=True, eq=False)
class Policy:
    """The Bayes policy of a problem and sensor, and its figures (see the module notes).

    Attributes
    ----------
    root : PolicyNode
    parts : tuple of str
        Names of the candidate parts.
    part_prior : tuple of float
    sensor : WidthSensor
    max_actions : int
    expected_cost : float
        ``cycle_cost / success_probability``: the expected cost until a cycle succeeds.
    success_probability : float
        ``P``, per cycle.
    cycle_cost : float
        ``E[C] + rho (1 - P)``: the expected cost of one cycle, retry overhead included.
    reject_probability : float
        Probability that a cycle ends in a rejection.
    expected_actions : float
        Expected number of actions in one cycle.
    expected_entropy : tuple of float
        ``expected_entropy[l]``: the expected entropy (bits) of the belief over the states
        after the reading of action ``l + 1`` (a path that ended earlier keeps its last
        belief), for ``l`` up to the policy's depth minus one.
    sensorless_cost : float or None
        The sensorless Bayes plan's expected cost within ``max_actions`` (one part, when
        asked for; else ``None``).
    iterations : int
        Parametric (Dinkelbach) steps taken (over both depths when deepening).
    beliefs : int
        Distinct (belief, actions left) pairs in the programme of the step whose policy is
        returned.
    searched : int
        (Belief, actions left) pairs searched over all the parametric steps (the search's
        work: a belief searched again with a larger budget counts again).
    first_angle_exact : bool
        Every first gripper angle that can be optimal was tried (see the module notes).
    units : str or None
        Units of the readings (the parts' units).
    noise : NoiseModel or None
        The action noise the policy was planned and evaluated under
        (:func:`~bayesgrasp.planning.noisy_policy.plan_noisy_policy`; ``None``: exact
        actions).
    refinement_bound : float
        Noisy actions: no single turn of the policy, the rest kept, can lower the value at
        the policy's ratio by more than this (0 when exact; see
        :mod:`~bayesgrasp.planning.noisy_policy`).
    payoff : tuple of float or None
        With a payoff (:mod:`~bayesgrasp.planning.noisy_policy`), the value of each state:
        a declaring leaf stops and earns the payoff of the state the part is in (its
        ``success_probability`` is then the expected payoff, and ``success_probability``
        of the policy the expected payoff of a cycle).
    stopped : str
        Empty when the search finished. Otherwise why it stopped (its time or memory bound)
        before proving the best policy of ``requested_actions`` actions: the policy is then
        the best of at most ``max_actions`` actions (the deepest search that finished), and
        no policy of ``requested_actions`` costs less than ``lower_bound``.
    requested_actions : int
        The number of actions asked for (``max_actions`` unless the search stopped).
    lower_bound : float
        A lower bound on the expected cost of every policy of ``requested_actions`` actions
        (``c_first / U + v``: a cycle acts once and verifies what it declares, and succeeds
        with at most ``U``; :func:`~bayesgrasp.planning.policy.lower_bound`). A finished
        exact search gives its own cost (the optimum); a finished search under noisy actions
        ``nan`` (its optimum is over a candidate set of turns, see
        :mod:`~bayesgrasp.planning.noisy_policy`).
    """

    root: PolicyNode
    parts: tuple[str, ...]
    part_prior: tuple[float, ...]
    sensor: WidthSensor
    max_actions: int
    expected_cost: float
    success_probability: float
    cycle_cost: float
    reject_probability: float
    expected_actions: float
    expected_entropy: tuple[float, ...]
    sensorless_cost: float | None = None
    iterations: int = 1
    beliefs: int = 0
    first_angle_exact: bool = True
    units: str | None = None
    searched: int = 0
    noise: NoiseModel | None = None
    refinement_bound: float = 0.0
    payoff: tuple[float, ...] | None = None
    stopped: str = ""
    requested_actions: int = 0
    lower_bound: float = math.nan

    def __post_init__(self) -> None:
        if not self.requested_actions:
            object.__setattr__(self, "requested_actions", self.max_actions)

    @property
    def complete(self) -> bool:
        """Whether the search finished (the policy is the best of ``requested_actions``)."""
        return not self.stopped

    @property
    def expected_total_actions(self) -> float:
        """Expected number of actions until a cycle succeeds (``expected_actions / P``)."""
        p = self.success_probability
        return self.expected_actions / p if p > 0 else math.inf

    @property
    def depth(self) -> int:
        """Most actions on any path."""
        return tree_depth(self.root)

    def leaves(self) -> Iterator[tuple[float, Declare | Reject]]:
        """Every leaf with the probability of reaching it."""
        yield from tree_leaves(self.root, 1.0)


def tree_depth(node: PolicyNode) -> int:
    """Most actions on any path from ``node`` down."""
    return 1 + max(
        (tree_depth(b.next) for b in node.branches if isinstance(b.next, PolicyNode)), default=0
    )


def tree_leaves(node: PolicyNode, p: float = 1.0) -> Iterator[tuple[float, Declare | Reject]]:
    """Every leaf below ``node`` with the probability of reaching it (``p``: of ``node``)."""
    for b in node.branches:
        if isinstance(b.next, PolicyNode):
            yield from tree_leaves(b.next, p * b.probability)
        else:
            yield p * b.probability, b.next


# -- presentation --------------------------------------------------------------------------


def policy_text(
    policy: Policy, units: str | None = None, digits: int = 2, min_probability: float = 0.0
) -> str:
    """The policy as an indented tree a person can follow (angles in degrees).

    Each node says the action; each branch the readings that take it (``below a``,
    ``in [a, b)``, ``b or more``), the probability of such a reading where the node is
    reached, and what follows. With noisy readings a node has a bin for nearly every
    encoder step, most of them with a tiny probability; ``min_probability`` leaves out of the
    text the branches whose probability where their node is reached is below it (and so
    their subtrees), and says at each node how many were left out and their probability in
    all. The JSON document (:func:`bayesgrasp.io.policies.policy_document`) keeps every
    branch: a robot runs that, not the text.

    Parameters
    ----------
    policy : Policy
    units : str, optional
        Units of the readings (default: the policy's, else none).
    digits : int
        Decimals of readings and angles.
    min_probability : float
        Leave out the branches whose probability at their node is below this (default 0:
        every branch).

    Examples
    --------
    >>> from bayesgrasp.geometry import Part
    >>> from bayesgrasp.model import Problem
    >>> rect = Problem.build(Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)], units="mm"))
    >>> from bayesgrasp.planning.policy import plan_policy
    >>> print(policy_text(plan_policy(rect, "width", 2)))
    squeeze with the gripper at 0.00 deg
      if the width reads below 1.50 mm (p = 0.70): declare 90.00 deg (success 0.50)
      if the width reads 1.50 mm or more (p = 0.30): declare 0.00 deg (success 0.50)
    """
    if not 0.0 <= min_probability <= 1.0:
        raise PlanningError(f"min_probability must lie in [0, 1], got {min_probability!r}")
    u = policy.units if units is None else units
    unit = f" {u}" if u else ""
    lines: list[str] = []
    several = len(policy.parts) > 1

    def num(x: float) -> str:
        return f"{x:.{digits}f}"

    def prob(p: float) -> str:
        # Two significant digits below 10^-digits, so a small branch does not read "0.00".
        return f"{p:.{digits}f}" if p >= 10.0**-digits or p == 0.0 else f"{p:.1e}"

    def readings(b: Branch) -> str:
        if b.lo == -math.inf and b.hi == math.inf:
            return "any width"
        if b.lo == -math.inf:
            return f"the width reads below {num(b.hi)}{unit}"
        if b.hi == math.inf:
            return f"the width reads {num(b.lo)}{unit} or more"
        return f"the width reads in [{num(b.lo)}, {num(b.hi)}){unit}"

    def leaf(x: Declare | Reject) -> str:
        if isinstance(x, Reject):
            return "reject (back to the feeder)"
        if policy.payoff is not None:
            likeliest = f"{math.degrees(x.orientation):.{digits}f} deg"
            return (
                f"stop, verify (expected payoff {x.success_probability:.{digits}f}; most "
                f"valued at {likeliest})"
            )
        what = f"{math.degrees(x.orientation):.{digits}f} deg"
        if several:
            what = f"part {x.part_name!r} at {what}"
        return f"declare {what} (success {x.success_probability:.{digits}f})"

    def walk(node: PolicyNode, depth: int, first: bool) -> None:
        pad = "  " * depth
        ang = f"{math.degrees(node.step.alpha):.{digits}f} deg"
        if first:
            lines.append(f"{pad}{node.step.kind} with the gripper at {ang}")
        else:
            lines.append(f"{pad}turn {ang}, {node.step.kind}")
        left_out, left_p = 0, 0.0
        for b in node.branches:
            if b.probability < min_probability:
                left_out += 1
                left_p += b.probability
                continue
            cond = f"{pad}  if {readings(b)} (p = {prob(b.probability)})"
            if isinstance(b.next, PolicyNode):
                lines.append(cond + ":")
                walk(b.next, depth + 2, False)
            else:
                lines.append(f"{cond}: {leaf(b.next)}")
        if left_out:
            s = "" if left_out == 1 else "s"
            lines.append(
                f"{pad}  ({left_out} more reading interval{s}, p = {prob(left_p)} in all, "
                "left out here; the JSON document lists every branch)"
            )

    walk(policy.root, 0, True)
    return "\n".join(lines)
