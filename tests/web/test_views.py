"""The saved views of the gallery: save, page, refresh; only what the user saved."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from bayesgrasp.web.app import create_app


def test_saved_views_are_paged_newest_first(client: Any) -> None:
    assert client.get("/api/v1/saved").json()["total"] == 0
    # an automatic plan does not make a saved entry
    assert client.post("/api/v1/plan", json={"part": {"catalogue": "house"}}).status_code == 200
    assert client.get("/api/v1/saved").json()["total"] == 0
    ids = []
    for i in range(5):
        body = {
            "name": f"p{i}",
            "view": f"part=house&verify_cost={i}&squeeze_cost=2",
            "outline": [[0, 0], [1, 0], [0, 1]],
            "summary": {"success_probability": 0.5, "expected_cost": 4.0 + i, "plan": "S"},
        }
        r = client.post("/api/v1/saved", json=body)
        assert r.status_code == 200
        ids.append(r.json()["id"])
    first = client.get("/api/v1/saved", params={"page": 1, "per_page": 2}).json()
    assert first["total"] == 5 and [r["name"] for r in first["rows"]] == ["p4", "p3"]
    last = client.get("/api/v1/saved", params={"page": 3, "per_page": 2}).json()
    assert [r["name"] for r in last["rows"]] == ["p0"]
    assert last["rows"][0]["view"] == "part=house&verify_cost=0&squeeze_cost=2"
    assert last["rows"][0]["summary"]["expected_cost"] == 4.0
    assert last["rows"][0]["id"] == ids[0]
    # saving the same view again refreshes it, no duplicate
    again = {"name": "p0", "view": last["rows"][0]["view"], "outline": [[0, 0], [1, 0], [0, 1]]}
    assert client.post("/api/v1/saved", json=again).json()["id"] == ids[0]
    top = client.get("/api/v1/saved", params={"per_page": 1}).json()
    assert top["total"] == 5 and top["rows"][0]["name"] == "p0"


def test_bad_saves_are_422(client: Any) -> None:
    r = client.post("/api/v1/saved", json={"name": "", "view": "x", "outline": []})
    assert r.status_code == 422 and isinstance(r.json()["detail"], str)
    r = client.post("/api/v1/saved", json={"name": "a", "view": "x", "outline": [], "z": 1})
    assert r.status_code == 422
    assert client.get("/api/v1/saved", params={"per_page": 0}).status_code == 422


def test_no_gallery_without_a_data_folder() -> None:
    from fastapi.testclient import TestClient

    with TestClient(create_app()) as c:
        assert c.get("/api/v1/saved").json()["total"] == 0
        body = {"name": "a", "view": "part=house", "outline": []}
        assert c.post("/api/v1/saved", json=body).status_code == 404


def test_functions_and_beliefs_agree_with_the_plan(client: Any, cli_json: Any) -> None:
    """The last belief's mass at the final orientation is the plan's success probability."""
    from pathlib import Path

    peanut = Path(__file__).resolve().parents[2] / "examples" / "peanut.svg"
    for part, args in (
        ({"catalogue": "house"}, ["house"]),
        ({"catalogue": "key"}, ["key", "--prior", "vonmises:30,4"]),
    ):
        body: dict[str, Any] = {"part": part}
        if len(args) > 1:
            body["prior"] = args[2]
        r = client.post("/api/v1/views/functions", json=body)
        assert r.status_code == 200, r.text
        doc = r.json()
        _, want = cli_json("plan", *args)
        bayes = want["options"][want["bayes"]]
        assert len(doc["belief"]) == len(bayes["steps"])
        assert abs(sum(a["probability"] for a in doc["belief"][0]) - 1) < 1e-9
        final = doc["plan"]["final_deg"]
        mass = sum(
            a["probability"]
            for a in doc["belief"][-1]
            if abs((a["orientation_deg"] - final + 180) % 360 - 180) < 1e-6
        )
        assert abs(mass - bayes["success_probability"]) < 1e-9
        assert len(doc["functions"]["diameter"]) == len(doc["theta_deg"]) == 721
        for name in ("squeeze", "push", "push_grasp"):
            assert set(doc["functions"][name]) <= {
                round(x % 360, 4) for x in doc["stable_deg"][name]
            } | {round(x, 4) for x in doc["functions"][name]}
    import base64

    data = base64.b64encode(peanut.read_bytes()).decode()
    r = client.post(
        "/api/v1/views/functions", json={"part": {"file": {"format": "svg", "data_base64": data}}}
    )
    assert r.status_code == 200, r.text
    assert r.json()["plan"]["success_probability"] == 0.5


NOISE_CELLS: dict[str, tuple[dict[str, Any], list[str]]] = {
    "turn normal": ({"turn_noise": "normal:2"}, ["--turn-noise", "normal:2"]),
    "turn uniform": ({"turn_noise": "uniform:3"}, ["--turn-noise", "uniform:3"]),
    "contact": ({"contact_noise": 0.2}, ["--contact-noise", "0.2"]),
}


@pytest.mark.parametrize("name", list(NOISE_CELLS))
def test_beliefs_under_noise_follow_the_noise_aware_plan(
    name: str, client: Any, cli_json: Any
) -> None:
    """With noise the beliefs are those of the noise-aware plan, exact under the noise.

    The final belief's mass at the plan's final orientation is the success probability
    ``plan --turn-noise ... --json`` gives that plan; the beliefs are distributions; and a
    sampled check: the kinematic simulation of the plan under the noise lands on the goal as
    often (``bayesgrasp simulate --json``, 40,000 trials, within 5 standard errors).
    """
    body, args = NOISE_CELLS[name]
    r = client.post("/api/v1/views/functions", json={"part": {"catalogue": "key"}, **body})
    assert r.status_code == 200, r.text
    doc = r.json()
    _, want = cli_json("plan", "key", *args)
    bayes = want["options"][want["bayes"]]
    assert doc["plan"]["planner"] == "noise-aware" and doc["plan"]["noise"]
    assert [s["type"] for s in doc["plan"]["steps"]] == [s["type"] for s in bayes["steps"]]
    assert len(doc["belief"]) == len(bayes["steps"])
    for b in doc["belief"]:
        assert abs(sum(a["probability"] for a in b) - 1) < 1e-9
    final = doc["plan"]["final_deg"]
    assert abs(math.radians(final) - bayes["final_orientation_rad"]) < 1e-9
    mass = sum(
        a["probability"]
        for a in doc["belief"][-1]
        if abs((a["orientation_deg"] - final + 180) % 360 - 180) < 1e-6
    )
    assert abs(mass - bayes["success_probability"]) < 1e-9
    assert abs(doc["plan"]["success_probability"] - bayes["success_probability"]) < 1e-12
    _, sim = cli_json("simulate", "key", *args, "--trials", "40000", "--seed", "1")
    p_hat = sim["observed_success"]
    assert abs(p_hat - mass) < 5 * math.sqrt(mass * (1 - mass) / 40000) + 1e-9


def test_beliefs_with_a_payoff_and_without_noise(client: Any) -> None:
    """A payoff alone: the noise-aware planner's plan; no noise: the noise-free plan."""
    root = Path(__file__).resolve().parents[2]
    payoff = json.loads((root / "tests/snapshots/parts/payoff-key.json").read_text("utf-8"))
    part = {"catalogue": "key"}
    doc = client.post("/api/v1/views/functions", json={"part": part, "payoff": payoff}).json()
    assert doc["plan"]["planner"] == "noise-aware" and doc["plan"]["payoff"] is True
    plan = client.post("/api/v1/plan", json={"part": part, "payoff": payoff}).json()
    bayes = plan["options"][plan["bayes"]]
    assert [s["type"] for s in doc["plan"]["steps"]] == [s["type"] for s in bayes["steps"]]
    free = client.post("/api/v1/views/functions", json={"part": part}).json()
    assert free["plan"]["planner"] == "noise-free" and free["plan"]["noise"] is None
    r = client.post(
        "/api/v1/views/functions",
        json={"part": part, "turn_noise": "normal:2", "plan": "guaranteed"},
    )
    assert r.status_code == 422 and "unbounded" in r.json()["detail"]
