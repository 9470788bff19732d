"""Load test of ``bayesgrasp serve``: light plan requests beside heavy policy requests.

Starts the server on a free 127.0.0.1 port (a subprocess, stopped at the end) and, for
``--seconds`` (at most ``--max-requests`` light requests), runs ``--light-clients`` threads
sending plan requests (catalogue and random parts, several option sets; every answer checked
against the library's own document) beside ``--heavy-clients`` threads sending deep sensing
policies (two 27-sided parts told apart, four actions, a fine jaw-width sensor: more than a
minute of work each). Prints the light requests' p50/p99 latency and status counts, the
heavy requests' statuses, and the server's memory (the proportional set size of the server
and its worker processes) before, during (peak) and ``--settle`` seconds after the load.

With ``--baseline-rev REV`` the same load runs first against the server of git revision
``REV`` (its ``src`` unpacked into a temporary folder), side by side with this one; with
``--light-only`` this server runs the light clients alone too (what the machine gives light
requests without the heavy ones).

    python benchmarks/bench_web.py [--seconds 30] [--baseline-rev REV] [--light-only]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def light_bodies(n_random: int = 24) -> list[dict[str, Any]]:
    """Plan request bodies: every catalogue part and random polygons, four option sets."""
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
    return out


def sided(n: int, seed: int) -> list[list[float]]:
    """A convex ``n``-gon close to regular (radius 30 +- 0.5, angles +- 0.03 rad)."""
    rng = np.random.default_rng(seed)
    ang = np.linspace(0, 2 * math.pi, n, endpoint=False) + rng.uniform(-0.03, 0.03, n)
    r = 30 + rng.uniform(-0.5, 0.5, n)
    return np.c_[r * np.cos(ang), r * np.sin(ang)].round(3).tolist()


HEAVY: dict[str, Any] = {
    "part": {"vertices": sided(27, 27), "name": "gon27"},
    "also": [{"vertices": sided(27, 0), "name": "gon27b"}],
    "max_actions": 4,
    "sense": "width:0.05,0.01",
}


def expected(body: dict[str, Any]) -> dict[str, Any]:
    """The document the library (and ``plan --json``) gives for a body."""
    from bayesgrasp.web.app import Limits, Service, plan_result_document
    from bayesgrasp.web.models import PlanRequest

    return plan_result_document(Service(Limits(), None), PlanRequest.model_validate(body))


def tree_memory(pid: int) -> float:
    """Memory of process ``pid`` and its descendants, MB (proportional set size)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", encoding="ascii") as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(entry))
    total = 0.0
    todo = [pid]
    while todo:
        p = todo.pop()
        todo.extend(children.get(p, []))
        try:
            with open(f"/proc/{p}/smaps_rollup", encoding="ascii") as f:
                for line in f:
                    if line.startswith("Pss:"):
                        total += int(line.split()[1]) / 1024
                        break
        except OSError:
            continue
    return total


@dataclass
class Run:
    """What one server did under the load."""

    label: str
    light: list[float] = field(default_factory=list)  # seconds, 200 answers
    light_status: dict[str, int] = field(default_factory=dict)
    wrong: int = 0
    heavy: list[tuple[int, float]] = field(default_factory=list)
    memory: dict[str, float] = field(default_factory=dict)
    load: tuple[float, float] = (0.0, 0.0)

    def count(self, key: str) -> None:
        self.light_status[key] = self.light_status.get(key, 0) + 1


def post(url: str, body: dict[str, Any], timeout: float) -> tuple[int, Any]:
    req = urllib.request.Request(
        url, data=json.dumps(body).encode(), headers={"content-type": "application/json"}
    )
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as exc:
        return exc.code, json.loads(exc.read() or b"{}")
    except OSError as exc:
        return 0, str(exc)


def load(
    label: str,
    src: Path,
    server_args: list[str],
    args: argparse.Namespace,
    cases: list[Any],
    heavy_clients: int | None = None,
) -> Run:
    """Start the server of ``src``, run the load, stop it."""
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
        *server_args,
    ]
    env = {**os.environ, "PYTHONPATH": str(src)}
    proc = subprocess.Popen(cmd, cwd=data, env=env, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}/api/v1"
    run = Run(label)
    n_heavy = args.heavy_clients if heavy_clients is None else heavy_clients
    try:
        for _ in range(600):
            try:
                urllib.request.urlopen(f"{url}/health", timeout=1).close()
                break
            except OSError:
                time.sleep(0.1)
        for body, _ in cases[:8]:  # warm up
            post(f"{url}/plan", body, 60)
        time.sleep(1.0)
        run.memory["before"] = tree_memory(proc.pid)
        load_before = os.getloadavg()[0]
        stop = time.monotonic() + args.seconds
        sent = iter(range(args.max_requests))
        lock = threading.Lock()
        peak = [run.memory["before"]]

        def light_client(c: int) -> None:
            while time.monotonic() < stop:
                with lock:
                    i = next(sent, None)
                if i is None:
                    return
                body, want = cases[(i * 7 + c) % len(cases)]
                t0 = time.perf_counter()
                status, doc = post(f"{url}/plan", body, 60)
                dt = time.perf_counter() - t0
                with lock:
                    run.count(str(status))
                    if status == 200:
                        run.light.append(dt)
                        run.wrong += doc != want
                    elif status == 0:
                        run.count(f"error: {doc}"[:60])

        def heavy_client(c: int) -> None:
            time.sleep(0.2 * c)
            while time.monotonic() < stop:
                t0 = time.perf_counter()
                status, _ = post(f"{url}/policy", HEAVY, 120)
                with lock:
                    run.heavy.append((status, time.perf_counter() - t0))

        def sample() -> None:
            while time.monotonic() < stop:
                peak[0] = max(peak[0], tree_memory(proc.pid))
                time.sleep(0.5)

        with ThreadPoolExecutor(args.light_clients + n_heavy + 1) as pool:
            jobs = [pool.submit(heavy_client, c) for c in range(n_heavy)]
            jobs += [pool.submit(light_client, c) for c in range(args.light_clients)]
            jobs.append(pool.submit(sample))
            for j in jobs:
                j.result()
        run.memory["during (peak)"] = peak[0]
        time.sleep(args.settle)
        run.memory[f"{args.settle:g} s after"] = tree_memory(proc.pid)
        run.load = (load_before, os.getloadavg()[0])
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    return run


def p(values: list[float], q: float) -> float:
    lat = sorted(values)
    return lat[min(len(lat) - 1, int(q * len(lat)))] * 1000 if lat else float("nan")


def report(runs: list[Run], args: argparse.Namespace) -> str:
    lines = [
        f"bench_web: {args.light_clients} clients of light plan requests beside "
        f"{args.heavy_clients} clients of deep policies (two 27-sided parts, 4 actions, "
        f"sensor width:0.05,0.01), {args.seconds:g} s a server, {os.cpu_count()} cores",
        "",
    ]
    head = f"{'':34}" + "".join(f"{r.label:>26}" for r in runs)
    lines.append(head)

    def row(name: str, cells: list[str]) -> None:
        lines.append(f"{name:34}" + "".join(f"{c:>26}" for c in cells))

    row("light requests answered 200", [str(len(r.light)) for r in runs])
    row(
        "light p50 (ms)",
        [f"{statistics.median(r.light) * 1000:.1f}" if r.light else "-" for r in runs],
    )
    row("light p99 (ms)", [f"{p(r.light, 0.99):.1f}" for r in runs])
    row("light max (ms)", [f"{max(r.light) * 1000:.0f}" if r.light else "-" for r in runs])
    row("light 503", [str(r.light_status.get("503", 0)) for r in runs])
    row(
        "light other failures",
        [str(sum(v for k, v in r.light_status.items() if k not in ("200", "503"))) for r in runs],
    )
    row("light answers wrong", [str(r.wrong) for r in runs])
    row(
        "heavy requests: 200 / 503",
        [
            f"{sum(s == 200 for s, _ in r.heavy)} / {sum(s == 503 for s, _ in r.heavy)}"
            for r in runs
        ],
    )
    row(
        "heavy median answer (s)",
        [f"{statistics.median(t for _, t in r.heavy):.1f}" if r.heavy else "-" for r in runs],
    )
    for key in runs[0].memory:
        row(f"server memory {key} (MB)", [f"{r.memory.get(key, float('nan')):.0f}" for r in runs])
    row("load average before / after", [f"{r.load[0]:.2f} / {r.load[1]:.2f}" for r in runs])
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=30.0, help="length of the load a server")
    ap.add_argument("--max-requests", type=int, default=5000, help="most light requests")
    ap.add_argument("--light-clients", type=int, default=8)
    ap.add_argument("--heavy-clients", type=int, default=4)
    ap.add_argument("--settle", type=float, default=10.0, help="seconds before 'after'")
    ap.add_argument("--baseline-rev", help="git revision of a server to compare with")
    ap.add_argument("--server-args", default="", help="options of this server (e.g. '--workers 2')")
    ap.add_argument(
        "--light-only",
        action="store_true",
        help="also run this server with the light clients alone (the machine's own latency)",
    )
    args = ap.parse_args()

    bodies = light_bodies()
    cases = [(b, expected(b)) for b in bodies]
    runs: list[Run] = []
    if args.baseline_rev:
        base = Path(tempfile.mkdtemp(prefix="bench-web-base-"))
        archive = subprocess.run(
            ["git", "-C", str(ROOT), "archive", args.baseline_rev, "src"],
            check=True,
            capture_output=True,
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(base)], input=archive, check=True)
        runs.append(load(f"server at {args.baseline_rev[:10]}", base / "src", [], args, cases))
    runs.append(load("this server", ROOT / "src", args.server_args.split(), args, cases))
    if args.light_only:
        here = ROOT / "src"
        runs.append(load("this, light only", here, args.server_args.split(), args, cases, 0))
    print(report(runs, args))
    return 1 if any(r.wrong for r in runs) else 0


if __name__ == "__main__":
    sys.exit(main())
