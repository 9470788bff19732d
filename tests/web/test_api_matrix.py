"""The option cells of ``tests/cli/test_matrix.py`` through the HTTP API.

Each set of planning options, as request members, gives the command line's ``--json``
document (the payoff inline, as a payoff file holds it), or the 422 whose reason the command
line gives with exit code 2: nothing is ignored and nothing means something else.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

CliJson = Any

ROOT = Path(__file__).resolve().parents[2]
PAYOFF = "tests/snapshots/parts/payoff-key.json"

# (request members, the command line's options)
CELLS: dict[str, tuple[dict[str, Any], list[str]]] = {
    "plain": ({}, []),
    "prior": ({"prior": "vonmises:40,4"}, ["--prior", "vonmises:40,4"]),
    "push-grasp": ({"actions": "squeeze,push-grasp"}, ["--actions", "squeeze,push-grasp"]),
    "accuracy": ({"accuracy": 2.0}, ["--accuracy", "2"]),
    "turn normal": ({"turn_noise": "normal:2"}, ["--turn-noise", "normal:2"]),
    "turn uniform": ({"turn_noise": "uniform:3"}, ["--turn-noise", "uniform:3"]),
    "contact": ({"contact_noise": 0.1}, ["--contact-noise", "0.1"]),
    "payoff": (
        {"payoff": json.loads((ROOT / PAYOFF).read_text(encoding="utf-8"))},
        ["--payoff", PAYOFF],
    ),
    "guaranteed": ({"guaranteed": True}, ["--guaranteed"]),
    "guaranteed uniform": (
        {"guaranteed": True, "turn_noise": "uniform:1"},
        ["--guaranteed", "--turn-noise", "uniform:1"],
    ),
    "guaranteed normal": (
        {"guaranteed": True, "turn_noise": "normal:2"},
        ["--guaranteed", "--turn-noise", "normal:2"],
    ),
}


def _strip_times(doc: Any) -> Any:
    if isinstance(doc, dict):
        return {k: _strip_times(v) for k, v in doc.items() if "seconds" not in k}
    if isinstance(doc, list):
        return [_strip_times(v) for v in doc]
    return doc


@pytest.mark.parametrize("name", list(CELLS))
def test_api_equals_the_command_line(
    name: str, client: Any, cli_json: CliJson, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    body, args = CELLS[name]
    r = client.post("/api/v1/plan", json={"part": {"catalogue": "key"}, **body})
    code, doc = cli_json("plan", "key", *args)
    if code == 2:
        assert r.status_code == 422, r.text
        assert "unbounded" in r.json()["detail"] and "unbounded" in doc
        return
    assert r.status_code == 200, r.text
    assert _strip_times(r.json()) == _strip_times(doc)


POLICY_CELLS: dict[str, tuple[dict[str, Any], list[str]]] = {
    "exact": ({}, []),
    "turn normal": ({"turn_noise": "normal:2"}, ["--turn-noise", "normal:2"]),
    "contact": ({"contact_noise": 0.1}, ["--contact-noise", "0.1"]),
    "payoff": (
        {"payoff": json.loads((ROOT / PAYOFF).read_text(encoding="utf-8"))},
        ["--payoff", PAYOFF],
    ),
}


@pytest.mark.parametrize("name", list(POLICY_CELLS))
def test_api_policy_equals_the_command_line(
    name: str, client: Any, cli_json: CliJson, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    body, args = POLICY_CELLS[name]
    sense = {"sense": "width:0.5,0.1", "max_actions": 2}
    r = client.post("/api/v1/policy", json={"part": {"catalogue": "key"}, **sense, **body})
    code, doc = cli_json("plan", "key", "--sense", "width:0.5,0.1", "--max-actions", "2", *args)
    assert code == 0, doc
    assert r.status_code == 200, r.text
    assert _strip_times(r.json()) == _strip_times(doc)


SIMULATE_CELLS: dict[str, tuple[dict[str, Any], list[str]]] = {
    "exact": ({}, []),
    "noise (older spelling)": ({"noise": 3.0}, ["--noise", "3"]),
    "turn uniform": ({"turn_noise": "uniform:3"}, ["--turn-noise", "uniform:3"]),
    "contact": ({"contact_noise": 0.2}, ["--contact-noise", "0.2"]),
    "guaranteed under noise": (
        {"plan": "guaranteed", "turn_noise": "uniform:2"},
        ["--plan", "guaranteed", "--turn-noise", "uniform:2"],
    ),
}


@pytest.mark.parametrize("name", list(SIMULATE_CELLS))
def test_api_simulate_equals_the_command_line(
    name: str, client: Any, cli_json: CliJson, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    body, args = SIMULATE_CELLS[name]
    run = {"trials": 20000, "seed": 3}
    r = client.post("/api/v1/simulate", json={"part": {"catalogue": "key"}, **run, **body})
    code, doc = cli_json("simulate", "key", "--trials", "20000", "--seed", "3", *args)
    assert code == 0, doc
    assert r.status_code == 200, r.text
    assert _strip_times(r.json()) == _strip_times(doc)


# the gripper's stroke: (request members, the command line's options)
STROKE_CELLS: dict[str, tuple[dict[str, Any], list[str]]] = {
    "fits": ({"max_opening": 100.0}, ["--max-opening", "100"]),
    "min": ({"min_opening": 12.0}, ["--min-opening", "12"]),
    "both": (
        {"min_opening": 5.0, "max_opening": 60.0},
        ["--min-opening", "5", "--max-opening", "60"],
    ),
    "within": (
        {"min_opening": 12.0, "within_stroke": True},
        ["--min-opening", "12", "--within-stroke"],
    ),
    "within, noise": (
        {"max_opening": 100.0, "within_stroke": True, "turn_noise": "normal:2"},
        ["--max-opening", "100", "--within-stroke", "--turn-noise", "normal:2"],
    ),
    "noise, fits": (
        {"max_opening": 100.0, "turn_noise": "normal:2"},
        ["--max-opening", "100", "--turn-noise", "normal:2"],
    ),
}
# refused with exit code 2 / 422: the reason's words both give
STROKE_REFUSED: dict[str, tuple[dict[str, Any], list[str], str]] = {
    "too narrow": ({"max_opening": 1.0}, ["--max-opening", "1"], "does not fit"),
    "within, no stroke": ({"within_stroke": True}, ["--within-stroke"], "needs the stroke"),
    "within, accuracy": (
        {"max_opening": 100.0, "within_stroke": True, "accuracy": 2.0},
        ["--max-opening", "100", "--within-stroke", "--accuracy", "2"],
        "exact turns",
    ),
    "min over max": (
        {"min_opening": 50.0, "max_opening": 40.0},
        ["--min-opening", "50", "--max-opening", "40"],
        "less than",
    ),
    "max zero": ({"max_opening": 0.0}, ["--max-opening", "0"], "must be a number > 0"),
}


@pytest.mark.parametrize("name", list(STROKE_CELLS))
def test_api_stroke_equals_the_command_line(
    name: str, client: Any, cli_json: CliJson, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    body, args = STROKE_CELLS[name]
    r = client.post("/api/v1/plan", json={"part": {"catalogue": "key"}, **body})
    code, doc = cli_json("plan", "key", *args)
    if code == 2:  # both refuse the combination
        assert r.status_code == 422, r.text
        assert "within_stroke" in r.json()["detail"] and "--within-stroke" in doc
        return
    assert code == 0, doc
    assert r.status_code == 200, r.text
    assert _strip_times(r.json()) == _strip_times(doc)


def test_within_stroke_changes_the_plans_as_on_the_command_line(client: Any) -> None:
    """Only plans the stroke allows: the most certain plan of 3 squeezes changes."""
    part = {"catalogue": "key"}
    free = client.post("/api/v1/plan", json={"part": part, "min_opening": 12.0}).json()
    within = client.post(
        "/api/v1/plan", json={"part": part, "min_opening": 12.0, "within_stroke": True}
    ).json()
    assert free["options"] != within["options"]
    assert free["bayes"] == within["bayes"]  # the Bayes plan fits the stroke already


@pytest.mark.parametrize("name", list(STROKE_REFUSED))
def test_api_stroke_refusals_equal_the_command_line(
    name: str, client: Any, cli_json: CliJson, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    body, args, words = STROKE_REFUSED[name]
    r = client.post("/api/v1/plan", json={"part": {"catalogue": "key"}, **body})
    code, doc = cli_json("plan", "key", *args)
    assert code == 2 and words in doc, doc
    assert r.status_code == 422, r.text
    assert words in r.json()["detail"]


def test_policy_takes_the_stroke_as_the_command_line(
    client: Any, cli_json: CliJson, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    sense = {"sense": "width:0.5,0.1", "max_actions": 2}
    args = ["--sense", "width:0.5,0.1", "--max-actions", "2"]
    ok = {"part": {"catalogue": "key"}, **sense, "max_opening": 100.0}
    r = client.post("/api/v1/policy", json=ok)
    code, doc = cli_json("plan", "key", *args, "--max-opening", "100")
    assert code == 0 and r.status_code == 200, r.text
    assert _strip_times(r.json()) == _strip_times(doc)
    r = client.post("/api/v1/policy", json={**ok, "max_opening": 1.0})
    code, doc = cli_json("plan", "key", *args, "--max-opening", "1")
    assert code == 2 and "does not fit" in doc
    assert r.status_code == 422 and "does not fit" in r.json()["detail"]
    r = client.post("/api/v1/policy", json={**ok, "within_stroke": True})
    code, doc = cli_json("plan", "key", *args, "--max-opening", "100", "--within-stroke")
    assert code == 2 and "a policy is checked against the stroke" in doc
    assert r.status_code == 422 and "a policy is checked against the stroke" in r.json()["detail"]


# robot files: (request members, the command line's options)
EXPORT_CELLS: dict[str, tuple[dict[str, Any], list[str]]] = {
    "plain": ({}, []),
    "accuracy": ({"accuracy": 2.0}, ["--accuracy", "2"]),
    "turn normal": ({"turn_noise": "normal:2"}, ["--turn-noise", "normal:2"]),
    "payoff": (
        {"payoff": json.loads((ROOT / PAYOFF).read_text(encoding="utf-8"))},
        ["--payoff", PAYOFF],
    ),
    "within": (
        {"min_opening": 12.0, "within_stroke": True},
        ["--min-opening", "12", "--within-stroke"],
    ),
    "policy": (
        {"sense": "width:0.5,0.1", "max_actions": 2},
        ["--sense", "width:0.5,0.1", "--max-actions", "2"],
    ),
    "policy, contact": (
        {"sense": "width:0.5,0.1", "max_actions": 2, "contact_noise": 0.1},
        ["--sense", "width:0.5,0.1", "--max-actions", "2", "--contact-noise", "0.1"],
    ),
}


@pytest.mark.parametrize("fmt", ["csv", "json"])
@pytest.mark.parametrize("name", list(EXPORT_CELLS))
def test_export_is_the_command_lines_file(
    name: str,
    fmt: str,
    client: Any,
    cli_json: CliJson,
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
) -> None:
    monkeypatch.chdir(ROOT)
    body, args = EXPORT_CELLS[name]
    r = client.post("/api/v1/export", json={"part": {"catalogue": "key"}, "format": fmt, **body})
    target = tmp_path / f"robot.{fmt}"
    code, _ = cli_json("plan", "key", *args, "--export", str(target))
    assert code == 0
    assert r.status_code == 200, r.text
    assert r.content == target.read_bytes()
    kind = "policy" if "sense" in body else "plan"
    assert r.headers["content-disposition"] == f'attachment; filename="key-{kind}.{fmt}"'
    assert r.headers["content-type"].startswith("text/csv" if fmt == "csv" else "application/json")


def test_export_refuses_what_the_command_line_refuses(client: Any) -> None:
    part = {"catalogue": "key"}
    cases = [
        ({"format": "csv", "max_opening": 1.0}, "does not fit"),
        ({"format": "csv", "also": [{"catalogue": "house"}]}, "need `sense`"),
        ({"format": "csv", "sense": "width", "guaranteed": True}, "no `guaranteed`"),
        ({"format": "csv", "sense": "width", "max_actions": 9}, "max_actions"),
        ({"format": "pdf"}, "format"),
        ({}, "format"),
    ]
    for body, words in cases:
        r = client.post("/api/v1/export", json={"part": part, **body})
        assert r.status_code == 422, (body, r.text)
        assert words in r.json()["detail"], (body, r.text)


def test_export_runs_in_the_lanes_of_its_work(client: Any) -> None:
    """An exact plan's file in the quick lane; a policy's and a noisy plan's in the heavy."""
    from bayesgrasp.web.app import lane_of
    from bayesgrasp.web.models import ExportRequest

    def lane(**body: Any) -> str:
        req = ExportRequest.model_validate({"part": {"catalogue": "key"}, "format": "csv", **body})
        return lane_of("export", req)

    assert lane() == "quick"
    assert lane(sense="width") == "heavy"
    assert lane(turn_noise="normal:1") == "heavy"
