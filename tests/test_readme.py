"""The README's library example runs and prints what the README says it prints."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

from bayesgrasp.model.actions import unregister_action

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.parametrize("heading", ["## Library use", "## Architecture"])
def test_library_example_output_matches_the_readme(heading: str) -> None:
    text = README.read_text(encoding="utf-8")
    section = text[text.index(heading) :]
    code = re.search(r"```python\n(.*?)```", section, re.S)
    shown = re.search(r"prints\n\n```text\n(.*?)```", section, re.S)
    assert code is not None and shown is not None
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            exec(compile(code.group(1), str(README), "exec"), {})
        finally:
            unregister_action("station-2")  # the Architecture example's action
    assert out.getvalue() == shown.group(1)
