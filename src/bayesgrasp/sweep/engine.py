"""The Dask driver of a sweep: find the parts, send them to workers, write the rows.

By default a local cluster of ``workers`` processes (one thread each: planning is Python
and numpy, bound by the GIL) starts on this machine and stops with the sweep; with
``scheduler`` the same sweep runs on an existing Dask cluster (``dask scheduler`` and
``dask worker``, dask-jobqueue, Kubernetes, ...), whose workers need bayesgrasp installed.

The client sends each task a few :class:`~bayesgrasp.sweep.tasks.PartSource` values, paths
(local cluster: the workers share the file system) or paths and bytes (a remote cluster),
never parsed parts; at most a few tasks per worker are in flight, so that a catalogue of
10^5 files is never all in the scheduler's memory. Faults:

- a worker that dies (killed, out of memory) loses only its running task, which the
  scheduler runs again on another worker; a task that kills workers repeatedly
  (``distributed.scheduler.allowed-failures``, default 3) is split into single parts, and
  a single part that still does becomes an error row ``KilledWorker``;
- a part whose work takes longer than ``timeout`` seconds becomes an error row
  ``TimeoutError``, and its worker is restarted (a Python thread cannot be stopped);
- Ctrl-C cancels the tasks, writes the rows received and raises :class:`SweepInterrupted`
  (a ``KeyboardInterrupt``): the results file is complete up to there and resumable.
"""

from __future__ import annotations

import glob
import hashlib
import logging
import math
import os
import time
import uuid
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from ..errors import MissingExtraError
from ..model.prior import parse_prior
from .results import open_results, results_format
from .tasks import PartSource, SweepError, SweepOptions, error_rows, run_chunk

__all__ = [
    "SweepInterrupted",
    "SweepProgress",
    "SweepSummary",
    "find_parts",
    "run_sweep",
    "task_parts",
]

logger = logging.getLogger(__name__)

#: Most parts per task, by simulation engine (None: planning only, a few milliseconds a
#: part). Fewer when the parts are few: :func:`task_parts`.
CHUNK_PARTS: dict[str | None, int] = {None: 64, "kinematic": 2, "mujoco": 1}
#: Tasks per worker :func:`task_parts` aims at: enough that every worker starts at once and
#: a slow task at the end leaves the others little idle time. Physics tasks (seconds a part)
#: are split finer than planning ones (milliseconds).
TASKS_PER_WORKER: dict[str | None, int] = {None: 4, "kinematic": 8, "mujoco": 16}


def task_parts(n_parts: int, n_workers: int, simulate: str | None) -> int:
    """Parts per task: the parts spread over ``TASKS_PER_WORKER`` tasks per worker.

    At most :data:`CHUNK_PARTS` (a task's overhead is then small next to its work), at
    least one.

    Examples
    --------
    >>> task_parts(40, 2, None), task_parts(10_000, 2, None), task_parts(40, 2, "mujoco")
    (5, 64, 1)
    """
    want = math.ceil(n_parts / (max(1, n_workers) * TASKS_PER_WORKER[simulate]))
    return max(1, min(CHUNK_PARTS[simulate], want))


#: Most bytes of part files in one task (a larger file is a task of its own).
CHUNK_BYTES = 1 << 20


@dataclass(frozen=True, slots=True)
class SweepProgress:
    """Where a sweep is: given to the ``progress`` callback after each task.

    Attributes
    ----------
    done : int
        Parts finished in this run (planned or failed).
    failed : int
        Of those, the parts whose row is an error.
    total : int
        Parts to do in this run (found, less those a resumed file already has).
    skipped : int
        Parts skipped because the results file already has their row.
    elapsed : float
        Seconds since the first task was sent.
    """

    done: int
    failed: int
    total: int
    skipped: int
    elapsed: float

    @property
    def rate(self) -> float:
        """Parts a second so far."""
        return self.done / self.elapsed if self.elapsed > 0 else 0.0

    @property
    def eta(self) -> float | None:
        """Seconds left at the rate so far (``None`` before the first part)."""
        return (self.total - self.done) / self.rate if self.rate > 0 else None


@dataclass(frozen=True, slots=True)
class SweepSummary:
    """What a sweep did.

    Attributes
    ----------
    out : Path
    fmt : {"parquet", "csv"}
    found : int
        Part files found.
    skipped : int
        Parts the results already had (resume).
    written : int
        Rows written by this run.
    ok, no_plan, errors : int
        Rows by status (``no_plan``: no guaranteed plan; ``errors``: failed parts).
    timeouts : int
        Of the errors, the parts over the timeout.
    retried : int
        Tasks split and sent again after killing workers.
    workers : int
        Dask workers when the sweep started.
    seconds : float
    interrupted : bool
        Stopped by Ctrl-C (then the rows received were written).
    """

    out: Path
    fmt: str
    found: int
    skipped: int
    written: int
    ok: int
    no_plan: int
    errors: int
    timeouts: int
    retried: int
    workers: int
    seconds: float
    interrupted: bool = False


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep; the rows received are written (``summary`` says how many)."""

    def __init__(self, summary: SweepSummary) -> None:
        super().__init__(f"sweep interrupted after {summary.written} rows")
        self.summary = summary


def _part_files(folder: Path, extensions: Sequence[str]) -> Iterator[Path]:
    """Part files under a folder, recursively, by extension; hidden names skipped."""
    for f in sorted(folder.rglob("*")):
        rel = f.relative_to(folder).parts
        if any(p.startswith(".") for p in rel):
            continue
        if f.is_file() and f.suffix.lstrip(".").lower() in extensions:
            yield f


def find_parts(paths: Sequence[str | Path]) -> list[str]:
    """The part files of a sweep: files, folders (recursively) and globs, each once.

    A folder gives every file with an extension the readers know
    (:data:`bayesgrasp.io.EXTENSIONS`), and so does a glob; a file named explicitly is
    kept whatever its extension (the reader says what is wrong with it), and so is a
    path or a glob that matches nothing (its row says the file is missing).

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> for name in ("a.json", "b/c.DXF", "b/notes.txt"):
    ...     (d / name).parent.mkdir(exist_ok=True)
    ...     _ = (d / name).write_text("{}")
    >>> [Path(p).relative_to(d).as_posix() for p in find_parts([d])]
    ['a.json', 'b/c.DXF']
    """
    from ..io import EXTENSIONS

    out: dict[str, None] = {}
    for spec in paths:
        text = str(spec)
        p = Path(text)
        if p.is_dir():
            out.update(dict.fromkeys(str(f) for f in _part_files(p, tuple(EXTENSIONS))))
        elif glob.has_magic(text) and not p.exists():
            matches = sorted(glob.glob(text, recursive=True))
            for m in matches:
                mp = Path(m)
                if mp.is_dir():
                    out.update(dict.fromkeys(str(f) for f in _part_files(mp, tuple(EXTENSIONS))))
                elif mp.suffix.lstrip(".").lower() in EXTENSIONS:
                    out[m] = None
            if not matches:
                out[text] = None
        else:
            out[text] = None
    return list(out)


def _source(path: str, send_bytes: bool) -> tuple[PartSource, int]:
    """The source of a path and its size; the hash is of the bytes read here."""
    try:
        with open(path, "rb") as f:
            if send_bytes:
                data = f.read()
                return PartSource(path, hashlib.sha256(data).hexdigest(), data), len(data)
            digest = hashlib.file_digest(f, "sha256").hexdigest()
            return PartSource(path, digest), os.fstat(f.fileno()).st_size
    except OSError:
        return PartSource(path), 0  # the worker's reader gives the CLI's message


def _chunks(
    sources: Sequence[tuple[PartSource, int]], parts: int, limit: int = CHUNK_BYTES
) -> list[tuple[PartSource, ...]]:
    """Consecutive parts, at most ``parts`` and ``limit`` bytes a chunk."""
    out: list[tuple[PartSource, ...]] = []
    cur: list[PartSource] = []
    size = 0
    for src, n in sources:
        if cur and (len(cur) >= parts or size + n > limit):
            out.append(tuple(cur))
            cur, size = [], 0
        cur.append(src)
        size += n
    if cur:
        out.append(tuple(cur))
    return out


def _connect(workers: int | None, scheduler: str | None) -> tuple[Any, Any, int]:
    """A client (and the local cluster it owns, or None) and the number of workers."""
    try:
        import distributed
    except ImportError:
        raise MissingExtraError("dask[distributed]", "sweep") from None
    # distributed has no type hints: its classes are used as Any
    Client: Any = distributed.Client
    LocalCluster: Any = distributed.LocalCluster
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=30)
        except OSError as exc:
            raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from None
        try:
            client.wait_for_workers(1, timeout=60)
        except TimeoutError:
            client.close()
            raise SweepError(f"the Dask scheduler at {scheduler} has no workers") from None
        return client, None, len(client.scheduler_info()["workers"])
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        # A part past --timeout restarts its worker: the rows say so, Dask's warnings of
        # lost tasks and restarts are not for the user.
        silence_logs=logging.ERROR,
        # without a dashboard the scheduler still serves /health on 8787, or warns that
        # another cluster has it: any free port will do
        scheduler_kwargs={"dashboard_address": ":0"},
    )
    return Client(cluster), cluster, n


def run_sweep(
    paths: Sequence[str | Path],
    out: Path,
    options: SweepOptions,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    fmt: str = "parquet",
    resume: bool = False,
    force: bool = False,
    timeout: float | None = None,
    progress: Callable[[SweepProgress], None] | None = None,
    send: Literal["auto", "path", "bytes"] = "auto",
    chunk_parts: int | None = None,
    batch_rows: int = 500,
    flush_seconds: float = 5.0,
) -> SweepSummary:
    """Plan (and optionally simulate) every part of a catalogue on Dask; one row a part.

    Parameters
    ----------
    paths : sequence of str or Path
        Part files, folders (searched recursively for every format the readers know) and
        globs (see :func:`find_parts`).
    out : Path
        The results: a Parquet folder or a CSV file (see :mod:`bayesgrasp.sweep.results`).
    options : SweepOptions
        Planning and simulation options, the same for every part.
    workers : int, optional
        Processes of the local cluster (default: the core count). Not with ``scheduler``.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``) to run on instead.
    fmt : {"parquet", "csv"}
    resume : bool
        Keep the rows in ``out`` and skip the parts (same path, bytes and options) they hold.
    force : bool
        Replace an existing ``out``.
    timeout : float, optional
        Seconds a part may take (planning and simulation); over it the part is an error row.
    progress : callable, optional
        ``progress(SweepProgress)`` once at the start and after each task.
    send : {"auto", "path", "bytes"}
        What the client sends: paths (the workers read the files) or the files' bytes;
        ``auto``: paths to a local cluster, bytes to a scheduler.
    chunk_parts : int, optional
        Parts a task (default :func:`task_parts`: the parts spread over 4 tasks per worker
        planning only, 8 kinematic, 16 MuJoCo, and at most 64, 2 and 1 a task).
    batch_rows, flush_seconds : int, float
        Rows are written when ``batch_rows`` have come, or ``flush_seconds`` after the
        last write, and at the end.

    Returns
    -------
    SweepSummary

    Raises
    ------
    SweepError
        Bad settings, no parts found, or ``out`` exists without ``resume`` or ``force``.
    SweepInterrupted
        Ctrl-C (a ``KeyboardInterrupt``): the rows received are written.
    MissingExtraError
        Dask or pyarrow (extra ``sweep``) is missing; MuJoCo (``sim``) for ``mujoco``.
    """
    t0 = time.perf_counter()
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise SweepError(f"`workers` must be an integer >= 1; got {workers!r}")
    if workers is not None and scheduler is not None:
        raise SweepError("give `workers` (a local cluster) or `scheduler`, not both")
    if timeout is not None and not timeout > 0:
        raise SweepError(f"`timeout` must be a number of seconds > 0; got {timeout!r}")
    if send not in ("auto", "path", "bytes"):
        raise SweepError(f"`send` must be 'auto', 'path' or 'bytes'; got {send!r}")
    kind = results_format(Path(out), fmt)
    prior = parse_prior(options.prior)  # once, here: a prior file need not be on the workers
    payoff = None
    if options.payoff is not None:  # the same for a payoff file
        from ..model.payoff import read_payoff

        payoff = read_payoff(options.payoff)
    if options.simulate == "mujoco":
        from ..sim import require_mujoco

        require_mujoco()
    found = find_parts(paths)
    if not found:
        raise SweepError("no part files found in the paths given")
    writer = open_results(Path(out), options, kind, resume=resume, force=force)
    done_keys = writer.done_keys() if resume else set()
    send_bytes = send == "bytes" or (send == "auto" and scheduler is not None)
    todo: list[tuple[PartSource, int]] = []
    for path in found:
        src, size = _source(path, send_bytes)
        if (path, src.sha256, options.key) not in done_keys:
            todo.append((src, size))
    skipped = len(found) - len(todo)
    counts = {"ok": 0, "no-plan": 0, "error": 0, "timeouts": 0, "retried": 0, "written": 0}
    n_workers = 0

    def summary(interrupted: bool = False) -> SweepSummary:
        return SweepSummary(
            Path(out),
            kind,
            len(found),
            skipped,
            counts["written"],
            counts["ok"],
            counts["no-plan"],
            counts["error"],
            counts["timeouts"],
            counts["retried"],
            n_workers,
            time.perf_counter() - t0,
            interrupted,
        )

    if not todo:
        return summary()
    client, cluster, n_workers = _connect(workers, scheduler)
    per_task = chunk_parts or task_parts(len(todo), n_workers, options.simulate)
    queue = deque(_chunks(todo, per_task))
    import distributed
    from distributed.client import FutureCancelledError
    from distributed.scheduler import KilledWorker

    as_completed: Any = distributed.as_completed

    buffer: list[dict[str, Any]] = []
    seen: set[str] = set()  # the paths done
    seen_rows: set[str] = set()
    last_flush = time.monotonic()
    started = time.perf_counter()
    tag = uuid.uuid4().hex[:8]
    running: dict[Any, tuple[PartSource, ...]] = {}
    pending = as_completed()
    window = max(8, 4 * n_workers)
    sent = 0

    def flush() -> None:
        nonlocal last_flush
        writer.write(buffer)
        counts["written"] += len(buffer)
        buffer.clear()
        last_flush = time.monotonic()

    def submit() -> None:
        nonlocal sent
        while queue and len(running) < window:
            chunk = queue.popleft()
            fut = client.submit(
                run_chunk,
                chunk,
                options,
                prior,
                timeout,
                payoff,
                key=f"bayesgrasp-sweep-{tag}-{sent}",
            )
            sent += 1
            running[fut] = chunk
            pending.add(fut)

    def report() -> None:
        if progress is not None:
            done = len(seen)
            progress(
                SweepProgress(
                    done, counts["error"], len(todo), skipped, time.perf_counter() - started
                )
            )

    try:
        report()
        submit()
        for fut in pending:
            chunk = running.pop(fut)
            rows: list[dict[str, Any]]
            try:
                res = fut.result()
            except KilledWorker as exc:
                if len(chunk) > 1:  # find the part that kills workers: one a task
                    counts["retried"] += 1
                    queue.extendleft((s,) for s in reversed(chunk))
                    rows = []
                else:
                    rows = error_rows(chunk, options, exc)
            except FutureCancelledError as exc:
                rows = error_rows(chunk, options, exc)
            except Exception as exc:  # the task itself never raises: a cluster fault
                rows = error_rows(chunk, options, exc)
            else:
                rows = res.rows
                if res.pending:
                    queue.extendleft((s,) for s in reversed(res.pending))
                if res.stuck:
                    counts["timeouts"] += 1
                    _restart(client, res.worker)
            fut.release()
            for row in rows:
                key = row["part_id"]  # a mesh's poses share their path
                if key in seen_rows:  # a task run twice (its worker died after it ended)
                    continue
                seen_rows.add(key)
                seen.add(row["path"])
                buffer.append(row)
                counts[row["status"]] += 1
            if len(buffer) >= batch_rows or time.monotonic() - last_flush >= flush_seconds:
                flush()
            report()
            submit()
        flush()
    except KeyboardInterrupt:
        logger.warning("interrupted: cancelling %d tasks", len(running))
        client.cancel(list(running))
        flush()
        raise SweepInterrupted(summary(True)) from None
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return summary()


def _restart(client: Any, worker: str) -> None:
    """Restart a worker whose thread outlived a timeout (best effort)."""
    if not worker:
        return
    try:
        client.restart_workers([worker])
    except Exception as exc:  # the worker may be gone already; the sweep goes on
        logger.warning("could not restart worker %s after a timeout: %s", worker, exc)
