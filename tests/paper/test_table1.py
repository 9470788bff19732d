"""The seed's Table 1: printed numbers, our rows, the text and JSON forms, the command."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.errors import PartError
from bayesgrasp.paper.table1 import (
    PAPER_TABLE1,
    PaperRow,
    Table1Row,
    paper_row,
    table1_json,
    table1_row,
    table1_rows,
    table1_text,
)
from bayesgrasp.shapes import load

# Which printed columns our catalogue reproduces at the printed precision (README says so).
EXPECTED_MATCHES = {
    "triangle": (True, True, True),
    "rectangle": (True, True),
    "ic-chip": (True, True),
    "house": (True, False, True, True),
    "example": (True, True, True),
    "allen-wrench": (True, True, True),
    "tuning-fork": (True, True),
    "key": (True, True, False),
    "hand": (True, True, True),
}


@pytest.fixture(scope="module")
def rows() -> list[Table1Row]:
    return table1_rows()


def test_printed_table_is_self_consistent() -> None:
    """The asterisks as printed agree with the printed numbers (a check of the transcription)."""
    assert [r.sides for r in PAPER_TABLE1] == [3, 4, 5, 5, 5, 6, 6, 11, 13]
    for r in PAPER_TABLE1:
        last = len(r.costs) - 1
        assert r.asterisk == (int(np.argmin(r.costs)) < last), r.part
        # Probabilities implied by the printed costs (k + 1) / p never exceed 1/2 ...
        p = [(k + 2) / c for k, c in enumerate(r.costs)]
        assert max(p) <= 0.5 + 0.5 * 0.05 / min(r.costs), r.part


@pytest.mark.parametrize("name", ["triangle", "rectangle"])
def test_fitted_rows_match_the_printed_numbers(name: str) -> None:
    row = table1_row(name)
    assert row.row_matches
    assert [round(c, 1) for c in row.costs] == list(paper_row(name).costs)


def test_triangle_row_in_closed_form() -> None:
    """Independent: a triangle's basins are its angles; p_1 is the largest over 2 pi.

    The two-squeeze plan collapses the widest arc of two adjacent basins whose stable
    orientations lie closer than the widest basin: here the largest angle with the one
    beside it that makes the larger sum, and three squeezes reach 1/2.
    """
    v = np.asarray(load("triangle").hull.vertices)
    ang = []
    for i in range(3):
        a, b = v[i - 1] - v[i], v[(i + 1) % 3] - v[i]
        ang.append(math.acos(float(a @ b) / float(np.linalg.norm(a) * np.linalg.norm(b))))
    big = sorted(ang)
    p1 = big[2] / (2 * math.pi)
    p2 = (big[2] + big[1]) / (2 * math.pi)
    assert_allclose(table1_row("triangle").costs, [2 / p1, 3 / p2, 4 / 0.5], rtol=1e-9)


def test_rectangle_row_in_closed_form() -> None:
    """Independent: an a x b rectangle's wider basin is 2 atan(a / b); two squeezes reach 1/2."""
    p1 = 2 * math.atan(31 / 20) / (2 * math.pi)
    assert_allclose(table1_row("rectangle").costs, [2 / p1, 3 / 0.5], rtol=1e-12)


def test_costs_are_k_plus_one_over_p(rows: list[Table1Row]) -> None:
    for r in rows:
        k = np.arange(1, len(r.costs) + 1)
        assert_allclose(r.costs, (k + 1) / np.array(r.probabilities), rtol=1e-12)
        # The last plan is the most certain: 1/2, the gripper's 180-degree ambiguity.
        assert r.most_certain == len(r.costs) - 1
        assert_allclose(r.probabilities[-1], 0.5, atol=1e-12)
        assert r.bayes == int(np.argmin(r.costs))


def test_catalogue_rows_against_the_paper(rows: list[Table1Row]) -> None:
    assert [r.part for r in rows] == list(EXPECTED_MATCHES)
    for r in rows:
        assert r.matches == EXPECTED_MATCHES[r.part], (r.part, r.costs)
        assert r.sides == r.paper.sides
        assert r.shorter_plan_better == r.paper.asterisk, r.part
    assert [r.part for r in rows if r.row_matches] == [
        n for n, m in EXPECTED_MATCHES.items() if all(m)
    ]


def test_matches_at_the_printed_precision() -> None:
    paper = PaperRow("x", "x", 4, (6.3, 6.0), False)

    def row(*costs: float) -> Table1Row:
        probs = tuple(2 / c for c in costs)
        return Table1Row("x", 4, costs, probs, int(np.argmin(costs)), len(costs) - 1, paper)

    assert row(6.2501, 6.0).matches == (True, True)
    assert row(6.3499, 5.9501).matches == (True, True)
    assert row(6.2499, 6.0).matches == (False, True)
    assert row(6.3, 6.0, 8.0).matches == (True, True, False)  # a column the paper lacks
    assert row(6.3).matches == (True, False)  # a column we lack
    assert not row(6.3, 6.0, 8.0).row_matches
    assert row(6.3, 6.0).row_matches


def test_paper_row_unknown_part() -> None:
    with pytest.raises(PartError, match=r"Table 1 has no row 'spoon'; expected one of triangle"):
        paper_row("spoon")
    with pytest.raises(PartError, match="no row 'spoon'"):
        table1_rows(["spoon"])


def test_json_form(rows: list[Table1Row]) -> None:
    doc = table1_json(rows)
    assert doc["schema"] == "bayesgrasp.table1/1"
    text = json.dumps(doc, allow_nan=False)
    back = json.loads(text)["rows"]
    assert [r["part"] for r in back] == [r.part for r in PAPER_TABLE1]
    for got, r in zip(back, rows, strict=True):
        assert set(got) == {
            "part",
            "label",
            "sides",
            "paper_sides",
            "expected_costs",
            "success_probabilities",
            "paper_expected_costs",
            "bayes",
            "most_certain",
            "shorter_plan_better",
            "paper_shorter_plan_better",
            "matches",
            "row_matches",
        }
        assert got["expected_costs"] == list(r.costs)
        assert got["paper_expected_costs"] == list(r.paper.costs)
        assert got["matches"] == list(r.matches)
    assert back[4]["label"] == "example (Fig.1)"


def test_text_form(rows: list[Table1Row]) -> None:
    text = table1_text(rows)
    lines = text.splitlines()
    body = {ln.split()[0]: ln for ln in lines[3:-2]}
    assert list(body) == [r.part for r in PAPER_TABLE1]
    assert "10.80 (10.8)" in body["triangle"]
    assert body["house"].count("!") == 1 and "9.30 (9.2)!" in body["house"]
    assert "8.00 (8.2)!" in body["key"]
    assert "!" not in body["hand"]
    assert body["ic-chip"].endswith("*  (*)")
    assert body["hand"].endswith("-  (-)")
    # Columns line up: every row is as long as the header.
    assert len({len(ln) for ln in lines[2:-2]}) == 1


def test_cli_table1(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["table1"]) == 0
    out = capsys.readouterr().out
    assert "The seed's Table 1" in out and "tuning-fork" in out
    assert main(["table1", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["schema"] == "bayesgrasp.table1/1"
    assert len(doc["rows"]) == 9
    assert doc["rows"][0]["expected_costs"][0] == pytest.approx(10.8, abs=0.05)
