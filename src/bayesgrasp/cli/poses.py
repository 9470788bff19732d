"""``poses``: the resting poses of a mesh, their probabilities, footprints and drops."""

from __future__ import annotations

import enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from ..runs.poses import FRAME_TEXT, poses_document
from .common import emit_json
from .options import JsonOpt, command_app

if TYPE_CHECKING:
    from ..solid.mesh import Solid
    from ..solid.poses import PoseStudy

app = command_app()


class Estimator(enum.StrEnum):
    """The pose estimators."""

    quasi_static = "quasi-static"
    perturbed = "perturbed"


MeshArg = Annotated[
    str, typer.Argument(metavar="MESH", help="A mesh file (.stl, .obj, .ply, .3mf, .glb).")
]
MeshComOpt = Annotated[
    str | None,
    typer.Option(
        "--com",
        metavar="X,Y,Z",
        help="The centre of mass, mesh coordinates (default: the closed mesh's solid centroid, "
        "uniform density).",
    ),
]
UnitsOpt = Annotated[
    str | None,
    typer.Option(
        "--units",
        metavar="U",
        help="The mesh's units: mm, cm, m, um, in, ft (default: the file's, where it says; "
        "3MF and GLB do).",
    ),
]


def load_solid(mesh: str, com: str | None, units: str | None) -> Solid:
    """The solid of a mesh file, ``--com X,Y,Z`` and ``--units`` applied."""
    from ..solid.mesh import read_mesh
    from ..solid.parts import parse_com

    return read_mesh(mesh, com=parse_com(com), units=units)


def drop_frequencies(
    solid: Solid, study: PoseStudy, trials: int, seed: int
) -> tuple[Any, list[tuple[float, float, float]]]:
    """MuJoCo drops of the solid: the study and each pose's (frequency, low, high)."""
    try:
        from ..sim.drops import drop_poses
    except ImportError as exc:
        if "mujoco" in str(exc).lower():
            from ..errors import MissingExtraError

            raise MissingExtraError("mujoco", "sim") from None
        raise typer.BadParameter(
            "MuJoCo drops are not available in this installation", param_hint="--drops"
        ) from None
    drops = drop_poses(
        solid.vertices, solid.faces, solid.center_of_mass, study.normals, trials, seed=seed
    )
    freq = drops.frequencies()
    band = drops.intervals(0.95)
    rows = [(float(freq[k]), float(band[k, 0]), float(band[k, 1])) for k in range(len(freq))]
    return drops, rows


def poses_text(
    solid: Solid, study: PoseStudy, drops: Any = None, rows: list[Any] | None = None
) -> str:
    """The poses as a table for people."""
    unit = f" {solid.units}" if solid.units else ""
    com = ", ".join(f"{x:.6g}" for x in study.center_of_mass)
    lines = [
        f"{solid.name}: {len(study.poses)} stable poses ({study.estimator}); centre of mass "
        f"({com}){unit}",
    ]
    head = f"{'pose':>4}  {'probability':>11}  {'normal (mesh)':^26}  {'com height':>10}  footprint"
    if rows is not None:
        head += f"  {'drops':>6}  95% interval"
    lines.append(head)
    for k, p in enumerate(study.poses):
        n = " ".join(f"{x:+.4f}" for x in p.normal)
        ext = p.footprint.max(axis=0) - p.footprint.min(axis=0)
        line = (
            f"{k:>4}  {p.probability:>11.6f}  {n:^26}  {p.com_height:>10.4g}  "
            f"{len(p.footprint)} sides, {ext[0]:.4g} x {ext[1]:.4g}"
        )
        if rows is not None:
            f, lo, hi = rows[k]
            line += f"  {f:>6.3f}  [{lo:.3f}, {hi:.3f}]"
        lines.append(line)
    if drops is not None:
        s = dict(drops.settings)
        lines.append(
            f"drops: {drops.trials} from uniform random orientations in MuJoCo ("
            + ", ".join(f"{k} {v:g}" for k, v in s.items())
            + f"); {drops.unmatched} came to rest on no listed pose"
        )
    lines.append(f"footprints: {FRAME_TEXT}")
    return "\n".join(lines)


@app.command()
def poses(
    mesh: MeshArg,
    com: MeshComOpt = None,
    units: UnitsOpt = None,
    as_json: JsonOpt = False,
    plot_file: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            metavar="FILE",
            help="Also draw each pose on the table, its footprint and its probability "
            "(.png, .svg, .pdf).",
        ),
    ] = None,
    drops: Annotated[
        int | None,
        typer.Option(
            "--drops",
            min=1,
            metavar="N",
            help="Also drop the mesh N times in MuJoCo from uniform random orientations and "
            "report each pose's frequency with its 95% interval (extra `sim`).",
        ),
    ] = None,
    estimator: Annotated[
        Estimator,
        typer.Option(
            "--estimator",
            help="quasi-static: exact first-contact solid angles and topple walks; perturbed: "
            "their average over centres of mass perturbed by --sigma.",
        ),
    ] = Estimator.quasi_static,
    sigma: Annotated[
        float,
        typer.Option(
            "--sigma",
            min=1e-9,
            help="With --estimator perturbed: standard deviation of the centre of mass, as a "
            "fraction of the part's size.",
        ),
    ] = 0.02,
    samples: Annotated[
        int,
        typer.Option("--samples", min=1, help="With --estimator perturbed: centres drawn."),
    ] = 200,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the drops and draws.")] = 0,
    force: Annotated[
        bool, typer.Option("--force", help="Replace the --plot file if it exists.")
    ] = False,
) -> None:
    """Stable resting poses of a mesh, their probabilities and footprints.

    Quasi-static model (Goldberg et al., Part pose statistics, 1999): the hull face first
    hit has probability its solid angle from the centre of mass / 4 pi; an unstable face
    topples over the edge towards the centre of mass's projection until a face holds it.
    Coplanar hull triangles are one face. Sorted by probability, most probable first: pose
    K here is pose K of plan MESH --pose K.
    """
    from ..solid.poses import resting_poses
    from .common import check_figure_path, check_outputs, save_figure

    if estimator is not Estimator.perturbed and (sigma != 0.02 or samples != 200):
        raise typer.BadParameter("--sigma and --samples need --estimator perturbed")
    if plot_file is not None:
        check_figure_path(plot_file)
        check_outputs([plot_file], [Path(mesh)], force, hint="--plot")
    solid = load_solid(mesh, com, units)
    study = resting_poses(
        solid.hull if solid.hull is not None else solid.vertices[_used(solid)],
        solid.center_of_mass,
        estimator=estimator.value,
        sigma=sigma,
        samples=samples,
        rng=seed,
    )
    found: Any = None
    rows = None
    if drops is not None:
        found, rows = drop_frequencies(solid, study, drops, seed)
    if as_json:
        emit_json(poses_document(solid, study, found, rows))
    else:
        typer.echo(poses_text(solid, study, found, rows))
    if plot_file is not None:
        from ..figures.poses import poses_figure

        save_figure(poses_figure(solid, study, frequencies=rows), plot_file)


def _used(solid: Solid) -> Any:
    import numpy as np

    return np.unique(solid.faces)
