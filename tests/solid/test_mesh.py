"""Mesh files in: every format, units, the centre of mass, and bad meshes refused."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
import trimesh
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.errors import PartError, PartFileError
from bayesgrasp.io import read_part
from bayesgrasp.solid.mesh import read_mesh, read_mesh_bytes, solid_from_arrays

BOX = trimesh.creation.box((1, 2, 4))  # centred at the origin
CORNER = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
CORNER_FACES = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]


def _write(tmp_path: Path, name: str, data: bytes | str) -> Path:
    p = tmp_path / name
    p.write_bytes(data if isinstance(data, bytes) else data.encode())
    return p


@pytest.mark.parametrize("fmt", ["stl", "obj", "ply", "3mf", "glb"])
def test_every_format_reads_the_box(tmp_path: Path, fmt: str) -> None:
    f = tmp_path / f"box.{fmt}"
    BOX.export(f)
    s = read_mesh(f)
    assert s.name == "box"
    assert_allclose(s.volume, 8.0, rtol=1e-12)
    assert_allclose(s.center_of_mass, 0.0, atol=1e-12)
    assert s.units == {"3mf": "mm", "glb": "m"}.get(fmt)
    assert read_mesh(f, units="in").units == "in"  # --units wins over the file's


def test_ascii_and_binary_stl_and_ply(tmp_path: Path) -> None:
    for enc in ("ascii", "binary"):
        stl = _write(
            tmp_path, f"b-{enc}.stl", BOX.export(file_type="stl_ascii" if enc == "ascii" else "stl")
        )
        ply = _write(tmp_path, f"b-{enc}.ply", BOX.export(file_type="ply", encoding=enc))
        for f in (stl, ply):
            assert_allclose(read_mesh(f).volume, 8.0, rtol=1e-12)
    assert read_mesh(tmp_path / "b-ascii.stl").faces.shape == (12, 3)


@pytest.mark.parametrize(
    "face",
    ["f 1 2 3 4", "f 1/1 2/2 3/3 4/4", "f 1//1 2//1 3//1 4//1", "f 1/1/1 2/2/1 3/3/1 4/4/1"],
)
def test_obj_polygon_faces_in_every_index_form(tmp_path: Path, face: str) -> None:
    """A cube of quads written as ``i``, ``i/j``, ``i//k`` and ``i/j/k``."""
    v = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    quads = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    form = face.split()[1]
    parts = form.count("/")
    lines = [f"v {x} {y} {z}" for x, y, z in v]
    lines += [f"vt {i % 2} {i // 2 % 2}" for i in range(8)] + ["vn 0 0 1"]
    for q in quads:
        if parts == 0:
            idx = [str(i) for i in q]
        elif "//" in form:
            idx = [f"{i}//1" for i in q]
        elif parts == 1:
            idx = [f"{i}/{i}" for i in q]
        else:
            idx = [f"{i}/{i}/1" for i in q]
        lines.append("f " + " ".join(idx))
    s = read_mesh(_write(tmp_path, "cube.obj", "\n".join(lines) + "\n"))
    assert_allclose(s.volume, 1.0, rtol=1e-12)
    assert_allclose(s.center_of_mass, 0.5, atol=1e-12)


def test_centre_of_mass_of_an_off_centre_solid() -> None:
    # An L made of a 3x1x1 bar and a 1x1x2 post: the volume-weighted centroid.
    bar = trimesh.creation.box((3, 1, 1))
    bar.apply_translation((1.5, 0.5, 0.5))
    post = trimesh.creation.box((1, 1, 2))
    post.apply_translation((0.5, 0.5, 2.0))
    ell = trimesh.boolean.union([bar, post]) if False else trimesh.util.concatenate([bar, post])
    s = solid_from_arrays(ell.vertices, ell.faces)  # two closed shells: volumes add
    assert_allclose(s.volume, 5.0, rtol=1e-12)
    assert_allclose(s.center_of_mass, [1.1, 0.5, 1.1], atol=1e-12)
    assert_allclose(s.center_of_mass, ell.center_mass, atol=1e-12)  # trimesh agrees


def test_open_mesh_needs_the_centre_of_mass() -> None:
    with pytest.raises(PartFileError, match=r"not closed .* give the centre of mass"):
        solid_from_arrays(CORNER, CORNER_FACES[:3])
    s = solid_from_arrays(CORNER, CORNER_FACES[:3], com=[0.2, 0.2, 0.2])
    assert s.volume is None


def _binary_stl(n_declared: int, n_written: int) -> bytes:
    body = b"".join(struct.pack("<12fH", *([0.0] * 12), 0) for _ in range(n_written))
    return b"\0" * 80 + struct.pack("<I", n_declared) + body


@pytest.mark.parametrize(
    ("name", "data", "match"),
    [
        ("e.stl", b"", "the file is empty"),
        ("e.obj", b"# nothing\n", "empty"),
        ("lie.stl", _binary_stl(1000, 3), "header says 1000 triangles .* but the file has"),
        ("short.stl", b"\0" * 40, "shorter than a binary STL's header"),
        (
            "nan.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 nan\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
            "NaN or infinite",
        ),
        (
            "flat.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 1 3 2\nf 2 3 4\n",
            "zero volume",
        ),
        (
            "bad.ply",
            b"ply\nformat binary_little_endian 1.0\nelement vertex 100\n"
            b"property float x\nproperty float y\nproperty float z\nend_header\n\0\0\0",
            "not a readable PLY|empty",
        ),
    ],
)
def test_bad_meshes_are_refused_with_one_line(
    tmp_path: Path, name: str, data: bytes, match: str, capsys: pytest.CaptureFixture[str]
) -> None:
    f = _write(tmp_path, name, data)
    with pytest.raises(PartFileError, match=match):
        read_mesh(f)
    assert main(["poses", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("bayesgrasp: error: ") and "Traceback" not in err


def test_centre_of_mass_outside_the_hull_is_refused(tmp_path: Path, capsys) -> None:
    f = tmp_path / "box.stl"
    BOX.export(f)
    with pytest.raises(PartFileError, match="not strictly inside the convex hull"):
        read_mesh(f, com=[0, 0, 2.0])  # on the top face
    assert main(["poses", str(f), "--com", "0,0,5"]) == 2
    assert "not strictly inside" in capsys.readouterr().err
    assert main(["poses", str(f), "--com", "0,0"]) == 2
    assert "X,Y,Z" in capsys.readouterr().err
    assert main(["poses", str(f), "--units", "furlong"]) == 2
    assert "unknown units" in capsys.readouterr().err


def test_io_reads_a_mesh_as_a_pose_footprint(tmp_path: Path) -> None:
    f = tmp_path / "box.stl"
    BOX.export(f)
    p0 = read_part(f)
    assert p0.name == "box-pose-0" and p0.hull.n_sides == 4
    assert_allclose(p0.hull.area, 8.0, rtol=1e-12)  # resting on a 2 x 4 face
    p4 = read_part(f, element="4")
    assert_allclose(p4.hull.area, 2.0, rtol=1e-12)
    with pytest.raises(PartError, match="pose '9' does not exist; the mesh has 6"):
        read_part(f, element="9")
    with pytest.raises(PartFileError, match="no layers"):
        read_part(f, layer="0")


def test_mesh_bytes_need_a_mesh_format() -> None:
    with pytest.raises(PartFileError, match="unknown mesh format"):
        read_mesh_bytes(b"x", "dxf")
