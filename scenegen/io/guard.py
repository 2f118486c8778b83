"""Time-boxed, isolated reads of files not yet known to be sound.

Some damage sends libhdf5 into an endless loop (a zeroed global heap: ``H5Aread`` ->
``H5T__conv_vlen`` -> ``H5HG...`` never returns) or crashes it (a segmentation fault on
corrupted metadata). Neither can be interrupted from Python in the process that runs
it, so the first look at a file -- opening it and reading its metadata (every attribute,
every variable-length string, every dataset's shape, type and filters) -- happens in a
child process under a deadline:

- the child is started by the ``forkserver`` method (``spawn`` where there is none): it
  never inherits the parent's open HDF5 files, locks or threads;
- it dies with its parent: ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` on Linux, a thread that
  polls the parent's pid elsewhere, and in any case ``alarm()`` (the kernel kills the
  child with ``SIGALRM`` once it has made no progress for the deadline, even when it is
  stuck inside C code that holds the GIL);
- the parent waits with :meth:`Connection.poll` and a timeout, and kills the child when
  the deadline passes. Long checks call :func:`beat` to say they are still progressing
  (each beat restarts the deadline), so the deadline bounds a *stall*, not the work.

A timeout becomes one line, ``"PATH: metadata unreadable: ..."`` (a :class:`DataError`,
exit code 1), and so does a crash of the library.

:func:`preflight` is the check that :func:`scenegen.io.read` and the other readers run
before they open a file in the calling process; its verdict is cached per file version
(path, inode, size, modification time), so reading one file many times pays it once.
The deadline is :data:`TIMEOUT` seconds, or ``SCENEGEN_READ_TIMEOUT`` from the
environment.
"""

from __future__ import annotations

import contextlib
import ctypes
import faulthandler
import math
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from scenegen.errors import ConfigError, DataError

__all__ = [
    "PRELOAD",
    "TIMEOUT",
    "Unreadable",
    "beat",
    "call",
    "clear_cache",
    "describe_exit",
    "die_with_parent",
    "preflight",
    "prepare_temp_dir",
    "in_child",
    "survey",
    "timeout",
    "trust",
]

TIMEOUT = 10.0
"""Default deadline in seconds: the longest a reader may go without progress on a file
not yet known to be sound (override with ``SCENEGEN_READ_TIMEOUT``)."""

PRELOAD = ("scenegen.io.guard", "h5py", "scenegen.io.validate")
"""Modules the fork server imports once, before it forks any guarded child: what the
children run (:func:`survey`, the checks of :mod:`scenegen.io.validate`). A child that had
to import the checks itself would pay about 0.11 s each time (scipy.ndimage, the presets);
the server pays it once, when the process makes its first guarded read (``scenegen
bench --only guarded``)."""

_PR_SET_PDEATHSIG = 1
_BEAT_EVERY = 0.2  # seconds between heartbeats sent to the parent, at most
_CACHE_SIZE = 256

_conn: Connection | None = None  # set in a guarded child: where beats go
_last_beat = 0.0
_alarm = 0
_cache: dict[tuple[str, int, int, int], None] = {}


class Unreadable(DataError):
    """The guarded child timed out or crashed: the file's metadata could not be read."""


def timeout() -> float:
    """The deadline in seconds: ``SCENEGEN_READ_TIMEOUT`` if set (and positive), else
    :data:`TIMEOUT`.

    Returns
    -------
    float
        The deadline, seconds; :data:`TIMEOUT` also when the variable is not a finite
        number.
    """
    text = os.environ.get("SCENEGEN_READ_TIMEOUT", "")
    try:
        value = float(text)
    except ValueError:
        return TIMEOUT
    return value if value > 0 and math.isfinite(value) else TIMEOUT


# ---------------------------------------------------------------------------------------
# The child side


def die_with_parent(parent: int) -> None:
    """Arrange for this process, a child started by ``forkserver``, to die when ``parent``
    (the process that asked for it) does.

    Used by guarded children and by the workers of local pools
    (:class:`scenegen.datasets.executor.LocalPool`): ``PR_SET_PDEATHSIG`` on Linux kills
    the child at once when the fork server exits, which it does when ``parent`` dies once no
    child holds its keep-alive pipe (closed here); a thread polling ``parent`` every 0.5 s
    covers other systems and a fork server that outlives ``parent``.

    Parameters
    ----------
    parent : int
        The process id to outlive by at most about half a second.
    """
    # A forkserver child holds the write end of the server's "alive" pipe, which keeps the
    # server (this process's parent) alive as long as the child runs: closing it lets the
    # server exit when the caller dies, and PR_SET_PDEATHSIG then kills this child.
    from multiprocessing import forkserver

    alive = getattr(forkserver._forkserver, "_forkserver_alive_fd", None)
    if alive is not None:
        with contextlib.suppress(OSError):
            os.close(alive)
        forkserver._forkserver._forkserver_alive_fd = None
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)

    def watch() -> None:  # also covers a forkserver parent that outlives the caller
        while True:
            time.sleep(0.5)
            try:
                os.kill(parent, 0)
            except ProcessLookupError:
                os._exit(70)
            except PermissionError:  # pid reused by another user's process: parent gone
                os._exit(70)

    threading.Thread(target=watch, name="scenegen-guard-watch", daemon=True).start()
    with contextlib.suppress(ProcessLookupError):
        os.kill(parent, 0)
        return
    os._exit(70)  # the parent died before the child got here


def _arm(seconds: int) -> None:
    global _alarm
    _alarm = seconds
    if hasattr(signal, "alarm"):
        signal.signal(signal.SIGALRM, signal.SIG_DFL)  # the kernel kills, no Python needed
        signal.alarm(seconds)


def beat() -> None:
    """Tell the waiting parent that a guarded check is still progressing.

    A no-op outside a guarded child. Cheap enough to call once per frame: beats are sent
    at most every 0.2 s. Each restarts the deadline (the parent's and the child's own
    alarm).
    """
    global _last_beat
    if _conn is None:
        return
    now = time.monotonic()
    if now - _last_beat < _BEAT_EVERY:
        return
    _last_beat = now
    with contextlib.suppress(OSError, ValueError):
        _conn.send(("beat",))
    if _alarm and hasattr(signal, "alarm"):
        signal.alarm(_alarm)


def _one_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return text[0][:300] if text else type(err).__name__


def _child(
    conn: Connection, parent: int, seconds: float, fn: Callable[..., Any], args: tuple[Any, ...]
) -> None:
    global _conn
    die_with_parent(parent)
    _arm(math.ceil(seconds) + 1)
    faulthandler.disable()  # a crash is reported by the parent, in one line
    _conn = conn
    try:
        msg: tuple[Any, ...] = ("ok", fn(*args))
    except DataError as err:
        msg = ("data", str(err))
    except ConfigError as err:
        msg = ("config", str(err))
    except BaseException as err:  # whatever else a damaged file provokes: one line
        msg = ("error", f"{type(err).__name__}: {_one_line(err)}")
    try:
        conn.send(msg)
    except Exception as err:  # an unpicklable result
        conn.send(("error", f"{type(err).__name__}: {_one_line(err)}"))
    conn.close()
    # No interpreter clean-up: closing HDF5 objects of a damaged file can loop as well.
    os._exit(0)


# ---------------------------------------------------------------------------------------
# The parent side


def _forget_inherited_forkserver() -> None:
    """In a process made by ``fork`` (a worker of a PyTorch DataLoader or of a fork pool),
    the parent's fork server is inherited in name only: it is not this process's child,
    and starting a guard through it failed with ``ChildProcessError``. Forget it (closing
    this copy of its keep-alive pipe, which the parent still holds); this process starts
    its own fork server when it needs one."""
    from multiprocessing import forkserver

    server = getattr(forkserver, "_forkserver", None)
    if server is None or getattr(server, "_forkserver_pid", None) is None:
        return
    alive = server._forkserver_alive_fd
    server._forkserver_pid = server._forkserver_address = server._forkserver_alive_fd = None
    server._lock = threading.Lock()  # it may have been held by another thread at the fork
    if alive is not None:
        with contextlib.suppress(OSError):
            os.close(alive)


os.register_at_fork(after_in_child=_forget_inherited_forkserver)


def _context() -> Any:
    methods = multiprocessing.get_all_start_methods()
    if in_child() and "fork" in methods:
        # A guarded child is a fresh single-threaded process that holds no HDF5 file open
        # while it starts another guard (which it does only before any reading): forking it
        # is safe, and spares a second fork server.
        return multiprocessing.get_context("fork")
    if "forkserver" in methods:
        ctx = multiprocessing.get_context("forkserver")
        # Children fork from a server that has imported what they run (PRELOAD). It takes
        # effect when this process starts its fork server (a LocalPool may start it first).
        ctx.set_forkserver_preload(list(PRELOAD))
        return ctx
    return multiprocessing.get_context("spawn")


# A fork server listens on "TEMP/pymp-<8 random characters>/listener-<8 more>", a Unix
# socket path of at most 103 bytes (104 with its NUL on macOS, 108 on Linux). Only the
# lengths of those names matter here: _RANDOM stands for the random characters.
_RANDOM = "r" * 8
_SOCKET_PATH_MAX = 103
_SOCKET_NAME = "/listener-" + _RANDOM
_SYSTEM_TEMP_DIRS = ("/tmp", "/var/tmp", "/usr/tmp")


def _fits(folder: str) -> bool:
    return len(os.fsencode(folder)) + len(_SOCKET_NAME) <= _SOCKET_PATH_MAX


def prepare_temp_dir() -> None:
    """Make sure multiprocessing has a temporary folder a fork server can listen in.

    multiprocessing makes a private folder (``pymp-`` and 8 random characters, mode 0700) in
    the temporary folder (``TMPDIR``, or ``tempfile.tempdir`` when a program sets it) for
    its sockets. When that folder cannot be written to, or its path is too long for a Unix
    socket (about 75 characters), the private folder is made under the system's ``/tmp``
    (or ``/var/tmp``) instead, as Python 3.14 itself does for long paths. Called before a
    guarded child or a local pool starts; cheap once the folder exists.

    Raises
    ------
    ConfigError
        One line naming ``TMPDIR`` and why each folder was refused, when none is usable.
    """
    import shutil
    import tempfile
    from multiprocessing import process, util

    config = process.current_process()._config
    held = config.get("tempdir")
    if held is not None and _fits(held):
        return
    bases: list[str] = []
    refused: list[str] = []
    try:
        bases.append(tempfile.gettempdir())
    except OSError:  # no usable folder among TMPDIR, TEMP, TMP, /tmp, ... and the cwd
        refused.append("tempfile: no writable default folder")
    bases += [b for b in _SYSTEM_TEMP_DIRS if b not in bases]
    for base in bases:
        if not _fits(os.path.join(base, "pymp-" + _RANDOM)):
            refused.append(f"{base}: too long a path for a socket")
            continue
        try:
            made = tempfile.mkdtemp(prefix="pymp-", dir=base)
        except OSError as err:
            refused.append(f"{base}: {err.strerror or type(err).__name__}")
            continue
        util.Finalize(None, shutil.rmtree, args=(made,), kwargs={"ignore_errors": True},
                      exitpriority=-100)  # fmt: skip
        config["tempdir"] = made
        return
    where = f"TMPDIR={os.environ['TMPDIR']!r}" if "TMPDIR" in os.environ else "TMPDIR unset"
    raise ConfigError(
        f"no usable temporary folder to start child processes in ({where}; "
        f"{'; '.join(refused)}): set TMPDIR to a writable folder with a short path"
    )


@contextlib.contextmanager
def _main_hidden() -> Any:
    """Start a child without re-running the caller's ``__main__``: ``spawn`` and
    ``forkserver`` children import the main script unless it has neither ``__file__``
    nor ``__spec__``, and a plain script calling :func:`scenegen.io.read` at top level
    would then run again in every child (the functions run there live in scenegen)."""
    # A daemonic process (a worker of a multiprocessing pool) may not start children,
    # because it would leave them behind when it is terminated; a guarded child dies with
    # its parent (PR_SET_PDEATHSIG, alarm), so the rule is lifted while it starts.
    config = multiprocessing.current_process()._config
    daemon = config.pop("daemon", None)
    main = sys.modules.get("__main__")
    saved = {}
    if main is not None:
        saved = {k: main.__dict__[k] for k in ("__file__", "__spec__") if k in main.__dict__}
        main.__dict__.pop("__file__", None)
        main.__dict__["__spec__"] = None
    try:
        yield
    finally:
        if main is not None:
            main.__dict__.pop("__spec__", None)
            main.__dict__.update(saved)
        if daemon is not None:
            config["daemon"] = daemon


def describe_exit(code: int | None) -> str:
    """How a child process ended, from its ``exitcode``: ``"SIGKILL"``, ``"exit status 3"``.

    Parameters
    ----------
    code : int or None
        The child's ``exitcode``: negative for the signal that killed it, None if it has
        not ended.

    Returns
    -------
    str
        The signal's name (``"signal N"`` for an unknown one), ``"exit status N"``, or
        ``"no exit status"``.

    Examples
    --------
    >>> describe_exit(-9), describe_exit(3), describe_exit(None)
    ('SIGKILL', 'exit status 3', 'no exit status')
    """
    if code is None:
        return "no exit status"
    if code < 0:
        try:
            return signal.Signals(-code).name
        except ValueError:
            return f"signal {-code}"
    return f"exit status {code}"


def call(
    fn: Callable[..., Any],
    *args: Any,
    label: str,
    seconds: float | None = None,
) -> Any:
    """Run ``fn(*args)`` in a child process under a deadline and return its result.

    Parameters
    ----------
    fn : callable
        A module-level (picklable) function; its arguments and result must pickle. It may
        call :func:`beat` to restart the deadline while it progresses.
    *args : object
        Its arguments.
    label : str
        What is read (usually the path): the prefix of the error lines.
    seconds : float, optional
        The deadline (default :func:`timeout`): how long the child may go without
        finishing or beating.

    Returns
    -------
    object
        What ``fn`` returned.

    Raises
    ------
    ConfigError
        No usable temporary folder to start the child in (:func:`prepare_temp_dir`).
    Unreadable
        If the child made no progress within the deadline (it is killed) or died (a
        crash of the HDF5 library): ``"LABEL: metadata unreadable: ..."``.
    DataError, ConfigError
        Raised by ``fn`` in the child (same message).
    DataError
        Any other exception of ``fn``: ``"LABEL: could not be read (Type: message)"``.
    """
    limit = timeout() if seconds is None else float(seconds)
    ctx = _context()
    if ctx.get_start_method() == "forkserver":
        prepare_temp_dir()
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(
        target=_child, args=(send, os.getpid(), limit, fn, args), name="scenegen-guard"
    )
    with _main_hidden():
        proc.start()
    send.close()
    msg: tuple[Any, ...] | None = None
    try:
        deadline = time.monotonic() + limit
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise Unreadable(
                    f"{label}: metadata unreadable: no answer from the HDF5 library within "
                    f"{limit:g} s (damaged file)"
                )
            if not recv.poll(remaining):
                continue
            try:
                msg = recv.recv()
            except (EOFError, OSError):
                msg = None
                break
            if msg[0] != "beat":
                break
            deadline = time.monotonic() + limit
    finally:
        recv.close()
        if msg is None or msg[0] == "beat":
            proc.kill()
        proc.join()
        code = proc.exitcode
        proc.close()
    if msg is None:
        raise Unreadable(
            f"{label}: metadata unreadable: the HDF5 library crashed reading it "
            f"({describe_exit(code)})"
        )
    kind, value = msg[0], msg[1]
    if kind == "ok":
        return value
    if kind == "data":
        raise DataError(value)
    if kind == "config":
        raise ConfigError(value)
    raise DataError(f"{label}: could not be read ({value})")


# ---------------------------------------------------------------------------------------
# The metadata survey and the cached preflight


def in_child() -> bool:
    """True inside a guarded child (where reads need no further guard).

    Returns
    -------
    bool
    """
    return _conn is not None


def survey(path: str) -> int:
    """Open ``path`` and read all of its metadata; meant to run in a guarded child.

    Reads every attribute of every object (variable-length strings included), every
    string dataset whole, and every dataset's shape, type, filters and chunk index.

    Parameters
    ----------
    path : str

    Returns
    -------
    int
        The number of objects surveyed.

    Raises
    ------
    DataError
        One line if the file cannot be opened or its metadata cannot be read.
    """
    import h5py

    from scenegen.io.hdf5 import describe_open_error

    try:
        f = h5py.File(path, "r")
    except OSError as err:
        raise DataError(describe_open_error(path, err)) from None
    count = 0

    def look(name: str, obj: Any) -> None:
        nonlocal count
        beat()
        count += 1
        for key in obj.attrs:
            obj.attrs[key]
        if isinstance(obj, h5py.Dataset):
            obj.shape, obj.dtype, obj.chunks, obj.compression, obj.fletcher32  # noqa: B018
            if obj.chunks is not None and obj.size:
                obj.id.get_num_chunks()
            if h5py.check_string_dtype(obj.dtype) is not None or obj.dtype.kind == "O":
                obj[()]

    try:
        with f:
            look("/", f)
            f.visititems(look)
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as err:
        raise DataError(f"{path}: damaged HDF5 metadata ({_one_line(err)})") from None
    return count


def _version_key(p: Path) -> tuple[str, int, int, int]:
    st = p.stat()
    return (str(p.resolve()), st.st_ino, st.st_size, st.st_mtime_ns)


def preflight(path: str | Path) -> None:
    """Check in a guarded child that ``path``'s metadata reads (once per file version).

    Called by the readers of :mod:`scenegen.io` before they open a file in this process.
    A verdict of "sound" is cached per (path, inode, size, modification time), so reading
    a file again costs one ``stat``; a file written by this process is trusted (see
    :func:`trust`). Inside a guarded child it does nothing (the child is guarded already).

    Parameters
    ----------
    path : str or Path

    Raises
    ------
    DataError
        One line: the file cannot be opened, its metadata is damaged, or reading it
        stalled past the deadline (``"metadata unreadable: ..."``, :class:`Unreadable`).
    """
    if in_child():
        return
    p = Path(path)
    try:
        key = _version_key(p)
    except OSError:
        return  # the reader reports a missing file in its own words
    if key in _cache:
        return
    call(survey, str(p), label=str(p))
    _remember(key)


def _remember(key: tuple[str, int, int, int]) -> None:
    if len(_cache) >= _CACHE_SIZE:
        _cache.pop(next(iter(_cache)))
    _cache[key] = None


def trust(path: str | Path) -> None:
    """Record that ``path`` (as it is now) was written by this process and is sound.

    :func:`preflight` then skips the file until it changes (path, inode, size or
    modification time). A path that cannot be examined is ignored.

    Parameters
    ----------
    path : str or Path
        The file written.
    """
    with contextlib.suppress(OSError):
        _remember(_version_key(Path(path)))


def clear_cache() -> None:
    """Forget every cached verdict (tests)."""
    _cache.clear()
