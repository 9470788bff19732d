"""Fixtures of the sweep tests: a generated catalogue folder and the CLI's own answers."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from bayesgrasp import shapes
from bayesgrasp.sweep import SweepOptions

ROOT = Path(__file__).resolve().parents[2]

# Files that cannot be read, and the start of what `bayesgrasp plan` says about each.
BROKEN = {
    "broken/empty.json": ("", "the file is empty"),
    "broken/bad.json": ("{not json", "JSON"),
    "broken/cut.wkt": ("POLYGON ((0 0, 1 0, 1 1", "WKT"),
    "broken/collinear.csv": ("0,0\n1,1\n2,2\n", ""),
    "broken/garbage.dxf": ("this is not a drawing\n", ""),
    "broken/nothing.svg": ('<svg xmlns="http://www.w3.org/2000/svg"></svg>', ""),
}


def random_hull(rng: np.random.Generator) -> np.ndarray:
    """The seed's random part: the hull of 10 points in the unit square."""
    pts = rng.random((10, 2))
    return pts[ConvexHull(pts).vertices]


def write_catalogue(folder: Path, rng: np.random.Generator, n_random: int = 8) -> list[str]:
    """Catalogue parts as JSON, random polygons in each point and outline format, the
    examples (.dxf, .svg, .geojson), and broken files. Returns the part files written."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "catalogue").mkdir()
    for name in shapes.names():
        e = shapes.entry(name)
        doc = {"name": name, "units": e.units, "vertices": [list(v) for v in e.vertices]}
        (folder / "catalogue" / f"{name}.json").write_text(json.dumps(doc))
    rnd = folder / "random" / "deeper"
    rnd.mkdir(parents=True)
    for i in range(n_random):
        v = random_hull(rng)
        kind = ("json", "csv", "wkt", "geojson")[i % 4]
        f = rnd / f"r{i:03d}.{kind}"
        if kind == "json":
            f.write_text(json.dumps({"vertices": v.tolist()}))
        elif kind == "csv":
            f.write_text("x,y\n" + "".join(f"{float(x)!r},{float(y)!r}\n" for x, y in v))
        else:
            ring = [*v.tolist(), v[0].tolist()]
            if kind == "wkt":
                f.write_text("POLYGON ((" + ", ".join(f"{x!r} {y!r}" for x, y in ring) + "))")
            else:
                geom = {"type": "Polygon", "coordinates": [ring]}
                f.write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": geom}))
    (folder / "examples").mkdir()
    for name in ("bracket.dxf", "peanut.svg", "plate.geojson"):
        shutil.copy(ROOT / "examples" / name, folder / "examples" / name)
    (folder / "broken").mkdir()
    for rel, (text, _) in BROKEN.items():
        (folder / rel).write_text(text)
    (folder / "random" / "notes.txt").write_text("not a part")  # not a part extension
    (folder / ".hidden").mkdir()
    (folder / ".hidden" / "skip.json").write_text("{}")
    return sorted(
        str(p)
        for p in folder.rglob("*")
        if p.is_file() and ".hidden" not in p.parts and p.suffix != ".txt"
    )


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """Run ``bayesgrasp ARGV`` in this process: exit code, stdout, stderr."""
    from bayesgrasp.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def expected_row(path: str, options: SweepOptions) -> dict[str, Any]:
    """What the CLI says of a part: its plan document, or its error message."""
    code, out, err = run_cli(["plan", path, *options.plan_args()])
    if code == 2:
        prefix = "bayesgrasp: error: "
        assert err.startswith(prefix), err
        return {"status": "error", "error_message": err[len(prefix) :].strip()}
    doc = json.loads(out)
    return {"status": "ok" if code == 0 else "no-plan", "plan": doc}


def check_rows(rows: list[dict[str, Any]], paths: list[str], options: SweepOptions) -> None:
    """Each path has exactly one row, and each row says what ``bayesgrasp plan`` says."""
    by_path = [r["path"] for r in rows]
    assert sorted(by_path) == sorted(paths)
    for r in rows:
        want = expected_row(r["path"], options)
        assert r["status"] == want["status"], (r["path"], r["error_message"])
        assert r["options_key"] == options.key
        if want["status"] == "error":
            assert r["error_message"] == want["error_message"]
            assert r["plan_json"] is None
        else:
            assert json.loads(r["plan_json"]) == want["plan"]
            assert r["error_class"] is None
            assert r["sides"] == want["plan"]["part"]["n_sides"]
            bayes = want["plan"]["options"][want["plan"]["bayes"]]
            assert r["bayes_cost"] == bayes["expected_cost"]
            assert r["bayes_actions"] == bayes["squeezes"]


@pytest.fixture(scope="module")
def catalogue(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """A generated catalogue folder and its part files (shared by a module's tests)."""
    folder = tmp_path_factory.mktemp("catalogue")
    return folder, write_catalogue(folder, np.random.default_rng(7))


@pytest.fixture
def rows_check() -> Callable[[list[dict[str, Any]], list[str], SweepOptions], None]:
    return check_rows


@pytest.fixture
def make_catalogue() -> Callable[[Path, np.random.Generator, int], list[str]]:
    return write_catalogue


@pytest.fixture
def cli_run() -> Callable[[list[str]], tuple[int, str, str]]:
    return run_cli


#: Catalogue parts of the noise tests (``parts``), in this order.
NAMED_PARTS = ("triangle", "rectangle", "key", "hand")


@pytest.fixture(scope="module")
def parts(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """Catalogue parts as JSON part files (:data:`NAMED_PARTS`, in order)."""
    folder = tmp_path_factory.mktemp("named-parts")
    files = []
    for name in NAMED_PARTS:
        e = shapes.entry(name)
        doc = {"name": name, "units": e.units, "vertices": [list(v) for v in e.vertices]}
        f = folder / f"{name}.json"
        f.write_text(json.dumps(doc))
        files.append(str(f))
    return files
