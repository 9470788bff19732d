"""Figures and animations of parts, their functions and plans (optional extra ``plot``).

Every function returns a matplotlib :class:`~matplotlib.figure.Figure` drawn on the Agg
canvas (no window, no global pyplot state), so it is safe in scripts, servers and tests;
save it with ``fig.savefig(path)`` (the format follows the extension). People see degrees on
every angle axis; titles say what the figure shows. Artists that carry data have a ``gid``
(``"hull"``, ``"chord"``, ``"minima"``, ``"histogram"``, ...) so that tests and users can
find them. Figures take a :class:`~bayesgrasp.model.problem.Problem` (or what a planner
returned) and read the model it holds; a bare part is built into a problem once.

- :func:`part_figure` (a, :mod:`.part`): the part, its convex hull, the antipodal chord that
  touches the jaws, and the jaws.
- :func:`diameter_figure` (b, :mod:`.functions`): the diameter function over ``[0, 180)``
  degrees with its maxima and minima, and the distribution after the first action (the
  seed's Fig. 3).
- :func:`transfer_figure` (c, :mod:`.functions`): the transfer function of every action.
- :func:`evolution_figure` (d, :mod:`.plans`): the distribution over orientations before and
  after each step of a plan (the seed's Fig. 1).
- :func:`plan_figure` (:mod:`.plans`): (a), (b) and (d) together, for ``plan --plot``.
- :func:`plan_animation` (e, :mod:`.animation`): a plan executed kinematically from several
  initial orientations; :func:`save_animation` writes a GIF (and an MP4 when ffmpeg is
  present).
- :func:`write_figures` (:mod:`.files`): all of them into a folder, for ``bayesgrasp plot``.

Matplotlib (and pillow, for GIFs) are the optional extra ``plot``
(``pip install 'bayesgrasp[plot]'``); they are imported only inside the functions that
draw, which raise :class:`~bayesgrasp.errors.MissingExtraError` without them.
"""

from .animation import PlanAnimation, plan_animation, save_animation
from .files import write_figures
from .functions import diameter_figure, transfer_figure
from .part import part_figure
from .plans import evolution_figure, plan_figure, step_distributions

__all__ = [
    "PlanAnimation",
    "diameter_figure",
    "evolution_figure",
    "part_figure",
    "plan_animation",
    "plan_figure",
    "save_animation",
    "step_distributions",
    "transfer_figure",
    "write_figures",
]
