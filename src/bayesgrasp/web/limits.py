"""The server's limits: what one request may ask, and the worker processes it has.

:class:`Limits` is given to :func:`~bayesgrasp.web.app.create_app` (``bayesgrasp serve``'s
options); :func:`limits_document` is what ``GET /api/v1/limits`` answers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Limits", "engines", "limits_document"]


@dataclass(frozen=True, slots=True)
class Limits:
    """What one request may ask of the server, and the server's workers.

    Attributes
    ----------
    max_body_bytes : int
        Largest request body (larger: 413).
    max_vertices : int
        Most vertices (or outline points) of a part (more: 422).
    time_limit : float
        Seconds a request's work may take, waiting in the queue included (then its worker
        is killed and the answer is a 503). A request may ask for less (``?timeout=S``).
    max_trials : int
        Most kinematic simulation trials a request may ask for (more: 422).
    workers : int
        Worker processes of the heavy lane: policies, noise-aware plans, simulations and
        simulation jobs.
    quick_workers : int
        Worker processes of the quick lane: squeeze and push functions, plans.
    figure_workers : int
        Worker processes drawing figures (about a second each; apart, so that the quick
        lane stays quick).
    queue : int
        Requests that may wait for a worker, in each lane (more: 503 at once).
    worker_memory : int or None
        Memory a worker may take beyond its libraries, MB (``RLIMIT_AS``; more: 503 and the
        worker is replaced). ``None``: no cap.
    gallery_rows : int
        Rows the gallery keeps.
    job_time_limit : float
        Seconds a simulation job may take (then it is stopped and marked failed).
    max_jobs : int
        Simulation jobs kept (queued, running or finished; the oldest finished go first).
    max_mujoco_trials : int
        Most MuJoCo trials a job may ask for (more: 422).
    """

    max_body_bytes: int = 1_000_000
    max_vertices: int = 2000
    time_limit: float = 10.0
    max_trials: int = 1_000_000
    workers: int = 2
    quick_workers: int = 2
    figure_workers: int = 1
    queue: int = 16
    worker_memory: int | None = 2048
    gallery_rows: int = 500
    job_time_limit: float = 600.0
    max_jobs: int = 100
    max_mujoco_trials: int = 2000

    def __post_init__(self) -> None:
        counts = {
            "workers": self.workers,
            "quick_workers": self.quick_workers,
            "figure_workers": self.figure_workers,
            "max_jobs": self.max_jobs,
        }
        for name, value in counts.items():
            if value < 1:
                raise ValueError(f"Limits.{name} must be at least 1; got {value}")
        if self.queue < 0:
            raise ValueError(f"Limits.queue must be at least 0; got {self.queue}")
        if not (self.time_limit > 0 and self.job_time_limit > 0):
            raise ValueError("Limits.time_limit and Limits.job_time_limit must be positive")
        if self.worker_memory is not None and self.worker_memory < 1:
            raise ValueError(
                f"Limits.worker_memory must be at least 1 MB or None; got {self.worker_memory}"
            )


def engines() -> list[str]:
    """The simulation engines this server runs: kinematic, and MuJoCo where it is installed."""
    import importlib.util

    return ["kinematic"] + (["mujoco"] if importlib.util.find_spec("mujoco") else [])


def limits_document(lim: Limits) -> dict[str, Any]:
    """The limits a request must keep to, as ``GET /api/v1/limits`` answers them.

    Examples
    --------
    >>> limits_document(Limits(max_vertices=500))["max_vertices"]
    500
    """
    return {
        "max_body_bytes": lim.max_body_bytes,
        "max_vertices": lim.max_vertices,
        "time_limit_s": lim.time_limit,
        "max_trials": lim.max_trials,
        "workers": lim.workers,
        "quick_workers": lim.quick_workers,
        "figure_workers": lim.figure_workers,
        "queue": lim.queue,
        "worker_memory_mb": lim.worker_memory,
        "job_time_limit_s": lim.job_time_limit,
        "max_jobs": lim.max_jobs,
        "max_mujoco_trials": lim.max_mujoco_trials,
        "engines": engines(),
    }
