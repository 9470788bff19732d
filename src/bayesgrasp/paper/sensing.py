"""The sensing study: what reading the jaw width saves, on the seed's polygons and parts.

For each of the seed's random polygons (section 5: hulls of 10 uniform points in the unit
square, :func:`~bayesgrasp.paper.study.random_polygon`) and each part of Table 1, under the
uniform prior and unit costs, :func:`run_sensing_study` plans

- the sensorless Bayes plan within ``max_actions`` actions
  (:func:`~bayesgrasp.planning.exact.plan_exact`, the seed's ``C / p``), and
- the Bayes policy (:func:`~bayesgrasp.planning.policy.plan_policy`, the seed's section 6.2)
  for each sensor: exact readings, and noisy readings whose ``SIGMA`` is a fraction of the
  part's largest diameter (1% and 5% by default) with ``RES = SIGMA / 2``,

with squeezes only and with squeezes and push-grasps (each action costing 1), and reports
the mean expected cost (and success per cycle, actions per cycle) of each column. A sensor
given as ``width:SIGMA,RES`` to the study is read *relative* to each part's largest
diameter, so that one setting suits parts of every size.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import PlanningError
from ..model.actions import PUSH_GRASP, SQUEEZE, Action
from ..model.problem import Problem
from ..model.sensing import WidthSensor, parse_sensor
from ..planning.exact import plan_exact
from ..planning.policy import plan_policy
from .study import random_polygon

__all__ = [
    "SensingColumn",
    "SensingStudy",
    "run_sensing_study",
    "sensing_columns",
    "sensing_json",
    "sensing_table",
]

SCHEMA = "bayesgrasp.sensing-study/1"
ACTION_SETS: tuple[tuple[str, tuple[Action, ...]], ...] = (
    ("squeezes", (SQUEEZE,)),
    ("squeezes and push-grasps", (SQUEEZE, PUSH_GRASP)),
)


@dataclass(frozen=True, slots=True)
class SensingColumn:
    """One sensor of the study: none, exact, or noise relative to the largest diameter.

    Attributes
    ----------
    label : str
    kind : str
        ``"none"`` (the sensorless Bayes plan), ``"exact"`` or ``"relative"``.
    sigma, resolution : float
        Fractions of each part's largest diameter (``"relative"``).
    """

    label: str
    kind: str
    sigma: float = 0.0
    resolution: float = 0.0

    def sensor(self, problem: Problem) -> WidthSensor:
        """The sensor in the part's units."""
        if self.kind == "exact":
            return WidthSensor()
        d = float(problem.widths.max())
        return WidthSensor(self.sigma * d, self.resolution * d)


def sensing_columns(spec: str | None = "width") -> tuple[SensingColumn, ...]:
    """The study's columns: none, exact, then 1% and 5% (``width``) or the sensor given.

    Examples
    --------
    >>> [c.label for c in sensing_columns("width")]
    ['none', 'exact', 'SIGMA 1%', 'SIGMA 5%']
    >>> [c.label for c in sensing_columns("width:0.02,0.01")]
    ['none', 'exact', 'SIGMA 2%, RES 1%']
    """
    cols = [SensingColumn("none", "none"), SensingColumn("exact", "exact")]
    s = parse_sensor(spec or "width", units="fractions of each part's largest diameter")
    if s.kind == "exact":
        cols += [SensingColumn(f"SIGMA {f:.0%}", "relative", f, f / 2) for f in (0.01, 0.05)]
    else:
        cols.append(SensingColumn(_label(s), "relative", s.sigma, s.resolution))
    return tuple(cols)


def _label(s: WidthSensor) -> str:
    def pct(x: float) -> str:
        return f"{100 * x:.3g}%"

    return f"SIGMA {pct(s.sigma)}, RES {pct(s.resolution)}"


@dataclass(frozen=True, slots=True)
class _Cell:
    cost: float
    success: float
    actions: float


def _plan(problem: Problem, col: SensingColumn, max_actions: int) -> _Cell:
    if col.kind == "none":
        p = plan_exact(problem, max_actions=max_actions).bayes_plan
        return _Cell(p.expected_cost, p.success_probability, float(p.n_actions))
    pol = plan_policy(problem, col.sensor(problem), max_actions, sensorless=False)
    return _Cell(pol.expected_cost, pol.success_probability, pol.expected_actions)


@dataclass(frozen=True, slots=True, eq=False)
class SensingStudy:
    """Mean figures per (action set, sensor column), on the polygons and on named parts.

    Attributes
    ----------
    polygons : int
    seed : int
    max_actions : int
    columns : tuple of SensingColumn
    action_sets : tuple of str
    polygon_cost, polygon_success, polygon_actions : dict
        ``[action set][column label]`` -> mean over the polygons.
    parts : dict
        ``[part][action set][column label]`` -> expected cost.
    seconds : dict
        ``[action set][column label]`` -> planning seconds over the polygons.
    """

    polygons: int
    seed: int
    max_actions: int
    columns: tuple[SensingColumn, ...]
    action_sets: tuple[str, ...]
    polygon_cost: dict[str, dict[str, float]]
    polygon_success: dict[str, dict[str, float]]
    polygon_actions: dict[str, dict[str, float]]
    parts: dict[str, dict[str, dict[str, float]]]
    seconds: dict[str, dict[str, float]]


def run_sensing_study(
    polygons: int = 2000,
    seed: int = 1,
    max_actions: int = 2,
    sense: str | None = "width",
    parts: Sequence[str] | None = None,
    push_grasps: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> SensingStudy:
    """Plan every polygon (and Table-1 part) without sensing and with each sensor.

    Parameters
    ----------
    polygons : int
        How many random polygons (the seed: 2000); polygon ``i`` is the same as in
        :func:`~bayesgrasp.paper.study.run_study` with this seed.
    seed : int
    max_actions : int
        At most this many actions on any path, and in the sensorless plan (default 2: noisy
        policies with push-grasps grow fast with depth).
    sense : str
        ``width`` (columns exact, 1% and 5%) or ``width:SIGMA,RES`` relative to each
        part's largest diameter.
    parts : sequence of str, optional
        Catalogue parts planned the same way (default: the parts of Table 1).
    push_grasps : bool
        Also the action set of squeezes and push-grasps.
    progress : callable, optional
        ``progress(done, total)`` after each polygon.

    Examples
    --------
    >>> res = run_sensing_study(polygons=5, parts=["rectangle"], push_grasps=False)
    >>> round(res.polygon_cost["squeezes"]["exact"], 4)
    4.0
    >>> {k: round(v, 4) for k, v in res.parts["rectangle"]["squeezes"].items()}
    {'none': 6.0, 'exact': 4.0, 'SIGMA 1%': 4.0, 'SIGMA 5%': 4.001}
    """
    if polygons < 1:
        raise PlanningError(f"`polygons` must be at least 1; got {polygons}")
    from .table1 import PAPER_TABLE1

    cols = sensing_columns(sense)
    sets = ACTION_SETS if push_grasps else ACTION_SETS[:1]
    names = [r.part for r in PAPER_TABLE1] if parts is None else list(parts)
    rng = np.random.default_rng(seed)
    shapes_ = [random_polygon(rng) for _ in range(polygons)]
    acc: dict[str, dict[str, list[_Cell]]] = {s: {c.label: [] for c in cols} for s, _ in sets}
    secs: dict[str, dict[str, float]] = {s: {c.label: 0.0 for c in cols} for s, _ in sets}
    for i, part in enumerate(shapes_):
        for sname, acts in sets:
            pb = Problem.build(part, actions=acts)
            for c in cols:
                t0 = time.perf_counter()
                acc[sname][c.label].append(_plan(pb, c, max_actions))
                secs[sname][c.label] += time.perf_counter() - t0
        if progress is not None:
            progress(i + 1, polygons)
    from ..shapes import load

    per_part: dict[str, dict[str, dict[str, float]]] = {}
    for n in names:
        part = load(n)
        per_part[n] = {}
        for sname, acts in sets:
            pb = Problem.build(part, actions=acts)
            per_part[n][sname] = {c.label: _plan(pb, c, max_actions).cost for c in cols}

    def mean(f: Callable[[_Cell], float]) -> dict[str, dict[str, float]]:
        return {
            s: {k: float(np.mean([f(x) for x in v])) for k, v in d.items()} for s, d in acc.items()
        }

    return SensingStudy(
        polygons,
        seed,
        max_actions,
        cols,
        tuple(s for s, _ in sets),
        mean(lambda x: x.cost),
        mean(lambda x: x.success),
        mean(lambda x: x.actions),
        per_part,
        secs,
    )


def sensing_json(res: SensingStudy) -> dict[str, Any]:
    """``bayesgrasp.sensing-study/1``: every mean and every part's cost, by action set."""

    def num(x: float) -> float | None:
        return None if not math.isfinite(x) else x

    return {
        "schema": SCHEMA,
        "polygons": res.polygons,
        "seed": res.seed,
        "max_actions": res.max_actions,
        "columns": [
            {"label": c.label, "kind": c.kind, "sigma": c.sigma, "resolution": c.resolution}
            for c in res.columns
        ],
        "mean_cost": res.polygon_cost,
        "mean_success": res.polygon_success,
        "mean_actions": res.polygon_actions,
        "parts": {
            p: {s: {k: num(v) for k, v in d.items()} for s, d in r.items()}
            for p, r in res.parts.items()
        },
        "planning_seconds": res.seconds,
    }


def sensing_table(res: SensingStudy) -> str:
    """The study as text: mean cost on the polygons, then each part's cost (Markdown)."""
    labels = [c.label for c in res.columns]
    head = "| | " + " | ".join(labels) + " |"
    rule = "|---" * (len(labels) + 1) + "|"
    lines = [
        f"Mean expected cost of {res.polygons} random polygons (seed {res.seed}), at most "
        f"{res.max_actions} actions; SIGMA relative to each part's largest diameter, "
        "RES = SIGMA / 2",
        "",
        head,
        rule,
    ]
    for s in res.action_sets:
        cells = " | ".join(f"{res.polygon_cost[s][k]:.3f}" for k in labels)
        lines.append(f"| {s} | {cells} |")
    for s in res.action_sets:
        cells = " | ".join(f"{res.polygon_success[s][k]:.3f}" for k in labels)
        lines.append(f"| success a cycle, {s} | {cells} |")
    lines += ["", f"Expected cost of the Table 1 parts, at most {res.max_actions} actions", ""]
    sets = res.action_sets
    head = (
        "| part | "
        + " | ".join(f"{k} ({'S' if s == sets[0] else 'S+P'})" for s in sets for k in labels)
        + " |"
    )
    lines += [head, "|---" * (len(labels) * len(sets) + 1) + "|"]
    for p, r in res.parts.items():
        cells = " | ".join(f"{r[s][k]:.3f}" for s in sets for k in labels)
        lines.append(f"| {p} | {cells} |")
    lines.append("")
    lines.append("S: squeezes only; S+P: squeezes and push-grasps.")
    return "\n".join(lines)
