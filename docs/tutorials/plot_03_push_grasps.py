"""
Push-grasps and guaranteed plans
================================

A squeeze cannot tell an orientation from the one 180 degrees away, so no plan of squeezes
orients an asymmetric part more than half the time. A *push-grasp* (one jaw pushes first,
then the jaws squeeze) breaks the tie. And a *guaranteed* plan orients the part from every
start.
"""

# %%
import math

import matplotlib.pyplot as plt
import numpy as np

import bayesgrasp as bg
from bayesgrasp.figures import transfer_figure


def show(fig):
    """Hand a figure drawn by bayesgrasp (without pyplot) to pyplot, so the page shows it."""
    manager = plt.figure().canvas.manager
    manager.canvas.figure = fig
    fig.set_canvas(manager.canvas)


part = bg.shapes.load("house")

# %%
# The transfer functions
# ----------------------
# The squeeze function has period 180 degrees; the push-grasp function, which turns the part
# about its centre of mass, has period 360 degrees.
mixed = bg.Problem.build(part, actions=("squeeze", "push-grasp"))
show(transfer_figure(mixed))

# %%
# Plans with and without push-grasps
# ----------------------------------
squeezes = bg.Problem.build(part)
fig, ax = plt.subplots(figsize=(6, 3.5))
for label, problem in [("squeezes only", squeezes), ("squeezes and push-grasps", mixed)]:
    report = bg.plan_exact(problem)
    ks = [o.n_actions for o in report.options]
    ax.plot(ks, [o.success_probability for o in report.options], marker="o", label=label)
    b = report.bayes_plan
    print(
        f"{label}: Bayes plan {[s.kind for s in b.steps]}, "
        f"P {b.success_probability:.4f}, E {b.expected_cost:.3f}"
    )
ax.set_xlabel("actions in the plan")
ax.set_ylabel("P(success)")
ax.set_title("The house")
ax.legend()
fig.tight_layout()


# %%
# Guaranteed plans
# ----------------
# :func:`bayesgrasp.plan_guaranteed` gives the shortest plan that sends every orientation
# to one orientation, up to the period of the actions: 180 degrees with squeezes alone,
# 360 degrees with push-grasps.
for label, problem in [("squeezes only", squeezes), ("squeezes and push-grasps", mixed)]:
    o = bg.plan_guaranteed(problem).option
    steps = ", ".join(f"{s.kind} {math.degrees(s.alpha):+.2f}" for s in o.steps)
    print(
        f"{label}: {o.n_actions} actions ({steps}); from every start to "
        f"{math.degrees(o.final_orientation):.2f} deg, tolerance {math.degrees(o.tolerance):.3f} deg"
    )

# %%
# Replay the mixed guaranteed plan (its first action at any gripper angle) from 3600 starts: every one ends at the same orientation.
g = bg.plan_guaranteed(mixed)
starts = np.linspace(0, 2 * np.pi, 3600, endpoint=False) + 1e-3
final = bg.execute_plan(mixed, g.option.steps, starts)
print(
    "distinct final orientations (deg):", sorted({round(math.degrees(f) % 360, 3) for f in final})
)
