"""What the reports add for a curved part: what it rests on, the error bound, shallow states.

For a :class:`~bayesgrasp.geometry.curved.CurvedPart` every document's ``part`` object gets a
``curved`` member and the tables a few lines: the number of exact arcs, the error bound of
the outline (flattened curves and ``--shape-tol``) and the depth below which minima are not
states, and for each stable orientation (over half a turn; the other half is the same with
the jaws swapped) the straight edges flush with the jaws, or "smooth" for a minimum where
curves touch, its depth and whether it is shallow (:data:`~bayesgrasp.geometry.curved.SHALLOW`).
A plan whose final orientation is a shallow state gets a warning: a small error of shape,
friction or inertia may carry the part across so shallow a minimum.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..geometry.curved import SHALLOW, CurvedPart, RestingState, resting_states

if TYPE_CHECKING:
    from ..geometry.polygon import Part
    from ..model.problem import Problem

__all__ = ["curved_document", "curved_lines", "shallow_warnings"]


def _states(part: CurvedPart) -> list[RestingState]:
    return resting_states(part.diameter_function)


def curved_document(part: Part) -> dict[str, Any] | None:
    """The ``curved`` member of a part document (None for a polygon).

    Examples
    --------
    >>> from bayesgrasp.geometry.curved import CurvedRing, curved_part
    >>> doc = curved_document(curved_part(CurvedRing([(0, -1), (2, -1), (2, 1), (0, 1)],
    ...                                              [0, 1, 0, 1])))
    >>> doc["arcs"], len(doc["resting"]), len(doc["resting"][0]["edges"])
    (2, 1, 2)
    """
    if not isinstance(part, CurvedPart) or part.ring is None:
        return None
    d = part.diameter_function
    return {
        "arcs": part.ring.n_arcs,
        "curve_error": part.curve_error,
        "shape_tol": part.shape_tol,
        "min_depth": d.depth,
        "resting": [
            {
                "orientation_rad": s.theta,
                "width": s.width,
                "depth": s.depth,
                "edges": [[a.tolist(), b.tolist()] for a, b in s.edges],
                "shallow": s.shallow,
                "flat_rad": list(s.flat),
            }
            for s in _states(part)
        ],
    }


def _edge_text(state: RestingState, units: str) -> str:
    if not state.edges:
        return "smooth (curves touch both jaws)"
    parts = []
    for a0, b0 in state.edges:
        length = math.dist(a0, b0)
        # Coordinates that are rounding noise on a zero (1e-16 of the part) print as 0.
        a, b = (np.where(np.abs(p) <= 1e-12 * max(length, 1.0), 0.0, p) for p in (a0, b0))
        parts.append(
            f"edge ({a[0]:.4g}, {a[1]:.4g})-({b[0]:.4g}, {b[1]:.4g}), {length:.4g}{units} long"
        )
    return "; ".join(parts)


def curved_lines(part: Part) -> list[str]:
    """Lines for the tables: the model, and what the part rests on in each state."""
    if not isinstance(part, CurvedPart) or part.ring is None:
        return []
    d = part.diameter_function
    units = f" {part.units}" if part.units else ""
    bound = (
        f"curves flattened within {part.curve_error:.3g}{units}"
        if part.curve_error
        else "no other curves"
    )
    if part.shape_tol:
        bound += f", shape tolerance {part.shape_tol:.3g}{units}"
    lines = [
        f"curved outline: {part.ring.n_arcs} exact arcs, {bound}; minima shallower than "
        f"{d.depth:.3g}{units} are not states",
        "rests on (state, orientation mod 180 deg: what lies flush with the jaws, depth):",
    ]
    for i, s in enumerate(_states(part)):
        mark = "  SHALLOW" if s.shallow else ""
        if s.is_flat:
            lo, hi = (math.degrees(x) for x in s.flat)
            mark += f"  FLAT from {lo:.1f} to {hi:.1f} deg"
        lines.append(
            f"  {i:>3} {math.degrees(s.theta):9.3f}  {_edge_text(s, units)}; depth "
            f"{s.depth:.4g}{units}{mark}"
        )
    return lines


def shallow_warnings(problem: Problem, finals: dict[str, float]) -> list[str]:
    """Warnings for plans whose final orientation is a shallow state.

    ``finals`` maps a plan's label to its final orientation (radians).
    """
    part = problem.part
    if not isinstance(part, CurvedPart):
        return []
    states = _states(part)
    units = f" {part.units}" if part.units else ""
    out = []
    for label, theta in finals.items():
        for s in states:
            if abs(math.remainder(theta - s.theta, math.pi)) > 1e-6:
                continue
            if s.is_flat:
                lo, hi = (math.degrees(x - s.theta + theta) for x in s.flat)
                out.append(
                    f"warning: the {label} ends at {math.degrees(theta):.2f} deg, where the "
                    f"width stays within {SHALLOW:.0%} of {s.width:.4g}{units} from {lo:.1f} "
                    f"to {hi:.1f} deg: support friction may stop the part anywhere there"
                )
            if s.shallow:
                out.append(
                    f"warning: the {label} ends at {math.degrees(theta):.2f} deg, a shallow "
                    f"minimum (depth {s.depth:.3g}{units}, under {SHALLOW:.0%} of the jaw "
                    f"opening {s.width:.4g}{units}): a small error of shape, friction or "
                    "inertia may leave the part elsewhere"
                )
    return out
