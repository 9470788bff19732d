"""POST /api/v1/policy answers with what ``bayesgrasp plan --sense ... --json`` prints."""

from __future__ import annotations

import base64
import json
from collections.abc import Callable
from typing import Any

import pytest
from fastapi.testclient import TestClient

CliJson = Callable[..., tuple[int, Any]]


@pytest.mark.parametrize(
    ("body", "args"),
    [
        ({"part": {"catalogue": "house"}}, ["house", "--sense", "width"]),
        (
            {"part": {"catalogue": "house"}, "sense": "width:0.5,0.1", "max_actions": 2},
            ["house", "--sense", "width:0.5,0.1", "--max-actions", "2"],
        ),
        (
            {"part": {"catalogue": "key"}, "sense": "width:0.5,0.1", "accuracy": 10},
            ["key", "--sense", "width:0.5,0.1", "--accuracy", "10"],
        ),
        (
            {"part": {"catalogue": "key"}, "actions": "squeeze,push-grasp", "verify_cost": 3},
            ["key", "--sense", "width", "--actions", "squeeze,push-grasp", "--verify-cost", "3"],
        ),
        (
            {
                "part": {"catalogue": "rectangle"},
                "also": [{"catalogue": "tuning-fork"}, {"catalogue": "ic-chip"}],
                "part_prior": [1, 2, 3],
            },
            [
                *("rectangle", "--also", "tuning-fork", "--also", "ic-chip"),
                *("--sense", "width", "--part-prior", "1,2,3"),
            ],
        ),
    ],
)
def test_policy_equals_cli(
    client: TestClient, cli_json: CliJson, body: dict[str, Any], args: list[str]
) -> None:
    r = client.post("/api/v1/policy", json=body)
    code, doc = cli_json("plan", *args)
    assert code == 0 and r.status_code == 200, r.text
    assert r.json() == doc and doc["schema"] == "bayesgrasp.policy/1"


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ({"sense": "width:-1,1"}, "sigma"),
        ({"sense": "width:1,0"}, "resolution"),
        ({"sense": "camera"}, "width:SIGMA,RES"),
        ({"part_prior": [1, 2]}, "one weight per part"),
        ({"max_actions": 0}, "max_actions"),
        ({"max_actions": 5}, "max_actions"),
        ({"also": [{"catalogue": "key"}] * 4}, "also"),
        ({"also": [{"catalogue": "no-such-part"}]}, "not a catalogue part"),
    ],
)
def test_bad_policy_requests_are_one_clear_422(
    client: TestClient, body: dict[str, Any], match: str
) -> None:
    r = client.post("/api/v1/policy", json={"part": {"catalogue": "house"}, **body})
    assert r.status_code == 422
    assert match in r.json()["detail"]


def test_policy_of_an_uploaded_file(client: TestClient, cli_json: CliJson, tmp_path: Any) -> None:
    path = tmp_path / "tri.json"
    path.write_text(json.dumps({"vertices": [[0, 0], [40, 0], [10, 30]], "units": "mm"}))
    r = client.post(
        "/api/v1/policy/upload",
        files={"file": ("tri.json", path.read_bytes())},
        data={"format": "json", "options": json.dumps({"sense": "width:0.2,0.1"})},
    )
    assert r.status_code == 200, r.text
    assert r.json() == cli_json("plan", str(path), "--sense", "width:0.2,0.1")[1]
    inline = {"format": "json", "data_base64": base64.b64encode(path.read_bytes()).decode()}
    r2 = client.post(
        "/api/v1/policy", json={"part": {"name": "tri", "file": inline}, "sense": "width:0.2,0.1"}
    )
    assert r2.json() == r.json()
