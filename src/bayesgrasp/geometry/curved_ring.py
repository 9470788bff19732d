"""Closed outlines of line segments and circular arcs: points and bulges, area and centroid.

The outline of a curved part (:mod:`bayesgrasp.geometry.curved`): :class:`CurvedRing`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import PartError
from .polygon import as_points

__all__ = ["SAFE_SIZE", "CurvedRing"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]

SAFE_SIZE = (1e-90, 1e90)
"""Outline sizes whose areas and moments (squares and cubes of coordinates) are computed as
they come; others are computed at unit size and scaled back."""


# --------------------------------------------------------------------------------------
# Outlines of segments and arcs


@dataclass(frozen=True, slots=True, eq=False)
class CurvedRing:
    """A closed outline of segments and circular arcs, given by points and bulges.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        The ends of the pieces, in order, no repeated closing point.
    bulges : array_like of shape (N,)
        ``tan(sweep / 4)`` of the piece from point ``i`` to point ``i + 1`` (0: a segment;
        positive: an arc turning counter-clockwise; 1: a half circle).
    chords : array_like of bool of shape (N,), optional
        Which pieces are chords of a flattened curve (not straight edges of the part).

    Examples
    --------
    >>> disc = CurvedRing([(1, 0), (-1, 0)], [1.0, 1.0])  # two half circles
    >>> a, c = disc.area_centroid()
    >>> round(a, 12), np.round(c, 12).tolist()
    (3.14159265359, [0.0, 0.0])
    """

    points: FloatArray
    bulges: FloatArray
    chords: NDArray[np.bool_] | None = None

    def __post_init__(self) -> None:
        p = as_points(self.points, "points")
        b = np.asarray(self.bulges, dtype=np.float64).reshape(-1)
        ch = np.zeros(len(p), dtype=bool) if self.chords is None else np.asarray(self.chords, bool)
        if ch.shape != (len(p),):
            raise PartError(f"`chords` must have one value per point ({len(p)})")
        ch = ch.copy()
        ch.setflags(write=False)
        object.__setattr__(self, "chords", ch)
        if len(b) != len(p):
            raise PartError(f"`bulges` must have one value per point ({len(p)}); got {len(b)}")
        if not np.all(np.isfinite(b)):
            raise PartError("`bulges` must be finite")
        if len(p) < 2 or (len(p) == 2 and not np.any(b != 0)):
            raise PartError(f"a curved outline needs at least 3 points or arcs; got {len(p)}")
        step = np.roll(p, -1, axis=0) - p
        gaps = np.hypot(step[:, 0], step[:, 1])
        extent = float(np.max(np.ptp(p, axis=0)))
        if not extent > 1e-150 or float(np.max(np.abs(p))) > 1e150:
            raise PartError(
                f"the outline is {extent:g} across; it must be between 1e-150 and 1e150 "
                "(rescale the part's units)"
            )
        short = np.flatnonzero(gaps <= 1e-12 * extent)
        if len(short):
            i = int(short[0])
            raise PartError(f"`points` {i} and {(i + 1) % len(p)} of the outline coincide")
        p = p.copy()
        b = b.copy()
        p.setflags(write=False)
        b.setflags(write=False)
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "bulges", b)

    @property
    def n_arcs(self) -> int:
        """Number of arc pieces."""
        return int(np.count_nonzero(self.bulges))

    def arcs(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, IntArray]:
        """Centre, radius, start angle and signed sweep of each arc piece, and its index.

        Returns
        -------
        centers : ndarray of shape (A, 2)
        radii, starts, sweeps : ndarray of shape (A,)
            The arc runs from angle ``starts`` (about its centre) through ``sweeps``.
        index : ndarray of shape (A,)
            The piece (from point ``index`` to the next).
        """
        idx = np.flatnonzero(self.bulges)
        p = self.points[idx]
        q = np.roll(self.points, -1, axis=0)[idx]
        b = self.bulges[idx]
        chord = q - p
        length = np.hypot(chord[:, 0], chord[:, 1])
        left = np.column_stack([-chord[:, 1], chord[:, 0]]) / length[:, None]
        centers = 0.5 * (p + q) + left * (0.5 * length * (1.0 - b * b) / (2.0 * b))[:, None]
        sweeps = 4.0 * np.arctan(b)
        radii = 0.5 * length / np.abs(np.sin(0.5 * sweeps))
        starts = np.arctan2(p[:, 1] - centers[:, 1], p[:, 0] - centers[:, 0])
        return centers, radii, starts, sweeps, idx

    def area_centroid(self) -> tuple[float, FloatArray]:
        """Signed area (positive counter-clockwise) and area centroid, exact.

        The shoelace polygon of the points, plus for each arc the circular segment between
        its chord and the arc: area ``r^2 (a - sin a) / 2`` (``a`` the sweep), centroid at
        ``4 r sin^3(a / 2) / (3 (a - sin a))`` from the centre toward the arc.
        """
        p = self.points
        origin = p[0]
        rel = p - origin
        size = float(np.max(np.abs(rel)))
        if not SAFE_SIZE[0] <= size <= SAFE_SIZE[1] and size > 0.0:
            # Moments are cubes of coordinates: at unit size they neither overflow nor
            # underflow (outlines may reach 1e150 across, or be 1e-150 small).
            unit = CurvedRing(rel / size, self.bulges).area_centroid()
            return unit[0] * size * size, np.asarray(unit[1] * size + origin, dtype=np.float64)
        q = np.roll(rel, -1, axis=0)
        cross = rel[:, 0] * q[:, 1] - q[:, 0] * rel[:, 1]
        area = 0.5 * float(cross.sum())
        moment = ((rel + q) * cross[:, None]).sum(axis=0) / 6.0  # (2,) area times centroid
        if self.n_arcs:
            centers, radii, _, sweeps, idx = self.arcs()
            a = np.abs(sweeps)
            seg = np.sign(sweeps) * 0.5 * radii**2 * (a - np.sin(a))  # (A,) signed areas
            start, end = rel[idx], q[idx]
            chord = end - start
            length = np.hypot(chord[:, 0], chord[:, 1])
            right = np.column_stack([chord[:, 1], -chord[:, 0]]) / length[:, None]
            tip = 0.5 * (start + end) + right * (0.5 * self.bulges[idx] * length)[:, None]
            c = centers - origin
            toward = (tip - c) / radii[:, None]  # unit vector from the centre to the arc
            dist = 4.0 * radii * np.sin(0.5 * a) ** 3 / (3.0 * (a - np.sin(a)))
            area += float(seg.sum())
            moment = moment + ((c + toward * dist[:, None]) * seg[:, None]).sum(axis=0)
        if area == 0.0:
            return 0.0, p.mean(axis=0)
        return area, np.asarray(moment / area + origin, dtype=np.float64)

    def flattened(self, tol: float) -> FloatArray:
        """Points within ``tol`` of the outline (arcs sampled on the arc), in order."""
        if not self.n_arcs:
            return np.array(self.points, dtype=np.float64)
        centers, radii, starts, sweeps, idx = self.arcs()
        out: list[FloatArray] = []
        arc_of = {int(i): k for k, i in enumerate(idx.tolist())}
        for i in range(len(self.points)):
            out.append(self.points[i : i + 1])
            k = arc_of.get(i)
            if k is None:
                continue
            step = 2.0 * math.acos(max(-1.0, 1.0 - tol / radii[k])) if tol < radii[k] else 1.0
            n = max(2, math.ceil(abs(sweeps[k]) / max(step, 1e-6)))
            t = starts[k] + sweeps[k] * np.arange(1, n) / n
            out.append(centers[k] + radii[k] * np.column_stack([np.cos(t), np.sin(t)]))
        return np.concatenate(out)

    def reversed(self) -> CurvedRing:
        """The same outline run the other way."""
        p = self.points[::-1]
        b = -np.roll(self.bulges[::-1], -1)
        chords = np.asarray(self.chords, dtype=bool)
        return CurvedRing(p, b, np.roll(chords[::-1], -1))
