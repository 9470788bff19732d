"""
Simulation: the kinematic model and MuJoCo
==========================================

Run a plan many times and compare where the part ends with what the planner predicts:
first in the kinematic model (the transfer functions, with the gripper's noise drawn), then
in the MuJoCo physics engine, which knows none of the formulas.
"""

# %%
import json
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt

# The repository's root: where this script runs from, or above it (the docs build runs it
# from docs/tutorials).
ROOT = next(
    p for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples" / "bracket.dxf").exists()
)
BAYESGRASP = str(Path(sys.executable).parent / "bayesgrasp")


def run(*args):
    """Run a bayesgrasp command from the repository root; print its text, return its output."""
    out = subprocess.run([BAYESGRASP, *args], cwd=ROOT, capture_output=True, text=True)
    return out.stdout + out.stderr


# %%
# The kinematic model
# -------------------
# A million executions take a fraction of a second. The predicted column is exact; the
# verdict says whether the prediction lies within the observed interval.
print(run("simulate", "example", "--trials", "200000", "--seed", "1"))

# %%
# With the gripper's noise
# ------------------------
# Under a turn error, ``simulate`` predicts the plan exactly under the noise and draws the
# noise into every trial. Without ``--plan`` it runs the noise-aware plan.
print(run("simulate", "key", "--turn-noise", "uniform:2", "--trials", "200000", "--seed", "1"))

# %%
# Predicted against observed, per final orientation
# -------------------------------------------------
doc = json.loads(run("simulate", "example", "--trials", "20000", "--seed", "1", "--json"))
rows = doc["per_orientation"]
labels = [f"{r['orientation_rad'] * 57.29577951308232:.1f}" for r in rows]
x = range(len(rows))
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.bar([i - 0.2 for i in x], [r["predicted"] for r in rows], width=0.4, label="predicted")
ax.bar([i + 0.2 for i in x], [r["observed"] for r in rows], width=0.4, label="observed")
ax.set_xticks(list(x), labels)
ax.set_xlabel("final orientation (deg)")
ax.set_ylabel("probability")
ax.set_title("The example part's Bayes plan, kinematic model")
ax.legend()
fig.tight_layout()


# %%
# MuJoCo
# ------
# ``--engine mujoco`` lays the part (its hull extruded into a prism) on a table with
# friction, closes two frictionless jaws on it and reads where it ends. It takes a few
# hundredths of a second a squeeze, so here only 20 trials (a real check takes a few
# hundred; ``--workers`` runs them in parallel). It needs the ``sim`` extra.
try:
    import mujoco  # noqa: F401
except ImportError:
    print("MuJoCo is not installed: pip install 'bayesgrasp[sim]'")
else:
    print(run("simulate", "example", "--engine", "mujoco", "--trials", "20", "--seed", "1"))
