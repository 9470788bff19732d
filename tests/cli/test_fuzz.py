"""A bounded fuzz campaign through the command line (in-process, ``bayesgrasp.cli.main``).

Generated command lines: every command that reports results, parts from the catalogue and
from generated files of every format (well-formed, truncated, garbage, huge or non-finite
numbers), and options drawn from valid values and from the edge cases that broke the CLI
before (nan, inf, negative, huge, non-numbers). Each must end with exit code 0, 1 or 2 and
no traceback: a bug raises out of ``main`` and fails the test; a refusal is one line on
stderr. Files given as inputs are never changed.

The default run is a fixed seed and a few hundred cases (CI); ``BAYESGRASP_LONG_FUZZ=1``
runs ``BAYESGRASP_FUZZ_CASES`` (default 3000) cases from a random seed, printed for replay
(``BAYESGRASP_FUZZ_SEED``).
"""

from __future__ import annotations

import hashlib
import json
import os
import random
from pathlib import Path

import pytest

from bayesgrasp.cli import main

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")

LONG = os.environ.get("BAYESGRASP_LONG_FUZZ") == "1"
CASES = int(os.environ.get("BAYESGRASP_FUZZ_CASES", "3000")) if LONG else 200
SEED = int(os.environ.get("BAYESGRASP_FUZZ_SEED", str(random.SystemRandom().randrange(10**9))))
SEED = SEED if LONG else 20261202

CATALOGUE = ["triangle", "rectangle", "house", "key", "example", "triangle", "house"]
BAD_PARTS = ["nope", ""]
GOOD_NUMBERS = ["0", "1", "2.5", "3", "0.001", "0.5"]
BAD_NUMBERS = ["-1", "nan", "inf", "-inf", "1e308", "1e-300", "abc", "", "1e999",
               "100000000000000000000000"]  # fmt: skip
BAD = 0.12
"""The chance that an option gets a bad value (so most command lines get far enough)."""
GOOD_VERTS = [[0, 0], [31, 0], [31, 20], [0, 20]]


def part_files(folder: Path, rng: random.Random) -> list[Path]:
    """Files of every format: good ones, and each mangled one way."""
    good = {
        "a.json": json.dumps({"name": "a", "vertices": GOOD_VERTS, "units": "mm"}),
        "b.csv": "x,y\n0,0\n40,0\n40,10\n10,10\n10,40\n0,40\n",
        "c.wkt": "POLYGON ((0 0, 30 0, 30 20, 0 20, 0 0))",
        "d.geojson": json.dumps(
            {"type": "Polygon", "coordinates": [[[0, 0], [3, 0], [2, 2], [0, 1], [0, 0]]]}
        ),
        "e.svg": '<svg xmlns="http://www.w3.org/2000/svg"><polygon points="0,0 30,0 25,18 0,12"/>'
        "</svg>",
        "f.dxf": "0\nSECTION\n2\nENTITIES\n0\nLWPOLYLINE\n90\n3\n70\n1\n10\n0\n20\n0\n10\n5\n20\n0"
        "\n10\n0\n20\n4\n0\nENDSEC\n0\nEOF\n",
    }
    bad = {
        "huge.json": json.dumps({"vertices": [[0, 0], [1e300, 0], [0, 1e300]]}),
        "nan.csv": "0,0\nnan,1\n1,1\n",
        "two.csv": "0,0\n1,1\n",
        "line.json": json.dumps({"vertices": [[0, 0], [1, 1], [2, 2]]}),
        "nest.json": "[" * 5000 + "]" * 5000,
        "com.json": json.dumps({"vertices": GOOD_VERTS, "center_of_mass": [1, 2, 3]}),
        "geo.geojson": json.dumps({"type": "FeatureCollection", "features": [1, "x", None]}),
        "neg.svg": '<svg xmlns="http://www.w3.org/2000/svg"><rect width="-3" height="2"/></svg>',
        "bomb.dxf": "0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n2\nA\n0\nINSERT\n2\nA\n0\nENDBLK\n0\nENDSEC"
        "\n0\nSECTION\n2\nENTITIES\n0\nINSERT\n2\nA\n0\nENDSEC\n0\nEOF\n",
        "empty.wkt": "",
        "bin.svg": bytes(range(256)).decode("latin-1"),
    }
    files = []
    for name, text in {**good, **bad}.items():
        path = folder / name
        path.write_text(text, encoding="latin-1" if name == "bin.svg" else "utf-8")
        files.append(path)
    for name, text in good.items():  # truncated at a random place
        cut = folder / f"cut-{name}"
        cut.write_text(text[: rng.randrange(len(text))], encoding="utf-8")
        files.append(cut)
    return files


def priors(folder: Path) -> list[str]:
    (folder / "h.txt").write_text("1 2 3 0 4", encoding="utf-8")
    (folder / "s.txt").write_text("10 20 200", encoding="utf-8")
    (folder / "z.txt").write_text("0 0 0", encoding="utf-8")
    good = ["uniform", "vonmises:135,6", f"histogram:{folder}/h.txt", f"sample:{folder}/s.txt"]
    bad = ["vonmises:nan,1", "vonmises:0,-1", f"histogram:{folder}/z.txt", "histogram:/no", "x:"]
    return good + bad


def command_line(
    rng: random.Random, parts: list[str], prior_specs: list[str], out: Path
) -> list[str]:
    """One generated command line (kept cheap: short plans, few trials)."""
    command = rng.choice(["squeeze", "push", "plan", "plan", "plan", "simulate", "simulate"])
    command = "plot" if rng.random() < 0.04 else command  # figures are slow: a few
    argv = [command, rng.choice(parts if rng.random() < 0.4 else CATALOGUE)]

    def maybe(p: float, *opt: str) -> None:
        if rng.random() < p:
            argv.extend(opt)

    def num() -> str:
        return rng.choice(BAD_NUMBERS if rng.random() < BAD else GOOD_NUMBERS)

    def pick(good: list[str], bad: list[str]) -> str:
        return rng.choice(bad if rng.random() < BAD else good)

    maybe(0.3, "--prior", pick(prior_specs[:4], prior_specs[4:]))
    maybe(0.1, "--com", pick(["10,10", "5,5"], ["0,0", "1e9,0", "a", "nan,nan"]))
    maybe(0.1, "--flatten-tol", num())
    maybe(0.05, "--element", pick(["0"], ["x", "1"]))
    if command in ("plan", "simulate", "plot"):
        argv += ["--max-squeezes", pick(["1", "2", "3"], ["0", "-1", "x"])]
        maybe(0.2, "--squeeze-cost", num())
        maybe(0.1, "--verify-cost", num())
        maybe(0.1, "--first-squeeze-cost", num())
        maybe(0.1, "--retry-cost", num())
        maybe(0.2, "--goal", pick(["single", "symmetry"], ["any"]))
        maybe(0.2, "--actions", pick(["squeeze", "push-grasp", "squeeze,push-grasp"], ["x", ""]))
        maybe(0.15, "--accuracy", num())
        maybe(0.1, "--method", pick(["exact", "bfs"], ["dfs"]))
    if command == "plan":
        maybe(0.2, "--guaranteed")
        maybe(0.1, "--export", str(out / pick(["r.csv", "r.json"], ["r.txt"])))
    if command == "simulate":
        argv += ["--trials", pick(["1", "50", "200"], ["0", "-5", "1000000000000"])]
        maybe(
            0.3,
            "--plan",
            pick(["bayes", "most-certain", "guaranteed", str(out / "p.json")], ["x"]),
        )
        maybe(0.2, "--noise", num())
        maybe(0.1, "--noise-kind", pick(["normal", "uniform"], ["cauchy"]))
        maybe(0.2, "--seed", pick(["0", "7"], ["-1", "x"]))
        maybe(0.05, "--offset", num())
    if command == "plot":
        argv += ["--out", str(out / "figs"), "--no-animation", "--image-formats"]
        argv.append(pick(["svg"], ["jpg", ""]))
        maybe(0.5, "--force")
    maybe(0.5, "--json")
    return argv


def digest(paths: list[Path]) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def test_cli_fuzz_campaign(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = random.Random(SEED)
    inputs = tmp_path / "in"
    inputs.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    files = part_files(inputs, rng)
    prior_specs = priors(inputs)
    bare = {"steps": [{"type": "squeeze", "alpha_rad": 0.3}], "final_orientation_rad": 0.0}
    (out / "p.json").write_text(json.dumps(bare), encoding="utf-8")
    before = digest(sorted(inputs.iterdir()))
    parts = CATALOGUE + [str(f) for f in files]
    codes: dict[int, int] = {}
    for case in range(CASES):
        argv = command_line(rng, parts, prior_specs, out)
        try:
            code = main(argv)
        except BaseException as exc:  # a bug: report the case to replay it
            pytest.fail(f"seed {SEED} case {case}: {argv} raised {type(exc).__name__}: {exc}")
        stdout, err = capsys.readouterr()
        assert code in (0, 1, 2), (SEED, case, argv, code, err)
        assert "Traceback" not in err, (SEED, case, argv, err)
        if code == 2:
            assert len(err.strip().splitlines()) == 1, (SEED, case, argv, err)
            assert stdout == "", (SEED, case, argv)
        if code == 0 and "--json" in argv and "--export" not in argv:
            json.loads(stdout)  # a machine can read it
        codes[code] = codes.get(code, 0) + 1
    assert digest(sorted(inputs.iterdir())) == before  # no input was written over
    print(f"seed {SEED}: {CASES} cases, exit codes {codes}")
    assert codes.get(0, 0) > CASES // 5 and codes.get(2, 0) > CASES // 10, codes
