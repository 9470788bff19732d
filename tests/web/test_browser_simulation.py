"""The page's simulation jobs in real headless Chromium, against ``bayesgrasp serve``.

The panel runs the plan the animation's selector names as a job (``POST /simulate/jobs``),
polls it, and shows the ``simulate --json`` document; these tests hold it to the command line
run on the same plan, seed and noise.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import urllib.parse
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.browser  # the `browser` fixture skips where Chromium is missing
ROOT = Path(__file__).resolve().parents[2]
# BAYESGRASP_SCREENSHOTS=1 retakes the documentation's screenshot of the panel
SHOTS = ROOT / "docs" / "screenshots" if os.environ.get("BAYESGRASP_SCREENSHOTS") == "1" else None
CliJson = Callable[..., tuple[int, Any]]


def _open(page: Any, url: str) -> dict[str, Any]:
    """Open the page at ``url`` and wait for its plan; the plan document it shows."""
    page.goto(url)
    page.wait_for_function("() => state.last && document.body.dataset.planned !== 'error'")
    return page.evaluate("() => state.last.plan")  # type: ignore[no-any-return]


def _simulate(page: Any) -> str:
    """Click Simulate and wait for the job's end; ``done`` or ``error``."""
    page.click("#simulate")
    page.wait_for_function("() => ['done', 'error'].includes(document.body.dataset.sim)")
    return page.evaluate("() => document.body.dataset.sim")  # type: ignore[no-any-return]


def _summary(page: Any) -> dict[str, str]:
    return page.evaluate(  # type: ignore[no-any-return]
        """() => Object.fromEntries([...document.querySelectorAll('#sim-result td[data-key]')]
            .map((td) => [td.dataset.key, td.textContent]))"""
    )


def _cli_text(*args: str) -> str:
    """What ``bayesgrasp ARGS`` prints (the table and the verdict of ``simulate``)."""
    out = subprocess.run(
        [sys.executable, "-m", "bayesgrasp.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    return out.stdout


def test_a_kinematic_job_shows_what_the_cli_prints(
    server: str, page: Any, cli_json: CliJson, tmp_path: Path
) -> None:
    plan = _open(page, server + "/#part=house&actions=squeeze,push-grasp")
    row = 2  # P P-40.86 S+23.49, success probability 0.6075 (the Bayes plan has 5 actions)
    assert row != plan["bayes"]
    page.select_option("#anim-plan", str(row))
    page.select_option("#sim-engine", "kinematic")
    page.fill("#sim-trials", "100000")
    page.fill("#sim-seed", "0")
    assert _simulate(page) == "done"
    result = page.locator("#sim-result")
    assert result.get_attribute("data-engine") == "kinematic"
    assert result.get_attribute("data-trials") == "100000"

    # the command line, on the same row written to a file (simulate --plan FILE.json)
    f = tmp_path / "row.json"
    f.write_text(json.dumps(plan["options"][row]))
    args = ("--actions", "squeeze,push-grasp", "--trials", "100000", "--seed", "0")
    code, cli = cli_json("simulate", "house", "--plan", str(f), *args)
    assert code == 0, cli
    assert float(result.get_attribute("data-observed")) == cli["observed_success"]
    assert float(result.get_attribute("data-predicted")) == cli["predicted_success"]
    assert cli["predicted_success"] == pytest.approx(
        plan["options"][row]["success_probability"], abs=1e-12
    )
    s = _summary(page)
    assert s["predicted"] == f"{cli['predicted_success']:.4f}"
    successes = round(cli["observed_success"] * 100000)
    assert s["observed"] == f"{cli['observed_success']:.4f} ({successes:,} of 100,000)"
    assert s["ci95"] == f"[{cli['ci95'][0]:.4f}, {cli['ci95'][1]:.4f}]"
    # the verdict line is the command line's, word for word
    text = _cli_text("simulate", "house", "--plan", str(f), *args)
    verdict = next(line for line in text.splitlines() if line.startswith("verdict: "))
    assert page.locator("#sim-result .verdict").text_content() == verdict
    # each final orientation's count
    counts = [
        int(c)
        for c in page.locator("#sim-result tr[data-count]").evaluate_all(
            "(trs) => trs.map((tr) => tr.dataset.count)"
        )
    ]
    assert counts == [r["count"] for r in cli["per_orientation"]]
    assert not page.locator("#sim-progress").is_visible()
    assert page.locator("#sim-status").text_content() == "done: 100,000 trials"
    if SHOTS is not None:
        page.locator("#sim-panel").screenshot(path=str(SHOTS / "web-simulation.png"))


def test_noise_reaches_the_simulation(server: str, page: Any, cli_json: CliJson) -> None:
    """Under a turn error the job runs the noise-aware Bayes plan and predicts under it."""
    plan = _open(page, server + "/#part=key&turn_noise=normal:3")
    page.select_option("#sim-engine", "kinematic")
    page.fill("#sim-trials", "30000")
    page.fill("#sim-seed", "5")
    assert _simulate(page) == "done"
    code, cli = cli_json(
        "simulate", "key", "--turn-noise", "normal:3", "--trials", "30000", "--seed", "5"
    )
    assert code == 0, cli
    bayes = plan["options"][plan["bayes"]]
    assert cli["plan"]["steps"] == bayes["steps"]  # the page's Bayes plan is the CLI's
    result = page.locator("#sim-result")
    assert float(result.get_attribute("data-predicted")) == pytest.approx(
        cli["predicted_success"], abs=1e-12
    )
    assert float(result.get_attribute("data-observed")) == cli["observed_success"]
    _, free = cli_json("plan", "key")  # noise-free: another prediction (0.484, not 0.385)
    free_p = free["options"][free["bayes"]]["success_probability"]
    assert abs(cli["predicted_success"] - free_p) > 0.01
    # typed and clicked at once: the click ends the typing, the page plans for the new error
    # and only then runs the job (which that plan would otherwise clear)
    page.fill("#turn-deg", "5")
    page.click("#simulate")
    page.wait_for_function("() => ['done', 'error'].includes(document.body.dataset.sim)")
    assert "turn_noise=normal%3A5" in page.url
    code, five = cli_json(
        "simulate", "key", "--turn-noise", "normal:5", "--trials", "30000", "--seed", "5"
    )
    assert float(result.get_attribute("data-predicted")) == pytest.approx(
        five["predicted_success"], abs=1e-12
    )
    assert five["predicted_success"] != pytest.approx(cli["predicted_success"], abs=1e-3)


def test_inputs_are_checked_before_a_job_is_sent(server: str, page: Any) -> None:
    _open(page, server + "/#part=triangle")
    sent: list[str] = []
    page.on("request", lambda r: sent.append(r.url) if "/simulate/jobs" in r.url else None)
    limits = page.evaluate("() => fetch('/api/v1/limits').then((r) => r.json())")
    page.wait_for_function("() => serverLimits !== null")
    for engine, value, message in [
        ("kinematic", "0", "trials: must be at least 1"),
        ("kinematic", "2.5", "trials: a whole number"),
        ("kinematic", "", "trials: enter a whole number"),
        (
            "kinematic",
            str(limits["max_trials"] + 1),
            f"trials: the server runs at most {limits['max_trials']:,} kinematic trials a job",
        ),
        (
            "mujoco",
            str(limits["max_mujoco_trials"] + 1),
            f"trials: the server runs at most {limits['max_mujoco_trials']:,} MuJoCo trials a job",
        ),
    ]:
        if "mujoco" not in limits["engines"] and engine == "mujoco":
            continue
        page.select_option("#sim-engine", engine)
        page.fill("#sim-trials", value)
        page.click("#simulate")
        assert page.locator("#sim-trials-error").text_content() == message
        assert page.locator("#sim-trials").get_attribute("aria-invalid") == "true"
    page.fill("#sim-trials", "10")
    page.fill("#sim-seed", "-1")
    page.click("#simulate")
    assert page.locator("#sim-seed-error").text_content() == "seed: must be at least 0"
    page.fill("#sim-seed", "0")
    if "mujoco" in limits["engines"]:
        # MuJoCo has no contact noise of the model's: said next to the engine, nothing sent
        page.select_option("#sim-engine", "mujoco")
        page.fill("#contact-noise", "0.2")
        page.click("#simulate")
        assert "contact noise applies to the kinematic engine only" in (
            page.locator("#sim-engine-error").text_content()
        )
        page.fill("#contact-noise", "")  # planned again when the next click ends the typing
    assert sent == []  # no request reached the server
    # the server's own refusal (the offset is not less than the part's size) shows beside it
    if "mujoco" in limits["engines"]:
        page.select_option("#sim-engine", "mujoco")
        page.fill("#sim-trials", "2")
        page.fill("#sim-offset", "100000")
        assert _simulate(page) == "error"
        assert "is not less than the part's size" in page.locator("#sim-status").text_content()


def test_a_new_part_or_plan_clears_the_panel(server: str, page: Any) -> None:
    plan = _open(page, server + "/#part=house")
    other = next(i for i in range(len(plan["options"])) if i != plan["bayes"])
    page.select_option("#sim-engine", "kinematic")
    page.fill("#sim-trials", "2000")
    assert _simulate(page) == "done"
    assert page.locator("#sim-result table").count() == 2
    # another row of the selector: the result was of the other plan
    page.select_option("#anim-plan", str(other))
    assert page.locator("#sim-result").inner_html() == ""
    assert _simulate(page) == "done"
    # a long job, then another part: its polling stops and the panel is empty
    page.fill("#sim-trials", "1000000")
    page.click("#simulate")
    page.wait_for_function("() => !document.querySelector('#sim-progress').hidden")
    status = page.locator("#sim-status").text_content()
    assert re.fullmatch(
        r"(submitting the job\.\.\.|(queued|running): [\d,]+ of 1,000,000 trials)", status
    )
    page.select_option("#catalogue", "triangle")
    page.wait_for_function("() => state.last && state.last.plan.part.name === 'triangle'")
    page.wait_for_timeout(1200)  # two polls' time: nothing comes back to the panel
    assert page.locator("#sim-result").inner_html() == ""
    assert page.locator("#sim-status").text_content() == ""
    assert not page.locator("#sim-progress").is_visible()
    assert page.evaluate("() => document.body.dataset.sim") is None


def test_settings_are_in_the_address(server: str, page: Any) -> None:
    url = server + "/#part=house&sim_engine=kinematic&sim_trials=1234&sim_seed=9&anim_n=40"
    plan = _open(page, url + "&anim_plan=2&anim_starts=random&anim_seed=4")
    assert plan["bayes"] != 2 and len(plan["options"]) > 2
    assert page.input_value("#sim-trials") == "1234"
    assert page.input_value("#sim-seed") == "9"
    assert page.input_value("#anim-n") == "40"
    assert page.input_value("#anim-seed") == "4"
    assert page.input_value("#anim-plan") == "2"
    page.fill("#sim-seed", "11")
    page.locator("#sim-seed").dispatch_event("change")
    query = urllib.parse.parse_qs(urllib.parse.urlsplit(page.url).fragment)
    assert query["sim_seed"] == ["11"] and query["sim_trials"] == ["1234"]
    assert query["anim_plan"] == ["2"]
    # another part's plan starts from its Bayes plan again
    page.select_option("#catalogue", "triangle")
    page.wait_for_function("() => state.last && state.last.plan.part.name === 'triangle'")
    bayes = page.evaluate("() => String(state.last.plan.bayes)")
    assert page.input_value("#anim-plan") == bayes
    assert f"anim_plan={bayes}" in page.url


def test_a_jaw_lag_reaches_a_mujoco_job(server: str, page: Any) -> None:
    """The jaw lag is MuJoCo's: checked beside its input, sent as `jaw_lag_s`."""
    _open(page, server + "/#part=triangle")
    page.wait_for_function("() => serverLimits !== null")
    if "mujoco" not in page.evaluate("() => serverLimits.engines"):
        pytest.skip("MuJoCo is not installed")
    assert page.locator("#sim-lag").is_disabled()  # kinematic: no jaws to lag
    page.select_option("#sim-engine", "mujoco")
    page.fill("#sim-lag", "-1")
    page.click("#simulate")
    assert page.locator("#sim-lag-error").text_content() == "jaw lag: must be at least 0"
    bodies: list[Any] = []
    page.on(
        "request",
        lambda r: bodies.append(json.loads(r.post_data)) if r.url.endswith("/jobs") else None,
    )
    page.fill("#sim-lag", "100")  # a push of 500 mm: the server's one line, beside Simulate
    page.fill("#sim-trials", "1")
    assert _simulate(page) == "error"
    assert bodies and bodies[-1]["jaw_lag_s"] == 100 and bodies[-1]["engine"] == "mujoco"
    assert (
        page.locator("#sim-status")
        .text_content()
        .startswith("`jaw_lag_s`: a lag of 100 s pushes the part 500 mm")
    )
    assert "sim_lag=100" in page.url


@pytest.mark.physics
def test_a_mujoco_job_from_the_page(server: str, page: Any) -> None:
    pytest.importorskip("mujoco")
    _open(page, server + "/#part=triangle")
    page.select_option("#sim-engine", "mujoco")
    assert page.input_value("#sim-trials") == "200"  # the engine's default
    page.fill("#sim-trials", "4")
    page.fill("#sim-seed", "1")
    page.click("#simulate")
    page.wait_for_function("() => document.body.dataset.sim !== 'running'", timeout=600_000)
    assert page.evaluate("() => document.body.dataset.sim") == "done"
    result = page.locator("#sim-result")
    assert result.get_attribute("data-engine") == "mujoco"
    assert result.get_attribute("data-trials") == "4"
    s = _summary(page)
    assert s["engine"].startswith("MuJoCo, 4 trials in ")
    assert "prediction_interval95" in s and "jams" in s  # every trial counted, jams shown
    assert page.locator("#sim-result .verdict").text_content().startswith("verdict: ")


def test_the_panel_fits_a_phone(server: str, browser: Any) -> None:
    context = browser.new_context(viewport={"width": 390, "height": 844})
    pg = context.new_page()
    try:
        _open(pg, server + "/#part=house&sim_engine=kinematic&sim_trials=5000")
        assert _simulate(pg) == "done"
        assert pg.locator("#sim-result table").count() == 2
        width = pg.evaluate("document.documentElement.scrollWidth")
        assert width <= 390, width
    finally:
        context.close()
