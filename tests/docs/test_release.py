"""Release hygiene, as a user installing from an index meets it.

``python -m build`` makes an sdist and a wheel (the wheel built from the sdist, as ``build``
does); each installs into a clean venv and runs ``bayesgrasp demo`` there, from a folder
outside the repository, so nothing of the source tree is on the path. To stay fast and
offline the venvs get the package alone (``--no-deps``); its dependencies come from the
site-packages of the venv running the tests, added to the new venv's path by a ``.pth``
file (that folder's own ``.pth`` files, among them the editable install of the source
tree, are not processed from there).

The version is in one place: ``pyproject.toml``'s ``[project] version``, which the built
metadata, ``bayesgrasp.__version__`` and ``bayesgrasp --version`` must all show.
"""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
import tomllib
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PROJECT = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
VERSION = PROJECT["version"]


def _run(args: list[str | Path], cwd: Path, **kw: object) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    proc = subprocess.run(
        [str(a) for a in args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        **kw,  # type: ignore[arg-type]
    )
    assert proc.returncode == 0, f"{args}: exit {proc.returncode}\n{proc.stdout}\n{proc.stderr}"
    return proc


@pytest.fixture(scope="module")
def dist(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("dist")
    _run([sys.executable, "-m", "build", "--outdir", out, REPO], cwd=REPO)
    return out


def _clean_venv(where: Path) -> Path:
    """A venv without pip or packages; the test venv's site-packages on its path."""
    _run([sys.executable, "-m", "venv", "--without-pip", where], cwd=where.parent)
    python = where / "bin" / "python"
    purelib = _run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=where
    ).stdout.strip()
    Path(purelib, "_test_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    return python


def _install_and_run_demo(artifact: Path, where: Path) -> None:
    python = _clean_venv(where)
    _run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            python,
            "install",
            "--quiet",
            "--no-deps",
            artifact,
        ],
        cwd=where,
    )
    outside = where / "elsewhere"
    outside.mkdir()
    probe = _run(
        [
            python,
            "-c",
            "import bayesgrasp; print(bayesgrasp.__file__); print(bayesgrasp.__version__)",
        ],
        cwd=outside,
    ).stdout.split()
    assert Path(probe[0]).is_relative_to(where), f"imported {probe[0]}, not the installed copy"
    assert probe[1] == VERSION
    command = where / "bin" / "bayesgrasp"
    assert _run([command, "--version"], cwd=outside).stdout == f"bayesgrasp {VERSION}\n"
    demo = _run([command, "demo"], cwd=outside).stdout
    assert "Table 1" in demo
    assert "B = Bayes plan" in demo


def test_build_makes_an_sdist_and_a_wheel_of_the_one_version(dist: Path) -> None:
    (sdist,) = dist.glob("*.tar.gz")
    (wheel,) = dist.glob("*.whl")
    assert sdist.name == f"bayesgrasp-{VERSION}.tar.gz"
    assert wheel.name == f"bayesgrasp-{VERSION}-py3-none-any.whl"
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        metadata = zf.read(f"bayesgrasp-{VERSION}.dist-info/METADATA").decode()
    # the package data the commands need
    assert "bayesgrasp/py.typed" in names
    assert any(n.startswith("bayesgrasp/shapes/") and n.endswith(".json") for n in names)
    assert any(n.startswith("bayesgrasp/web/static/") for n in names)
    assert f"Version: {VERSION}\n" in metadata
    assert "License-Expression: MIT" in metadata
    assert "Project-URL: Documentation, " in metadata
    assert "Classifier: Programming Language :: Python :: 3" in metadata
    assert "Requires-Python: >=3.11" in metadata
    assert "Description-Content-Type: text/markdown" in metadata


def test_the_version_is_in_one_place() -> None:
    src = (REPO / "src" / "bayesgrasp").rglob("*.py")
    for path in src:
        text = path.read_text(encoding="utf-8")
        assert f'"{VERSION}"' not in text, f"{path} spells the version out"
    import bayesgrasp

    assert bayesgrasp.__version__ == VERSION


def test_wheel_installs_into_a_clean_venv_and_runs_the_demo(dist: Path, tmp_path: Path) -> None:
    (wheel,) = dist.glob("*.whl")
    _install_and_run_demo(wheel, tmp_path / "venv")


def test_sdist_installs_into_a_clean_venv_and_runs_the_demo(dist: Path, tmp_path: Path) -> None:
    (sdist,) = dist.glob("*.tar.gz")
    _install_and_run_demo(sdist, tmp_path / "venv")
