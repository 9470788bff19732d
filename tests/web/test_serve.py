"""The ``serve`` command module and the gallery's defaults."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from bayesgrasp.cli.serve import app
from bayesgrasp.web.gallery import Gallery, default_data_dir


def test_serve_help_names_the_options() -> None:
    result = CliRunner().invoke(app, ["--help"])
    assert result.exit_code == 0
    for option in (
        "--host",
        "--port",
        "--data",
        "--gallery-rows",
        "--timeout",
        "--workers",
        "--quick-workers",
        "--figure-workers",
        "--worker-memory",
        "--queue",
        "--job-timeout",
    ):
        assert option in result.output
    assert "127.0.0.1" in result.output


def test_serve_refuses_a_bad_port() -> None:
    result = CliRunner().invoke(app, ["--port", "70000"])
    assert result.exit_code == 2


@pytest.mark.parametrize(
    "args",
    [["--workers", "0"], ["--quick-workers", "0"], ["--queue", "-1"], ["--timeout", "0"]],
)
def test_serve_refuses_bad_worker_options(args: list[str]) -> None:
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output


def test_default_data_dir(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    assert default_data_dir().name == "bayesgrasp"


def test_gallery_refreshes_a_repeated_view(tmp_path: Path) -> None:
    g = Gallery(tmp_path, max_rows=2)
    tri = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    first = g.save("a", "part=house", tri, {"expected_cost": 4.0})
    g.save("b", "part=key", tri, {})
    assert g.save("a", "part=house", tri, {"expected_cost": 4.0}) == first
    assert [r["name"] for r in g.saved_page(1, 10)["rows"]] == ["a", "b"]
    assert len(g) == 2
    g.save("c", "part=lever", tri, {})
    assert [r["name"] for r in g.saved_page(1, 10)["rows"]] == ["c", "a"]
    with pytest.raises(ValueError, match="max_rows"):
        Gallery(tmp_path, max_rows=0)
