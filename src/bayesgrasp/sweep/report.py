"""An HTML report of a sweep's results: one self-contained file (figures inline).

Sections: the run (options, versions), a summary table (parts, planned, no guaranteed
plan, errors by class, Bayes cost and plan length statistics), histograms of the Bayes
plan's expected cost and of its length, predicted against observed success in simulation
(with each part's 95% interval), the parts where the simulation disagrees with the
prediction (outside the observed 95% interval: "physics disagrees" for MuJoCo, a
"kinematic mismatch" for the model's own Monte Carlo, which is a sampling or evaluation
error, not physics), each with its outline drawn, a table of every part (sortable by any
column: click its header) with the simulation's agreement and interval, and the parts that
failed, with their messages.

Figures are drawn with matplotlib (extra ``plot``) as inline SVG.
"""

from __future__ import annotations

import html
import io
import json
import math
import statistics
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..errors import MissingExtraError
from .results import read_metadata, read_results

__all__ = ["disagreements", "report_html", "row_label", "write_report"]


def row_label(row: dict[str, Any]) -> str:
    """A row's part as the report names it: its path, and a mesh's pose with its probability.

    Examples
    --------
    >>> row_label({"path": "a.stl", "pose": 2, "pose_probability": 0.125})
    'a.stl (pose 2, p = 0.125)'
    >>> row_label({"path": "a.json"})
    'a.json'
    """
    if row.get("pose") is None:
        return str(row["path"])
    return f"{row['path']} (pose {row['pose']}, p = {float(row['pose_probability']):.3g})"


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise MissingExtraError("matplotlib", "plot") from None
    return plt


def _svg(fig: Any) -> str:
    """A figure as inline SVG (closed afterwards)."""
    plt = _pyplot()
    buf = io.StringIO()
    fig.savefig(buf, format="svg", bbox_inches="tight")
    plt.close(fig)
    text = buf.getvalue()
    return text[text.index("<svg") :]


def _histogram(values: Sequence[float], xlabel: str, integer: bool = False) -> str:
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(5, 3))
    if integer:
        lo, hi = min(values), max(values)
        ax.hist(values, bins=[v - 0.5 for v in range(int(lo), int(hi) + 2)], rwidth=0.8)
        ax.set_xticks(range(int(lo), int(hi) + 1))
    else:
        ax.hist(values, bins=min(40, max(5, len(values) // 5)))
    ax.set_xlabel(xlabel)
    ax.set_ylabel("parts")
    return _svg(fig)


def _scatter(rows: Sequence[dict[str, Any]]) -> str:
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    x = [r["sim_predicted"] for r in rows]
    y = [r["sim_observed"] for r in rows]
    lo = [r["sim_observed"] - r["sim_ci_low"] for r in rows]
    hi = [r["sim_ci_high"] - r["sim_observed"] for r in rows]
    bad = {id(r) for r in disagreements(rows)}
    colors = ["tab:red" if id(r) in bad else "tab:blue" for r in rows]
    ax.errorbar(x, y, yerr=[lo, hi], fmt="none", ecolor="0.7", lw=0.8)
    ax.scatter(x, y, c=colors, s=12, zorder=3)
    ax.plot([0, 1], [0, 1], "k--", lw=0.8)
    ax.set(xlim=(0, 1), ylim=(0, 1), xlabel="predicted success", ylabel="observed success")
    ax.set_aspect("equal")
    return _svg(fig)


def _outline(row: dict[str, Any]) -> str:
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(2, 2))
    pts = json.loads(row["outline"]) if row.get("outline") else []
    if pts:
        xs, ys = zip(*[*pts, pts[0]], strict=True)
        ax.fill(xs, ys, color="0.85", ec="k", lw=1)
    ax.set_aspect("equal")
    ax.axis("off")
    return _svg(fig)


def disagreements(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Simulated parts whose predicted success is outside the observed 95% interval.

    The largest gap first.

    Examples
    --------
    >>> rows = [{"sim_predicted": 0.5, "sim_observed": 0.3, "sim_ci_low": 0.25,
    ...          "sim_ci_high": 0.35}, {"sim_predicted": 0.5, "sim_observed": 0.49,
    ...          "sim_ci_low": 0.45, "sim_ci_high": 0.53}]
    >>> len(disagreements(rows))
    1
    """
    out = [
        r
        for r in rows
        if r.get("sim_observed") is not None
        and not r["sim_ci_low"] <= r["sim_predicted"] <= r["sim_ci_high"]
    ]
    return sorted(out, key=lambda r: -abs(r["sim_predicted"] - r["sim_observed"]))


def _engine_words(rows: Sequence[dict[str, Any]]) -> tuple[str, str]:
    """What a disagreement is called for these rows' engine: (summary label, heading)."""
    engines = {r.get("sim_engine") for r in rows}
    if engines == {"kinematic"}:
        return (
            "kinematic mismatch (predicted outside the observed 95% interval)",
            "Parts where the kinematic simulation misses the prediction",
        )
    return (
        "physics disagrees (predicted outside the observed 95% interval)",
        "Parts where physics disagrees with the model",
    )


#: Sorts a table by the column whose header is clicked (numbers as numbers; again: reversed).
_SORT_JS = """<script>
document.querySelectorAll('table.sortable th').forEach(function (th, i) {
  th.style.cursor = 'pointer';
  th.addEventListener('click', function () {
    var table = th.closest('table'), rows = Array.from(table.rows).slice(1);
    var dir = th.dataset.dir === 'asc' ? -1 : 1; th.dataset.dir = dir > 0 ? 'asc' : 'desc';
    var key = function (r) { var c = r.cells[i]; var v = c.dataset.v ?? c.textContent;
      var x = parseFloat(v); return isNaN(x) ? v : x; };
    rows.sort(function (a, b) { var x = key(a), y = key(b);
      if (typeof x !== typeof y) { return typeof x === 'number' ? -dir : dir; }
      return x < y ? -dir : x > y ? dir : 0; });
    rows.forEach(function (r) { table.tBodies[0].appendChild(r); });
  });
});
</script>"""


def _agreement(r: dict[str, Any]) -> str:
    """A simulated row's verdict at 95%: agrees, or which way the observation misses."""
    if r.get("sim_observed") is None:
        return "-"
    if r["sim_ci_low"] <= r["sim_predicted"] <= r["sim_ci_high"]:
        return "agrees"
    return "observed below" if r["sim_observed"] < r["sim_predicted"] else "observed above"


def _parts_table(rows: Sequence[dict[str, Any]], limit: int) -> str:
    """Every part (at most ``limit``), one row each, sortable by any column."""
    head = [
        "part", "status", "sides", "states", "Bayes actions", "Bayes cost", "Bayes success",
        "engine", "predicted", "observed", "95% interval", "p", "jams", "simulation",
    ]  # fmt: skip
    body = []
    for r in rows[:limit]:
        sim = r.get("sim_observed") is not None
        body.append(
            [
                row_label(r),
                r["status"],
                r.get("sides") if r.get("sides") is not None else "-",
                r.get("states") if r.get("states") is not None else "-",
                r.get("bayes_actions") if r.get("bayes_actions") is not None else "-",
                _num(r.get("bayes_cost")),
                _num(r.get("bayes_probability")),
                r.get("sim_engine") or "-",
                _num(r.get("sim_predicted")) if sim else "-",
                _num(r.get("sim_observed")) if sim else "-",
                f"[{_num(r['sim_ci_low'])}, {_num(r['sim_ci_high'])}]" if sim else "-",
                _num(r.get("sim_p_value"), 3) if sim else "-",
                r.get("sim_jams") if sim and r.get("sim_jams") is not None else "-",
                _agreement(r),
            ]
        )
    return _table(head, body, sortable=True)


def _table(head: Sequence[str], body: Sequence[Sequence[Any]], sortable: bool = False) -> str:
    cells = "".join(f"<th>{html.escape(str(h))}</th>" for h in head)
    cls = " class='sortable'" if sortable else ""
    lines = [f"<table{cls}><thead><tr>{cells}</tr></thead><tbody>"]
    for row in body:
        tds = "".join(
            f"<td>{c}</td>" if str(c).startswith("<svg") else f"<td>{html.escape(str(c))}</td>"
            for c in row
        )
        lines.append(f"<tr>{tds}</tr>")
    return "\n".join([*lines, "</tbody></table>"])


def _fmean_or_none(xs: Sequence[float]) -> float | None:
    """The mean, or ``None`` of no values."""
    return statistics.fmean(xs) if xs else None


def _num(x: float | None, digits: int = 4) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{x:.{digits}g}"


def report_html(
    rows: Sequence[dict[str, Any]],
    metadata: Sequence[dict[str, Any]] = (),
    *,
    limit: int = 50,
    limit_parts: int = 10_000,
) -> str:
    """The report of a results table, as one HTML document.

    Parameters
    ----------
    rows : sequence of dict
        Rows as :func:`~bayesgrasp.sweep.results.read_results` gives them.
    metadata : sequence of dict
        The runs' metadata (:func:`~bayesgrasp.sweep.results.read_metadata`).
    limit : int
        Most parts listed (and drawn) among those where the simulation disagrees, and errors.
    limit_parts : int
        Most parts in the table of every part (the first ones of the results).
    """
    planned = [r for r in rows if r["status"] in ("ok", "no-plan")]
    failed = [r for r in rows if r["status"] == "error"]
    costs = [r["bayes_cost"] for r in planned if r["bayes_cost"] is not None]
    lengths = [r["bayes_actions"] for r in planned if r["bayes_actions"] is not None]
    sims = [r for r in planned if r.get("sim_observed") is not None]
    parts: list[str] = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'><title>bayesgrasp sweep</title>",
        "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
        "td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}</style></head><body>",
        "<h1>bayesgrasp sweep</h1>",
    ]
    if metadata:
        last = metadata[-1]
        parts.append(
            f"<p>bayesgrasp {html.escape(str(last.get('bayesgrasp_version')))}, "
            f"{len(metadata)} run(s), last started {html.escape(str(last.get('started')))}; "
            f"options <code>{html.escape(json.dumps(last.get('options')))}</code></p>"
        )
    summary: list[tuple[str, Any]] = [
        ("parts", len(rows)),
        ("planned", len(planned)),
        ("no guaranteed plan", sum(r["status"] == "no-plan" for r in rows)),
        ("errors", len(failed)),
    ]
    summary += [
        (f"errors: {k}", v) for k, v in Counter(r["error_class"] for r in failed).most_common()
    ]
    if costs:
        summary += [
            ("Bayes cost: mean", _num(statistics.fmean(costs))),
            ("Bayes cost: median", _num(statistics.median(costs))),
            ("Bayes cost: max", _num(max(costs))),
            ("Bayes plan length: mean", _num(statistics.fmean(lengths), 3)),
        ]
    paid = [r for r in planned if r.get("bayes_payoff") is not None]
    if paid:  # rows of a sweep with noise or a payoff: the noise-aware Bayes plans
        noises = Counter(
            ", ".join(f"{k} {r[k]}" for k in ("turn_noise", "contact_noise", "payoff") if r.get(k))
            or "none"
            for r in paid
        )
        summary += [(f"noise: {k}", v) for k, v in noises.most_common()]
        summary.append(
            (
                "Bayes plan expected payoff: mean",
                _num(statistics.fmean(r["bayes_payoff"] for r in paid)),
            )
        )
    sensed = [r for r in planned if r.get("policy_cost") is not None]
    if sensed:  # rows of a sweep with --sense: what reading the jaw width buys
        acts = statistics.fmean(r["policy_actions"] for r in sensed)
        ratio = [r["policy_cost"] / r["bayes_cost"] for r in sensed if r["bayes_cost"]]
        summary += [
            ("sensing policy cost: mean", _num(statistics.fmean(r["policy_cost"] for r in sensed))),
            ("sensing policy actions a cycle: mean", _num(acts, 3)),
            ("sensing policy cost / Bayes plan cost: mean", _num(_fmean_or_none(ratio), 3)),
        ]
    if sims:
        summary += [
            ("simulated parts", len(sims)),
            (_engine_words(sims)[0], len(disagreements(sims))),
        ]
    parts += ["<h2>Summary</h2>", _table(["", ""], summary)]
    if costs:
        parts += [
            "<h2>Bayes plans</h2>",
            _histogram(costs, "expected cost of the Bayes plan"),
            _histogram(lengths, "actions in the Bayes plan", integer=True),
        ]
    if sims:
        parts += ["<h2>Predicted against observed success</h2>", _scatter(sims)]
        bad = disagreements(sims)[:limit]
        if bad:
            parts.append(f"<h2>{html.escape(_engine_words(sims)[1])}</h2>")
            parts.append(
                _table(
                    ["part", "outline", "predicted", "observed", "95% interval", "jams"],
                    [
                        (
                            row_label(r),
                            _outline(r),
                            _num(r["sim_predicted"]),
                            _num(r["sim_observed"]),
                            f"[{_num(r['sim_ci_low'])}, {_num(r['sim_ci_high'])}]",
                            r["sim_jams"],
                        )
                        for r in bad
                    ],
                )
            )
    if rows:
        shown = min(len(rows), limit_parts)
        parts += [
            "<h2>Every part</h2>",
            f"<p>{shown} of {len(rows)} parts; click a column's header to sort by it.</p>",
            _parts_table(rows, limit_parts),
        ]
    if failed:
        parts += [
            "<h2>Parts that failed</h2>",
            _table(
                ["part", "error", "message"],
                [(row_label(r), r["error_class"], r["error_message"]) for r in failed[:limit]],
            ),
        ]
    parts += [_SORT_JS, "</body></html>"]
    return "\n".join(parts)


def write_report(results: str | Path, out: str | Path, *, limit: int = 50) -> Path:
    """Write the HTML report of a results file (Parquet folder or CSV); returns ``out``."""
    path = Path(out)
    text = report_html(read_results(results), read_metadata(results), limit=limit)
    path.write_text(text, encoding="utf-8")
    return path
