"""A mesh part's resting poses in a run: their document, prior weights and toppling check.

Shared by the command line (``poses``, ``plan MESH --sense ... --pose-prior P --jaw-height
H``) and the server (``/poses``, ``/policy`` on a mesh). A bad option raises
:class:`PoseOptionError`, which names the command line's option; each surface words it its
own way (``--pose-prior`` on the command line, ``pose_prior`` in a request).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import BayesGraspError
from .specs import ProblemSpec

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem
    from ..solid.mesh import Solid
    from ..solid.poses import PoseStudy

__all__ = [
    "FRAME_TEXT",
    "POSES_SCHEMA",
    "PoseOptionError",
    "PoseProblems",
    "match_weights",
    "pose_prior_weights",
    "pose_toppling",
    "poses_document",
    "poses_toppling",
]

POSES_SCHEMA = "bayesgrasp.poses/1"
FRAME_TEXT = (
    "each pose's planar frame: z up (minus the supporting face's outward normal); x the mesh "
    "axis most parallel to the table, projected on it; y = z cross x; origin the centre of "
    "mass's projection on the table"
)

#: Weights of a solid's poses from N MuJoCo drops: ``drops(solid, study, n)``.
Drops = Callable[["Solid", "PoseStudy", int], list[float]]


class PoseOptionError(BayesGraspError):
    """A pose option that cannot be used; ``option`` is the command line's name of it.

    Examples
    --------
    >>> e = PoseOptionError("drops:N needs N >= 1 drops; got 'drops:0'", "--pose-prior")
    >>> e.option, str(e)
    ('--pose-prior', "drops:N needs N >= 1 drops; got 'drops:0'")
    """

    def __init__(self, message: str, option: str) -> None:
        super().__init__(message)
        self.option = option


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


def poses_document(
    solid: Solid, study: PoseStudy, drops: Any = None, rows: list[Any] | None = None
) -> dict[str, Any]:
    """The ``bayesgrasp.poses/1`` document (poses most probable first)."""
    doc: dict[str, Any] = {
        "schema": POSES_SCHEMA,
        "poses": [
            {
                "probability": p.probability,
                "normal": p.normal.tolist(),
                "com_height": p.com_height,
                "footprint": p.footprint.tolist(),
            }
            for p in study.poses
        ],
        "mesh": solid.name,
        "units": solid.units,
        "center_of_mass": study.center_of_mass.tolist(),
        "estimator": study.estimator,
        "frame": FRAME_TEXT,
        "frames": [p.frame.tolist() for p in study.poses],
    }
    if drops is not None and rows is not None:
        doc["drops"] = {
            "trials": int(drops.trials),
            "unmatched": int(drops.unmatched),
            "settings": {k: float(v) for k, v in dict(drops.settings).items()},
            "counts": [int(c) for c in drops.counts],
            "frequencies": [r[0] for r in rows],
            "intervals_95": [[r[1], r[2]] for r in rows],
        }
    return doc


def pose_prior_weights(
    text: str | None, solid: Solid, study: PoseStudy, drops: Drops | None = None
) -> list[float]:
    """``--pose-prior``: the poses' weights, in the study's order.

    ``quasi-static`` (default) the study's own probabilities; ``perturbed`` those of the
    perturbed estimator, matched by normal; ``drops:N`` the frequencies of N drops, made by
    ``drops`` (``None``: refused); otherwise a ``bayesgrasp.poses/1`` file, matched by normal.
    """
    import numpy as np

    from ..solid.parts import study_of

    if text is None or text.strip().lower() == "quasi-static":
        return [p.probability for p in study.poses]
    key = text.strip()
    if key.lower() == "perturbed":
        other = study_of(solid, "perturbed")
        # Faces stable only for some perturbed centres are no pose of the mesh: left out.
        return match_weights(other.normals, other.probabilities, study, "perturbed", strict=False)
    if key.lower().startswith("drops:"):
        try:
            n = int(key.partition(":")[2])
        except ValueError:
            n = 0
        if n < 1:
            raise PoseOptionError(f"drops:N needs N >= 1 drops; got {key!r}", "--pose-prior")
        if drops is None:
            raise PoseOptionError(
                "drops:N runs MuJoCo drops, which this run does not", "--pose-prior"
            )
        w = drops(solid, study, n)
        if not sum(w) > 0:
            raise PoseOptionError(
                f"none of the {n} drops came to rest on a listed pose", "--pose-prior"
            )
        return w
    path = Path(key)
    if not path.is_file():
        raise PoseOptionError(
            f"expected quasi-static, perturbed, drops:N or a poses file; got {key!r}",
            "--pose-prior",
        )
    from .. import files
    from ..errors import PartFileError

    try:
        doc = json.loads(files.read_bytes(path, PartFileError, "poses file"))
        normals = np.array([p["normal"] for p in doc["poses"]], dtype=float).reshape(-1, 3)
        probs = np.array([p["probability"] for p in doc["poses"]], dtype=float)
        if doc.get("schema") != POSES_SCHEMA:
            raise ValueError(f"its schema is not {POSES_SCHEMA}")
    except (ValueError, KeyError, TypeError) as exc:
        raise PoseOptionError(
            f"{key}: not a {POSES_SCHEMA} document ({exc})", "--pose-prior"
        ) from None
    return match_weights(normals, probs, study, key)


def match_weights(
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
            raise PoseOptionError(
                f"{what}: a pose with normal {np.round(n, 6).tolist()} is not a stable pose of "
                "this mesh",
                "--pose-prior",
            )
        out[k] += p
    if not np.all(np.isfinite(out)) or np.any(out < 0) or out.sum() <= 0:
        raise PoseOptionError(f"{what}: probabilities must be >= 0", "--pose-prior")
    return [float(x) for x in out]


def pose_toppling(study: PoseStudy, k: int, jaw_height: float, pose_option: str = "--pose") -> str:
    """Pose ``k`` squeezed with the jaws at ``jaw_height``: refused if a squeeze may topple it.

    The part's planar orientation is unknown, so a squeeze at any gripper angle may meet the
    pose at any closing direction: a pose that topples at some direction
    (:func:`bayesgrasp.solid.topple.toppling_report`) topples under every gripper angle
    (:class:`PoseOptionError`; ``pose_option`` is how the message names the pose's option).
    Returns the note that it does not topple.
    """
    from ..solid.topple import toppling_report

    found = toppling_report(study, jaw_height)[k]
    if found.fraction > 0:
        raise PoseOptionError(
            f"a squeeze with the jaws at height {jaw_height:g} topples pose {k} (the push tips "
            f"it before it slides at {found.describe()} of its frame; the planar orientation "
            f"is unknown, so every gripper angle may meet one): plan another {pose_option} or "
            "lower the jaws",
            "--jaw-height",
        )
    return f"no squeeze with the jaws at height {jaw_height:g} topples pose {k}"


def poses_toppling(study: PoseStudy, weights: list[float], jaw_height: float) -> str:
    """A policy over poses with the jaws at ``jaw_height``: refused if a squeeze may topple one.

    Every action of the policy squeezes whichever pose the part is in, at an unknown planar
    orientation; a pose of positive prior weight that some closing direction topples
    (:func:`bayesgrasp.solid.topple.toppling_report`) would be tipped, so the policy is
    refused (:class:`PoseOptionError`), naming those poses. Poses of weight 0 do not count.
    Returns the note that none topples.
    """
    from ..solid.topple import toppling_report

    report = toppling_report(study, jaw_height)
    bad = [r for r in report if r.fraction > 0 and weights[r.pose] > 0]
    if bad:
        which = "; ".join(f"pose {r.pose} at {r.describe()}" for r in bad)
        every = " (every pose that may occur)" if len(bad) == sum(w > 0 for w in weights) else ""
        raise PoseOptionError(
            f"a squeeze with the jaws at height {jaw_height:g} topples{every}: {which} (closing "
            "directions in each pose's frame; the planar orientation is unknown, so every "
            "gripper angle may meet one): give those poses weight 0 (--pose-prior FILE) or "
            "lower the jaws",
            "--jaw-height",
        )
    return f"no squeeze with the jaws at height {jaw_height:g} topples a pose of positive weight"
