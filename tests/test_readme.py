"""The README is a short front door whose commands and example run as shown.

Its ``console`` blocks are transcripts: a line starting with ``$ `` is a command run by
``bash`` from the repository root (``bayesgrasp`` the installed command), the lines after it
what it prints (both streams; a line ``...`` stands for any lines). Its ``python`` block is
run and must print the ``text`` block after it. Its links point at files that exist.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
README = REPO / "README.md"
TEXT = README.read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    """The bodies of the README's fenced blocks of one language."""
    return re.findall(rf"^```{language}\n(.*?)^```", TEXT, re.S | re.M)


def steps(block: str) -> list[tuple[str, list[str]]]:
    """The commands of a console block, each with the lines it must print."""
    out: list[tuple[str, list[str]]] = []
    for line in block.splitlines():
        if line.startswith("$ "):
            out.append((line[2:], []))
        else:
            assert out, f"a console block must start with a command; got {line!r}"
            out[-1][1].append(line.rstrip())
    return out


def matches(expected: list[str], actual: list[str]) -> bool:
    """Whether ``actual`` is ``expected``, a line ``...`` standing for any lines."""
    if not expected:
        return not actual
    if expected[0] == "...":
        return any(matches(expected[1:], actual[k:]) for k in range(len(actual) + 1))
    return bool(actual) and actual[0] == expected[0] and matches(expected[1:], actual[1:])


def test_the_readme_is_short_and_says_what_a_user_needs() -> None:
    assert len(TEXT.splitlines()) <= 200
    for needed in ("make demo", "make test", "--export", "--plot", "Bayesian Grasping", "MIT"):
        assert needed in TEXT
    # Nothing that goes stale: no test counts, session timings or issue numbers.
    assert not re.search(r"\b\d[\d,]* tests\b|\bissue \d+|\bUTC\b|\bthe seed\b", TEXT)


def test_the_readme_links_point_at_files_that_exist() -> None:
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", TEXT)
    local = [link for link in links if "://" not in link]
    assert local
    missing = [link for link in local if not (REPO / link).exists()]
    assert not missing


@pytest.mark.parametrize("block", blocks("console"), ids=lambda b: b.splitlines()[0][2:40])
def test_the_readme_commands_print_what_it_shows(block: str) -> None:
    env = dict(os.environ, COLUMNS="80", TERM="dumb", NO_COLOR="1")
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    before = set(REPO.iterdir())
    try:
        for command, expected in steps(block):
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
            actual = [line.rstrip() for line in proc.stdout.splitlines()]
            while expected and not expected[-1]:
                expected.pop()
            assert matches(expected, actual), f"`{command}` printed\n" + "\n".join(actual)
    finally:
        for p in set(REPO.iterdir()) - before:
            shutil.rmtree(p) if p.is_dir() else p.unlink()


def test_the_readme_library_example_prints_what_it_shows(monkeypatch: pytest.MonkeyPatch) -> None:
    code = re.search(r"^```python\n(.*?)^```\n\nprints\n\n```text\n(.*?)^```", TEXT, re.S | re.M)
    assert code is not None
    monkeypatch.chdir(REPO)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code.group(1), str(README), "exec"), {})
    assert out.getvalue() == code.group(2)
