"""The documentation site: it builds with warnings as errors, fetches nothing from the network,
its generated reference covers the program, and every documented command prints what the
documentation shows.

The site
--------
``make test`` builds the site once (``make docs``: ``sphinx-build -E -W --keep-going``) and
passes its folder in ``BAYESGRASP_DOCS_HTML``; without it these tests build the site into a
temporary folder themselves (about half a minute, plus the tutorials).

Transcripts
-----------
Every fenced block of language ``console`` in ``README.md`` and ``docs/**/*.md`` is a
transcript. A line starting with ``$ `` is a command (a trailing ``\\`` continues it on the
next line), run by ``bash`` from the repository root with the venv's ``bin`` first on
``PATH`` (so ``bayesgrasp`` is the venv's command); the lines after it, up to the next
``$ ``, are what it must print (standard output and standard error together). The
comparison is exact after normalising, on both sides:

- trailing spaces of each line, and blank lines at the end of the output;
- volatile figures (:data:`VOLATILE`): elapsed times (``0.8 s``, ``12 ms``) and temporary
  folders (``/tmp/...``);
- a line that is exactly ``...`` in the expected output stands for any number of lines.

Blocks of language ``text``, ``sh`` or anything else are not run. A command that writes into
the repository root leaves nothing behind: new top-level files and folders (but hidden ones,
such as tool caches) are removed after each transcript. Transcripts that run MuJoCo
(``--engine mujoco``) are marked ``physics``, those that start Dask (``bayesgrasp sweep``)
``dask``.
"""

from __future__ import annotations

import html.parser
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"
VENV_BIN = Path(sys.executable).parent

# --------------------------------------------------------------------------- transcripts

FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})\s*(?P<info>[^`]*)$")

#: Volatile figures, replaced on both sides before comparing.
VOLATILE: tuple[tuple[re.Pattern[str], str], ...] = (
    (re.compile(r"\b\d+(?:\.\d+)? ?s\b"), "<seconds> s"),  # elapsed seconds
    (re.compile(r"\b\d+(?:\.\d+)? ?ms\b"), "<ms> ms"),  # elapsed milliseconds
    (re.compile(r"/tmp/[^\s'\"/:]+"), "/tmp/<tmp>"),  # temporary folders
)
ELLIPSIS = "..."


@dataclass(frozen=True)
class Step:
    """One command of a transcript and the lines it must print."""

    command: str
    expected: tuple[str, ...]


@dataclass(frozen=True)
class Transcript:
    """A ``console`` block: where it is and its commands."""

    path: Path
    line: int
    steps: tuple[Step, ...]

    @property
    def id(self) -> str:
        return f"{self.path.relative_to(REPO)}:{self.line}"


def fenced_blocks(text: str, language: str) -> list[tuple[int, list[str]]]:
    """The fenced blocks of ``language`` in a Markdown text: (line of the fence, lines)."""
    blocks: list[tuple[int, list[str]]] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m is None:
            i += 1
            continue
        fence, info = m["fence"], m["info"].strip()
        lang = info.split()[0] if info else ""
        body: list[str] = []
        j = i + 1
        while j < len(lines):
            close = lines[j].strip()
            if close.startswith(fence[0] * len(fence)) and set(close) == {fence[0]}:
                break
            body.append(lines[j])
            j += 1
        if lang == language:
            blocks.append((i + 1, body))
        i = j + 1
    return blocks


def parse_transcript(lines: list[str]) -> tuple[Step, ...]:
    """The commands of a ``console`` block and their expected output.

    >>> parse_transcript(["$ echo a \\\\", "  b", "a b", "$ true"])
    (Step(command='echo a b', expected=('a b',)), Step(command='true', expected=()))
    """
    steps: list[Step] = []
    command: str | None = None
    expected: list[str] = []
    it = iter(lines)
    for line in it:
        if line.startswith("$ "):
            if command is not None:
                steps.append(Step(command, tuple(expected)))
            command, expected = line[2:].strip(), []
            while command.endswith("\\"):
                command = command[:-1].rstrip() + " " + next(it, "").strip()
        elif command is None:
            if line.strip():
                raise ValueError(f"a console block must start with a `$ ` command; got {line!r}")
        else:
            expected.append(line)
    if command is not None:
        steps.append(Step(command, tuple(expected)))
    return tuple(steps)


def normalise(lines: list[str] | tuple[str, ...]) -> list[str]:
    """Lines without trailing spaces or trailing blank lines, volatile figures replaced."""
    out = []
    for line in lines:
        line = line.rstrip()
        for pattern, repl in VOLATILE:
            line = pattern.sub(repl, line)
        out.append(line)
    while out and not out[-1]:
        out.pop()
    return out


def output_matches(expected: list[str], actual: list[str]) -> bool:
    """Whether ``actual`` is ``expected``, a line ``...`` standing for any lines."""
    if not expected:
        return not actual
    head = expected[0]
    if head == ELLIPSIS:
        return any(output_matches(expected[1:], actual[k:]) for k in range(len(actual) + 1))
    return bool(actual) and actual[0] == head and output_matches(expected[1:], actual[1:])


def transcripts() -> list[Transcript]:
    """Every ``console`` block of README.md and docs/**/*.md."""
    pages = sorted(
        p
        for p in DOCS.rglob("*.md")
        if not {"_build", "auto_tutorials"} & set(p.relative_to(DOCS).parts)
    )
    paths = [REPO / "README.md", *pages]
    found = []
    for path in paths:
        if not path.exists():
            continue
        for line, body in fenced_blocks(path.read_text(encoding="utf-8"), "console"):
            found.append(Transcript(path, line, parse_transcript(body)))
    return found


def _marks(t: Transcript) -> list[pytest.MarkDecorator]:
    commands = " ".join(s.command for s in t.steps)
    marks = []
    if "--engine mujoco" in commands:
        marks.append(pytest.mark.physics)
    if re.search(r"\bbayesgrasp sweep\b", commands):
        marks.append(pytest.mark.dask)
    return marks


def run_command(command: str) -> list[str]:
    """Run a documented command from the repository root; its output, both streams."""
    env = dict(os.environ)
    env["PATH"] = f"{VENV_BIN}{os.pathsep}{env.get('PATH', '')}"
    env.update(COLUMNS="80", TERM="dumb", NO_COLOR="1")
    proc = subprocess.run(
        ["bash", "-c", command],
        cwd=REPO,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=300,
        check=False,
    )
    return proc.stdout.splitlines()


_TRANSCRIPTS = transcripts()


@pytest.mark.parametrize(
    "transcript",
    [pytest.param(t, id=t.id, marks=_marks(t)) for t in _TRANSCRIPTS],
)
def test_documented_commands_print_what_the_docs_show(transcript: Transcript) -> None:
    before = {p.name for p in REPO.iterdir()}
    try:
        for step in transcript.steps:
            actual = normalise(run_command(step.command))
            expected = normalise(step.expected)
            assert output_matches(expected, actual), (
                f"{transcript.id}: `$ {step.command}` printed\n"
                + "\n".join(actual)
                + "\n--- the documentation shows ---\n"
                + "\n".join(expected)
            )
    finally:
        for p in REPO.iterdir():
            if p.name not in before and not p.name.startswith("."):
                shutil.rmtree(p) if p.is_dir() else p.unlink()


# Python examples: a ``python`` block, a line "prints", a ``text`` block with its output.


def python_examples(text: str) -> list[tuple[int, str, list[str]]]:
    """(line, code, expected output) of each python block followed by "prints" and a text block.

    >>> python_examples("```python\\nprint(1)\\n```\\n\\nprints\\n\\n```text\\n1\\n```\\n")
    [(1, 'print(1)', ['1'])]
    """
    lines = text.splitlines()
    blocks = {line: body for line, body in fenced_blocks(text, "python")}
    outputs = {line: body for line, body in fenced_blocks(text, "text")}
    found = []
    for line, body in blocks.items():
        after = line + len(body) + 1  # the closing fence's line number
        rest = [(n, lines[n - 1].strip()) for n in range(after + 1, min(after + 5, len(lines)) + 1)]
        rest = [(n, t) for n, t in rest if t]
        if len(rest) >= 2 and rest[0][1] == "prints" and rest[1][0] in outputs:
            found.append((line, "\n".join(body), outputs[rest[1][0]]))
    return found


_EXAMPLES = [
    pytest.param(code, expected, id=f"{path.relative_to(REPO)}:{line}")
    for path in sorted(DOCS.rglob("*.md"))
    if not {"_build", "auto_tutorials"} & set(path.relative_to(DOCS).parts)
    for line, code, expected in python_examples(path.read_text(encoding="utf-8"))
]


@pytest.mark.parametrize(("code", "expected"), _EXAMPLES)
def test_python_examples_print_what_the_docs_show(code: str, expected: list[str]) -> None:
    proc = subprocess.run(
        [sys.executable, "-c", code],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert normalise(proc.stdout.splitlines()) == normalise(expected)


# The checker itself: it must pass what matches and fail what does not.


def test_fenced_blocks_take_only_console_blocks() -> None:
    text = "\n".join(
        [
            "```console",
            "$ echo hi",
            "hi",
            "```",
            "```text",
            "$ echo not run",
            "```",
            "````sh",
            "$ echo not run either",
            "````",
            "~~~console",
            "$ true",
            "~~~",
        ]
    )
    blocks = fenced_blocks(text, "console")
    assert [line for line, _ in blocks] == [1, 11]
    assert blocks[0][1] == ["$ echo hi", "hi"]


def test_transcript_that_matches_passes_and_one_that_drifts_fails() -> None:
    (step,) = parse_transcript(["$ printf 'a  \\nb\\n\\n'", "a", "b"])
    actual = normalise(run_command(step.command))
    assert output_matches(normalise(step.expected), actual)
    assert not output_matches(normalise(["a", "c"]), actual)
    assert not output_matches(normalise(["a"]), actual)
    assert not output_matches(normalise(["a", "b", "c"]), actual)


def test_ellipsis_and_volatile_figures() -> None:
    actual = normalise(["sweep: 5 rows in 0.8 s", "x", "y", "wrote /tmp/abc123/plan.json"])
    assert output_matches(
        normalise(["sweep: 5 rows in 12.5 s", "...", "wrote /tmp/q/plan.json"]), actual
    )
    assert output_matches(normalise(["...", "y", "..."]), actual)
    assert not output_matches(normalise(["sweep: 6 rows in 0.8 s", "..."]), actual)
    assert not output_matches(normalise(["...", "z", "..."]), actual)


def test_a_console_block_starts_with_a_command() -> None:
    with pytest.raises(ValueError, match="must start with a `\\$ ` command"):
        parse_transcript(["output before any command"])


def test_commands_run_from_the_repository_root_with_the_venv_command() -> None:
    assert run_command("pwd") == [str(REPO)]
    (path,) = run_command("command -v bayesgrasp")
    assert Path(path).parent == VENV_BIN


# --------------------------------------------------------------------------- the site


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The built site: ``make test``'s build, or one built here with warnings as errors."""
    given = os.environ.get("BAYESGRASP_DOCS_HTML")
    if given:
        path = Path(given)
        assert (path / "index.html").exists(), f"BAYESGRASP_DOCS_HTML={given} has no index.html"
        return path
    out = tmp_path_factory.mktemp("docs")
    env = dict(os.environ)
    env["PATH"] = f"{VENV_BIN}{os.pathsep}{env.get('PATH', '')}"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-j",
            "auto",
            "-b",
            "html",
            "-E",
            "-W",
            "--keep-going",
            "-q",
            "-d",
            str(out / "doctrees"),
            str(DOCS),
            str(out / "html"),
        ],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    warnings = [line for line in proc.stderr.splitlines() if "WARNING" in line or "ERROR" in line]
    assert proc.returncode == 0 and not warnings, "\n".join(warnings or [proc.stderr[-3000:]])
    return out / "html"


class _Assets(html.parser.HTMLParser):
    """Every URL an HTML page loads (not the links a reader may follow)."""

    LOADS: ClassVar[dict[str, tuple[str, ...]]] = {
        "script": ("src",),
        "img": ("src", "srcset"),
        "iframe": ("src",),
        "source": ("src", "srcset"),
        "video": ("src", "poster"),
        "audio": ("src",),
        "embed": ("src",),
        "object": ("data",),
        "link": ("href",),
    }

    def __init__(self) -> None:
        super().__init__()
        self.urls: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if value and name in self.LOADS.get(tag, ()):
                self.urls.append(value)
            if value and name == "style":
                self.urls.extend(re.findall(r"url\(\s*['\"]?([^'\")]+)", value))


REMOTE = re.compile(r"^\s*(https?:)?//", re.IGNORECASE)


def _remote_assets(site: Path) -> list[str]:
    found = []
    for page in site.rglob("*.html"):
        parser = _Assets()
        parser.feed(page.read_text(encoding="utf-8"))
        found += [f"{page.relative_to(site)}: {u}" for u in parser.urls if REMOTE.match(u)]
    for css in site.rglob("*.css"):
        text = css.read_text(encoding="utf-8", errors="replace")
        for url in re.findall(r"(?:url\(\s*['\"]?|@import\s+['\"])([^'\")]+)", text):
            if REMOTE.match(url):
                found.append(f"{css.relative_to(site)}: {url}")
    return found


def test_the_asset_check_finds_remote_assets(tmp_path: Path) -> None:
    (tmp_path / "a.html").write_text(
        '<a href="https://example.org/">a plain link</a>'
        '<script src="https://cdn.example.org/x.js"></script>'
        '<link rel="stylesheet" href="//cdn.example.org/x.css">'
        '<img src="_images/local.png"><div style="background: url(\'http://e.org/i.png\')"></div>'
    )
    (tmp_path / "b.css").write_text('@import "https://fonts.example.org/f.css"; a{}')
    found = _remote_assets(tmp_path)
    assert len(found) == 4
    assert not any("a plain link" in f or 'example.org/"' in f for f in found)


@pytest.mark.slow
def test_site_loads_nothing_from_the_network(site: Path) -> None:
    assert _remote_assets(site) == []
    for text in (p.read_text(encoding="utf-8") for p in site.rglob("*.html")):
        assert re.search(r"<script[^>]*mathjax", text, re.IGNORECASE) is None


@pytest.mark.slow
def test_site_has_every_section(site: Path) -> None:
    for page in [
        "index.html",
        "getting-started.html",
        "auto_tutorials/index.html",
        "guide/index.html",
        "concepts/index.html",
        "concepts/mathematics.html",
        "reference/cli.html",
        "reference/api.html",
        "reference/schemas.html",
        "reference/errors.html",
        "performance.html",
        "changelog.html",
    ]:
        assert (site / page).exists(), page
    # the mathematics is MathML, converted at build time
    assert "<math" in (site / "concepts/mathematics.html").read_text(encoding="utf-8")


def _text(page: Path) -> str:
    return re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8")).replace("&#8212;", "-")


@pytest.mark.slow
def test_cli_reference_has_every_command_and_option(site: Path) -> None:
    import click
    import typer

    from bayesgrasp.cli import COMMANDS, app

    text = _text(site / "reference/cli.html")
    group = typer.main.get_command(app)
    root = click.Context(group, info_name="bayesgrasp")
    assert group.list_commands(root) == list(COMMANDS)
    for name in COMMANDS:
        assert f"bayesgrasp {name}" in text, name
        cmd = group.get_command(root, name)
        assert cmd is not None
        for param in cmd.params:
            if getattr(param, "hidden", False):
                continue
            for opt in [*param.opts, *param.secondary_opts]:
                if opt.startswith("-"):
                    assert opt in text, f"{name} {opt}"


@pytest.mark.slow
def test_api_reference_has_every_public_name(site: Path) -> None:
    import bayesgrasp

    text = _text(site / "reference/api.html")
    for name in bayesgrasp.__all__:
        obj = getattr(bayesgrasp, name)
        aliased = any(
            getattr(bayesgrasp, other) is obj
            for other in bayesgrasp.__all__[: bayesgrasp.__all__.index(name)]
        )
        if not aliased:
            assert name in text, name
            assert (site / f"reference/generated/bayesgrasp.{name}.html").exists(), name


@pytest.mark.slow
def test_schema_page_shows_generated_documents(site: Path) -> None:
    text = _text(site / "reference/schemas.html")
    for schema in ["plan/1", "plan/2", "policy/1", "simulate/1", "robot/1", "robot-policy/1"]:
        assert f'"bayesgrasp.{schema}"' in text.replace("&quot;", '"') or (
            f"bayesgrasp.{schema}" in text
        ), schema
    assert "Traceback" not in text
    errors = _text(site / "reference/errors.html")
    assert "bayesgrasp: error: 'no-such-part' is neither a catalogue part" in errors.replace(
        "&#39;", "'"
    )


@pytest.mark.slow
def test_gallery_ran_and_shows_its_figures(site: Path) -> None:
    scripts = sorted((DOCS / "tutorials").glob("plot_*.py"))
    if not scripts:
        pytest.skip("no tutorials in docs/tutorials yet")
    for script in scripts:
        page = site / "auto_tutorials" / f"{script.stem}.html"
        assert page.exists(), page
        text = page.read_text(encoding="utf-8")
        assert re.search(r'<img [^>]*src="\.\./_images/sphx_glr_', text), f"{page}: no figure"


# --------------------------------------------------------------------------- the extension


def _extension():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(
        "bayesgrasp_docs", DOCS / "_ext" / "bayesgrasp_docs.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_compact_json_is_the_same_document() -> None:
    ext = _extension()
    doc = {"a": [1, 2.5, None], "b": {"c": [[0.0, 1.0], [2.0, 3.0]], "d": []}, "e": [{"f": 1}]}
    text = ext._compact_json(doc)
    assert json.loads(text) == doc
    assert "[1, 2.5, null]" in text and "[[0.0, 1.0], [2.0, 3.0]]" in text


def test_csv_row_shows_one_row_by_column() -> None:
    ext = _extension()
    text = ext._csv_row("a,bb\n1," + "x" * 100 + "\n", 0, width=20)
    assert text.splitlines() == ["a   1", "bb  " + "x" * 15 + " ..."]


def test_compact_json_text_takes_a_document_or_json_lines() -> None:
    ext = _extension()
    doc = {"ci95": [0.25, 0.26], "rows": [{"a": 1}]}
    pretty = json.dumps(doc, indent=2)
    assert json.loads(ext._compact_json_text(pretty)) == doc
    assert '"ci95": [0.25, 0.26]' in ext._compact_json_text(pretty)
    lines = ext._compact_json_text(json.dumps({"b": [1]}) + "\n" + json.dumps({"c": 2}) + "\n")
    assert lines == '{\n  "b": [1]\n}\n{\n  "c": 2\n}'
    assert ext._compact_json_text("not json") is None


# --------------------------------------------------------------------------- written for users

#: What user documentation does not say: the paper is "the paper", and no page tells the
#: history of its making (issue numbers, commits, session times). What a command prints (the
#: output in a ``console`` transcript, a ``text`` block) is the program's text: not here.
NOT_FOR_USERS = (
    (
        re.compile(
            r"\bseed's\b|\bthe seed (paper|\(|calls|says|lists|uses|searched|sketches)",
            re.IGNORECASE,
        ),
        'call the paper "the paper"',
    ),
    (re.compile(r"\bissue \d+|\bissue #\d+", re.IGNORECASE), "an issue number"),
    (re.compile(r"\bcommit [0-9a-f]{7,40}\b"), "a commit"),
    (re.compile(r"\b\d{2}:\d{2}(-\d{2}:\d{2})? UTC\b"), "a time of day"),
)


def _user_pages() -> list[Path]:
    pages = [REPO / "README.md", *(t for t in (DOCS / "tutorials").glob("*.py"))]
    pages += [
        p
        for p in DOCS.rglob("*.md")
        if not {"_build", "auto_tutorials"} & set(p.relative_to(DOCS).parts)
    ]
    return sorted(p for p in pages if p.exists())


def _transcript_lines(text: str) -> set[int]:
    """Line numbers of what programs print: output in ``console`` blocks, ``text`` blocks."""
    out = set()
    for start, body in fenced_blocks(text, "console"):
        out.update(start + i for i, line in enumerate(body, 1) if not line.startswith("$ "))
    for start, body in fenced_blocks(text, "text"):
        out.update(start + i for i in range(1, len(body) + 1))
    return out


def test_pages_are_written_for_users() -> None:
    problems = []
    for page in _user_pages():
        text = page.read_text(encoding="utf-8")
        skip = _transcript_lines(text) if page.suffix == ".md" else set()
        for number, line in enumerate(text.splitlines(), 1):
            if number in skip:
                continue
            for pattern, what in NOT_FOR_USERS:
                if pattern.search(line):
                    problems.append(f"{page.relative_to(REPO)}:{number}: {what}: {line.strip()}")
    assert not problems, "\n".join(problems)


def test_only_transcript_output_is_exempt() -> None:
    text = "x\n```console\n$ bayesgrasp table1\nThe seed's Table 1\n```\nthe seed\n"
    assert _transcript_lines(text) == {4}
    text = "```text\nThe seed's Table 1\n```\n```python\n# the seed's problem\n```\n"
    assert _transcript_lines(text) == {2}
    paper = NOT_FOR_USERS[0][0]
    assert paper.search("The seed's Table 1") and paper.search("the seed (section 4.2)")
    assert not paper.search("the seed of the random polygons, the versions")
    assert NOT_FOR_USERS[1][0].search("(issue 12)") and NOT_FOR_USERS[2][0].search("commit 373822f")
    assert NOT_FOR_USERS[3][0].search("at 04:39-04:45 UTC on")
