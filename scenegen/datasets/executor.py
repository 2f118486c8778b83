"""Run independent tasks in this process, on local worker processes or on a Dask cluster.

The same picklable function runs on the same task objects whichever executor is chosen;
results are handed to a callback in the parent as they arrive (in completion order, so
callers must not depend on it). Local pools use the ``forkserver`` start method (never
fork a parent whose numba threads may already run). A Dask scheduler is probed first
(within :data:`SCHEDULER_TIMEOUT` seconds) so that a wrong address fails with one line;
tasks are retried up to 3 times when a worker is lost.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Hashable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from multiprocessing import get_context
from typing import Any

from scenegen.errors import ConfigError

__all__ = [
    "SCHEDULER_TIMEOUT",
    "WORKER_TIMEOUT",
    "check_executor",
    "connect",
    "probe",
    "run_tasks",
    "worker_timeout",
]

SCHEDULER_TIMEOUT = 5.0
"""Seconds to wait for a Dask scheduler before giving up."""

WORKER_TIMEOUT = 60.0
"""Seconds to wait for a Dask scheduler with no worker to get one (environment variable
``SCENEGEN_DASK_WORKER_TIMEOUT`` overrides it) before giving up instead of waiting forever."""


def worker_timeout() -> float:
    """:data:`WORKER_TIMEOUT`, or ``SCENEGEN_DASK_WORKER_TIMEOUT`` when set to a positive
    number (ConfigError naming it otherwise)."""
    text = os.environ.get("SCENEGEN_DASK_WORKER_TIMEOUT")
    if text is None:
        return WORKER_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise ConfigError(f"SCENEGEN_DASK_WORKER_TIMEOUT must be a positive number, got {text!r}")
    return value


def check_executor(jobs: int | None, scheduler: str | None) -> None:
    """Raise :class:`ConfigError` for jobs < 1 or both jobs and a scheduler."""
    if jobs is not None and jobs < 1:
        raise ConfigError(f"--jobs must be >= 1, got {jobs}")
    if jobs is not None and scheduler is not None:
        raise ConfigError("give either --jobs or --scheduler, not both")


async def _identity(address: str) -> dict[str, Any]:
    from distributed.comm import connect as dask_connect

    comm = await dask_connect(address, timeout=SCHEDULER_TIMEOUT)
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        await comm.close()


def probe(address: str) -> None:
    """Check within :data:`SCHEDULER_TIMEOUT` seconds that a Dask scheduler answers.

    Raises
    ------
    ConfigError
        One line naming the address and what went wrong.
    """
    import asyncio

    try:
        reply = asyncio.run(asyncio.wait_for(_identity(address), SCHEDULER_TIMEOUT))
    except Exception as err:  # any failure to talk to it means: not a usable scheduler
        why = (
            "the peer does not speak the Dask protocol"
            if isinstance(err, MemoryError)
            else f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else 'no reply'}"
        )
        raise ConfigError(
            f"cannot reach the Dask scheduler at {address!r} within {SCHEDULER_TIMEOUT:g} s: {why}"
        ) from None
    if not isinstance(reply, dict) or reply.get("type") != "Scheduler":
        raise ConfigError(f"{address!r} answered, but it is not a Dask scheduler")


def connect(address: str) -> Any:
    """A ``distributed.Client`` of the scheduler at ``address`` (probed first).

    Raises
    ------
    ConfigError
        If no Dask scheduler answers there within :data:`SCHEDULER_TIMEOUT` seconds.
    """
    from distributed import Client

    probe(address)
    try:
        return Client(address, timeout=SCHEDULER_TIMEOUT, set_as_default=False)
    except Exception as err:
        raise ConfigError(
            f"cannot reach the Dask scheduler at {address!r} within {SCHEDULER_TIMEOUT:g} s: "
            f"{type(err).__name__}: {err}"
        ) from None


def run_tasks(
    fn: Callable[[Any], Any],
    tasks: list[Any],
    on_result: Callable[[Any, Any], None],
    *,
    jobs: int | None = None,
    scheduler: str | None = None,
    key: Callable[[Any], Hashable] = id,
    name: str = "scenegen",
) -> None:
    """Run ``fn(task)`` for every task; call ``on_result(task, result)`` in this process.

    Parameters
    ----------
    fn : callable
        A module-level (picklable) function.
    tasks : list
        Picklable task objects.
    on_result : callable
        Called with each task and its result as soon as it arrives.
    jobs : int or None
        Local worker processes (None: all cores; 1 runs here, in order).
    scheduler : str or None
        A ``dask.distributed`` scheduler address (``tcp://host:8786``).
    key : callable
        A unique text key per task (Dask task keys).
    name : str
        Prefix of the Dask task keys (a random part follows it).

    Raises
    ------
    ConfigError
        For jobs < 1 or an unreachable scheduler. A task's own exception is re-raised
        after the pending tasks are cancelled.
    """
    check_executor(jobs, scheduler)
    if not tasks:
        return
    if scheduler is not None:
        _run_dask(fn, tasks, on_result, scheduler, key, name)
        return
    n = min(jobs or os.cpu_count() or 1, len(tasks))
    if n <= 1:
        for t in tasks:
            on_result(t, fn(t))
        return
    # Bounded in-flight work: at most 2 tasks per worker are submitted at once, so a long
    # run's results never pile up in the parent.
    ctx = get_context("forkserver")
    with ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=_ignore_sigint) as pool:
        pending: dict[Any, Any] = {}
        it = iter(tasks)
        try:
            for t in it:
                pending[pool.submit(fn, t)] = t
                if len(pending) >= 2 * n:
                    break
            while pending:
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    t = pending.pop(fut)
                    on_result(t, fut.result())
                    nxt = next(it, None)
                    if nxt is not None:
                        pending[pool.submit(fn, nxt)] = nxt
        except BaseException:
            # Ctrl-C or a failed task: drop the queued tasks; the running ones finish
            # (each writes its own file atomically, so a rerun finds them done).
            pool.shutdown(wait=True, cancel_futures=True)
            raise


def _ignore_sigint() -> None:
    """Pool workers leave Ctrl-C to the parent, which stops the pool cleanly."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_dask(
    fn: Callable[[Any], Any],
    tasks: list[Any],
    on_result: Callable[[Any, Any], None],
    address: str,
    key: Callable[[Any], Hashable],
    name: str,
) -> None:
    import uuid

    from distributed import as_completed as dask_completed

    client = connect(address)
    name = f"{name}-{uuid.uuid4().hex[:8]}"  # two runs on one cluster never share keys
    try:
        limit = worker_timeout()
        try:
            client.wait_for_workers(1, timeout=limit)
        except TimeoutError:  # a scheduler no worker serves: it would wait forever
            raise ConfigError(
                f"the Dask scheduler at {address!r} has no worker (waited {limit:g} s; "
                "start one with `dask worker ADDRESS`)"
            ) from None
        futures = {}
        for t in tasks:
            fut = client.submit(fn, t, key=f"{name}-{key(t)}", retries=3, pure=False)
            futures[fut.key] = (fut, t)
        try:
            for fut in dask_completed([f for f, _ in futures.values()], loop=client.loop):
                on_result(futures[fut.key][1], fut.result())
        except BaseException:
            client.cancel([f for f, _ in futures.values()])
            raise
    finally:
        client.close()
