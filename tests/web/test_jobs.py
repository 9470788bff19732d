"""Simulation jobs: queued, run in a worker, polled for progress and the result."""

from __future__ import annotations

import json
import time
from pathlib import Path
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


def test_a_request_the_server_cannot_run_is_refused_when_posted(make_client: Any) -> None:
    client = make_client(max_mujoco_trials=10, max_trials=1000)
    jobs = client.app.state.jobs.jobs
    cases = [
        ({"trials": 11}, "`trials` is 11; the limit is 10"),
        ({"engine": "kinematic", "trials": 1001}, "`trials` is 1001; the limit is 1000"),
        ({"engine": "kinematic"}, "`trials` is 100000; the limit is 1000"),  # the default
        ({"contact_noise": 0.1, "trials": 5}, "`contact_noise`: applies to the kinematic"),
        (
            {"engine": "kinematic", "trials": 5, "offset_mm": 1},
            "`offset_mm`: applies to the mujoco",
        ),
    ]
    for extra, detail in cases:
        r = client.post("/api/v1/simulate/jobs", json={"part": {"catalogue": "key"}, **extra})
        assert r.status_code == 422, (extra, r.text)
        assert r.json()["detail"].startswith(detail), r.json()
    assert not jobs  # nothing was queued
    lim = client.get("/api/v1/limits").json()
    assert lim["max_mujoco_trials"] == 10 and lim["max_trials"] == 1000
    assert lim["engines"][0] == "kinematic" and set(lim["engines"]) <= {"kinematic", "mujoco"}


def test_a_failed_job_says_why(client: Any) -> None:
    # a plan document for another part: refused by the worker that reads the part
    other = client.post("/api/v1/plan", json={"part": {"catalogue": "triangle"}}).json()
    body = {"part": {"catalogue": "key"}, "engine": "kinematic", "trials": 10, "plan": other}
    r = client.post("/api/v1/simulate/jobs", json=body)
    doc = _wait(client, r.json()["url"])
    assert doc["status"] == "failed"
    assert doc["error"]["status"] == 422 and doc["error"]["error"] == "limit"
    assert doc["error"]["detail"].startswith(
        "`plan`: the plan document is for part 'triangle' (sha256:"
    ), doc["error"]


def test_a_plan_of_the_table_runs_as_the_cli_runs_it_from_a_file(
    client: Any, cli_json: Any, tmp_path: Path
) -> None:
    """Any row of ``plan``'s answer, sent back, is the plan ``simulate --plan FILE`` runs."""
    plan = client.post("/api/v1/plan", json={"part": {"catalogue": "house"}}).json()
    row = next(i for i in range(len(plan["options"])) if i != plan["bayes"])
    option = plan["options"][row]
    f = tmp_path / "row.json"
    f.write_text(json.dumps(option))
    code, cli = cli_json("simulate", "house", "--plan", str(f), "--trials", "20000", "--seed", "3")
    assert code == 0, cli
    body = {"part": {"catalogue": "house"}, "engine": "kinematic", "trials": 20000, "seed": 3}
    doc = _wait(
        client, client.post("/api/v1/simulate/jobs", json={**body, "plan": option}).json()["url"]
    )
    assert doc["status"] == "done", doc
    result = doc["result"]
    assert result["plan"]["steps"] == option["steps"]
    assert result["predicted_success"] == pytest.approx(option["success_probability"], abs=1e-12)
    assert result["predicted_success"] != plan["options"][plan["bayes"]]["success_probability"]
    for key in ("observed_success", "per_orientation", "predicted_success", "ci95"):
        assert result[key] == cli[key], key
    assert result["provenance"]["plan"] == "request"


def test_a_whole_plan_document_keeps_its_prior_and_goal(
    client: Any, cli_json: Any, tmp_path: Path
) -> None:
    made = {"part": {"catalogue": "house"}, "prior": "vonmises:30,4", "goal": "symmetry"}
    plan = client.post("/api/v1/plan", json=made).json()
    bayes = plan["options"][plan["bayes"]]
    f = tmp_path / "plan.json"
    f.write_text(json.dumps(plan))
    code, cli = cli_json("simulate", "house", "--plan", str(f), "--trials", "5000", "--seed", "1")
    assert code == 0, cli
    body = {"part": {"catalogue": "house"}, "trials": 5000, "seed": 1, "plan": plan}
    doc = client.post("/api/v1/simulate", json=body).json()  # the direct route takes it too
    assert doc["predicted_success"] == pytest.approx(bayes["success_probability"], abs=1e-12)
    assert (
        doc["provenance"]["prior"]["kind"] == "von-mises"
        and doc["provenance"]["goal"] == "symmetry"
    )
    assert doc["observed_success"] == cli["observed_success"]
    # a prior given in the request wins over the document's
    uniform = client.post("/api/v1/simulate", json={**body, "prior": "uniform"}).json()
    assert uniform["provenance"]["prior"]["kind"] == "uniform"
    assert uniform["predicted_success"] != pytest.approx(doc["predicted_success"], abs=1e-3)


def test_a_plan_under_noise_is_predicted_under_it(
    client: Any, cli_json: Any, tmp_path: Path
) -> None:
    noisy = {"part": {"catalogue": "house"}, "turn_noise": "normal:3"}
    plan = client.post("/api/v1/plan", json=noisy).json()
    option = plan["options"][plan["bayes"]]
    f = tmp_path / "noisy.json"
    f.write_text(json.dumps(option))
    args = ("--turn-noise", "normal:3", "--trials", "20000", "--seed", "2")
    code, cli = cli_json("simulate", "house", "--plan", str(f), *args)
    assert code == 0, cli
    body = {**noisy, "engine": "kinematic", "trials": 20000, "seed": 2, "plan": option}
    doc = _wait(client, client.post("/api/v1/simulate/jobs", json=body).json()["url"])
    result = doc["result"]
    assert result["predicted_success"] == pytest.approx(option["success_probability"], abs=1e-9)
    assert result["observed_success"] == cli["observed_success"]
    assert result["agrees"] is True


def test_a_malformed_plan_is_one_line(client: Any) -> None:
    body = {"part": {"catalogue": "key"}, "trials": 10}
    for plan, detail in [
        ({"steps": []}, "`steps` must be a non-empty list"),
        ({"steps": [{"type": "squeeze", "alpha_rad": 0}]}, "a plan needs a finite"),
        ("best", "plan"),
    ]:
        r = client.post("/api/v1/simulate", json={**body, "plan": plan})
        assert r.status_code == 422, r.text
        assert detail in r.json()["detail"] and "\n" not in r.json()["detail"]


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


def test_a_job_checks_the_offset_in_millimetres(client: Any) -> None:
    """The triangle reaches 24.62 mm from its centroid: 30 mm is refused as the CLI does."""
    body = {"part": {"catalogue": "triangle"}, "engine": "mujoco", "trials": 1, "offset_mm": 30}
    doc = _wait(client, client.post("/api/v1/simulate/jobs", json=body).json()["url"])
    assert doc["status"] == "failed"
    assert doc["error"]["detail"] == (
        "`offset_mm`: 30 mm is not less than the part's size (24.62 mm from its centroid to "
        "its farthest vertex)"
    )


def test_jaw_lag_is_for_mujoco_and_bounded(client: Any) -> None:
    kin = {"part": {"catalogue": "triangle"}, "engine": "kinematic", "trials": 5, "jaw_lag_s": 1}
    r = client.post("/api/v1/simulate/jobs", json=kin)
    assert r.status_code == 422
    assert r.json()["detail"].startswith("`jaw_lag_s`: applies to the mujoco engine only")
    body = {"part": {"catalogue": "triangle"}, "engine": "mujoco", "trials": 1, "jaw_lag_s": 100}
    doc = _wait(client, client.post("/api/v1/simulate/jobs", json=body).json()["url"])
    assert doc["status"] == "failed"
    assert doc["error"]["detail"] == (
        "`jaw_lag_s`: a lag of 100 s pushes the part 500 mm, more than twice its size "
        "(24.62 mm from its centroid to its farthest vertex): give at most 9.847 s"
    )


@pytest.mark.physics
def test_a_mujoco_job_with_a_jaw_lag_is_the_cli_run(client: Any, cli_json: Any) -> None:
    pytest.importorskip("mujoco")
    args = ("--engine", "mujoco", "--jaw-lag", "2", "--trials", "6", "--seed", "4")
    code, cli = cli_json("simulate", "triangle", *args)
    assert code == 0, cli
    body = {
        "part": {"catalogue": "triangle"},
        "engine": "mujoco",
        "trials": 6,
        "seed": 4,
        "jaw_lag_s": 2,
    }
    doc = _wait(client, client.post("/api/v1/simulate/jobs", json=body).json()["url"], 600)
    assert doc["status"] == "done", doc
    result = doc["result"]
    assert result["provenance"]["jaw_lag_s"] == 2 == cli["provenance"]["jaw_lag_s"]
    assert result["per_orientation"] == cli["per_orientation"]
    assert result["jams"] == cli["jams"]
