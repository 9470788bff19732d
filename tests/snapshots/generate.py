"""Write ``tests/snapshots/cli.json``: what the command line prints with ``--json``, case by case.

The snapshot pins every number of every ``--json`` document (``squeeze``, ``push``, ``plan``,
``table1``, ``study``, ``simulate``) for the catalogue parts, the example files, six random
polygons in ``tests/snapshots/parts/`` and a spread of options, so that a refactor can prove it
changed nothing: ``tests/test_snapshot.py`` re-runs each stored ``argv`` with the current code
and compares. Each entry of the file is ``{"argv": [...], "exit_code": n, "json": doc}``, with
``doc`` ``null`` when the command printed nothing (bad input, exit code 2). Keys in
:data:`VOLATILE_KEYS` (wall times) are dropped from every document, at any depth.

Regenerate only on purpose, from the code the snapshot should hold (e.g. a clean worktree)::

    python tests/snapshots/generate.py            # run the cases, write cli.json
    python tests/snapshots/generate.py --times    # the same, printing each case's run time
    python tests/snapshots/generate.py --parts    # first rewrite the random part files

The script runs the command line in-process (``bayesgrasp.cli.main``) from the repository root,
and every path in an ``argv`` is relative to that root.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import re
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
SNAPSHOT = HERE / "cli.json"
MORE = HERE / "more.json"
TMP = "{tmp}"  # in a more_cases argv: a fresh folder for the files the command writes
PARTS = "tests/snapshots/parts"  # relative to ROOT, as it appears in argv

# Machine-dependent fields, dropped from every document before it is stored or compared.
VOLATILE_KEYS = frozenset({"seconds", "planner_seconds"})

EXAMPLES = ("examples/bracket.dxf", "examples/peanut.svg", "examples/plate.geojson")
RANDOM = tuple(
    f"{PARTS}/{name}.json"
    for name in ("random-1", "random-2", "random-3", "random-4", "ellipse", "lattice")
)
HISTOGRAM = f"{PARTS}/histogram.txt"
PAYOFF = f"{PARTS}/payoff-key.json"
BATCH = f"{PARTS}/batch.jsonl"
SAMPLE = f"{PARTS}/sample.txt"


def all_parts() -> tuple[str, ...]:
    """Every catalogue part, the example files and the random parts."""
    from bayesgrasp.shapes import names

    return (*names(), *EXAMPLES, *RANDOM)


def symmetric_parts() -> tuple[str, ...]:
    """The parts with a rotational symmetry, where ``--goal symmetry`` makes a difference."""
    from bayesgrasp.io import resolve_part

    return tuple(p for p in all_parts() if resolve_part(p).hull.symmetry_order > 1)


def plan_cases() -> list[list[str]]:
    """The ``plan`` command lines."""
    cases: list[list[str]] = []
    for part in all_parts():
        cases.append(["plan", part, "--json"])
        cases.append(["plan", part, "--prior", "vonmises:40,4", "--json"])
        cases.append(["plan", part, "--actions", "squeeze,push-grasp", "--json"])
        cases.append(["plan", part, "--actions", "push-grasp", "--json"])
        cases.append(["plan", part, "--accuracy", "2", "--json"])
        cases.append(["plan", part, "--guaranteed", "--json"])
        cases.append(["plan", part, "--guaranteed", "--actions", "squeeze,push-grasp", "--json"])
        cases.append(["plan", part, "--method", "bfs", "--json"])  # each well under 0.1 s
    for part in ("triangle", "key", "example", "examples/peanut.svg", f"{PARTS}/random-2.json"):
        cases.append(["plan", part, "--prior", f"histogram:{HISTOGRAM}", "--json"])
    for part in ("house", f"{PARTS}/ellipse.json"):
        cases.append(["plan", part, "--prior", f"sample:{SAMPLE}", "--json"])
    cases.append(["plan", "triangle", "--prior", "vonmises:40,4", "--method", "bfs", "--json"])
    for part in symmetric_parts():
        cases.append(["plan", part, "--goal", "symmetry", "--json"])
        cases.append(["plan", part, "--goal", "symmetry", "--method", "bfs", "--json"])
        cases.append(["plan", part, "--goal", "symmetry", "--guaranteed", "--json"])
    # No rotational symmetry: the same plans as --goal single.
    cases.append(["plan", "ic-chip", "--goal", "symmetry", "--json"])
    cases.append(["plan", "triangle", "--goal", "symmetry", "--json"])
    cases += [
        ["plan", "triangle", "--actions", "push-grasp", "--method", "bfs", "--json"],
        ["plan", "house", "--actions", "squeeze,push-grasp", "--method", "bfs", "--json"],
        ["plan", "key", "--prior", "vonmises:40,4", "--accuracy", "2", "--json"],
        ["plan", "example", "--accuracy", "2", "--actions", "squeeze,push-grasp", "--json"],
        ["plan", "house", "--accuracy", "5", "--guaranteed", "--json"],
        ["plan", "key", "--guaranteed", "--accuracy", "30", "--json"],  # exit 1: no such plan
        ["plan", "hand", "--guaranteed", "--accuracy", "30", "--json"],
        ["plan", "rectangle", "--squeeze-cost", "2", "--verify-cost", "0.5", "--json"],
        ["plan", "example", "--squeeze-cost", "0.25", "--verify-cost", "3", "--json"],
        ["plan", "triangle", "--first-squeeze-cost", "0", "--json"],
        ["plan", "key", "--first-squeeze-cost", "4", "--retry-cost", "2", "--json"],
        ["plan", "house", "--retry-cost", "3", "--json"],
        ["plan", "house", "--retry-cost", "3", "--method", "bfs", "--json"],
        "plan example --actions squeeze,push-grasp --push-grasp-cost 0.3 --json".split(),
        "plan example --actions squeeze,push-grasp --push-grasp-cost 5 --json".split(),
        ["plan", "hand", "--max-squeezes", "1", "--json"],
        ["plan", "key", "--max-squeezes", "2", "--json"],
        ["plan", "key", "--max-squeezes", "2", "--method", "bfs", "--json"],
        "plan tuning-fork --max-squeezes 3 --actions squeeze,push-grasp --json".split(),
    ]
    return cases


def simulate_cases() -> list[list[str]]:
    """Kinematic ``simulate`` command lines (small, seeded)."""
    n = ["--trials", "10000"]
    return [
        f"simulate house --plan {PARTS}/plan-squeeze.json --trials 10000 --seed 9 --json".split(),
        ["simulate", "house", "--plan", f"{PARTS}/plan-mixed.json", *n, "--seed", "10", "--json"],
        ["simulate", "key", *n, "--seed", "5", "--json"],
        ["simulate", "triangle", "--plan", "most-certain", *n, "--seed", "1", "--json"],
        ["simulate", "triangle", "--noise", "3", *n, "--seed", "2", "--json"],
        "simulate example --plan guaranteed --noise 2 --noise-kind uniform --trials 10000 "
        "--seed 3 --json".split(),
        ["simulate", "house", "--push-grasp", *n, "--seed", "4", "--json"],
        f"simulate {PARTS}/random-1.json --prior vonmises:40,4 --accuracy 2 --trials 10000 "
        "--seed 6 --json".split(),
        ["simulate", "rectangle", "--goal", "symmetry", *n, "--seed", "7", "--json"],
        ["simulate", "examples/peanut.svg", *n, "--seed", "8", "--json"],
    ]


def bad_cases() -> list[list[str]]:
    """Bad input: exit code 2 and nothing on stdout."""
    return [
        ["plan", "no-such-part", "--json"],
        ["squeeze", f"{PARTS}/missing.json", "--json"],
        ["plan", "triangle", "--prior", "vonmises:40", "--json"],
        ["plan", "triangle", "--actions", "teleport", "--json"],
        ["plan", "triangle", "--squeeze-cost", "-1", "--json"],
        ["simulate", "key", "--offset", "1", "--json"],
    ]


def cases() -> list[list[str]]:
    """Every command line of the snapshot, in order."""
    out: list[list[str]] = []
    for part in all_parts():
        out.append(["squeeze", part, "--json"])
        out.append(["push", part, "--json"])
    out += [
        ["squeeze", "key", "--prior", "vonmises:40,4", "--json"],
        ["squeeze", "triangle", "--prior", f"histogram:{HISTOGRAM}", "--json"],
        ["push", "house", "--prior", "vonmises:40,4", "--json"],
        ["push", "example", "--prior", f"histogram:{HISTOGRAM}", "--json"],
    ]
    out += plan_cases()
    out += [
        ["table1", "--json"],
        ["study", "--polygons", "100", "--json"],
        ["study", "--polygons", "60", "--seed", "3", "--method", "bfs", "--json"],
        ["study", "--polygons", "60", "--seed", "2", "--no-bfs-stats", "--json"],
        "study --polygons 60 --seed 4 --method bfs --no-bfs-stats --json".split(),
    ]
    out += simulate_cases()
    out += bad_cases()
    seen = set()
    for argv in out:
        key = tuple(argv)
        if key in seen:
            raise AssertionError(f"duplicate case {argv}")
        seen.add(key)
    return out


def more_cases() -> list[dict[str, Any]]:
    """The command lines of ``more.json``: sensing, noise, payoff, export, batch, text tables.

    Each case says what to keep of its output: ``"json"`` (one document), ``"jsonl"`` (one
    document a line: several parts, ``--batch``), ``"text"`` (the numbers of a table, in
    order) or ``"files"`` (the files written into :data:`TMP`, with the stdout document when
    ``--json`` is given).
    """
    sense = ["--sense", "width:0.5,0.1"]
    json_cases = [
        ["plan", "key", "--turn-noise", "normal:2", "--json"],
        ["plan", "house", "--turn-noise", "uniform:3", "--json"],
        ["plan", "triangle", "--contact-noise", "0.1", "--json"],
        ["plan", "example", "--turn-noise", "normal:1", "--contact-noise", "0.05", "--json"],
        ["plan", "key", "--payoff", PAYOFF, "--json"],
        ["plan", "key", "--turn-noise", "normal:2", "--payoff", PAYOFF, "--json"],
        ["plan", "house", "--sense", "width", "--json"],
        ["plan", "house", *sense, "--json"],
        ["plan", "key", *sense, "--max-actions", "2", "--json"],
        ["plan", "triangle", "--sense", "width", "--also", "rectangle", "--json"],
        [
            "plan",
            "rectangle",
            "--sense",
            "width:0.2,0.05",
            "--also",
            "triangle",
            "--part-prior",
            "1,3",
            "--max-actions",
            "2",
            "--json",
        ],
        [
            "plan",
            "example",
            "--sense",
            "width",
            "--actions",
            "squeeze,push-grasp",
            "--max-actions",
            "2",
            "--json",
        ],
        ["simulate", "house", "--sense", "width", "--trials", "3000", "--seed", "1", "--json"],
        [
            "simulate",
            "key",
            *sense,
            "--max-actions",
            "2",
            "--trials",
            "3000",
            "--seed",
            "2",
            "--json",
        ],
    ]
    out: list[dict[str, Any]] = [{"argv": a, "keep": "json"} for a in json_cases]
    out += [
        {"argv": ["plan", "key", "house", "--json"], "keep": "jsonl"},
        {"argv": ["plan", "--batch", BATCH], "keep": "jsonl"},
        {"argv": ["plan", "--batch", BATCH, "--only", "best", "--guaranteed"], "keep": "jsonl"},
    ]
    text_cases = [
        ["plan", "key"],
        ["plan", "house", "--actions", "squeeze,push-grasp", "--guaranteed"],
        ["plan", "key", "--turn-noise", "normal:2"],
        ["plan", "key", "--payoff", PAYOFF],
        ["plan", "house", "--sense", "width"],
        ["plan", "house", *sense, "--max-actions", "2"],
        ["squeeze", "key"],
        ["simulate", "key", "--trials", "20000", "--seed", "3"],
        ["simulate", "house", "--sense", "width", "--trials", "3000", "--seed", "4"],
    ]
    out += [{"argv": a, "keep": "text"} for a in text_cases]
    file_cases = [
        ["plan", "key", "--export", f"{TMP}/robot.csv"],
        ["plan", "key", "--export", f"{TMP}/robot.json", "--json"],
        ["plan", "house", "--actions", "squeeze,push-grasp", "--export", f"{TMP}/robot.csv"],
        [
            "plan",
            "examples/bracket.dxf",
            "--prior",
            "vonmises:40,4",
            "--export",
            f"{TMP}/robot.json",
        ],
    ]
    out += [{"argv": a, "keep": "files"} for a in file_cases]
    return out


NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|inf|nan")


SECONDS = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)? s\b")


def numbers(text: str) -> list[float]:
    """The numbers of a text, in order (what a table's snapshot keeps; wall times dropped)."""
    lines = (SECONDS.sub("", x) for x in text.splitlines() if not x.startswith("wall time"))
    return [float(x) for line in lines for x in NUMBER.findall(line)]


def run_more(case: dict[str, Any], tmp: Path) -> dict[str, Any]:
    """Run one of :func:`more_cases` with its files written into ``tmp``; what it keeps."""
    from bayesgrasp.cli import main

    argv = [a.replace(TMP, str(tmp)) for a in case["argv"]]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    text, keep = out.getvalue(), case["keep"]
    got: dict[str, Any] = {"argv": case["argv"], "keep": keep, "exit_code": code}
    if keep == "json" or (keep == "files" and "--json" in argv):
        got["json"] = drop_volatile(json.loads(text, parse_constant=_no_constants))
    elif keep == "jsonl":
        lines = text.splitlines()
        got["jsonl"] = [drop_volatile(json.loads(x, parse_constant=_no_constants)) for x in lines]
    else:  # a table
        got["numbers"] = numbers(text)
    if keep == "files":
        files: dict[str, Any] = {}
        for f in sorted(tmp.iterdir()):
            body = f.read_text(encoding="utf-8")
            files[f.name] = json.loads(body) if f.suffix == ".json" else numbers(body)
        got["files"] = files
    return got


def generate_more() -> list[dict[str, Any]]:
    """Run every case of :func:`more_cases`, each with a fresh folder for its files."""
    import tempfile

    entries = []
    for case in more_cases():
        with tempfile.TemporaryDirectory() as d:
            entries.append(run_more(case, Path(d)))
    return entries


def drop_volatile(doc: Any) -> Any:
    """``doc`` without the keys of :data:`VOLATILE_KEYS`, at any depth."""
    if isinstance(doc, dict):
        return {k: drop_volatile(v) for k, v in doc.items() if k not in VOLATILE_KEYS}
    if isinstance(doc, list):
        return [drop_volatile(v) for v in doc]
    return doc


def _no_constants(name: str) -> None:
    raise ValueError(f"the output holds {name}")


def run_cli(argv: Sequence[str]) -> tuple[int, Any]:
    """Run the command line in-process; return its exit code and its parsed ``--json`` output.

    The output is ``None`` when the command printed nothing; anything else on stdout that is
    not one JSON document raises ``ValueError``. Must be called from the repository root.
    """
    from bayesgrasp.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    text = out.getvalue()
    if not text.strip():
        return code, None
    try:
        doc = json.loads(text, parse_constant=_no_constants)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{argv}: stdout is not JSON ({exc.msg}): {text[:200]!r}") from None
    return code, drop_volatile(doc)


def write_parts() -> None:
    """Write the random part files and prior files (seeded: the same files every time)."""
    import numpy as np

    folder = ROOT / PARTS
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(20240917)
    docs: dict[str, dict[str, Any]] = {}
    # The seed's study polygons: hulls of uniform points in the unit square.
    for i, n in enumerate((10, 10, 10, 25), start=1):
        docs[f"random-{i}"] = {"name": f"random-{i}", "vertices": rng.random((n, 2)).tolist()}
    # Sixteen points on an ellipse of random aspect, rotation and centre, in millimetres.
    t = np.sort(rng.uniform(0.0, 2.0 * np.pi, 16))
    a, b, phi = 30.0, 30.0 * rng.uniform(0.3, 0.8), rng.uniform(0.0, np.pi)
    x, y = a * np.cos(t), b * np.sin(t)
    c, s = np.cos(phi), np.sin(phi)
    pts = np.stack([c * x - s * y, s * x + c * y], axis=1) + rng.uniform(-10.0, 10.0, 2)
    docs["ellipse"] = {"name": "ellipse", "units": "mm", "vertices": pts.tolist()}
    # An integer parallelogram (rotational symmetry of order 2) with points inside it.
    u, v = rng.integers(5, 40, 2), rng.integers(-20, 20, 2)
    corners = [[0, 0], u.tolist(), (u + v).tolist(), v.tolist()]
    inside = [((u + v) // 2).tolist(), (u // 3 + v // 2).tolist()]
    docs["lattice"] = {
        "name": "lattice",
        "vertices": [[int(q) for q in p] for p in corners + inside],
        # Simple in file order, so it would read as an outline: the parallelogram's centre.
        "center_of_mass": ((u + v) / 2).tolist(),
    }
    # Plan files for ``simulate --plan FILE`` on the house (made up, near its Bayes plans).
    docs["plan-squeeze"] = {
        "first_squeeze_rad": 0.0,
        "actions_rad": [0.4],
        "final_orientation_rad": 0.0,
    }
    docs["plan-mixed"] = {
        "steps": [{"type": "push-grasp", "alpha_rad": 0.0}, {"type": "squeeze", "alpha_rad": 0.4}],
        "final_orientation_rad": 0.0,
    }
    for name, doc in docs.items():
        (folder / f"{name}.json").write_text(json.dumps(doc) + "\n", encoding="utf-8")
    weights = rng.integers(0, 10, 12)
    (ROOT / HISTOGRAM).write_text(" ".join(str(w) for w in weights) + "\n", encoding="utf-8")
    angles = np.concatenate([rng.normal(80.0, 15.0, 12), rng.normal(250.0, 30.0, 8)]) % 360.0
    (ROOT / SAMPLE).write_text("\n".join(f"{d:.2f}" for d in angles) + "\n", encoding="utf-8")


def generate(times: bool = False) -> list[dict[str, Any]]:
    """Run every case; return the snapshot entries."""
    entries: list[dict[str, Any]] = []
    for argv in cases():
        t0 = time.perf_counter()
        code, doc = run_cli(argv)
        dt = time.perf_counter() - t0
        if times:
            print(f"{dt:7.3f} s  exit {code}  {' '.join(argv)}", file=sys.stderr)
        entries.append({"argv": argv, "exit_code": code, "json": doc})
    return entries


def main(argv: Sequence[str] | None = None) -> int:
    """Write the snapshot file."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", action="store_true", help="rewrite the random part files")
    parser.add_argument("--times", action="store_true", help="print each case's run time")
    args = parser.parse_args(argv)
    os.chdir(ROOT)
    if args.parts:
        write_parts()
    entries = generate(times=args.times)
    SNAPSHOT.write_text(json.dumps(entries, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    print(f"wrote {len(entries)} cases to {SNAPSHOT.relative_to(ROOT)}")
    more = generate_more()
    MORE.write_text(json.dumps(more, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    print(f"wrote {len(more)} cases to {MORE.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
