"""
Priors and costs
================

The Bayes plan depends on how the parts arrive (the prior over their initial orientation)
and on what each action costs. A peaked prior or a dear verification changes which plan is
best.
"""

# %%
import math

import matplotlib.pyplot as plt
import numpy as np

import bayesgrasp as bg

part = bg.shapes.load("key")
priors = {
    "uniform": None,
    "von Mises at 30 deg, kappa 4": bg.von_mises(math.radians(30), 4.0),
    "von Mises at 120 deg, kappa 8": bg.von_mises(math.radians(120), 8.0),
}

# %%
# The prior
# ---------
# Under a uniform prior any first gripper angle is as good; under a peaked one the planner
# also chooses the first angle, placing the orientations the plan orients where the prior
# has most mass.
fig, ax = plt.subplots(figsize=(6, 3.5))
for label, prior in priors.items():
    report = bg.plan_exact(bg.Problem.build(part, prior=prior))
    k = [o.n_actions for o in report.options]
    cost = [o.expected_cost for o in report.options]
    ax.plot(k, cost, marker="o", label=label)
    b = report.bayes_plan
    print(
        f"{label}: Bayes plan {b.n_actions} squeeze(s), first at "
        f"{math.degrees(b.first_angle):.2f} deg, P {b.success_probability:.4f}, "
        f"E {b.expected_cost:.3f}"
    )
ax.set_xlabel("squeezes in the plan")
ax.set_ylabel("expected cost")
ax.set_title("The key: best plan of each length under three priors")
ax.legend()
fig.tight_layout()


# %%
# The costs
# ---------
# :class:`bayesgrasp.CostModel` prices each action kind, the verification and an overhead
# paid on each failed attempt (``retry``). A plan of k squeezes and success probability p
# costs ``(first + (k - 1) squeeze + verify) / p + retry (1 / p - 1)``: a dear retry favours
# certain plans. Here the wedge of the user guide: its Bayes plan has 2 squeezes (probability
# 0.41), its most certain plan 3 (probability 0.5).
wedge = bg.Part.from_points([(0, 0), (40, 0), (10, 20)], name="wedge", units="mm")
retries = np.linspace(0, 4, 9)
lengths = []
for retry in retries:
    report = bg.plan_exact(bg.Problem.build(wedge, cost=bg.CostModel(retry=float(retry))))
    lengths.append(report.bayes_plan.n_actions)
    print(
        f"retry cost {retry:.1f}: Bayes plan of {report.bayes_plan.n_actions} squeezes, "
        f"E {report.bayes_plan.expected_cost:.3f}"
    )
fig, ax = plt.subplots(figsize=(6, 3))
ax.step(retries, lengths, where="mid")
ax.set_xlabel("retry cost")
ax.set_ylabel("squeezes in the Bayes plan")
ax.set_title("The wedge: a dear retry makes the certain plan best")
ax.set_yticks(sorted(set(lengths)))
fig.tight_layout()
