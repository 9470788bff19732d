"""Catalogue sweeps: plan, and check in physics, every part of a catalogue on Dask.

Needs the ``sweep`` extra (``pip install 'bayesgrasp[sweep]'``: Dask distributed and
pyarrow); the core of bayesgrasp never imports this package. Dask is imported only when a
sweep runs, so this package imports without it.

- :mod:`~bayesgrasp.sweep.options`: :class:`SweepOptions`, the options of every part;
- :mod:`~bayesgrasp.sweep.rows`: a row's columns, the part file a task gets, error rows;
- :mod:`~bayesgrasp.sweep.tasks`: the work of one part on a worker (a row, never an
  exception; a mesh, a row per resting pose);
- :mod:`~bayesgrasp.sweep.engine`: :func:`run_sweep`, the Dask driver;
- :mod:`~bayesgrasp.sweep.results`: Parquet and CSV results, appended in batches, resumable;
- :mod:`~bayesgrasp.sweep.report`: an HTML report of a results file.
"""

from .engine import SweepInterrupted, SweepProgress, SweepSummary, find_parts, run_sweep
from .report import write_report
from .results import read_metadata, read_results
from .tasks import PartSource, SweepError, SweepOptions, plan_part

__all__ = [
    "PartSource",
    "SweepError",
    "SweepInterrupted",
    "SweepOptions",
    "SweepProgress",
    "SweepSummary",
    "find_parts",
    "plan_part",
    "read_metadata",
    "read_results",
    "run_sweep",
    "write_report",
]
