"""The seed's random-polygon study (section 5).

"We generate 10 random points in the unit square and find their convex hull. The average
number of sides was 5.9." For each of 2000 such polygons the seed planned squeeze plans
under the uniform prior and unit costs and reported: how often a shorter, less certain plan
has lower expected time than the most certain plan (737/2000), and the node statistics of
its breadth-first search (1% of the polygons passed 1000 nodes; the best-first fallback then
used fewer than 236). :func:`run_study` repeats the experiment with either planner; the
breadth-first statistics come from :func:`~bayesgrasp.planning.bfs.search_bfs`.

A "shorter plan is better" when the Bayes plan's expected cost is strictly below the most
certain plan's (the Bayes plan is then shorter: ties go to fewer squeezes).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from ..errors import PlanningError
from ..geometry.polygon import Part
from ..model.problem import Problem
from ..planning.bfs import search_bfs
from ..planning.exact import plan_exact

__all__ = [
    "PAPER",
    "BfsNodeStats",
    "StudyResult",
    "random_polygon",
    "run_study",
    "study_json",
    "study_table",
]

#: The seed's printed figures for its 2000 polygons.
PAPER: dict[str, float] = {
    "polygons": 2000,
    "mean_sides": 5.9,
    "shorter_plan_better": 737,
    "over_node_limit_fraction": 0.01,
    "node_limit": 1000,
    "fallback_nodes_below": 236,
}


def random_polygon(rng: np.random.Generator | int | None = None, points: int = 10) -> Part:
    """The convex hull of ``points`` uniform random points in the unit square (the seed).

    Examples
    --------
    >>> random_polygon(1).hull.n_sides
    7
    """
    g = np.random.default_rng(rng)
    return Part.from_points(g.uniform(size=(points, 2)), name="random")


# Polygons whose points run_study draws in one call (the same numbers as one call each:
# the generator's doubles come one after the other).
_DRAW = 500


@dataclass(frozen=True, slots=True)
class BfsNodeStats:
    """Node counts of the breadth-first baseline over the study's polygons.

    Attributes
    ----------
    node_limit : int
        The breadth-first search's limit (the seed: 1000).
    over_limit : int
        Polygons whose breadth-first search reached the limit (then the fallback ran).
    mean_nodes, median_nodes : float
        Nodes of the breadth-first search (capped at the limit).
    max_nodes_completed : int
        Most nodes used by a search that finished under the limit.
    fallback_max_nodes : int
        Most nodes used by the best-first fallback (0 if it never ran).
    fallback_reached : int
        Fallback runs that reached the highest attainable probability.
    agree : int
        Polygons where the search finished under the limit and its success probabilities
        equal the exact planner's for every plan length (to 1e-9).
    tree_over_limit : int
        Polygons where a search merging no duplicate hyperstates would pass the limit.
    tree_max_nodes : int
        Most nodes of the unmerged search, among polygons where it was counted.
    seconds : float
        Wall time of the breadth-first searches (problem set-up excluded).
    """

    node_limit: int
    over_limit: int
    mean_nodes: float
    median_nodes: float
    max_nodes_completed: int
    fallback_max_nodes: int
    fallback_reached: int
    agree: int
    tree_over_limit: int
    tree_max_nodes: int
    seconds: float


@dataclass(frozen=True, slots=True)
class StudyResult:
    """Figures of one run of the study.

    Attributes
    ----------
    polygons, seed : int
    method : str
        Planner whose plans give the figures: ``"exact"`` or ``"bfs"``.
    mean_sides : float
    sides_histogram : dict of int to int
    shorter_plan_better : int
        Polygons where a shorter, less certain plan has lower expected cost.
    plan_length_histogram : dict of int to int
        Lengths (squeezes) of the most certain plans.
    bayes_length_histogram : dict of int to int
        Lengths of the Bayes plans.
    planner_seconds : float
        Wall time of the chosen planner (problem set-up excluded).
    bfs : BfsNodeStats or None
        Breadth-first node statistics (when computed).
    seconds : float
        Wall time of the whole run.
    """

    polygons: int
    seed: int
    method: str
    mean_sides: float
    sides_histogram: dict[int, int]
    shorter_plan_better: int
    plan_length_histogram: dict[int, int]
    bayes_length_histogram: dict[int, int]
    planner_seconds: float
    bfs: BfsNodeStats | None
    seconds: float

    @property
    def shorter_plan_fraction(self) -> float:
        """Fraction of polygons where a shorter plan is better."""
        return self.shorter_plan_better / self.polygons


def run_study(
    polygons: int = 2000,
    seed: int = 0,
    method: Literal["exact", "bfs"] = "exact",
    bfs_stats: bool | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> StudyResult:
    """Plan every polygon of the seed's random study and gather its figures.

    Parameters
    ----------
    polygons : int
        How many random polygons (the seed: 2000).
    seed : int
        Seed of the random generator; polygon ``i`` is the hull of the ``i``-th draw of 10
        points, so a run with more polygons extends a shorter one.
    method : {"exact", "bfs"}
        Planner whose plans give the figures.
    bfs_stats : bool, optional
        Also run the breadth-first baseline for its node statistics (default: when
        ``method`` is ``"bfs"``).
    progress : callable, optional
        Called as ``progress(done, total)`` after each polygon.

    Returns
    -------
    StudyResult

    Examples
    --------
    >>> res = run_study(polygons=50, seed=1)
    >>> res.mean_sides, res.shorter_plan_better, sum(res.plan_length_histogram.values())
    (6.0, 18, 50)
    """
    if polygons < 1:
        raise PlanningError(f"`polygons` must be at least 1; got {polygons}")
    if method not in ("exact", "bfs"):
        raise PlanningError(f"`method` must be 'exact' or 'bfs'; got {method!r}")
    with_bfs = method == "bfs" if bfs_stats is None else bfs_stats
    start = time.perf_counter()
    rng = np.random.default_rng(seed)
    sides: list[int] = []
    better = 0
    most_len: Counter[int] = Counter()
    bayes_len: Counter[int] = Counter()
    t_plan = t_bfs = 0.0
    bfs_nodes: list[int] = []
    over = fb_max = fb_reached = agree = tree_over = tree_max = max_done = 0
    limit = int(PAPER["node_limit"])
    draws = np.empty((0, 10, 2))
    for i in range(polygons):
        if i % _DRAW == 0:  # the points of the next polygons, as random_polygon draws them
            draws = rng.uniform(size=(min(_DRAW, polygons - i), 10, 2))
        part = Part.from_points(draws[i % _DRAW], name="random")
        problem = Problem.build(part)
        sides.append(part.hull.n_sides)
        exact = None
        if method == "exact" or with_bfs:
            t0 = time.perf_counter()
            exact = plan_exact(problem)
            if method == "exact":
                t_plan += time.perf_counter() - t0
        res = None
        if with_bfs:
            t0 = time.perf_counter()
            res = search_bfs(problem, node_limit=limit)
            dt = time.perf_counter() - t0
            t_bfs += dt
            if method == "bfs":
                t_plan += dt
            st = res.stats
            bfs_nodes.append(st.bfs_nodes)
            if st.completed:
                max_done = max(max_done, st.bfs_nodes)
                if exact is not None and _agree(res.report.options, exact.options):
                    agree += 1
            else:
                over += 1
                fb_max = max(fb_max, st.fallback_nodes)
                fb_reached += st.reached
            if st.tree_nodes is None or st.tree_nodes > limit:
                tree_over += 1
            if st.tree_nodes is not None:
                tree_max = max(tree_max, st.tree_nodes)
        report = res.report if method == "bfs" and res is not None else exact
        if report is None:  # pragma: no cover - one of the planners always ran
            raise PlanningError("internal error: no planner ran")
        b, m = report.bayes_plan, report.most_certain_plan
        if b.expected_cost < m.expected_cost * (1.0 - 1e-9):
            better += 1
        most_len[m.n_actions] += 1
        bayes_len[b.n_actions] += 1
        if progress is not None:
            progress(i + 1, polygons)
    bfs = None
    if with_bfs:
        arr = np.array(bfs_nodes)
        bfs = BfsNodeStats(
            limit,
            over,
            float(arr.mean()),
            float(np.median(arr)),
            max_done,
            fb_max,
            fb_reached,
            agree,
            tree_over,
            tree_max,
            t_bfs,
        )
    return StudyResult(
        polygons,
        seed,
        method,
        float(np.mean(sides)),
        dict(sorted(Counter(sides).items())),
        better,
        dict(sorted(most_len.items())),
        dict(sorted(bayes_len.items())),
        t_plan,
        bfs,
        time.perf_counter() - start,
    )


def _agree(a: tuple[Any, ...], b: tuple[Any, ...]) -> bool:
    """Same number of options and the same success probabilities to 1e-9."""
    return len(a) == len(b) and all(
        abs(x.success_probability - y.success_probability) <= 1e-9
        for x, y in zip(a, b, strict=True)
    )


def study_json(result: StudyResult) -> dict[str, Any]:
    """The ``bayesgrasp.study/1`` document.

    Examples
    --------
    >>> doc = study_json(run_study(polygons=5, seed=1))
    >>> doc["schema"], doc["polygons"], sum(doc["plan_length_histogram"].values())
    ('bayesgrasp.study/1', 5, 5)
    """
    doc: dict[str, Any] = {
        "schema": "bayesgrasp.study/1",
        "polygons": result.polygons,
        "seed": result.seed,
        "method": result.method,
        "points_per_polygon": 10,
        "mean_sides": result.mean_sides,
        "sides_histogram": {str(k): v for k, v in result.sides_histogram.items()},
        "shorter_plan_better": result.shorter_plan_better,
        "shorter_plan_fraction": result.shorter_plan_fraction,
        "plan_length_histogram": {str(k): v for k, v in result.plan_length_histogram.items()},
        "bayes_length_histogram": {str(k): v for k, v in result.bayes_length_histogram.items()},
        "planner_seconds": result.planner_seconds,
        "seconds": result.seconds,
        "bfs": None,
        "paper": dict(PAPER),
    }
    if result.bfs is not None:
        s = result.bfs
        doc["bfs"] = {
            "node_limit": s.node_limit,
            "over_limit": s.over_limit,
            "over_limit_fraction": s.over_limit / result.polygons,
            "mean_nodes": s.mean_nodes,
            "median_nodes": s.median_nodes,
            "max_nodes_completed": s.max_nodes_completed,
            "fallback_max_nodes": s.fallback_max_nodes,
            "fallback_reached": s.fallback_reached,
            "agree_with_exact": s.agree,
            "unmerged_over_limit": s.tree_over_limit,
            "unmerged_max_nodes": s.tree_max_nodes,
            "seconds": s.seconds,
        }
    return doc


def study_table(result: StudyResult) -> str:
    """The study's figures beside the seed's, as text.

    Examples
    --------
    >>> print(study_table(run_study(polygons=5, seed=1)).splitlines()[0])
    5 random polygons (hulls of 10 uniform points in the unit square), seed 1, exact planner
    """
    n = result.polygons
    pct = 100.0 * result.shorter_plan_fraction
    paper_better = int(PAPER["shorter_plan_better"])
    paper_pct = 100.0 * paper_better / PAPER["polygons"]
    rows = [
        (
            "mean number of sides",
            f"{result.mean_sides:.3f}",
            f"{PAPER['mean_sides']}",
        ),
        (
            "shorter, less certain plan better",
            f"{result.shorter_plan_better} ({pct:.1f}%)",
            f"{paper_better} ({paper_pct:.1f}%)",
        ),
    ]
    if result.bfs is not None:
        s = result.bfs
        rows += [
            (
                f"breadth-first over {s.node_limit} nodes",
                f"{s.over_limit} ({100.0 * s.over_limit / n:.1f}%)",
                f"{100 * PAPER['over_node_limit_fraction']:.0f}%",
            ),
            (
                "best-first fallback, most nodes",
                f"{s.fallback_max_nodes} ({s.fallback_reached}/{s.over_limit} reached)",
                f"< {int(PAPER['fallback_nodes_below'])}",
            ),
            (
                "breadth-first nodes: mean / median",
                f"{s.mean_nodes:.1f} / {s.median_nodes:g}",
                "-",
            ),
            (
                "same probabilities as exact",
                f"{s.agree} of {n - s.over_limit} completed",
                "-",
            ),
            (
                f"without merging: over {s.node_limit}",
                f"{s.tree_over_limit} ({100.0 * s.tree_over_limit / n:.1f}%)",
                "-",
            ),
            ("breadth-first time (s)", f"{s.seconds:.2f}", "-"),
        ]
    rows += [
        (f"{result.method} planner time (s)", f"{result.planner_seconds:.2f}", "-"),
        ("wall time (s)", f"{result.seconds:.2f}", "-"),
    ]
    w0 = max(len(r[0]) for r in rows)
    w1 = max(len(r[1]) for r in rows)
    lines = [
        f"{n} random polygons (hulls of 10 uniform points in the unit square), seed "
        f"{result.seed}, {result.method} planner",
        f"{'':<{w0}}  {'this run':>{w1}}  paper",
    ]
    lines += [f"{a:<{w0}}  {b:>{w1}}  {c}" for a, b, c in rows]
    for title, hist in (
        ("most certain plan", result.plan_length_histogram),
        ("Bayes plan", result.bayes_length_histogram),
    ):
        counts = ", ".join(f"{k}: {v}" for k, v in hist.items())
        lines.append(f"{title} length (squeezes: polygons): {counts}")
    return "\n".join(lines)
