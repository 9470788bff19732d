"""The plan endpoint with turn noise, contact noise and a payoff equals ``plan ... --json``."""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

CliJson = Callable[..., tuple[int, Any]]
PREFIX = "bayesgrasp: error: "

# (request members, plan options of the command line)
NOISE = [
    ({"turn_noise": "normal:2"}, ["--turn-noise", "normal:2"]),
    ({"turn_noise": "uniform:3"}, ["--turn-noise", "uniform:3"]),
    ({"contact_noise": 0.2}, ["--contact-noise", "0.2"]),
    (
        {"turn_noise": "normal:1.5", "contact_noise": 0.1, "max_actions": 3},
        ["--turn-noise", "normal:1.5", "--contact-noise", "0.1", "--max-squeezes", "3"],
    ),
    (
        {"turn_noise": "uniform:2", "prior": "vonmises:30,2", "retry_cost": 0.5},
        ["--turn-noise", "uniform:2", "--prior", "vonmises:30,2", "--retry-cost", "0.5"],
    ),
]


def assert_same_document(api: dict[str, Any], cli: dict[str, Any]) -> None:
    """Field by field (the message names the first field that differs), then as a whole."""
    assert sorted(api) == sorted(cli)
    for key in cli:
        assert api[key] == cli[key], key
    assert json.dumps(api, sort_keys=True) == json.dumps(cli, sort_keys=True)


@pytest.mark.parametrize("part", ["key", "example"])
def test_guaranteed_under_bounded_noise_equals_cli(
    client: TestClient, cli_json: CliJson, part: str
) -> None:
    code, doc = cli_json("plan", part, "--turn-noise", "uniform:1", "--guaranteed")
    r = client.post(
        "/api/v1/plan",
        json={"part": {"catalogue": part}, "turn_noise": "uniform:1", "guaranteed": True},
    )
    assert r.status_code == 200, r.text
    assert_same_document(r.json(), doc)
    assert code == 0 and "guaranteed" in doc


@pytest.mark.parametrize("part", ["triangle", "rectangle", "key", "hand"])
@pytest.mark.parametrize(("body", "args"), NOISE)
def test_noisy_plan_equals_cli(
    client: TestClient,
    cli_json: CliJson,
    part: str,
    body: dict[str, Any],
    args: list[str],
) -> None:
    code, doc = cli_json("plan", part, *args)
    assert code == 0, doc
    r = client.post("/api/v1/plan", json={"part": {"catalogue": part}, **body})
    assert r.status_code == 200, r.text
    api = r.json()
    assert api["method"] == "noisy"
    assert api["noise"] == doc["noise"]  # the noise is recorded, as the CLI records it
    assert_same_document(api, doc)


@pytest.mark.parametrize("as_list", [False, True])
def test_inline_payoff_equals_payoff_file(
    client: TestClient,
    cli_json: CliJson,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    as_list: bool,
) -> None:
    # the key's stable orientations, from the CLI: pay 1 on one, 0.4 on another
    _, exact = cli_json("plan", "key")
    stable = [math.degrees(x) for x in exact["stable_orientations_rad"]]
    chosen = {f"{stable[1]:.4f}": 1.0, f"{stable[4]:.4f}": 0.4}
    file_doc = {"payoff": chosen, "default": 0.1}
    (tmp_path / "u.json").write_text(json.dumps(file_doc))
    monkeypatch.chdir(tmp_path)
    code, doc = cli_json("plan", "key", "--turn-noise", "normal:1", "--payoff", "u.json")
    assert code == 0, doc
    payoff: dict[str, Any] = dict(file_doc)
    if as_list:
        payoff["payoff"] = [{"orientation_deg": float(k), "value": v} for k, v in chosen.items()]
    body = {"part": {"catalogue": "key"}, "turn_noise": "normal:1", "payoff": payoff}
    r = client.post("/api/v1/plan", json=body)
    assert r.status_code == 200, r.text
    expected = [0.1] * len(stable)  # each state's payoff
    expected[1], expected[4] = 1.0, 0.4
    assert r.json()["payoff"] == expected
    assert_same_document(r.json(), doc)


def test_payoff_alone_asks_for_the_noisy_planner(client: TestClient, cli_json: CliJson) -> None:
    payoff = {"payoff": {"0": 1.0, "90": 0.5}}
    r = client.post("/api/v1/plan", json={"part": {"catalogue": "rectangle"}, "payoff": payoff})
    assert r.status_code == 200, r.text
    assert r.json()["method"] == "noisy"
    assert r.json()["payoff"] == [1.0, 0.5, 0.0, 0.0]  # 270 deg not listed: 0


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        ({"turn_noise": "gauss:2"}, "turn_noise: must be normal:SIGMA_DEG or uniform:A_DEG"),
        ({"turn_noise": "normal:-1"}, "got 'normal:-1'"),
        ({"turn_noise": "normal"}, "turn_noise: must be"),
        ({"contact_noise": 1.5}, "contact_noise: Input should be less than or equal to 1"),
        ({"contact_noise": -0.1}, "contact_noise: Input should be greater than or equal to 0"),
        ({"payoff": {"payoff": {"x": 1}}}, "payoff.payoff: 'x' is not an orientation in degrees"),
        ({"payoff": {"payoff": {"90": 1.5}}}, "the value of 90 must be a number in [0, 1]"),
        ({"payoff": {"payoff": {"90": True}}}, "the value of 90 must be a number in [0, 1]"),
        ({"payoff": {"payoff": [{"orientation_deg": 90}]}}, 'entry #1 must be {"orientation_deg"'),
        ({"payoff": {"payoff": "90"}}, "payoff.payoff: must be an object or a list; got str"),
        ({"payoff": {"payoff": {"90": 1}, "default": 2}}, "payoff.default: Input should be less"),
        ({"payoff": {"payoff": {"90": 1}, "extra": 1}}, "payoff.extra: Extra inputs"),
        ({"payoff": {"payoff": {"90": 0}}}, "a payoff must be positive somewhere; got all zero"),
        ({"turn_noise": "normal:1", "method": "bfs"}, "seeds from the exact planner"),
        ({"turn_noise": "normal:1", "guaranteed": True}, "`guaranteed`: no plan of two"),
    ],
)
def test_bad_noise_is_422(client: TestClient, extra: dict[str, Any], match: str) -> None:
    r = client.post("/api/v1/plan", json={"part": {"catalogue": "rectangle"}, **extra})
    assert r.status_code == 422, r.text
    assert match in r.json()["detail"]


def test_payoff_off_the_states_gives_the_cli_message(
    client: TestClient,
    cli_json: CliJson,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    (tmp_path / "u.json").write_text(json.dumps({"payoff": {"45": 1}}))
    monkeypatch.chdir(tmp_path)
    code, err = cli_json("plan", "rectangle", "--payoff", "u.json")
    assert code == 2
    assert err.startswith(PREFIX), err
    r = client.post(
        "/api/v1/plan", json={"part": {"catalogue": "rectangle"}, "payoff": {"payoff": {"45": 1}}}
    )
    assert r.status_code == 422
    assert r.json()["detail"] == err[len(PREFIX) :]


def test_noisy_upload_equals_catalogue(client: TestClient) -> None:
    from bayesgrasp.shapes import entry

    vertices = [list(v) for v in entry("house").vertices]
    options = {"turn_noise": "normal:2", "contact_noise": 0.05}
    data = json.dumps({"vertices": vertices}).encode()
    r = client.post(
        "/api/v1/plan/upload",
        files={"file": ("house.json", data)},
        data={"format": "json", "options": json.dumps(options)},
    )
    assert r.status_code == 200, r.text
    direct = client.post("/api/v1/plan", json={"part": {"vertices": vertices}, **options}).json()
    assert r.json()["options"] == direct["options"]
    assert r.json()["noise"] == direct["noise"]


def _many_sided(n: int) -> list[list[float]]:
    """A convex n-gon with slightly uneven sides: n stable orientations, a heavy noisy plan."""
    out = []
    for i in range(n):
        a = 2 * math.pi * i / n + 0.004 * math.sin(7 * i)
        r = 10 + 0.5 * math.sin(3 * i) ** 2
        out.append([r * math.cos(a), r * math.sin(a)])
    return out


def test_a_heavy_noisy_plan_is_503_and_light_requests_go_on(make_client: Any) -> None:
    client = make_client(time_limit=0.5, workers=1)
    # a few seconds of work (46 states): its worker is killed at the time limit
    heavy = {"part": {"vertices": _many_sided(40)}, "turn_noise": "normal:0.5", "max_actions": 6}
    light_noisy = {"part": {"catalogue": "triangle"}, "turn_noise": "normal:2"}
    answer: dict[str, Any] = {}

    def ask() -> None:
        t0 = time.perf_counter()
        r = client.post("/api/v1/plan", json=heavy)
        answer.update(status=r.status_code, detail=r.json()["detail"], at=time.perf_counter() - t0)

    t0 = time.perf_counter()
    thread = threading.Thread(target=ask)
    thread.start()
    time.sleep(0.1)
    light = client.post("/api/v1/plan", json={"part": {"catalogue": "key"}})
    light_at = time.perf_counter() - t0
    thread.join(30)
    assert light.status_code == 200
    assert answer["status"] == 503, answer
    assert "time limit of 0.5 s" in answer["detail"]
    assert light_at < answer["at"]  # the light plan did not wait for the heavy one

    # the heavy plan's worker was killed and is replaced: noisy plans are served again
    r = client.post("/api/v1/plan", json=light_noisy, params={"timeout": 0.5})
    deadline = time.monotonic() + 30
    while r.status_code == 503 and time.monotonic() < deadline:  # a loaded machine
        r = client.post("/api/v1/plan", json=light_noisy, params={"timeout": 0.5})
    assert r.status_code == 200 and r.json()["method"] == "noisy"
    lanes = client.get("/api/v1/health").json()["lanes"]
    assert lanes["heavy"]["killed"] >= 1
    assert lanes["heavy"]["live"] <= 1


def test_a_noisy_body_over_the_limit_is_413(make_client: Any) -> None:
    client = make_client(max_body_bytes=2000)
    payoff = {"payoff": {f"{i / 10:.1f}": 0.5 for i in range(300)}}
    r = client.post(
        "/api/v1/plan",
        json={"part": {"catalogue": "key"}, "turn_noise": "normal:1", "payoff": payoff},
    )
    assert r.status_code == 413
    assert "limit of 2000 bytes" in r.json()["detail"]
