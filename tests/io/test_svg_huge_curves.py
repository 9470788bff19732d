"""Curved parts at the edge of the coordinate range: one clean line, or the same plans.

Outlines may reach 1e150 (the readers' limit); their areas and moments (cubes of
coordinates) are computed at unit size. A circle of radius 1e150 is refused in one line on
stderr (its sampled arcs pass the limit), with no numpy warning on the way; smaller ones
are planned, and a part scaled by 1e140 (or 1e-140) has the same plans as at unit size.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main
from bayesgrasp.geometry.curved import CurvedRing, curved_part
from bayesgrasp.model.problem import Problem
from bayesgrasp.planning import plan_exact

ROOT = Path(__file__).resolve().parents[2]


def svg(body: str) -> str:
    return f'<svg xmlns="http://www.w3.org/2000/svg">{body}</svg>'


def dxf_circle(r: str) -> str:
    pairs = [(0, "SECTION"), (2, "ENTITIES"), (0, "CIRCLE"), (8, "0"), (10, 0), (20, 0)]
    pairs += [(30, 0), (40, r), (0, "ENDSEC"), (0, "EOF")]
    return "".join(f"{code}\n{value}\n" for code, value in pairs)


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    """The real command, as a user runs it (numpy's warnings are printed, not raised)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    env.pop("PYTHONWARNINGS", None)
    code = "import sys; from bayesgrasp.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, check=False
    )


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("circle.svg", svg('<circle cx="0" cy="0" r="1e150"/>')),
        ("circle.dxf", dxf_circle("1e150")),
    ],
)
def test_circle_of_radius_1e150_is_one_line(tmp_path: Path, name: str, text: str) -> None:
    f = tmp_path / name
    f.write_text(text, encoding="utf-8")
    done = run_cli("plan", str(f))
    assert done.returncode == 2
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith(f"bayesgrasp: error: {f}: `outline` reaches 1.0000000000000002e+150")
    assert "Warning" not in done.stderr


def test_circle_of_radius_1e149_says_it_is_a_disc(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "disc.svg"
    f.write_text(svg('<circle cx="0" cy="0" r="1e149"/>'), encoding="utf-8")
    assert main(["plan", str(f)]) == 2  # in-process: a numpy warning would raise here
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1
    assert "has no stable orientation" in err and "2e+149" in err


@pytest.mark.parametrize("scale", [1e-140, 1e140])
def test_scaled_curved_part_plans_as_at_unit_size(scale: float) -> None:
    """The same probabilities, angles and (scaled) centre of mass as the unit-size part."""
    pts = np.array([(0.0, 0.0), (3.0, 0.0), (3.0, 2.0), (0.0, 2.0)])
    bulges = [0.0, 1.0, 0.0, 0.0]  # a rectangle with a half circle on one side
    plans = []
    coms = []
    for s in (1.0, scale):
        part = curved_part(CurvedRing(pts * s, bulges), name="slot")
        coms.append(np.asarray(part.center_of_mass) / s)
        res = plan_exact(Problem.build(part))
        plans.append(
            [
                (o.success_probability, [st.alpha for st in o.steps], o.final_orientation)
                for o in res.options
            ]
        )
    assert_allclose(coms[1], coms[0], rtol=1e-12)
    assert len(plans[0]) == len(plans[1])
    for (p0, a0, f0), (p1, a1, f1) in zip(*plans, strict=True):
        assert_allclose(p1, p0, rtol=1e-9)
        assert_allclose(a1, a0, atol=1e-9)
        assert_allclose(f1, f0, atol=1e-9)


@pytest.mark.parametrize("scale", [1e-150, 1e-100, 1.0, 1e100, 1e149])
def test_area_and_centroid_at_every_scale(scale: float) -> None:
    """Against the shoelace formula on the arcs sampled densely (at unit size)."""
    pts = np.array([(0.0, 0.0), (3.0, 0.0), (3.0, 2.0), (0.0, 2.0)])
    bulges = np.array([0.0, math.tan(math.pi / 4), 0.0, -0.2])  # a half circle, a dent
    ring = CurvedRing(pts * scale + 0.5 * scale, bulges)
    area, centroid = ring.area_centroid()
    dense = CurvedRing(pts, bulges).flattened(1e-7)
    x, y = dense[:, 0], dense[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    a = 0.5 * cross.sum()
    c = np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * a)
    assert math.isfinite(area) and np.all(np.isfinite(centroid))
    assert_allclose(area / scale**2, a, rtol=1e-6)
    assert_allclose(centroid / scale - 0.5, c, atol=1e-6)


@pytest.mark.parametrize("size", ["1e78", "2e149"])
def test_a_path_arc_too_large_to_compute_says_so(tmp_path: Path, size: str) -> None:
    """svgelements squares an arc's radii for its centre: past about 1e77 that overflows."""
    f = tmp_path / "arc.svg"
    d = f"M 0 0 A {size} {size} 0 0 1 {size} 0 L {size} {size} Z"
    f.write_text(svg(f'<path d="{d}"/>'), encoding="utf-8")
    done = run_cli("plan", str(f))
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.splitlines() == [
        f"bayesgrasp: error: {f}: <path> number 0 has an arc too large to compute: its centre "
        "overflows floating point (coordinates or radii beyond about 1e77); scale the drawing down"
    ]


def test_a_path_arc_of_1e77_plans_as_at_unit_size(tmp_path: Path) -> None:
    rows = []
    for size in ("1", "1e77"):
        f = tmp_path / f"arc{size}.svg"
        d = f"M 0 0 A {size} {size} 0 0 1 {size} 0 L {size} {size} Z"
        f.write_text(svg(f'<path d="{d}"/>'), encoding="utf-8")
        done = run_cli("plan", str(f), "--json")
        assert done.returncode == 0, done.stderr
        import json

        doc = json.loads(done.stdout)
        rows.append([o["success_probability"] for o in doc["options"]])
    assert_allclose(rows[0], rows[1], atol=1e-9)
