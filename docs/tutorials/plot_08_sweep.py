"""
A catalogue sweep on Dask
=========================

``bayesgrasp sweep`` plans (and optionally simulates) every part of a folder on a Dask
cluster and writes one row a part. Here a small run: the part files of ``examples/`` on a
local cluster of one worker process, results in CSV.
"""

# %%
import csv
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

# The repository's root: where this script runs from, or above it (the docs build runs it
# from docs/tutorials).
ROOT = next(
    p for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples" / "bracket.dxf").exists()
)
BAYESGRASP = str(Path(sys.executable).parent / "bayesgrasp")
out_dir = Path(tempfile.mkdtemp())
results = out_dir / "results.csv"

# %%
# The sweep
# ---------
# ``--workers 1`` starts a Dask ``LocalCluster`` of one worker for the run and closes it at
# the end; ``--scheduler ADDRESS`` would use a cluster you started. ``--simulate kinematic``
# adds an execution check of every part's Bayes plan.
cmd = [
    BAYESGRASP,
    "sweep",
    "examples",
    "--out",
    str(results),
    "--workers",
    "1",
    "--simulate",
    "kinematic",
    "--trials",
    "20000",
    "--seed",
    "1",
]
done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
print(done.stdout + done.stderr)

# %%
# The rows
# --------
# One row a part: its states, the Bayes plan's cost, probability and length, the plan
# lengths of the most certain and guaranteed plans, and the simulation's check.
with results.open(newline="") as f:
    every = list(csv.DictReader(f))
# A file the readers cannot plan would be a row with its error (none here).
rows = [r for r in every if r["status"] == "ok"]
print(len(every), "rows,", len(every) - len(rows), "with an error; the first columns:")
print(", ".join(list(every[0])[:16]), "...")
for r in every:
    if r["status"] != "ok":
        print(f"{Path(r['path']).name}: {r['status']}, {r['error_message'][:80]}")
observed = next((c for c in rows[0] if "observed" in c), None)
for r in rows:
    check = f", observed {float(r[observed]):.4f}" if observed and r[observed] else ""
    print(
        f"{r['name']:10s} {r['states']:>3s} states, Bayes plan of {r['bayes_actions']} "
        f"action(s): P {float(r['bayes_probability']):.4f}, E {float(r['bayes_cost']):.3f}" + check
    )

# %%
fig, ax = plt.subplots(figsize=(6, 3))
ax.barh([r["name"] for r in rows], [float(r["bayes_cost"]) for r in rows])
ax.set_xlabel("expected cost of the Bayes plan")
ax.set_title("The example parts")
fig.tight_layout()
