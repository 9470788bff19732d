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
import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from ..solid.parts import study_of
from .specs import PartSpec, ProblemSpec, SenseSpec

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
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


@dataclass(frozen=True, slots=True)
class PoseProblems(ProblemSpec):
    """The problem options, with the poses that may not be declared."""

    undeclared: frozenset[str] = frozenset()

    def build(self, part: Part, more_actions: tuple[str, ...] = (), prior: Any = None) -> Problem:
        """The problem of a footprint; an undeclared pose's goal is no success."""
        from ..model.problem import Problem
        from ..solid.policy import NoDeclaration

        inputs = self.problem_inputs(more_actions, prior)
        if part.name in self.undeclared:
            inputs["goal"] = NoDeclaration(inputs["goal"].kind)
        return Problem.build(part, **inputs)


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
    """``--pose-prior``: the poses' weights, in the study's order."""
    import numpy as np

    if text is None or text.strip().lower() == "quasi-static":
        return [p.probability for p in study.poses]
    key = text.strip()
    if key.lower() == "perturbed":
        other = study_of(solid, "perturbed")
        # Faces stable only for some perturbed centres are no pose of the mesh: left out.
        return _match(other.normals, other.probabilities, study, "perturbed", strict=False)
    if key.lower().startswith("drops:"):
        try:
            n = int(key.partition(":")[2])
        except ValueError:
            n = 0
        if n < 1:
            raise typer.BadParameter(
                f"drops:N needs N >= 1 drops; got {key!r}", param_hint="--pose-prior"
            )
        from .poses import drop_frequencies

        _, rows = drop_frequencies(solid, study, n, 0)
        w = [r[0] for r in rows]
        if not sum(w) > 0:
            raise typer.BadParameter(
                f"none of the {n} drops came to rest on a listed pose", param_hint="--pose-prior"
            )
        return w
    path = Path(key)
    if not path.is_file():
        raise typer.BadParameter(
            f"expected quasi-static, perturbed, drops:N or a poses file; got {key!r}",
            param_hint="--pose-prior",
        )
    from .. import files
    from ..errors import PartFileError

    try:
        doc = json.loads(files.read_bytes(path, PartFileError, "poses file"))
        normals = np.array([p["normal"] for p in doc["poses"]], dtype=float).reshape(-1, 3)
        probs = np.array([p["probability"] for p in doc["poses"]], dtype=float)
        if doc.get("schema") != "bayesgrasp.poses/1":
            raise ValueError("its schema is not bayesgrasp.poses/1")
    except (ValueError, KeyError, TypeError) as exc:
        raise typer.BadParameter(
            f"{key}: not a bayesgrasp.poses/1 document ({exc})", param_hint="--pose-prior"
        ) from None
    return _match(normals, probs, study, key)


def _match(
    normals: Any, probs: Any, study: PoseStudy, what: str, strict: bool = True
) -> list[float]:
    """The weights of ``study``'s poses from poses given by their normals (0 where absent).

    ``strict``: a given pose that is not one of ``study``'s is refused (else left out).
    """
    import numpy as np

    out = np.zeros(len(study.poses))
    for n, p in zip(normals, probs, strict=True):
        d = np.linalg.norm(study.normals - n, axis=1)
        k = int(np.argmin(d))
        if d[k] > 1e-6:
            if not strict:
                continue
            raise typer.BadParameter(
                f"{what}: a pose with normal {np.round(n, 6).tolist()} is not a stable pose of "
                "this mesh",
                param_hint="--pose-prior",
            )
        out[k] += p
    if not np.all(np.isfinite(out)) or np.any(out < 0) or out.sum() <= 0:
        raise typer.BadParameter(f"{what}: probabilities must be >= 0", param_hint="--pose-prior")
    return [float(x) for x in out]


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
    from ..solid.topple import toppling_report

    study = study_of(part.load_solid())
    k = pose_index(part.element, len(study.poses), f"{part.part}: pose")
    found = toppling_report(study, jaw_height)[k]
    if found.fraction > 0:
        raise typer.BadParameter(
            f"a squeeze with the jaws at height {jaw_height:g} topples pose {k} (the push tips "
            f"it before it slides at {found.describe()} of its frame; the "
            "planar orientation is unknown, so every gripper angle may meet one): plan another "
            "--pose or lower the jaws",
            param_hint="--jaw-height",
        )
    typer.echo(
        f"bayesgrasp: note: no squeeze with the jaws at height {jaw_height:g} topples pose {k}",
        err=True,
    )


def check_poses_toppling(study: PoseStudy, weights: list[float], jaw_height: float) -> None:
    """``plan MESH --sense --jaw-height H``: refuse the policy if a squeeze may topple a pose.

    Every action of the policy squeezes whichever pose the part is in, at an unknown planar
    orientation; a pose of positive prior weight that some closing direction topples would
    be tipped, so the policy is refused, naming those poses. Poses of weight 0 do not count.
    """
    from ..solid.topple import toppling_report

    report = toppling_report(study, jaw_height)
    bad = [r for r in report if r.fraction > 0 and weights[r.pose] > 0]
    if bad:
        which = "; ".join(f"pose {r.pose} at {r.describe()}" for r in bad)
        every = " (every pose that may occur)" if len(bad) == sum(w > 0 for w in weights) else ""
        raise typer.BadParameter(
            f"a squeeze with the jaws at height {jaw_height:g} topples{every}: {which} (closing "
            "directions in each pose's frame; the planar orientation is unknown, so every "
            "gripper angle may meet one): give those poses weight 0 (--pose-prior FILE) or "
            "lower the jaws",
            param_hint="--jaw-height",
        )
    typer.echo(
        f"bayesgrasp: note: no squeeze with the jaws at height {jaw_height:g} topples a pose "
        "of positive weight",
        err=True,
    )


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
