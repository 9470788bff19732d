"""The point-list reader's plain-Python path for small parts against its numpy path (issue 12).

``point_list_part`` decides outline or cloud, simple or not, convex or not, on Python floats
for at most ``sizes.SMALL`` points; forcing the general path (``_small_floats`` returning
``None``) must give the same part, or the same error, on every input.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import orjson
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp.errors import BayesGraspError
from bayesgrasp.io import points as points_module
from bayesgrasp.io.points import point_list_part

PATH = Path("p.json")


def _outcome(pts: object) -> tuple[object, ...]:
    """The part's arrays and name, or the error's type and message."""
    try:
        part = point_list_part(PATH, pts, "p")
    except BayesGraspError as exc:
        return (type(exc).__name__, str(exc))
    return (
        part.hull.vertices.tolist(),
        part.outline.tolist(),
        part.center_of_mass.tolist(),
        [h.tolist() for h in part.holes],
    )


def _both(pts: object, monkeypatch: pytest.MonkeyPatch) -> tuple[object, object]:
    fast = _outcome(pts)
    with monkeypatch.context() as m:
        m.setattr(points_module, "_small_floats", lambda _: None)
        general = _outcome(pts)
    return fast, general


# Small integer grids make collinear runs, repeated points, touching and crossing edges
# common; floats add near-degenerate turns.
_grid = st.lists(st.lists(st.integers(-4, 4), min_size=2, max_size=2), min_size=3, max_size=12)
_floats = st.lists(
    st.lists(st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False), min_size=2, max_size=2),
    min_size=3,
    max_size=20,
)


@settings(max_examples=300, deadline=None)
@given(pts=st.one_of(_grid, _floats))
def test_fast_and_general_paths_agree(pts: list[list[float]]) -> None:
    with pytest.MonkeyPatch.context() as mp:
        fast, general = _both(pts, mp)
    assert fast == general


@pytest.mark.parametrize(
    "pts",
    [
        [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],  # an L outline
        [[0, 0], [1, 1], [1, 0], [0, 1]],  # a bow tie: a cloud
        [[0, 0], [2, 0], [1, 0], [1, 1]],  # folds back along an edge
        [[0, 0], [1, 0], [1, 0], [1, 1], [0, 0]],  # repeated and closing points
        [[0, 0], [1, 0], [2, 0]],  # collinear: an error
        [[0, 0], [0, 0], [0, 0]],  # one point: an error
        [[0, 0], [1, 0], [0, float("nan")]],  # NaN: the general path's error
        [[0, 0], [1, 0], [0, 1e200]],  # too large
        [[0, 0], [1, 0], [True, 1]],  # a boolean
        [[0, 0], [1, 0], [0, 10**400]],  # an int beyond floats
        [[0, 0], [1, 0], [0, 2**60 + 1]],  # an int numpy and float() might round apart
        [[0, 0], [1, 0], [0, 1, 2]],  # a bad shape
        [[0.0, 0.0], [1.0, 1e-13], [2.0, 0.0], [1.0, 1.0]],  # a nearly straight turn
    ],
)
def test_adversarial_inputs_agree(pts: list[list[object]], monkeypatch: pytest.MonkeyPatch) -> None:
    fast, general = _both(pts, monkeypatch)
    assert fast == general


def test_fast_path_taken_for_small_lists() -> None:
    assert points_module._small_floats([[0, 0], [1, 0], [0, 1]]) == (
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    )
    assert points_module._small_floats([[0, 0], [1, 0], [0, True]]) is None
    assert points_module._small_floats(np.zeros((3, 2)).tolist() * 30) is None  # above SMALL


def _read(fn: object, *args: object) -> tuple[object, ...] | None:
    try:
        part = fn(*args)  # type: ignore[operator]
    except BayesGraspError as exc:
        return (type(exc).__name__, str(exc))
    if part is None:
        return None
    return (part.name, part.units, part.hull.vertices.tolist(), part.center_of_mass.tolist())


@pytest.mark.parametrize(
    "line",
    [
        '{"name": "a", "vertices": [[0, 0], [3, 0], [0, 1]], "units": "mm"}',
        '{"vertices": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}',
        '{"vertices": [[0, 0], [1, 0], [2, 0]]}',  # collinear: the same error
        '{"vertices": [[0, 0], [1, 0], [0, 1]], "center_of_mass": [5, 5]}',
        '{"vertices": "none"}',
        '{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 1], [0, 0]]]}',
        '{"vertices": [[0, 0], [1, 0], [0, 1e999]]}',  # too large: the general path
        '{"vertices": [[0, 0], [1, 0], [0, NaN]]}',
        "[[0, 0], [1, 0], [0, 1]]",  # not an object: the general path
        '{"vertices": [[0, 0], [1, 0], [0, 1]]',  # malformed: the general path
    ],
)
def test_json_line_part_reads_as_parse_json(line: str) -> None:
    from bayesgrasp.io._common import ReadOptions
    from bayesgrasp.io.points import json_line_part, parse_json

    fast = _read(json_line_part, line, "b.jsonl:3")
    general = _read(parse_json, line.encode(), Path("b.jsonl:3"), ReadOptions())
    general_path = "1e999" in line or line.startswith("[") or not line.endswith("}")
    assert (fast is None) == general_path
    if fast is not None:
        assert fast == general


def _star(n: int, step: int, radius: float = 1.0, centre: tuple[float, float] = (0.0, 0.0)):
    """The regular star polygon {n/step} (a convex n-gon for step 1)."""
    t = 2 * np.pi * step * np.arange(n) / n
    return np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])


def _decisions(pts: list[list[float]]) -> tuple[bool, bool | None, bool]:
    """(firmly convex, simple, convex) of the plain-Python tests, on the cleaned ring."""
    small = points_module._small_floats(pts)
    assert small is not None
    ring = points_module._small_ring(list(zip(*small, strict=True)))
    turns = points_module._turns(ring)
    simple = points_module._small_is_simple(ring, turns)
    convex = points_module._small_is_convex(ring, turns) if simple else None
    return bool(_firm_turn(ring)), simple, bool(convex)


def _firm_turn(ring: list[tuple[float, float]]) -> float:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    return points_module._firm_turn(xs, ys, min(xs), max(xs), min(ys), max(ys))


def _firm_turn_by_angles(ring: list[tuple[float, float]]) -> float:
    """The reference: the winding summed from each vertex's turning angle (the former test)."""
    n = len(ring)
    turns = []
    for i in range(n):
        (ax, ay), (bx, by), (cx, cy) = ring[i - 1], ring[i], ring[(i + 1) % n]
        ux, uy, wx, wy = bx - ax, by - ay, cx - bx, cy - by
        turns.append((ux * wy - uy * wx, ux * wx + uy * wy))
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    firm = points_module._FIRM * ((max(xs) - min(xs)) ** 2 + (max(ys) - min(ys)) ** 2)
    low, high = min(t[0] for t in turns), max(t[0] for t in turns)
    least = low if low > firm else high if high < -firm else 0.0
    if not least:
        return 0.0
    winding = sum(math.atan2(abs(c), d) for c, d in turns)
    return least if winding < 3 * math.pi else 0.0


@pytest.mark.parametrize(
    "pts",
    [
        _star(5, 2).tolist(),  # a pentagram: turns one way, winds twice
        _star(10, 3).tolist(),  # {10/3}: winds three times
        _star(7, 1).tolist(),
        _star(64, 1, 1e6, (1e7, -3e7)).tolist(),  # tiny turns far from the origin
        _star(60, 1, 1.0, (1e9, 1e9)).tolist(),  # far from the origin: firm all the same
        [[0, 0], [1, 0], [2, 1e-13], [2, 1], [0, 1]],  # a nearly straight vertex
        [[0, 0], [1e6, 0], [1e6, 1e-6], [0, 1e-6]],  # very thin
        [[0, 0], [1, 0], [1, 1], [0, 1]][::-1],  # clockwise
        [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],  # an L: not convex
    ],
)
def test_firmly_convex_implies_simple_and_convex(
    pts: list[list[float]], monkeypatch: pytest.MonkeyPatch
) -> None:
    firm, simple, convex = _decisions(pts)
    if firm:
        assert simple and convex
    fast, general = _both(pts, monkeypatch)
    assert fast == general


def test_stars_and_tiny_turns_are_not_firm() -> None:
    assert not _decisions(_star(5, 2).tolist())[0]
    assert not _decisions([[0, 0], [1, 0], [2, 1e-13], [2, 1], [0, 1]])[0]
    assert _decisions(_star(7, 1).tolist())[0]
    assert _decisions(_star(60, 1, 1.0, (1e9, 1e9)).tolist())[0]  # rounding relative to D


# Convex polygons (random points on a circle, in order, either way round), near-degenerate
# ones (points nearly on a line or huge offsets) and stars.
@settings(max_examples=300, deadline=None)
@given(
    angles=st.lists(st.floats(0.0, 2 * np.pi, exclude_max=True), min_size=3, max_size=40),
    radius=st.sampled_from([1e-6, 1.0, 1e6]),
    offset=st.sampled_from([0.0, 1.0, 1e8, -1e12]),
    squash=st.sampled_from([1.0, 1e-6, 1e-12]),
    step=st.integers(1, 4),
    reverse=st.booleans(),
)
def test_firm_convexity_against_the_pair_test(
    angles: list[float], radius: float, offset: float, squash: float, step: int, reverse: bool
) -> None:
    t = np.sort(np.asarray(angles))
    order = np.concatenate([np.arange(k, len(t), step) for k in range(step)])  # wind `step` x
    pts = np.column_stack([offset + radius * np.cos(t[order]), squash * radius * np.sin(t[order])])
    pts_list = (pts[::-1] if reverse else pts).tolist()
    if points_module._small_floats(pts_list) is None:
        return
    small = points_module._small_floats(pts_list) or ([], [])
    if len(points_module._small_ring(list(zip(*small, strict=True)))) < 3:
        return
    firm, simple, convex = _decisions(pts_list)
    if firm:
        assert simple and convex
    with pytest.MonkeyPatch.context() as mp:
        fast, general = _both(pts_list, mp)
    assert fast == general


# Rings that wind 1 to 4 times, turning either way, with tiny turns, far from the origin, or
# not turning one way at all (random points): the count of upward crossings against the sum
# of turning angles.
@settings(max_examples=500, deadline=None)
@given(
    angles=st.lists(st.floats(0.0, 2 * np.pi, exclude_max=True), min_size=3, max_size=40),
    radius=st.sampled_from([1e-6, 1.0, 1e6]),
    offset=st.sampled_from([0.0, 1.0, 1e8, -1e12]),
    squash=st.sampled_from([1.0, 1e-6, 1e-12]),
    step=st.integers(1, 4),
    reverse=st.booleans(),
    swap=st.booleans(),
    sort=st.booleans(),
)
def test_winding_counted_as_summed(
    angles: list[float],
    radius: float,
    offset: float,
    squash: float,
    step: int,
    reverse: bool,
    swap: bool,
    sort: bool,
) -> None:
    t = np.sort(np.asarray(angles)) if sort else np.asarray(angles)
    order = np.concatenate([np.arange(k, len(t), step) for k in range(step)])
    x, y = offset + radius * np.cos(t[order]), squash * radius * np.sin(t[order])
    pts = np.column_stack([y, x] if swap else [x, y])
    ring = [(float(a), float(b)) for a, b in (pts[::-1] if reverse else pts)]
    got = _firm_turn(ring)
    assert got == _firm_turn_by_angles(ring)
    if got:
        assert math.copysign(1.0, got) == (1.0 if _shoelace(ring) > 0 else -1.0)


def _shoelace(ring: list[tuple[float, float]]) -> float:
    """Twice the signed area, about the first point (no cancellation far from the origin)."""
    ox, oy = ring[0]
    p = [(x - ox, y - oy) for x, y in ring]
    return sum(ax * by - bx * ay for (ax, ay), (bx, by) in zip(p, p[1:] + p[:1], strict=True))


@pytest.mark.parametrize(
    "ring",
    [
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],  # edges along the axes
        [(0.0, 1.0), (0.0, 0.0), (1.0, 0.0)],
        [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)][::-1],
        [tuple(p) for p in _star(5, 2).tolist()],  # winds twice
        [tuple(p) for p in _star(9, 4).tolist()],  # winds four times
        [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (1.0, 0.5), (0.0, 2.0)],  # turns both ways
    ],
)
def test_winding_counted_on_axis_edges_and_stars(ring: list[tuple[float, float]]) -> None:
    for k in range(len(ring)):
        turned = ring[k:] + ring[:k]
        assert _firm_turn(turned) == _firm_turn_by_angles(turned)
        swapped = [(b, a) for a, b in turned]
        assert _firm_turn(swapped) == _firm_turn_by_angles(swapped)


# JSON values as orjson reads them: every leaf type, pairs that are strings or objects of
# two, big and exact-limit integers and floats, nesting.
_leaf = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.floats(-1e3, 1e3),
    st.integers(-(2**53) - 2, 2**53 + 2),
    st.sampled_from([2**53, -(2**53), 2**53 + 1, 2**63, -(2**63), 2**64 - 1]),
    st.sampled_from([2.0**53, -(2.0**53), 2.0**53 + 2, 1e300, -0.0, 5e-324]),
    st.booleans(),
    st.none(),
    st.text(max_size=2),
)
_number = st.one_of(st.floats(-1e17, 1e17), st.integers(-(2**54), 2**54))
_item = st.one_of(
    st.lists(_number, min_size=2, max_size=2),
    st.lists(_number, min_size=2, max_size=2),
    st.lists(_leaf, min_size=2, max_size=2),
    st.lists(_leaf, max_size=3),
    st.dictionaries(st.text(max_size=2), _leaf, min_size=2, max_size=2),
    st.text(min_size=2, max_size=2),
    _leaf,
)


@settings(max_examples=500, deadline=None)
@given(points=st.one_of(st.lists(_item, max_size=70), _leaf))
def test_line_floats_are_the_small_floats(points: object) -> None:
    read = orjson.loads(orjson.dumps(points))
    assert points_module._line_floats(read) == points_module._small_floats(read, math.inf)


def test_orjson_reads_only_finite_floats() -> None:
    """What _line_floats relies on: orjson refuses what would be a NaN or an infinity."""
    for text in ["[NaN]", "[Infinity]", "[-Infinity]", "[1e400]", "[-1e999]"]:
        with pytest.raises(orjson.JSONDecodeError, match=r"."):
            orjson.loads(text)
    assert orjson.loads("[1e-400, 18446744073709551616]") == [0.0, 2.0**64]


def test_line_floats_cases() -> None:
    line = points_module._line_floats
    assert line([[0, 0], [1, 0.5], [0, 1]]) == ([0.0, 1.0, 0.0], [0.0, 0.5, 1.0])
    assert line([[0, 0], [1, 0], [0, 2**53]]) == ([0.0, 1.0, 0.0], [0.0, 0.0, 2.0**53])
    assert line([[0, 0], [1, 0], [0, 2**53 + 1]]) is None  # would round to 2^53
    assert line([[0, 0], [1, 0], [-(2**53) - 1, 0]]) is None
    big = 2.0**53 + 2  # a float: the limit is the caller's
    assert line([[0, 0], [1, 0], [0, big]]) == ([0.0, 1.0, 0.0], [0.0, 0.0, big])
    assert line([[0.0, 0.0], [1.0, 0.0], [0.0, 1e300]]) == ([0.0, 1.0, 0.0], [0.0, 0.0, 1e300])
    assert line([[0, 0], [1, 0], "ab"]) is None
    assert line([[0, 0], [1, 0], {"a": 1, "b": 2}]) is None
    assert line([[0, 0], [1, 0], [0, True]]) is None
    assert line([[0, 0], [1, 0], [0, 1, 2]]) is None
    assert line([[0, 0], [1, 0], [0]]) is None
    assert line([[0, 0], [1, 0], 5]) is None
    assert line([[0, 0], [1, 0]]) is None
    assert line([[0.0, 0.0]] * 65) is None  # above SMALL


def _record_strict_decodes(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The lines the strict decoder reads from now on (it still decodes them)."""
    used: list[str] = []
    strict = points_module._DECODER

    class Recording:
        def decode(self, text: str) -> object:
            used.append(text)
            return strict.decode(text)

    monkeypatch.setattr(points_module, "_DECODER", Recording())
    return used


@pytest.mark.parametrize(
    ("far", "strict"),
    [
        ("9007199254740992.0", False),  # 2^53: read by orjson's values
        ("9007199254740994.0", True),  # beyond: the strict decoder reads the line
        ("-9007199254740994.0", True),
        ("-9007199254740992", False),
        ("9007199254740993", True),
    ],
)
def test_coordinates_beyond_2_53_take_the_strict_decoder(
    far: str, strict: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    from bayesgrasp.io._common import ReadOptions
    from bayesgrasp.io.points import json_line_part, parse_json

    used = _record_strict_decodes(monkeypatch)
    for line in [
        f'{{"vertices": [[0, 0], [{far}, 0], [0, 1e15]]}}',
        f'{{"vertices": [[0.0, 0.0], [0.0, 1e15], [{far}, 5.0]]}}',
    ]:
        used.clear()
        fast = _read(json_line_part, line, "b.jsonl:3")
        assert (used == [line]) == strict
        assert fast == _read(parse_json, line.encode(), Path("b.jsonl:3"), ReadOptions())


# Lines of the shape the batch reads without the strict decoder, and near it: numbers of
# every kind (beyond a float, big integers, booleans, constants), names and extra members.
_plain_number = st.one_of(
    st.floats(-1e6, 1e6, allow_nan=False).map(repr), st.integers(-9, 9).map(str)
)
_odd_number = st.one_of(
    st.integers(-(2**60), 2**60).map(str),
    st.sampled_from(["1e400", "-1e999", "NaN", "Infinity", "true", "null", "1" * 301, "2e-320"]),
    # integers beyond 2^53 and 64 bits (orjson, the first reader, makes floats of the latter)
    st.sampled_from(["9007199254740993", "18446744073709551617", "-9223372036854775809"]),
    st.integers(-(10**30), 10**30).map(str),
)
_number_text = st.one_of(_plain_number, _plain_number, _plain_number, _odd_number)
_point_text = st.one_of(
    st.tuples(_number_text, _number_text).map(lambda p: f"[{p[0]}, {p[1]}]"),
    st.lists(_number_text, min_size=1, max_size=3).map(lambda p: f"[{', '.join(p)}]"),
)


_clean_points = st.lists(
    st.tuples(_plain_number, _plain_number).map(lambda p: f"[{p[0]}, {p[1]}]"),
    min_size=3,
    max_size=10,
)


@settings(max_examples=300, deadline=None)
@given(
    points=st.one_of(_clean_points, st.lists(_point_text, min_size=0, max_size=10)),
    name=st.sampled_from(['"a"', '"caf\\u00e9"', '"\\ud800"', '"\\ud83d\\ude00"', "5", None]),
    extra=st.sampled_from([None, '"units": "mm"', '"center_of_mass": [0.1, 0.2]', '"x": 1e400']),
)
def test_json_lines_read_as_parse_json(
    points: list[str], name: str | None, extra: str | None
) -> None:
    from bayesgrasp.io._common import ReadOptions
    from bayesgrasp.io.points import json_line_part, parse_json

    members = [f'"vertices": [{", ".join(points)}]']
    members += [f'"name": {name}'] if name is not None else []
    members += [extra] if extra is not None else []
    line = "{" + ", ".join(members) + "}"
    fast = _read(json_line_part, line, "b.jsonl:3")
    general = _read(parse_json, line.encode(), Path("b.jsonl:3"), ReadOptions())
    if fast is not None:  # None: the batch reads the line the general way
        assert fast == general


def test_simple_lines_skip_the_strict_decoder(monkeypatch: pytest.MonkeyPatch) -> None:
    """The comparison above sees the C-number path: simple lines never reach _DECODER."""
    from bayesgrasp.io.points import json_line_part

    used = _record_strict_decodes(monkeypatch)
    part = json_line_part('{"name": "w", "vertices": [[0, 0], [3, 0.5], [0, 1]]}', "b.jsonl:1")
    assert part is not None and part.name == "w"
    assert json_line_part('{"vertices": [[0, 0], [3, 0], [0, 1]]}', "b.jsonl:2").name == "b"
    assert used == []
    # a number beyond a float, or another member: the strict decoder reads the line
    assert json_line_part('{"vertices": [[0, 0], [3, 0], [0, 1e400]]}', "b.jsonl:3") is None
    json_line_part('{"vertices": [[0, 0], [3, 0], [0, 1]], "units": "mm"}', "b.jsonl:4")
    assert len(used) == 2
