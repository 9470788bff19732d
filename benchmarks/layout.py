"""The package's layout, measured: module sizes, import circles, imports up the layers, and
private names imported across modules.

The data flow of the library (``part source -> part -> diameter and transfer functions ->
problem -> planner -> strategy -> evaluation -> documents, figures, simulation -> CLI,
server, sweep``) sets the layers, lowest first. A module may import from its own layer and
the layers below it, never from a layer above:

0. ``foundation``: ``errors``, ``units``, ``angles``, ``tolerance``, ``sizes``, ``files``,
   ``_lazy``, ``_version`` (no knowledge of parts);
1. ``part``: ``geometry`` (parts, diameter, radius and transfer functions), ``solid`` (meshes
   and their resting poses; except ``solid.policy``), ``shapes`` (the catalogue);
2. ``model``: ``model`` (states, prior, actions, sensing, noise, cost, goal, problem);
3. ``planning``: ``planning`` (the planners and their result type ``planning.result``) and
   ``solid.policy`` (policies over poses), except the module of the next layer;
4. ``strategy``: ``planning.strategy`` (one strategy type over every planner, and its exact
   evaluation);
5. ``output``: ``io``, ``report`` (with ``report.curved``), ``figures``, ``sim``, ``paper``;
6. ``run``: ``runs`` (what a request asks of the library: the part, problem and planner
   options, the noise-aware run, the provenance; shared by the surfaces);
7. ``surface``: ``cli``, ``web``, ``sweep``, and the package's own ``__init__`` (the facade).

Measured on every ``.py`` file under ``src/bayesgrasp`` with :mod:`ast`; nothing is imported:

- **sizes**: modules over :data:`LIMIT` lines;
- **circles**: strongly connected sets of modules in the graph of imports that run (at module
  level or inside a function); imports under ``if TYPE_CHECKING:`` are left out, as they
  serve annotations only and never run;
- **upward imports**: imports that run, from a module to a module of a higher layer; a
  package's ``__init__`` (its facade) may import any module of its own package;
- **private names**: ``from M import _name`` or ``M._name`` where ``M`` is another module of
  the package (dunder names aside), and a private module (``pkg/_x.py``) imported from
  outside its own package. ``tests/test_layout.py`` fails on any of these.

Run: ``python benchmarks/layout.py [--limit N]``; the exit code is 0 either way.
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"
PACKAGE = "bayesgrasp"
LIMIT = 700

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "foundation",
        (
            "errors",
            "units",
            "angles",
            "tolerance",
            "sizes",
            "files",
            "_lazy",
            "_version",
        ),
    ),
    ("part", ("geometry", "solid", "shapes")),
    ("model", ("model",)),
    ("planning", ("planning", "solid.policy")),
    ("strategy", ("planning.strategy",)),
    ("output", ("io", "report", "figures", "sim", "paper")),
    ("run", ("runs",)),
    ("surface", ("cli", "web", "sweep", "")),
)


@dataclass(frozen=True)
class Import:
    """One import statement's dependency of ``source`` on ``target`` (both module names)."""

    source: str
    target: str
    line: int
    names: tuple[str, ...]  # the names taken from ``target`` (``from target import names``)
    typing_only: bool  # under ``if TYPE_CHECKING:``


def module_files(src: Path = SRC) -> dict[str, Path]:
    """Map every module of the package to its file (a package to its ``__init__.py``)."""
    out: dict[str, Path] = {}
    for path in sorted((src / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def layer_of(module: str) -> int:
    """The layer of ``module``: the longest prefix listed in :data:`LAYERS` decides."""
    rest = module.removeprefix(PACKAGE).removeprefix(".")
    best, best_length = len(LAYERS) - 1, -1
    for index, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            matches = rest == prefix or (prefix != "" and rest.startswith(prefix + "."))
            if matches and len(prefix) > best_length:
                best, best_length = index, len(prefix)
    return best


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _walk(node: ast.AST, typing_only: bool = False) -> Iterator[tuple[ast.AST, bool]]:
    """Every node under ``node``, with whether it sits under ``if TYPE_CHECKING:``."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.If) and _is_type_checking(child.test):
            for sub in child.body:
                yield sub, True
                yield from _walk(sub, True)
            for sub in child.orelse:
                yield sub, typing_only
                yield from _walk(sub, typing_only)
            continue
        yield child, typing_only
        yield from _walk(child, typing_only)


def imports_of(module: str, path: Path, modules: dict[str, Path]) -> list[Import]:
    """The package-internal imports of one module, resolved to module names."""
    is_package = path.name == "__init__.py"
    here = module.split(".") if is_package else module.split(".")[:-1]
    out: list[Import] = []
    for node, typing_only in _walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == PACKAGE and alias.name in modules:
                    out.append(Import(module, alias.name, node.lineno, (), typing_only))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[: len(here) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != PACKAGE:
                continue
            names: list[str] = []
            for alias in node.names:
                if f"{target}.{alias.name}" in modules:  # ``from pkg import module``
                    out.append(
                        Import(module, f"{target}.{alias.name}", node.lineno, (), typing_only)
                    )
                else:
                    names.append(alias.name)
            if names and target in modules:
                out.append(Import(module, target, node.lineno, tuple(names), typing_only))
    return out


def import_graph(src: Path = SRC) -> list[Import]:
    """Every package-internal import of every module."""
    modules = module_files(src)
    return [imp for name, path in modules.items() for imp in imports_of(name, path, modules)]


def sizes(src: Path = SRC, limit: int = LIMIT) -> list[tuple[str, int]]:
    """The modules over ``limit`` lines, longest first."""
    counted = [
        (name, len(path.read_text().splitlines())) for name, path in module_files(src).items()
    ]
    return sorted(((name, lines) for name, lines in counted if lines > limit), key=lambda x: -x[1])


def circles(graph: list[Import]) -> list[list[str]]:
    """The strongly connected sets (over one module) of the imports that run (Tarjan)."""
    edges: dict[str, set[str]] = {}
    for imp in graph:
        if not imp.typing_only and imp.source != imp.target:
            edges.setdefault(imp.source, set()).add(imp.target)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(edges.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.append(top)
                if top == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(max(10_000, sys.getrecursionlimit()))
    for node in sorted(edges):
        if node not in index:
            visit(node)
    return sorted(found)


def upward(graph: list[Import]) -> list[Import]:
    """The imports that run from a module to a module of a higher layer."""
    return [
        imp
        for imp in graph
        if not imp.typing_only
        and layer_of(imp.target) > layer_of(imp.source)
        and not imp.target.startswith(imp.source + ".")  # a facade and its own modules
    ]


def _package(module: str, modules: dict[str, Path]) -> str:
    path = modules[module]
    return module if path.name == "__init__.py" else module.rpartition(".")[0]


def private_imports(src: Path = SRC) -> list[tuple[str, str, int, str]]:
    """Private names taken across modules: ``(importer, module, line, name)``.

    A private name is one with a leading underscore and not a dunder. Counted: ``from M
    import _name``; ``M._name`` where ``M`` was bound by ``import`` or ``from pkg import M``;
    and a private module imported from outside the package that holds it.
    """
    modules = module_files(src)
    found: list[tuple[str, str, int, str]] = []
    for module, path in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        bound: dict[str, str] = {}  # local name -> package module it is bound to
        for imp in imports_of(module, path, modules):
            leaf = imp.target.rpartition(".")[2]
            if leaf.startswith("_") and not leaf.startswith("__"):
                holder = imp.target.rpartition(".")[0]
                if not (module == holder or module.startswith(holder + ".")):
                    found.append((module, imp.target, imp.line, "(module)"))
            for name in imp.names:
                if name.startswith("_") and not name.startswith("__") and imp.target != module:
                    found.append((module, imp.target, imp.line, name))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom | ast.Import):
                for alias in node.names:
                    local = alias.asname or alias.name.split(".")[0]
                    for imp in imports_of(module, path, modules):
                        if imp.line == node.lineno and imp.target.endswith("." + alias.name):
                            bound[local] = imp.target
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.value, ast.Name)
                and node.value.id in bound
                and node.attr.startswith("_")
                and not node.attr.startswith("__")
                and bound[node.value.id] != module
            ):
                found.append((module, bound[node.value.id], node.lineno, node.attr))
    return sorted(set(found))


def report(src: Path = SRC, limit: int = LIMIT) -> str:
    """The four measures as text."""
    graph = import_graph(src)
    lines = [f"modules over {limit} lines:"]
    lines += [f"  {lines_:5d}  {name}" for name, lines_ in sizes(src, limit)] or ["  none"]
    lines.append("import circles (imports that run):")
    lines += ["  " + " <-> ".join(c) for c in circles(graph)] or ["  none"]
    lines.append("imports up the layers (imports that run):")
    lines += [
        f"  {imp.source}:{imp.line} ({LAYERS[layer_of(imp.source)][0]})"
        f" -> {imp.target} ({LAYERS[layer_of(imp.target)][0]})"
        for imp in upward(graph)
    ] or ["  none"]
    lines.append("private names imported across modules:")
    lines += [
        f"  {src_}:{line} {name} of {target}" for src_, target, line, name in private_imports(src)
    ] or ["  none"]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Print the measures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--limit", type=int, default=LIMIT, help="module size to report over")
    parser.add_argument("--src", type=Path, default=SRC, help="the source folder to measure")
    args = parser.parse_args(argv)
    print(report(args.src, args.limit))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
