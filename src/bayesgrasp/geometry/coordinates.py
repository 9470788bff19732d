"""Coordinates as the library accepts them: finite real numbers, shape (N, 2), in range.

Every part, hull and outline starts here. :func:`as_points` refuses anything but real
numbers (text is not parsed, booleans are not numbers) with one line naming the offending
point, and the range checks keep the products of two coordinates (areas, cross products)
away from float64's overflow (about 1e308) and underflow (about 1e-308).
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import PartError
from ..tolerance import Tolerance

__all__ = [
    "MAX_COORD",
    "MIN_EXTENT",
    "FloatArray",
    "as_points",
    "check_magnitude",
    "check_tolerance",
    "odd_magnitude",
]

FloatArray = NDArray[np.float64]


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


def check_tolerance(tol: object) -> None:
    """Refuse a ``tol`` that is not a :class:`~bayesgrasp.tolerance.Tolerance`.

    Examples
    --------
    >>> check_tolerance(Tolerance())
    >>> check_tolerance(1e-9)
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.PartError: `tol` must be a Tolerance; got float
    """
    if not isinstance(tol, Tolerance):
        raise PartError(f"`tol` must be a Tolerance; got {type(tol).__name__}")


# Areas are products of two coordinates: beyond these magnitudes they overflow or underflow.
MAX_COORD = 1e150
MIN_EXTENT = 1e-150


def check_magnitude(pts: FloatArray, extent: float) -> None:
    """Refuse coordinates whose products overflow, or parts too small to tell from a point.

    An area or cross product multiplies two coordinates (or two differences of them): with
    every ``|coordinate|`` at most :data:`MAX_COORD` = 1e150 and an extent of at least
    :data:`MIN_EXTENT` = 1e-150 the products stay within float64's normal range.

    Examples
    --------
    >>> check_magnitude(np.array([[0.0, 0.0], [1.0, 1.0]]), 1.0)
    >>> check_magnitude(np.array([[0.0, 0.0], [1e200, 1.0]]), 1e200)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    bayesgrasp.errors.PartError: `vertices` must be at most 1e+150 in absolute value; got 1e+200 ...
    """
    if len(pts) and float(np.max(np.abs(pts))) > MAX_COORD:
        raise PartError(
            f"`vertices` must be at most {MAX_COORD:g} in absolute value; "
            f"got {float(np.max(np.abs(pts))):g} (rescale the part's units)"
        )
    if 0.0 < extent < MIN_EXTENT:
        raise PartError(
            f"the part is {extent:g} across; parts smaller than {MIN_EXTENT:g} cannot be "
            "resolved (rescale the part's units)"
        )


def odd_magnitude(x0: float, x1: float, y0: float, y1: float, extent: float) -> bool:
    """Whether :func:`check_magnitude` must look: a coordinate or the extent out of range.

    ``x0, x1, y0, y1`` are the least and largest coordinates, so the largest
    ``|coordinate|`` is the largest of ``x1, -x0, y1, -y0``; a cheap pre-test on a few
    floats before the array check.
    """
    big = MAX_COORD
    return x1 > big or -x0 > big or y1 > big or -y0 > big or 0.0 < extent < MIN_EXTENT
