"""The built-in fixtures, available wherever scenegen is installed.

:func:`scenegen.testing.fixtures.definitions` defines every built-in fixture (a config
and a seed); the package ships their SHA-256 digests (``builtin_digests.json``, written by
``scenegen fixtures regen`` from the repository's registry), not the files. The first
:func:`builtin_fixture` call for a name regenerates the sequence from its definition,
checks it against the shipped digests and caches it as HDF5 in :func:`cache_dir`; later
calls read the cached file and check it again, so a damaged or stale cache entry is
regenerated, and a generator that no longer gives the same bytes is an error that names
the arrays that differ.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from scenegen.errors import DataError

__all__ = [
    "DIGESTS_FILE",
    "builtin_fixture",
    "builtin_names",
    "cache_dir",
    "differing",
    "shipped_digests",
    "write_digests",
]

DIGESTS_FILE = Path(__file__).with_name("builtin_digests.json")
_SCHEMA = "scenegen-builtin-digests/1"


def cache_dir() -> Path:
    """Where regenerated built-in fixtures are cached: ``$SCENEGEN_CACHE/fixtures``, else
    ``$XDG_CACHE_HOME/scenegen/fixtures``, else ``~/.cache/scenegen/fixtures``."""
    if os.environ.get("SCENEGEN_CACHE"):
        return Path(os.environ["SCENEGEN_CACHE"]) / "fixtures"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "scenegen" / "fixtures"


def shipped_digests() -> dict[str, dict[str, Any]]:
    """Name -> ``{"seed": int, "digests": {HDF5 path: SHA-256}}`` as shipped."""
    try:
        doc = json.loads(DIGESTS_FILE.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as err:
        raise DataError(f"{DIGESTS_FILE}: unreadable ({err}); reinstall scenegen") from None
    if doc.get("schema") != _SCHEMA:
        raise DataError(f"{DIGESTS_FILE}: schema is not {_SCHEMA!r}")
    return dict(doc["fixtures"])


def builtin_names() -> list[str]:
    """Names of the built-in fixtures (the presets' ``-small`` versions, the edge cases)."""
    return list(shipped_digests())


def write_digests(entries: dict[str, dict[str, Any]], path: Path | None = None) -> bool:
    """Write the shipped digests from registry ``entries`` (name -> entry with ``seed``
    and ``digests``); returns True if the file changed."""
    from scenegen.io.atomic import write_text

    path = DIGESTS_FILE if path is None else path
    doc = {
        "schema": _SCHEMA,
        "fixtures": {
            n: {"seed": int(e["seed"]), "digests": dict(sorted(e["digests"].items()))}
            for n, e in entries.items()
        },
    }
    text = json.dumps(doc, indent=1) + "\n"
    if path.exists() and path.read_text(encoding="utf-8") == text:
        return False
    write_text(path, text)
    return True


def differing(seq: Any, expected: dict[str, str]) -> list[str]:
    """The arrays of ``seq`` whose digests differ from ``expected`` (sorted)."""
    from scenegen.testing.fixtures import digests

    actual = digests(seq)
    return sorted(k for k in set(expected) | set(actual) if expected.get(k) != actual.get(k))


def builtin_fixture(name: str, *, cache: str | Path | None = None) -> Any:
    """The built-in fixture ``name`` as a :class:`~scenegen.sequence.Sequence` (lazy arrays
    from the cached file).

    Parameters
    ----------
    name : str
        One of :func:`builtin_names`, e.g. ``"one-pixel"``.
    cache : str or Path, optional
        The cache folder (default :func:`cache_dir`).

    Raises
    ------
    KeyError
        For an unknown name, listing the known ones.
    DataError
        If regenerating the fixture does not give the shipped digests (naming the arrays).
    """
    from scenegen.io import read, write
    from scenegen.render.plan import generate
    from scenegen.testing.fixtures import definitions

    shipped = shipped_digests()
    if name not in shipped:
        raise KeyError(f"no built-in scenegen fixture {name!r}; known: {', '.join(shipped)}")
    expected = shipped[name]["digests"]
    folder = cache_dir() if cache is None else Path(cache)
    path = folder / f"{name}.h5"
    if path.exists():
        try:
            seq = read(path)
            if not differing(seq, expected):
                return seq
            _close(seq)
        except DataError:
            pass  # a damaged cache entry is regenerated below
    d = definitions()[name]
    seq = generate(d.config, seed=int(shipped[name]["seed"]))
    bad = differing(seq, expected)
    if bad:
        raise DataError(
            f"built-in fixture {name!r}: regenerating it gives different {', '.join(bad)} "
            "than the digests shipped with scenegen (generator or numpy/numba changed?)"
        )
    folder.mkdir(parents=True, exist_ok=True)
    write(path, seq, compression="gzip")
    return read(path)


def _close(seq: Any) -> None:
    for arr in (seq.frames, seq.labels):
        if hasattr(arr, "close"):
            arr.close()
