"""Numba's on-disk cache of the kernels, kept consistent across the package's modules.

Numba keys a cached function on the time stamp and size of *its own* source file. A
kernel that calls a kernel of another module (``direct._accumulate`` calls
``profiles._box_row_weights``; ``stages`` calls ``sampling``) compiles the callee into
itself, so after an edit of the callee's file the caller's cache entry still holds the old
callee: the edit has no effect until the caller's file changes too (numba issue 6845).
Tests and mutation runs would then check code that is not the source.

:func:`drop_stale` makes the cache follow the sources as a whole: it keeps a digest of
every ``*.py`` file of the folder in ``__pycache__`` and, when it differs, removes the
folder's cache files (``*.nbi`` index, ``*.nbc`` code) before any kernel loads, so every
kernel recompiles once from the current sources. An installed package whose files do not
change keeps its cache; a folder that cannot be written is left as it is.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

__all__ = ["STAMP_NAME", "drop_stale", "sources_digest"]

STAMP_NAME = "kernel-sources.sha256"


def sources_digest(folder: Path) -> str:
    """SHA-256 (hex) of the names and contents of every ``*.py`` file in ``folder``.

    Parameters
    ----------
    folder : pathlib.Path
        A package folder.

    Returns
    -------
    str
        64 hex digits; it changes when any source file of the folder does.
    """
    h = hashlib.sha256()
    for path in sorted(folder.glob("*.py")):
        h.update(path.name.encode())
        h.update(b"\0")
        h.update(path.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def drop_stale(folder: Path) -> bool:
    """Remove ``folder/__pycache__``'s numba cache files if any source changed since.

    Parameters
    ----------
    folder : pathlib.Path
        The package folder whose kernels call one another across modules.

    Returns
    -------
    bool
        True when cache files were removed (or there was no stamp yet and the stamp was
        written), False when the stamp matched or the folder cannot be written.
    """
    cache = folder / "__pycache__"
    digest = sources_digest(folder)
    stamp = cache / STAMP_NAME
    try:
        if stamp.read_text(encoding="ascii") == digest:
            return False
    except (OSError, UnicodeDecodeError):
        pass
    try:
        cache.mkdir(exist_ok=True)
        for pattern in ("*.nbi", "*.nbc"):
            for entry in cache.glob(pattern):
                entry.unlink(missing_ok=True)
        temp = cache / f".{STAMP_NAME}.{os.getpid()}.tmp"
        temp.write_text(digest, encoding="ascii")
        os.replace(temp, stamp)
    except OSError:  # a read-only install: its sources do not change either
        return False
    return True
