"""Every ``--json`` document of the snapshot ``tests/snapshots/cli.json``, re-run and compared.

Each stored command line is run in-process with the current code from the repository root; the
exit code must be the same and the document equal to the stored one: floats to a relative or
absolute 1e-9, everything else (ints, strings, bools, null, list lengths, the stored object
keys) exactly; keys a document gained since the snapshot are allowed (new fields are fine,
changed values are not). Wall times (``VOLATILE_KEYS``) are not compared. To change the
snapshot on purpose, run ``python tests/snapshots/generate.py`` and review the diff of ``cli.json``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from snapshots.generate import (
    MORE,
    ROOT,
    SNAPSHOT,
    VOLATILE_KEYS,
    drop_volatile,
    numbers,
    run_cli,
    run_more,
)

REL = ABS = 1e-9

ENTRIES: list[dict[str, Any]] = json.loads(SNAPSHOT.read_text(encoding="utf-8"))
MORE_ENTRIES: list[dict[str, Any]] = json.loads(MORE.read_text(encoding="utf-8"))


def _kind(x: Any) -> str:
    """JSON type of a parsed value (bool before int: a bool is an int in Python)."""
    for t, name in ((bool, "bool"), (int, "int"), (float, "float"), (str, "string")):
        if isinstance(x, t):
            return name
    if x is None:
        return "null"
    return {list: "array", dict: "object"}.get(type(x), type(x).__name__)


def first_difference(expected: Any, actual: Any, path: str = "$") -> str | None:
    """Where ``actual`` first differs from ``expected`` and how, or ``None`` if they agree.

    Floats agree to a relative or absolute ``1e-9``; ints, strings, bools, null and list
    lengths must be equal; every stored object key must be there (added keys are allowed).
    """
    ke, ka = _kind(expected), _kind(actual)
    if ke != ka:
        return f"{path}: expected {ke} {expected!r}, got {ka} {actual!r}"
    if ke == "float":
        if math.isclose(expected, actual, rel_tol=REL, abs_tol=ABS):
            return None
        return f"{path}: expected {expected!r}, got {actual!r}"
    if ke == "array":
        if len(expected) != len(actual):
            return f"{path}: expected {len(expected)} items, got {len(actual)}"
        for i, (e, a) in enumerate(zip(expected, actual, strict=True)):
            diff = first_difference(e, a, f"{path}[{i}]")
            if diff is not None:
                return diff
        return None
    if ke == "object":  # keys added since the snapshot are fine; a key gone is not
        missing = sorted(set(expected) - set(actual))
        if missing:
            return f"{path}: keys missing {missing}"
        for k in expected:
            diff = first_difference(expected[k], actual[k], f"{path}.{k}")
            if diff is not None:
                return diff
        return None
    if expected != actual:
        return f"{path}: expected {expected!r}, got {actual!r}"
    return None


@pytest.mark.parametrize("entry", ENTRIES, ids=[" ".join(e["argv"]) for e in ENTRIES])
def test_cli_json_unchanged(entry: dict[str, Any], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    code, doc = run_cli(entry["argv"])
    assert code == entry["exit_code"]
    diff = first_difference(entry["json"], doc)
    assert diff is None, diff


@pytest.mark.parametrize("entry", MORE_ENTRIES, ids=[" ".join(e["argv"]) for e in MORE_ENTRIES])
def test_cli_more_unchanged(
    entry: dict[str, Any], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Sensing, noise, payoff, several parts, batch, tables and robot files as they were."""
    monkeypatch.chdir(ROOT)
    got = run_more(entry, tmp_path)
    assert got["exit_code"] == entry["exit_code"]
    if "numbers" in entry:  # a table may gain lines; the numbers it had stay, in order
        missing = missing_numbers(entry["numbers"], got["numbers"])
        assert missing is None, missing
    for key in ("json", "jsonl", "files"):
        if key in entry:
            diff = first_difference(entry[key], got.get(key), f"$.{key}")
            assert diff is None, diff


def missing_numbers(expected: list[float], actual: list[float]) -> str | None:
    """The first expected number not found, in order, among the actual ones (or ``None``)."""
    i = 0
    for k, x in enumerate(expected):
        while i < len(actual) and not math.isclose(x, actual[i], rel_tol=REL, abs_tol=ABS):
            i += 1
        if i == len(actual):
            return f"number #{k} ({x!r}) of the table is gone (after {expected[:k][-3:]})"
        i += 1
    return None


def test_missing_numbers() -> None:
    assert missing_numbers([1.0, 2.0], [1.0, 5.0, 2.0, 7.0]) is None
    assert missing_numbers([1.0, 2.0], [2.0, 1.0]) is not None
    assert missing_numbers([1.0], [1.0 + 1e-6]) is not None


def test_numbers_of_a_table() -> None:
    assert numbers("p 0.5, cost -4e+00 at 12 deg\nwall time 0.01 s (3e6 trials/s)\n") == [
        0.5,
        -4.0,
        12.0,
    ]


def test_snapshot_has_no_volatile_keys() -> None:
    assert drop_volatile(ENTRIES) == ENTRIES
    assert {"seconds", "planner_seconds"} <= VOLATILE_KEYS


def test_first_difference_paths() -> None:
    doc = {"a": [1, 2.0, {"b": None, "c": "x", "d": True}]}
    assert first_difference(doc, json.loads(json.dumps(doc))) is None
    assert first_difference(doc, {"a": [1, 2.0 * (1 + 1e-10), doc["a"][2]]}) is None
    assert first_difference({"x": 0.0}, {"x": 1e-10}) is None
    assert first_difference({"x": 0.0}, {"x": 0.0, "added": 1}) is None  # new keys are fine
    cases = [
        ({"a": [1, 2.0 + 1e-6, doc["a"][2]]}, "$.a[1]: expected 2.0, got 2.000001"),
        ({"a": [2, 2.0, doc["a"][2]]}, "$.a[0]: expected 1, got 2"),
        ({"a": [1.0, 2.0, doc["a"][2]]}, "$.a[0]: expected int 1, got float 1.0"),
        ({"a": [1, 2.0]}, "$.a: expected 3 items, got 2"),
        ({"a": [1, 2.0, {"b": 0.0, "c": "x", "d": True}]}, "$.a[2].b: expected null None"),
        ({"a": [1, 2.0, {"b": None, "c": "y", "d": True}]}, "$.a[2].c: expected 'x', got 'y'"),
        ({"a": [1, 2.0, {"b": None, "c": "x", "d": 1}]}, "$.a[2].d: expected bool True"),
        ({"a": [1, 2.0, {"b": None, "c": "x"}]}, "$.a[2]: keys missing ['d']"),
    ]
    for actual, message in cases:
        diff = first_difference(doc, actual)
        assert diff is not None
        assert diff.startswith(message), diff


def test_run_cli_refuses_text_output(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    with pytest.raises(ValueError, match="stdout is not JSON"):
        run_cli(["squeeze", "triangle"])
