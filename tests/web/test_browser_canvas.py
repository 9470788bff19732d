"""The drawing canvas in real headless Chromium: every part seen whole, zoom, pan and Fit."""

from __future__ import annotations

from typing import Any

import pytest

pytestmark = pytest.mark.browser  # the `browser` fixture skips where Chromium is missing

LEVER = [[-120.0, -40.0], [310.0, -40.0], [310.0, 25.0], [-120.0, 25.0]]  # 430 mm long


def _circles(page: Any) -> list[tuple[float, float]]:
    """The vertex handles' centres, in canvas pixels (0-400)."""
    return [
        (float(x), float(y))
        for x, y in page.evaluate(
            """() => [...document.querySelectorAll('#canvas circle.vertex')]
                .map((c) => [c.getAttribute('cx'), c.getAttribute('cy')])"""
        )
    ]


def _inside(points: list[tuple[float, float]]) -> bool:
    return all(0 <= x <= 400 and 0 <= y <= 400 for x, y in points)


def _at(page: Any, px: float, py: float) -> tuple[float, float]:
    """The page coordinates of canvas pixel (px, py)."""
    box = page.locator("#canvas").bounding_box()
    return box["x"] + px * box["width"] / 400, box["y"] + py * box["height"] / 400


def _grid(page: Any) -> float:
    return float(page.locator("#canvas").get_attribute("data-grid"))


def test_pasted_coordinates_are_seen_whole(server: str, page: Any) -> None:
    page.goto(server + "/")
    assert _grid(page) == 5  # the default view: 0-100 mm on a 5 mm grid
    page.fill("#coords", "\n".join(f"{x:g}, {y:g}" for x, y in LEVER))
    page.click("#use-coords")
    circles = _circles(page)
    assert len(circles) == 4 and _inside(circles)
    # framed with the margin of 24 px: the long side spans 352 px
    xs = [x for x, _ in circles]
    assert max(xs) - min(xs) == pytest.approx(352, abs=1e-6)
    assert _grid(page) in (10, 20)  # a round step of about 20 px
    assert page.locator("#grid-step").text_content() == f"{_grid(page):g} mm"


def test_the_address_frames_a_large_part(server: str, page: Any) -> None:
    v = ";".join(f"{x:g},{y:g}" for x, y in LEVER)
    page.goto(server + f"/#v={v}")
    page.wait_for_selector("#canvas circle.vertex")
    assert _inside(_circles(page))


def test_wheel_zooms_about_the_pointer_and_shift_drag_pans(server: str, page: Any) -> None:
    page.goto(server + "/")
    page.fill("#coords", "25, 25\n75, 25\n40, 70")
    page.click("#use-coords")  # inside the default view: it stays
    assert _circles(page) == [(100, 300), (300, 300), (160, 120)]
    under = page.evaluate("() => toPart(100, 300)")
    assert under == [25, 25]
    page.mouse.move(*_at(page, 100, 300))
    for _ in range(4):
        page.mouse.wheel(0, 100)  # out: 1.25 ** 4 = 2.44 times more of the plane
    page.wait_for_function("() => document.querySelector('#canvas').dataset.grid !== '5'")
    # the point under the pointer stays (to the pointer's rounding to a whole screen pixel)
    assert page.evaluate("() => toPart(100, 300)") == pytest.approx(under, abs=0.5)
    circles = _circles(page)
    assert circles[0] == pytest.approx((100, 300), abs=1)  # the vertex under it stayed
    assert circles[1][0] - circles[0][0] == pytest.approx(200 / 1.25**4)
    assert _grid(page) == 10
    # shift+drag: the plane moves with the pointer; no vertex is added
    page.keyboard.down("Shift")
    page.mouse.move(*_at(page, 200, 200))
    page.mouse.down()
    page.mouse.move(*_at(page, 260, 170), steps=4)
    page.mouse.up()
    page.keyboard.up("Shift")
    moved = _circles(page)
    assert len(moved) == 3
    for (x0, y0), (x1, y1) in zip(circles, moved, strict=True):
        assert (x1 - x0, y1 - y0) == pytest.approx((60, -30), abs=1e-3)
    # a click adds the grid point under it, in the zoomed and panned view
    page.mouse.click(*_at(page, 330, 330))
    want = page.evaluate(
        "() => { const s = gridStep(); return toPart(330, 330).map((v) => Math.round(v / s) * s); }"
    )
    last = page.locator("#coords").input_value().splitlines()[-1]
    assert [float(v) for v in last.split(",")] == pytest.approx(want)
    # Fit frames the drawn part; Clear goes back to the 5 mm grid
    page.click("#fit")
    assert _inside(_circles(page))
    page.click("#clear")
    assert _grid(page) == 5
    assert page.evaluate("() => toPart(0, 400)") == [0, 0]


def test_catalogue_parts_are_framed_and_zoomable(server: str, page: Any) -> None:
    page.goto(server + "/#part=hand")  # 165 x 187 mm: larger than the default view
    page.wait_for_selector("#given-part")

    def box() -> list[float]:
        return page.evaluate(  # type: ignore[no-any-return]
            """() => { const b = document.getElementById('given-part').getBBox();
                       return [b.x, b.y, b.x + b.width, b.y + b.height]; }"""
        )

    b = box()
    assert 0 <= b[0] < b[2] <= 400 and 0 <= b[1] < b[3] <= 400
    assert max(b[2] - b[0], b[3] - b[1]) == pytest.approx(352, abs=0.5)
    page.mouse.move(*_at(page, 200, 200))
    page.mouse.wheel(0, -100)  # in: the part grows about the pointer
    z = box()
    assert z[2] - z[0] == pytest.approx((b[2] - b[0]) / 0.8, rel=1e-6)
    # another catalogue part is framed again
    page.select_option("#catalogue", "ic-chip")
    page.wait_for_function("() => state.catalogue === 'ic-chip'")
    c = box()
    assert 0 <= c[0] < c[2] <= 400 and c[2] - c[0] == pytest.approx(352, abs=0.5)


def test_drawing_a_new_part_clears_the_results_of_the_old(server: str, page: Any) -> None:
    page.goto(server + "/#part=house")
    page.wait_for_selector("#plans tbody tr")
    page.mouse.click(*_at(page, 100, 300))  # the first vertex of a new part
    page.wait_for_function("() => document.querySelectorAll('#plans tbody tr').length === 0")
    assert page.locator("#anim-plan option").count() == 0
    assert "add at least three vertices" in page.locator("#status").text_content()
    assert page.evaluate("() => state.last") is None
