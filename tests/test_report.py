"""Text tables of bayesgrasp.report: numbers as people read them."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from bayesgrasp.cli import main
from bayesgrasp.report import num

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_the_lever_basin_prints_zero_not_negative_zero(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 16: the lever's first basin began at ``-0.000`` (a boundary at -1e-14 rad)."""
    assert main(["squeeze", str(EXAMPLES / "lever.svg")]) == 0
    out = capsys.readouterr().out
    assert "(    0.000,   180.000)" in out
    assert "-0.000" not in out


@given(
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6),
    st.sampled_from(["9.3f", "+.2f", ".4f", "12.3f", ".1f"]),
)
def test_num_is_format_without_negative_zero(x: float, spec: str) -> None:
    text, plain = num(x, spec), format(x, spec)
    assert float(text) == float(plain)  # the same number
    assert len(text) == len(plain) or plain.lstrip().startswith("-")  # widths kept
    if float(plain) == 0.0:
        assert "-" not in text
    else:
        assert text == plain


def test_num_keeps_what_is_not_finite() -> None:
    assert num(-math.inf, ".2f") == "-inf"
    assert num(math.nan, "9.3f") == format(math.nan, "9.3f")
