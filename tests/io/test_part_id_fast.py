"""``part_id``'s plain-Python path for small hulls against its numpy path (issue 12).

For a hull of at most ``sizes.SMALL`` vertices :func:`bayesgrasp.io.plans.part_id` rounds
and hashes on Python floats; forcing the numpy path (``_small_id_bytes`` returning ``None``)
must give the same id for every part, including coordinates that round at exact halves.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bayesgrasp.geometry.polygon import Part
from bayesgrasp.io import part_identity
from bayesgrasp.io.plans import part_id
from bayesgrasp.shapes import load, names


def _both(part: Part) -> tuple[str, str]:
    fast = part_id(part)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(part_identity, "_small_id_bytes", lambda *_: None)
        general = part_id(part)
    return fast, general


def test_the_small_path_is_taken() -> None:
    part = load("key")
    assert part_identity._small_id_bytes(part, part_identity._grid(part.hull)) is not None


@pytest.mark.parametrize("name", names())
def test_catalogue_parts(name: str) -> None:
    fast, general = _both(load(name))
    assert fast == general


_coord = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(
    pts=st.one_of(
        st.lists(st.tuples(_coord, _coord), min_size=3, max_size=40),
        st.lists(st.tuples(st.integers(-6, 6), st.integers(-6, 6)), min_size=3, max_size=40),
    )
)
def test_random_parts(pts: list[tuple[float, float]]) -> None:
    try:
        part = Part.from_points(pts)
    except ValueError:  # too few distinct points, collinear
        return
    fast, general = _both(part)
    assert fast == general


@settings(max_examples=200, deadline=None)
@given(
    pts=st.lists(st.tuples(st.integers(-40, 40), st.integers(-40, 40)), min_size=3, max_size=30),
    com=st.tuples(st.integers(-3, 3), st.integers(-3, 3)),
)
def test_exact_halves_round_to_even(pts: list[tuple[int, int]], com: tuple[int, int]) -> None:
    """Vertices on a quarter grid and a rounding step of 1/2: many ties, even on both paths."""
    try:
        part = Part.from_points(
            [(x / 4, y / 4) for x, y in pts], center_of_mass=(com[0] / 4, com[1] / 4)
        )
    except ValueError:  # degenerate, or the centre of mass outside the hull
        return
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(part_identity, "_grid", lambda hull: 0.5)
        fast, general = _both(part)
    assert fast == general


def test_a_large_hull_takes_numpy() -> None:
    t = 2 * math.pi * np.arange(200) / 200
    part = Part.from_points(np.column_stack([np.cos(t), 2 * np.sin(t)]))
    assert len(part.hull.vertices) > part_identity.SMALL
    assert part_id(part).startswith("sha256:")


def test_values_near_the_int64_limit() -> None:
    """Rounded values within int64 are packed as numpy casts them; beyond it, numpy decides."""
    square = Part.from_points([(0.0, 0.0), (3.0, 0.0), (3.0, 3.0), (0.0, 3.0)])
    step = 2.0**-62  # (x - cx) / step = +-1.5 * 2^62: in [2^62, 2^63), numpy's cast exact
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(part_identity, "_grid", lambda hull: step)
        assert part_identity._small_id_bytes(square, step) is not None
        fast, general = _both(square)
    assert fast == general
    wide = Part.from_points([(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 3.0)])
    assert part_identity._small_id_bytes(wide, step) is None  # 2^63: beyond int64
    assert part_identity._small_id_bytes(wide, 1e-320) is None  # an infinity
    assert part_identity._small_id_bytes(wide, math.nan) is None
