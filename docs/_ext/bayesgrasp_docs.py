"""Sphinx extension of the bayesgrasp documentation: pages generated from the code at build time.

Four pieces, so that the reference cannot drift from the program it documents:

``bayesgrasp-cli`` (directive)
    The command-line reference: walks the click command tree of the typer app
    (:data:`bayesgrasp.cli.app`) and writes, for every command, its usage line, its help text
    and a table of its arguments and options (the same records ``--help`` prints, defaults
    and ranges included).

``bayesgrasp-run`` (directive)
    Runs one ``bayesgrasp`` command (``python -m bayesgrasp.cli`` of the interpreter that
    builds the docs, from the repository root) and shows what it printed, or a file it wrote,
    as a literal block. JSON is re-indented with lists of numbers on one line. A command whose
    exit code differs from ``:exit-code:`` (default 0) is a build warning, so an example that
    stops working fails ``make docs``. ``{tmp}`` in the command is a fresh temporary folder
    (left out where the command is shown: ``{tmp}/robot.csv`` shows as ``robot.csv``).

The API page
    ``reference/api.rst`` is written when the configuration is read (before the sources are found)
    from the ``__all__`` of :mod:`bayesgrasp` and of each of its subpackages, so a public
    name added to the package appears in the reference without editing a page.

MathML
    ``$...$`` and ``math`` blocks are converted to MathML at build time (``latex2mathml``),
    which browsers render natively: no MathJax, no network.
"""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

logger = logging.getLogger(__name__)

REPO = Path(__file__).resolve().parents[2]


# --------------------------------------------------------------------------- MathML


def _mathml(latex: str, display: str) -> str:
    from latex2mathml.converter import convert

    return convert(latex.strip(), display=display)


def _visit_inline_math(self: Any, node: nodes.Element) -> None:
    self.body.append(f'<span class="math">{_mathml(node.astext(), "inline")}</span>')
    raise nodes.SkipNode


def _visit_block_math(self: Any, node: nodes.Element) -> None:
    if node.get("label"):
        self.body.append(f'<span class="eqno">({node["number"]})</span>')
    self.body.append(f'<div class="math">{_mathml(node.astext(), "block")}</div>')
    raise nodes.SkipNode


# --------------------------------------------------------------------------- CLI reference


def _paragraphs(text: str) -> list[nodes.Node]:
    """Help text as paragraphs (blank lines separate them), literal otherwise."""
    out: list[nodes.Node] = []
    for para in text.strip().split("\n\n"):
        para = " ".join(line.strip() for line in para.splitlines())
        if para:
            out.append(nodes.paragraph(text=para))
    return out


def _table(
    rows: list[tuple[str, str]],
    header: tuple[str, str],
    targets: list[str] | None = None,
) -> nodes.table:
    table = nodes.table(classes=["bayesgrasp-cli-options"])
    group = nodes.tgroup(cols=2)
    table += group
    group += nodes.colspec(colwidth=30)
    group += nodes.colspec(colwidth=70)

    def row(cells: tuple[str, str], literal_first: bool, target: str | None = None) -> nodes.row:
        r = nodes.row()
        for i, cell in enumerate(cells):
            entry = nodes.entry()
            para = nodes.paragraph()
            content: nodes.Node = (
                nodes.literal(text=cell) if (i == 0 and literal_first) else nodes.Text(cell)
            )
            if i == 0 and target:
                ref = nodes.reference("", "", internal=True, refid=target)
                ref += content
                content = ref
            para += content
            entry += para
            r += entry
        return r

    thead = nodes.thead()
    thead += row(header, literal_first=False)
    group += thead
    tbody = nodes.tbody()
    for k, cells in enumerate(rows):
        tbody += row(cells, literal_first=True, target=targets[k] if targets else None)
    group += tbody
    return table


class CliDirective(SphinxDirective):
    """``bayesgrasp-cli``: the reference of every command of the typer app."""

    has_content = False

    def _section(self, title: str, ident: str) -> nodes.section:
        section = nodes.section(ids=[ident], names=[nodes.fully_normalize_name(ident)])
        section += nodes.title(text=title)
        self.state.document.note_implicit_target(section, section)
        return section

    def run(self) -> list[nodes.Node]:
        """The nodes of the reference."""
        import click
        import typer

        from bayesgrasp.cli import COMMANDS
        from bayesgrasp.cli import app as typer_app

        group = typer.main.get_command(typer_app)
        root = click.Context(group, info_name="bayesgrasp")
        out: list[nodes.Node] = []
        out.extend(_paragraphs(group.help or ""))
        out.append(nodes.literal_block(text=group.get_usage(root)))
        records = [p.get_help_record(root) for p in group.get_params(root)]
        out.append(_table([r for r in records if r], ("option", "meaning")))
        out.append(
            _table(
                [(f"bayesgrasp {n}", s) for n, (_, s) in COMMANDS.items()],
                ("command", "what it does"),
                targets=[f"cli-{n}" for n in COMMANDS],
            )
        )
        for name in group.list_commands(root):
            cmd = group.get_command(root, name)
            if cmd is None or cmd.hidden:
                continue
            ctx = click.Context(cmd, info_name=name, parent=root)
            section = self._section(f"bayesgrasp {name}", f"cli-{name}")
            section += nodes.literal_block(text=cmd.get_usage(ctx))
            section.extend(_paragraphs(cmd.help or ""))
            args, opts = [], []
            for param in cmd.get_params(ctx):
                record = param.get_help_record(ctx)
                if record is None and isinstance(param, click.Argument):
                    record = (param.make_metavar(ctx), "")
                if record is None:
                    continue
                (args if isinstance(param, click.Argument) else opts).append(record)
            if args:
                section += nodes.rubric(text="Arguments")
                section += _table(args, ("argument", "meaning"))
            if opts:
                section += nodes.rubric(text="Options")
                section += _table(opts, ("option", "meaning"))
            out.append(section)
        return out


# --------------------------------------------------------------------------- command output


def _compact_json(value: Any, indent: int = 0) -> str:
    """JSON with two-space indents and every list of scalars on one line."""
    pad = "  " * indent
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [
            f"{pad}  {json.dumps(k)}: {_compact_json(v, indent + 1)}" for k, v in value.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list):
        if all(not isinstance(v, (dict, list)) for v in value) or all(
            isinstance(v, list) and all(not isinstance(w, (dict, list)) for w in v) for v in value
        ):
            return json.dumps(value)
        items = [f"{pad}  {_compact_json(v, indent + 1)}" for v in value]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(value)


def _compact_json_text(text: str) -> str | None:
    """A JSON document (or JSON lines) compacted; ``None`` when it is not JSON."""
    try:
        return _compact_json(json.loads(text))
    except json.JSONDecodeError:
        pass
    try:
        return "\n".join(_compact_json(json.loads(line)) for line in text.splitlines() if line)
    except json.JSONDecodeError:
        return None


def _csv_row(text: str, index: int, width: int = 72) -> str:
    """Row ``index`` of a CSV text as ``column: value`` lines (long values cut)."""
    import csv
    import io

    rows = list(csv.DictReader(io.StringIO(text)))
    row = rows[index] if index < len(rows) else {}
    pad = max((len(k) for k in row), default=0)
    out = []
    for key, value in row.items():
        if len(value) > width:
            value = value[: width - 5] + " ..."
        out.append(f"{key:<{pad}}  {value}")
    return "\n".join(out)


class SweepColumnsDirective(SphinxDirective):
    """``bayesgrasp-sweep-columns``: the columns of a sweep's rows, in order, with types."""

    def run(self) -> list[nodes.Node]:
        """The table of columns."""
        from bayesgrasp.sweep.tasks import ROW_COLUMNS

        rows = [(name, kind.__name__) for name, kind in ROW_COLUMNS]
        return [_table(rows, ("column", "type"))]


def run_bayesgrasp(args: list[str], cwd: Path = REPO) -> subprocess.CompletedProcess[str]:
    """Run ``bayesgrasp ARGS`` with the interpreter that builds the docs."""
    env = dict(os.environ, COLUMNS="100", NO_COLOR="1", TERM="dumb")
    return subprocess.run(
        [sys.executable, "-m", "bayesgrasp.cli", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


class RunDirective(SphinxDirective):
    """``bayesgrasp-run``: a command's output (or a file it writes) as a literal block."""

    required_arguments = 1
    final_argument_whitespace = True
    option_spec = {  # noqa: RUF012 (docutils reads it as a class attribute)
        "language": directives.unchanged,
        "file": directives.unchanged,
        "exit-code": directives.nonnegative_int,
        "stderr": directives.flag,
        "max-lines": directives.nonnegative_int,
        "show-command": directives.flag,
        "csv-row": directives.nonnegative_int,
    }

    def run(self) -> list[nodes.Node]:
        """Run the command; its output as a literal block."""
        with tempfile.TemporaryDirectory(prefix="bayesgrasp-docs-") as tmp:
            command = self.arguments[0]
            args = shlex.split(command.replace("{tmp}", tmp))
            proc = run_bayesgrasp(args)
            expected = self.options.get("exit-code", 0)
            if proc.returncode != expected:
                logger.warning(
                    "bayesgrasp %s: exit code %d (expected %d): %s",
                    command,
                    proc.returncode,
                    expected,
                    (proc.stderr or proc.stdout).strip().splitlines()[-1:],
                    location=self.get_location(),
                )
            if "file" in self.options:
                path = Path(tmp) / self.options["file"]
                if not path.exists():
                    logger.warning(
                        "bayesgrasp %s wrote no %s",
                        command,
                        path.name,
                        location=self.get_location(),
                    )
                text = path.read_text() if path.exists() else ""
            elif "stderr" in self.options:
                text = proc.stderr
            else:
                text = proc.stdout
        language = self.options.get("language", "text")
        if "csv-row" in self.options:
            text = _csv_row(text, self.options["csv-row"])
        if language == "json":
            compact = _compact_json_text(text)
            if compact is None:
                language = "text"
            else:
                text = compact
        lines = text.rstrip("\n").splitlines()
        limit = self.options.get("max-lines")
        if limit and len(lines) > limit:
            lines = [*lines[:limit], f"... ({len(lines) - limit} more lines)"]
            language = "text"
        if "show-command" in self.options:
            shown = self.arguments[0].replace("{tmp}/", "")
            lines = [f"$ bayesgrasp {shown}", *lines]
            language = "console"
        block = nodes.literal_block(text="\n".join(lines), language=language)
        return [block]


class FieldsDirective(SphinxDirective):
    """``bayesgrasp-fields MODULE``: the first literal block (``::``) of a module's docstring.

    The modules that write documents describe their fields there; the page shows that text,
    so the description is the one kept beside the writer.
    """

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        """The literal block, or a warning when the docstring has none."""
        import importlib
        import textwrap

        module = importlib.import_module(self.arguments[0])
        doc = module.__doc__ or ""
        lines = doc.splitlines()
        for i, line in enumerate(lines):
            if line.rstrip().endswith("::"):
                block: list[str] = []
                for follow in lines[i + 1 :]:
                    if follow.strip() and not follow.startswith((" ", "\t")):
                        break
                    block.append(follow)
                text = textwrap.dedent("\n".join(block)).strip("\n")
                return [nodes.literal_block(text=text, language="text")]
        logger.warning(
            "%s: no literal block in the docstring", self.arguments[0], location=self.get_location()
        )
        return []


# --------------------------------------------------------------------------- API page

#: Subpackages not in the API page: the command line has its own reference.
API_SKIP = ("cli",)


def _first_line(obj: Any) -> str:
    doc = (getattr(obj, "__doc__", None) or "").strip()
    return doc.splitlines()[0] if doc else ""


def api_page() -> str:
    """The text of ``reference/api.rst``: autosummary tables of every public name."""
    import importlib
    import pkgutil

    import bayesgrasp

    lines = [
        ".. This page is generated by docs/_ext/bayesgrasp_docs.py when the docs are built.",
        "",
        "The Python API",
        "==============",
        "",
        "The public names of ``bayesgrasp`` (``import bayesgrasp as bg``) and of its",
        "subpackages, from their ``__all__``. A name the top level exports is listed there",
        "only. Optional subpackages need their extra (``plot``, ``sim``, ``sweep``, ``web``,",
        "...); importing one without it raises ``MissingExtraError`` naming the extra.",
        "",
    ]
    seen: set[int] = set()

    def section(modname: str, names: list[str]) -> None:
        module = importlib.import_module(modname)
        rows = []
        for name in names:
            obj = getattr(module, name)
            key = id(obj)
            if key in seen and not isinstance(obj, (int, float, str, tuple)):
                continue
            seen.add(key)
            rows.append(name)
        if not rows:
            return
        title = f"``{modname}``"
        lines.extend([title, "-" * len(title), ""])
        summary = _first_line(module)
        if summary:
            lines.extend([summary, ""])
        lines.extend(
            [f".. currentmodule:: {modname}", "", ".. autosummary::", "   :toctree: generated", ""]
        )
        lines.extend(f"   {name}" for name in rows)
        lines.append("")

    section("bayesgrasp", list(bayesgrasp.__all__))
    for info in pkgutil.iter_modules(bayesgrasp.__path__):
        if not info.ispkg or info.name in API_SKIP or info.name.startswith("_"):
            continue
        modname = f"bayesgrasp.{info.name}"
        module = importlib.import_module(modname)
        names = list(getattr(module, "__all__", []))
        if names:
            section(modname, names)
    return "\n".join(lines)


def _write_api_page(app: Sphinx, config: Any) -> None:
    path = Path(app.srcdir) / "reference" / "api.rst"
    text = api_page()
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the directives and the MathML renderer."""
    app.connect("config-inited", _write_api_page)
    app.add_directive("bayesgrasp-cli", CliDirective)
    app.add_directive("bayesgrasp-run", RunDirective)
    app.add_directive("bayesgrasp-fields", FieldsDirective)
    app.add_directive("bayesgrasp-sweep-columns", SweepColumnsDirective)
    app.add_html_math_renderer("mathml", (_visit_inline_math, None), (_visit_block_math, None))
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
