"""
Noise and payoffs
=================

A real gripper turns a little off the commanded angle, and its jaws may not touch at once.
:func:`~bayesgrasp.planning.noisy.plan_noisy` plans under such noise, exactly, and a payoff
says which final orientations are worth how much.
"""

# %%
import math

import matplotlib.pyplot as plt

import bayesgrasp as bg
from bayesgrasp.figures.plans import noisy_plan_figure
from bayesgrasp.model.noise import NoiseModel, TurnNoise
from bayesgrasp.planning.noisy import evaluate_plan, plan_noisy


def show(fig):
    """Hand a figure drawn by bayesgrasp (without pyplot) to pyplot, so the page shows it."""
    manager = plt.figure().canvas.manager
    manager.canvas.figure = fig
    fig.set_canvas(manager.canvas)


part = bg.shapes.load("key")
problem = bg.Problem.build(part)
fragile = bg.plan_exact(problem).bayes_plan
robust = bg.plan_exact(bg.Problem.build(part, accuracy=math.radians(2))).bayes_plan
print(f"noise-free Bayes plan: tolerance {math.degrees(fragile.tolerance):.3f} deg")
print(f"--accuracy 2 plan:     tolerance {math.degrees(robust.tolerance):.3f} deg")

# %%
# The same plans under a turn error
# ---------------------------------
# Under a uniform error of up to 2 degrees on every turn, the noise-free plan's 0.8 degrees
# of tolerance are not enough. The noise-aware plan keeps what it orients away from the basin
# boundary the error would cross.
noise = NoiseModel(TurnNoise("uniform", math.radians(2)), 0.0)
aware = plan_noisy(problem, noise)
for label, steps in [
    ("noise-free", fragile.steps),
    ("--accuracy 2", robust.steps),
    ("noise-aware", aware.bayes_plan.option.steps),
]:
    ev = evaluate_plan(problem, noise, steps)
    print(
        f"{label:12s} turns {[round(math.degrees(s.alpha), 2) for s in steps[1:]]}: "
        f"P(success) under the noise {ev.success_probability:.4f}"
    )
show(noisy_plan_figure(aware))

# %%
# Success against the size of the error
# -------------------------------------
sizes = [0.0, 0.5, 1.0, 2.0, 4.0, 8.0]
fig, ax = plt.subplots(figsize=(6, 3.5))
for label, steps in [("noise-free Bayes plan", fragile.steps), ("--accuracy 2 plan", robust.steps)]:
    p = [
        evaluate_plan(
            problem, NoiseModel(TurnNoise("normal", math.radians(s)), 0.0), steps
        ).success_probability
        for s in sizes
    ]
    ax.plot(sizes, p, marker="o", label=label)
ax.set_xlabel("normal turn error, sigma (deg)")
ax.set_ylabel("P(success), exact")
ax.set_title("The key's two-squeeze plans")
ax.legend()
fig.tight_layout()


# %%
# A payoff
# --------
# Some final orientations may be worth more than others (a better grasp, say). With a payoff
# the planner minimises the expected cost per unit payoff.
import numpy as np

from bayesgrasp.model.payoff import Payoff

payoff = Payoff(np.radians([80.63, 260.63, 101.56, 281.56]), [1.0, 0.6, 0.9, 0.9])
normal = NoiseModel(TurnNoise("normal", math.radians(2)), 0.0)
result = plan_noisy(problem, normal, payoff)
for o in result.options:
    e = o.evaluation
    print(
        f"{o.option.n_actions} squeeze(s): E[payoff] {e.expected_payoff:.4f}, "
        f"cost per unit payoff {e.expected_cost:.3f}"
    )
b = result.bayes_plan.option
print(
    f"Bayes plan: {b.n_actions} squeeze(s), ending at {math.degrees(b.final_orientation):.2f} deg"
)
