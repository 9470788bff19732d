"""Solids from mesh files: STL, OBJ, PLY, 3MF and GLB, checked, with units and centre of mass.

=========  ==========  ===========================================================
format     extension   what is read
=========  ==========  ===========================================================
stl        ``.stl``    ASCII or binary triangles (a binary header must match the
                       file's size)
obj        ``.obj``    vertices and polygon faces (``f i``, ``i/j``, ``i//k``,
                       ``i/j/k``; polygons are triangulated)
ply        ``.ply``    ASCII or binary vertices and faces
3mf        ``.3mf``    every mesh of the model, placed; the model's units
glb        ``.glb``    every mesh of the scene, placed; metres (glTF's unit)
=========  ==========  ===========================================================

The files are parsed by trimesh (the ``mesh`` extra: ``pip install 'bayesgrasp[mesh]'``);
what is checked here: the file is not empty, the binary STL header's triangle count matches
the file's size, there are faces, every coordinate is finite, the solid spans a volume, and
the centre of mass lies strictly inside the convex hull.

The centre of mass of a closed mesh is the centroid of the solid it bounds (uniform density;
divergence theorem over signed tetrahedra from the origin, so the faces' winding may be
either way as long as it is consistent). A mesh that is not closed bounds no solid: give
the centre of mass (``com``). Units come from the file where it says (3MF, GLB) or from
``units`` (which wins); STL, OBJ and PLY say nothing, and their units are then unknown
(``None``): widths are read in the file's numbers.
"""

from __future__ import annotations

import io
import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import MissingExtraError, PartError, PartFileError

if TYPE_CHECKING:
    from .poses import HullFaces

__all__ = [
    "MESH_EXTENSIONS",
    "MESH_FORMATS",
    "UNITS",
    "Solid",
    "is_mesh",
    "read_mesh",
    "read_mesh_bytes",
    "solid_from_arrays",
]

MESH_FORMATS = ("stl", "obj", "ply", "3mf", "glb")
"""Mesh formats, by their usual extension."""

MESH_EXTENSIONS = {f: f for f in MESH_FORMATS}
"""File extensions (lower case, no dot) and their mesh formats."""

UNITS = {
    "m": "m",
    "meter": "m",
    "meters": "m",
    "metre": "m",
    "metres": "m",
    "cm": "cm",
    "centimeter": "cm",
    "centimeters": "cm",
    "mm": "mm",
    "millimeter": "mm",
    "millimeters": "mm",
    "um": "um",
    "micron": "um",
    "microns": "um",
    "in": "in",
    "inch": "in",
    "inches": "in",
    "ft": "ft",
    "foot": "ft",
    "feet": "ft",
}
"""Unit names a file or ``--units`` may give, and the short name a part carries."""

MAX_FACES = 5_000_000
"""Most triangles a mesh may have."""

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]


@dataclass(frozen=True, slots=True, eq=False)
class Solid:
    """A solid given by a triangle mesh, checked.

    Attributes
    ----------
    name : str
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (T, 3)
    center_of_mass : ndarray of shape (3,)
    units : str or None
        A short unit name (:data:`UNITS`), ``None`` when unknown.
    volume : float or None
        The enclosed volume (``None`` for an open mesh, whose centre of mass was given).
    hull : HullFaces
        The convex hull (:func:`bayesgrasp.solid.poses.hull_faces`), computed once.

    Examples
    --------
    >>> corner = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    >>> s = solid_from_arrays(corner, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> s.center_of_mass.round(12).tolist(), round(s.volume, 12)
    ([0.25, 0.25, 0.25], 0.166666666667)
    """

    name: str
    vertices: FloatArray
    faces: IntArray
    center_of_mass: FloatArray
    units: str | None = None
    volume: float | None = None
    hull: HullFaces | None = None


def is_mesh(path: str | os.PathLike[str], fmt: str | None = None) -> bool:
    """Whether a part path (or ``fmt``) names a mesh format.

    Examples
    --------
    >>> is_mesh("bracket.STL"), is_mesh("plate.dxf"), is_mesh("-", "obj")
    (True, False, True)
    """
    if fmt is not None:
        return fmt.lower() in MESH_FORMATS
    return Path(path).suffix.lstrip(".").lower() in MESH_EXTENSIONS


def _units(value: str | None, what: str) -> str | None:
    if value is None:
        return None
    key = str(value).strip().lower()
    if key not in UNITS:
        raise PartError(
            f"{what}: unknown units {value!r}; expected one of {', '.join(sorted(set(UNITS)))}"
        )
    return UNITS[key]


def _closed_volume(v: FloatArray, f: IntArray) -> tuple[float, FloatArray] | None:
    """Volume and centroid of the solid a closed, consistently wound mesh bounds.

    ``None`` when some edge is not shared by exactly two faces in opposite directions.
    """
    src = f.ravel()
    dst = f[:, [1, 2, 0]].ravel()
    n = len(v)
    fwd = np.sort(src * n + dst)
    back = np.sort(dst * n + src)
    if len(np.unique(fwd)) != len(fwd) or not np.array_equal(fwd, back):
        return None
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    o = v.mean(axis=0)  # about the mean: less cancellation far from the origin
    a, b, c = a - o, b - o, c - o
    det = np.einsum("ij,ij->i", a, np.cross(b, c))  # 6 x signed tetrahedron volumes
    six = float(det.sum())
    if six == 0.0:
        return 0.0, o
    com = (det[:, None] * (a + b + c)).sum(axis=0) / (4.0 * six) + o
    return abs(six) / 6.0, com


def solid_from_arrays(
    vertices: ArrayLike,
    faces: ArrayLike,
    *,
    com: ArrayLike | None = None,
    name: str = "solid",
    units: str | None = None,
    source: str = "mesh",
) -> Solid:
    """A checked :class:`Solid` from vertex and triangle arrays.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
    faces : array_like of shape (T, 3)
        Vertex indices of each triangle.
    com : array_like of shape (3,), optional
        The centre of mass (default: the closed mesh's solid centroid).
    name : str
    units : str, optional
        One of :data:`UNITS`.
    source : str
        What starts the error messages (a file name).

    Raises
    ------
    PartError
        Empty, non-finite, flat, open without ``com``, or ``com`` outside the hull; one line
        starting with ``source``.
    """
    from .poses import hull_faces

    v = np.array(vertices, dtype=np.float64)  # copies: they are kept, read-only
    f = np.array(faces)
    if v.ndim != 2 or v.shape[1] != 3 or len(v) == 0 or f.size == 0:
        raise PartFileError(f"{source}: the mesh is empty (no vertices or no faces)")
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise PartFileError(f"{source}: faces must be triangles of vertex indices")
    f = f.astype(np.intp)
    if f.min() < 0 or f.max() >= len(v):
        raise PartFileError(f"{source}: a face refers to a vertex the mesh does not have")
    if len(f) > MAX_FACES:
        raise PartFileError(f"{source}: {len(f)} triangles; at most {MAX_FACES} are read")
    if not np.isfinite(v).all():
        raise PartFileError(f"{source}: the mesh has NaN or infinite coordinates")
    if np.abs(v).max() > 1e150:
        raise PartFileError(f"{source}: coordinates larger than 1e150")
    used = np.unique(f)
    try:
        hull = hull_faces(v[used])
    except PartError as exc:
        raise PartFileError(f"{source}: the solid has zero volume ({exc})") from None
    closed = _closed_volume(v, f)
    volume = None
    if closed is not None:
        volume = closed[0]
        if volume <= 1e-12 * hull.size**3:
            raise PartFileError(f"{source}: the solid has zero volume (its faces enclose none)")
    if com is None:
        if closed is None:
            raise PartFileError(
                f"{source}: the mesh is not closed (some edge is not shared by exactly two "
                "faces wound opposite ways), so it bounds no solid and has no centre of mass; "
                "repair it or give the centre of mass (--com X,Y,Z)"
            )
        c = closed[1]
    else:
        c = np.array(com, dtype=np.float64)
        if c.shape != (3,) or not np.isfinite(c).all():
            raise PartError(f"`com` must be three finite numbers X,Y,Z; got {com!r}")
    if not np.all(hull.normals @ c - hull.offsets < -1e-12 * hull.size):
        where = ", ".join(f"{x:.6g}" for x in c)
        raise PartFileError(
            f"{source}: the centre of mass ({where}) is not strictly inside the convex hull"
        )
    for a in (v, f, c):
        a.setflags(write=False)
    return Solid(name, v, f, c, _units(units, source), volume, hull)


def _check_stl(data: bytes, source: str) -> None:
    """Refuse a binary STL whose header's triangle count does not match the file's size."""
    head = data[:4096]
    if data.lstrip()[:5].lower() == b"solid" and (b"facet" in head or b"\0" not in head):
        try:
            data[:4096].decode("ascii")
            return  # ASCII STL
        except UnicodeDecodeError:
            pass
    if len(data) < 84:
        raise PartFileError(f"{source}: not an STL file (shorter than a binary STL's header)")
    (count,) = struct.unpack("<I", data[80:84])
    if 84 + 50 * count != len(data):
        raise PartFileError(
            f"{source}: the binary STL header says {count} triangles "
            f"({84 + 50 * count} bytes) but the file has {len(data)} bytes"
        )


def read_mesh_bytes(
    data: bytes,
    fmt: str,
    name: str = "<stdin>",
    *,
    com: ArrayLike | None = None,
    units: str | None = None,
) -> Solid:
    r"""A solid from the contents of a mesh file (see the module notes).

    Parameters
    ----------
    data : bytes
    fmt : str
        One of :data:`MESH_FORMATS`.
    name : str
        The file name, for messages and the solid's name (its stem).
    com : array_like of shape (3,), optional
    units : str, optional
        Overrides the file's units.

    Raises
    ------
    PartFileError
        Unreadable or unusable mesh, one line naming the file.
    MissingExtraError
        trimesh is not installed.

    Examples
    --------
    >>> corner = ["0 0 0", "1 0 0", "0 1 0", "0 0 1"]
    >>> facets = [
    ...     "facet normal 0 0 0\nouter loop\n"
    ...     + "".join(f"vertex {corner[i]}\n" for i in tri)
    ...     + "endloop\nendfacet\n"
    ...     for tri in ([0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3])
    ... ]
    >>> stl = ("solid t\n" + "".join(facets) + "endsolid t\n").encode()
    >>> s = read_mesh_bytes(stl, "stl", "corner.stl", units="mm")
    >>> s.name, s.units, s.center_of_mass.round(12).tolist()
    ('corner', 'mm', [0.25, 0.25, 0.25])
    """
    kind = (fmt or "").lower()
    if kind not in MESH_FORMATS:
        raise PartFileError(f"`fmt`: unknown mesh format {fmt!r}; expected one of {MESH_FORMATS}")
    source = name
    if not data.strip():
        raise PartFileError(f"{source}: the file is empty")
    if kind == "stl":
        _check_stl(data, source)
    try:
        import trimesh
    except ImportError:  # pragma: no cover - the extra is installed in the tests
        raise MissingExtraError("trimesh", "mesh") from None
    import logging

    logging.getLogger("trimesh").setLevel(logging.ERROR)  # its warnings are ours to word
    try:
        # Unprocessed: trimesh's processing drops NaN vertices silently; they are refused.
        loaded = trimesh.load(io.BytesIO(data), file_type=kind, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds on malformed files
        reason = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise PartFileError(f"{source}: not a readable {kind.upper()} file ({reason})") from None
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.intp)
    if len(vertices) and np.isfinite(vertices).all() and faces.size:
        # Vertices repeated exactly (an STL repeats each one per triangle) are one, and
        # triangles with a repeated corner enclose nothing.
        vertices, inverse = np.unique(vertices, axis=0, return_inverse=True)
        faces = inverse.reshape(-1)[faces]
        faces = faces[
            (faces[:, 0] != faces[:, 1])
            & (faces[:, 1] != faces[:, 2])
            & (faces[:, 2] != faces[:, 0])
        ]
    file_units = getattr(loaded, "units", None)
    chosen = units if units is not None else file_units
    if units is not None:
        _units(units, "--units")
    return solid_from_arrays(
        vertices, faces, com=com, name=Path(name).stem, units=chosen, source=source
    )


def read_mesh(
    path: str | os.PathLike[str],
    fmt: str | None = None,
    *,
    com: ArrayLike | None = None,
    units: str | None = None,
) -> Solid:
    """A solid from a mesh file (:func:`read_mesh_bytes`; the format from the extension).

    Examples
    --------
    >>> import tempfile, trimesh
    >>> f = Path(tempfile.mkdtemp()) / "box.stl"
    >>> _ = trimesh.creation.box((1, 2, 4)).export(f)
    >>> s = read_mesh(f)
    >>> s.name, round(s.volume, 9), s.center_of_mass.round(9).tolist()
    ('box', 8.0, [0.0, 0.0, 0.0])
    """
    from .. import files

    p = Path(path)
    kind = (fmt or p.suffix.lstrip(".")).lower()
    if kind not in MESH_FORMATS:
        raise PartFileError(
            f"{p}: unknown mesh format {kind!r}; expected one of {', '.join(MESH_FORMATS)}"
        )
    data = files.read_bytes(p, PartFileError, "mesh file")
    return read_mesh_bytes(data, kind, str(p), com=com, units=units)
