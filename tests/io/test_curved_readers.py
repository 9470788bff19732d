"""The readers keep circular arcs exact; other curves converge as the tolerance shrinks.

Independent checks: closed forms for slots, discs and ellipses drawn in DXF and SVG, and the
convergence of states, probabilities and plan costs of random Bezier outlines as the
flattening tolerance goes from 1e-2 to 1e-6 of their size (issue 16).
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.errors import PlanningError
from bayesgrasp.geometry import Part
from bayesgrasp.geometry.curved import CurvedPart, squeeze_model
from bayesgrasp.io import read_part_bytes
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")


def dxf_bytes(build) -> bytes:  # type: ignore[no-untyped-def]
    doc = ezdxf.new("R2010", units=4)
    build(doc.modelspace())
    text = io.StringIO()
    doc.write(text)
    return text.getvalue().encode()


def test_dxf_bulged_slot_is_exact() -> None:
    data = dxf_bytes(
        lambda m: m.add_lwpolyline(
            [(0, -5, 0), (40, -5, 1), (40, 5, 0), (0, 5, 1)], format="xyb", close=True
        )
    )
    part = read_part_bytes(data, "dxf", "slot.dxf")
    assert isinstance(part, CurvedPart) and part.curve_error == 0.0
    _, s = squeeze_model(part)
    assert_allclose(np.degrees(s.stable), [90.0, 270.0], atol=1e-9)
    assert_allclose(part.center_of_mass, [20.0, 0.0], atol=1e-9)
    assert_allclose(part.diameter_function([0.0, math.pi / 2]), [50.0, 10.0], rtol=1e-12)


def test_dxf_loop_of_lines_and_arcs_equals_the_bulged_slot() -> None:
    def build(m):  # type: ignore[no-untyped-def]
        m.add_line((0, -5), (40, -5))
        m.add_arc((40, 0), 5, -90, 90)
        m.add_line((40, 5), (0, 5))
        m.add_arc((0, 0), 5, 90, 270)

    part = read_part_bytes(dxf_bytes(build), "dxf", "slot.dxf")
    assert isinstance(part, CurvedPart)
    _, s = squeeze_model(part)
    assert_allclose(np.degrees(s.stable), [90.0, 270.0], atol=1e-9)


def test_dxf_circle_is_a_disc_and_plans_are_refused() -> None:
    part = read_part_bytes(dxf_bytes(lambda m: m.add_circle((3, 4), 10)), "dxf", "disc.dxf")
    assert isinstance(part, CurvedPart)
    assert_allclose(part.center_of_mass, [3.0, 4.0], atol=1e-9)
    with pytest.raises(PlanningError, match="no stable orientation"):
        Problem.build(part)


def test_cli_refuses_to_plan_a_disc(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    f = tmp_path / "disc.dxf"
    f.write_bytes(dxf_bytes(lambda m: m.add_circle((0, 0), 10)))
    for cmd in ("plan", "squeeze"):
        code = main([cmd, str(f)])
        out, err = capsys.readouterr()
        assert code == 2, out + err
        assert "no stable orientation" in err and "Traceback" not in err
        assert len(err.strip().splitlines()) == 1


def test_dxf_polygon_stays_a_polygon() -> None:
    data = dxf_bytes(lambda m: m.add_lwpolyline([(0, 0), (4, 0), (4, 1), (0, 1)], close=True))
    part = read_part_bytes(data, "dxf", "plate.dxf")
    assert type(part) is Part


def test_dxf_ellipse_minimum_at_the_minor_axis() -> None:
    data = dxf_bytes(lambda m: m.add_ellipse((0, 0), major_axis=(20, 0), ratio=0.5))
    part = read_part_bytes(data, "dxf", "ellipse.dxf")
    assert isinstance(part, CurvedPart) and part.curve_error > 0
    d = part.diameter_function
    # The minor axis (along y) is across the jaws when the part is at 90 degrees.
    assert_allclose(d.minima, [math.pi / 2], atol=1e-7)
    (top,) = d.maxima
    assert abs(math.remainder(top, math.pi)) < 1e-7


def test_svg_circle_and_arcs_are_exact_under_the_y_flip() -> None:
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">'
        '<path d="M 10 40 L 50 40 A 10 10 0 0 1 50 60 L 10 60 A 10 10 0 0 1 10 40 Z"/></svg>'
    )
    part = read_part_bytes(svg.encode(), "svg", "slot.svg")
    assert isinstance(part, CurvedPart) and part.curve_error == 0.0
    assert part.ring is not None and part.ring.n_arcs >= 2
    _, s = squeeze_model(part)
    assert_allclose(np.degrees(s.stable), [90.0, 270.0], atol=1e-9)
    assert_allclose(part.center_of_mass, [30.0, -50.0], atol=1e-9)  # y negated
    assert_allclose(part.diameter_function(0.0), 60.0, rtol=1e-12)


def catmull_rom_svg(rng: np.random.Generator, n: int = 6) -> str:
    """A smooth closed outline of n cubic Bezier curves through random points."""
    t = 2 * math.pi * (np.arange(n) + rng.uniform(-0.25, 0.25, n)) / n
    r = rng.uniform(35, 50, n)
    p = np.column_stack([50 + r * np.cos(t), 50 + r * np.sin(t)])
    d = [f"M {p[0, 0]:.6f} {p[0, 1]:.6f}"]
    for i in range(n):
        p0, p1, p2, p3 = p[i - 1], p[i], p[(i + 1) % n], p[(i + 2) % n]
        c1, c2 = p1 + (p2 - p0) / 6, p2 - (p3 - p1) / 6
        d.append(f"C {c1[0]:.6f} {c1[1]:.6f} {c2[0]:.6f} {c2[1]:.6f} {p2[0]:.6f} {p2[1]:.6f}")
    head = '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">'
    return f'{head}<path d="{" ".join(d)} Z"/></svg>'


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_states_and_costs_converge_as_the_flattening_tolerance_shrinks(seed: int) -> None:
    svg = catmull_rom_svg(np.random.default_rng(seed)).encode()
    size = 100.0
    results = []
    for rel in (1e-2, 1e-3, 1e-4, 1e-5, 1e-6):
        part = read_part_bytes(svg, "svg", "blob.svg", tolerance=rel * size)
        pb = Problem.build(part)
        report = plan_exact(pb)
        results.append(
            (pb.states.stable, pb.state_distribution(), report.options[-1].expected_cost)
        )
        # No state has a basin narrower than the error bound could shift it.
        assert np.all(pb.states.widths > 1e-6)
    stable, probs, cost = results[-1]
    for s, p, c in results[1:-1]:
        assert len(s) == len(stable)
        assert_allclose(s, stable, atol=1e-6)
        assert_allclose(p, probs, atol=1e-6)
        assert_allclose(c, cost, rtol=1e-6)


def test_exact_arcs_are_the_limit_of_ever_finer_flattenings() -> None:
    # The bracket's arcs flattened at 1e-4 .. 1e-6 of its size (every chord marked as such,
    # with its error bound): the same states (flush edges: exact), and probabilities that
    # approach the exact ones as the chords' angle, about the square root of the tolerance.
    from pathlib import Path

    from bayesgrasp.geometry.curved import CurvedRing, curved_part
    from bayesgrasp.io import read_part

    part = read_part(Path(__file__).resolve().parents[2] / "examples" / "bracket.dxf")
    assert isinstance(part, CurvedPart) and part.ring is not None
    _, exact = squeeze_model(part)
    probs = Problem.build(part).state_distribution()
    size = part.curved_hull.size
    for rel in (1e-4, 1e-5, 1e-6):
        pts = part.ring.flattened(rel * size)
        ring = CurvedRing(pts, np.zeros(len(pts)), np.ones(len(pts), dtype=bool))
        flat = curved_part(ring, curve_error=rel * size)
        _, s = squeeze_model(flat)
        assert_allclose(s.stable, exact.stable, atol=1e-12)
        gap = np.abs(Problem.build(flat).state_distribution() - probs).max()
        assert gap <= 0.3 * math.sqrt(rel)


SHALLOW_EDGE_SVG = (
    b'<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200">'
    b'<path transform="scale(2)" d="M 0 0 L 40 0 C 50 10 45 30 30 35 L 0 25 Z"/></svg>'
)


def _true_minima(svg: bytes, samples: int = 72_000) -> list[float]:
    """Minima (deg, over [0, 180)) of the diameter of a finely flattened outline, sampled.

    A minimum is a sample lowest within half a degree either side: the flattened chords'
    own kinks (tiny minima next to the maxima, hundredths of a degree wide) are not.
    """
    from scipy.ndimage import minimum_filter1d

    pts = read_part_bytes(svg, "svg", tolerance=1e-4).hull.vertices
    th = np.linspace(0.0, np.pi, samples, endpoint=False)
    d = np.ptp(pts[:, 0, None] * np.cos(th) - pts[:, 1, None] * np.sin(th), axis=0)
    low = minimum_filter1d(d, size=2 * samples // 360 + 1, mode="wrap")
    return sorted(float(np.degrees(t)) for t in th[d == low])


def test_a_shallow_minimum_on_a_straight_edge_survives_the_default_flattening() -> None:
    # The edge (0, 50)-(60, 70) is exact; the opposite contact is on the cubic. Its minimum
    # (0.069 px deep) is shallower than 4x the default flattening bound, but flattening
    # cannot remove it: every tolerance gives the true curve's six states.
    truth = _true_minima(SHALLOW_EDGE_SVG)
    assert len(truth) == 3 and abs(truth[2] - 108.435) < 0.01
    for tol in (None, 0.5, 0.01, 0.001):
        opts = {} if tol is None else {"tolerance": tol}
        part = read_part_bytes(SHALLOW_EDGE_SVG, "svg", **opts)
        d, _ = squeeze_model(part)
        states = np.degrees(d.minima)
        assert_allclose(np.sort(states), truth, atol=0.01)
        p1 = plan_exact(Problem.build(part), max_actions=1).options[0].success_probability
        assert p1 == pytest.approx(0.2066, abs=5e-5)


def test_a_shape_tolerance_still_removes_the_shallow_edge_minimum() -> None:
    part = read_part_bytes(SHALLOW_EDGE_SVG, "svg")
    d, _ = squeeze_model(part)
    assert d.minima.size == 3
    from bayesgrasp.geometry.curved import with_shape_tol

    loose, _ = squeeze_model(with_shape_tol(part, 0.05))  # 4 x 0.05 > 0.069 px deep
    assert loose.minima.size == 2
