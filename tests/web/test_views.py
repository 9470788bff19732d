"""The saved views of the gallery: save, page, refresh; only what the user saved."""

from __future__ import annotations

from typing import Any

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
