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
