"""Length units: a fixed list of names, conversion between them, no silent mixing.

Independent checks: the widths a gripper reads scale by the conversion factor while every
angle stays; a recognition policy of parts given in inches equals the one of the same parts
given in millimetres.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from bayesgrasp import Part, Problem, shapes
from bayesgrasp.cli import main
from bayesgrasp.errors import PartError, PlanningError
from bayesgrasp.planning.policy import plan_policy
from bayesgrasp.units import LENGTHS, PRIMARY, convert, factor, unit_name

RECT = [(0, 0), (31, 0), (31, 20), (0, 20)]


@pytest.mark.parametrize(
    ("given_name", "name"),
    [("mm", "mm"), ("MM", "mm"), (" Inches ", "in"), ("µm", "um"), ("metres", "m"),
     ("feet", "ft"), ("mil", "mil"), ("US ft", "US ft"), ("px", "px"), (None, None)],
)  # fmt: skip
def test_names(given_name: str | None, name: str | None) -> None:
    assert unit_name(given_name) == name


@pytest.mark.parametrize("bad", ["furlong", "", "mmm", 5, ["mm"]])
def test_unknown_names_are_refused(bad: object) -> None:
    with pytest.raises(PartError, match="units"):
        unit_name(bad)
    if isinstance(bad, str):
        with pytest.raises(PartError, match="unknown units"):
            Part.from_points(RECT, units=bad)


def test_every_dxf_unit_and_the_primary_ones_are_known() -> None:
    from bayesgrasp.io.dxf import INSUNITS

    assert all(unit_name(u) in LENGTHS for u in INSUNITS.values())
    assert set(PRIMARY) <= set(LENGTHS)


@given(st.sampled_from(sorted(LENGTHS)), st.sampled_from(sorted(LENGTHS)), st.sampled_from(PRIMARY))
def test_factors_compose(a: str, b: str, c: str) -> None:
    assert factor(a, b) * factor(b, c) == pytest.approx(factor(a, c), rel=1e-12)
    assert factor(a, b) * factor(b, a) == pytest.approx(1.0, rel=1e-12)


def test_known_factors() -> None:
    assert factor("in", "mm") == pytest.approx(25.4)
    assert factor("ft", "in") == pytest.approx(12.0)
    assert factor("m", "um") == pytest.approx(1e6)
    assert factor("px", "in") == pytest.approx(1 / 96)


@given(st.sampled_from(PRIMARY), st.sampled_from(PRIMARY))
def test_conversion_scales_widths_and_keeps_angles(src: str, dst: str) -> None:
    part = shapes.load("house")
    part = Part.from_points(part.outline, "house", part.center_of_mass, src)
    moved = convert(part, dst)
    f = factor(src, dst)
    assert moved.units == dst
    np.testing.assert_allclose(moved.center_of_mass, part.center_of_mass * f, rtol=1e-12)
    a, b = Problem.build(part), Problem.build(moved)
    np.testing.assert_allclose(b.widths, a.widths * f, rtol=1e-9)
    np.testing.assert_allclose(b.states.stable, a.states.stable, atol=1e-9)


def test_conversion_keeps_holes() -> None:
    outer = [(0, 0), (4, 0), (4, 4), (0, 4)]
    hole = [(1, 1), (1, 2), (2, 2), (2, 1)]
    part = Part.from_outline(outer, [hole], "plate", units="in")
    moved = convert(part, "mm")
    assert len(moved.holes) == 1
    np.testing.assert_allclose(moved.center_of_mass, part.center_of_mass * 25.4)


def test_conversion_refuses_what_it_cannot_mean() -> None:
    with pytest.raises(PartError, match="has no units"):
        convert(Part.from_points(RECT), "mm")
    from bayesgrasp.geometry.curved import CurvedRing, curved_part

    slot = curved_part(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)], [0, 1, 0, 1]), units="in")
    with pytest.raises(PartError, match="curved"):
        convert(slot, "mm")


def test_recognition_never_mixes_units_silently() -> None:
    mm = Problem.build(Part.from_points(RECT, "mm-part", units="mm"))
    bare = Problem.build(Part.from_points([(0, 0), (40, 0), (10, 30)], "bare"))
    inch = Problem.build(Part.from_points([(0, 0), (2, 0), (1, 1)], "inch", units="in"))
    with pytest.raises(PlanningError, match="'bare' has no units"):
        plan_policy([mm, bare], "width", 2)
    with pytest.raises(PlanningError, match="convert them to one"):
        plan_policy([mm, inch], "width", 2)
    plan_policy([Problem.build(Part.from_points(RECT)), bare], "width", 2)  # none: fine


def test_the_command_line_converts_candidates_to_parts_units(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inch = tmp_path / "plate_in.json"
    mm = tmp_path / "plate_mm.json"
    inch.write_text(json.dumps({"name": "P", "vertices": [[x / 25.4, y / 25.4] for x, y in RECT],
                                "units": "in"}))  # fmt: skip
    mm.write_text(json.dumps({"name": "P", "vertices": RECT, "units": "mm"}))
    outs = []
    for f in (inch, mm):
        assert main(["plan", "house", str(f), "--sense", "width", "--json"]) == 0
        doc = json.loads(capsys.readouterr().out)
        outs.append(round(doc["expected_cost"], 9))
    assert outs[0] == outs[1] and math.isfinite(outs[0])
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps({"vertices": RECT}))
    assert main(["plan", "house", str(bare), "--sense", "width"]) == 2
    err = capsys.readouterr().err
    assert "has no units" in err and len(err.strip().splitlines()) == 1


def test_a_part_file_with_unknown_units_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "fur.json"
    f.write_text(json.dumps({"vertices": RECT, "units": "furlong"}))
    assert main(["plan", str(f)]) == 2
    err = capsys.readouterr().err
    assert "unknown units 'furlong'" in err and len(err.strip().splitlines()) == 1
