"""The page's policy and figures under the gripper's noise, in real headless Chromium.

The policy request carries the noise fieldset (``plan --sense ... --turn-noise ...``); its
tree reads as the library prints the noise-aware policy, and its robot file is the command
line's, byte for byte. The figures of ``plot`` are drawn under the noise too; results of
other options never stay on screen.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.browser  # the `browser` fixture skips where Chromium is missing


def _policy(page: Any) -> str:
    page.click("#policy")
    page.wait_for_function("() => ['done', 'error'].includes(document.body.dataset.policy)")
    return page.locator("#policy-tree").text_content()  # type: ignore[no-any-return]


def test_the_policy_is_planned_under_the_noise(
    server: str, page: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from bayesgrasp import shapes
    from bayesgrasp.cli import main
    from bayesgrasp.model import Problem
    from bayesgrasp.model.noise import NoiseModel, TurnNoise
    from bayesgrasp.planning.noisy_policy import plan_noisy_policy
    from bayesgrasp.planning.policy import plan_policy, policy_text

    pb = Problem.build(shapes.load("house"))
    page.goto(server + "/#part=house&turn_noise=normal:2&sense_depth=2")
    page.wait_for_function("() => state.last !== null")
    tree = _policy(page)
    noisy = plan_noisy_policy(pb, "width", 2, NoiseModel(TurnNoise("normal", 0.0349065850398866)))
    free = plan_policy(pb, "width", 2)
    assert tree == policy_text(noisy, min_probability=0.01)
    assert tree != policy_text(free, min_probability=0.01)  # the noise changes the policy
    summary = page.locator("#policy-summary").text_content()
    assert summary.startswith(f"expected cost {noisy.expected_cost:.4f}")
    assert summary.endswith("; under turn error normal:2 deg")
    # drawn: the root and each declaration (the page cannot follow a belief under noise)
    declarations = tree.count("declare")
    assert page.locator("#policy-nodes svg.policy-part").count() == 1 + declarations
    # its robot file is the command line's
    page.select_option("#export-format", "json")
    with page.expect_download(timeout=60_000) as info:
        page.click("#export-policy")
    got = Path(info.value.path()).read_bytes()
    want = tmp_path / "policy.json"
    args = ["house", "--sense", "width", "--max-actions", "2", "--turn-noise", "normal:2"]
    assert main(["plan", *args, "--export", str(want)]) == 0
    capsys.readouterr()
    assert got == want.read_bytes()
    # without the noise: the noise-free policy again, every node drawn
    page.select_option("#turn-kind", "")
    page.wait_for_function("() => !location.hash.includes('turn_noise')")
    text = _policy(page)
    assert text == policy_text(free, min_probability=0.01)
    assert "under" not in page.locator("#policy-summary").text_content()
    nodes = 1 + sum(text.count(w) for w in ("turn ", "declare", "reject"))
    assert (
        page.locator("#policy-nodes svg.policy-part").count() == nodes > 1 + text.count("declare")
    )


def test_a_policy_of_other_options_does_not_stay(server: str, page: Any) -> None:
    page.goto(server + "/#part=house&sense_depth=2")
    page.wait_for_function("() => state.last !== null")
    assert _policy(page).startswith("squeeze with the gripper")
    page.fill("#cost-verify", "3")
    page.locator("#cost-verify").dispatch_event("change")
    page.wait_for_function("() => location.hash.includes('verify_cost=3')")
    assert page.locator("#policy-tree").text_content() == ""
    assert page.locator("#policy-nodes").inner_html() == ""
    assert page.locator("#policy-summary").text_content() == ""
    # a policy still being planned when the options change is dropped, not shown
    page.click("#policy")
    page.fill("#cost-verify", "4")
    page.locator("#cost-verify").dispatch_event("change")
    page.wait_for_function("() => location.hash.includes('verify_cost=4')")
    page.wait_for_timeout(1500)
    assert page.evaluate("() => document.body.dataset.policy") is None
    assert page.locator("#policy-tree").text_content() == ""


def test_figures_are_drawn_under_the_noise(server: str, page: Any) -> None:
    import json

    page.goto(server + "/#part=key&turn_noise=normal:2&contact_noise=0.1")
    page.wait_for_function("() => state.last !== null")
    bodies: list[dict[str, Any]] = []
    page.on(
        "request",
        lambda r: bodies.append(json.loads(r.post_data)) if "/figures/" in r.url else None,
    )
    page.click("#figures")
    page.wait_for_function(
        "document.getElementById('fig-plan').naturalWidth > 0"
        " && document.getElementById('fig-transfer').naturalWidth > 0"
    )
    assert len(bodies) == 2
    assert all(b["turn_noise"] == "normal:2" and b["contact_noise"] == 0.1 for b in bodies)
    # (the API's figures under the noise are plot's, byte for byte: tests/web/test_api.py)
    # another option: the figures go (they were of the previous options)
    page.fill("#contact-noise", "0.2")
    page.locator("#contact-noise").dispatch_event("change")
    page.wait_for_function("() => location.hash.includes('contact_noise=0.2')")
    assert page.locator("#fig-plan").get_attribute("src") is None
    assert page.locator("#fig-transfer").get_attribute("src") is None
