"""The guaranteed plan is written in the plan table's notation, in every text output.

The expected text is rebuilt here from the ``--json`` document's steps (radians), not from the
report's own formatting: squeezes only, ``[+a2, +a3, ...]``; with other action kinds, each
step's tag then its turn (``P P+45.00 S+23.49``), the first angle in its own field.
"""

from __future__ import annotations

import json
import math
import re

import pytest

from bayesgrasp.cli import main

TAGS = {"squeeze": "S", "push-grasp": "P"}


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str]:
    code = main(list(args))
    out, _ = capsys.readouterr()
    return code, out


def deg(x: float, spec: str) -> str:
    text = format(math.degrees(x), spec)
    return text.replace("-", "+") if float(text) == 0 else text  # no negative zero


def expected_steps(steps: list[dict[str, object]], mixed: bool) -> str:
    """The table's notation of a plan, from its document's steps."""
    if not mixed:
        turns = [deg(float(s["alpha_rad"]), "+.2f") for s in steps[1:]]  # type: ignore[arg-type]
        return f"[{', '.join(turns)}]" if turns else "-"
    first = TAGS[str(steps[0]["type"])]
    rest = [f"{TAGS[str(s['type'])]}{deg(float(s['alpha_rad']), '+.2f')}" for s in steps[1:]]  # type: ignore[arg-type]
    return " ".join([first, *rest])


CASES = [
    ("house", ()),
    ("rectangle", ()),
    ("key", ()),
    ("house", ("--actions", "squeeze,push-grasp")),
    ("triangle", ("--actions", "squeeze,push-grasp")),
    ("key", ("--actions", "push-grasp")),
]


@pytest.mark.parametrize(("part", "more"), CASES)
def test_guaranteed_line_matches_the_table(
    capsys: pytest.CaptureFixture[str], part: str, more: tuple[str, ...]
) -> None:
    code, out = run(capsys, "plan", part, "--guaranteed", *more, "--json")
    assert code == 0
    doc = json.loads(out)
    sure = doc["guaranteed"]
    mixed = bool(more)
    steps = expected_steps(sure["steps"], mixed)
    code, text = run(capsys, "plan", part, "--guaranteed", *more)
    assert code == 0
    line = next(x for x in text.splitlines() if x.startswith("guaranteed plan:"))
    first = deg(sure["steps"][0]["alpha_rad"], ".2f")
    head = "steps" if mixed else "alphas"
    assert line == (
        f"guaranteed plan: {len(sure['steps'])} action(s), first {first} deg, {head} (deg) {steps}"
    )
    assert "S(" not in text and "P(" not in text.replace("P(success)", "")
    # The table's row of a plan with the same steps writes them the same way.
    rows = [r for r in text.splitlines() if re.match(r"\s+\d+\s", r)]
    same = [
        r
        for r, o in zip(rows, doc["options"], strict=True)
        if [s["type"] for s in o["steps"]] == [s["type"] for s in sure["steps"]]
        and expected_steps(o["steps"], mixed) == steps
    ]
    for row in same:
        assert f"  {steps} " in row + " "


def test_the_notations_agree_where_the_plans_agree(capsys: pytest.CaptureFixture[str]) -> None:
    """house: the guaranteed plan is the table's most certain plan, written alike."""
    for more in ((), ("--actions", "squeeze,push-grasp")):
        _, text = run(capsys, "plan", "house", "--guaranteed", *more)
        lines = text.splitlines()
        certain = next(r for r in lines if re.match(r"\s+\d+\s", r) and r.rstrip().endswith("C"))
        sure = next(x for x in lines if x.startswith("guaranteed plan:"))
        written = sure.partition(" (deg) ")[2]
        assert written and f"  {written} " in certain
