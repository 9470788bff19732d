"""``Problem.state_distribution``: the plain-float path of the uniform prior against numpy's.

The fast path (uniform prior, the states' own transfer function, a Python float angle, at
most ``SMALL`` states) must give the same bits as the prior's vectorised ``mass``.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal

from bayesgrasp import Part, Problem
from bayesgrasp.model.prior import UniformPrior
from bayesgrasp.sizes import SMALL


class _Uniform(UniformPrior):
    """The uniform prior under another type: it takes the general (numpy) path."""


def _general(pb: Problem, angle: float) -> np.ndarray:
    f = pb.states
    return np.asarray(pb.prior.mass(f.basin_lo + angle, f.basin_hi + angle), dtype=np.float64)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(3, 12),
    angle=st.one_of(
        st.floats(-20.0, 20.0, allow_nan=False),
        st.sampled_from([0.0, -0.0, 1e-300, 3.141592653589793, 6.283185307179586]),
    ),
)
def test_uniform_plain_floats_equal_numpy(seed: int, n: int, angle: float) -> None:
    pts = np.random.default_rng(seed).uniform(size=(n, 2))
    part = Part.from_points(pts)
    pb = Problem.build(part)
    assert pb.n_states <= SMALL
    fast = pb.state_distribution(angle)
    assert fast.dtype == np.float64
    assert_array_equal(fast, _general(pb, angle))
    slow = Problem.build(part, prior=_Uniform()).state_distribution(angle)  # the numpy path
    assert fast.tobytes() == slow.tobytes()


def test_many_states_and_numpy_angles_take_numpy() -> None:
    t = 2 * np.pi * np.arange(SMALL + 7) / (SMALL + 7) + 0.01 * np.sin(np.arange(SMALL + 7))
    pb = Problem.build(Part.from_points(np.column_stack([np.cos(t), np.sin(t)])))
    assert pb.n_states > SMALL
    assert_array_equal(pb.state_distribution(0.3), _general(pb, 0.3))
    small = Problem.build(Part.from_points([(0, 0), (3, 0), (3, 1), (0, 1.5)]))
    a = np.float64(0.7)
    assert small.state_distribution(a).tobytes() == _general(small, 0.7).tobytes()
