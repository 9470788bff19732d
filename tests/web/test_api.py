"""The API answers with the documents the command line prints with --json."""

from __future__ import annotations

import base64
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from bayesgrasp.shapes import names

CATALOGUE = names()
CliJson = Callable[..., tuple[int, Any]]
FIG_FORMATS = {"png": b"\x89PNG", "svg": b"<svg"}


def cli_args(options: dict[str, Any]) -> list[str]:
    """The command-line options of an API body's options."""
    args: list[str] = []
    for key, value in options.items():
        if key == "costs":
            for name, cost in value.items():
                args += [f"--{name}-cost", str(cost)]
        elif key == "first_costs":
            for name, cost in value.items():
                args += [f"--first-{name}-cost", str(cost)]
        elif key == "max_actions":
            args += ["--max-squeezes", str(value)]
        elif key == "guaranteed":
            args += ["--guaranteed"] if value else []
        elif key == "noise_kind":
            args += ["--noise-kind", value]
        elif key == "plan":
            args += ["--plan", value]
        else:
            args += [f"--{key.replace('_', '-')}", str(value)]
    return args


def random_vertices(rng: np.random.Generator, n: int) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in rng.uniform(-50, 50, size=(n, 2))]


def write_part(tmp_path: Path, vertices: list[list[float]], name: str = "part") -> str:
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps({"vertices": vertices}))
    return str(path)


@pytest.mark.parametrize("name", CATALOGUE)
@pytest.mark.parametrize("command", ["squeeze", "push", "plan"])
def test_catalogue_equals_cli(
    client: TestClient, cli_json: CliJson, name: str, command: str
) -> None:
    r = client.post(f"/api/v1/{command}", json={"part": {"catalogue": name}})
    assert r.status_code == 200, r.text
    code, doc = cli_json(command, name)
    assert code == 0
    assert r.json() == doc


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("command", ["squeeze", "push", "plan"])
def test_random_parts_equal_cli(
    client: TestClient, cli_json: CliJson, tmp_path: Path, seed: int, command: str
) -> None:
    rng = np.random.default_rng(seed)
    vertices = random_vertices(rng, int(rng.integers(3, 12)))
    r = client.post(f"/api/v1/{command}", json={"part": {"vertices": vertices}})
    code, doc = cli_json(command, write_part(tmp_path, vertices))
    assert r.status_code == (200 if code == 0 else 422), r.text
    assert r.json() == doc


PLAN_OPTIONS = [
    {"prior": "vonmises:30,4"},
    {"costs": {"squeeze": 2.5}, "verify_cost": 0.5, "retry_cost": 1.0},
    {"first_costs": {"squeeze": 5.0}},
    {"actions": "squeeze,push-grasp", "costs": {"push-grasp": 3.0}},
    {"actions": "push-grasp"},
    {"accuracy": 2.0},
    {"goal": "symmetry"},
    {"method": "bfs"},
    {"max_actions": 2},
    {"guaranteed": True},
    {"guaranteed": True, "accuracy": 30.0},
    {"method": "bfs", "max_actions": 3, "prior": "vonmises:-80,1.5", "goal": "symmetry"},
]


@pytest.mark.parametrize("options", PLAN_OPTIONS, ids=lambda o: ",".join(o))
@pytest.mark.parametrize("name", ["triangle", "house", "key"])
def test_plan_options_equal_cli(
    client: TestClient, cli_json: CliJson, name: str, options: dict[str, Any]
) -> None:
    r = client.post("/api/v1/plan", json={"part": {"catalogue": name}, **options})
    code, doc = cli_json("plan", name, *cli_args(options))
    assert code in (0, 1)
    assert r.status_code == 200, r.text
    assert r.json() == doc


def test_actions_as_a_list(client: TestClient, cli_json: CliJson) -> None:
    body = {"part": {"catalogue": "house"}, "actions": ["squeeze", "push-grasp"]}
    r = client.post("/api/v1/plan", json=body)
    assert r.json() == cli_json("plan", "house", "--actions", "squeeze,push-grasp")[1]


@pytest.mark.parametrize("kind", ["histogram", "sample"])
def test_inline_priors_equal_prior_files(
    client: TestClient, cli_json: CliJson, tmp_path: Path, kind: str
) -> None:
    values = [1.0, 3.0, 0.5, 2.0, 4.0, 1.0] if kind == "histogram" else [10.0, 12.5, 200.0, 95.0]
    path = tmp_path / "prior.txt"
    path.write_text(" ".join(map(str, values)))
    r = client.post("/api/v1/plan", json={"part": {"catalogue": "house"}, f"prior_{kind}": values})
    assert r.status_code == 200, r.text
    assert r.json() == cli_json("plan", "house", "--prior", f"{kind}:{path}")[1]


@pytest.mark.parametrize(
    "options",
    [
        {"trials": 5000},
        {"trials": 3000, "plan": "most-certain", "seed": 7},
        {"trials": 2000, "plan": "guaranteed", "noise": 1.5, "noise_kind": "uniform"},
        {"trials": 2000, "actions": "squeeze,push-grasp", "prior": "vonmises:20,3"},
    ],
)
def test_simulate_equals_cli(
    client: TestClient, cli_json: CliJson, options: dict[str, Any]
) -> None:
    r = client.post("/api/v1/simulate", json={"part": {"catalogue": "house"}, **options})
    assert r.status_code == 200, r.text
    code, doc = cli_json("simulate", "house", "--engine", "kinematic", *cli_args(options))
    assert code == 0
    got = r.json()
    assert got.pop("seconds") >= 0
    doc.pop("seconds")
    assert got == doc


@pytest.mark.parametrize("fmt", ["png", "svg"])
@pytest.mark.parametrize("figure", ["part", "diameter", "transfer", "plan"])
def test_figures(client: TestClient, figure: str, fmt: str) -> None:
    body = {"part": {"catalogue": "triangle"}, "actions": "squeeze,push-grasp"}
    r = client.post(f"/api/v1/figures/{figure}.{fmt}", json=body)
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("image/png" if fmt == "png" else "image/svg")
    assert FIG_FORMATS[fmt] in r.content[:400]


@pytest.mark.parametrize(
    "options",
    [
        {},
        {"turn_noise": "normal:2"},
        {"contact_noise": 0.2, "plan": "most-certain"},
        {"turn_noise": "uniform:3", "plan": "guaranteed"},
    ],
)
def test_figures_are_the_cli_plot_files(
    client: TestClient, tmp_path: Path, options: dict[str, Any]
) -> None:
    """Each figure is the PNG ``bayesgrasp plot`` writes with the same options, byte for byte."""
    from bayesgrasp.cli import main

    args = ["--actions", "squeeze,push-grasp"]
    for key, flag in [("turn_noise", "--turn-noise"), ("contact_noise", "--contact-noise")]:
        if key in options:
            args += [flag, str(options[key])]
    args += ["--plan", options.get("plan", "bayes")]
    out = tmp_path / "figs"
    code = main(
        ["plot", "key", *args, "--out", str(out), "--image-formats", "png", "--no-animation"]
    )
    assert code == 0
    body = {"part": {"catalogue": "key"}, "actions": "squeeze,push-grasp", **options}
    for name in ("part", "diameter", "transfer", "plan"):
        r = client.post(f"/api/v1/figures/{name}.png", json=body)
        assert r.status_code == 200, r.text
        assert r.content == (out / f"{name}.png").read_bytes(), name


def test_figure_names_are_checked(client: TestClient) -> None:
    r = client.post("/api/v1/figures/nope.png", json={"part": {"catalogue": "triangle"}})
    assert r.status_code == 422
    assert "name" in r.json()["detail"]


def _dxf_bytes() -> bytes:
    ezdxf = pytest.importorskip("ezdxf")
    import io

    doc = ezdxf.new()
    doc.modelspace().add_lwpolyline(
        [(0, 0), (40, 0), (40, 10), (10, 10), (10, 30), (0, 30)], close=True
    )
    buf = io.StringIO()
    doc.write(buf)
    return buf.getvalue().encode()


FILES = {
    "csv": b"0,0\n40,0\n15,36\n",
    "wkt": b"POLYGON ((0 0, 4 0, 4 1, 1 1, 1 3, 0 3, 0 0))",
    "geojson": json.dumps(
        {"type": "Polygon", "coordinates": [[[0, 0], [5, 0], [5, 2], [0, 3], [0, 0]]]}
    ).encode(),
    "svg": b'<svg xmlns="http://www.w3.org/2000/svg"><polygon points="0,0 30,0 10,20"/></svg>',
}


@pytest.mark.parametrize("fmt", [*FILES, "dxf"])
@pytest.mark.parametrize("command", ["plan", "push"])
def test_files_equal_cli(
    client: TestClient,
    cli_json: CliJson,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    fmt: str,
    command: str,
) -> None:
    data = FILES[fmt] if fmt in FILES else _dxf_bytes()
    (tmp_path / f"upload.{fmt}").write_bytes(data)
    monkeypatch.chdir(tmp_path)
    code, doc = cli_json(command, f"upload.{fmt}")
    assert code == 0
    part = {
        "name": "upload",
        "file": {"format": fmt, "data_base64": base64.b64encode(data).decode()},
    }
    r = client.post(f"/api/v1/{command}", json={"part": part})
    assert r.status_code == 200, r.text
    assert r.json() == doc
    up = client.post(
        f"/api/v1/{command}/upload",
        files={"file": (f"upload.{fmt}", data)},
        data={"format": fmt, "options": "{}"},
    )
    assert up.status_code == 200, up.text
    assert up.json() == doc


def test_upload_with_options(client: TestClient, cli_json: CliJson, tmp_path: Path) -> None:
    (tmp_path / "tri.csv").write_bytes(FILES["csv"])
    _, doc = cli_json("plan", str(tmp_path / "tri.csv"), "--guaranteed", "--prior", "vonmises:10,2")
    up = client.post(
        "/api/v1/plan/upload",
        files={"file": ("../../etc/tri.csv", FILES["csv"])},
        data={
            "format": "csv",
            "options": json.dumps({"guaranteed": True, "prior": "vonmises:10,2"}),
        },
    )
    assert up.status_code == 200, up.text
    assert up.json() == doc


@pytest.mark.parametrize("fmt", ["csv", "json"])
def test_an_uploaded_part_exports_the_cli_robot_file(
    client: TestClient, cli_json: CliJson, tmp_path: Path, fmt: str
) -> None:
    """``export/upload`` answers the file ``plan PART.svg --export FILE`` writes, byte for byte."""
    from bayesgrasp.cli import main

    data = FILES["svg"]
    (tmp_path / "tri.svg").write_bytes(data)
    target = tmp_path / f"robot.{fmt}"
    args = [str(tmp_path / "tri.svg"), "--prior", "vonmises:10,2", "--export", str(target)]
    assert main(["plan", *args]) == 0
    up = client.post(
        "/api/v1/export/upload",
        files={"file": ("tri.svg", data)},
        data={"format": "svg", "options": json.dumps({"format": fmt, "prior": "vonmises:10,2"})},
    )
    assert up.status_code == 200, up.text
    assert up.content == target.read_bytes()
    assert up.headers["content-disposition"] == f'attachment; filename="tri-plan.{fmt}"'
    # the robot file's format is required, as on /export
    bad = client.post(
        "/api/v1/export/upload",
        files={"file": ("tri.svg", data)},
        data={"format": "svg", "options": "{}"},
    )
    assert bad.status_code == 422 and "format" in bad.json()["detail"]


def test_catalogue_endpoint(client: TestClient) -> None:
    doc = client.get("/api/v1/catalogue").json()
    assert [p["name"] for p in doc["parts"]] == list(CATALOGUE)
    assert all(len(p["outline"]) >= 3 for p in doc["parts"])


def test_openapi_lists_the_api(client: TestClient) -> None:
    paths = client.get("/openapi.json").json()["paths"]
    for p in ("squeeze", "push", "plan", "policy", "export", "simulate", "catalogue", "saved"):
        assert f"/api/v1/{p}" in paths
    assert "/api/v1/figures/{name}.{fmt}" in paths


def test_page_and_assets(client: TestClient) -> None:
    r = client.get("/")
    assert r.status_code == 200 and '<svg id="canvas"' in r.text
    for asset in ("app.js", "style.css"):
        assert client.get(f"/static/{asset}").status_code == 200


def test_plans_are_not_recorded_and_a_curved_part_keeps_its_model(make_client: Any) -> None:
    """Planning stores nothing (no hull of a curved upload); the gallery is what users save."""
    client = make_client(gallery_rows=3)
    peanut = (Path(__file__).resolve().parents[2] / "examples" / "peanut.svg").read_bytes()
    data = base64.b64encode(peanut).decode()
    part = {"name": "peanut", "file": {"format": "svg", "data_base64": data}}
    for body in ({"part": part}, {"part": {"vertices": [[0, 0], [10, 0], [0, 7]]}}):
        assert client.post("/api/v1/plan", json=body).status_code == 200
    service = client.app.state.service  # type: ignore[attr-defined]
    assert len(service.gallery) == 0
    assert client.get("/api/v1/saved").json()["total"] == 0
    assert client.get("/api/v1/gallery").status_code == 404  # the automatic record is gone
    # the curved part planned from its exact model: 1 squeeze, p 0.5, cost 4 (its hull: 2)
    doc = client.post("/api/v1/plan", json={"part": part}).json()
    bayes = doc["options"][doc["bayes"]]
    assert (bayes["squeezes"], bayes["success_probability"]) == (1, 0.5)


@pytest.mark.parametrize("command", ["squeeze", "push"])
@pytest.mark.parametrize("prior", ["vonmises:45,2", "vonmises:-120,0.5"])
def test_prior_of_squeeze_and_push_equals_cli(
    client: TestClient, cli_json: CliJson, command: str, prior: str
) -> None:
    r = client.post(f"/api/v1/{command}", json={"part": {"catalogue": "key"}, "prior": prior})
    assert r.json() == cli_json(command, "key", "--prior", prior)[1]


def test_shape_tol_equals_cli(
    client: TestClient, cli_json: CliJson, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 16: `--shape-tol` was missing from the API; the bracket keeps 1 state of 3."""
    bracket = Path(__file__).resolve().parents[2] / "examples" / "bracket.dxf"
    (tmp_path / "bracket.dxf").write_bytes(bracket.read_bytes())
    monkeypatch.chdir(tmp_path)
    f = {"format": "dxf", "data_base64": base64.b64encode(bracket.read_bytes()).decode()}
    part = {"name": "bracket", "file": f}
    for shape_tol in (None, 0.5):
        args = [] if shape_tol is None else ["--shape-tol", str(shape_tol)]
        code, want = cli_json("squeeze", "bracket.dxf", *args)
        assert code == 0
        body = part if shape_tol is None else {**part, "shape_tol": shape_tol}
        r = client.post("/api/v1/squeeze", json={"part": body})
        assert r.status_code == 200, r.text
        assert r.json() == want
        assert len(want["stable_orientations_rad"]) == (6 if shape_tol is None else 2)
    r = client.post("/api/v1/squeeze", json={"part": {**part, "shape_tol": -1}})
    assert r.status_code == 422


def test_file_options_equal_cli(
    client: TestClient, cli_json: CliJson, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (4, 0), (0, 3)], close=True, dxfattribs={"layer": "A"})
    # (an ellipse, not a circle: a disc has no stable orientation and cannot be squeezed)
    msp.add_ellipse((0, 0), major_axis=(5, 0), ratio=0.5, dxfattribs={"layer": "B"})
    doc.saveas(tmp_path / "two.dxf")
    monkeypatch.chdir(tmp_path)
    data = (tmp_path / "two.dxf").read_bytes()
    for layer, tol in (("A", None), ("B", 0.01)):
        args = ["--layer", layer] + ([] if tol is None else ["--flatten-tol", str(tol)])
        code, want = cli_json("squeeze", "two.dxf", *args)
        assert code == 0
        f = {"format": "dxf", "data_base64": base64.b64encode(data).decode(), "layer": layer}
        if tol is not None:
            f["flatten_tol"] = tol
        r = client.post("/api/v1/squeeze", json={"part": {"name": "two", "file": f}})
        assert r.json() == want
    code, err = cli_json("squeeze", "two.dxf", "--layer", "C")
    assert code == 2
    f = {"format": "dxf", "data_base64": base64.b64encode(data).decode(), "layer": "C"}
    r = client.post("/api/v1/squeeze", json={"part": {"name": "two", "file": f}})
    assert r.status_code == 422
    assert r.json()["detail"] == err.removeprefix("bayesgrasp: error: ")
