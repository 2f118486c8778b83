"""Atomic replacement of files and folders, and the temporary files it leaves.

Atomic writes
    Every write goes to a temporary file in the target's folder, named
    ``.NAME.tmp-PID@HOST-RANDOM``, which is flushed to disk and renamed onto the target
    only when complete. A crash or a SIGKILL therefore never leaves a half-written file at
    the target path and never damages an earlier file there; a reader sees either the old
    complete file or the new complete one. Concurrent writers never collide: every write
    has its own temporary name, and when several processes write the same target the last
    rename wins with a complete file.

Leftover temporary files
    A killed writer leaves its temporary file behind. Such files start with a dot, so
    shell globs such as ``*.h5`` skip them, and :func:`clean_temp_files` removes those
    whose writing process (on this host) no longer runs. Every atomic write first cleans
    the stale leftovers of its own target, so rerunning a killed command tidies up after
    it. Files written by other hosts (shared folders) are left alone.

Helpers
    :func:`write_text`, :func:`write_json` and :func:`write_npy` are the one way the
    package writes a text, JSON or ``.npy`` file; everything else uses :func:`atomic_path`
    directly (HDF5, images, videos).
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import socket
import stat
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from scenegen.errors import ConfigError, DataError

__all__ = [
    "atomic_path",
    "clean_temp_files",
    "describe_special_file",
    "describe_temp_file",
    "discard_temp_files",
    "read_regular",
    "read_regular_text",
    "refuse_special_files",
    "SpecialFile",
    "temp_file_owner",
    "temp_prefix",
    "write_json",
    "write_npy",
    "write_text",
]

class SpecialFile(DataError):
    """A FIFO, a device or a socket where a file was to be read (:func:`read_regular`);
    its message is :func:`describe_special_file`'s line."""


_in_progress: set[Path] = set()  # temporary files of this process's unfinished writes

_TEMP_NAME = re.compile(r"^\.(?P<target>.+)\.(?P<kind>tmp|old)-(?P<pid>\d+)@(?P<host>[\w.]*)-")


def _host() -> str:
    return re.sub(r"[^\w.]", "_", socket.gethostname(), flags=re.ASCII)


def temp_prefix(name: str, kind: str = "tmp") -> str:
    """The prefix of this process's temporary files for a target called ``name``.

    Parameters
    ----------
    name : str
        The target's file or folder name (no directory).
    kind : {'tmp', 'old'}
        ``tmp`` for a file or folder being written, ``old`` for a folder being replaced.

    Returns
    -------
    str
        ``.NAME.KIND-PID@HOST-``; a random part follows it in the actual name.

    Examples
    --------
    >>> temp_prefix("a.h5").startswith(".a.h5.tmp-")
    True
    """
    return f".{name}.{kind}-{os.getpid()}@{_host()}-"


def temp_file_owner(path: str | Path) -> tuple[str, int, str] | None:
    """Parse the name of a temporary file written by :func:`atomic_path`.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    (target, pid, host) or None
        The target's name, and the process and host that write(s) it; None if ``path``
        is not named like a temporary file.

    Examples
    --------
    >>> temp_file_owner(".a.h5.tmp-123@box-x1y2z3")
    ('a.h5', 123, 'box')
    """
    m = _TEMP_NAME.match(Path(path).name)
    if m is None:
        return None
    return m["target"], int(m["pid"]), m["host"]


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's live process
        return True
    return True


def _stale(path: Path) -> bool:
    owner = temp_file_owner(path)
    if owner is None:
        return False
    _, pid, host = owner
    return host == _host() and pid != os.getpid() and not _running(pid)


def clean_temp_files(folder: str | Path, name: str | None = None) -> list[Path]:
    """Remove stale temporary files and folders left in ``folder`` by killed writers.

    A temporary file is stale when it was written on this host by a process that no
    longer runs. Files of running processes and of other hosts are never touched.

    Parameters
    ----------
    folder : str or Path
    name : str, optional
        Only the leftovers of this target name (default: of every target).

    Returns
    -------
    list of Path
        What was removed.
    """
    d = Path(folder)
    pattern = f".{_glob_escape(name)}.*-*@*-*" if name is not None else ".*.*-*@*-*"
    removed = []
    for p in sorted(d.glob(pattern)):
        if not _stale(p):
            continue
        with contextlib.suppress(OSError):
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p)
            else:
                p.unlink()
            removed.append(p)
    return removed


def _glob_escape(text: str) -> str:
    # Path.glob treats *, ? and [ specially.
    return re.sub(r"([*?\[])", r"[\1]", text)


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(folder: Path) -> None:
    # Makes the rename itself durable; not every file system allows it.
    with contextlib.suppress(OSError):
        _fsync(folder)


def _target_folder(target: Path) -> Path:
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        # The nearest existing ancestor says why: missing, or a file where a folder is.
        up = folder
        while not up.exists() and up != up.parent:
            up = up.parent
        if up.exists() and not up.is_dir():
            raise ConfigError(f"{target}: {up} is a file, not a folder")
        raise ConfigError(f"{target}: folder {folder} does not exist")
    if target.is_dir():
        raise ConfigError(f"{target}: is a folder, expected a file name")
    # A rename would put a regular file in place of /dev/null, a FIFO or a socket.
    special = describe_special_file(target)
    if special is not None:
        raise ConfigError(special)
    return folder


def describe_special_file(path: str | Path) -> str | None:
    """``"PATH: is not a regular file (a FIFO)"`` if ``path`` names (through symbolic
    links) a FIFO, a device or a socket; else None (a regular file, a folder, nothing).

    Writers refuse such a target (a rename would replace it), and readers refuse such an
    input at once: opening a FIFO waits for a writer that may never come, and a device
    such as ``/dev/zero`` never ends.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    str or None
    """
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    return _special_text(path, mode)


def refuse_special_files(paths: Iterable[str | Path]) -> None:
    """Refuse, before any work, a FIFO, a device or a socket among the files a command is
    about to write (writing it would fail only at the end; reading it would wait).

    Parameters
    ----------
    paths : iterable of str or Path
        The files to be written.

    Raises
    ------
    ConfigError
        :func:`describe_special_file`'s line for the first such file.
    """
    for p in paths:
        special = describe_special_file(p)
        if special is not None:
            raise ConfigError(special)


def _special_text(path: str | Path, mode: int) -> str | None:
    """:func:`describe_special_file`'s line for a file of ``mode`` (None: regular or
    folder)."""
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return None
    if stat.S_ISFIFO(mode):
        kind = "a FIFO"
    elif stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        kind = "a device"
    elif stat.S_ISSOCK(mode):
        kind = "a socket"
    else:
        kind = "a special file"
    return f"{path}: is not a regular file ({kind})"


def read_regular(path: str | Path) -> bytes:
    """The bytes of the regular file at ``path`` (through symbolic links), never waiting
    on a FIFO or reading a device without end.

    The file is opened without blocking and checked on the open descriptor, so a FIFO,
    device or socket put there at any moment is refused at once (no window between a
    check and the read).

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    bytes
        Its content.

    Raises
    ------
    SpecialFile
        ``path`` is a FIFO, a device or a socket: :func:`describe_special_file`'s line.
    FileNotFoundError, IsADirectoryError, OSError
        As :func:`open` raises them (missing, a folder, unreadable).
    """
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        mode = os.fstat(fd).st_mode
    except BaseException:
        os.close(fd)
        raise
    if not stat.S_ISREG(mode):
        os.close(fd)
        if stat.S_ISDIR(mode):
            raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
        raise SpecialFile(_special_text(path, mode))
    with os.fdopen(fd, "rb") as fh:
        return fh.read()


def read_regular_text(path: str | Path, encoding: str = "utf-8") -> str:
    """:func:`read_regular`, decoded as :meth:`pathlib.Path.read_text` decodes (universal
    newlines).

    Parameters
    ----------
    path : str or Path
        The file.
    encoding : str, optional
        Its encoding.

    Returns
    -------
    str
        Its text.

    Raises
    ------
    SpecialFile, FileNotFoundError, IsADirectoryError, OSError
        As :func:`read_regular`.
    UnicodeDecodeError
        The bytes are not text in ``encoding``.
    """
    import io

    return io.TextIOWrapper(io.BytesIO(read_regular(path)), encoding=encoding).read()


def _real_target(path: str | Path) -> Path:
    """``path``, or the file a symbolic link at ``path`` points to (written through, so
    the link stays a link)."""
    target = Path(path)
    return Path(os.path.realpath(target)) if target.is_symlink() else target


@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` on success.

    The temporary file is named ``.NAME.tmp-PID@HOST-RANDOM`` + ``suffix`` (unique per
    call, so concurrent writers never collide) and is flushed to disk before the rename.
    On any exception it is removed and ``path`` is left untouched; if the process is
    killed it stays behind, and the next atomic write of the same target (or
    :func:`clean_temp_files`) removes it.

    Parameters
    ----------
    path : str or Path
        The target file; its folder must exist.
    suffix : str
        Ending of the temporary name (lets writers that pick a format by extension work).

    Yields
    ------
    Path
        The temporary file (created empty) to write the content to.

    Raises
    ------
    ConfigError
        If the folder does not exist, or the target is a folder or another file that is
        not a regular one (a device such as ``/dev/null``, a FIFO); a symbolic link is
        written through.
    """
    target = _real_target(path)
    folder = _target_folder(target)
    clean_temp_files(folder, target.name)
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(target.name), suffix=suffix, dir=folder)
    os.close(fd)
    tmp_path = Path(tmp)
    _in_progress.add(tmp_path)
    # mkstemp makes the file private; give it the permissions a plain open() would.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)
    try:
        yield tmp_path
        _fsync(tmp_path)
        os.replace(tmp_path, target)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise
    finally:
        _in_progress.discard(tmp_path)
    _fsync_dir(folder)


def discard_temp_files() -> None:
    """Remove the temporary files of this process's unfinished atomic writes.

    For a process about to exit at once (a pool worker told to stop by SIGTERM): its
    targets stay untouched and no temporary file is left behind.
    """
    for tmp in list(_in_progress):
        with contextlib.suppress(OSError):
            tmp.unlink()


def describe_temp_file(path: str | Path) -> str | None:
    """One line saying that ``path`` is a temporary file of an atomic write, or None.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    str or None
        ``"PATH: an unfinished temporary file of a write to 'NAME' (process PID on HOST,
        running)"`` (or ``no longer running``; the state is only known on this host).
    """
    owner = temp_file_owner(path)
    if owner is None:
        return None
    target, pid, host = owner
    where = f"process {pid} on {host or '?'}"
    if host == _host():
        where += ", running" if _running(pid) else ", no longer running"
    return f"{path}: an unfinished temporary file of a write to {target!r} ({where})"


# ---------------------------------------------------------------------------------------
# Helpers


def _prepare(path: str | Path, parents: bool) -> Path:
    target = Path(path)
    if parents:
        target.parent.mkdir(parents=True, exist_ok=True)
    return target


def write_text(path: str | Path, text: str, *, parents: bool = False) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (see :func:`atomic_path`).

    Parameters
    ----------
    path : str or Path
    text : str
        Written as is (no newline added).
    parents : bool
        Create missing parent folders first.

    Raises
    ------
    ConfigError
        If the folder does not exist (and ``parents`` is false) or ``path`` is a folder.
    """
    target = _prepare(path, parents)
    with atomic_path(target, target.suffix) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_json(
    path: str | Path,
    data: Any,
    *,
    indent: int | None = None,
    sort_keys: bool = True,
    allow_nan: bool = False,
    parents: bool = False,
) -> None:
    """Write ``data`` as JSON, ending with a newline, to ``path`` atomically.

    Parameters
    ----------
    path : str or Path
    data : any JSON-serialisable value
    indent : int, optional
        None writes one compact line (no spaces after separators).
    sort_keys : bool
    allow_nan : bool
        False refuses NaN and infinities (``ValueError``): they are not JSON.
    parents : bool
        Create missing parent folders first.

    Raises
    ------
    ValueError
        For NaN or infinite values when ``allow_nan`` is false.
    ConfigError
        As :func:`write_text`.
    """
    text = json.dumps(
        data,
        sort_keys=sort_keys,
        allow_nan=allow_nan,
        indent=indent,
        separators=(",", ":") if indent is None else (",", ": "),
    )
    write_text(path, text + "\n", parents=parents)


def write_npy(path: str | Path, array: ArrayLike, *, parents: bool = False) -> None:
    """Write ``array`` in NumPy's ``.npy`` format to ``path`` atomically.

    Parameters
    ----------
    path : str or Path
        Written as given (no ``.npy`` appended).
    array : array_like, any shape and dtype
        Saved as ``np.asarray(array)``.
    parents : bool
        Create missing parent folders first.

    Raises
    ------
    ConfigError
        As :func:`write_text`.
    """
    target = _prepare(path, parents)
    with atomic_path(target) as tmp, open(tmp, "wb") as fh:
        np.save(fh, np.asarray(array))
