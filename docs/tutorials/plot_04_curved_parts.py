"""
Curved parts and ``--shape-tol``
================================

Arcs in a DXF or SVG file stay exact: the jaws can rest on a flat edge or, for a curved
outline, where its width is least, but not on the chords a flattened arc would have.
A manufacturing tolerance (``--shape-tol``) removes minima too shallow to trust.
"""

# %%
import subprocess
import sys
from pathlib import Path

import matplotlib.pyplot as plt

import bayesgrasp as bg
from bayesgrasp.figures import diameter_figure, part_figure

# The repository's root: where this script runs from, or above it (the docs build runs it
# from docs/tutorials).
ROOT = next(
    p for p in [Path.cwd(), *Path.cwd().parents] if (p / "examples" / "bracket.dxf").exists()
)
BAYESGRASP = str(Path(sys.executable).parent / "bayesgrasp")


def show(fig):
    """Hand a figure drawn by bayesgrasp (without pyplot) to pyplot, so the page shows it."""
    manager = plt.figure().canvas.manager
    manager.canvas.figure = fig
    fig.set_canvas(manager.canvas)


def run(*args):
    """Run a bayesgrasp command from the repository root and print what it prints."""
    out = subprocess.run([BAYESGRASP, *args], cwd=ROOT, capture_output=True, text=True)
    print(out.stdout + out.stderr)


# %%
# A lever of Bezier curves
# ------------------------
# ``examples/lever.svg`` is drawn with cubic Bezier curves. Flattened into chords it would
# have spurious stable orientations on the chords; kept in exact form it has one per half
# turn, a smooth minimum at 90 degrees where curves touch both jaws.
lever = bg.read_part(ROOT / "examples" / "lever.svg")
problem = bg.Problem.build(lever)
show(part_figure(problem, 1.5707963267948966))
show(diameter_figure(problem))
run("squeeze", "examples/lever.svg")

# %%
# The bracket and a manufacturing tolerance
# -----------------------------------------
# The bracket rests on two shallow flats (marked ``SHALLOW`` and ``FLAT``) besides its long
# diagonal edge. A shape error of 0.5 mm could remove them, so ``--shape-tol 0.5`` keeps
# only the diagonal, and one squeeze orients the bracket up to the gripper's 180-degree
# ambiguity.
run("squeeze", "examples/bracket.dxf")
run("plan", "examples/bracket.dxf", "--shape-tol", "0.5")
