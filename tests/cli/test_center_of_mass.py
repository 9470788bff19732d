"""Point lists: an ordered outline has its area centroid, a point cloud is a hull; --com.

The issue's L outline gave (40.00, 26.85) from CSV and (37.15, 19.58) from WKT; an ordered
simple outline is an outline in every format, a self-crossing list a point cloud (its hull),
and ``--com X,Y`` sets the centre of mass of any part.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from bayesgrasp.cli import main

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

L = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 40), (0, 40)]


def push_doc(capsys: pytest.CaptureFixture[str], *args: str) -> dict:
    code = main(["push", *args, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_outline_centroid_is_the_same_in_every_format(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    csv = tmp_path / "L.csv"
    csv.write_text("".join(f"{x},{y}\n" for x, y in L), encoding="utf-8")
    js = tmp_path / "L.json"
    js.write_text(json.dumps({"vertices": L}), encoding="utf-8")
    wkt = tmp_path / "L.wkt"
    ring = ", ".join(f"{x} {y}" for x, y in [*L, L[0]])
    wkt.write_text(f"POLYGON (({ring}))", encoding="utf-8")
    # area centroid of the L: two rectangles 40x10 and 10x30
    expect = [(40 * 10 * 20 + 10 * 30 * 5) / 700, (40 * 10 * 5 + 10 * 30 * 25) / 700]
    for f in (csv, js, wkt):
        assert_allclose(push_doc(capsys, str(f))["center_of_mass"], expect, rtol=1e-12)


def test_point_cloud_is_its_hull_and_com_sets_it(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    cloud = tmp_path / "cloud.csv"
    cloud.write_text(
        "".join(f"{x},{y}\n" for x, y in [L[i] for i in (0, 3, 1, 5, 2, 4)]), encoding="utf-8"
    )
    hull = push_doc(capsys, str(cloud))
    assert hull["part"]["n_sides"] == 5
    # the hull's area centroid (the pentagon without the L's notch)
    assert hull["center_of_mass"] != pytest.approx(
        push_doc(capsys, str(cloud), "--com", "12,12")["center_of_mass"]
    )
    assert push_doc(capsys, str(cloud), "--com", "12,12")["center_of_mass"] == [12.0, 12.0]
    assert push_doc(capsys, "triangle", "--com", "18,11")["part"]["center_of_mass"] == [18.0, 11.0]


@pytest.mark.parametrize(
    ("com", "words"), [("100,0", "inside the part's convex hull"), ("a,b", "two finite numbers")]
)
def test_bad_com(capsys: pytest.CaptureFixture[str], com: str, words: str) -> None:
    code = main(["plan", "triangle", "--com", com])
    out, err = capsys.readouterr()
    assert (code, out) == (2, "")
    assert len(err.strip().splitlines()) == 1 and words in err


def test_a_point_cloud_is_announced(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    cloud = tmp_path / "cloud.csv"
    cloud.write_text("".join(f"{x},{y}\n" for x, y in [L[i] for i in (0, 3, 1, 5, 2, 4)]))
    ordered = tmp_path / "L.csv"
    ordered.write_text("".join(f"{x},{y}\n" for x, y in L))
    assert main(["squeeze", str(cloud)]) == 0
    err = capsys.readouterr().err
    assert "point cloud: the part is their convex hull" in err and "--com X,Y" in err
    assert main(["squeeze", str(ordered)]) == 0
    assert capsys.readouterr().err == ""
