"""The seed's Table 1: its printed numbers, and the same rows computed by the exact planner.

Goldberg and Mason (1990), Table 1, "Expected time for squeezing plans": for each familiar
part, the expected cost of the best plan of 1, 2, 3 and 4 squeezes, each squeeze and the
verification costing one unit, under a uniform prior and a single goal orientation, each
orientation counted as its own state (section 4.5). The last entry of a row is the most
certain plan; an asterisk marks parts where a shorter, less certain plan is cheaper.

With these assumptions the best k-squeeze plan succeeds with probability ``p_k`` and costs
``(k + 1) / p_k``. The seed prints no coordinates, so the catalogue parts
(:mod:`bayesgrasp.shapes`) are our designs; :func:`table1_rows` says, column by column,
whether our row rounds to the printed one.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import PartError
from ..model.problem import Problem
from ..planning import plan_exact
from ..shapes import load

__all__ = [
    "PAPER_TABLE1",
    "PaperRow",
    "Table1Row",
    "paper_row",
    "table1_json",
    "table1_row",
    "table1_rows",
    "table1_text",
]

SCHEMA = "bayesgrasp.table1/1"


@dataclass(frozen=True, slots=True)
class PaperRow:
    """One row of the seed's Table 1, as printed.

    Attributes
    ----------
    part : str
        The catalogue name of the part.
    label : str
        The row's label in the seed.
    sides : int
        The printed number of sides (of the convex hull: the gripper sees the hull).
    costs : tuple of float
        Expected time of the best plan of 1, 2, ... squeezes, to one decimal.
    asterisk : bool
        The seed's mark: a shorter, less certain plan has a lower expected time.
    """

    part: str
    label: str
    sides: int
    costs: tuple[float, ...]
    asterisk: bool

    @property
    def digits(self) -> int:
        """Decimals printed (one for every entry of Table 1)."""
        return 1


#: The seed's Table 1, row by row, exactly as printed.
PAPER_TABLE1: tuple[PaperRow, ...] = (
    PaperRow("triangle", "triangle", 3, (10.8, 8.7, 8.0), False),
    PaperRow("rectangle", "rectangle", 4, (6.3, 6.0), False),
    PaperRow("ic-chip", "ic-chip", 5, (5.0, 6.0), True),
    PaperRow("house", "house", 5, (8.0, 9.2, 9.4, 10.0), True),
    PaperRow("example", "example (Fig.1)", 5, (7.4, 6.2, 8.0), True),
    PaperRow("allen-wrench", "allen-wrench", 6, (9.1, 7.4, 8.0), True),
    PaperRow("tuning-fork", "tuning fork", 6, (4.9, 6.0), True),
    PaperRow("key", "key", 11, (9.1, 6.2, 8.2), True),
    PaperRow("hand", "hand", 13, (8.2, 8.1, 8.0), False),
)


def paper_row(part: str) -> PaperRow:
    """The printed row of a catalogue part.

    Parameters
    ----------
    part : str
        A catalogue name (see :func:`bayesgrasp.shapes.names`).

    Returns
    -------
    PaperRow

    Raises
    ------
    PartError
        If the seed's Table 1 has no row for this part.

    Examples
    --------
    >>> paper_row("house").costs
    (8.0, 9.2, 9.4, 10.0)
    """
    for row in PAPER_TABLE1:
        if row.part == part:
            return row
    raise PartError(
        f"the seed's Table 1 has no row {part!r}; "
        f"expected one of {', '.join(r.part for r in PAPER_TABLE1)}"
    )


@dataclass(frozen=True, slots=True)
class Table1Row:
    """Our row of Table 1 for one part, beside the printed one.

    Attributes
    ----------
    part : str
        Catalogue name.
    sides : int
        Sides of our part's convex hull.
    costs : tuple of float
        Expected cost of the best plan of 1, 2, ... squeezes, up to the most certain plan.
    probabilities : tuple of float
        Their success probabilities.
    bayes : int
        Index of the plan of least expected cost (ties go to fewer squeezes).
    most_certain : int
        Index of the shortest plan of highest success probability.
    paper : PaperRow
        The seed's printed row.
    """

    part: str
    sides: int
    costs: tuple[float, ...]
    probabilities: tuple[float, ...]
    bayes: int
    most_certain: int
    paper: PaperRow

    @property
    def shorter_plan_better(self) -> bool:
        """The seed's asterisk: a shorter, less certain plan costs less than the most certain."""
        return self.bayes < self.most_certain

    @property
    def matches(self) -> tuple[bool, ...]:
        """Per printed column, whether our cost rounds to the printed number.

        A column that one of the two rows lacks does not match.
        """
        half = 0.5 * 10.0 ** (-self.paper.digits)
        n = max(len(self.costs), len(self.paper.costs))
        out = []
        for i in range(n):
            if i < len(self.costs) and i < len(self.paper.costs):
                # A hair of slack: 6.25 printed as 6.2 or 6.3 are both honest roundings.
                out.append(abs(self.costs[i] - self.paper.costs[i]) <= half + 1e-9)
            else:
                out.append(False)
        return tuple(out)

    @property
    def row_matches(self) -> bool:
        """Every column, the side count and the asterisk agree with the printed row."""
        return (
            all(self.matches)
            and self.sides == self.paper.sides
            and self.shorter_plan_better == self.paper.asterisk
        )


def table1_row(part: str) -> Table1Row:
    """Compute our Table 1 row of one catalogue part with the exact planner.

    Uniform prior, every squeeze and the verification cost 1, a single goal orientation (the
    seed's accounting); plans up to the most certain one.

    Parameters
    ----------
    part : str
        A catalogue name that has a row in the seed's Table 1.

    Returns
    -------
    Table1Row

    Raises
    ------
    PartError
        If the seed's Table 1 has no row for this part.

    Examples
    --------
    >>> row = table1_row("rectangle")
    >>> [round(c, 2) for c in row.costs], row.matches, row.shorter_plan_better
    ([6.3, 6.0], (True, True), False)
    """
    paper = paper_row(part)
    p = load(part)
    rep = plan_exact(Problem.build(p))
    return Table1Row(
        part,
        p.hull.n_sides,
        tuple(o.expected_cost for o in rep.options),
        tuple(o.success_probability for o in rep.options),
        rep.bayes,
        rep.most_certain,
        paper,
    )


def table1_rows(parts: Iterable[str] | None = None) -> list[Table1Row]:
    """Our rows of Table 1, in the seed's order (or for the given parts).

    Parameters
    ----------
    parts : iterable of str, optional
        Catalogue names; default every row of the seed's table.

    Returns
    -------
    list of Table1Row

    Examples
    --------
    >>> [r.part for r in table1_rows()][:2]
    ['triangle', 'rectangle']
    """
    names = [r.part for r in PAPER_TABLE1] if parts is None else list(parts)
    return [table1_row(n) for n in names]


def _num(x: float) -> float | None:
    return x if math.isfinite(x) else None


def table1_json(rows: Sequence[Table1Row]) -> dict[str, Any]:
    """The machine form: ``{"schema": "bayesgrasp.table1/1", "rows": [...]}``.

    Each row: ``part``, ``label``, ``sides``, ``paper_sides``, ``expected_costs``,
    ``success_probabilities``, ``paper_expected_costs``, ``bayes`` and ``most_certain``
    (0-based indices into ``expected_costs``), ``shorter_plan_better``,
    ``paper_shorter_plan_better``, ``matches`` (per column, at the printed precision) and
    ``row_matches``.

    Parameters
    ----------
    rows : sequence of Table1Row

    Returns
    -------
    dict

    Examples
    --------
    >>> doc = table1_json(table1_rows(["triangle"]))
    >>> doc["schema"], doc["rows"][0]["paper_expected_costs"]
    ('bayesgrasp.table1/1', [10.8, 8.7, 8.0])
    """
    return {
        "schema": SCHEMA,
        "rows": [
            {
                "part": r.part,
                "label": r.paper.label,
                "sides": r.sides,
                "paper_sides": r.paper.sides,
                "expected_costs": [_num(c) for c in r.costs],
                "success_probabilities": list(r.probabilities),
                "paper_expected_costs": list(r.paper.costs),
                "bayes": r.bayes,
                "most_certain": r.most_certain,
                "shorter_plan_better": r.shorter_plan_better,
                "paper_shorter_plan_better": r.paper.asterisk,
                "matches": list(r.matches),
                "row_matches": r.row_matches,
            }
            for r in rows
        ],
    }


def _mark(agrees: bool) -> str:
    return " " if agrees else "!"


def table1_text(rows: Sequence[Table1Row]) -> str:
    """Table 1 for people: our expected cost of each plan length, the printed one beside it.

    A ``!`` marks a column (or side count) that does not round to the printed number; the
    last column shows our asterisk and, in brackets, the seed's.

    Parameters
    ----------
    rows : sequence of Table1Row

    Returns
    -------
    str

    Examples
    --------
    >>> table1_text(table1_rows(["rectangle"])).splitlines()[3].split()
    ['rectangle', '4', '(4)', '6.30', '(6.3)', '6.00', '(6.0)', '-', '-', '-', '(-)']
    """
    width = max([4, *(max(len(r.costs), len(r.paper.costs)) for r in rows)])
    # Every field ends in a one-character slot for the "!" mark, so columns line up.
    labels = [f"{k} squeeze" + ("s" if k > 1 else "") for k in range(1, width + 1)]
    head = f"{'part':<18} {'sides':>7} " + "".join(f"{x:>14} " for x in labels)
    lines = [
        "The seed's Table 1: expected cost of the best plan of k squeezes, ours (printed);",
        "each squeeze and the verification cost 1, uniform prior, one goal orientation.",
        head + f" {'shorter wins':>12}",
    ]
    for r in rows:
        fields = [
            f"{r.part:<18} {f'{r.sides} ({r.paper.sides})':>7}" + _mark(r.sides == r.paper.sides)
        ]
        for i in range(width):
            ours = f"{r.costs[i]:.2f}" if i < len(r.costs) else "-"
            printed = f"{r.paper.costs[i]:.1f}" if i < len(r.paper.costs) else "-"
            if ours == "-" and printed == "-":
                fields.append(f"{'-':>14} ")
            else:
                fields.append(f"{f'{ours} ({printed})':>14}" + _mark(r.matches[i]))
        star = "*" if r.shorter_plan_better else "-"
        pstar = "*" if r.paper.asterisk else "-"
        same = r.shorter_plan_better == r.paper.asterisk
        fields.append(f" {f'{star}  ({pstar})':>12}" + ("" if same else "!"))
        lines.append("".join(fields))
    lines.append(
        "ours (printed); ! = does not round to the printed number;\n"
        "* = a shorter, less certain plan costs less than the most certain one (the seed's mark)"
    )
    return "\n".join(lines)
