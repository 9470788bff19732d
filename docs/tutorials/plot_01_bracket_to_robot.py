"""
From a DXF bracket to a robot file
==================================

Read a part drawn in CAD, look at how a squeeze moves it, plan the squeezes that orient it
at least expected cost, and write the plan as a file a robot controller can run.
"""

# %%
# The part
# --------
# ``examples/bracket.dxf`` is an L-shaped bracket in millimetres: one polyline with rounded
# corners, two circular holes and a slot. :func:`bayesgrasp.read_part` reads DXF, SVG,
# GeoJSON, WKT, CSV and JSON outlines; circular arcs stay exact.
import math
from pathlib import Path

import matplotlib.pyplot as plt

import bayesgrasp as bg
from bayesgrasp.figures import diameter_figure, part_figure, plan_figure
from bayesgrasp.io.export import robot_csv


def show(fig):
    """Hand a figure drawn by bayesgrasp (without pyplot) to pyplot, so the page shows it."""
    manager = plt.figure().canvas.manager
    manager.canvas.figure = fig
    fig.set_canvas(manager.canvas)


# The repository's root: where this script runs from, or above it (the docs build runs it
# from docs/tutorials).
ROOT = next(
    p for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples" / "bracket.dxf").exists()
)
part = bg.read_part(ROOT / "examples" / "bracket.dxf")
print(part.name, part.units, len(part.hull.vertices), "hull vertices")
problem = bg.Problem.build(part)
show(part_figure(problem))

# %%
# What a squeeze does
# -------------------
# The jaws close and the part turns down its *diameter function* (its width between the
# jaws) to the nearest minimum: a stable orientation. The dotted bars are the probability
# of each stable orientation after one squeeze, when the part may lie any way.
print("stable orientations (deg):", [round(math.degrees(a), 2) for a in problem.states.stable])
show(diameter_figure(problem))

# %%
# The plan
# --------
# :func:`bayesgrasp.plan_exact` gives the best plan of every length; the Bayes plan is the
# one of least expected cost (a check follows each attempt, and the plan repeats until the
# check succeeds).
report = bg.plan_exact(problem)
for option in report.options:
    turns = [round(math.degrees(a), 2) for a in option.alphas]
    print(
        f"{option.n_actions} squeeze(s), turns {turns}: "
        f"P(success) {option.success_probability:.4f}, E[cost] {option.expected_cost:.3f}"
    )
best = report.bayes_plan
print("Bayes plan:", best.n_actions, "squeezes")
show(plan_figure(report))

# %%
# The robot file
# --------------
# One row a step: the gripper's absolute angle (in the frame of the part file), how far the
# jaws must open before closing, and the jaw width to expect after closing. ``bayesgrasp
# plan examples/bracket.dxf --export robot.csv`` writes the same file.
print(robot_csv(problem, best))
