"""The page's animation under the options' noise, in real headless Chromium.

Each cell draws its own turn errors and contact events, as the kinematic simulator draws them
(``bayesgrasp.sim.kinematic``): the share of cells oriented then follows the plan's success
probability under the noise, not the noise-free one, and each cell's final orientation is
the one the library's transfer functions give for the same start and draws.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

pytestmark = pytest.mark.browser  # the `browser` fixture skips where Chromium is missing
CliJson = Callable[..., tuple[int, Any]]


def _finish(page: Any) -> None:
    page.evaluate("() => drawAnimationFrame(1e9)")
    page.wait_for_selector("#anim[data-done=true]")


def _animate(page: Any, row: int, seed: int, n: int = 400) -> None:
    """Animate the table's row ``row`` from ``n`` random starts with ``seed``, to its end."""
    page.select_option("#anim-plan", str(row))
    page.select_option("#anim-starts", "random")
    page.fill("#anim-n", str(n))
    page.fill("#anim-seed", str(seed))
    page.locator("#anim-seed").dispatch_event("change")
    _finish(page)


def _cells(page: Any) -> list[dict[str, Any]]:
    raw = page.evaluate(
        """() => [...document.querySelectorAll('#anim rect')].map((r) => ({
            start: Number(r.dataset.start), final: Number(r.dataset.final),
            ok: r.dataset.ok === 'true', errors: r.dataset.errors,
            contacts: r.dataset.contacts}))"""
    )
    for c in raw:
        c["errors"] = [float(e) for e in c["errors"].split(",")] if c["errors"] else []
        c["contacts"] = c["contacts"].split(",")
    return raw  # type: ignore[no-any-return]


def _within(k: int, n: int, p: float) -> bool:
    """k successes of n near n p: within four standard deviations (about 6e-5 to fail)."""
    return abs(k - n * p) <= 4 * math.sqrt(n * p * (1 - p)) + 1


def _library_finals(name: str, actions: str, steps: list[dict[str, Any]], cells: Any) -> Any:
    """Each cell's start run through the library's transfer functions with the cell's draws."""
    from bayesgrasp import shapes
    from bayesgrasp.geometry.push import push_grasp_function
    from bayesgrasp.runs.specs import ProblemSpec

    pb = ProblemSpec(actions=tuple(actions.split(","))).build(shapes.load(name))
    grasp = push_grasp_function(pb.part, pb.states)
    out = []
    for c in cells:
        theta = np.array([c["start"]])
        for j, s in enumerate(steps):
            turned = theta - s["alpha_rad"] - c["errors"][j]
            side = c["contacts"][j] if j < len(c["contacts"]) else ""
            if side == "left" or s["type"] == "push-grasp":
                theta = grasp(turned)
            elif side == "right":
                theta = grasp(turned - math.pi) + math.pi
            else:
                theta = pb.transfer(s["type"])(turned)
        out.append(float(theta[0]))
    return out


CASES = [
    # part, the noise in the address, the CLI's options, the table's row: a plan the noise
    # hurts (its probability under the noise far from the one without)
    ("triangle", "turn_noise=normal:8", ["--turn-noise", "normal:8"], 2),
    ("allen-wrench", "contact_noise=0.8", ["--contact-noise", "0.8"], 2),
    (
        "triangle",
        "turn_noise=uniform:10&contact_noise=0.5",
        ["--turn-noise", "uniform:10", "--contact-noise", "0.5"],
        2,
    ),
]


@pytest.mark.parametrize(("name", "query", "args", "row"), CASES)
def test_the_cells_draw_the_noise(
    server: str, page: Any, cli_json: CliJson, name: str, query: str, args: list[str], row: int
) -> None:
    page.goto(server + f"/#part={name}&actions=squeeze&{query}")
    page.wait_for_function("() => state.last !== null")
    code, want = cli_json("plan", name, *args)
    assert code == 0, want
    option = want["options"][row]
    _animate(page, row, 7)
    cells = _cells(page)
    assert len(cells) == 400
    # the page's final orientations are the library's for the same starts and draws
    finals = _library_finals(name, "squeeze", option["steps"], cells)
    for c, f in zip(cells, finals, strict=True):
        gap = (c["final"] - f) / (2 * math.pi)
        assert abs(gap - round(gap)) * 2 * math.pi < 1e-6, (c, f)
    # the share oriented is the plan's probability under the noise, not the noise-free one
    k = sum(c["ok"] for c in cells)
    p = option["success_probability"]
    assert _within(k, 400, p), (k, p)
    json_row = page.evaluate(f"() => state.last.plan.options[{row}].success_probability")
    assert json_row == pytest.approx(p, abs=1e-12)
    free = page.evaluate(
        """async (o) => {
            const r = await fetch('/api/v1/simulate', {method: 'POST',
                headers: {'content-type': 'application/json'},
                body: JSON.stringify({part: {catalogue: state.catalogue}, plan: o, trials: 1})});
            return (await r.json()).predicted_success;
        }""",
        option,
    )
    assert not _within(k, 400, free), (k, free)  # the noise-free model would fail here
    status = page.locator("#anim-status").text_content()
    assert f"{k} of 400 oriented" in status and "drawn in every cell" in status
    # the draws: turn errors where there is a turn error, pushes from both sides with contacts
    errors = [e for c in cells for e in c["errors"]]
    if "turn_noise" in query:
        bound = math.radians(10) if "uniform" in query else math.inf
        assert np.std(errors) > 0 and max(abs(e) for e in errors) <= bound
    else:
        assert not any(errors)
    sides = {s for c in cells for s in c["contacts"]}
    if "contact_noise" in query:
        assert {"left", "right", ""} <= sides
        assert page.locator("#anim").get_attribute("data-push-sides") == "left,right"
    else:
        assert sides == {""}


def test_a_push_from_the_right_is_drawn_from_the_right(server: str, page: Any) -> None:
    page.goto(server + "/#part=key&actions=squeeze&contact_noise=1")
    page.wait_for_function("() => state.last !== null")
    page.select_option("#anim-starts", "random")
    page.fill("#anim-n", "16")
    page.locator("#anim-n").dispatch_event("change")
    # the push phase of the first squeeze: every cell pushes (q = 1), from its drawn side
    page.evaluate("() => drawAnimationFrame(12 + 6)")
    assert page.locator("#anim").get_attribute("data-kind") == "push"
    cells = _cells(page)
    geometry = page.evaluate(
        """() => [...document.querySelectorAll('#anim rect')].map((r) => {
            const lines = [];
            let n = r.nextElementSibling;
            while (n && n.tagName !== 'rect') {
                if (n.tagName === 'line')
                    lines.push([Number(n.getAttribute('x1')), n.getAttribute('class')]);
                n = n.nextElementSibling;
            }
            return lines;
        })"""
    )
    for c, jaws in zip(cells, geometry, strict=True):
        (_, cls_left), (_, cls_right) = sorted(jaws)  # by x: the -x jaw, then the +x jaw
        if c["contacts"][0] == "right":
            assert cls_right == "jaw pusher" and cls_left == "jaw"
        else:
            assert c["contacts"][0] == "left"
            assert cls_left == "jaw pusher" and cls_right == "jaw"
    assert {c["contacts"][0] for c in cells} == {"left", "right"}
    assert page.locator("#anim .push-arrow").count() == 16


def test_without_noise_the_cells_draw_nothing(server: str, page: Any) -> None:
    page.goto(server + "/#part=house&actions=squeeze")
    page.wait_for_function("() => state.last !== null")
    _finish(page)
    cells = _cells(page)
    assert all(not any(c["errors"]) for c in cells)
    assert all(set(c["contacts"]) == {""} for c in cells)
    assert "drawn" not in page.locator("#anim-status").text_content()


def test_a_playing_animation_keeps_the_noise_of_its_plan(server: str, page: Any) -> None:
    """Changing the noise while the animation plays: its frames keep the plan's own noise
    (they read the inputs before: a squeeze became a push with no push function, a crash)."""
    page.goto(server + "/#part=triangle&actions=squeeze")
    page.wait_for_function("() => state.last !== null")
    page.click("#play")
    page.fill("#contact-noise", "0.8")
    page.locator("#contact-noise").dispatch_event("change")
    page.wait_for_timeout(100)  # frames drawn while the next plan is scheduled
    assert page.evaluate("() => state.last.noise.contact_noise") is None
    page.wait_for_function("() => state.last && state.last.noise.contact_noise === 0.8")
    _finish(page)
    assert "contact noise 0.8, drawn in every cell" in page.locator("#anim-status").text_content()


def test_with_a_payoff_a_cell_counts_where_the_payoff_is_positive(
    server: str, page: Any, cli_json: CliJson, tmp_path: Any
) -> None:
    """The table's success under a payoff is the chance of ending where it pays; so is a cell's."""
    import json
    import urllib.parse

    payoff = {"0": 1, "180": 0.5}
    q = urllib.parse.quote(json.dumps(payoff))
    page.goto(server + f"/#part=house&actions=squeeze&turn_noise=normal:3&payoff={q}")
    page.wait_for_function("() => state.last !== null")
    f = tmp_path / "payoff.json"
    f.write_text(json.dumps({"payoff": payoff, "default": 0}))
    code, want = cli_json("plan", "house", "--turn-noise", "normal:3", "--payoff", str(f))
    assert code == 0, want
    row = 0
    p = want["options"][row]["success_probability"]
    _animate(page, row, 3)
    cells = _cells(page)
    k = sum(c["ok"] for c in cells)
    assert _within(k, 400, p), (k, p)
    final = want["options"][row]["final_orientation_rad"]
    at_final = sum(
        abs((c["final"] - final + math.pi) % (2 * math.pi) - math.pi) < 1e-6 for c in cells
    )
    assert at_final < k and not _within(at_final, 400, p)  # the final orientation alone: fewer
    assert "positive payoff" in page.locator("#anim-status").text_content()
