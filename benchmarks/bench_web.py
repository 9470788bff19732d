"""Load test of ``bayesgrasp serve``: plan requests from concurrent clients on localhost.

Starts the server on a free 127.0.0.1 port (a subprocess, stopped at the end), sends
``--requests`` plan requests (catalogue and random parts, several option sets) from
``--clients`` threads, checks every answer against the library's own document, and prints
p50/p99 latency and throughput.

    python benchmarks/bench_web.py [--requests 2000] [--clients 8] [--noisy]

``--noisy``: one body in four also asks for turn or contact noise (the noise-aware
planner, heavier), and the latencies of the noisy and the other requests are printed apart.
"""

from __future__ import annotations

import argparse
import json
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


NOISE: list[dict[str, Any]] = [
    {"turn_noise": "normal:1"},
    {"turn_noise": "uniform:2", "contact_noise": 0.05},
    {"contact_noise": 0.1},
]


def bodies(n_random: int = 24, noisy: bool = False) -> list[dict[str, Any]]:
    from bayesgrasp.shapes import names

    rng = np.random.default_rng(7)
    options: list[dict[str, Any]] = [
        {},
        {"prior": "vonmises:30,4"},
        {"actions": "squeeze,push-grasp", "costs": {"push-grasp": 2.0}},
        {"guaranteed": True},
    ]
    out = []
    for i, name in enumerate(names()):
        out.append({"part": {"catalogue": name}, **options[i % len(options)]})
    for i in range(n_random):
        verts = rng.uniform(-40, 40, size=(int(rng.integers(3, 10)), 2)).round(3).tolist()
        out.append({"part": {"vertices": verts}, **options[i % len(options)]})
    if noisy:  # one body in four: with noise (and so without the guaranteed plan)
        for i in range(0, len(out), 4):
            out[i] = {**out[i], **NOISE[(i // 4) % len(NOISE)]}
            out[i].pop("guaranteed", None)
    return out


def expected(body: dict[str, Any]) -> dict[str, Any]:
    """The document the library (and ``plan --json``) gives for a body."""
    from bayesgrasp.web.app import Limits, Service, plan_result_document
    from bayesgrasp.web.models import PlanRequest

    return plan_result_document(Service(Limits(), None), PlanRequest.model_validate(body))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=2000)
    ap.add_argument("--clients", type=int, default=8)
    ap.add_argument("--noisy", action="store_true", help="one body in four with noise")
    args = ap.parse_args()

    cases = bodies(noisy=args.noisy)
    want = [expected(b) for b in cases]
    port = free_port()
    data = tempfile.mkdtemp(prefix="bench-web-")
    cmd = [
        sys.executable,
        "-c",
        "import sys; from bayesgrasp.cli.serve import app; app(sys.argv[1:])",
        "--port",
        str(port),
        "--data",
        data,
    ]
    proc = subprocess.Popen(cmd, cwd=ROOT, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}/api/v1"
    try:
        for _ in range(300):
            try:
                urllib.request.urlopen(f"{url}/health", timeout=1).close()
                break
            except OSError:
                time.sleep(0.1)
        latencies: list[float] = []
        noisy_latencies: list[float] = []
        failures: list[str] = []

        def one(i: int) -> None:
            k = i % len(cases)
            req = urllib.request.Request(
                f"{url}/plan",
                data=json.dumps(cases[k]).encode(),
                headers={"content-type": "application/json"},
            )
            t0 = time.perf_counter()
            try:
                with urllib.request.urlopen(req, timeout=60) as r:
                    doc = json.loads(r.read())
            except OSError as exc:
                failures.append(f"request {i}: {exc}")
                return
            noisy = any(key in cases[k] for key in ("turn_noise", "contact_noise"))
            (noisy_latencies if noisy else latencies).append(time.perf_counter() - t0)
            if doc != want[k]:
                failures.append(f"request {i}: the answer differs from the library's document")

        t0 = time.perf_counter()
        with ThreadPoolExecutor(args.clients) as pool:
            list(pool.map(one, range(args.requests)))
        wall = time.perf_counter() - t0
    finally:
        proc.terminate()
        proc.wait(timeout=10)

    def p50_p99(values: list[float]) -> str:
        lat = sorted(values)
        if not lat:
            return "none"
        p99 = lat[min(len(lat) - 1, int(0.99 * len(lat)))] * 1000
        return f"p50 {statistics.median(lat) * 1000:.1f} ms, p99 {p99:.1f} ms"

    noisy = f" (noisy requests: {p50_p99(noisy_latencies)})" if args.noisy else ""
    print(
        f"bench_web: {args.requests} plan requests ({len(cases)} distinct bodies) from "
        f"{args.clients} clients: {p50_p99(latencies)}{noisy}, "
        f"{args.requests / wall:.0f} requests/s, {len(failures)} wrong or failed"
    )
    for f in failures[:10]:
        print("  " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
