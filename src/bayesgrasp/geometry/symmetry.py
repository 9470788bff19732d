"""Rotational symmetry of a convex polygon about its centroid.

A part with r-fold symmetry has a squeeze function of period ``2 pi / (r (1 + r mod 2))``
(the seed, section 4.1): no plan can tell orientations one period apart. The order is
tested within a tolerance, ``eps = Tolerance.symmetry * size``, since coordinates are
rounded: a turn by ``2 pi / r`` about the centroid must carry every vertex within ``eps`` of
another. A turn keeps the cyclic order of the vertices, so with ``n`` vertices vertex ``i``
must land on vertex ``i + n / r``: ``r`` divides ``n``, and only the divisors are tested,
largest first (the order is the largest that passes).

The test exists twice, held together by tests/geometry/test_numerics.py: on Python floats
for a few vertices (:func:`symmetry_order_python`) and by array operations for many
(:func:`symmetry_order_arrays`, which first compares the radii of a few spread-out vertices
for every order at once; a regular 10^5-gon has 36 divisors).

:func:`symmetrized_vertices` gives the nearest exactly symmetric polygon: each vertex
replaced by the mean of its orbit under the group's rotations (the orthogonal projection,
in the vertices' coordinates, onto the polygons with that symmetry).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from .coordinates import FloatArray

__all__ = [
    "orders_between",
    "orders_from",
    "symmetrized_vertices",
    "symmetry_order_arrays",
    "symmetry_order_python",
    "symmetry_orders",
    "turns_onto",
]


@functools.cache
def symmetry_orders(n: int) -> list[int]:
    """The divisors of ``n`` above 1, largest first: the possible orders of symmetry."""
    small = [r for r in range(2, math.isqrt(n) + 1) if n % r == 0]
    return sorted({n, *small, *(n // r for r in small)} - {1}, reverse=True)


@functools.cache
def orders_from(n: int, lowest: int) -> list[int]:
    """:func:`symmetry_orders` from ``lowest`` up (the caller must not change the list)."""
    return [r for r in symmetry_orders(n) if r >= lowest]


@functools.cache
def orders_between(n: int, lowest: int, below: int) -> list[int]:
    """:func:`symmetry_orders` from ``lowest`` up and below ``below`` (not to be changed)."""
    return [r for r in symmetry_orders(n) if lowest <= r < below]


def symmetry_order_python(
    xs: list[float], ys: list[float], centroid: Sequence[float], orders: list[int], eps: float
) -> int:
    """The first of ``orders`` that is a symmetry of the polygon, else 1 (a few vertices).

    :func:`symmetry_order_arrays` on Python floats, the same tests in the same order
    (tests/geometry/test_numerics.py holds the two together): faster below
    :data:`~bayesgrasp.sizes.SMALL` vertices. ``xs`` and ``ys`` are the vertices'
    coordinates. The distance of vertex ``n / r`` from the centroid, compared with vertex
    0's, rejects most orders of most parts before any other work.

    Examples
    --------
    >>> symmetry_order_python([0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0], (0.5, 0.5), [4, 2], 1e-9)
    4
    """
    if not orders:
        return 1
    cx, cy = centroid
    n = len(xs)
    r0 = math.hypot(xs[0] - cx, ys[0] - cy)
    for r in orders:
        step = n // r
        if abs(math.hypot(xs[step] - cx, ys[step] - cy) - r0) > eps:
            continue
        if turns_onto(xs, ys, cx, cy, r, eps):
            return r
    return 1


def turns_onto(xs: list[float], ys: list[float], cx: float, cy: float, r: int, eps: float) -> bool:
    """Whether a turn by ``2 pi / r`` about (cx, cy) keeps the vertices within ``eps``.

    Vertex i must land within ``eps`` of vertex ``i + n / r``: the test of one order of
    :func:`symmetry_order_python`, after its first, cheap rejection (the radii about the
    centroid, which the turn keeps, compared first).
    """
    n = len(xs)
    step = n // r
    radii = [math.hypot(x - cx, y - cy) for x, y in zip(xs, ys, strict=True)]
    if any(abs(radii[i + step] - radii[i]) > eps for i in range(n - step)):
        return False
    a = 2.0 * math.pi / r
    c, s = math.cos(a), math.sin(a)
    return all(
        math.hypot(
            c * (xs[i] - cx) - s * (ys[i] - cy) - (xs[(i + step) % n] - cx),
            s * (xs[i] - cx) + c * (ys[i] - cy) - (ys[(i + step) % n] - cy),
        )
        <= eps
        for i in range(n)
    )


def symmetry_order_arrays(
    vertices: FloatArray, centre: FloatArray, orders: list[int], eps: float
) -> int:
    """The first of ``orders`` that is a symmetry of the polygon, else 1 (many vertices).

    Parameters
    ----------
    vertices : ndarray of shape (N, 2)
        Counter-clockwise.
    centre : ndarray of shape (2,)
        The centroid: the centre of any rotational symmetry.
    orders : list of int
        Divisors of N, largest first.
    eps : float
        How far a turned vertex may land from its image.

    Examples
    --------
    >>> t = 2 * np.pi * np.arange(12) / 12
    >>> v = np.column_stack([np.cos(t), np.sin(t)])
    >>> symmetry_order_arrays(v, np.zeros(2), symmetry_orders(12), 1e-9)
    12
    """
    n = len(vertices)
    if not orders:
        return 1
    # Vertex i lands on vertex i + n / r, at the same distance from the centroid. Test
    # those distances on a few vertices for every order at once, then on all vertices for
    # the orders left: enough to reject most parts before the rotation test.
    probe = np.linspace(0, n - 1, 16).astype(np.intp)  # (16,) a few vertices, spread out
    steps = np.array([n // r for r in orders], dtype=np.intp)
    ends = (probe[None, :] + steps[:, None]) % n  # (R, 16) where each probe lands
    rp = np.hypot(*(vertices[probe] - centre).T)
    re = np.hypot(*(vertices[ends] - centre).transpose(2, 0, 1))
    left = [r for r, ok in zip(orders, np.max(np.abs(re - rp), axis=1) <= eps, strict=True) if ok]
    if not left:
        return 1
    v = vertices - centre
    radii = np.hypot(v[:, 0], v[:, 1])  # (N,) a rotation about the centroid keeps them
    for r in left:
        step = n // r
        if np.max(np.abs(radii[step:] - radii[:-step])) > eps:
            continue
        a = 2.0 * math.pi / r
        c, s = math.cos(a), math.sin(a)
        turned = v @ np.array([[c, s], [-s, c]])  # (N, 2) rotated counter-clockwise
        miss = turned - np.concatenate((v[step:], v[:step]))
        if np.all(np.hypot(miss[:, 0], miss[:, 1]) <= eps):
            return r
    return 1


def symmetrized_vertices(v: FloatArray, c: FloatArray, r: int, centred: bool) -> FloatArray:
    """The vertices ``v`` made exactly r-fold symmetric about ``c`` (the orbit means).

    Vertex ``i + k n / r`` turned back by ``2 pi k / r`` about ``c``, averaged over ``k``,
    and the mean turned forward again; relative to ``c`` when ``centred``. See
    :meth:`~bayesgrasp.geometry.convex.ConvexPolygon.symmetrized`.

    Examples
    --------
    >>> v = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.000004]])
    >>> np.hypot(*symmetrized_vertices(v, np.zeros(2), 4, True).T).round(9).tolist()
    [1.000001, 1.000001, 1.000001, 1.000001]
    """
    n = len(v)
    step = n // r
    a = 2.0 * math.pi * np.arange(r) / r  # (r,)
    cos, sin = np.cos(a)[:, None], np.sin(a)[:, None]
    blocks = (v - c).reshape(r, step, 2)  # (r, n / r, 2): block k is block 0 turned k times
    back_x = cos * blocks[..., 0] + sin * blocks[..., 1]  # (r, n / r) turned back
    back_y = -sin * blocks[..., 0] + cos * blocks[..., 1]
    mx, my = back_x.mean(axis=0), back_y.mean(axis=0)  # (n / r,) orbit means
    out = np.empty((r, step, 2))
    out[..., 0] = cos * mx - sin * my
    out[..., 1] = sin * mx + cos * my
    flat = out.reshape(n, 2)
    return flat if centred else flat + c
