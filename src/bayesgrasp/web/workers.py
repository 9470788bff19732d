"""Worker processes for the server's planning: stopped at a time limit, memory capped.

A :class:`Lane` is a set of worker processes with a bounded queue in front of it. A piece of
work (a module-level function and its arguments, pickled) runs in one worker; the server's
event loop only waits for the answer, so a slow piece of work never delays a light request.
When the work takes longer than its time limit the worker is killed (``SIGKILL``), reaped off
the event loop and replaced; its memory goes back to the system. Each worker's address space
is capped (``resource.setrlimit(RLIMIT_AS)``): work that reaches the cap ends with a
:class:`LimitError` naming it, and the worker is replaced. A worker whose resident memory
grew by more than :attr:`Lane.recycle_mb` during a piece of work is replaced too, so the
server's memory returns to its level after heavy requests end.

Workers are forked from a server process (``multiprocessing``'s *forkserver*) that has
imported the planning code already, so a new worker starts in tens of milliseconds and no
request pays for the imports; it runs with one BLAS thread, and a lane's workers can be
niced, so that the heavy lane leaves the processor to the light one.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import math
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Lane", "LimitError", "failure_of", "start_forkserver"]

#: Modules the forkserver imports once, so that workers forked from it start ready.
PRELOAD = (
    "numpy",
    "bayesgrasp.web.app",
    "bayesgrasp.web.documents",
    "bayesgrasp.runs.specs",
    "bayesgrasp.runs.noisy",
    "bayesgrasp.io.plans",
    "bayesgrasp.io.policies",
    "bayesgrasp.report",
    "bayesgrasp.planning.policy",
    "bayesgrasp.planning.noisy",
    "bayesgrasp.planning.noisy_policy",
    "bayesgrasp.sim.kinematic",
    "bayesgrasp.shapes",
    "bayesgrasp.geometry.curved",
    "bayesgrasp.io",
    "bayesgrasp.figures.plots",
)
_ONE_THREAD = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
_forkserver_lock = threading.Lock()


class LimitError(Exception):
    """A request over one of the server's limits: its HTTP status, reason and kind.

    Examples
    --------
    >>> e = LimitError(503, "the queue is full", kind="queue-full", retry_after=10)
    >>> e.status, str(e), e.kind, e.retry_after
    (503, 'the queue is full', 'queue-full', 10)
    """

    def __init__(
        self, status: int, message: str, kind: str | None = None, retry_after: int | None = None
    ) -> None:
        super().__init__(message)
        self.status = status
        self.kind = kind or {413: "too-large", 422: "limit", 503: "unavailable"}.get(
            status, "limit"
        )
        self.retry_after = retry_after

    def __reduce__(self) -> Any:  # picklable with its members (workers send it back)
        return (LimitError, (self.status, str(self), self.kind, self.retry_after))


def failure_of(exc: BaseException) -> tuple[int, str, str]:
    """The HTTP status, kind and one-line reason of an exception raised by a piece of work.

    Examples
    --------
    >>> from bayesgrasp.errors import PartError
    >>> failure_of(PartError("the part has fewer than 3 vertices"))
    (422, 'PartError', 'the part has fewer than 3 vertices')
    >>> failure_of(LimitError(422, "the limit is 2000"))
    (422, 'limit', 'the limit is 2000')
    """
    from ..errors import BayesGraspError, NoPlanError

    if isinstance(exc, LimitError):
        return exc.status, exc.kind, str(exc)
    if isinstance(exc, NoPlanError):
        return 422, "no-plan", f"no plan: {exc}"
    if isinstance(exc, BayesGraspError):
        return 422, type(exc).__name__, str(exc)
    return 500, "internal", f"internal error: {type(exc).__name__}: {exc}"


def start_forkserver(preload: tuple[str, ...] = PRELOAD) -> None:
    """Start the forkserver with ``preload`` imported and one BLAS thread (idempotent)."""
    if sys.platform == "win32":  # pragma: no cover - no forkserver there
        return
    from multiprocessing import forkserver

    with _forkserver_lock:
        saved = {k: os.environ.get(k) for k in _ONE_THREAD}
        try:
            for k in _ONE_THREAD:
                os.environ[k] = "1"
            multiprocessing.set_forkserver_preload(list(preload))
            forkserver.ensure_running()
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v


def _statm() -> tuple[int, int]:
    """The address space and resident memory of this process, bytes (Linux; else zeros)."""
    try:
        with open("/proc/self/statm", encoding="ascii") as f:
            size, resident = f.read().split()[:2]
    except OSError:  # pragma: no cover - not Linux
        return 0, 0
    page = os.sysconf("SC_PAGE_SIZE")
    return int(size) * page, int(resident) * page


def _worker_main(conn: Any, memory_mb: int | None, nice: int) -> None:
    """A worker: receive ``(function, args, kwargs)``, send the answer; until the pipe closes.

    Answers: ``("ok", value, rss_bytes)``, ``("fail", status, kind, reason)`` or, while the
    work runs, ``("progress", done, total)``.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the server's to handle
    if nice:
        with contextlib.suppress(OSError):
            os.nice(nice)
    if memory_mb is not None:
        import resource

        size, _ = _statm()
        cap = size + memory_mb * 2**20
        _, hard = resource.getrlimit(resource.RLIMIT_AS)
        if hard != resource.RLIM_INFINITY:
            cap = min(cap, hard)
        resource.setrlimit(resource.RLIMIT_AS, (cap, hard))

    def progress(done: int, total: int) -> None:
        conn.send(("progress", int(done), int(total)))

    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        fn, args, kwargs = message
        if kwargs.pop("_progress", False):
            kwargs["progress"] = progress
        try:
            value = fn(*args, **kwargs)
            conn.send(("ok", value, _statm()[1]))
        except MemoryError:
            reason = (
                f"the work reached the worker's memory limit of {memory_mb} MB and was "
                "stopped; ask for less (a smaller max_actions, a coarser sensor, fewer parts)"
            )
            with contextlib.suppress(Exception):
                conn.send(("fail", 503, "memory-limit", reason))
            os._exit(3)  # a fresh worker replaces this one
        except Exception as exc:
            status, kind, reason = failure_of(exc)
            if status >= 500:
                traceback.print_exc(file=sys.stderr)
            conn.send(("fail", status, kind, reason))


@dataclass(eq=False)
class _Worker:
    process: Any
    conn: Any
    rss: int = 0  # resident memory after its start or its last piece of work


@dataclass(eq=False)
class Lane:
    """Worker processes with a bounded queue: :meth:`run` a piece of work in one of them.

    Parameters
    ----------
    name : str
        Named in messages (``"plans"``, ``"heavy"``).
    size : int
        Most worker processes (started when work comes, kept while idle).
    queue : int
        Most pieces of work waiting for a worker (more: 503 at once).
    memory_mb : int or None
        The memory a worker may take beyond its size at start (its libraries), MB
        (``None``: no cap).
    nice : int
        Niceness of the workers (``os.nice``; 0: the server's priority).
    recycle_mb : int
        A worker whose resident memory grew more than this during a piece of work is
        replaced, so that memory freed by the work goes back to the system.

    Examples
    --------
    >>> import asyncio, math
    >>> lane = Lane("demo", size=1, queue=2, memory_mb=None)
    >>> asyncio.run(lane.run(math.hypot, (3.0, 4.0), timeout=30))
    5.0
    >>> lane.close()
    """

    name: str
    size: int
    queue: int
    memory_mb: int | None = None
    nice: int = 0
    recycle_mb: int = 150
    idle: list[_Worker] = field(default_factory=list)
    live: int = 0
    waiting: collections.deque[asyncio.Future[_Worker]] = field(default_factory=collections.deque)
    killed: int = 0
    replaced: int = 0
    closed: bool = False

    def __post_init__(self) -> None:
        if self.size < 1 or self.queue < 0:
            raise ValueError(
                f"a lane needs size >= 1 and queue >= 0; got {self.size}, {self.queue}"
            )
        # threads that wait on the workers' pipes and reap killed workers, off the event loop
        self._threads = ThreadPoolExecutor(2 * self.size + 2, thread_name_prefix=f"bg-{self.name}")
        self._lock = threading.Lock()
        self._workers: set[_Worker] = set()  # every worker started and not yet forgotten

    # -- state ---------------------------------------------------------------------------

    def status(self) -> dict[str, Any]:
        """Workers at work, idle and starting; work waiting; workers killed and replaced."""
        return {
            "workers": self.size,
            "live": self.live,
            "idle": len(self.idle),
            "waiting": len(self.waiting),
            "queue": self.queue,
            "memory_mb": self.memory_mb,
            "killed": self.killed,
            "replaced": self.replaced,
        }

    def full(self) -> bool:
        """Whether new work would be refused now (every worker busy and the queue full)."""
        return not self.idle and self.live >= self.size and len(self.waiting) >= self.queue

    async def prestart(self) -> None:
        """Start every worker now (off the event loop), so that no request waits for one."""
        loop = asyncio.get_running_loop()
        while self.live < self.size and not self.closed:
            self.live += 1
            try:
                worker = await loop.run_in_executor(self._threads, self._spawn)
            except BaseException:
                self.live -= 1
                raise
            self._release(worker)

    # -- running work --------------------------------------------------------------------

    async def run(
        self,
        fn: Callable[..., Any],
        args: tuple[Any, ...],
        timeout: float,
        progress: Callable[[int, int], None] | None = None,
        on_start: Callable[[], None] | None = None,
        **kwargs: Any,
    ) -> Any:
        """``fn(*args, **kwargs)`` in a worker, within ``timeout`` seconds from now.

        ``fn`` must be a module-level function (it is pickled by name) and the arguments and
        the answer picklable. With ``progress``, ``fn`` is called with a ``progress(done,
        total)`` keyword argument whose calls reach ``progress`` here; ``on_start()`` is
        called when a worker takes the work.

        Raises
        ------
        LimitError
            503: the queue is full, the time limit passed (the worker is killed) or the
            worker's memory cap was reached; or the status of the work's own error.
        """
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        code: int | None = None
        worker = await self._acquire(deadline, timeout)
        if on_start is not None:
            on_start()
        message: Any = (fn, args, {**kwargs, "_progress": progress is not None})
        answer = loop.run_in_executor(
            self._threads, self._exchange, worker, message, progress, loop
        )
        try:
            reply = await asyncio.wait_for(asyncio.shield(answer), max(0.0, deadline - loop.time()))
        except TimeoutError:
            self._kill(worker)
            raise LimitError(
                503,
                f"the work timed out after {timeout:g} s (the time limit of {timeout:g} s) "
                "and was stopped; ask for less (a smaller max_actions, method exact, fewer "
                "trials)",
                kind="timeout",
                retry_after=_retry(timeout),
            ) from None
        except asyncio.CancelledError:  # the client went away: the worker is stopped
            self._kill(worker)
            raise
        if reply[0] == "ok":
            grown = reply[2] - worker.rss > self.recycle_mb * 2**20
            if grown:
                self._kill(worker, replaced=True)
            else:
                self._release(worker)
            return reply[1]
        if reply[0] == "fail":
            _, status, kind, reason = reply
            if kind == "memory-limit":
                self._forget(worker, replaced=True)
                raise LimitError(status, reason, kind, retry_after=_retry(timeout))
            self._release(worker)
            raise LimitError(status, reason, kind)
        # the worker died without an answer (a crash, or its memory cap hit in C code)
        with contextlib.suppress(ValueError):
            code = worker.process.exitcode  # before the reaper closes the process object
        self._forget(worker, replaced=True)
        raise LimitError(
            503,
            f"the worker stopped during the work (exit code {code}); it may have reached its "
            f"memory limit of {self.memory_mb} MB: ask for less",
            kind="memory-limit" if self.memory_mb is not None else "worker-stopped",
            retry_after=_retry(timeout),
        )

    def _exchange(
        self,
        worker: _Worker,
        message: Any,
        progress: Callable[[int, int], None] | None,
        loop: asyncio.AbstractEventLoop,
    ) -> Any:
        """Send the work and wait for its answer (in a thread; a killed worker ends it)."""
        try:
            worker.conn.send(message)
            while True:
                reply = worker.conn.recv()
                if reply[0] != "progress":
                    return reply
                if progress is not None:
                    loop.call_soon_threadsafe(progress, reply[1], reply[2])
        except (EOFError, OSError):
            with contextlib.suppress(Exception):
                worker.process.join(5)
            return ("died",)

    async def _acquire(self, deadline: float, timeout: float) -> _Worker:
        if self.closed:
            raise LimitError(503, "the server is stopping", kind="stopping", retry_after=5)
        if self.idle:
            return self.idle.pop()
        if self.live < self.size:
            self.live += 1
            try:
                return await asyncio.get_running_loop().run_in_executor(self._threads, self._spawn)
            except BaseException:
                self.live -= 1
                raise
        if len(self.waiting) >= self.queue:
            raise LimitError(
                503,
                f"the queue is full: {self.size} worker(s) of the {self.name} lane at work and "
                f"{len(self.waiting)} request(s) waiting (the limit is {self.queue}); try again "
                "later",
                kind="queue-full",
                retry_after=_retry(timeout),
            )
        loop = asyncio.get_running_loop()
        wait: asyncio.Future[_Worker] = loop.create_future()
        self.waiting.append(wait)
        try:
            return await asyncio.wait_for(asyncio.shield(wait), max(0.0, deadline - loop.time()))
        except (TimeoutError, asyncio.CancelledError) as exc:
            with contextlib.suppress(ValueError):
                self.waiting.remove(wait)
            if wait.done() and not wait.cancelled() and wait.exception() is None:
                self._release(wait.result())  # handed over as the wait ended: pass it on
            if isinstance(exc, asyncio.CancelledError):
                raise
            raise LimitError(
                503,
                f"the work timed out after {timeout:g} s (the time limit of {timeout:g} s) "
                f"waiting in the queue of the {self.name} lane; try again later",
                kind="timeout",
                retry_after=_retry(timeout),
            ) from None

    def _spawn(self) -> _Worker:
        ctx: Any = multiprocessing.get_context("forkserver" if sys.platform != "win32" else "spawn")
        if sys.platform != "win32":
            start_forkserver()
        ours, theirs = ctx.Pipe()
        process = ctx.Process(
            target=_worker_main,
            args=(theirs, self.memory_mb, self.nice),
            name=f"bayesgrasp-{self.name}",
            daemon=True,
        )
        process.start()
        theirs.close()
        worker = _Worker(process, ours, _resident(process.pid))
        with self._lock:
            self._workers.add(worker)
        return worker

    def _release(self, worker: _Worker) -> None:
        """Hand ``worker`` to the first request waiting, or keep it idle."""
        if self.closed:
            self._kill(worker)
            return
        while self.waiting:
            wait = self.waiting.popleft()
            if not wait.done():
                wait.set_result(worker)
                return
        self.idle.append(worker)

    def _kill(self, worker: _Worker, replaced: bool = False) -> None:
        """Kill ``worker`` (at once) and reap it in a thread; start a replacement if needed."""
        with contextlib.suppress(Exception):
            worker.process.kill()
        self.killed += not replaced
        self._forget(worker, replaced)

    def _forget(self, worker: _Worker, replaced: bool = False) -> None:
        with self._lock:
            self._workers.discard(worker)
        self.live -= 1
        self.replaced += replaced
        try:
            self._threads.submit(_reap, worker)
        except RuntimeError:  # closed: reap here (the worker was killed or told to stop)
            _reap(worker)
        if not self.closed:  # a replacement starts now (off the loop), ready for the next work
            self.live += 1
            loop = asyncio.get_running_loop()
            spawned = loop.run_in_executor(self._threads, self._spawn)

            def hand_over(f: asyncio.Future[_Worker]) -> None:
                if f.cancelled() or f.exception() is not None:
                    self.live -= 1
                    while self.waiting:
                        wait = self.waiting.popleft()
                        if not wait.done():
                            wait.set_exception(
                                LimitError(503, "no worker could be started", "worker-stopped")
                            )
                    return
                self._release(f.result())

            spawned.add_done_callback(hand_over)

    def close(self) -> None:
        """Stop every worker: idle ones are told to end, busy ones are killed."""
        self.closed = True
        idle = list(self.idle)
        self.idle.clear()
        with self._lock:
            busy = [w for w in self._workers if w not in idle]
            self._workers.clear()
        for w in idle:
            with contextlib.suppress(Exception):
                w.conn.send(None)
        for w in busy:
            with contextlib.suppress(Exception):
                w.process.kill()
        for w in idle + busy:
            _reap(w)
        self._threads.shutdown(wait=False, cancel_futures=True)


def _reap(worker: _Worker) -> None:
    with contextlib.suppress(ValueError):  # reaped already: the process object is closed
        worker.process.join(2)
        if worker.process.is_alive():
            worker.process.kill()
            worker.process.join(2)
    with contextlib.suppress(Exception):
        worker.conn.close()
    with contextlib.suppress(Exception):
        worker.process.close()


def _resident(pid: int | None) -> int:
    """Resident memory of process ``pid``, bytes (0 when unknown)."""
    try:
        with open(f"/proc/{pid}/statm", encoding="ascii") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):  # pragma: no cover - not Linux
        return 0


def _retry(timeout: float) -> int:
    """Seconds a client should wait before trying again (the ``Retry-After`` header)."""
    return max(1, math.ceil(min(timeout, 60.0)))


def now() -> float:
    """Monotonic seconds (for job timestamps)."""
    return time.monotonic()
