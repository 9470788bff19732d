"""The OpenAPI schema states what the server does; schemathesis checks it on 127.0.0.1."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings

from bayesgrasp.web.app import Limits, create_app

schemathesis = pytest.importorskip("schemathesis")
uvicorn = pytest.importorskip("uvicorn")

from schemathesis.specs.openapi.checks import (  # noqa: E402
    content_type_conformance,
    response_headers_conformance,
    response_schema_conformance,
    status_code_conformance,
)

ERROR = "#/components/schemas/ErrorBody"


def test_every_post_declares_its_errors(client: Any) -> None:
    doc = client.get("/openapi.json").json()
    assert "HTTPValidationError" not in str(doc)  # FastAPI's default 422 body is not ours
    error = doc["components"]["schemas"]["ErrorBody"]
    assert error["properties"]["detail"]["type"] == "string"
    assert set(error["required"]) == {"detail", "error", "status"}
    posts = [(p, ops["post"]) for p, ops in doc["paths"].items() if "post" in ops]
    assert len(posts) >= 8
    for path, op in posts:
        for status in ("413", "422", "503"):
            content = op["responses"][status]["content"]["application/json"]
            assert content["schema"]["$ref"] == ERROR, (path, status)
        assert "Retry-After" in op["responses"]["503"]["headers"]


def test_the_part_is_exactly_one_of_three(client: Any) -> None:
    part = client.get("/openapi.json").json()["components"]["schemas"]["PartIn"]
    assert part["oneOf"] == [
        {"required": ["vertices"]},
        {"required": ["catalogue"]},
        {"required": ["file"]},
    ]
    for key in ("vertices", "catalogue", "file"):
        assert "null" not in str(part["properties"][key])


def test_a_422_body_is_as_the_schema_says(client: Any) -> None:
    for body in (
        {"part": {"catalogue": "key", "vertices": [[0, 0], [1, 0], [0, 1]]}},
        {"part": {"catalogue": "key"}, "accuracy": "x"},
        {},
    ):
        r = client.post("/api/v1/plan", json=body)
        assert r.status_code == 422
        doc = r.json()
        assert set(doc) == {"detail", "error", "status"}
        assert isinstance(doc["detail"], str) and doc["status"] == 422


def test_the_reference_pages_use_local_assets(client: Any) -> None:
    for page, assets in (
        ("/docs", ("swagger-ui-bundle.js", "swagger-ui.css")),
        ("/redoc", ("redoc.standalone.js",)),
    ):
        html = client.get(page).text
        assert "http" not in html.replace("http-equiv", "")  # nothing from a CDN
        for asset in assets:
            assert f"/static/vendor/{asset}" in html
            r = client.get(f"/static/vendor/{asset}")
            assert r.status_code == 200 and len(r.content) > 100_000
    vendor = Path(__file__).parents[2] / "src/bayesgrasp/web/static/vendor"
    assert (vendor / "swagger-ui-dist.LICENSE").exists() and (vendor / "redoc.LICENSE").exists()


# -- schemathesis against the server on 127.0.0.1 ----------------------------------------------


@pytest.fixture(scope="module")
def live_schema(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    app = create_app(
        tmp_path_factory.mktemp("data"),
        Limits(time_limit=2.0, max_trials=20_000, workers=1, quick_workers=1, queue=4),
    )
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="error"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 60
    while not server.started:
        assert time.monotonic() < deadline and thread.is_alive(), "the server did not start"
        time.sleep(0.05)
    try:
        yield schemathesis.openapi.from_url(f"http://127.0.0.1:{port}/openapi.json")
    finally:
        server.should_exit = True
        thread.join(30)


def test_the_server_does_what_its_schema_says(live_schema: Any) -> None:
    checks = [
        status_code_conformance,
        content_type_conformance,
        response_headers_conformance,
        response_schema_conformance,
    ]
    # not_a_server_error counts the declared 503 (queue full, time limit) as a failure:
    # statuses other than 503 are checked below instead
    operations = [result.ok() for result in live_schema.get_all_operations()]
    assert len(operations) >= 12
    statuses: dict[str, set[int]] = {}
    for operation in operations:

        @given(case=operation.as_strategy())
        @settings(
            max_examples=10,
            deadline=None,
            derandomize=True,
            database=None,
            suppress_health_check=list(HealthCheck),
        )
        def check(case: Any) -> None:
            response = case.call_and_validate(timeout=30, checks=checks)
            assert response.status_code < 500 or response.status_code == 503, response.text
            statuses.setdefault(case.operation.label, set()).add(response.status_code)

        check()
    assert len(statuses) == len(operations)  # every operation was called
    assert {200, 422} <= set().union(*statuses.values())
