"""The package's layout (``benchmarks/layout.py``): no private name imported across modules, no
import circle, no import up the layers, no module over the size limit."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parent.parent


def _layout() -> ModuleType:
    path = ROOT / "benchmarks" / "layout.py"
    spec = importlib.util.spec_from_file_location("layout_measures", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["layout_measures"] = module  # for its dataclasses
    spec.loader.exec_module(module)
    return module


layout = _layout()
FOUND = layout.private_imports(ROOT / "src")


def test_no_private_name_imported_across_modules() -> None:
    found = FOUND
    assert found == [], "\n".join(f"{a}:{line} imports {name} of {b}" for a, b, line, name in found)


def test_no_circle_and_no_import_up_the_layers() -> None:
    graph = layout.import_graph(ROOT / "src")
    assert layout.circles(graph) == []
    assert [f"{i.source}:{i.line} -> {i.target}" for i in layout.upward(graph)] == []


def test_no_module_over_the_size_limit() -> None:
    assert layout.sizes(ROOT / "src") == [], f"modules over {layout.LIMIT} lines"


def test_the_checker_sees_private_names(tmp_path: Path) -> None:
    pkg = tmp_path / "bayesgrasp"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "_hidden.py").write_text("X = 1\n")
    (pkg / "a.py").write_text("_SECRET = 1\nPUBLIC = 2\n__all__ = ['PUBLIC']\n")
    (pkg / "b.py").write_text(
        "from .a import _SECRET, PUBLIC, __all__\n"
        "from . import a\n"
        "from .sub import _hidden\n"
        "def f():\n    return a._SECRET + a.PUBLIC\n"
    )
    (pkg / "sub" / "c.py").write_text("from . import _hidden\n")  # its own package: allowed
    found = layout.private_imports(tmp_path)
    assert [(s, t, n) for s, t, _, n in found] == [
        ("bayesgrasp.b", "bayesgrasp.a", "_SECRET"),
        ("bayesgrasp.b", "bayesgrasp.a", "_SECRET"),
        ("bayesgrasp.b", "bayesgrasp.sub._hidden", "(module)"),
    ]


def test_the_checker_sees_circles_and_upward_imports(tmp_path: Path) -> None:
    pkg = tmp_path / "bayesgrasp"
    (pkg / "model").mkdir(parents=True)
    (pkg / "geometry").mkdir()
    for folder in (pkg, pkg / "model", pkg / "geometry"):
        (folder / "__init__.py").write_text("")
    (pkg / "model" / "goal.py").write_text("def f():\n    from .problem import g\n")
    (pkg / "model" / "problem.py").write_text("from .goal import f\ndef g(): ...\n")
    (pkg / "geometry" / "polygon.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from ..model.goal import f\n"  # annotations only: not counted
        "def h():\n    from ..model.problem import g\n"
    )
    graph = layout.import_graph(tmp_path)
    assert layout.circles(graph) == [["bayesgrasp.model.goal", "bayesgrasp.model.problem"]]
    assert [(i.source, i.target) for i in layout.upward(graph)] == [
        ("bayesgrasp.geometry.polygon", "bayesgrasp.model.problem")
    ]
    assert layout.layer_of("bayesgrasp.planning.strategy") > layout.layer_of("bayesgrasp.planning")
