"""Simulation jobs: queued, run in a worker, polled for progress and the result."""

from __future__ import annotations

import time
from typing import Any

import pytest


def _wait(client: Any, url: str, seconds: float = 120) -> dict[str, Any]:
    deadline = time.monotonic() + seconds
    while True:
        doc: dict[str, Any] = client.get(url).json()
        if doc["status"] in ("done", "failed") or time.monotonic() > deadline:
            return doc
        time.sleep(0.1)


def test_a_kinematic_job_gives_the_simulate_document(client: Any) -> None:
    body = {"part": {"catalogue": "key"}, "engine": "kinematic", "trials": 20000, "seed": 3}
    r = client.post("/api/v1/simulate/jobs", json=body)
    assert r.status_code == 202, r.text
    job = r.json()
    assert job["status"] == "queued" and job["progress"]["total"] == 20000
    assert r.headers["location"] == job["url"] == f"/api/v1/simulate/jobs/{job['id']}"
    doc = _wait(client, job["url"])
    assert doc["status"] == "done", doc
    assert doc["progress"] == {"done": 20000, "total": 20000, "fraction": 1.0}
    # the same document as the simulate endpoint (and so the command line) gives
    direct = client.post(
        "/api/v1/simulate", json={"part": {"catalogue": "key"}, "trials": 20000, "seed": 3}
    ).json()
    result = doc["result"]
    assert result["observed_success"] == direct["observed_success"]
    assert result["per_orientation"] == direct["per_orientation"]
    assert result["provenance"]["engine"] == "kinematic"


def test_a_failed_job_says_why(make_client: Any) -> None:
    client = make_client(max_mujoco_trials=10)
    r = client.post("/api/v1/simulate/jobs", json={"part": {"catalogue": "key"}, "trials": 11})
    doc = _wait(client, r.json()["url"])
    assert doc["status"] == "failed"
    assert doc["error"] == {
        "status": 422,
        "error": "limit",
        "detail": "`trials` is 11; the limit is 10",
    }


def test_a_job_past_its_time_limit_is_stopped(make_client: Any) -> None:
    client = make_client(job_time_limit=0.5)
    body = {"part": {"catalogue": "hand"}, "engine": "kinematic", "trials": 10**6}
    doc = _wait(client, client.post("/api/v1/simulate/jobs", json=body).json()["url"])
    assert doc["status"] == "failed"
    assert doc["error"]["status"] == 503 and "time limit of 0.5 s" in doc["error"]["detail"]


def test_an_unknown_job_is_404(client: Any) -> None:
    r = client.get("/api/v1/simulate/jobs/nope")
    assert r.status_code == 404
    assert r.json()["error"] == "not-found"


def test_old_jobs_make_room(make_client: Any) -> None:
    client = make_client(max_jobs=2)
    body = {"part": {"catalogue": "triangle"}, "engine": "kinematic", "trials": 100}
    urls = []
    for _ in range(3):
        urls.append(client.post("/api/v1/simulate/jobs", json=body).json()["url"])
        assert _wait(client, urls[-1])["status"] == "done"
    assert client.get(urls[0]).status_code == 404  # the oldest finished job went
    assert client.get(urls[2]).json()["status"] == "done"


@pytest.mark.physics
def test_a_mujoco_job_reports_progress(client: Any) -> None:
    pytest.importorskip("mujoco")
    body = {"part": {"catalogue": "triangle"}, "engine": "mujoco", "trials": 8, "seed": 1}
    r = client.post("/api/v1/simulate/jobs?", json=body)
    assert r.status_code == 202, r.text
    doc = _wait(client, r.json()["url"], seconds=600)
    assert doc["status"] == "done", doc
    assert doc["result"]["engine"] == "mujoco"
    assert doc["result"]["trials"] == 8
    assert doc["progress"]["done"] == 8
