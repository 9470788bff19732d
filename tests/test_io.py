"""Part readers (bayesgrasp.io) and Part.from_outline.

Geometry is checked against independent constructions: shapely buffers and centroids,
closed-form circles and ellipses, Bezier curves evaluated here in Bernstein form, and a
brute-force segment-intersection test.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from shapely.geometry import LineString, Point, Polygon

from bayesgrasp.cli import main
from bayesgrasp.errors import MissingExtraError, PartError, PartFileError
from bayesgrasp.geometry.polygon import Part, find_crossing
from bayesgrasp.io import MAX_POINTS, read_part, resolve_part

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


# ---------------------------------------------------------------- helpers


def ring_distance(points: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Distance from each point to a closed polyline (shapely, independent of the reader)."""
    line = shapely.LinearRing(ring)
    return np.asarray(shapely.distance(shapely.points(points), line))


def boundary_distance(points: np.ndarray, geom: object) -> np.ndarray:
    return np.asarray(shapely.distance(shapely.points(points), shapely.boundary(geom)))


def bernstein(ctrl: np.ndarray, n: int = 4001) -> np.ndarray:
    """Dense points of a Bezier curve (its own evaluation, not the reader's)."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    d = len(ctrl) - 1
    return sum(math.comb(d, k) * t**k * (1 - t) ** (d - k) * ctrl[k] for k in range(d + 1))


def write(tmp_path: Path, name: str, text: str) -> Path:
    f = tmp_path / name
    f.write_text(text, encoding="utf-8")
    return f


def svg(body: str, attrs: str = "") -> str:
    return f'<svg xmlns="http://www.w3.org/2000/svg" {attrs}>{body}</svg>'


def new_dxf(units: int = 4) -> tuple[ezdxf.document.Drawing, object]:
    doc = ezdxf.new("R2010", units=units)
    return doc, doc.modelspace()


def save(doc: ezdxf.document.Drawing, tmp_path: Path, name: str = "part.dxf") -> Path:
    f = tmp_path / name
    doc.saveas(f)
    return f


def cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


# ---------------------------------------------------------------- Part.from_outline

L_SHAPE = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]


def test_from_outline_uses_area_centroid_not_hull() -> None:
    p = Part.from_outline(L_SHAPE, name="L", units="mm")
    assert_allclose(p.center_of_mass, [5 / 6, 5 / 6], atol=1e-12)
    assert_allclose(p.hull.centroid, Polygon(p.hull.vertices).centroid.coords[0], atol=1e-12)
    assert not np.allclose(p.center_of_mass, p.hull.centroid)
    assert p.hull.n_sides == 5 and p.units == "mm" and p.holes == ()


def test_from_outline_is_invariant_to_direction_start_and_closing_vertex() -> None:
    ref = Part.from_outline(L_SHAPE)
    for ring in (L_SHAPE[::-1], L_SHAPE[3:] + L_SHAPE[:3], [*L_SHAPE, L_SHAPE[0]]):
        p = Part.from_outline(ring)
        assert_allclose(p.center_of_mass, ref.center_of_mass, atol=1e-12)
        assert_allclose(p.hull.vertices, ref.hull.vertices, atol=1e-12)
        assert Polygon(p.outline).exterior.is_ccw


def test_from_outline_centroid_matches_shapely_with_holes(rng: np.random.Generator) -> None:
    for _ in range(25):
        n = int(rng.integers(6, 40))
        # Star-shaped about c with angular gaps < pi / 2 and radii >= 2: every chord stays
        # farther than 2 cos(pi / 4) > 1.4 from c, so a hole of radius 0.8 about c fits.
        ang = 2 * np.pi * (np.arange(n) + rng.uniform(0, 0.5, n)) / n
        rad = rng.uniform(2.0, 5.0, n)
        c = rng.normal(0, 10, 2)
        outer = c + np.c_[rad * np.cos(ang), rad * np.sin(ang)]
        t = np.linspace(0, 2 * np.pi, 9, endpoint=False)
        hole = c + 0.8 * np.c_[np.cos(t), np.sin(t)]
        p = Part.from_outline(outer, [hole])
        exact = Polygon(outer, [hole])
        assert_allclose(p.center_of_mass, exact.centroid.coords[0], atol=1e-9)
        assert_allclose(Polygon(p.hull.vertices).area, exact.convex_hull.area, rtol=1e-12)


@pytest.mark.parametrize(
    ("outline", "holes", "match"),
    [
        ([(0, 0), (1, 1), (1, 0), (0, 1)], [], "crosses itself near"),
        ([(0, 0), (2, 0), (1, 1), (2, 2), (0, 2), (1, 1)], [], "crosses itself"),
        ([(0, 0), (2, 0), (3, 0), (1, 0), (1, 1)], [], "folds back on itself"),
        ([(0, 0), (4, 0), (4, 4), (0, 4)], [[(5, 5), (6, 5), (6, 6)]], "must lie inside"),
        ([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (5, 1), (1, 2)]], r"crosses `holes\[0\]`"),
        (
            [(0, 0), (9, 0), (9, 9), (0, 9)],
            [[(1, 1), (8, 1), (8, 8), (1, 8)], [(2, 2), (3, 2), (3, 3)]],
            "holes cannot nest",
        ),
        ([(0, 0), (1, 0), (math.nan, 1)], [], "must be finite"),
        ([(0, 0), (1, 0), (1, 0)], [], "at least 3 distinct vertices"),
        ([(0, 0), (1, 0), (2, 0)], [], "folds back|non-zero area"),
    ],
)
def test_from_outline_rejects_bad_outlines(outline: list, holes: list, match: str) -> None:
    with pytest.raises(PartError, match=match):
        Part.from_outline(outline, holes)


def brute_crossing(ring: np.ndarray) -> bool:
    """O(n^2) reference: any two non-adjacent edges that share a point."""
    n = len(ring)

    def orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float(np.sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])))

    def on(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> bool:
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(
            a[1], b[1]
        )

    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue
            p, q, r, s = ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]
            o1, o2, o3, o4 = orient(p, q, r), orient(p, q, s), orient(r, s, p), orient(r, s, q)
            if o1 * o2 < 0 and o3 * o4 < 0:
                return True
            if (
                (o1 == 0 and on(p, q, r))
                or (o2 == 0 and on(p, q, s))
                or (o3 == 0 and on(r, s, p))
                or (o4 == 0 and on(r, s, q))
            ):
                return True
    return False


@given(st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4)), min_size=3, max_size=10))
def test_find_crossing_agrees_with_brute_force(pts: list[tuple[int, int]]) -> None:
    ring = np.array(pts, dtype=np.float64)
    ring = ring[~np.all(ring == np.roll(ring, -1, axis=0), axis=1)]
    if len(ring) < 3:
        return
    assert (find_crossing([ring]) is not None) == brute_crossing(ring)


def test_find_crossing_on_a_large_simple_outline_and_one_flaw() -> None:
    t = np.linspace(0, 2 * np.pi, 50_000, endpoint=False)
    r = 1 + 0.3 * np.cos(7 * t)
    ring = np.c_[r * np.cos(t), r * np.sin(t)]
    assert find_crossing([ring]) is None
    flawed = ring.copy()
    flawed[100] = [-1.5, 0.0]  # a spike across the middle and out through the far side
    assert find_crossing([flawed]) is not None


# ---------------------------------------------------------------- JSON and CSV (as before)


def test_json_and_csv_readers_keep_their_behaviour(tmp_path: Path) -> None:
    j = write(tmp_path, "w.json", '{"name": "w", "vertices": [[0,0],[3,0],[0,1]], "units": "in"}')
    p = read_part(j)
    assert (p.name, p.units, p.hull.n_sides) == ("w", "in", 3)
    assert_allclose(p.center_of_mass, [1.0, 1 / 3], atol=1e-12)
    c = write(tmp_path, "sq.csv", "x,y\n0,0\n1,0\n1,1\n0,1\n0.5,0.5\n")
    assert read_part(c).hull.n_sides == 4
    assert resolve_part("rectangle").hull.n_sides == 4


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("a.json", "", "the file is empty"),
        ("a.json", '{"vertices": [[0, 0], [1, 0]', "not valid JSON"),
        ("a.json", '{"points": []}', "expected an object"),
        ("a.json", '{"vertices": [[0, 0], [1, NaN], [0, 1]]}', "must be finite"),
        ("a.csv", "0,0\n1,nan\n0,1\n", "not finite"),
        ("a.csv", "0,0\n1\n0,1\n", "row 2 has 1 fields"),
        ("a.xyz", "0,0", "unknown part format 'xyz'"),
    ],
)
def test_point_list_errors_name_the_file(tmp_path: Path, name: str, text: str, match: str) -> None:
    f = write(tmp_path, name, text)
    with pytest.raises(PartFileError, match=match) as info:
        read_part(f)
    assert str(info.value).startswith(str(f))


def test_point_limit_applies_to_point_lists(tmp_path: Path) -> None:
    f = write(tmp_path, "many.csv", "\n".join(f"{i},{i * i % 7}" for i in range(40)))
    with pytest.raises(PartFileError, match="40 points; the limit is 10"):
        read_part(f, max_points=10)


def test_missing_file_and_bad_arguments(tmp_path: Path) -> None:
    with pytest.raises(PartFileError, match="no such file"):
        read_part(tmp_path / "nothing.dxf")
    with pytest.raises(PartFileError, match="`max_points` must be an integer >= 3"):
        read_part(tmp_path / "x.json", max_points=2)
    with pytest.raises(PartFileError, match="neither a catalogue part"):
        resolve_part("no-such-part")


# ---------------------------------------------------------------- WKT


def test_wkt_polygon_with_hole(tmp_path: Path) -> None:
    text = "POLYGON ((0 0, 10 0, 10 4, 4 4, 4 8, 0 8, 0 0), (1 1, 3 1, 3 3, 1 3, 1 1))"
    p = read_part(write(tmp_path, "plate.wkt", text))
    exact = shapely.from_wkt(text)
    assert len(p.holes) == 1 and p.units is None and p.name == "plate"
    assert_allclose(p.center_of_mass, exact.centroid.coords[0], atol=1e-12)
    assert_allclose(Polygon(p.hull.vertices).area, exact.convex_hull.area, atol=1e-12)


def test_wkt_several_polygons_need_a_choice(tmp_path: Path) -> None:
    text = "MULTIPOLYGON (((0 0, 1 0, 0 1, 0 0)), ((5 5, 8 5, 8 6, 5 6, 5 5)))"
    f = write(tmp_path, "two.wkt", text)
    with pytest.raises(PartFileError, match=r"2 polygons \(0, 1\); choose one with --element"):
        read_part(f)
    p = read_part(f, element="1")
    assert p.hull.n_sides == 4 and p.name == "two[1]"
    with pytest.raises(PartFileError, match="no polygon '7'; found: 0, 1"):
        read_part(f, element="7")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("POLYGON ((0 0, 1 0, 1 1", "not valid WKT"),
        ("POLYGON EMPTY", "no polygon: the file holds an empty geometry"),
        ("LINESTRING (0 0, 1 1, 2 0)", "no polygon: the file holds a LineString"),
        ("POLYGON ((0 0, 1 1, 1 0, 0 1, 0 0))", "crosses itself near"),
        ("POLYGON ((0 0, 1 0, nan 1, 0 0))", "must be finite"),
        ("hello", "not valid WKT"),
    ],
)
def test_wkt_errors(tmp_path: Path, text: str, match: str) -> None:
    with pytest.raises(PartFileError, match=match):
        read_part(write(tmp_path, "bad.wkt", text))


# ---------------------------------------------------------------- GeoJSON


def feature(name: str | None, coords: list, fid: object = None, units: str = "mm") -> dict:
    f: dict = {
        "type": "Feature",
        "properties": {"units": units} | ({"name": name} if name else {}),
        "geometry": {"type": "Polygon", "coordinates": coords},
    }
    if fid is not None:
        f["id"] = fid
    return f


SQUARE = [[[0, 0], [2, 0], [2, 2], [0, 2], [0, 0]]]
TRIANGLE = [[[0, 0], [4, 0], [0, 3], [0, 0]]]


def test_geojson_sample_plate() -> None:
    p = read_part(EXAMPLES / "plate.geojson")
    data = json.loads((EXAMPLES / "plate.geojson").read_text())
    exact = shapely.geometry.shape(data["geometry"])
    assert (p.name, p.units, p.hull.n_sides, len(p.holes)) == ("tee-plate", "mm", 6, 1)
    assert_allclose(p.center_of_mass, exact.centroid.coords[0], atol=1e-12)
    assert_allclose(Polygon(p.hull.vertices).area, exact.convex_hull.area, atol=1e-12)


def test_geojson_choice_by_name_id_or_index(tmp_path: Path) -> None:
    coll = {
        "type": "FeatureCollection",
        "features": [feature("sq", SQUARE, fid=7), feature("tri", TRIANGLE, units="in")],
    }
    f = write(tmp_path, "two.geojson", json.dumps(coll))
    with pytest.raises(PartFileError, match=r"2 polygons \(sq, tri\); choose one with --element"):
        read_part(f)
    assert read_part(f, element="tri").hull.n_sides == 3
    assert read_part(f, element="tri").units == "in"
    assert read_part(f, element="7").name == "sq"
    assert read_part(f, element="1").name == "tri"
    # A GeoJSON object in a .json file is read as GeoJSON.
    g = write(tmp_path, "one.json", json.dumps(feature("sq", SQUARE)))
    assert read_part(g).name == "sq"


@pytest.mark.parametrize(
    ("doc", "match"),
    [
        (
            {
                "type": "Feature",
                "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]},
            },
            "no polygon found",
        ),
        ({"type": "Polygon", "coordinates": [[[0, 0], [1]]]}, "not a valid GeoJSON geometry"),
        ({"type": "FeatureCollection", "features": 3}, "not valid GeoJSON"),
        (feature("x", SQUARE) | {"properties": {"units": 5}}, '"units" must be a string'),
        ([1, 2], "not GeoJSON"),
    ],
)
def test_geojson_errors(tmp_path: Path, doc: object, match: str) -> None:
    with pytest.raises(PartFileError, match=match):
        read_part(write(tmp_path, "bad.geojson", json.dumps(doc)))


# ---------------------------------------------------------------- SVG


def affine(a: float, b: float, c: float, d: float, e: float, f: float) -> np.ndarray:
    return np.array([[a, c, e], [b, d, f], [0, 0, 1.0]])


def svg_transform_matrix() -> np.ndarray:
    """rotate(20) scale(1.5, 0.7) skewX(15), composed by hand (SVG applies right to left)."""
    r = math.radians(20)
    rot = affine(math.cos(r), math.sin(r), -math.sin(r), math.cos(r), 0, 0)
    scale = affine(1.5, 0, 0, 0.7, 0, 0)
    skew = affine(1, 0, math.tan(math.radians(15)), 1, 0, 0)
    return rot @ scale @ skew


def apply(m: np.ndarray, pts: np.ndarray, flip: bool = True) -> np.ndarray:
    out = pts @ m[:2, :2].T + m[:2, 2]
    return out * [1, -1] if flip else out


BEZIER_D = "M 0 0 C 10 -20 30 20 40 0 Q 50 15 30 30 C 20 40 -10 35 0 0 Z"
BEZIER_CTRL = [
    np.array([[0, 0], [10, -20], [30, 20], [40, 0]], dtype=float),
    np.array([[40, 0], [50, 15], [30, 30]], dtype=float),
    np.array([[30, 30], [20, 40], [-10, 35], [0, 0]], dtype=float),
]


@pytest.mark.parametrize("tol", [0.5, 0.05, 0.002])
def test_svg_bezier_flattening_error_is_bounded(tmp_path: Path, tol: float) -> None:
    body = (
        '<g transform="rotate(20) scale(1.5, 0.7)"><path id="b" transform="skewX(15)" '
        f'd="{BEZIER_D}"/></g>'
    )
    p = read_part(write(tmp_path, "b.svg", svg(body)), tolerance=tol)
    m = svg_transform_matrix()
    exact = np.vstack([apply(m, bernstein(c)) for c in BEZIER_CTRL])
    err = ring_distance(exact, p.outline)
    assert err.max() <= tol * (1 + 1e-9)
    assert err.max() >= tol / 20  # not wastefully fine: the bound is used, not ignored
    # every vertex of the polyline lies on the curve
    assert ring_distance(p.outline, exact).max() <= 1e-5  # (the dense sampling's own error)
    assert p.units == "px" and p.name == "b"


@pytest.mark.parametrize("tol", [0.3, 0.01])
def test_svg_arc_and_circle_flattening_under_affine_transforms(tmp_path: Path, tol: float) -> None:
    body = (
        '<g transform="rotate(20) scale(1.5, 0.7)">'
        '<circle id="c" cx="5" cy="3" r="10" transform="skewX(15)"/></g>'
    )
    p = read_part(write(tmp_path, "c.svg", svg(body)), tolerance=tol)
    t = np.linspace(0, 2 * np.pi, 20001)
    circle = np.c_[5 + 10 * np.cos(t), 3 + 10 * np.sin(t)]
    exact = apply(svg_transform_matrix(), circle)
    err = ring_distance(exact, p.outline)
    assert tol / 20 <= err.max() <= tol * (1 + 1e-9)
    # vertices on the ellipse: map them back to the circle
    m = svg_transform_matrix()
    back = (p.outline * [1, -1] - m[:2, 2]) @ np.linalg.inv(m[:2, :2]).T
    assert_allclose(np.hypot(back[:, 0] - 5, back[:, 1] - 3), 10.0, atol=1e-9)


def test_svg_arc_radii_too_small_are_scaled_up_as_the_spec_says(tmp_path: Path) -> None:
    body = '<path id="d" d="M 0 0 A 1 1 0 0 1 10 0 L 10 5 L 0 5 Z"/>'
    p = read_part(write(tmp_path, "d.svg", svg(body)), tolerance=0.01)
    arc = p.outline[p.outline[:, 1] > 1e-9]  # y flipped: the half disc is above y = 0
    assert len(arc) > 5
    assert_allclose(np.hypot(arc[:, 0] - 5, arc[:, 1]), 5.0, atol=1e-9)
    assert_allclose(p.outline[:, 1].min(), -5.0, atol=1e-12)
    assert_allclose(p.outline[:, 1].max(), 5.0, atol=0.01)


@pytest.mark.parametrize(
    ("attrs", "shape", "width", "units"),
    [
        ('width="50mm" height="40mm" viewBox="0 0 100 80"', 'width="100" height="80"', 50.0, "mm"),
        ('width="2in" height="1in"', 'width="96" height="48"', 25.4, "mm"),
        ('width="10cm" height="5cm" viewBox="0 0 10 5"', 'width="10" height="5"', 100.0, "mm"),
        ('width="72pt" height="72pt" viewBox="0 0 1 1"', 'width="1" height="1"', 25.4, "mm"),
        ('viewBox="0 0 30 20"', 'width="30" height="20"', 30.0, "px"),
        ("", 'width="30" height="20"', 30.0, "px"),
    ],
)
def test_svg_units(tmp_path: Path, attrs: str, shape: str, width: float, units: str) -> None:
    p = read_part(write(tmp_path, "u.svg", svg(f'<rect id="r" x="0" y="0" {shape}/>', attrs)))
    assert p.units == units
    assert_allclose(np.ptp(p.outline[:, 0]), width, rtol=1e-12)


def test_svg_y_axis_is_flipped_so_the_part_looks_as_drawn(tmp_path: Path) -> None:
    p = read_part(write(tmp_path, "t.svg", svg('<polygon id="t" points="0,0 10,0 0,5"/>')))
    assert sorted(set(p.outline[:, 1].tolist())) == [-5.0, 0.0]


def test_svg_several_shapes_need_element_and_groups_pool_holes(tmp_path: Path) -> None:
    body = (
        '<rect id="a" x="0" y="0" width="4" height="4"/>'
        '<g id="plate"><rect id="b" x="10" y="0" width="10" height="6"/>'
        '<circle id="h" cx="13" cy="3" r="1"/></g>'
    )
    f = write(tmp_path, "s.svg", svg(body))
    with pytest.raises(
        PartFileError, match=r"3 shapes with a closed outline \(a, b, h\).*--element"
    ):
        read_part(f)
    assert read_part(f, element="b").holes == ()
    p = read_part(f, element="plate", tolerance=1e-4)
    assert p.name == "plate" and len(p.holes) == 1
    exact = Polygon([(10, 0), (20, 0), (20, -6), (10, -6)]).difference(
        Point(13, -3).buffer(1, quad_segs=256)
    )
    assert_allclose(p.center_of_mass, exact.centroid.coords[0], atol=1e-4)
    with pytest.raises(PartFileError, match="no element with id 'zz'; ids in the file: a, plate"):
        read_part(f, element="zz")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", "the file is empty"),
        ('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 L 1', "not a readable SVG file"),
        ("<html><body/></html>", "not a readable SVG file|not an SVG document"),
        (svg('<polyline id="o" points="0,0 1,1 2,0"/>'), r"no closed outline \(1 shape"),
        (svg('<text x="0" y="0">hi</text>'), "no closed outline \\(no shape elements\\)"),
        (svg('<path id="n" d="M 0 0 L nan 0 L 1 1 Z"/>'), "not finite"),
        (svg('<path id="x" d="M 0 0 L 1 1 L 1 0 L 0 1 Z"/>'), "self-intersecting outline"),
        (svg('<path id="z" d="M 0 0 L 1 0 L 1 1 Z M 5 5 L 6 5 L 6 6 Z"/>'), "2 separate closed"),
    ],
)
def test_svg_errors(tmp_path: Path, text: str, match: str) -> None:
    f = write(tmp_path, "bad.svg", text)
    with pytest.raises(PartFileError, match=match) as info:
        read_part(f)
    assert str(info.value).startswith(str(f))


def test_svg_binary_junk_and_layer_option(tmp_path: Path) -> None:
    f = tmp_path / "junk.svg"
    f.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    with pytest.raises(PartFileError, match="not a readable SVG file"):
        read_part(f)
    g = write(tmp_path, "ok.svg", svg('<rect id="r" width="2" height="1"/>'))
    with pytest.raises(PartFileError, match="`layer` applies to DXF"):
        read_part(g, layer="0")


def test_svg_curve_with_too_many_points_is_refused_before_flattening(tmp_path: Path) -> None:
    f = write(tmp_path, "big.svg", svg('<circle id="c" cx="0" cy="0" r="1000"/>'))
    with pytest.raises(PartFileError, match=r"flatten to \d+ points .* limit is 100000"):
        read_part(f, tolerance=1e-9)
    assert read_part(f).hull.n_sides > 20  # the default tolerance is fine


PEANUT_CTRL = [
    np.array([[8, 30], [8, 14], [26, 8], [38, 18]], dtype=float),
    np.array([[38, 18], [50, 4], [76, 8], [76, 30]], dtype=float),
    np.array([[76, 30], [76, 54], [50, 58], [38, 44]], dtype=float),
    np.array([[38, 44], [28, 53], [8, 48], [8, 30]], dtype=float),
]  # the numbers of examples/make_examples.py


def test_svg_sample_peanut_matches_its_bezier_curves() -> None:
    tol = 0.02
    p = read_part(EXAMPLES / "peanut.svg", tolerance=tol)
    shift = np.array([2.0, 3.0])
    exact = np.vstack([(bernstein(c) + shift) * [1, -1] for c in PEANUT_CTRL])
    assert (p.name, p.units, len(p.holes)) == ("peanut", "mm", 1)
    assert ring_distance(exact, p.outline).max() <= tol * (1 + 1e-9)
    t = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    hole = np.c_[23 + 6 * np.cos(t), 30 + 6 * np.sin(t)] + shift
    hole *= [1, -1]
    assert ring_distance(hole, p.holes[0]).max() <= tol * (1 + 1e-9)
    solid = Polygon(exact, [hole])
    assert_allclose(p.center_of_mass, solid.centroid.coords[0], atol=tol)
    hull = Polygon(p.hull.vertices)
    assert shapely.hausdorff_distance(hull, solid.convex_hull, densify=0.01) <= tol + 1e-3


# ---------------------------------------------------------------- DXF


def test_dxf_sample_bracket_matches_its_exact_geometry() -> None:
    p = read_part(EXAMPLES / "bracket.dxf")
    tol = 1e-3 * math.hypot(80, 60)  # the default: 0.1% of the drawing's diagonal
    q = 1024
    ell = Polygon([(0, 0), (80, 0), (80, 20), (20, 20), (20, 60), (0, 60)])
    rounded = ell.buffer(-6, quad_segs=q).buffer(6, quad_segs=q)  # convex corners, r = 6
    fillet = shapely.box(20, 20, 28, 28).difference(Point(28, 28).buffer(8, quad_segs=q))
    rounded = rounded.union(fillet)  # the inner corner filleted with r = 8
    holes = [Point(60, 10).buffer(4, quad_segs=q), Point(10, 45).buffer(4, quad_segs=q)]
    slot = LineString([(30, 10), (45, 10)]).buffer(3, quad_segs=q)
    exact = rounded.difference(shapely.union_all([*holes, slot]))
    assert (p.name, p.units, len(p.holes)) == ("bracket", "mm", 3)
    dense = shapely.get_coordinates(shapely.segmentize(rounded.exterior, 0.05))
    assert ring_distance(dense, p.outline).max() <= tol + 1e-4
    assert boundary_distance(p.outline, rounded).max() <= 1e-4  # vertices on the outline
    hull = Polygon(p.hull.vertices)
    assert shapely.hausdorff_distance(hull, exact.convex_hull, densify=0.01) <= tol + 1e-4
    assert_allclose(p.center_of_mass, exact.centroid.coords[0], atol=tol)
    assert_allclose(Polygon(p.outline, p.holes).area, exact.area, rtol=2e-3)


def rounded_rect_sdf(pts: np.ndarray, w: float, h: float, r: float) -> np.ndarray:
    """Signed distance to the rectangle [0, w] x [0, h] with corners rounded by r."""
    q = np.abs(pts - [w / 2, h / 2]) - [w / 2 - r, h / 2 - r]
    outside = np.hypot(np.maximum(q[:, 0], 0), np.maximum(q[:, 1], 0))
    return outside + np.minimum(np.maximum(q[:, 0], q[:, 1]), 0) - r


@pytest.mark.parametrize("tol", [0.1, 0.001])
def test_dxf_lwpolyline_bulges(tmp_path: Path, tol: float) -> None:
    b = math.tan(math.pi / 8)
    doc, msp = new_dxf()
    msp.add_lwpolyline(
        [
            (5, 0, 0),
            (35, 0, b),
            (40, 5, 0),
            (40, 15, b),
            (35, 20, 0),
            (5, 20, b),
            (0, 15, 0),
            (0, 5, b),
        ],
        format="xyb",
        close=True,
    )
    p = read_part(save(doc, tmp_path), tolerance=tol)
    assert np.abs(rounded_rect_sdf(p.outline, 40, 20, 5)).max() <= 1e-9
    t = np.linspace(0, np.pi / 2, 2001)
    corners = [(35, 5, -np.pi / 2), (35, 15, 0.0), (5, 15, np.pi / 2), (5, 5, np.pi)]
    dense = np.vstack(
        [np.c_[cx + 5 * np.cos(t + a), cy + 5 * np.sin(t + a)] for cx, cy, a in corners]
    )
    err = ring_distance(dense, p.outline)
    assert tol / 20 <= err.max() <= tol * (1 + 1e-9)
    assert_allclose(p.center_of_mass, [20, 10], atol=1e-9)


def test_dxf_loop_of_lines_and_arcs_in_any_order_and_direction(tmp_path: Path) -> None:
    doc, msp = new_dxf()
    msp.add_arc((0, 0), 3, 90, 270)  # left end
    msp.add_line((15, 3), (0, 3))  # top, drawn right to left
    msp.add_line((0, -3), (15, -3))
    msp.add_arc((15, 0), 3, -90, 90)  # right end
    tol = 0.001
    p = read_part(save(doc, tmp_path), tolerance=tol)
    stadium = LineString([(0, 0), (15, 0)]).buffer(3, quad_segs=2048)
    assert boundary_distance(p.outline, stadium).max() <= 1e-5
    dense = shapely.get_coordinates(shapely.segmentize(stadium.exterior, 0.01))
    assert ring_distance(dense, p.outline).max() <= tol + 1e-5
    assert_allclose(Polygon(p.outline).area, 15 * 6 + math.pi * 9, rtol=1e-3)


def test_dxf_circle_sagitta_is_within_tolerance(tmp_path: Path) -> None:
    doc, msp = new_dxf(units=1)
    msp.add_circle((2, 3), 7)
    tol = 0.01
    p = read_part(save(doc, tmp_path), tolerance=tol)
    assert p.units == "in"
    assert_allclose(np.hypot(*(p.outline - [2, 3]).T), 7, atol=1e-12)
    mids = (p.outline + np.roll(p.outline, -1, axis=0)) / 2
    sagitta = 7 - np.hypot(*(mids - [2, 3]).T)
    assert tol / 4 <= sagitta.max() <= tol


def test_dxf_ellipse_spline_and_mirrored_arc(tmp_path: Path) -> None:
    doc, msp = new_dxf(units=6)
    msp.add_ellipse((0, 0), major_axis=(6, 2), ratio=0.4)  # full ellipse
    f = save(doc, tmp_path, "ellipse.dxf")
    tol = 0.002
    p = read_part(f, tolerance=tol)
    e = msp.query("ELLIPSE")[0].construction_tool()
    dense = np.array([[v.x, v.y] for v in e.vertices(np.linspace(0, 2 * np.pi, 20001))])
    assert p.units == "m"
    assert ring_distance(dense, p.outline).max() <= tol * (1 + 1e-9)

    doc, msp = new_dxf()
    spline = msp.add_open_spline([(0, 0), (5, 10), (15, -4), (20, 6), (25, 0)], degree=3)
    msp.add_line((25, 0), (0, 0))
    p = read_part(save(doc, tmp_path, "spline.dxf"), tolerance=tol)
    bs = spline.construction_tool()
    dense = np.array([[v.x, v.y] for v in bs.points(np.linspace(0, bs.max_t, 20001))])
    assert ring_distance(dense, p.outline).max() <= tol * (1 + 1e-9)

    doc, msp = new_dxf()
    arc = msp.add_arc((4, 0), 4, 0, 180, dxfattribs={"extrusion": (0, 0, -1)})
    s, e2 = arc.start_point, arc.end_point
    msp.add_line(e2, s)
    p = read_part(save(doc, tmp_path, "mirror.dxf"), tolerance=tol)
    centre = arc.ocs().to_wcs(arc.dxf.center)
    assert_allclose(np.hypot(p.outline[:, 0] - centre.x, p.outline[:, 1] - centre.y).max(), 4)
    assert_allclose(centre.x, -4.0)  # the mirrored frame puts the arc at x < 0
    assert p.outline[:, 0].max() <= 1e-12


def test_dxf_rational_spline_and_block_reference(tmp_path: Path) -> None:
    doc, msp = new_dxf()
    msp.add_rational_spline([(0, 0), (5, 8), (10, 0)], weights=[1, 2, 1], degree=2)
    msp.add_line((10, 0), (0, 0))
    tol = 0.01
    p = read_part(save(doc, tmp_path, "rational.dxf"), tolerance=tol)
    bs = msp.query("SPLINE")[0].construction_tool()
    dense = np.array([[v.x, v.y] for v in bs.points(np.linspace(0, bs.max_t, 5001))])
    assert ring_distance(dense, p.outline).max() <= 2 * tol  # ezdxf's adaptive flattening

    doc, msp = new_dxf()
    block = doc.blocks.new("HOLE_PLATE")
    block.add_lwpolyline([(0, 0), (10, 0), (10, 10), (0, 10)], close=True)
    block.add_circle((5, 5), 2)
    msp.add_blockref("HOLE_PLATE", (100, 50), dxfattribs={"xscale": 2, "yscale": 2})
    p = read_part(save(doc, tmp_path, "block.dxf"), tolerance=tol)
    assert len(p.holes) == 1
    assert_allclose(p.hull.vertices.min(axis=0), [100, 50], atol=1e-9)
    assert_allclose(p.center_of_mass, [110, 60], atol=1e-9)


def test_dxf_polylines_2d_3d_and_closed_spline(tmp_path: Path) -> None:
    doc, msp = new_dxf()
    b = math.tan(math.pi / 8)
    # An old-style 2D POLYLINE whose last vertex repeats the first (closed without the flag).
    msp.add_polyline2d(
        [
            (5, 0, 0, 0, 0),
            (35, 0, 0, 0, b),
            (40, 5, 0, 0, 0),
            (40, 20, 0, 0, 0),
            (5, 20, 0, 0, 0),
            (5, 0, 0, 0, 0),
        ],
        format="xyseb",
    )
    p = read_part(save(doc, tmp_path, "poly2d.dxf"), tolerance=0.01)
    corner = p.outline[(p.outline[:, 0] > 35 + 1e-9) & (p.outline[:, 1] < 5 - 1e-9)]
    assert len(corner) >= 2
    assert_allclose(np.hypot(corner[:, 0] - 35, corner[:, 1] - 5), 5, atol=1e-12)

    doc, msp = new_dxf()
    msp.add_polyline3d([(0, 0, 1), (4, 0, 2), (4, 3, 3), (0, 3, 4)], close=True)
    p = read_part(save(doc, tmp_path, "poly3d.dxf"))
    assert_allclose(p.center_of_mass, [2, 1.5], atol=1e-12)  # projected on xy

    doc, msp = new_dxf()
    spline = msp.add_spline()  # a periodic ("closed") spline: unclamped knots
    spline.set_closed([(0, 0, 0), (10, -2, 0), (14, 6, 0), (6, 12, 0), (-3, 7, 0)], degree=3)
    tol = 0.01
    p = read_part(save(doc, tmp_path, "closed_spline.dxf"), tolerance=tol)
    bs = spline.construction_tool()
    lo, hi = bs.knots()[bs.degree], bs.knots()[bs.count]  # the curve's valid domain
    dense = np.array([[v.x, v.y] for v in bs.points(np.linspace(lo, hi, 20001))])
    assert ring_distance(dense, p.outline).max() <= tol * (1 + 1e-9)
    assert ring_distance(p.outline, dense).max() <= 1e-4  # no points off the curve


@pytest.mark.parametrize(
    ("order", "knots", "weights"),
    [
        (4, [0, 1, 2, 3, 4, 5, 6, 7, 8, 9], None),
        (3, [0, 1, 2, 3, 4, 5, 6, 7, 8], [1, 2, 1, 3, 1, 2]),
        (4, [0, 0.5, 2, 3, 3, 5, 6, 7, 9.5, 10], None),
        (4, [0, 0, 0, 0, 1, 2, 3, 4, 4.5, 6], [1, 1, 0.5, 2, 1, 1]),
    ],
)
def test_unclamped_splines_are_restricted_to_their_domain(
    order: int, knots: list[float], weights: list[float] | None
) -> None:
    from ezdxf.math import BSpline

    from bayesgrasp.io.dxf import _clamped

    pts = [(0, 0, 0), (5, 8, 0), (10, 0, 0), (15, 5, 0), (20, 0, 0), (25, 3, 0)]
    bs = BSpline(pts, order=order, knots=knots, weights=weights)
    clamped = _clamped(bs)
    assert clamped.is_clamped
    lo, hi = knots[order - 1], knots[len(pts)]
    u0, u1 = clamped.knots()[0], clamped.max_t
    ref = np.array([list(v) for v in bs.points(np.linspace(lo, hi, 301))])
    got = np.array([list(v) for v in clamped.points(np.linspace(u0, u1, 301))])
    assert_allclose(got, ref, atol=1e-12)


def two_squares(tmp_path: Path, layers: tuple[str, str]) -> Path:
    doc, msp = new_dxf()
    msp.add_lwpolyline(
        [(0, 0), (1, 0), (1, 1), (0, 1)], close=True, dxfattribs={"layer": layers[0]}
    )
    msp.add_lwpolyline(
        [(5, 0), (7, 0), (7, 2), (5, 2)], close=True, dxfattribs={"layer": layers[1]}
    )
    return save(doc, tmp_path)


def test_dxf_layers_choose_between_outlines(tmp_path: Path) -> None:
    f = two_squares(tmp_path, ("A", "B"))
    with pytest.raises(
        PartFileError, match=r"2 separate closed outlines .*--layer \(layers: A, B\)"
    ):
        read_part(f)
    p = read_part(f, layer="b")
    assert_allclose(np.ptp(p.outline, axis=0), [2, 2])
    assert p.name == "part:b"
    with pytest.raises(PartFileError, match=r"on layer 'Z' \(layers: A, B\)"):
        read_part(f, layer="Z")
    g = two_squares(tmp_path, ("A", "A"))
    with pytest.raises(PartFileError, match="keep one part per layer"):
        read_part(g)


def test_dxf_duplicated_outline_and_construction_lines_are_ignored(tmp_path: Path) -> None:
    doc, msp = new_dxf()
    for _ in range(2):
        msp.add_lwpolyline([(0, 0), (4, 0), (4, 3), (0, 3)], close=True)
    msp.add_line((-1, 1.5), (5, 1.5))  # a centre line: an open chain
    msp.add_text("label")
    p = read_part(save(doc, tmp_path))
    assert p.holes == () and p.hull.n_sides == 4


def dxf_with(tmp_path: Path, build: object, name: str = "bad.dxf") -> Path:
    doc, msp = new_dxf()
    build(msp)  # type: ignore[operator]
    return save(doc, tmp_path, name)


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (
            lambda m: m.add_line((0, 0), (1, 1)),
            r"no closed outline; LINE #\w+ on layer 0: its chain ends at",
        ),
        (
            lambda m: [
                m.add_line((0, 0), (1, 0)),
                m.add_line((1, 0), (0, 1)),
                m.add_line((0, 1), (0, 0)),
                m.add_line((0, 0), (-1, -1)),
            ],
            "no closed outline; .*its chain (branches|ends) at",
        ),
        (
            lambda m: m.add_lwpolyline([(0, 0), (1, 1), (1, 0), (0, 1)], close=True),
            "self-intersecting outline",
        ),
        (lambda m: [m.add_circle((0, 0), 2), m.add_circle((3, 0), 2)], "cross or touch"),
        (lambda m: m.add_text("only text"), "no lines, arcs, circles"),
        (lambda m: m.add_point((1, 2)), "no lines, arcs, circles"),
    ],
)
def test_dxf_geometry_errors(tmp_path: Path, build: object, match: str) -> None:
    with pytest.raises(PartFileError, match=match):
        read_part(dxf_with(tmp_path, build))


def test_dxf_huge_counts_are_refused(tmp_path: Path) -> None:
    f = dxf_with(tmp_path, lambda m: m.add_circle((0, 0), 1e6))
    with pytest.raises(PartFileError, match=r"flatten to \d+ points at chordal tolerance 1e-06"):
        read_part(f, tolerance=1e-6)
    with pytest.raises(PartFileError, match="limit is 40"):
        read_part(EXAMPLES / "bracket.dxf", max_points=40)
    with pytest.raises(PartFileError, match="tolerance must be a number > 0"):
        read_part(f, tolerance=0.0)


def test_dxf_nan_and_malformed_files(tmp_path: Path) -> None:
    f = dxf_with(
        tmp_path, lambda m: m.add_lwpolyline([(0, 0), (3, 0), (3.25, 2), (0, 2)], close=True)
    )
    text = f.read_text()
    nan = tmp_path / "nan.dxf"
    nan.write_text(text.replace("\n3.25\n", "\nnan\n", 1))
    with pytest.raises(PartFileError, match="finite"):
        read_part(nan)
    cut = tmp_path / "cut.dxf"
    cut.write_text(text[: len(text) // 2])
    with pytest.raises(PartFileError, match="not a readable DXF file"):
        read_part(cut)
    for name, data in [
        ("empty.dxf", b""),
        ("svg.dxf", b"<svg></svg>"),
        ("junk.dxf", bytes(range(256))),
    ]:
        g = tmp_path / name
        g.write_bytes(data)
        with pytest.raises(PartFileError, match=r"the file is empty|not a readable DXF file"):
            read_part(g)
    with pytest.raises(PartFileError, match="`element` applies to SVG"):
        read_part(f, element="x")


def test_dxf_units_from_insunits(tmp_path: Path) -> None:
    for code, units in [(0, None), (1, "in"), (4, "mm"), (6, "m")]:
        doc, msp = new_dxf(units=code)
        msp.add_circle((0, 0), 1)
        assert read_part(save(doc, tmp_path, f"u{code}.dxf")).units == units


def test_missing_extra_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "ezdxf", None)
    with pytest.raises(MissingExtraError, match=r"pip install 'bayesgrasp\[io\]'"):
        read_part(EXAMPLES / "bracket.dxf")


# ---------------------------------------------------------------- command line


def test_cli_reads_every_sample(capsys: pytest.CaptureFixture[str]) -> None:
    for name, units in [("bracket.dxf", "mm"), ("peanut.svg", "mm"), ("plate.geojson", "mm")]:
        code, out, err = cli(["squeeze", str(EXAMPLES / name), "--json"], capsys)
        assert code == 0, err
        assert json.loads(out)["part"]["units"] == units


def test_cli_part_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = write(
        tmp_path, "shape.txt", "MULTIPOLYGON (((0 0, 1 0, 0 1, 0 0)), ((5 5, 8 5, 8 6, 5 6, 5 5)))"
    )
    code, out, _ = cli(["squeeze", str(f), "--format", "wkt", "--element", "1", "--json"], capsys)
    assert code == 0 and json.loads(out)["part"]["n_sides"] == 4
    g = two_squares(tmp_path, ("A", "B"))
    code, out, _ = cli(["plan", str(g), "--layer", "A", "--json"], capsys)
    assert code == 0 and json.loads(out)["part"]["name"] == "part:A"
    code, out, _ = cli(
        ["squeeze", str(EXAMPLES / "peanut.svg"), "--flatten-tol", "0.5", "--json"], capsys
    )
    assert code == 0


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["squeeze", "{tmp}/empty.dxf"], "the file is empty"),
        (["squeeze", "{tmp}/cut.svg"], "not a readable SVG file"),
        (["plan", "{tmp}/bow.wkt"], "crosses itself"),
        (["plan", "{tmp}/two.svg"], "--element"),
        (["squeeze", "{ex}/bracket.dxf", "--layer", "NOPE"], "on layer 'NOPE'"),
        (["squeeze", "{ex}/bracket.dxf", "--flatten-tol", "0"], "should be a number > 0"),
        (["squeeze", "{tmp}/nothing.dxf"], "no such file"),
    ],
)
def test_cli_bad_files_exit_2_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], match: str
) -> None:
    (tmp_path / "empty.dxf").write_bytes(b"")
    write(tmp_path, "cut.svg", '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0')
    write(tmp_path, "bow.wkt", "POLYGON ((0 0, 1 1, 1 0, 0 1, 0 0))")
    write(
        tmp_path,
        "two.svg",
        svg('<rect id="a" width="1" height="1"/><rect id="b" x="3" width="1" height="1"/>'),
    )
    args = [a.format(tmp=tmp_path, ex=EXAMPLES) for a in argv]
    code, out, err = cli(args, capsys)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("bayesgrasp: error: ")
    assert match in lines[0] and "Traceback" not in err


def test_cli_process_prints_no_traceback(tmp_path: Path) -> None:
    bad = write(tmp_path, "bad.dxf", "0\nSECTION\n2\nENTITIES\n0\nLINE\n")
    run = subprocess.run(
        [sys.executable, "-m", "bayesgrasp.cli", "squeeze", str(bad)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr
    assert str(bad) in run.stderr


def test_read_part_default_limit_is_documented() -> None:
    assert MAX_POINTS == 100_000
    import bayesgrasp.io as io_pkg

    assert "100 000" in (io_pkg.__doc__ or "")
