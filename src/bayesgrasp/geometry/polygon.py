"""Planar parts: the convex polygon the gripper sees, and the part the user gave.

A frictionless parallel-jaw gripper only ever touches the convex hull of a part (the seed,
section 4.1, assumption 3, and Appendix A: "the diameter function for C is equal to the
diameter function for the convex hull of C"), so every transfer function is built from a
:class:`ConvexPolygon`. The :class:`Part` keeps the user's outline, name, units and centre of
mass beside the hull; the centre of mass matters for pushing (Goldberg 1993).

The library never rotates the user's coordinates: an orientation ``theta`` is always the
rotation of the part *as given* relative to the gripper frame.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, NoReturn

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PartError
from ..sizes import SMALL
from ..tolerance import DEFAULT_TOLERANCE, Tolerance
from ..units import unit_name

__all__ = ["ConvexPolygon", "Part", "as_points", "find_crossing", "polygon_area_centroid"]

FloatArray = NDArray[np.float64]
_FLOAT64 = np.dtype(np.float64)


def as_points(points: ArrayLike, what: str = "vertices") -> FloatArray:
    """Validate a point list and return it as a float64 array of shape (N, 2).

    Parameters
    ----------
    points : array_like of shape (N, 2)
        Coordinates; must be finite numbers.
    what : str
        Name used in error messages.

    Returns
    -------
    ndarray of shape (N, 2)

    Raises
    ------
    PartError
        If the input is not numeric, has the wrong shape, or holds NaN or infinite values.

    Examples
    --------
    >>> as_points([(0, 0), (1, 0), (0, 1)]).shape
    (3, 2)
    """
    if (
        type(points) is np.ndarray
        and points.dtype == np.float64
        and points.ndim == 2
        and points.shape[1] == 2
    ):  # already float64 (N, 2): a copy, if finite (the same result as below, sooner)
        arr = points.copy()
        if arr.size and not np.isfinite(arr).all():
            bad = int(np.argwhere(~np.isfinite(arr))[0, 0])
            raise PartError(f"`{what}` must be finite; point {bad} is {arr[bad].tolist()}")
        return arr
    try:
        raw = np.asarray(points)
        items = None
        if not isinstance(points, np.ndarray) and raw.dtype.kind in "iuf":
            # Lists mixing booleans and numbers become numbers in numpy: look at the items.
            items = np.asarray(points, dtype=object)
    except (TypeError, ValueError, OverflowError, RecursionError) as exc:
        # Ragged or deeply nested lists, objects whose __array__ or __len__ fails ...
        raise PartError(
            f"`{what}` must be numbers of shape (N, 2); could not read them: {exc}"
        ) from None
    if raw.dtype.kind not in "iuf":
        _check_real(raw, what)
    elif items is not None and items.ndim == 2:
        _check_real(items, what)
    if raw.ndim != 2 or raw.shape[1] != 2:
        raise PartError(f"`{what}` must have shape (N, 2); got shape {raw.shape}")
    try:
        arr = np.array(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        # Python ints beyond the float range (10**400), or numbers whose __float__ fails.
        raise PartError(_unconvertible(raw, what, exc)) from None
    if not np.all(np.isfinite(arr)):
        bad = int(np.argwhere(~np.isfinite(arr))[0, 0])
        raise PartError(f"`{what}` must be finite; point {bad} is {arr[bad].tolist()}")
    return arr


def _unconvertible(raw: NDArray[Any], what: str, exc: Exception) -> str:
    """Why an array of real numbers (dtype object) could not become float64."""
    for i, row in enumerate(raw.tolist()):
        for x in row:
            try:
                float(x)
            except OverflowError:
                bits = x.bit_length() if isinstance(x, int) else 0
                about = f" (about 1e{int(bits * math.log10(2))})" if bits else ""
                return (
                    f"`{what}` must be finite numbers within the range of a float; point {i} "
                    f"has a coordinate too large{about}"
                )
            except (TypeError, ValueError):
                break
    return f"`{what}` must be numbers of shape (N, 2); could not convert them: {exc}"


def _short_repr(x: object) -> str:
    """The first 40 characters of ``repr(x)``, which may itself fail (an int of 5000 digits)."""
    try:
        return f"{x!r:.40}"
    except Exception:  # any object's __repr__ may fail; the message must not
        return "too large to show"


_KIND_NAMES = {"b": "booleans", "c": "complex numbers", "U": "text", "S": "bytes"}


def _check_real(raw: NDArray[Any], what: str) -> None:
    """Refuse arrays of anything but real numbers (text, booleans, complex, None ...).

    ``np.array(["1", "2"], dtype=float)`` would quietly parse text and booleans would become
    0 and 1; coordinates must be numbers.
    """
    if raw.dtype.kind == "O":
        for x in raw.flat:
            if isinstance(x, bool | np.bool_) or not isinstance(x, numbers.Real):
                raise PartError(
                    f"`{what}` must be numbers of shape (N, 2); got a {type(x).__name__} "
                    f"({_short_repr(x)})"
                )
        return
    name = _KIND_NAMES.get(raw.dtype.kind, f"values of type {raw.dtype}")
    raise PartError(f"`{what}` must be numbers of shape (N, 2); got {name}")


def _check_tolerance(tol: object) -> None:
    if not isinstance(tol, Tolerance):
        raise PartError(f"`tol` must be a Tolerance; got {type(tol).__name__}")


# Areas are products of two coordinates: beyond these magnitudes they overflow or underflow.
_MAX_COORD = 1e150
_MIN_EXTENT = 1e-150


def _check_magnitude(pts: FloatArray, extent: float) -> None:
    """Refuse coordinates whose products overflow, or parts too small to tell from a point."""
    if len(pts) and float(np.max(np.abs(pts))) > _MAX_COORD:
        raise PartError(
            f"`vertices` must be at most {_MAX_COORD:g} in absolute value; "
            f"got {float(np.max(np.abs(pts))):g} (rescale the part's units)"
        )
    if 0.0 < extent < _MIN_EXTENT:
        raise PartError(
            f"the part is {extent:g} across; parts smaller than {_MIN_EXTENT:g} cannot be "
            "resolved (rescale the part's units)"
        )


def polygon_area_centroid(vertices: FloatArray) -> tuple[float, FloatArray]:
    """Signed area and area centroid of a simple polygon (shoelace formula).

    Parameters
    ----------
    vertices : ndarray of shape (N, 2)
        Vertices in order, no repeated closing vertex.

    Returns
    -------
    area : float
        Signed area (positive when counter-clockwise).
    centroid : ndarray of shape (2,)

    Examples
    --------
    >>> a, c = polygon_area_centroid(np.array([[0.0, 0], [2, 0], [2, 1], [0, 1]]))
    >>> a, c.tolist()
    (2.0, [1.0, 0.5])
    """
    # Shift to the first vertex: keeps the cross products well conditioned far from the origin;
    # and scale to unit size: the products neither overflow nor underflow (1e150 or 1e-150).
    origin = vertices[0]
    p = vertices - origin
    scale = float(np.max(np.abs(p)))
    if not 0.0 < scale < math.inf:
        return 0.0, vertices.mean(axis=0)
    p = p / scale
    q = np.concatenate((p[1:], p[:1]))
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]  # (N,)
    unit_area = 0.5 * float(cross.sum())
    if unit_area == 0.0:
        return 0.0, vertices.mean(axis=0)
    centroid = ((p + q) * cross[:, None]).sum(axis=0) * (scale / (6.0 * unit_area))
    return unit_area * scale * scale, centroid + origin


def _hull_indices(points: FloatArray) -> NDArray[np.intp]:
    """Counter-clockwise convex hull vertex indices (Andrew's monotone chain, vectorised sort).

    Collinear points on the hull are dropped. Runs in O(N log N).
    """
    order = np.lexsort((points[:, 1], points[:, 0]))
    pts = points[order]
    xs, ys = pts[:, 0], pts[:, 1]
    idx = np.arange(len(pts))
    lower, upper = _pruned_chain(xs, ys, idx), _pruned_chain(xs, ys, idx[::-1])
    if lower is None or upper is None:
        chain = np.array(_monotone_chain(xs.tolist(), ys.tolist()), dtype=np.intp)
    else:
        chain = np.concatenate([lower[:-1], upper[:-1]])
    return order[chain]


def _pruned_chain(
    xs: FloatArray, ys: FloatArray, idx: NDArray[np.intp], rounds: int = 64
) -> NDArray[np.intp] | None:
    """One half of Andrew's monotone chain by array operations.

    The points ``idx`` (sorted) less every point that does not turn strictly left between
    its neighbours, until none does. A point that turns right or goes straight between two
    others lies on or above the segment joining them (below, for the upper half), so it is
    no strict vertex of this half of the hull; removing every such point at once is safe,
    and what remains (a chain from the first point to the last turning strictly left at
    every point) is exactly what the monotone chain keeps. Usually a few rounds of O(N);
    ``None`` after ``rounds`` rounds
    (the caller then runs the sequential chain).

    Repeated points are first reduced to the one the monotone chain keeps: the first of
    those equal to the starting point, the last of every other run.
    """
    x, y = xs[idx], ys[idx]
    same = (x[1:] == x[:-1]) & (y[1:] == y[:-1])  # point i + 1 repeats point i
    if same.any():
        run0 = int(np.argmin(np.append(same, False)))  # points 1..run0 repeat the first
        drop = np.append(same, False)  # keep the last of a run ...
        drop[: run0 + 1] = False
        drop[1 : run0 + 1] = True  # ... but the first of the starting run
        idx = idx[~drop]
    for _ in range(rounds):
        if len(idx) < 3:
            return idx
        x, y = xs[idx], ys[idx]
        cross = (x[1:-1] - x[:-2]) * (y[2:] - y[:-2]) - (y[1:-1] - y[:-2]) * (x[2:] - x[:-2])
        bad = cross <= 0.0
        if not bad.any():
            return idx
        keep = np.ones(len(idx), dtype=bool)
        keep[1:-1] = ~bad
        idx = idx[keep]
    return None


def _monotone_chain(xs: list[float], ys: list[float]) -> list[int]:
    """Counter-clockwise hull of points sorted by x then y: indices, starting at the first."""

    def half(idx: range) -> list[int]:
        chain: list[int] = []
        for k in idx:
            while len(chain) >= 2:
                a, b = chain[-2], chain[-1]
                cross = (xs[b] - xs[a]) * (ys[k] - ys[a]) - (ys[b] - ys[a]) * (xs[k] - xs[a])
                if cross > 0:
                    break
                chain.pop()
            chain.append(k)
        return chain

    n = len(xs)
    return half(range(n))[:-1] + half(range(n - 1, -1, -1))[:-1]


def _hull_python(
    ordered: list[tuple[float, float]], eps: float
) -> tuple[list[float], list[float], float, float, float]:
    """Hull, area and centroid of a few points, in plain Python floats.

    ``ordered``: the points sorted (:func:`_sorted_pairs`; consumed). Andrew's monotone
    chain (the lower chain left to right, the upper right to left, :func:`_chain_python`),
    then the vertices within ``eps`` of their neighbours' chord dropped and the area and
    centroid measured (:func:`_drop_and_measure`): the steps of :func:`_hull_indices`,
    :func:`_drop_near_collinear` and :func:`polygon_area_centroid`, with the same results
    (tests/geometry/test_polygon.py holds the two paths together). For a few points the
    work is smaller than numpy's cost of a call.

    Returns
    -------
    xs, ys : list of float
        Hull vertices, counter-clockwise from the lowest leftmost point.
    area, cx, cy : float
        Area and centroid (area 0 when degenerate).
    """
    lower = _chain_python(ordered)
    ordered.reverse()
    hull = lower[:-1] + _chain_python(ordered)[:-1]
    return _drop_and_measure([p[0] for p in hull], [p[1] for p in hull], eps)


def _drop_and_measure(
    xs: list[float], ys: list[float], eps: float
) -> tuple[list[float], list[float], float, float, float]:
    """The near-collinear drop and the area and centroid of a hull chain, in plain Python."""
    hypot = math.hypot
    while len(xs) > 3:  # _drop_near_collinear, step for step
        n = len(xs)
        bad = []
        ax, ay = xs[-1], ys[-1]
        for x, y, bx, by in zip(xs, ys, [*xs[1:], xs[0]], [*ys[1:], ys[0]], strict=True):
            ux, uy = bx - ax, by - ay
            bad.append(abs(ux * (y - ay) - uy * (x - ax)) <= eps * hypot(ux, uy))
            ax, ay = x, y
        if True not in bad:
            break
        drop, run_start = [], 0
        for i in range(n):
            if not bad[i]:
                run_start = i + 1
            drop.append(bad[i] and (i - run_start) % 2 == 0)
        if drop[0] and drop[-1]:
            drop[-1] = False
        kept = n - sum(drop)
        if kept < 3:
            for i in [i for i in range(n) if drop[i]][: 3 - kept]:
                drop[i] = False
        xs = [x for x, d in zip(xs, drop, strict=True) if not d]
        ys = [y for y, d in zip(ys, drop, strict=True) if not d]
    if len(xs) < 3:
        return xs, ys, 0.0, 0.0, 0.0
    ox, oy = xs[0], ys[0]
    scale = max(max([abs(x - ox) for x in xs]), max([abs(y - oy) for y in ys]))
    if not 0.0 < scale < math.inf:
        return xs, ys, 0.0, 0.0, 0.0
    qx, qy = [(x - ox) / scale for x in xs], [(y - oy) / scale for y in ys]
    twice, cx, cy = 0.0, 0.0, 0.0
    for x0, y0, x1, y1 in zip(qx, qy, [*qx[1:], qx[0]], [*qy[1:], qy[0]], strict=True):
        c = x0 * y1 - x1 * y0
        twice += c
        cx += (x0 + x1) * c
        cy += (y0 + y1) * c
    if twice == 0.0:
        return xs, ys, 0.0, 0.0, 0.0
    unit = scale / (3.0 * twice)
    return xs, ys, 0.5 * twice * scale * scale, cx * unit + ox, cy * unit + oy


def _sorted_pairs(px: list[float], py: list[float]) -> list[tuple[float, float]]:
    """The (x, y) pairs sorted: the order of ``np.lexsort`` (equal pairs are the same point)."""
    return sorted(zip(px, py, strict=True))


def _chain_python(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """One half of :func:`_monotone_chain` on sorted points (the same cross products)."""
    chain: list[tuple[float, float]] = []
    pop = chain.pop
    for p in points:
        x, y = p
        while len(chain) >= 2:
            ax, ay = chain[-2]
            bx, by = chain[-1]
            if (bx - ax) * (y - ay) - (by - ay) * (x - ax) > 0:
                break
            pop()
        chain.append(p)
    return chain


# Below this the bound ``2 eps extent`` of ConvexPolygon._of_firm_ring is not trusted
# (products near the underflow).
_TINY = 1e-280


def _area_sums(
    rest: Iterable[tuple[float, float]], ox: float, oy: float, scale: float
) -> tuple[float, float, float]:
    """Twice the area and the centroid's sums of the ring ``(ox, oy), *rest``.

    :func:`_drop_and_measure`'s sums, in its order, about the first vertex in units of
    ``scale`` (the first vertex at (0, 0)): the centroid is ``(cx, cy) * scale / (3 * twice)
    + (ox, oy)``.
    """
    twice = cx = cy = qx = qy = 0.0
    for bx, by in rest:
        rx = (bx - ox) / scale
        ry = (by - oy) / scale
        c = qx * ry - rx * qy
        twice += c
        cx += (qx + rx) * c
        cy += (qy + ry) * c
        qx = rx
        qy = ry
    c = qx * 0.0 - 0.0 * qy  # the edge back to the first vertex, at (0, 0)
    return twice + c, cx + (qx + 0.0) * c, cy + (qy + 0.0) * c


def _odd_magnitude(x0: float, x1: float, y0: float, y1: float, extent: float) -> bool:
    """Whether :func:`_check_magnitude` must look: a coordinate or the extent out of range.

    (The largest ``|coordinate|`` is the largest of max and -min.)
    """
    big = _MAX_COORD
    return x1 > big or -x0 > big or y1 > big or -y0 > big or 0.0 < extent < _MIN_EXTENT


# A ring whose every turn exceeds this fraction of the squared bounding-box diagonal is
# decided by the hull's chains as in exact arithmetic (see ConvexPolygon._of_firm_ring).
_RING_FIRM = 2e-13


def _size(points: Iterable[tuple[float, float]], cx: float, cy: float) -> float:
    """The largest distance of the points from ``(cx, cy)`` (as the hull's size was made)."""
    top = 0.0
    for x, y in points:
        d = (x - cx) ** 2 + (y - cy) ** 2
        if d > top:
            top = d
    return math.sqrt(top)


def _drop_near_collinear(v: FloatArray, eps: float) -> FloatArray:
    """Drop hull vertices closer than ``eps`` to the segment joining their neighbours.

    Each round removes every other vertex of each run of such vertices, so a removed vertex
    always lies within ``eps`` of a chord whose ends stay: the error never accumulates.
    """
    while len(v) > 3:
        prev = np.roll(v, 1, axis=0)
        base = np.roll(v, -1, axis=0) - prev
        blen = np.hypot(base[:, 0], base[:, 1])
        cross = base[:, 0] * (v[:, 1] - prev[:, 1]) - base[:, 1] * (v[:, 0] - prev[:, 0])
        bad = np.abs(cross) <= eps * blen  # (N,) within eps of the neighbours' chord
        if not bad.any():
            break
        idx = np.arange(len(v))
        run_start = np.maximum.accumulate(np.where(~bad, idx + 1, 0))
        drop = bad & ((idx - run_start) % 2 == 0)
        if drop[0] and drop[-1]:
            drop[-1] = False
        keep = ~drop
        if keep.sum() < 3:
            keep[np.flatnonzero(drop)[: 3 - keep.sum()]] = True
        v = v[keep]
    return v


def _refuse(pts: FloatArray, eps: float) -> NoReturn:
    """Refuse points with no hull: too few distinct points, or all collinear."""
    # Tell "too few points" from "collinear" only on failure (np.unique is slow).
    distinct = 0
    if len(pts):
        grid = np.round((pts - pts.min(axis=0)) / max(eps, 1e-300))
        distinct = len(np.unique(grid, axis=0))
    if distinct < 3:
        raise PartError(
            f"a part needs at least 3 distinct points; got {len(pts)} point(s) "
            f"with {distinct} distinct"
        )
    raise PartError("the part's points are all collinear; a part needs a non-zero area")


def _restored(
    vertices: FloatArray, tol: Tolerance, area: float, centroid: FloatArray, size: float
) -> ConvexPolygon:
    """A pickled :class:`ConvexPolygon` (its fields, already checked)."""
    return ConvexPolygon._trusted(vertices, tol, area, centroid, size)


# Up to this many points, ConvexPolygon.from_points works on Python floats (faster there).
_SMALL = SMALL


class ConvexPolygon:
    """Convex polygon, vertices counter-clockwise, no repeated closing vertex.

    Build it with :meth:`from_points`, which takes the convex hull of any point list.
    A frozen value: the arrays are read-only (made on first use when the hull was taken in
    plain Python, from its Python floats).

    Attributes
    ----------
    vertices : ndarray of shape (N, 2)
        Counter-clockwise hull vertices in the user's coordinates (never rotated).
    tol : Tolerance
        The tolerances used for this polygon.
    area : float
    centroid : ndarray of shape (2,)
        The area centroid.
    size : float
        The largest distance of a vertex from the centroid.

    Examples
    --------
    >>> ConvexPolygon.from_points([(0, 0), (2, 0), (0, 1), (0.5, 0.2)]).n_sides
    3
    """

    __slots__ = ("_c", "_cxy", "_symmetry", "_v", "_xy", "area", "size", "tol")
    __match_args__ = ("vertices", "tol")

    tol: Tolerance
    area: float
    size: float
    # symmetry_order once known; -k when only known to be below k; 0 before any test.
    _symmetry: int
    # The vertices and the centroid as read-only arrays, or as Python floats (for the
    # plain-Python paths): at least one of each pair is set, the other made when asked for.
    _v: FloatArray | None
    _xy: tuple[list[float], list[float]] | None
    _c: FloatArray | None
    _cxy: tuple[float, float] | None

    def __init__(self, vertices: ArrayLike, tol: Tolerance = DEFAULT_TOLERANCE) -> None:
        _check_tolerance(tol)
        v = as_points(vertices)
        n = len(v)
        what = "`vertices` must be a counter-clockwise convex polygon"
        if n < 3:
            raise PartError(f"{what} of at least 3 vertices; got {n}")
        area, centroid = polygon_area_centroid(v)
        size = float(np.max(np.hypot(*(v - centroid).T)))
        e = np.concatenate((v[1:], v[:1])) - v  # (N, 2) edge i runs from vertex i to i + 1
        elen = np.hypot(e[:, 0], e[:, 1])
        short = np.flatnonzero(elen <= tol.length_for(size))
        if len(short):
            raise PartError(f"{what}; vertices {short[0]} and {(short[0] + 1) % n} coincide")
        en = np.concatenate((e[1:], e[:1]))  # (N, 2) the edge after each edge
        cross = e[:, 0] * en[:, 1] - e[:, 1] * en[:, 0]
        right = np.flatnonzero(cross < -tol.angle * elen * np.roll(elen, -1))
        if len(right):
            raise PartError(f"{what}; it turns clockwise at vertex {(right[0] + 1) % n}")
        turns = float(np.sum(np.arctan2(cross, np.sum(e * en, axis=1)))) / (2.0 * math.pi)
        if abs(turns - 1.0) > 1e-6:
            raise PartError(f"{what}; it winds {turns:.3g} times around")
        self._set_arrays(tol, v, area, centroid, size)

    def _set_arrays(
        self, tol: Tolerance, v: FloatArray, area: float, centroid: FloatArray, size: float
    ) -> None:
        v.setflags(write=False)
        centroid.setflags(write=False)
        _poly_tol(self, tol)
        _poly_v(self, v)
        _poly_xy(self, None)
        _poly_area(self, area)
        _poly_c(self, centroid)
        _poly_cxy(self, None)
        _poly_size(self, size)
        _poly_symmetry(self, 0)

    def __setattr__(self, name: str, value: object) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")

    def __reduce__(self) -> tuple[object, ...]:
        return (_restored, (self.vertices, self.tol, self.area, self.centroid, self.size))

    def __repr__(self) -> str:
        return (
            f"ConvexPolygon(vertices={self.vertices!r}, tol={self.tol!r}, area={self.area!r}, "
            f"centroid={self.centroid!r}, size={self.size!r})"
        )

    @property
    def vertices(self) -> FloatArray:
        """Counter-clockwise hull vertices, shape (N, 2), read-only."""
        v = self._v
        if v is None:
            assert self._xy is not None
            v = np.array(self._xy, dtype=np.float64).T.copy()
            v.setflags(write=False)
            object.__setattr__(self, "_v", v)
        return v

    @property
    def centroid(self) -> FloatArray:
        """The area centroid, shape (2,), read-only."""
        c = self._c
        if c is None:
            assert self._cxy is not None
            c = np.array(self._cxy)  # float64: two Python floats
            c.setflags(write=False)
            object.__setattr__(self, "_c", c)
        return c

    def _coords(self) -> tuple[list[float], list[float]]:
        """The vertices' x and y coordinates as lists of Python floats (made once)."""
        xy = self._xy
        if xy is None:
            xs, ys = self.vertices.T.tolist()
            xy = (xs, ys)
            object.__setattr__(self, "_xy", xy)
        return xy

    def _centroid_xy(self) -> tuple[float, float]:
        """The centroid as two Python floats (made once)."""
        cxy = self._cxy
        if cxy is None:
            cx, cy = self.centroid.tolist()
            cxy = (cx, cy)
            object.__setattr__(self, "_cxy", cxy)
        return cxy

    @classmethod
    def _trusted(
        cls,
        v: FloatArray,
        tol: Tolerance,
        area: float,
        centroid: FloatArray,
        size: float | None = None,
    ) -> ConvexPolygon:
        """A polygon known to be convex and counter-clockwise (from a hull or a rotation)."""
        poly = object.__new__(cls)
        if size is None:
            d = v - centroid
            size = math.sqrt(float(np.max(d[:, 0] ** 2 + d[:, 1] ** 2)))
        poly._set_arrays(tol, v, area, centroid, size)
        return poly

    @classmethod
    def _of_floats(
        cls,
        xs: list[float],
        ys: list[float],
        tol: Tolerance,
        area: float,
        cx: float,
        cy: float,
        size: float,
    ) -> ConvexPolygon:
        """A hull taken in plain Python, from its floats; the arrays are made on first use."""
        poly = object.__new__(cls)
        _poly_tol(poly, tol)
        _poly_v(poly, None)
        _poly_xy(poly, (xs, ys))
        _poly_area(poly, area)
        _poly_c(poly, None)
        _poly_cxy(poly, (cx, cy))
        _poly_size(poly, size)
        _poly_symmetry(poly, 0)
        return poly

    @classmethod
    def from_points(cls, points: ArrayLike, tol: Tolerance = DEFAULT_TOLERANCE) -> ConvexPolygon:
        """Convex hull of a point list, counter-clockwise, duplicates and collinear points dropped.

        Parameters
        ----------
        points : array_like of shape (N, 2)
            At least 3 distinct points, not all collinear. Order does not matter.
        tol : Tolerance, optional
            Points closer than ``tol.length`` times the part's size are merged.

        Returns
        -------
        ConvexPolygon

        Raises
        ------
        PartError
            Fewer than 3 distinct points, all points collinear, or bad coordinates.

        Examples
        --------
        >>> sq = ConvexPolygon.from_points([(1, 1), (0, 0), (1, 0), (0, 1), (0.5, 0)])
        >>> sq.vertices.tolist()
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        """
        _check_tolerance(tol)
        return cls._hull_of(as_points(points), tol)

    @classmethod
    def _hull_of(cls, pts: FloatArray, tol: Tolerance) -> ConvexPolygon:
        """:meth:`from_points` of points already checked by :func:`as_points`."""
        if 3 <= len(pts) <= _SMALL:
            px, py = pts.T.tolist()
            return cls._hull_of_floats(pts, px, py, tol)
        extent = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
        _check_magnitude(pts, extent)
        eps = tol.length_for(extent)
        area = 0.0
        if len(pts) < 3 or extent == 0.0:
            hull = pts[:0]
        else:
            hull = pts[_hull_indices(pts)]
            if len(hull) > 3:
                hull = _drop_near_collinear(hull, eps)
            if len(hull) >= 3:
                area, centroid = polygon_area_centroid(hull)
        if len(hull) < 3 or area <= eps * extent:
            _refuse(pts, eps)
        return cls._trusted(hull, tol, area, centroid)

    @classmethod
    def _hull_of_floats(
        cls, pts: FloatArray, px: list[float], py: list[float], tol: Tolerance
    ) -> ConvexPolygon:
        """:meth:`_hull_of` of 3 to :data:`_SMALL` points, in plain Python.

        ``px`` and ``py`` are the coordinates of ``pts`` as Python floats (the same values).
        """
        ordered = _sorted_pairs(px, py)  # by x first: the least and largest x at the ends
        by_y = sorted(py)  # the least and largest y at the ends
        x0, x1, y0, y1 = ordered[0][0], ordered[-1][0], by_y[0], by_y[-1]
        extent = max(x1 - x0, y1 - y0)
        if _odd_magnitude(x0, x1, y0, y1, extent):
            _check_magnitude(pts, extent)
        eps = tol.length_for(extent)
        if extent == 0.0:
            _refuse(pts, eps)
        xs, ys, area, cx, cy = _hull_python(ordered, eps)
        if len(xs) < 3 or area <= eps * extent:
            _refuse(pts, eps)
        return cls._of_floats(xs, ys, tol, area, cx, cy, _size(zip(xs, ys, strict=True), cx, cy))

    @classmethod
    def _of_firm_ring(
        cls,
        xs: list[float],
        ys: list[float],
        least: float,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        tol: Tolerance,
    ) -> ConvexPolygon | None:
        """:meth:`_hull_of_floats` of a ring's points, when the ring is already their hull.

        ``xs``, ``ys``: at most :data:`_SMALL` finite points in order round a polygon that
        turns the same way at every vertex and winds once (``io.points._firm_turn``), and
        ``x0, x1, y0, y1`` their least and largest; ``least``: the cross product
        ``(b - a) x (c - b)`` of least magnitude over its vertices, positive if the ring runs
        counter-clockwise. ``None`` when this cannot promise the same polygon: the caller
        then takes the hull. The polygon may keep ``xs`` and ``ys`` as its own (never
        changed): the caller hands them over.

        Why it is the same polygon, to the last bit: with ``D`` the bounding box's diagonal
        and ``u`` the unit roundoff, a computed orientation of three of the points (the
        chains' tests, the near-collinear test) or cross product of consecutive edges is
        within ``8 u D^2`` of its exact value. The ring is a convex polygon, and the least
        triangle on its vertices is one of three consecutive vertices (fix two vertices: the
        distance of the third from their line is unimodal round each side, so the least is
        next to one of them; again with that edge fixed). So when ``|least|`` exceeds
        :data:`_RING_FIRM` ``D^2`` (10^2 times ``16 u D^2``), every test of the monotone
        chains decides as exact arithmetic does: the hull's vertices are the ring's, every
        one, counter-clockwise from the lexicographically least. And when ``|least|`` is
        also above twice ``bound = 2 eps extent`` (the near-collinear test of a vertex is
        ``|u x w| <= eps |u|``, ``u`` the chord of its neighbours, and ``eps |u| <= eps
        sqrt(2) extent`` stays below ``bound`` after rounding), no vertex is within ``eps`` of
        its neighbours' chord, so the near-collinear test drops none, and
        :func:`_area_sums` (:func:`_drop_and_measure`'s sums in its order) gives the same
        area, centroid and size as :func:`_hull_python`. Odd magnitudes and degenerate areas
        go to the hull, which words the refusals.
        """
        # _hull_of_floats's tests, and the bound above.
        w, h = x1 - x0, y1 - y0
        extent = w if w >= h else h  # max(w, h)
        if _odd_magnitude(x0, x1, y0, y1, extent):
            return None
        eps = tol.length * extent  # tol.length_for(extent)
        bound = 2.0 * eps * extent
        margin = abs(least)
        if not (bound >= _TINY and margin > 2.0 * bound and margin > _RING_FIRM * (w**2 + h**2)):
            return None
        if least < 0:
            xs, ys = xs[::-1], ys[::-1]
        # The lexicographically least point starts the hull: the first of least x, or the
        # other point of least x if lower (a convex polygon has at most two, one after the
        # other: after the first, or last in the list when the first is first).
        i = xs.index(x0)
        n = len(xs)
        if i + 1 < n and xs[i + 1] == x0:
            if ys[i + 1] < ys[i]:
                i += 1
        elif i == 0 and xs[-1] == x0 and ys[-1] < ys[0]:
            i = n - 1
        if i:  # (else the lists are kept: the caller hands them over)
            xs, ys = xs[i:] + xs[:i], ys[i:] + ys[:i]
        # _drop_and_measure's scale and sums, in its order (the ring holds the least and
        # largest y, and the largest x is the x of its lexicographically largest point).
        ox, oy = xs[0], ys[0]
        scale = x1 - ox  # max(x1 - ox, y1 - oy, oy - y0)
        if y1 - oy > scale:
            scale = y1 - oy
        if oy - y0 > scale:
            scale = oy - y0
        twice, cx, cy = _area_sums(zip(xs[1:], ys[1:]), ox, oy, scale)  # noqa: B905
        if twice == 0.0:
            return None
        unit = scale / (3.0 * twice)
        cx = cx * unit + ox
        cy = cy * unit + oy
        area = 0.5 * twice * scale * scale
        if not area > eps * extent:
            return None
        return cls._of_floats(xs, ys, tol, area, cx, cy, _size(zip(xs, ys), cx, cy))  # noqa: B905

    @property
    def n_sides(self) -> int:
        """Number of sides (equal to the number of vertices)."""
        xy = self._xy
        return len(xy[0]) if xy is not None else len(self.vertices)

    def rotated(self, angle: float) -> ConvexPolygon:
        """The polygon rotated counter-clockwise by ``angle`` about the origin.

        Used to place the part in a gripper frame; the user's part is never changed.

        Examples
        --------
        >>> sq = ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> np.round(sq.rotated(np.pi / 2).vertices, 12).tolist()[1]
        [0.0, 1.0]
        """
        c, s = math.cos(angle), math.sin(angle)
        rot = np.array([[c, -s], [s, c]])
        return ConvexPolygon._trusted(
            self.vertices @ rot.T, self.tol, self.area, rot @ self.centroid
        )

    @property
    def symmetry_order(self) -> int:
        """Order r of the part's rotational symmetry about its centroid (1 if none).

        A rotation by ``2 pi / r`` must map every vertex within ``tol.symmetry * size`` of
        another vertex. A square is 4, an equilateral triangle 3, a rectangle 2. A part
        symmetric within that tolerance is treated as exactly symmetric everywhere
        downstream: its diameter function's extrema, hence its squeeze function, are those
        of :meth:`symmetrized` (see :func:`~bayesgrasp.geometry.diameter.diameter_function`).

        Examples
        --------
        >>> ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)]).symmetry_order
        2
        """
        return self.symmetry_order_from(2)

    def symmetry_order_from(self, lowest: int) -> int:
        """:attr:`symmetry_order` if it is at least ``lowest``, else 1.

        Only the orders from ``lowest`` up are tested (the answer is cached), so asking
        whether a part has an order of 3 or more skips the test of a half turn: the
        diameter function needs no more.

        Examples
        --------
        >>> rect = ConvexPolygon.from_points([(0, 0), (2, 0), (2, 1), (0, 1)])
        >>> rect.symmetry_order_from(3), rect.symmetry_order
        (1, 2)
        """
        known = self._symmetry
        if known > 0:
            return known if known >= lowest else 1
        n = self.n_sides  # the arrays are made on first use: not here
        if known < 0:
            if lowest >= -known:
                return 1  # every order from -known up failed
            orders = _orders_between(n, lowest, -known)
        else:
            orders = _orders_from(n, lowest)
        if not orders:  # (as an odd part's half turn, after the orders from 3 failed)
            _SET_SYMMETRY(self, -lowest)
            return 1
        eps = self.tol.symmetry_for(self.size)
        if n <= _SMALL:
            found = _symmetry_order_python(*self._coords(), self._centroid_xy(), orders, eps)
        else:
            found = self._find_symmetry_order(orders, eps)
        _SET_SYMMETRY(self, found if found > 1 else -lowest)
        return found

    def _find_symmetry_order(self, orders: list[int], eps: float) -> int:
        """The symmetry test by array operations (many vertices)."""
        n = len(self.vertices)
        if not orders:
            return 1
        # A rotation keeps the cyclic order: vertex i lands on vertex i + n / r, at the same
        # distance from the centroid. Test those distances on a few vertices for every
        # order at once (n may have many divisors), then on all vertices for the orders
        # left: enough to reject most parts before the rotation test.
        centre = self.centroid
        probe = np.linspace(0, n - 1, 16).astype(np.intp)  # (16,) a few vertices, spread out
        steps = np.array([n // r for r in orders], dtype=np.intp)
        ends = (probe[None, :] + steps[:, None]) % n  # (R, 16) where each probe lands
        rp = np.hypot(*(self.vertices[probe] - centre).T)
        re = np.hypot(*(self.vertices[ends] - centre).transpose(2, 0, 1))
        left = [
            r for r, ok in zip(orders, np.max(np.abs(re - rp), axis=1) <= eps, strict=True) if ok
        ]
        if not left:
            return 1
        v = self.vertices - centre
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

    def symmetrized(self, centred: bool = False) -> FloatArray:
        """The vertices made exactly r-fold symmetric, ``r = symmetry_order``.

        Each vertex is replaced by the mean of its orbit under the rotations by ``2 pi k / r``
        about the centroid (vertex ``i + k n / r`` turned back by ``2 pi k / r``), and the
        mean is turned forward again: the nearest exactly symmetric polygon with the same
        vertex correspondence, no vertex moved by more than ``tol.symmetry * size``. It is
        what the diameter function of a near-symmetric part is built from (its extrema), so
        that the squeeze function has the symmetry's period to rounding. For ``r = 1`` the
        vertices are returned unchanged.

        ``centred=True`` gives them relative to the centroid, the centroid not added back:
        symmetric to the rounding of the part's size rather than of its coordinates. Edge
        directions, the diameter and the radius about the centroid are the same; a part
        far from the origin (a 7 mm part at 500 m) keeps its symmetry to 1e-16 rad and not
        to 1e-8 rad, where the squeeze function's period test needs ``tol.angle``.

        Returns
        -------
        ndarray of shape (N, 2)

        Examples
        --------
        >>> sq = ConvexPolygon.from_points([(0, 0), (1, 0), (1, 1), (0, 1.000001)])
        >>> v = sq.symmetrized() - sq.centroid
        >>> turned = v @ np.array([[0.0, 1.0], [-1.0, 0.0]])  # a quarter turn
        >>> sq.symmetry_order, bool(np.abs(turned - np.roll(v, -1, axis=0)).max() < 1e-15)
        (4, True)
        >>> bool(np.abs(sq.symmetrized() - sq.vertices).max() < 1e-6)
        True
        """
        r = self.symmetry_order
        v = self.vertices
        n, c = len(v), self.centroid
        if r == 1:
            return v - c if centred else np.array(v, dtype=np.float64)
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


# The slots' own setters: the frozen class's __setattr__ refuses, and object.__setattr__
# costs twice as much (the plain-Python hull makes polygons by the thousand).
_poly_c, _poly_cxy, _poly_symmetry, _poly_v, _poly_xy, _poly_area, _poly_size, _poly_tol = (
    ConvexPolygon.__dict__[name].__set__ for name in ConvexPolygon.__slots__
)


@functools.cache
def _orders(n: int) -> list[int]:
    """The divisors of ``n`` above 1, largest first: the possible orders of symmetry."""
    small = [r for r in range(2, math.isqrt(n) + 1) if n % r == 0]
    return sorted({n, *small, *(n // r for r in small)} - {1}, reverse=True)


@functools.cache
def _orders_from(n: int, lowest: int) -> list[int]:
    """:func:`_orders` from ``lowest`` up (the caller must not change the list)."""
    return [r for r in _orders(n) if r >= lowest]


@functools.cache
def _orders_between(n: int, lowest: int, below: int) -> list[int]:
    """:func:`_orders` from ``lowest`` up and below ``below`` (the caller must not change it)."""
    return [r for r in _orders(n) if lowest <= r < below]


# The symmetry order's cache, set at half object.__setattr__'s cost (once for every part).
_SET_SYMMETRY = ConvexPolygon.__dict__["_symmetry"].__set__


def _symmetry_order_python(
    xs: list[float], ys: list[float], centroid: Sequence[float], orders: list[int], eps: float
) -> int:
    """:meth:`ConvexPolygon.symmetry_order` for a few vertices, in plain Python (faster).

    The same tests in the same order; the distance of vertex ``step`` from the centroid,
    compared with vertex 0's, rejects most orders of most parts before any other work.
    ``xs`` and ``ys`` are the vertices' coordinates.
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
        if _turns_onto(xs, ys, cx, cy, r, eps):
            return r
    return 1


def _turns_onto(xs: list[float], ys: list[float], cx: float, cy: float, r: int, eps: float) -> bool:
    """Whether a turn by ``2 pi / r`` about (cx, cy) keeps the vertices within ``eps``.

    Vertex i must land within ``eps`` of vertex ``i + n / r``: the test of one order of
    :func:`_symmetry_order_python`, after its first, cheap rejection. A function of its own:
    the generators' variables are cells, which each call of the caller would make, whether
    its first test rejects every order or not.
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


@dataclass(frozen=True, slots=True, eq=False)
class Part:
    """A part as the user gave it: name, outline, hull, centre of mass and units.

    Parameters
    ----------
    name : str
        Name shown in reports.
    hull : ConvexPolygon
        What the gripper touches.
    outline : ndarray of shape (M, 2)
        The user's points, as given (may be non-convex); read-only.
    center_of_mass : ndarray of shape (2,)
        Defaults to the hull's area centroid.
    units : str or None
        The units of the coordinates, when known: a name of :mod:`bayesgrasp.units`
        (others are refused; :func:`bayesgrasp.units.convert` converts a part).
    holes : tuple of ndarray of shape (K, 2)
        Holes inside the outline (parts built by :meth:`from_outline`); they move the
        centre of mass, never the hull.

    Examples
    --------
    >>> p = Part.from_points([(0, 0), (3, 0), (0, 1)], name="wedge")
    >>> p.hull.n_sides, p.center_of_mass.tolist()
    (3, [1.0, 0.3333333333333333])
    """

    name: str
    hull: ConvexPolygon
    outline: FloatArray
    center_of_mass: FloatArray
    units: str | None = None
    holes: tuple[FloatArray, ...] = ()

    @classmethod
    def from_points(
        cls,
        points: ArrayLike,
        name: str = "part",
        center_of_mass: ArrayLike | None = None,
        units: str | None = None,
        tol: Tolerance = DEFAULT_TOLERANCE,
    ) -> Part:
        """Build a part from a point list; the hull is what the gripper sees.

        Raises
        ------
        PartError
            Bad coordinates, or a centre of mass outside the hull.
        """
        hull = None
        if (  # a few float64 points: the finite check on Python floats (a sum is finite
            # only if every term is; else as_points decides and words its refusal)
            type(points) is np.ndarray
            and points.dtype is _FLOAT64  # (a non-native byte order is not)
            and points.ndim == 2
            and points.shape[1] == 2
            and 3 <= len(points) <= _SMALL
        ):
            outline = points.copy()
            px, py = outline.T.tolist()
            if math.isfinite(sum(px, sum(py))):
                if tol is not DEFAULT_TOLERANCE:
                    _check_tolerance(tol)
                hull = ConvexPolygon._hull_of_floats(outline, px, py, tol)
            else:
                outline = as_points(points)
        else:
            outline = as_points(points)  # a fresh array
        if hull is None:
            if tol is not DEFAULT_TOLERANCE:
                _check_tolerance(tol)
            hull = ConvexPolygon._hull_of(outline, tol)
        return cls._of_hull(hull, outline, name, center_of_mass, units)

    @classmethod
    def _of_hull(
        cls,
        hull: ConvexPolygon,
        outline: FloatArray,
        name: str,
        center_of_mass: ArrayLike | None,
        units: str | None,
    ) -> Part:
        """:meth:`from_points` of points whose hull is ``hull``.

        ``outline``: a fresh array, or a view of one that no one else holds.

        Raises
        ------
        PartError
            A centre of mass outside the hull.
        """
        if units is not None:
            units = unit_name(units)
        outline.setflags(write=False)
        if center_of_mass is None:  # the hull's centroid (the same read-only array)
            cx, cy = hull._centroid_xy()
            if math.isfinite(cx) and math.isfinite(cy) and _holds_centroid(hull):
                if cls is not Part:
                    return cls(name, hull, outline, hull.centroid, units)
                part = object.__new__(Part)  # Part(...), without its frozen __init__'s cost
                _part_name(part, name)
                _part_hull(part, hull)
                _part_outline(part, outline)
                _part_center_of_mass(part, hull.centroid)
                _part_units(part, units)
                _part_holes(part, ())
                return part
        com = _center_of_mass(hull, hull.centroid if center_of_mass is None else center_of_mass)
        com.setflags(write=False)
        return cls(name, hull, outline, com, units)

    @classmethod
    def from_outline(
        cls,
        outline: ArrayLike,
        holes: Sequence[ArrayLike] = (),
        name: str = "part",
        center_of_mass: ArrayLike | None = None,
        units: str | None = None,
        tol: Tolerance = DEFAULT_TOLERANCE,
    ) -> Part:
        """Build a part from a simple (possibly non-convex) outline, optionally with holes.

        The outline is an ordered ring, closed implicitly (a repeated closing vertex is
        dropped). The gripper sees its convex hull; the default centre of mass is the area
        centroid of the outline minus the holes (uniform density), not the hull's.

        Parameters
        ----------
        outline : array_like of shape (N, 2)
            Vertices in order around the outline, either direction.
        holes : sequence of array_like of shape (K, 2), optional
            Rings strictly inside the outline, not touching it or each other.
        name : str
        center_of_mass : array_like of shape (2,), optional
            Overrides the area centroid; must lie inside the hull.
        units : str, optional
        tol : Tolerance, optional

        Returns
        -------
        Part
            ``outline`` and ``holes`` are stored counter-clockwise without repeated
            vertices.

        Raises
        ------
        PartError
            Fewer than 3 distinct vertices, non-finite coordinates, a self-intersecting
            outline (two edges that cross or touch, or an edge that folds back), a hole
            outside the outline or crossing it, zero area, or a centre of mass outside the
            hull.

        Examples
        --------
        >>> p = Part.from_outline([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)], name="L")
        >>> p.hull.n_sides, np.round(p.center_of_mass, 6).tolist()
        (5, [0.833333, 0.833333])
        >>> Part.from_outline([(0, 0), (1, 1), (1, 0), (0, 1)])  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        bayesgrasp.errors.PartError: `outline` must be a simple polygon; it crosses itself ...
        """
        if units is not None:
            units = unit_name(units)
        ring = _clean_ring(outline, "outline")
        rings = [ring] + [_clean_ring(h, f"holes[{k}]") for k, h in enumerate(holes)]
        names = ["outline"] + [f"holes[{k}]" for k in range(len(rings) - 1)]
        for r, what in zip(rings, names, strict=True):
            fold = _fold_back(r)
            if fold is not None:
                x, y = r[fold]
                raise PartError(
                    f"`{what}` must be a simple polygon; it folds back on itself at vertex "
                    f"{fold} ({x:.6g}, {y:.6g})"
                )
        hit = find_crossing(rings)
        if hit is not None:
            ra, _, rb, _ = hit
            point = _crossing_point(rings, hit)
            where = "it crosses itself" if ra == rb else f"it crosses `{names[rb]}`"
            raise PartError(
                f"`{names[ra]}` must be a simple polygon; {where} near "
                f"({point[0]:.6g}, {point[1]:.6g})"
            )
        oriented: list[FloatArray] = []
        areas: list[float] = []
        centroids: list[FloatArray] = []
        for r in rings:
            a, c = polygon_area_centroid(r)
            oriented.append(r if a > 0 else r[::-1].copy())
            areas.append(abs(a))
            centroids.append(c)
        extent = float(np.max(np.ptp(ring, axis=0)))
        for k in range(1, len(rings)):
            if not _point_in_ring(oriented[k][0], oriented[0]):
                raise PartError(f"`{names[k]}` must lie inside `outline`; it lies outside")
            for m in range(1, len(rings)):
                if m != k and _point_in_ring(oriented[k][0], oriented[m]):
                    raise PartError(f"`{names[k]}` lies inside `{names[m]}`; holes cannot nest")
        net = areas[0] - sum(areas[1:])
        if net <= tol.length_for(extent) * extent:
            raise PartError(f"`outline` must enclose a non-zero area; got area {net:.6g}")
        hull = ConvexPolygon.from_points(oriented[0], tol)
        if center_of_mass is None:
            weighted = areas[0] * centroids[0] - sum(
                (a * c for a, c in zip(areas[1:], centroids[1:], strict=True)), np.zeros(2)
            )
            com = _center_of_mass(hull, weighted / net)
        else:
            com = _center_of_mass(hull, center_of_mass)
        for arr in (*oriented, com):
            arr.setflags(write=False)
        return cls(name, hull, oriented[0], com, units, tuple(oriented[1:]))

    def scaled(self, factor: float, units: str) -> Part:
        """The part with its outline, holes and centre of mass multiplied by ``factor``.

        :func:`bayesgrasp.units.convert` uses it to change units; ``units`` are the new ones.

        Examples
        --------
        >>> p = Part.from_points([(0, 0), (1, 0), (0, 1)], units="cm").scaled(10, "mm")
        >>> p.units, float(p.hull.vertices.max())
        ('mm', 10.0)
        """
        com = self.center_of_mass * factor
        if self.holes:
            return Part.from_outline(
                self.outline * factor, [h * factor for h in self.holes], self.name, com, units
            )
        return Part.from_points(self.outline * factor, self.name, com, units)


_part_name, _part_hull, _part_outline, _part_center_of_mass, _part_units, _part_holes = (
    Part.__dict__[f.name].__set__ for f in dataclasses.fields(Part)
)


def _center_of_mass(hull: ConvexPolygon, point: ArrayLike) -> FloatArray:
    """A centre of mass as a fresh (2,) array, refused unless strictly inside the hull."""
    try:
        flat = np.reshape(np.asarray(point, dtype=object), (1, -1))
    except (TypeError, ValueError, RecursionError) as exc:
        raise PartError(f"`center_of_mass` must be 2 numbers; could not read it: {exc}") from None
    com = as_points(flat, "center_of_mass")[0]
    if not hull_contains(hull, com):
        raise PartError(f"`center_of_mass` {com.tolist()} must lie inside the part's convex hull")
    return np.array(com, dtype=np.float64)


# Rounding allowance of _holds_centroid: far more than the error of the computed distances.
_CENTROID_SLACK = 1e-12


def _holds_centroid(hull: ConvexPolygon) -> bool:
    """``hull_contains(hull, hull.centroid)``, without the test when it cannot fail.

    The centroid of a convex polygon lies at least a third of the polygon's width from each
    edge's line (Minkowski and Radon), and the width is at least ``area / (2 size)`` (the
    polygon lies within ``size`` of its centroid): so when ``area / (6 size)`` exceeds the
    margin by far more than the rounding of the distances, every edge passes the test. Only
    thin polygons are tested edge by edge.
    """
    cx, cy = hull._centroid_xy()
    margin = hull.tol.length_for(hull.size)
    slack = _CENTROID_SLACK * (abs(cx) + abs(cy) + hull.size)
    if hull.area > 6.0 * hull.size * (2.0 * margin + slack):
        return True
    return hull_contains(hull, hull.centroid)


def hull_contains(hull: ConvexPolygon, point: FloatArray) -> bool:
    """Whether ``point`` lies strictly inside the convex polygon (by more than the tolerance)."""
    margin = hull.tol.length_for(hull.size)
    if hull.n_sides <= SMALL:  # on Python floats (math.hypot may differ from numpy's by an ulp)
        xs, ys = hull._coords()
        px, py = float(point[0]), float(point[1])
        n = len(xs)
        for i in range(n):
            ex, ey = xs[(i + 1) % n] - xs[i], ys[(i + 1) % n] - ys[i]
            cross = ex * (py - ys[i]) - ey * (px - xs[i])
            if not cross / math.hypot(ex, ey) > margin:
                return False
        return True
    v = hull.vertices
    e = np.roll(v, -1, axis=0) - v
    rel = point - v
    crosses = e[:, 0] * rel[:, 1] - e[:, 1] * rel[:, 0]
    lengths = np.hypot(e[:, 0], e[:, 1])
    return bool(np.all(crosses / lengths > margin))


def _clean_ring(points: ArrayLike, what: str) -> FloatArray:
    """A ring as float64 (N, 2) without repeated consecutive vertices or closing vertex."""
    ring = as_points(points, what)
    if len(ring) > 1:
        ring = ring[~np.all(ring == np.roll(ring, -1, axis=0), axis=1)]
    if len(ring) < 3:
        raise PartError(f"`{what}` must have at least 3 distinct vertices; got {len(ring)}")
    return np.array(ring, dtype=np.float64)


def _fold_back(ring: FloatArray) -> int | None:
    """Index of a vertex where the ring turns back along its incoming edge, if any."""
    u = ring - np.roll(ring, 1, axis=0)  # (N, 2) incoming edges
    w = np.roll(ring, -1, axis=0) - ring  # (N, 2) outgoing edges
    cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
    dot = (u * w).sum(axis=1)
    scale = np.hypot(u[:, 0], u[:, 1]) * np.hypot(w[:, 0], w[:, 1])
    bad = np.flatnonzero((np.abs(cross) <= 1e-12 * scale) & (dot < 0))
    return int(bad[0]) if len(bad) else None


def _point_in_ring(point: FloatArray, ring: FloatArray) -> bool:
    """Even-odd test: whether ``point`` lies inside the ring (vectorised over edges)."""
    x, y = float(point[0]), float(point[1])
    a, b = ring, np.roll(ring, -1, axis=0)
    straddle = (a[:, 1] > y) != (b[:, 1] > y)  # (N,) edges crossing the horizontal line
    dy = np.where(straddle, b[:, 1] - a[:, 1], 1.0)
    x_cross = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
    return bool(np.count_nonzero(straddle & (x < x_cross)) % 2)


def _crossing_point(rings: Sequence[FloatArray], hit: tuple[int, int, int, int]) -> FloatArray:
    """A point where the two segments named by ``hit`` meet (for error messages)."""
    ra, sa, rb, sb = hit
    a0, a1 = rings[ra][sa], rings[ra][(sa + 1) % len(rings[ra])]
    b0, b1 = rings[rb][sb], rings[rb][(sb + 1) % len(rings[rb])]
    da, db = a1 - a0, b1 - b0
    denom = da[0] * db[1] - da[1] * db[0]
    if denom == 0.0:  # collinear overlap: any shared point will do
        for p in (b0, b1, a0, a1):
            if min(a0[0], a1[0]) <= p[0] <= max(a0[0], a1[0]) and min(a0[1], a1[1]) <= p[1] <= max(
                a0[1], a1[1]
            ):
                return np.asarray(p, dtype=np.float64)
        return np.asarray(a0, dtype=np.float64)  # pragma: no cover - not reached
    t = ((b0[0] - a0[0]) * db[1] - (b0[1] - a0[1]) * db[0]) / denom
    return np.asarray(a0 + t * da, dtype=np.float64)


_PAIR_CHUNK = 1 << 20  # candidate segment pairs examined per vectorised batch


def find_crossing(rings: Sequence[FloatArray]) -> tuple[int, int, int, int] | None:
    """Find two non-adjacent edges of a set of rings that cross or touch.

    A sweep along the axis where the edges are shortest pairs every edge with the edges whose
    intervals overlap it on that axis (sort and prune); the pairs are filtered on the other
    axis and settled by exact orientation tests, in vectorised batches. Typical outlines
    (short edges) give O(N log N) work; the worst case is O(N^2).

    Parameters
    ----------
    rings : sequence of ndarray of shape (N_k, 2)
        Closed rings without repeated closing vertex and without repeated vertices.

    Returns
    -------
    tuple of int or None
        ``(ring_a, edge_a, ring_b, edge_b)`` for one offending pair (edge ``i`` runs from
        vertex ``i`` to vertex ``i + 1``), or ``None`` when the rings are simple and disjoint.

    Examples
    --------
    >>> square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    >>> find_crossing([square]) is None
    True
    >>> find_crossing([np.array([[0.0, 0], [1, 1], [1, 0], [0, 1]])])
    (0, 0, 0, 2)
    """
    starts = np.concatenate(rings)  # (S, 2)
    ends = np.concatenate([np.roll(r, -1, axis=0) for r in rings])  # (S, 2)
    ring_id = np.concatenate([np.full(len(r), k, dtype=np.intp) for k, r in enumerate(rings)])
    edge_id = np.concatenate([np.arange(len(r), dtype=np.intp) for r in rings])
    ring_len = np.asarray([len(r) for r in rings], dtype=np.intp)[ring_id]
    lo = np.minimum(starts, ends)  # (S, 2) bounding boxes
    hi = np.maximum(starts, ends)
    axis = int(np.argmin((hi - lo).sum(axis=0)))
    other = 1 - axis
    order = np.argsort(lo[:, axis], kind="stable")
    lo_sorted = lo[order, axis]
    stop = np.searchsorted(lo_sorted, hi[order, axis], side="right")  # (S,)
    counts = stop - np.arange(len(order)) - 1  # partners after each edge in sweep order
    cum = np.cumsum(counts)
    row = 0
    n = len(order)
    while row < n:
        base = cum[row - 1] if row else 0
        last = int(np.searchsorted(cum, base + _PAIR_CHUNK, side="right"))
        last = max(last, row + 1)
        c = counts[row:last]
        total = int(c.sum())
        if total:
            i_sorted = np.repeat(np.arange(row, last), c)
            j_sorted = i_sorted + 1 + (np.arange(total) - np.repeat(np.cumsum(c) - c, c))
            a, b = order[i_sorted], order[j_sorted]
            keep = (lo[a, other] <= hi[b, other]) & (lo[b, other] <= hi[a, other])
            gap = np.abs(edge_id[a] - edge_id[b])
            adjacent = (ring_id[a] == ring_id[b]) & ((gap == 1) | (gap == ring_len[a] - 1))
            keep &= ~adjacent
            a, b = a[keep], b[keep]
            hits = _segments_meet(starts[a], ends[a], starts[b], ends[b])
            if hits.any():
                k = int(np.flatnonzero(hits)[0])
                pa, pb = sorted((int(a[k]), int(b[k])))
                return (int(ring_id[pa]), int(edge_id[pa]), int(ring_id[pb]), int(edge_id[pb]))
        row = last
    return None


def _segments_meet(p: FloatArray, q: FloatArray, r: FloatArray, s: FloatArray) -> NDArray[np.bool_]:
    """Whether segments pq and rs share a point, for boxes already known to overlap."""

    def orient(a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
        out: FloatArray = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (
            c[:, 0] - a[:, 0]
        )
        return out

    o1, o2 = orient(p, q, r), orient(p, q, s)
    o3, o4 = orient(r, s, p), orient(r, s, q)
    # With overlapping boxes, opposite (or zero) signs on both sides mean the segments meet,
    # including the collinear case (all four zero).
    return np.asarray(
        (np.sign(o1) * np.sign(o2) <= 0) & (np.sign(o3) * np.sign(o4) <= 0), dtype=np.bool_
    )
