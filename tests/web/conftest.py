"""Fixtures of the web tests: the application, a test client, the CLI's JSON output, and a
served page in headless Chromium."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
import urllib.request
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
CHROMIUM = Path("/usr/bin/chromium")
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]
ROOT = Path(__file__).resolve().parents[2]


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


# ---- the page in a real browser, against `bayesgrasp serve` on a free local port ----


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _serve_command(port: int, data: Path) -> list[str]:
    from bayesgrasp.cli import COMMANDS

    args = ["--host", "127.0.0.1", "--port", str(port), "--data", str(data)]
    if "serve" in COMMANDS:
        return [sys.executable, "-m", "bayesgrasp.cli", "serve", *args]
    # until the command is listed: run the command module itself
    code = "import sys; from bayesgrasp.cli.serve import app; app(sys.argv[1:])"
    return [sys.executable, "-c", code, *args]


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The URL of a ``bayesgrasp serve`` started for these tests (stopped afterwards)."""
    port = _free_port()
    data = tmp_path_factory.mktemp("web-data")
    log = data / "serve.log"
    with log.open("wb") as out:
        proc = subprocess.Popen(
            _serve_command(port, data), stdout=out, stderr=subprocess.STDOUT, cwd=ROOT
        )
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                with urllib.request.urlopen(f"{url}/api/v1/health", timeout=1) as r:
                    if r.status == 200:
                        break
            except OSError:
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"serve did not start: {log.read_text()}") from None
                time.sleep(0.1)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    """Headless Chromium (Debian's), driven by Playwright; skipped where either is missing."""
    if not CHROMIUM.exists():
        pytest.skip(f"{CHROMIUM} is missing (apt-get install chromium); browser tests skipped")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=str(CHROMIUM), args=ARGS, headless=True)
        try:
            yield b
        finally:
            b.close()


@pytest.fixture
def page(browser: Any) -> Iterator[Any]:
    """A fresh page (1280 x 1100); the test fails if the page's script threw."""
    context = browser.new_context(viewport={"width": 1280, "height": 1100})
    context.set_default_timeout(60_000)  # a loaded CI machine; the waits end on conditions
    pg = context.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda exc: errors.append(str(exc)))
    try:
        yield pg
    finally:
        context.close()
    assert not errors, errors
