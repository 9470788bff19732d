"""A batch file that is not one: a FIFO, a folder, an empty file, each refused with one line."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest


def _plan(*args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "bayesgrasp.cli", "plan", *args],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=60,
    )


def _refused(run: subprocess.CompletedProcess[str], reason: str) -> None:
    assert run.returncode == 2, run.stderr
    assert run.stdout == ""
    assert len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert reason in run.stderr


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_a_fifo_batch_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "parts.jsonl"
    os.mkfifo(fifo)
    _refused(_plan("--batch", str(fifo)), "pipe them into --batch -")


def test_an_empty_batch_says_so(tmp_path: Path) -> None:
    empty = tmp_path / "empty.jsonl"
    empty.write_text("\n  \n")
    _refused(_plan("--batch", str(empty)), "holds no part")
    _refused(_plan("--batch", "-", stdin=""), "standard input holds no part")


def test_a_folder_or_a_missing_batch_is_refused(tmp_path: Path) -> None:
    _refused(_plan("--batch", str(tmp_path)), "is a folder")
    _refused(_plan("--batch", str(tmp_path / "no.jsonl")), "cannot read")


def test_a_batch_on_stdin_still_streams() -> None:
    run = _plan("--batch", "-", "--json", stdin='"house"\n"triangle"\n')
    assert run.returncode == 0, run.stderr
    assert len(run.stdout.splitlines()) == 2
