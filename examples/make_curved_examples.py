"""Write the curved sample parts of this folder (run from anywhere): a lever and a slot.

    python examples/make_curved_examples.py

- ``lever.svg``: a tapering lever drawn with cubic Bezier curves (the arm's sides have an
  inflection, so the convex hull bridges them), with a round pivot hole drawn with two
  arc commands; 1 user unit is 1 mm.
- ``slot.dxf``: a slotted link in millimetres: a stadium (two half circles of radius 5 whose
  centres are 40 mm apart) as one closed LWPOLYLINE with bulges, and a round hole (CIRCLE).

The README's "Curved parts" section runs bayesgrasp on them and on ``bracket.dxf``.
"""

from __future__ import annotations

from pathlib import Path

import ezdxf

HERE = Path(__file__).resolve().parent

LEVER_PATH = (
    "M 10 18 C 40 18 60 24 90 24 C 98 24 98 36 90 36 C 60 36 40 42 10 42 "
    "C -6 42 -6 18 10 18 Z "
    "M 16 30 A 6 6 0 1 0 4 30 A 6 6 0 1 0 16 30 Z"
)

SLOT_OUTLINE = [(0.0, -5.0, 0.0), (40.0, -5.0, 1.0), (40.0, 5.0, 0.0), (0.0, 5.0, 1.0)]
SLOT_HOLE = ((0.0, 0.0), 2.5)


def write_lever(path: Path) -> None:
    """The SVG lever."""
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" '
        'viewBox="0 0 100 60">\n'
        "  <title>lever: cubic Bezier outline with a round pivot hole</title>\n"
        f'  <path id="lever" fill="#c8d6e5" stroke="#222" stroke-width="0.3" '
        f'fill-rule="evenodd" d="{LEVER_PATH}"/>\n'
        "</svg>\n"
    )
    path.write_text(text, encoding="utf-8")


def write_slot(path: Path) -> None:
    """The DXF slotted link (fixed dates and GUIDs, so that regenerating changes nothing)."""
    ezdxf.options.write_fixed_meta_data_for_testing = True
    doc = ezdxf.new("R2010", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline(SLOT_OUTLINE, format="xyb", close=True)
    msp.add_circle(*SLOT_HOLE)
    doc.saveas(path)


def main() -> None:
    """Write the two sample files beside this script."""
    write_lever(HERE / "lever.svg")
    write_slot(HERE / "slot.dxf")
    for name in ("lever.svg", "slot.dxf"):
        print(f"wrote examples/{name}")  # noqa: T201 - a script reports what it wrote


if __name__ == "__main__":
    main()
