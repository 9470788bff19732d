"""Planning at the limit (issue 12): this branch beside commit 373822f and the baseline.

Every case runs in a fresh subprocess, so two versions of bayesgrasp can be timed in one
run: this worktree's ``src`` and a reference worktree of 373822f (``--ref``; make it with
``git worktree add /work/wt/ref373 373822f``). Cases of the two versions alternate, and each
is the best of ``--repeat`` runs (CPU time of the timed work, imports excluded).

Cases:

- ``study``: the seed's 2000-polygon study (hull, diameter, squeeze function, exact Bayes
  plans with angles), as ``run_study(2000, seed=1)`` runs it;
- ``batch``: ``plan --batch`` of the study's 2000 hulls as JSON lines, in one process (the
  command's ``main``; its first call imports the command's modules, so later calls are
  timed too), beside the in-process study; also the batch one part at a time and the study
  planned in groups stage by stage, as the batch plans its lines (the like-for-like
  comparison of that technique). With ``--before REV`` (a commit, or a ``src`` folder), the
  same runs of that version alternate with this branch's, and the two are shown side by
  side;
- ``bfs``: the breadth-first baseline (``planning/bfs.py``) on the same 2000 polygons, beside
  the exact planner on the same problems (this branch only);
- ``circle N``: N random points on the unit circle (N = 10^3, 10^4, 10^5);
- ``regular N``: the regular N-gon (N = 10^5);
- ``ellipse N``: N points on an ellipse of aspect 2 (N = 10^5).

For the large parts: the hull (``Part.from_points``), the problem, and the exact plans
(``report="best"``, the Bayes and most certain plans, where the version has it), with the
``tracemalloc`` peak of a second, traced run. A case that passes ``--timeout`` seconds is
reported as such. The machine may be shared: the figures are floors, compare them side by
side.

Run: ``.venv/bin/python benchmarks/bench_limits.py [--ref /work/wt/ref373] [--repeat 3]``;
the batch beside an earlier commit:
``.venv/bin/python benchmarks/bench_limits.py --only batch --before HEAD~1 --repeat 5``
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent.parent / "src"

# The work of each case, as a script: it prints one JSON object. ``NEW`` is true for this
# branch's layout (bayesgrasp.paper, bayesgrasp.model), false for 373822f's.
_SCRIPT = r"""
import json, math, sys, time, tracemalloc
import numpy as np
case, n, traced = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1"
try:
    from bayesgrasp.paper.study import run_study, random_polygon
    from bayesgrasp.model.problem import Problem
    from bayesgrasp.geometry.polygon import Part
    NEW = True
except ImportError:
    from bayesgrasp.study import run_study, random_polygon
    from bayesgrasp.problem import Problem
    from bayesgrasp.geometry import Part
    NEW = False
from bayesgrasp.planning.exact import plan_exact
from bayesgrasp.planning.bfs import search_bfs
import inspect
best = "report" in inspect.signature(plan_exact).parameters

def points(case, n):
    if case == "circle":
        t = np.random.default_rng(0).uniform(0.0, 2 * math.pi, n)
        return np.column_stack([np.cos(t), np.sin(t)])
    t = 2 * math.pi * np.arange(n) / n
    if case == "regular":
        return np.column_stack([np.cos(t), np.sin(t)])
    return np.column_stack([2.0 * np.cos(t), np.sin(t)])

out = {}
if case == "study":
    c0 = time.process_time()
    res = run_study(n, 1)
    out["cpu"] = time.process_time() - c0
    out["better"] = res.shorter_plan_better
elif case == "bfs":
    rng = np.random.default_rng(1)
    pbs = [Problem.build(random_polygon(rng)) for _ in range(n)]
    c0 = time.process_time()
    for pb in pbs:
        plan_exact(pb)
    c1 = time.process_time()
    nodes = []
    for pb in pbs:
        nodes.append(search_bfs(pb, tree_count=False).stats.bfs_nodes)
    c2 = time.process_time()
    out["exact"], out["cpu"] = c1 - c0, c2 - c1
    over = [k for k, m in enumerate(nodes) if m > 100]
    # The exact plans of these take a few ms: 20 rounds, their mean (one round is noisy).
    rounds = 20
    c3 = time.process_time()
    for _ in range(rounds):
        for k in over:
            plan_exact(pbs[k])
    c4 = time.process_time()
    for k in over:
        search_bfs(pbs[k], tree_count=False)
    c5 = time.process_time()
    out["over100"], out["exact100"], out["bfs100"] = len(over), (c4 - c3) / rounds, c5 - c4
elif case == "batch":
    import contextlib, io, os, tempfile
    from bayesgrasp.cli import main
    from bayesgrasp.planning.exact import plan_exact as exact
    try:
        import bayesgrasp.cli.batch as grouped
    except ImportError:
        grouped = None
    rng = np.random.default_rng(1)
    path = os.path.join(tempfile.mkdtemp(), "parts.jsonl")
    with open(path, "w") as fh:
        for k in range(n):
            hull = random_polygon(rng).hull.vertices.tolist()
            fh.write(json.dumps({"name": f"p{k}", "vertices": hull}) + "\n")

    def batch(group=None):
        if group is not None and grouped is not None and hasattr(grouped, "GROUP"):
            was, grouped.GROUP = grouped.GROUP, group
        sink = io.StringIO()
        c0 = time.process_time()
        with contextlib.redirect_stdout(sink):
            main(["plan", "--batch", path])
        cpu = time.process_time() - c0
        if group is not None and grouped is not None and hasattr(grouped, "GROUP"):
            grouped.GROUP = was
        return cpu, sink.getvalue().count("\n")

    def study_in_groups(size=32):
        # The study's work (hull, problem, exact plans) stage by stage in groups, as the
        # batch plans its lines: what the same technique would give the study.
        draws = np.random.default_rng(1).uniform(size=(n, 10, 2))
        c0 = time.process_time()
        for s in range(0, n, size):
            parts = [Part.from_points(d, name="random") for d in draws[s : s + size]]
            problems = [Problem.build(p) for p in parts]
            plans = [exact(pb) for pb in problems]
        return time.process_time() - c0

    out["cpu"], out["lines"] = batch()  # the first call imports the command's modules
    out["warm"], out["study"], out["one"], out["study_grouped"] = [], [], [], []
    for _ in range(3):  # alternating, so that a change of load hits all alike
        out["warm"].append(batch()[0])
        c0 = time.process_time()
        run_study(n, 1)
        out["study"].append(time.process_time() - c0)
        out["one"].append(batch(1)[0])
        out["study_grouped"].append(study_in_groups())
else:
    pts = points(case, n)
    if traced:
        tracemalloc.start()
    c0 = time.process_time()
    part = Part.from_points(pts)
    c1 = time.process_time()
    pb = Problem.build(part)
    c2 = time.process_time()
    rep = plan_exact(pb, report="best") if best else plan_exact(pb)
    c3 = time.process_time()
    if traced:
        out["peak_mb"] = tracemalloc.get_traced_memory()[1] / 1e6
    out.update(hull=c1 - c0, build=c2 - c1, plan=c3 - c2, cpu=c3 - c0, states=pb.n_states,
               levels=max(o.n_actions for o in rep.options), best=best)
print(json.dumps(out))
"""


def run(src: Path, case: str, n: int, traced: bool, timeout: float) -> dict[str, Any]:
    """One case in a subprocess with ``src`` first on the path."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    try:
        done = subprocess.run(
            [sys.executable, "-c", _SCRIPT, case, str(n), "1" if traced else "0"],
            env=env,
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
        )
    except subprocess.TimeoutExpired:
        return {"timeout": timeout}
    if done.returncode:
        return {"error": done.stderr.strip().splitlines()[-1] if done.stderr else "failed"}
    return dict(json.loads(done.stdout.strip().splitlines()[-1]))


def best_of(src: Path, case: str, n: int, repeat: int, timeout: float) -> dict[str, Any]:
    """Best CPU time of ``repeat`` runs, and (large parts) the peak of one traced run."""
    runs = [run(src, case, n, False, timeout) for _ in range(repeat)]
    ok = [r for r in runs if "cpu" in r]
    if not ok:
        return runs[0]
    out = min(ok, key=lambda r: r["cpu"])
    if case not in ("study", "bfs", "batch"):
        out["peak_mb"] = run(src, case, n, True, timeout).get("peak_mb")
    return out


def show(label: str, r: dict[str, Any]) -> str:
    """One line of figures."""
    if "timeout" in r:
        return f"{label}: no answer in {r['timeout']:.0f} s"
    if "error" in r:
        return f"{label}: {r['error']}"
    parts = [f"cpu {r['cpu']:.3f} s"]
    for key, fmt in (("hull", "hull {:.3f}"), ("build", "build {:.3f}"), ("plan", "plan {:.3f}")):
        if key in r:
            parts.append(fmt.format(r[key]))
    if "peak_mb" in r and r["peak_mb"] is not None:
        parts.append(f"peak {r['peak_mb']:.0f} MB")
    if "states" in r:
        parts.append(f"K {r['states']}, {r['levels']} actions")
    if "better" in r:
        parts.append(f"shorter plan better {r['better']}")
    return f"{label}: " + ", ".join(parts)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ref", type=Path, default=Path("/work/wt/ref373/src"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--polygons", type=int, default=2000)
    ap.add_argument("--quick", action="store_true", help="skip the 10^5 cases of 373822f")
    ap.add_argument(
        "--only", default="", help="comma-separated groups to run: study, bfs, batch, large"
    )
    ap.add_argument(
        "--before",
        default=None,
        help="batch: also time this version (a git commit, or a src folder), run by run",
    )
    args = ap.parse_args()
    only = set(args.only.split(",")) if args.only else {"study", "bfs", "batch", "large"}
    ref = args.ref if (args.ref / "bayesgrasp").is_dir() else None
    if args.ref.name != "src" and (args.ref / "src" / "bayesgrasp").is_dir():
        ref = args.ref / "src"
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")

    if "study" in only:
        study_cases(ref, args)
    if "bfs" in only:
        bfs_case(args)
    if "batch" in only:
        batch_case(args, _source(args.before) if args.before else None)
    if "large" in only:
        large_cases(ref, args)


def study_cases(ref: Path | None, args: argparse.Namespace) -> None:
    """The study, this branch beside 373822f, alternating run by run (best of each)."""
    news: list[dict[str, Any]] = []
    olds: list[dict[str, Any]] = []
    for _ in range(args.repeat):
        news.append(run(HERE, "study", args.polygons, False, args.timeout))
        if ref is not None:
            olds.append(run(ref, "study", args.polygons, False, args.timeout))
    new = min(news, key=lambda r: r.get("cpu", math.inf))
    print(show(f"study {args.polygons}, this branch", new))
    if olds:
        old = min(olds, key=lambda r: r.get("cpu", math.inf))
        print(show(f"study {args.polygons}, 373822f    ", old))
        if "cpu" in old and "cpu" in new:
            print(f"  speed-up {old['cpu'] / new['cpu']:.2f}x")


def bfs_case(args: argparse.Namespace) -> None:
    """The breadth-first baseline beside the exact planner (this branch)."""
    b = best_of(HERE, "bfs", args.polygons, 1, args.timeout * 5)
    if "cpu" in b:
        print(
            f"breadth-first baseline, {args.polygons} polygons: bfs {b['cpu']:.3f} s, exact "
            f"{b['exact']:.3f} s ({b['cpu'] / b['exact']:.1f}x); {b['over100']} polygons over "
            f"100 nodes: bfs {b['bfs100']:.3f} s, exact {b['exact100']:.4f} s (mean of 20 rounds) "
            f"({b['bfs100'] / max(b['exact100'], 1e-9):.1f}x)"
        )


def _source(before: str) -> Path:
    """The ``src`` of an earlier version: a folder as given, or a commit's, extracted."""
    given = Path(before)
    if (given / "bayesgrasp").is_dir():
        return given
    if (given / "src" / "bayesgrasp").is_dir():
        return given / "src"
    root = HERE.parent
    out = Path(tempfile.mkdtemp(prefix="bench-before-"))
    archive = subprocess.run(
        ["git", "-C", str(root), "archive", before, "src"], capture_output=True, check=True
    )
    subprocess.run(["tar", "-x", "-C", str(out)], input=archive.stdout, check=True)
    return out / "src"


def batch_case(args: argparse.Namespace, before: Path | None = None) -> None:
    """``plan --batch`` beside the in-process study (this branch, and ``before``'s).

    Each run: the first call (it imports the command's modules), then three rounds of a
    second call, the study, the batch one part at a time (``GROUP = 1``) and the study in
    groups; best of each over the runs, and the median of the rounds' ratios. The runs of
    the two versions alternate, so that a change of the machine's load hits both alike.
    """
    versions = [("this branch", HERE)] + ([(f"before ({args.before})", before)] if before else [])
    # The first call as users meet it: the modules' bytecode compiled (pip compiles it on
    # installing; under PYTHONDONTWRITEBYTECODE nothing else would).
    for _, src in versions:
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(src)], check=True)
    runs: dict[str, list[dict[str, Any]]] = {label: [] for label, _ in versions}
    for _ in range(args.repeat):
        for label, src in versions:
            runs[label].append(run(src, "batch", args.polygons, False, args.timeout))
    warm = {label: _show_batch(label, found) for label, found in runs.items()}
    if before is not None and all(w is not None for w in warm.values()):
        new, old = warm.values()
        assert new is not None and old is not None
        print(f"  this branch's warm batch {new / old:.2f}x the one before")


def _show_batch(label: str, runs: list[dict[str, Any]]) -> float | None:
    """Print one version's batch figures; its best warm time."""
    ok = [r for r in runs if "cpu" in r]
    if not ok:
        print(f"plan --batch, {label}: {runs[0]}")
        return None

    def best(key: str) -> float:
        return min(min(r[key]) if isinstance(r[key], list) else r[key] for r in ok)

    def median_ratio(key: str, of: str) -> float:
        ratios = sorted(a / b for r in ok for a, b in zip(r[key], r[of], strict=True))
        return ratios[len(ratios) // 2]

    study, warm, cold = best("study"), best("warm"), best("cpu")
    n = ok[0]["lines"]
    print(
        f"plan --batch, {label}, {n} parts in one process: {warm:.3f} s warm "
        f"({warm / n * 1e6:.0f} us a part), {cold:.3f} s the first call (the command's "
        f"imports); the in-process study {study:.3f} s ({study / n * 1e6:.0f} us a part): "
        f"warm {warm / study:.2f}x (median of the rounds {median_ratio('warm', 'study'):.2f}x), "
        f"first call {cold / study:.2f}x"
    )
    one, grouped = best("one"), best("study_grouped")
    print(
        f"  one part at a time (GROUP = 1): {one:.3f} s ({one / study:.2f}x the study); "
        f"the study in groups of 32: {grouped:.3f} s (the batch {warm / grouped:.2f}x it, "
        f"median {median_ratio('warm', 'study_grouped'):.2f}x)"
    )
    return warm


def large_cases(ref: Path | None, args: argparse.Namespace) -> None:
    """Parts with many points, this branch beside 373822f."""
    cases = [("circle", 1000), ("circle", 10_000), ("circle", 100_000)]
    cases += [("regular", 100_000), ("ellipse", 100_000)]
    for case, n in cases:
        print(show(f"{case} {n}, this branch", best_of(HERE, case, n, args.repeat, args.timeout)))
        if ref is not None and not (args.quick and n >= 100_000):
            reps = 1 if n >= 10_000 else args.repeat
            print(show(f"{case} {n}, 373822f    ", best_of(ref, case, n, reps, args.timeout)))


if __name__ == "__main__":
    main()
