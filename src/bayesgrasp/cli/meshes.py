"""``plan MESH``: one resting pose's footprint as a planar part, or a policy over the poses.

``plan MESH [--pose K]`` plans pose K's footprint (default 0, the most probable) as any
planar part. ``plan MESH --sense S [--goal-pose K|any] [--pose-prior P]`` plans the policy
that tells the poses apart by their widths (:mod:`bayesgrasp.solid.policy`): the candidate
parts are the footprints ``pose-0``, ``pose-1``, ... in the order ``poses`` lists them, the
part prior their probabilities. The rest (printing, --json, --plot, --export, noise) is the
recognition policy's own path (:func:`.sensing.plan_policy_command`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..runs.poses import PoseOptionError, PoseProblems, pose_toppling, poses_toppling
from ..runs.poses import pose_prior_weights as weights_of
from ..solid.parts import study_of
from .specs import PartSpec, ProblemSpec, SenseSpec

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..solid.mesh import Solid
    from ..solid.poses import PoseStudy


def is_mesh_part(part: PartSpec) -> bool:
    """Whether PART is a mesh file (by ``--format`` or its extension)."""
    from ..solid.mesh import is_mesh

    if part.part is None:
        return False
    return is_mesh(part.part, part.fmt.value if part.fmt else None)


def mesh_options(
    part: PartSpec,
    sense: str | None,
    pose: int | None,
    goal_pose: str | None,
    pose_prior: str | None,
    candidates: bool,
    batch: Path | None,
) -> PartSpec:
    """Check the mesh options of ``plan``; PART with the pose to plan chosen.

    ``candidates``: more parts were given (further PARTs, --also or --part-prior).
    """
    mesh = is_mesh_part(part)
    given = [n for n, v in (("--goal-pose", goal_pose), ("--pose-prior", pose_prior)) if v]
    if not mesh:
        if pose is not None or given:
            names = ", ".join(([] if pose is None else ["--pose"]) + given)
            raise typer.BadParameter(f"{names}: for a mesh PART (.stl, .obj, .ply, .3mf, .glb)")
        return part
    if batch is not None:
        raise typer.BadParameter("a mesh PART is planned alone, not with --batch")
    if sense is None:
        if given:
            raise typer.BadParameter(
                f"{', '.join(given)} plan a policy over the poses: add --sense"
            )
        if candidates:
            raise typer.BadParameter("a mesh PART is planned alone: drop the other parts")
        if pose is not None and part.element is not None:
            raise typer.BadParameter("give the pose once: --pose K (not --element)")
        return part if pose is None else dataclasses.replace(part, element=str(pose))
    if pose is not None:
        raise typer.BadParameter(
            "--sense plans a policy over every pose: choose the pose to orient with "
            "--goal-pose K, not --pose"
        )
    if candidates:
        raise typer.BadParameter(
            "with a mesh PART and --sense the candidates are its poses: drop --also, "
            "--part-prior and other PARTs (--pose-prior sets the poses' prior)"
        )
    return part


@dataclass(frozen=True, slots=True)
class PoseSense(SenseSpec):
    """A sensing policy whose candidate parts are a solid's pose footprints."""

    footprints: tuple[Part, ...] = ()

    def parts(self, part: PartSpec) -> list[Part]:
        """The footprints ``pose-0``, ``pose-1``, ... (PART is the mesh they come from)."""
        return list(self.footprints)


def goal_pose_index(text: str | None, n: int) -> int | None:
    """``--goal-pose``: a pose index, or ``None`` for any."""
    from ..solid.parts import pose_index

    if text is not None and text.strip().lower() == "any":
        return None
    try:
        return pose_index(text, n, "--goal-pose")
    except Exception as exc:
        raise typer.BadParameter(f"{exc}; or give any", param_hint="--goal-pose") from None


def pose_prior_weights(text: str | None, solid: Solid, study: PoseStudy) -> list[float]:
    """``--pose-prior``: the poses' weights (:func:`bayesgrasp.runs.poses.pose_prior_weights`)."""
    from .poses import drop_frequencies

    def drops(solid: Solid, study: PoseStudy, n: int) -> list[float]:
        return [r[0] for r in drop_frequencies(solid, study, n, 0)[1]]

    try:
        return weights_of(text, solid, study, drops)
    except PoseOptionError as exc:
        raise typer.BadParameter(str(exc), param_hint=exc.option) from None


def check_pose_toppling(part: PartSpec, jaw_height: float | None) -> None:
    """``plan MESH [--pose K] --jaw-height H``: refuse pose K if a squeeze may topple it.

    The part's planar orientation is unknown, so a squeeze at any gripper angle may meet the
    pose at any closing direction: a pose that topples at some direction
    (:func:`bayesgrasp.solid.topple.toppling_angles`) topples under every gripper angle.
    """
    if jaw_height is None:
        return
    if not is_mesh_part(part):
        raise typer.BadParameter("--jaw-height needs a mesh PART", param_hint="--jaw-height")
    if part.part == "-":  # the mesh would be read twice: the check, then the plan
        raise typer.BadParameter(
            "--jaw-height needs the mesh in a file, not on standard input",
            param_hint="--jaw-height",
        )
    from ..solid.parts import pose_index

    study = study_of(part.load_solid())
    k = pose_index(part.element, len(study.poses), f"{part.part}: pose")
    try:
        note = pose_toppling(study, k, jaw_height)
    except PoseOptionError as exc:
        raise typer.BadParameter(str(exc), param_hint=exc.option) from None
    typer.echo(f"bayesgrasp: note: {note}", err=True)


def check_poses_toppling(study: PoseStudy, weights: list[float], jaw_height: float) -> None:
    """``plan MESH --sense --jaw-height H``: refuse the policy if a squeeze may topple a pose.

    See :func:`bayesgrasp.runs.poses.poses_toppling`; else a note on stderr says none does.
    """
    try:
        note = poses_toppling(study, weights, jaw_height)
    except PoseOptionError as exc:
        raise typer.BadParameter(str(exc), param_hint=exc.option) from None
    typer.echo(f"bayesgrasp: note: {note}", err=True)


def pose_sensing(
    part: PartSpec,
    sensing: SenseSpec,
    spec: ProblemSpec,
    goal_pose: str | None,
    pose_prior: str | None,
    jaw_height: float | None = None,
) -> tuple[PoseSense, PoseProblems]:
    """The --sense options of ``plan MESH``: the poses as candidates, the goal pose's problems."""
    from ..solid.parts import pose_parts

    solid = part.load_solid()
    study = study_of(solid)
    n = len(study.poses)
    goal = goal_pose_index(goal_pose, n) if goal_pose is not None else 0
    weights = pose_prior_weights(pose_prior, solid, study)
    if jaw_height is not None:
        check_poses_toppling(study, weights, jaw_height)
    footprints = tuple(pose_parts(study, solid.units))
    undeclared = frozenset(f"pose-{k}" for k in range(n) if goal is not None and k != goal)
    values = {f.name: getattr(spec, f.name) for f in dataclasses.fields(ProblemSpec)}
    problems = PoseProblems(**values, undeclared=undeclared)
    prior = ",".join(repr(w) for w in weights)
    sense = PoseSense(
        sensing.sense,
        (),
        prior,
        sensing.max_actions,
        sensing.max_memory_mb,
        sensing.time_limit_s,
        footprints=footprints,
    )
    return sense, problems


def mesh_sensing(
    part: PartSpec,
    sensing: SenseSpec,
    spec: ProblemSpec,
    candidates: bool,
    goal_pose: str | None = None,
    pose_prior: str | None = None,
    jaw_height: float | None = None,
) -> tuple[SenseSpec, ProblemSpec]:
    """``simulate`` and ``plot`` with --sense: a mesh PART's policy is over its poses.

    As ``plan MESH --sense --goal-pose K --pose-prior P --jaw-height H`` (default goal pose
    0, the quasi-static pose prior, no toppling check); any other PART is returned as it
    came (and the pose options refused).
    """
    mesh_options(part, sensing.sense, None, goal_pose, pose_prior, candidates, None)
    if not is_mesh_part(part):
        if jaw_height is not None:
            check_pose_toppling(part, jaw_height)  # refuses: not a mesh
        return sensing, spec
    return pose_sensing(part, sensing, spec, goal_pose, pose_prior, jaw_height)
