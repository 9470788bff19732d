"""The identity of a part in documents: a hash of its hull, and the test of sameness.

A plan's angles hold for one part's hull and centre of mass, whatever the translation, so a
document names its part (:func:`part_id`) and a reader checks that a plan is run on the part
it was made for (:func:`same_part`).
"""

from __future__ import annotations

import hashlib
from array import array
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import BayesGraspError
from ..geometry.polygon import ConvexPolygon, Part
from ..sizes import SMALL

__all__ = ["part_id", "same_part"]


def _grid(hull: ConvexPolygon) -> float:
    """The rounding step of a part's identity: its symmetry tolerance (``symmetry * size``)."""
    return hull.tol.symmetry_for(hull.size)


def part_id(part: Part) -> str:
    """The identity of a part for plans: ``"sha256:"`` and 16 hex digits.

    A plan's angles hold for the part's hull and centre of mass in the user's coordinates,
    whatever the translation (design.md). So the hash is of the hull's vertices relative to
    the centre of mass, counter-clockwise from the lexicographically least, rounded to the
    part's symmetry tolerance ``tol.symmetry * size`` (:class:`~bayesgrasp.tolerance.
    Tolerance`): the same part read from another file, moved, or rounded to 7 digits has the
    same id, a rotated or different part another. Two parts a rounding step apart can hash
    differently; :func:`same_part` then compares the vertices themselves.

    Examples
    --------
    >>> a = Part.from_points([(0, 0), (3, 0), (0, 1)])
    >>> b = Part.from_points([(10, 5), (10, 6), (13, 5)])  # moved, another vertex order
    >>> part_id(a) == part_id(b), part_id(a) == part_id(Part.from_points([(0, 0), (1, 0), (0, 3)]))
    (True, False)
    """
    q = _grid(part.hull)
    data = _small_id_bytes(part, q) if len(part.hull.vertices) <= SMALL else None
    if data is None:
        ints = np.rint((part.hull.vertices - part.center_of_mass) / q).astype(np.int64)  # (N, 2)
        start = min(range(len(ints)), key=lambda i: (int(ints[i, 0]), int(ints[i, 1])))
        data = np.roll(ints, -start, axis=0).tobytes()
    return "sha256:" + hashlib.sha256(data).hexdigest()[:16]


def _small_id_bytes(part: Part, q: float) -> bytes | None:
    """The bytes :func:`part_id` hashes, on Python floats (a hull of at most ``SMALL`` vertices).

    The same subtraction and division as numpy's, then ``round`` (halves to even, as
    ``np.rint``), and the int64 values in the machine's byte order, as ``ndarray.tobytes``
    (``array("q")``: long long, 8 bytes). ``None`` (numpy decides) for a value ``round``
    refuses (not finite) or beyond int64, which ``array`` refuses; every rounded value it
    takes is an integral float within int64, which numpy's cast keeps exactly.
    """
    cx, cy = part.center_of_mass.tolist()
    units: list[float] = []  # x0, y0, x1, y1, ... in rounding steps from the centre of mass
    for x, y in zip(*part.hull._coords()):  # noqa: B905 (as long; strict= costs)
        units += ((x - cx) / q, (y - cy) / q)
    try:  # round() by the method itself: half round()'s cost, which looks the method up
        flat = [*map(float.__round__, units)]
    except (OverflowError, ValueError):  # an infinity, NaN
        return None
    start = 2 * _least(flat)
    try:
        return array("q", flat[start:] + flat[:start]).tobytes()
    except OverflowError:
        return None


def _least(flat: list[int]) -> int:
    """The index of the first lexicographically least (x, y) pair of ``[x0, y0, x1, ...]``.

    (A function of its own: a closure in :func:`_small_id_bytes` would make cells of its
    variables at every call, ties or not.)
    """
    xs = flat[0::2]
    least = min(xs)
    if xs.count(least) == 1:
        return xs.index(least)
    return min(range(len(xs)), key=lambda i: (xs[i], flat[2 * i + 1]))


def same_part(doc: Any, part: Part) -> bool | None:
    """Whether a document's ``part`` object is ``part`` (``None``: it names no part).

    The same :func:`part_id`, or else the same number of hull vertices, each within the
    part's symmetry tolerance of its counterpart after both hulls are moved to their area
    centroids, and the centre of mass (when the document has one) as near its place.
    """
    if not isinstance(doc, Mapping) or "vertices" not in doc:
        return None
    if isinstance(doc.get("id"), str) and doc["id"] == part_id(part):
        return True
    try:
        other = ConvexPolygon.from_points(doc["vertices"])
    except (BayesGraspError, TypeError, ValueError):
        return False
    q = _grid(part.hull)
    a = part.hull.vertices - part.hull.centroid  # (N, 2)
    b = other.vertices - other.centroid
    if len(a) != len(b):
        return False
    if not any(np.max(np.hypot(*(a - np.roll(b, k, axis=0)).T)) <= q for k in range(len(b))):
        return False
    com = doc.get("center_of_mass")
    if com is None:
        return True
    try:
        there = np.asarray(com, dtype=np.float64).reshape(2) - other.centroid
    except (TypeError, ValueError):
        return False
    return bool(np.hypot(*(there - (part.center_of_mass - part.hull.centroid))) <= q)
