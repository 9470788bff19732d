"""Simulation jobs of ``bayesgrasp serve``: queued, run in a worker, polled for progress.

A job is started by ``POST /api/v1/simulate/jobs`` (202 and the job's id) and read by
``GET /api/v1/simulate/jobs/{id}``: its status (``queued``, ``running``, ``done``,
``failed``), the trials done so far and, when done, the document ``bayesgrasp simulate
--json`` prints. Jobs run in the server's heavy lane under their own time limit; the store
keeps a bounded number of them, dropping the oldest finished first.
"""

from __future__ import annotations

import asyncio
import secrets
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field
from typing import Any, Literal

from .workers import LimitError, failure_of

__all__ = ["Job", "Jobs"]

Status = Literal["queued", "running", "done", "failed"]


@dataclass(eq=False)
class Job:
    """One simulation job: its status, progress and result (or error)."""

    id: str
    total: int
    status: Status = "queued"
    done: int = 0
    result: dict[str, Any] | None = None
    error: dict[str, Any] | None = None
    created: float = field(default_factory=time.time)
    started: float | None = None
    finished: float | None = None

    def start(self) -> None:
        """Mark the job running (a worker took it)."""
        self.status = "running"
        self.started = time.time()

    def tick(self, done: int, total: int) -> None:
        """Record the trials done."""
        self.done, self.total = done, total

    def document(self) -> dict[str, Any]:
        """The job as ``GET /simulate/jobs/{id}`` answers it.

        Examples
        --------
        >>> job = Job("abc", total=200)
        >>> job.tick(50, 200)
        >>> d = job.document()
        >>> d["status"], d["progress"]
        ('queued', {'done': 50, 'total': 200, 'fraction': 0.25})
        """
        fraction = self.done / self.total if self.total else 0.0
        return {
            "schema": "bayesgrasp.job/1",
            "id": self.id,
            "status": self.status,
            "progress": {"done": self.done, "total": self.total, "fraction": round(fraction, 4)},
            "created": self.created,
            "started": self.started,
            "finished": self.finished,
            "result": self.result,
            "error": self.error,
        }


class Jobs:
    """A bounded store of jobs, each run as a task on the server's event loop.

    Parameters
    ----------
    max_jobs : int
        Jobs kept; when full, the oldest finished one goes (none finished: 503).
    """

    def __init__(self, max_jobs: int) -> None:
        self.max_jobs = max_jobs
        self.jobs: dict[str, Job] = {}
        self.tasks: set[asyncio.Task[None]] = set()

    def get(self, job_id: str) -> Job | None:
        """The job ``job_id``, if kept."""
        return self.jobs.get(job_id)

    def submit(
        self,
        total: int,
        run: Callable[[Job], Awaitable[dict[str, Any]]],
    ) -> Job:
        """A new job whose work is ``run(job)`` (which calls ``job.start`` and ``job.tick``)."""
        if len(self.jobs) >= self.max_jobs:
            finished = [j for j in self.jobs.values() if j.status in ("done", "failed")]
            if not finished:
                raise LimitError(
                    503,
                    f"the server holds {len(self.jobs)} unfinished jobs (the limit is "
                    f"{self.max_jobs}); try again later",
                    kind="queue-full",
                    retry_after=30,
                )
            del self.jobs[min(finished, key=lambda j: j.created).id]
        job = Job(secrets.token_hex(8), total)
        self.jobs[job.id] = job

        async def go() -> None:
            try:
                job.result = await run(job)
                job.done = job.total
                job.status = "done"
            except asyncio.CancelledError:  # the server stops: the job ends, failed
                job.error = {"status": 503, "error": "worker-stopped", "detail": "cancelled"}
                job.status = "failed"
                raise
            except Exception as exc:
                status, kind, reason = failure_of(exc)
                job.error = {"status": status, "error": kind, "detail": reason}
                job.status = "failed"
            finally:
                job.finished = time.time()

        task = asyncio.get_running_loop().create_task(go())
        self.tasks.add(task)
        task.add_done_callback(self.tasks.discard)
        return job

    def cancel_all(self) -> None:
        """Cancel the running jobs (the server stops)."""
        for task in list(self.tasks):
            task.cancel()
