"""Mesh parts in the HTTP API: each answer is the command line's JSON for the same file."""

from __future__ import annotations

import base64
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from .conftest import ROOT, CliJson

WEDGE = ROOT / "examples" / "meshes" / "wedge.stl"
BRACKET = ROOT / "examples" / "bracket.obj"


def _part(path: Path, **file: Any) -> dict[str, Any]:
    data = base64.b64encode(path.read_bytes()).decode()
    fmt = path.suffix.lstrip(".")
    return {"name": path.stem, "file": {"format": fmt, "data_base64": data, **file}}


@pytest.mark.parametrize("mesh", [WEDGE, BRACKET], ids=["stl", "obj"])
def test_poses_equal_cli(client: TestClient, cli_json: CliJson, mesh: Path) -> None:
    code, doc = cli_json("poses", str(mesh))
    assert code == 0
    r = client.post("/api/v1/poses", json={"part": _part(mesh)})
    assert r.status_code == 200, r.text
    assert r.json() == doc
    assert len(doc["poses"]) == 5


@pytest.mark.parametrize(
    ("mesh", "pose"), [(WEDGE, 0), (WEDGE, 3), (BRACKET, 1)], ids=["wedge0", "wedge3", "bracket1"]
)
def test_plan_of_a_pose_equals_cli(
    client: TestClient, cli_json: CliJson, mesh: Path, pose: int
) -> None:
    code, doc = cli_json("plan", str(mesh), "--pose", str(pose))
    assert code == 0
    r = client.post("/api/v1/plan", json={"part": _part(mesh, pose=pose)})
    assert r.status_code == 200, r.text
    assert r.json() == doc
    assert doc["part"]["name"] == f"{mesh.stem}-pose-{pose}"


def test_squeeze_and_default_pose_equal_cli(client: TestClient, cli_json: CliJson) -> None:
    code, doc = cli_json("squeeze", str(WEDGE))
    assert code == 0
    r = client.post("/api/v1/squeeze", json={"part": _part(WEDGE)})
    assert r.json() == doc
    # pose 0 is the default: the same answer
    r0 = client.post("/api/v1/squeeze", json={"part": _part(WEDGE, pose=0)})
    assert r0.json() == doc


def test_jaw_height_of_a_pose(client: TestClient, cli_json: CliJson) -> None:
    code, doc = cli_json("plan", str(WEDGE), "--pose", "1", "--jaw-height", "14")
    assert code == 0
    body = {"part": _part(WEDGE, pose=1), "jaw_height": 14}
    r = client.post("/api/v1/plan", json=body)
    assert r.status_code == 200, r.text
    assert r.json() == doc
    code, err = cli_json("plan", str(WEDGE), "--pose", "4", "--jaw-height", "14")
    assert code == 2 and "topples pose 4" in err
    r = client.post("/api/v1/plan", json={"part": _part(WEDGE, pose=4), "jaw_height": 14})
    assert r.status_code == 422
    assert "topples pose 4" in r.json()["detail"]
    r = client.post(
        "/api/v1/simulate", json={"part": _part(WEDGE, pose=4), "jaw_height": 14, "trials": 10}
    )
    assert r.status_code == 422 and "topples pose 4" in r.json()["detail"]


@pytest.mark.parametrize(
    "args",
    [
        {},
        {"goal_pose": "any"},
        {"goal_pose": "1", "pose_prior": "perturbed"},
        {"goal_pose": "any", "jaw_height": 5},
    ],
    ids=["default", "any", "perturbed", "jaw"],
)
def test_pose_policy_equals_cli(
    client: TestClient, cli_json: CliJson, args: dict[str, Any]
) -> None:
    flags = ["--sense", "width", "--max-actions", "2"]
    flags += [x for k, v in args.items() for x in (f"--{k.replace('_', '-')}", str(v))]
    code, doc = cli_json("plan", str(WEDGE), *flags)
    assert code == 0, doc
    body = {"part": _part(WEDGE), "sense": "width", "max_actions": 2, **args}
    r = client.post("/api/v1/policy", json=body)
    assert r.status_code == 200, r.text
    assert r.json() == doc


def test_pose_policy_jaw_height_refused_as_cli(client: TestClient, cli_json: CliJson) -> None:
    code, err = cli_json("plan", str(WEDGE), "--sense", "width", "--jaw-height", "14")
    assert code == 2 and "topples" in err
    body = {"part": _part(WEDGE), "sense": "width", "jaw_height": 14}
    r = client.post("/api/v1/policy", json=body)
    assert r.status_code == 422
    detail = r.json()["detail"]
    assert "topples" in detail and "pose 4" in detail and "\n" not in detail


CSV = b"0,0\n4,0\n4,1\n1,1\n1,3\n0,3\n"


@pytest.mark.parametrize(
    ("endpoint", "body", "words"),
    [
        ("plan", {"part": {"file": {"format": "stl", "data_base64": "c29saWQgeAo="}}}, "part.stl"),
        ("plan", {"part": {"file": {"format": "glb", "data_base64": "AAAA"}}}, "part.glb"),
        ("plan", {"part": {"file": {"format": "obj", "data_base64": "AAAA"}}}, "part.obj"),
        ("plan", {"part": _part(WEDGE, pose=5)}, "pose"),
        ("squeeze", {"part": _part(WEDGE, pose=5)}, "0 to 4"),
        (
            "plan",
            {
                "part": {
                    "file": {
                        "format": "csv",
                        "data_base64": base64.b64encode(CSV).decode(),
                        "pose": 1,
                    }
                }
            },
            "for a mesh part",
        ),
        ("plan", {"part": {"catalogue": "triangle"}, "jaw_height": 1.0}, "mesh part"),
        ("plan", {"part": _part(WEDGE), "jaw_height": -1.0}, "jaw_height"),
        ("policy", {"part": _part(WEDGE), "pose_prior": "drops:50"}, "MuJoCo drops"),
        ("policy", {"part": _part(WEDGE), "pose_prior": "poses.json"}, "reads no files"),
        ("policy", {"part": _part(WEDGE), "goal_pose": "9"}, "goal_pose"),
        ("policy", {"part": _part(WEDGE, pose=1)}, "goal_pose"),
        ("policy", {"part": {"catalogue": "triangle"}, "goal_pose": "1"}, "mesh part"),
        ("export", {"part": _part(WEDGE), "format": "csv", "goal_pose": "1"}, "add `sense`"),
        ("export", {"part": _part(WEDGE, pose=4), "format": "csv", "jaw_height": 14}, "pose 4"),
        ("figures/plan.png", {"part": _part(WEDGE, pose=4), "jaw_height": 14}, "pose 4"),
        ("views/functions", {"part": _part(WEDGE, pose=4), "jaw_height": 14}, "pose 4"),
        ("poses", {"part": {"catalogue": "triangle"}}, "mesh part"),
    ],
)
def test_bad_mesh_input_is_one_line(
    client: TestClient, endpoint: str, body: dict[str, Any], words: str
) -> None:
    r = client.post(f"/api/v1/{endpoint}", json=body)
    assert r.status_code == 422, r.text
    detail = r.json()["detail"]
    text = detail if isinstance(detail, str) else str(detail)
    assert words in text and "\n" not in text


def test_openapi_states_mesh_members(client: TestClient) -> None:
    schema = client.get("/openapi.json").json()["components"]["schemas"]
    assert "stl" in schema["FileIn"]["properties"]["format"]["enum"]
    assert "pose" in schema["FileIn"]["properties"]
    assert "jaw_height" in schema["PlanRequest"]["properties"]
    assert {"goal_pose", "pose_prior"} <= set(schema["PolicyRequest"]["properties"])
    assert "/api/v1/poses" in client.get("/openapi.json").json()["paths"]


def test_upload_of_a_mesh_equals_cli(client: TestClient, cli_json: CliJson) -> None:
    _, poses = cli_json("poses", str(WEDGE))
    up = client.post(
        "/api/v1/poses/upload",
        files={"file": ("wedge.stl", WEDGE.read_bytes())},
        data={"format": "stl"},
    )
    assert up.status_code == 200, up.text
    assert up.json() == poses
    _, doc = cli_json("plan", str(WEDGE), "--pose", "2")
    up = client.post(
        "/api/v1/plan/upload",
        files={"file": ("wedge.stl", WEDGE.read_bytes())},
        data={"format": "stl", "options": '{"pose": 2}'},
    )
    assert up.status_code == 200, up.text
    assert up.json() == doc


def test_simulate_of_a_pose_equals_cli(client: TestClient, cli_json: CliJson) -> None:
    args = ["--element", "1", "--trials", "2000", "--seed", "3", "--noise", "2"]
    code, doc = cli_json("simulate", str(BRACKET), *args)
    assert code == 0, doc
    body = {"part": _part(BRACKET, pose=1), "trials": 2000, "seed": 3, "noise": 2}
    r = client.post("/api/v1/simulate", json=body)
    assert r.status_code == 200, r.text
    got = r.json()
    got.pop("seconds")
    doc.pop("seconds")
    assert got == doc


def test_export_of_the_pose_policy_equals_cli(
    client: TestClient, cli_json: CliJson, tmp_path: Path
) -> None:
    out = tmp_path / "policy.json"
    code, _ = cli_json(
        "plan", str(WEDGE), "--sense", "width", "--goal-pose", "any", "--export", str(out)
    )
    assert code == 0
    body = {"part": _part(WEDGE), "sense": "width", "goal_pose": "any", "format": "json"}
    r = client.post("/api/v1/export", json=body)
    assert r.status_code == 200, r.text
    assert r.content == out.read_bytes()


def test_figures_of_a_pose_are_the_cli_plot_files(client: TestClient, tmp_path: Path) -> None:
    from bayesgrasp.cli import main

    out = tmp_path / "figs"
    args = ["--element", "2", "--jaw-height", "5", "--out", str(out)]
    code = main(["plot", str(BRACKET), *args, "--image-formats", "png", "--no-animation"])
    assert code == 0
    body = {"part": _part(BRACKET, pose=2), "jaw_height": 5}
    for name in ("part", "plan"):
        r = client.post(f"/api/v1/figures/{name}.png", json=body)
        assert r.status_code == 200, r.text
        assert r.content == (out / f"{name}.png").read_bytes(), name
