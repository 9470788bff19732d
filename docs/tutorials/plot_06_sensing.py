"""
Sensing and recognition
=======================

A parallel-jaw gripper knows its jaw opening after every squeeze: the part's width in the
stable orientation it ended in. A *policy* reads that width and chooses the next action by
it; with several candidate parts it also says which part it holds.
"""

# %%
import matplotlib.pyplot as plt

import bayesgrasp as bg
from bayesgrasp.figures.policy import policy_figure
from bayesgrasp.planning.policy import plan_policy, policy_text


def show(fig):
    """Hand a figure drawn by bayesgrasp (without pyplot) to pyplot, so the page shows it."""
    manager = plt.figure().canvas.manager
    manager.canvas.figure = fig
    fig.set_canvas(manager.canvas)


# %%
# Orienting with the jaw width
# ----------------------------
# The house's sensorless Bayes plan costs 8 actions a part; reading the width after each
# squeeze, the Bayes policy costs about 4.6.
house = bg.Problem.build(bg.shapes.load("house"))
policy = plan_policy(house, "width")
print(policy_text(policy, units="mm"))
print(f"expected cost {policy.expected_cost:.4f}")
show(policy_figure(house, policy))

# %%
# A noisy encoder
# ---------------
# ``width:SIGMA,RES`` reads the width with a normal error of SIGMA and rounds it to RES
# (here in millimetres). The policy gets dearer as the readings get worse.
for sensor in ["width", "width:0.5,0.1", "width:2,0.5", "width:5,1"]:
    print(f"{sensor:14s} expected cost {plan_policy(house, sensor).expected_cost:.4f}")

# %%
# Recognition
# -----------
# The rectangle and the tuning fork are both 20 mm across one way, and the IC chip 19.05 mm:
# one squeeze cannot always tell them apart. The policy turns the gripper by 90 degrees and
# squeezes again when the first reading is ambiguous.
parts = [bg.Problem.build(bg.shapes.load(n)) for n in ("rectangle", "tuning-fork", "ic-chip")]
recognition = plan_policy(parts, "width")
print(policy_text(recognition, units="mm"))
show(policy_figure(parts, recognition))
