"""The seed's 2000-polygon study: its figures, the baseline's statistics and the command."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from bayesgrasp.cli import main
from bayesgrasp.errors import PlanningError
from bayesgrasp.model.problem import Problem
from bayesgrasp.paper.study import random_polygon, run_study, study_json, study_table
from bayesgrasp.planning import plan_exact


def test_two_thousand_polygons_land_near_the_paper() -> None:
    res = run_study(polygons=2000, seed=1)
    # The seed: 5.9 sides on average, 737/2000 polygons with a better shorter plan.
    assert 5.8 <= res.mean_sides <= 6.1
    assert 0.33 <= res.shorter_plan_fraction <= 0.40
    assert sum(res.plan_length_histogram.values()) == 2000
    assert sum(res.sides_histogram.values()) == 2000
    assert res.bfs is None


def test_polygons_are_hulls_of_uniform_points() -> None:
    """Independent hull (Qhull) of the same draws: same side counts."""
    rng_a, rng_b = np.random.default_rng(7), np.random.default_rng(7)
    for _ in range(200):
        part = random_polygon(rng_a)
        pts = rng_b.uniform(size=(10, 2))
        assert part.hull.n_sides == len(ConvexHull(pts).vertices)
    res = run_study(polygons=200, seed=7)
    rng = np.random.default_rng(7)
    sides = [len(ConvexHull(rng.uniform(size=(10, 2))).vertices) for _ in range(200)]
    assert res.mean_sides == pytest.approx(np.mean(sides), abs=1e-12)


def test_shorter_plan_count_recomputed_from_plans() -> None:
    res = run_study(polygons=60, seed=3)
    rng = np.random.default_rng(3)
    better = 0
    for _ in range(60):
        rep = plan_exact(Problem.build(random_polygon(rng)))
        costs = [o.expected_cost for o in rep.options]
        probs = [o.success_probability for o in rep.options]
        most = probs.index(max(probs))  # the shortest most certain plan
        better += min(costs) < costs[most] * (1 - 1e-9)
    assert res.shorter_plan_better == better


def test_breadth_first_statistics_match_the_paper_shape() -> None:
    res = run_study(polygons=300, seed=2, bfs_stats=True)
    s = res.bfs
    assert s is not None
    assert s.over_limit <= 0.03 * 300  # the seed: 1%
    assert s.fallback_reached == s.over_limit
    assert s.agree == 300 - s.over_limit  # every completed search equals the exact planner
    assert s.max_nodes_completed < s.node_limit
    assert s.tree_over_limit >= s.over_limit


def test_bfs_method_uses_the_baseline_plans() -> None:
    exact = run_study(polygons=80, seed=4)
    bfs = run_study(polygons=80, seed=4, method="bfs")
    assert bfs.bfs is not None
    assert bfs.mean_sides == exact.mean_sides
    if bfs.bfs.over_limit == 0:
        assert bfs.shorter_plan_better == exact.shorter_plan_better
        assert bfs.plan_length_histogram == exact.plan_length_histogram


def test_progress_is_reported_for_every_polygon() -> None:
    calls: list[tuple[int, int]] = []
    run_study(polygons=12, seed=1, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(i, 12) for i in range(1, 13)]


def test_json_and_table() -> None:
    res = run_study(polygons=30, seed=5, bfs_stats=True)
    doc = study_json(res)
    for key in ("polygons", "seed", "mean_sides", "shorter_plan_better", "seconds"):
        assert key in doc
    assert doc["plan_length_histogram"] == {str(k): v for k, v in res.plan_length_histogram.items()}
    assert doc["bfs"]["over_limit"] == res.bfs.over_limit  # type: ignore[union-attr]
    json.dumps(doc, allow_nan=False)
    text = study_table(res)
    assert "mean number of sides" in text and "737 (36.9%)" in text


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"polygons": 0}, "`polygons` must be at least 1; got 0"),
        ({"method": "dfs"}, "`method` must be 'exact' or 'bfs'; got 'dfs'"),
    ],
)
def test_bad_arguments(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(PlanningError, match=match):
        run_study(**kwargs)  # type: ignore[arg-type]


def test_cli_study_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["study", "--polygons", "25", "--seed", "2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["polygons"] == 25 and doc["seed"] == 2
    assert doc["mean_sides"] == run_study(polygons=25, seed=2).mean_sides
    assert doc["bfs"]["node_limit"] == 1000


def test_cli_study_table_and_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["study", "--polygons", "10", "--method", "bfs", "--no-bfs-stats"]) == 0
    out = capsys.readouterr().out
    assert "bfs planner" in out and "breadth-first over 1000 nodes" in out
    assert main(["study", "--polygons", "0"]) == 2
    assert "--polygons" in capsys.readouterr().err


def test_block_draws_are_random_polygons_draws(monkeypatch: pytest.MonkeyPatch) -> None:
    """The study draws several polygons' points per call: the same polygons, any block size."""
    from bayesgrasp.paper import study

    rng = np.random.default_rng(3)
    sides = [random_polygon(rng).hull.n_sides for _ in range(23)]
    whole = run_study(23, seed=3)
    assert sum(k * v for k, v in whole.sides_histogram.items()) == sum(sides)
    monkeypatch.setattr(study, "_DRAW", 5)  # blocks of 5 (the last one of 3)
    blocks = run_study(23, seed=3)
    assert whole.sides_histogram == blocks.sides_histogram
    assert whole.shorter_plan_better == blocks.shorter_plan_better
    assert whole.plan_length_histogram == blocks.plan_length_histogram
    assert whole.bayes_length_histogram == blocks.bayes_length_histogram
