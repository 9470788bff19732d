"""Ties between copies of a plan: broken the same way at every flattening of a curved part.

A transfer function of period ``P`` has copies of every arc shifted by ``P``, equal in
width and span; their computed widths differ in the last bits, and a curved part's change
with the chordal tolerance. The planners take the arcs of one period for curved parts
(``planning.arcs.period_rows``), so the peanut cam (two stable orientations 180 degrees apart,
each with a basin of exactly half a turn) ends at the same orientation at every tolerance.
Independent checks: the front of one period against the whole front (every width and span
again, to rounding), the three front paths against each other, and every plan executed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.geometry.curved import CurvedPart
from bayesgrasp.geometry.polygon import Part
from bayesgrasp.io import read_part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import arcs, plan_exact, plan_guaranteed
from bayesgrasp.planning.arcs import ArcPlanner, arc_front, one_period_arcs, period_rows
from bayesgrasp.planning.result import execute_plan

ROOT = Path(__file__).resolve().parents[2]
PEANUT = ROOT / "examples" / "peanut.svg"
BRACKET = ROOT / "examples" / "bracket.dxf"
TOLERANCES = (2.0, 1.0, 0.5, 0.25, 0.1)
TOL = 1e-9


def summary(part: Part, actions: str, guaranteed: bool = False) -> list[tuple[object, ...]]:
    """Each option's action types, and its gripper angles and final orientation (degrees)."""
    pb = Problem.build(part, actions=actions)
    res = plan_guaranteed(pb) if guaranteed else plan_exact(pb)
    return [
        (
            tuple(s.kind for s in o.steps),
            [math.degrees(s.alpha) for s in o.steps] + [math.degrees(o.final_orientation)],
        )
        for o in res.options
    ]


def assert_same_plans(seen: dict[float, list[tuple[object, ...]]]) -> None:
    """The same plans at every tolerance: angles within 1 degree (the shape moves a little;
    a tie broken the other way moves a plan by a period, 180 degrees)."""
    ref = seen[TOLERANCES[0]]
    for t, plans in seen.items():
        assert [kinds for kinds, _ in plans] == [kinds for kinds, _ in ref], (t, plans, ref)
        for (_, angles), (_, want) in zip(plans, ref, strict=True):
            d = (np.array(angles) - np.array(want) + 180.0) % 360.0 - 180.0
            assert np.all(np.abs(d) < 1.0), (t, plans, ref)


@pytest.mark.parametrize("fused", [True, False])
@pytest.mark.parametrize("actions", ["squeeze", "squeeze,push-grasp"])
def test_peanut_plans_agree_at_every_flattening(
    fused: bool, actions: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(arcs, "FUSED", fused)
    seen = {t: summary(read_part(PEANUT, tolerance=t), actions) for t in TOLERANCES}
    assert_same_plans(seen)
    if actions == "squeeze":  # the Bayes plan: one squeeze into the basin of 84.33 deg
        ((kinds, angles),) = seen[0.5]
        assert kinds == ("squeeze",)
        assert_allclose(angles, [0.0, 84.33], atol=0.01)


@pytest.mark.parametrize("path", [PEANUT, BRACKET])
def test_guaranteed_plans_agree_at_every_flattening(path: Path) -> None:
    seen = {t: summary(read_part(path, tolerance=t), "squeeze", True) for t in TOLERANCES}
    assert_same_plans(seen)


@pytest.mark.parametrize("t", TOLERANCES)
def test_peanut_plans_reach_their_final_orientation(t: float) -> None:
    """Every plan, executed from sampled orientations of its success arc, ends where it says."""
    pb = Problem.build(read_part(PEANUT, tolerance=t), actions="squeeze,push-grasp")
    rng = np.random.default_rng(7)
    for o in plan_exact(pb).options:
        a, b = o.success_arc
        starts = a + (b - a) * rng.uniform(0.01, 0.99, 50)
        finals = execute_plan(pb, o.steps, starts)
        d = (finals - o.final_orientation + math.pi) % (2 * math.pi) - math.pi
        assert_allclose(d, 0.0, atol=1e-6)


def test_one_period_only_for_curved_parts() -> None:
    rect = Part.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
    assert not ArcPlanner.for_problem(Problem.build(rect)).one_period
    peanut = read_part(PEANUT)
    assert isinstance(peanut, CurvedPart)
    assert one_period_arcs(Problem.build(peanut))


def test_period_rows_of_a_symmetric_part_and_a_state_at_zero() -> None:
    square = Problem.build(Part.from_points([(0, 0), (1, 0), (1, 1), (0, 1)]))
    f = square.transfers["squeeze"]  # states 0, 90, 180, 270 deg; period 90 deg
    assert period_rows(f, TOL) == [0]
    # A state at 0 computed as 2 pi less a rounding is still the first of its period.
    st, lo, hi = (np.array(x) for x in f.values)
    st[0] = math.nextafter(0.0, -1.0) % (2 * math.pi)
    order = np.argsort(st)
    g = type(f)("squeeze", st[order], lo[order], hi[order], f.period, f.angle_tol)
    assert [float(g.stable[i]) for i in period_rows(g, TOL) or []] == [float(st[0])]
    push = Problem.build(Part.from_points([(0, 0), (3, 0), (0, 1)]), actions="push-grasp")
    assert period_rows(push.transfers["push-grasp"], TOL) is None  # period 2 pi: every row


def test_front_of_one_period_has_every_width_and_span() -> None:
    """Each front arc of the whole circle has a copy of equal width and span in one period."""
    rng = np.random.default_rng(3)
    for t in TOLERANCES:
        f = Problem.build(read_part(PEANUT, tolerance=t)).transfers["squeeze"]
        parts = [f] + [
            Problem.build(Part.from_points(rng.random((9, 2)))).transfers["squeeze"]
            for _ in range(10)
        ]
        for g in parts:
            rows = period_rows(g, TOL)
            assert rows is not None
            whole, one = arc_front(g, 2 * math.pi), arc_front(g, 2 * math.pi, rows=rows)
            # Each front's arcs are matched by the other's to rounding: one at least as wide
            # (less 1e-12) whose image spans no more (plus 1e-12).
            for a, b in ((whole, one), (one, whole)):
                for x, w in zip(a.span_list, a.width_list, strict=True):
                    assert any(
                        y <= x + 1e-12 and v >= w - 1e-12
                        for y, v in zip(b.span_list, b.width_list, strict=True)
                    ), (x, w)
            starts = {float(g.stable[i]) for i in rows}
            assert set(one.s_first_list) <= starts


def test_front_paths_agree_on_one_period() -> None:
    """The plain-list front, the chunked numpy front and the pruned front, bit for bit."""
    rng = np.random.default_rng(11)
    angles = np.sort(rng.uniform(0, 2 * math.pi, 300))
    radii = 1.0 + 0.05 * rng.random(300)
    part = Part.from_points(np.c_[radii * np.cos(angles), radii * np.sin(angles)])
    f = Problem.build(part).transfers["squeeze"]
    rows = period_rows(f, TOL)
    assert rows is not None and len(rows) == f.n_states // 2
    fronts = [
        arcs._arc_front_python(f, 2.0, rows),  # the plain-list path
        arc_front(f, 2.0, prune=False, rows=rows, chunk=1000),
        arc_front(f, 2.0, prune=True, rows=rows),
    ]
    ref = fronts[0]
    for other in fronts[1:]:
        assert other.span_list == ref.span_list
        assert other.width_list == ref.width_list
        assert other.lo_list == ref.lo_list
        assert other.s_first_list == ref.s_first_list
