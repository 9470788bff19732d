"""Fixtures of the web tests: the application, a test client, the CLI's JSON output."""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("fastapi", reason="the web extra is not installed")

with warnings.catch_warnings():  # starlette's notice about httpx, not about our code
    warnings.simplefilter("ignore")
    from fastapi.testclient import TestClient

from bayesgrasp.cli import main
from bayesgrasp.web.app import Limits, create_app

CliJson = Callable[..., tuple[int, Any]]


@pytest.fixture
def make_client(tmp_path: Path) -> Iterator[Callable[..., TestClient]]:
    """Build clients of apps with chosen limits (gallery in a temporary folder)."""
    clients: list[TestClient] = []

    def make(**limits: Any) -> TestClient:
        client = TestClient(create_app(tmp_path / "data", Limits(**limits)))
        client.__enter__()
        clients.append(client)
        return client

    yield make
    for c in clients:
        c.__exit__(None, None, None)


@pytest.fixture
def client(make_client: Callable[..., TestClient]) -> TestClient:
    """A client of the app with the default limits."""
    return make_client()


@pytest.fixture
def cli_json(capsys: pytest.CaptureFixture[str]) -> CliJson:
    """Run ``bayesgrasp ARGS --json``: the exit code and the parsed document (or stderr)."""

    def run(*args: str) -> tuple[int, Any]:
        capsys.readouterr()
        code = main([*args, "--json"])
        out, err = capsys.readouterr()
        if out.strip():
            return code, json.loads(out)
        return code, err.strip()

    return run
