"""Run independent tasks in this process, on local worker processes or on a Dask cluster.

The same picklable function runs on the same task objects whichever executor is chosen;
results are handed to a callback in the parent as they arrive (in completion order, so
callers must not depend on it). Local pools (:class:`LocalPool`) use the ``forkserver``
start method (never fork a parent whose numba threads may already run); their workers die
with this process, a worker's death (the out-of-memory killer's SIGKILL, a crash) is one
line naming the task it ran, and Ctrl-C stops the running tasks at once (each removes its
temporary file). A Dask scheduler is probed first (within :data:`SCHEDULER_TIMEOUT`
seconds) so that a wrong address fails with one line; tasks are retried up to 3 times when
a worker is lost.
"""

from __future__ import annotations

import contextlib
import ctypes
import multiprocessing.util
import os
import signal
from collections.abc import Callable, Hashable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import get_context
from typing import Any

from scenegen.errors import ConfigError
from scenegen.io.atomic import discard_temp_files
from scenegen.io.guard import describe_exit, die_with_parent, prepare_temp_dir

__all__ = [
    "SCHEDULER_TIMEOUT",
    "WORKER_TIMEOUT",
    "LocalPool",
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
    number (ConfigError naming it otherwise).

    Returns
    -------
    float
        Seconds to wait for a Dask worker.

    Raises
    ------
    ConfigError
        ``SCENEGEN_DASK_WORKER_TIMEOUT`` is set to something other than a positive
        finite number.
    """
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
    """Raise :class:`ConfigError` for jobs < 1 or both jobs and a scheduler.

    Parameters
    ----------
    jobs : int or None
        Local worker processes (None: not given).
    scheduler : str or None
        A Dask scheduler address (None: not given).

    Raises
    ------
    ConfigError
        ``--jobs must be >= 1``, or ``give either --jobs or --scheduler, not both``.
    """
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

    Parameters
    ----------
    address : str
        The scheduler's address (``tcp://host:8786``).

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

    Parameters
    ----------
    address : str
        The scheduler's address (``tcp://host:8786``).

    Returns
    -------
    distributed.Client
        A client, not set as the default one; the caller closes it.

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
    label: Callable[[Any], str] | None = None,
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
    label : callable, optional
        What running a task does, in words (``"making shard-00002.h5 (sequences 8-11)"``),
        for the line that reports the death of its local worker (default: ``"running "``
        and its ``key``).

    Raises
    ------
    ConfigError
        For jobs < 1 or an unreachable scheduler; a local worker process that died (one
        line naming its task, :meth:`LocalPool.death`). A task's own exception is re-raised
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
    said = label or (lambda t: f"running {key(t)}")
    # Bounded in-flight work: at most 2 tasks per worker are submitted at once, so a long
    # run's results never pile up in the parent.
    pool = LocalPool(n)
    pending: dict[Any, Any] = {}
    it = iter(tasks)
    try:
        for t in it:
            pending[pool.submit(fn, t, said(t))] = t
            if len(pending) >= 2 * n:
                break
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                t = pending.pop(fut)
                on_result(t, fut.result())
                nxt = next(it, None)
                if nxt is not None:
                    pending[pool.submit(fn, nxt, said(nxt))] = nxt
    except BrokenProcessPool:
        raise pool.death() from None
    except KeyboardInterrupt:
        pool.close(interrupt=True)
        raise
    except BaseException:
        # A failed task: drop the queued tasks; the running ones finish (each writes its
        # own file atomically, so a rerun finds them done).
        pool.close()
        raise
    pool.close()


_SLOT = 2  # per worker in LocalPool's notes: its pid, and the number of its task (-1: idle)
_notes: Any = None  # in a LocalPool worker: the shared notes
_slot = -1  # in a LocalPool worker: the index of its slot in them


class LocalPool:
    """A ``forkserver`` process pool whose workers die with this process and whose death
    is one line naming the task it ran.

    Workers ignore Ctrl-C (this process stops them, :meth:`close`); ``PR_SET_PDEATHSIG``
    and a watching thread end them when this process dies, even by SIGKILL
    (:func:`scenegen.io.guard.die_with_parent`); each notes, in memory shared with this
    process, which task it runs, so that :meth:`death` can name it.

    Parameters
    ----------
    n : int
        Worker processes.
    preload : sequence of str, optional
        Modules the fork server imports before it forks the workers (when this process
        starts its fork server first).

    Examples
    --------
    >>> pool = LocalPool(2)                                 # doctest: +SKIP
    >>> fut = pool.submit(abs, -3, "taking abs(-3)")        # doctest: +SKIP
    >>> fut.result(); pool.close()                          # doctest: +SKIP
    3
    """

    def __init__(self, n: int, *, preload: Sequence[str] | None = None) -> None:
        prepare_temp_dir()
        ctx = get_context("forkserver")
        if preload is not None:
            ctx.set_forkserver_preload(list(preload))
        self._notes = ctx.RawArray(ctypes.c_longlong, [0, -1] * n)
        self._count = ctx.Value(ctypes.c_int, 0)
        self._labels: list[str] = []
        self._pool = ProcessPoolExecutor(
            max_workers=n, mp_context=ctx, initializer=_start_worker,
            initargs=(os.getpid(), self._notes, self._count),
        )  # fmt: skip

    def submit(self, fn: Callable[[Any], Any], task: Any, label: str) -> Future[Any]:
        """Run ``fn(task)`` on a worker; ``label`` says what it does (``"making FILE"``), for
        :meth:`death`.

        Parameters
        ----------
        fn : callable
            A module-level (picklable) function of one argument.
        task : object
            Its (picklable) argument.
        label : str
            What running it does, in words (``"making shard-00002.h5 (sequences 8-11)"``):
            the end of the line :meth:`death` gives if its worker dies while running it.

        Returns
        -------
        concurrent.futures.Future
            The future of ``fn(task)``'s result (or its exception).

        Raises
        ------
        BrokenProcessPool
            A worker has died (report it with :meth:`death`).
        """
        self._labels.append(label)
        return self._pool.submit(_run_noted, fn, task, len(self._labels) - 1)

    def _running(self) -> dict[int, int]:
        """pid -> number of the task that worker runs, for the busy workers."""
        notes = list(self._notes)
        return {notes[i]: notes[i + 1] for i in range(0, len(notes), _SLOT)
                if notes[i] > 0 and notes[i + 1] >= 0}  # fmt: skip

    def death(self) -> ConfigError:
        """After :class:`BrokenProcessPool`: stop the pool and say which worker died.

        Returns
        -------
        ConfigError
            One line: how the worker died (e.g. ``SIGKILL``, as when the system runs out
            of memory), the task it ran when known, and that running the same command
            again resumes (finished tasks are kept).
        """
        running = self._running()
        procs = dict(getattr(self._pool, "_processes", None) or {})
        self._pool.shutdown(wait=True, cancel_futures=True)
        # The others were stopped by the pool (SIGTERM, :func:`_on_sigterm`); the dead one
        # died otherwise.
        stopped = (None, 0, -signal.SIGTERM, 128 + signal.SIGTERM)
        dead = [(pid, p.exitcode) for pid, p in procs.items() if p.exitcode not in stopped]
        how, what = "", ""
        if len(dead) == 1:
            pid, code = dead[0]
            how = f" ({describe_exit(code)}{_WHY.get(code, '')})"
            number = running.get(pid)
            if number is not None and number < len(self._labels):
                what = f" while {self._labels[number]}"
        return ConfigError(
            f"a worker process died{how}{what}; run the same command again to resume "
            "(finished work is kept)"
        )

    def close(self, *, interrupt: bool = False) -> None:
        """Drop the queued tasks and stop the workers: let the running tasks finish, or
        (``interrupt``, after Ctrl-C) stop them at once (SIGTERM: each worker removes the
        temporary file it was writing and exits).

        Returns when every worker has exited.

        Parameters
        ----------
        interrupt : bool, default False
            Send SIGTERM to the workers running a task before shutting the pool down.
        """
        if interrupt:
            for pid in self._running():
                with contextlib.suppress(OSError):
                    os.kill(pid, signal.SIGTERM)
        self._pool.shutdown(wait=True, cancel_futures=True)


_WHY = {-signal.SIGKILL: ", as when the system runs out of memory: fewer --jobs use less"}


def _start_worker(parent: int, notes: Any, count: Any) -> None:
    """Initialise a :class:`LocalPool` worker."""
    global _notes, _slot
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    signal.signal(signal.SIGTERM, _on_sigterm)
    die_with_parent(parent)
    with count.get_lock():
        _slot = _SLOT * (count.value % (len(notes) // _SLOT))
        count.value += 1
    _notes = notes
    _notes[_slot] = os.getpid()


def _on_sigterm(signum: int, frame: Any) -> None:
    """Exit at once, removing the temporary file of a write in progress (the pool stops:
    Ctrl-C in the parent, or another worker died). Multiprocessing's exit finalizers run
    first: they release the named semaphores this worker made (numba's thread-pool lock),
    which ``os._exit`` would leave to the resource tracker's "leaked semaphore" warning
    after the one-line error."""
    discard_temp_files()
    with contextlib.suppress(Exception):
        multiprocessing.util._run_finalizers(0)  # what a normal exit runs
    os._exit(128 + signum)


def _run_noted(fn: Callable[[Any], Any], task: Any, number: int) -> Any:
    """``fn(task)``, noted as task ``number`` of this worker."""
    _notes[_slot + 1] = number
    try:
        return fn(task)
    finally:
        _notes[_slot + 1] = -1


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
