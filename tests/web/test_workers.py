"""The worker lanes of the server: time limits kill, memory caps hold, queues are bounded."""

from __future__ import annotations

import asyncio
import math
import os
import time
from typing import Any

import pytest

from bayesgrasp.web.workers import Lane, LimitError

_HELD: list[bytearray] = []


def hold(megabytes: int) -> int:
    """Allocate and keep ``megabytes`` MB in this worker (its resident memory grows)."""
    block = bytearray(megabytes * 2**20)
    block[::4096] = b"x" * len(block[::4096])  # touch every page
    _HELD.append(block)
    return os.getpid()


def count(n: int, progress: Any = None) -> int:
    """Report progress ``n`` times."""
    for i in range(n):
        if progress is not None:
            progress(i + 1, n)
    return n


def run(coro: Any) -> Any:
    return asyncio.run(coro)


def test_work_runs_in_another_process() -> None:
    async def go() -> tuple[float, int]:
        lane = Lane("t", size=1, queue=1)
        try:
            value = await lane.run(math.hypot, (3.0, 4.0), timeout=30)
            pid = await lane.run(os.getpid, (), timeout=30)
            return value, pid
        finally:
            lane.close()

    value, pid = run(go())
    assert value == 5.0
    assert pid != os.getpid()


def test_the_time_limit_kills_the_worker_and_a_new_one_serves() -> None:
    async def go() -> tuple[LimitError, float, int, int, dict[str, Any]]:
        lane = Lane("t", size=1, queue=1)
        try:
            first = await lane.run(os.getpid, (), timeout=30)
            t0 = time.perf_counter()
            with pytest.raises(LimitError) as err:
                await lane.run(time.sleep, (30,), timeout=0.3)
            took = time.perf_counter() - t0
            second = await lane.run(os.getpid, (), timeout=30)
            return err.value, took, first, second, lane.status()
        finally:
            lane.close()

    err, took, first, second, status = run(go())
    assert err.status == 503 and err.kind == "timeout"
    assert "timed out after 0.3 s" in str(err)
    assert took < 2.0  # answered at the limit, not when the sleep ends
    assert first != second  # the sleeper was killed; a new worker took its place
    assert status["killed"] == 1 and status["live"] == 1
    with pytest.raises(ProcessLookupError):
        os.kill(first, 0)  # killed and reaped


def test_the_memory_cap_is_a_503_naming_it() -> None:
    async def go() -> tuple[LimitError, int]:
        lane = Lane("t", size=1, queue=1, memory_mb=64)
        try:
            with pytest.raises(LimitError) as err:
                await lane.run(hold, (512,), timeout=30)
            await lane.run(hold, (8,), timeout=30)  # a fresh worker
            return err.value, lane.status()["replaced"]
        finally:
            lane.close()

    err, replaced = run(go())
    assert err.status == 503 and err.kind == "memory-limit"
    assert "memory limit of 64 MB" in str(err)
    assert replaced == 1


def test_a_worker_that_grew_is_replaced() -> None:
    async def go() -> tuple[int, int, int]:
        lane = Lane("t", size=1, queue=1, recycle_mb=50)
        try:
            a = await lane.run(hold, (10,), timeout=30)  # grows 10 MB: kept
            b = await lane.run(hold, (100,), timeout=30)  # grows past 50 MB: replaced
            c = await lane.run(os.getpid, (), timeout=30)
            return a, b, c
        finally:
            lane.close()

    a, b, c = run(go())
    assert a == b != c


def test_the_queue_is_bounded() -> None:
    async def go() -> list[Any]:
        lane = Lane("t", size=1, queue=1)
        try:
            await lane.run(os.getpid, (), timeout=30)  # the worker is up
            jobs = [asyncio.ensure_future(lane.run(time.sleep, (0.5,), timeout=30))]
            await asyncio.sleep(0.05)
            jobs.append(asyncio.ensure_future(lane.run(time.sleep, (0.1,), timeout=30)))
            await asyncio.sleep(0.05)
            jobs.append(asyncio.ensure_future(lane.run(time.sleep, (0.1,), timeout=30)))
            return await asyncio.gather(*jobs, return_exceptions=True)
        finally:
            lane.close()

    first, second, third = run(go())
    assert first is None and second is None  # at work, then waiting
    assert isinstance(third, LimitError) and third.kind == "queue-full"
    assert "the queue is full" in str(third)


def test_progress_reaches_the_caller() -> None:
    seen: list[tuple[int, int]] = []

    async def go() -> int:
        lane = Lane("t", size=1, queue=1)
        try:
            return await lane.run(
                count, (5,), timeout=30, progress=lambda d, t: seen.append((d, t))
            )  # type: ignore[no-any-return]
        finally:
            lane.close()

    assert run(go()) == 5
    assert seen == [(i, 5) for i in range(1, 6)]


def test_errors_of_the_work_come_back_with_their_status() -> None:
    async def go() -> LimitError:
        lane = Lane("t", size=1, queue=1)
        try:
            with pytest.raises(LimitError) as err:
                await lane.run(math.sqrt, (-1.0,), timeout=30)
            return err.value
        finally:
            lane.close()

    err = run(go())
    assert err.status == 500 and "math domain error" in str(err)


def test_closing_a_lane_stops_busy_workers() -> None:
    async def go() -> int:
        lane = Lane("t", size=1, queue=1)
        pid = await lane.run(os.getpid, (), timeout=30)
        task = asyncio.ensure_future(lane.run(time.sleep, (60,), timeout=120))
        await asyncio.sleep(0.3)
        lane.close()
        task.cancel()
        with pytest.raises((asyncio.CancelledError, LimitError)):
            await task
        return pid

    pid = run(go())
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            break
        time.sleep(0.05)
    else:
        pytest.fail("the busy worker still runs after the lane was closed")


@pytest.mark.parametrize(
    ("limits", "match"),
    [
        ({"workers": 0}, "workers must be at least 1"),
        ({"queue": -1}, "queue must be at least 0"),
        ({"time_limit": 0}, "must be positive"),
        ({"worker_memory": 0}, "worker_memory"),
    ],
)
def test_bad_limits_are_refused(limits: dict[str, Any], match: str) -> None:
    from bayesgrasp.web.app import Limits

    with pytest.raises(ValueError, match=match):
        Limits(**limits)


def test_a_worker_that_dies_is_a_503_and_is_replaced() -> None:
    async def go() -> tuple[LimitError, int, int]:
        lane = Lane("t", size=1, queue=1, memory_mb=None)
        try:
            first = await lane.run(os.getpid, (), timeout=30)
            with pytest.raises(LimitError) as err:
                await lane.run(os._exit, (7,), timeout=30)
            second = await lane.run(os.getpid, (), timeout=30)
            return err.value, first, second
        finally:
            lane.close()

    err, first, second = run(go())
    assert err.status == 503 and err.kind == "worker-stopped"
    assert "exit code 7" in str(err)
    assert first != second
