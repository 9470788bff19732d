"""
The paper's Table 1 and study
=============================

Goldberg and Mason's Table 1 gives the expected cost of the best plan of 1 to 4 squeezes
for nine parts; their study plans 2000 random polygons. bayesgrasp reproduces both (the
parts are our designs: the paper prints no coordinates).
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

from bayesgrasp.paper.study import run_study, study_table
from bayesgrasp.paper.table1 import table1_rows, table1_text

rows = table1_rows()
print(table1_text(rows))

# %%
# Ours against the printed numbers
# --------------------------------
fig, ax = plt.subplots(figsize=(6, 4))
for row in rows:
    n = min(len(row.costs), len(row.paper.costs))
    ax.scatter(row.paper.costs[:n], row.costs[:n], label=row.part)
lim = [3.5, 11.5]
ax.plot(lim, lim, color="grey", linewidth=0.8)
ax.set_xlabel("the paper's expected cost")
ax.set_ylabel("ours")
ax.set_title("Table 1: best plan of k squeezes")
ax.legend(fontsize=7, ncol=2)
fig.tight_layout()


# %%
# The study, small
# ----------------
# ``bayesgrasp study`` plans 2000 hulls of 10 random points; here 200 (the full study takes
# a few seconds). The paper found a shorter, less certain plan cheaper for 36.9% of them.
result = run_study(polygons=200, seed=1, bfs_stats=False)
print(study_table(result))

# %%
# Plan lengths over the 200 polygons: the Bayes plan is often shorter than the most certain.
fig, ax = plt.subplots(figsize=(6, 3.5))
for label, hist, dx in [
    ("most certain plan", result.plan_length_histogram, -0.2),
    ("Bayes plan", result.bayes_length_histogram, 0.2),
]:
    ks = sorted(hist)
    ax.bar(np.array(ks) + dx, [hist[k] for k in ks], width=0.4, label=label)
ax.set_xlabel("squeezes")
ax.set_ylabel("polygons")
ax.legend()
fig.tight_layout()
