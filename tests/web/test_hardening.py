"""Bad input is a 4xx with the command line's message; limits are named; never a 500."""

from __future__ import annotations

import base64
import json
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

CliJson = Callable[..., tuple[int, Any]]
PREFIX = "bayesgrasp: error: "


def cli_message(err: str) -> str:
    assert err.startswith(PREFIX), err
    return err[len(PREFIX) :]


@pytest.mark.parametrize(
    ("vertices", "options", "args"),
    [
        ([[0, 0], [1, 1], [2, 2]], {}, []),
        ([[0, 0], [1, 0]], {}, []),
        ([[0, 0], [4, 0], [0, 3]], {"prior": "vonmises:x"}, ["--prior", "vonmises:x"]),
        ([[0, 0], [4, 0], [0, 3]], {"prior": "gaussian"}, ["--prior", "gaussian"]),
        ([[0, 0], [4, 0], [0, 3]], {"actions": "pull"}, ["--actions", "pull"]),
        ([[0, 0], [4, 0], [0, 3]], {"prior": "vonmises:10,-3"}, ["--prior", "vonmises:10,-3"]),
        ([[0, 0], [1e200, 0], [0, 3]], {}, []),
        (
            [[0, 0], [4, 0], [0, 3]],
            {"costs": {"squeeze": 0}, "verify_cost": 0},
            ["--squeeze-cost", "0", "--verify-cost", "0"],
        ),
    ],
)
def test_bad_input_gives_the_cli_message(
    client: TestClient,
    cli_json: CliJson,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    vertices: list[list[float]],
    options: dict[str, Any],
    args: list[str],
) -> None:
    (tmp_path / "part.json").write_text(json.dumps({"vertices": vertices}))
    monkeypatch.chdir(tmp_path)
    code, err = cli_json("plan", "part.json", *args)
    assert code == 2
    r = client.post("/api/v1/plan", json={"part": {"vertices": vertices}, **options})
    assert r.status_code in (400, 422), r.text
    assert r.json()["detail"] == cli_message(err)


@pytest.mark.parametrize(
    ("fmt", "data"),
    [
        ("csv", b"0,0\n1,x\n"),
        ("wkt", b"POLYGON ((0 0, 1 0"),
        ("geojson", b'{"type": "Point", "coordinates": [0, 0]}'),
        ("svg", b"<svg"),
        ("dxf", b"0\nSECTION\n"),
        ("json", b""),
        ("json", b"\xff\xfe"),
        ("stl", b"solid x\n"),
        ("stl", b"\0" * 84 + b"\1"),
        ("obj", b"v 0 0 0\nf 1 2 3\n"),
        ("ply", b"ply\nformat"),
        ("3mf", b"PK\3\4"),
        ("glb", b"glTF"),
    ],
)
def test_bad_files_give_the_cli_message(
    client: TestClient,
    cli_json: CliJson,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    fmt: str,
    data: bytes,
) -> None:
    (tmp_path / f"bad.{fmt}").write_bytes(data)
    monkeypatch.chdir(tmp_path)
    code, err = cli_json("plan", f"bad.{fmt}")
    assert code == 2
    part = {"name": "bad", "file": {"format": fmt, "data_base64": base64.b64encode(data).decode()}}
    r = client.post("/api/v1/plan", json={"part": part})
    assert r.status_code in (400, 422), r.text
    assert r.json()["detail"] == cli_message(err)


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ({}, "part: Field required"),
        ({"part": {}}, "exactly one of"),
        ({"part": {"catalogue": "triangle", "vertices": [[0, 0]]}}, "exactly one of"),
        ({"part": {"catalogue": "nope"}}, "not a catalogue part"),
        ({"part": {"catalogue": "triangle"}, "costs": {"squeeze": -1}}, "costs.squeeze"),
        ({"part": {"catalogue": "triangle"}, "costs": {"pull": 1}}, "unknown action 'pull'"),
        ({"part": {"catalogue": "triangle"}, "method": "magic"}, "method"),
        ({"part": {"catalogue": "triangle"}, "bogus": 1}, "bogus: Extra inputs"),
        ({"part": {"catalogue": "triangle"}, "prior": "histogram:/etc/passwd"}, "prior_histogram"),
        ({"part": {"catalogue": "triangle"}, "prior": "sample:x.txt"}, "prior_sample"),
        ({"part": {"vertices": [[0, 0], [1, "a"], [0, 1]]}}, "part.vertices.1.1"),
        ({"part": {"vertices": [[0, 0], [1, 0], [0, 1]], "name": "../x"}}, "part.name"),
        ({"part": {"file": {"format": "csv", "data_base64": "***"}}}, "base64"),
        ({"part": {"file": {"format": "exe", "data_base64": ""}}}, "part.file.format"),
        (
            {"part": {"catalogue": "triangle"}, "prior_histogram": [1, 0], "prior_sample": [1]},
            "at most one",
        ),
        ({"part": {"catalogue": "triangle"}, "prior_histogram": [0, 0]}, "histogram"),
    ],
)
def test_bad_requests_are_422(client: TestClient, body: dict[str, Any], match: str) -> None:
    r = client.post("/api/v1/plan", json=body)
    assert r.status_code == 422, r.text
    assert match in r.json()["detail"]


@pytest.mark.parametrize(
    "raw", [b"{", b"[]", b'{"part": {"vertices": [[0, 0], [NaN, 0], [0, 1]]}}', b"\xff", b"null"]
)
def test_malformed_json_is_422(client: TestClient, raw: bytes) -> None:
    r = client.post("/api/v1/plan", content=raw, headers={"content-type": "application/json"})
    assert r.status_code in (400, 422), r.text
    assert r.json()["detail"]


def test_no_guaranteed_plan_for_simulate_is_422(client: TestClient, cli_json: CliJson) -> None:
    body = {"part": {"catalogue": "house"}, "plan": "guaranteed", "accuracy": 60, "trials": 10}
    r = client.post("/api/v1/simulate", json=body)
    code, err = cli_json("simulate", "house", "--plan", "guaranteed", "--accuracy", "60")
    assert code == 1
    assert r.status_code == 422
    assert f"bayesgrasp: {r.json()['detail']}" == err


def test_body_over_the_limit_is_413(make_client: Any) -> None:
    client = make_client(max_body_bytes=5000)
    big = {"part": {"vertices": [[i, i * i % 7] for i in range(1000)]}}
    r = client.post("/api/v1/plan", json=big)
    assert r.status_code == 413
    assert "5000 bytes" in r.json()["detail"]

    def chunks() -> Any:  # no content-length: counted as it comes
        for _ in range(10):
            yield b" " * 1000

    r = client.post("/api/v1/plan", content=chunks(), headers={"content-type": "application/json"})
    assert r.status_code == 413
    assert "5000 bytes" in r.json()["detail"]
    ok = client.post("/api/v1/plan", json={"part": {"catalogue": "triangle"}})
    assert ok.status_code == 200


def test_upload_over_the_limit_is_413(make_client: Any) -> None:
    client = make_client(max_body_bytes=2000)
    r = client.post(
        "/api/v1/plan/upload", files={"file": ("a.csv", b"0,0\n" * 1000)}, data={"format": "csv"}
    )
    assert r.status_code == 413
    assert "2000 bytes" in r.json()["detail"]


def test_too_many_vertices_is_422(make_client: Any) -> None:
    client = make_client(max_vertices=50)
    verts = [[float(i), float(i * i)] for i in range(51)]
    r = client.post("/api/v1/plan", json={"part": {"vertices": verts}})
    assert r.status_code == 422
    assert "the limit is 50" in r.json()["detail"]
    csv = "\n".join(f"{x},{y}" for x, y in verts).encode()
    part = {"file": {"format": "csv", "data_base64": base64.b64encode(csv).decode()}}
    r = client.post("/api/v1/squeeze", json={"part": part})
    assert r.status_code == 422
    assert "50" in r.json()["detail"]


def test_too_many_trials_is_422(make_client: Any) -> None:
    client = make_client(max_trials=1000)
    r = client.post("/api/v1/simulate", json={"part": {"catalogue": "triangle"}, "trials": 1001})
    assert r.status_code == 422
    assert "the limit is 1000" in r.json()["detail"]


def test_a_long_plan_is_503_and_the_server_keeps_serving(make_client: Any) -> None:
    client = make_client(time_limit=0.5, workers=1)
    slow = {"part": {"catalogue": "hand"}, "trials": 10**6}  # about a second of work
    t0 = time.perf_counter()
    r = client.post("/api/v1/simulate", json=slow)
    assert r.status_code == 503, r.text
    assert r.json()["error"] == "timeout"
    assert "time limit of 0.5 s" in r.json()["detail"]
    assert int(r.headers["retry-after"]) >= 1
    assert time.perf_counter() - t0 < 5
    health = client.get("/api/v1/health").json()
    assert health["status"] == "ok"
    assert health["lanes"]["heavy"]["killed"] >= 1
    assert client.post("/api/v1/squeeze", json={"part": {"catalogue": "key"}}).status_code == 200
    # the killed worker is replaced: the next simulation is answered
    client = make_client(time_limit=30.0, workers=1)
    r = client.post("/api/v1/simulate?timeout=0.5", json=slow)
    assert r.status_code == 503, r.text
    r = client.post("/api/v1/simulate", json={**slow, "trials": 1000})
    assert r.status_code == 200, r.text
    assert client.get("/api/v1/health").json()["lanes"]["heavy"]["live"] == 1


def test_a_request_may_ask_for_a_shorter_time_limit(make_client: Any) -> None:
    client = make_client(time_limit=5.0)
    slow = {"part": {"catalogue": "hand"}, "trials": 10**6}
    r = client.post("/api/v1/simulate?timeout=0.3", json=slow)
    assert r.status_code == 503, r.text
    assert "time limit of 0.3 s" in r.json()["detail"]
    r = client.post("/api/v1/simulate?timeout=6", json=slow)
    assert r.status_code == 422
    assert r.json()["detail"] == "`timeout` is 6 s; the server's time limit is 5 s"


def test_a_full_queue_is_503_at_once(make_client: Any) -> None:
    client = make_client(queue=0, workers=1, time_limit=5.0)
    slow = {"part": {"catalogue": "hand"}, "trials": 10**6}
    answers: list[Any] = []
    thread = threading.Thread(
        target=lambda: answers.append(client.post("/api/v1/simulate?timeout=2", json=slow))
    )
    thread.start()
    deadline = time.monotonic() + 10
    while client.get("/api/v1/health").json()["lanes"].get("heavy", {}).get("idle", 1) != 0:
        assert time.monotonic() < deadline
        time.sleep(0.05)  # the first simulation has the only heavy worker
    while client.get("/api/v1/health").json()["lanes"]["heavy"]["live"] != 1:
        time.sleep(0.05)
    t0 = time.perf_counter()
    r = client.post("/api/v1/simulate", json=slow)
    assert time.perf_counter() - t0 < 1.0
    assert r.status_code == 503
    assert r.json()["error"] == "queue-full"
    assert "the queue is full" in r.json()["detail"]
    assert "retry-after" in r.headers
    # light work has its own lane
    assert client.post("/api/v1/plan", json={"part": {"catalogue": "key"}}).status_code == 200
    thread.join(30)


# -- fuzz: the plan endpoint never answers 500 ------------------------------------------------

numbers = st.one_of(
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=False, allow_infinity=False, width=64),
    st.sampled_from([0, 1e-300, 1e300, -0.0]),
)
anything = st.recursive(
    st.none() | st.booleans() | numbers | st.text(max_size=20),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)
vertices = st.lists(st.tuples(numbers, numbers).map(list), min_size=0, max_size=12)
part = st.one_of(
    st.fixed_dictionaries({"vertices": vertices}),
    st.fixed_dictionaries({"catalogue": st.sampled_from(["triangle", "key", "nope", ""])}),
    st.fixed_dictionaries(
        {
            "file": st.fixed_dictionaries(
                {
                    "format": st.sampled_from(
                        ["csv", "json", "wkt", "svg", "dxf", "geojson", "stl", "obj", "glb"]
                    ),
                    "data_base64": st.binary(max_size=200).map(
                        lambda b: base64.b64encode(b).decode()
                    ),
                }
            )
        }
    ),
    anything,
)
plan_body = st.fixed_dictionaries(
    {"part": part},
    optional={
        "prior": st.sampled_from(["uniform", "vonmises:30,4", "vonmises:1e308,1e308", "x:"])
        | st.text(max_size=12),
        "prior_histogram": st.lists(numbers, max_size=6),
        "prior_sample": st.lists(numbers, max_size=6),
        "costs": st.dictionaries(st.sampled_from(["squeeze", "push-grasp", "x"]), numbers),
        "first_costs": st.dictionaries(st.sampled_from(["squeeze", "push-grasp"]), numbers),
        "verify_cost": numbers,
        "retry_cost": numbers,
        "jaw_height": numbers,
        "goal": st.sampled_from(["single", "symmetry", "both"]),
        "actions": st.sampled_from(["squeeze", "push-grasp", "squeeze,push-grasp", "", ","])
        | st.lists(st.text(max_size=10), max_size=3),
        "accuracy": numbers,
        "method": st.sampled_from(["exact", "bfs", "x"]),
        "max_actions": st.integers(-2, 6) | st.none(),
        "guaranteed": st.booleans() | anything,
        "extra": anything,
    },
)


@settings(max_examples=300, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(body=plan_body)
def test_fuzz_plan_never_500(make_client: Any, body: dict[str, Any]) -> None:
    client = _fuzz_client(make_client)
    r = client.post("/api/v1/plan", json=body)
    assert r.status_code in (200, 413, 422, 503), (r.status_code, r.text, body)
    doc = r.json()
    assert ("schema" in doc) if r.status_code == 200 else ("detail" in doc)


_CLIENTS: dict[int, TestClient] = {}


def _fuzz_client(make_client: Any) -> TestClient:
    # one app for all the examples of one test run (hypothesis reuses function fixtures)
    key = id(make_client)
    if key not in _CLIENTS:
        _CLIENTS.clear()
        _CLIENTS[key] = make_client(time_limit=5.0)
    return _CLIENTS[key]
