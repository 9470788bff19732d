"""Write the sample part files of this folder (run from anywhere: paths are relative to it).

    python examples/make_examples.py

- ``bracket.dxf``: an L-shaped bracket in millimetres ($INSUNITS = 4). The outline is one
  closed LWPOLYLINE with bulges (five convex corners rounded with radius 6, the inner corner
  with a fillet of radius 8); two mounting holes are CIRCLEs; a slot is a loop of two LINEs
  and two ARCs. Centre lines on the layer CENTER and a TEXT label are not outlines and are
  ignored by the reader.
- ``peanut.svg``: a non-convex peanut-shaped cam drawn with cubic Bezier curves, with a
  round hole drawn with two elliptical-arc commands, inside a translated group; 1 user unit
  is 1 mm (``width="80mm"``, ``viewBox="0 0 80 60"``).
- ``plate.geojson``: a T-shaped plate with a square hole, as a GeoJSON Feature with
  ``"units": "mm"``.

The numbers here are the ones tests/test_io.py checks against.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf

HERE = Path(__file__).resolve().parent

#: Quarter-turn bulge: tan(90 deg / 4).
QUARTER = math.tan(math.pi / 8)

#: (x, y, bulge) of the bracket outline, counter-clockwise; a vertex's bulge shapes the
#: segment that starts at it (positive: a left turn, convex; negative: the inner fillet).
BRACKET_OUTLINE = [
    (6.0, 0.0, 0.0),
    (74.0, 0.0, QUARTER),
    (80.0, 6.0, 0.0),
    (80.0, 14.0, QUARTER),
    (74.0, 20.0, 0.0),
    (28.0, 20.0, -QUARTER),
    (20.0, 28.0, 0.0),
    (20.0, 54.0, QUARTER),
    (14.0, 60.0, 0.0),
    (6.0, 60.0, QUARTER),
    (0.0, 54.0, 0.0),
    (0.0, 6.0, QUARTER),
]
BRACKET_HOLES = [((60.0, 10.0), 4.0), ((10.0, 45.0), 4.0)]  # (centre, radius)
BRACKET_SLOT = ((30.0, 10.0), (45.0, 10.0), 3.0)  # centres of the two ends, radius

PEANUT_PATH = (
    "M 8 30 C 8 14 26 8 38 18 C 50 4 76 8 76 30 "
    "C 76 54 50 58 38 44 C 28 53 8 48 8 30 Z "
    "M 29 30 A 6 6 0 1 0 17 30 A 6 6 0 1 0 29 30 Z"
)
PEANUT_OFFSET = (2.0, 3.0)  # the group's translation

PLATE_OUTER = [[0, 0], [40, 0], [40, 10], [25, 10], [25, 35], [15, 35], [15, 10], [0, 10], [0, 0]]
PLATE_HOLE = [[18, 20], [18, 26], [22, 26], [22, 20], [18, 20]]


def write_bracket(path: Path) -> None:
    """The DXF bracket (fixed dates and GUIDs, so that regenerating it changes nothing)."""
    ezdxf.options.write_fixed_meta_data_for_testing = True
    doc = ezdxf.new("R2010", units=4)
    doc.layers.add("OUTLINE", color=7)
    doc.layers.add("CENTER", color=1, linetype="CENTER")
    msp = doc.modelspace()
    outline = {"layer": "OUTLINE"}
    msp.add_lwpolyline(BRACKET_OUTLINE, format="xyb", close=True, dxfattribs=outline)
    for center, radius in BRACKET_HOLES:
        msp.add_circle(center, radius, dxfattribs=outline)
        cx, cy = center
        msp.add_line((cx - 6, cy), (cx + 6, cy), dxfattribs={"layer": "CENTER"})
        msp.add_line((cx, cy - 6), (cx, cy + 6), dxfattribs={"layer": "CENTER"})
    (x0, y0), (x1, _), r = BRACKET_SLOT
    msp.add_line((x0, y0 - r), (x1, y0 - r), dxfattribs=outline)
    msp.add_arc((x1, y0), r, -90, 90, dxfattribs=outline)
    msp.add_line((x1, y0 + r), (x0, y0 + r), dxfattribs=outline)
    msp.add_arc((x0, y0), r, 90, 270, dxfattribs=outline)
    msp.add_text("BRACKET 3 mm STEEL", dxfattribs={"layer": "CENTER", "height": 2.5}).set_placement(
        (30, 40)
    )
    doc.saveas(path)


def write_peanut(path: Path) -> None:
    """The SVG cam."""
    dx, dy = PEANUT_OFFSET
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<svg xmlns="http://www.w3.org/2000/svg" width="80mm" height="60mm" '
        'viewBox="0 0 80 60">\n'
        "  <title>peanut cam: cubic Bezier outline with a round hole</title>\n"
        f'  <g transform="translate({dx:g} {dy:g})">\n'
        f'    <path id="peanut" fill="#c8d6e5" stroke="#222" stroke-width="0.3" '
        f'fill-rule="evenodd" d="{PEANUT_PATH}"/>\n'
        "  </g>\n"
        "</svg>\n"
    )
    path.write_text(text, encoding="utf-8")


def write_plate(path: Path) -> None:
    """The GeoJSON plate."""
    feature = {
        "type": "Feature",
        "properties": {"name": "tee-plate", "units": "mm"},
        "geometry": {"type": "Polygon", "coordinates": [PLATE_OUTER, PLATE_HOLE]},
    }
    path.write_text(json.dumps(feature, indent=1) + "\n", encoding="utf-8")


def main() -> None:
    """Write the three sample files beside this script."""
    write_bracket(HERE / "bracket.dxf")
    write_peanut(HERE / "peanut.svg")
    write_plate(HERE / "plate.geojson")
    for name in ("bracket.dxf", "peanut.svg", "plate.geojson"):
        print(f"wrote examples/{name}")  # noqa: T201 - a script reports what it wrote


if __name__ == "__main__":
    main()
