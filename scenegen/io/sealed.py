"""Sealed JSON documents: a SHA-256 digest inside the file, over its canonical content.

A *sealed* document is a JSON object with one more top-level key, ``sha256``: the hex
SHA-256 of the object's **canonical** JSON without that key (keys sorted, no spaces,
ASCII with ``\\u`` escapes, no NaN or infinities). The digest lives in the file itself,
so it is replaced together with the content by one atomic write
(:func:`scenegen.io.atomic.write_json`), and the file stays plain JSON that users can
read. A reader parses the file, recomputes the digest of what it parsed and compares:
any change to the content (a truncation, a zeroed block, a flipped bit, an edited value)
is found, while a change of layout alone (indentation, key order) changes nothing that a
reader sees and passes.

:func:`read_sealed_json` returns the content without the digest or raises one
:class:`~scenegen.errors.DataError` line naming the file and the problem; a readable
object without a digest (a file written before digests existed, or a digest removed)
raises its subclass :class:`Unsealed`, so that callers can choose what old files mean.
Parsing is bounded: at most :data:`MAX_BYTES`, and nesting deeper than Python's
recursion limit, duplicate keys or NaN are refused with one line.

Examples
--------
>>> import tempfile, pathlib
>>> folder = tempfile.TemporaryDirectory()
>>> p = pathlib.Path(folder.name) / "run.json"
>>> digest = write_sealed_json(p, {"a": [1, 2.5]})
>>> read_sealed_json(p)
{'a': [1, 2.5]}
>>> folder.cleanup()
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from scenegen.config import json_object
from scenegen.errors import DataError
from scenegen.io.atomic import SpecialFile, describe_special_file, read_regular, write_json

__all__ = [
    "MAX_BYTES",
    "SEAL",
    "Unsealed",
    "canonical",
    "check_sealed_json",
    "content_digest",
    "read_sealed_json",
    "seal",
    "write_sealed_json",
]

SEAL = "sha256"
"""Top-level key of a sealed document: hex SHA-256 of the rest, canonically serialised."""
MAX_BYTES = 256 * 1024 * 1024
"""Largest sealed document read (a bound on memory for a damaged or hostile file)."""
_HEX64 = re.compile(r"[0-9a-f]{64}")


class Unsealed(DataError):
    """A readable JSON object without a digest: written before digests, or stripped."""


def canonical(data: Any) -> bytes:
    """The canonical JSON bytes of ``data`` (sorted keys, no spaces, ASCII, no NaN).

    Parameters
    ----------
    data : object
        A JSON value (dict, list, tuple, str, int, float, bool or None, nested).

    Returns
    -------
    bytes
        ASCII JSON, non-ASCII characters as ``\\u`` escapes.

    Raises
    ------
    ValueError
        For NaN or infinite floats; TypeError for values that are not JSON.

    Examples
    --------
    >>> canonical({"b": 1, "a": [1.5, "é"]})
    b'{"a":[1.5,"\\\\u00e9"],"b":1}'
    """
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      allow_nan=False)  # fmt: skip
    return text.encode("ascii")


def content_digest(data: Mapping[str, Any]) -> str:
    """Hex SHA-256 of the canonical JSON of ``data`` without its :data:`SEAL` key.

    Parameters
    ----------
    data : mapping
        A JSON object, sealed or not.

    Returns
    -------
    str
        64 lowercase hex digits.

    Raises
    ------
    ValueError, TypeError
        As :func:`canonical`.
    """
    body = {k: v for k, v in data.items() if k != SEAL}
    return hashlib.sha256(canonical(body)).hexdigest()


def seal(data: Mapping[str, Any]) -> dict[str, Any]:
    """A copy of ``data`` (a JSON object) with its :data:`SEAL` key set to its digest.

    The content is normalised through JSON first (tuples become lists, keys strings), so
    the digest is the one a reader of the written file recomputes.

    Parameters
    ----------
    data : mapping
        A JSON object; a :data:`SEAL` key it holds is replaced.

    Returns
    -------
    dict
        The normalised content plus :data:`SEAL`, the hex digest of the rest.

    Raises
    ------
    ValueError, TypeError
        As :func:`canonical`.
    """
    body = json.loads(canonical({k: v for k, v in data.items() if k != SEAL}))
    body[SEAL] = hashlib.sha256(canonical(body)).hexdigest()
    return body


def write_sealed_json(
    path: str | Path, data: Mapping[str, Any], *, indent: int | None = None,
    parents: bool = False,
) -> str:
    """Write ``data`` sealed (:func:`seal`) to ``path`` atomically; return the digest.

    Parameters
    ----------
    path : str or Path
    data : mapping
        A JSON object (no NaN or infinities).
    indent : int, optional
        As :func:`scenegen.io.atomic.write_json` (None: one compact line).
    parents : bool
        Create missing parent folders first.

    Returns
    -------
    str
        The digest written (64 lowercase hex digits).

    Raises
    ------
    ValueError
        For NaN or infinite values.
    TypeError
        For values that are not JSON.
    ConfigError
        As :func:`scenegen.io.atomic.write_text`.
    """
    doc = seal(data)
    write_json(path, doc, indent=indent, parents=parents)
    return str(doc[SEAL])


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def _parse(p: Path) -> Any:
    """The JSON value in ``p``, or one DataError line."""
    if not p.exists():
        raise DataError(f"{p}: no such file")
    if p.is_dir():
        raise DataError(f"{p}: is a folder, not a JSON file")
    special = describe_special_file(p)
    if special is not None:  # a FIFO waits for a writer; /dev/zero never ends
        raise SpecialFile(special)
    try:
        size = p.stat().st_size
        if size > MAX_BYTES:
            raise DataError(f"{p}: too large for a JSON document ({size} bytes, at most "
                            f"{MAX_BYTES})")  # fmt: skip
        raw = read_regular(p)
    except OSError as err:
        raise DataError(f"{p}: unreadable ({err.strerror or type(err).__name__})") from None
    if not raw.strip():
        raise DataError(f"{p}: empty file (truncated?)")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise DataError(f"{p}: not a readable JSON file (not UTF-8 at byte {err.start})") from None
    try:
        return json.loads(text, object_pairs_hook=json_object, parse_constant=_no_constant)
    except json.JSONDecodeError as err:
        msg = err.msg.removesuffix(" at")
        raise DataError(f"{p}: not a readable JSON file ({msg} at line {err.lineno} "
                        f"column {err.colno}: truncated or damaged)") from None  # fmt: skip
    except RecursionError:
        raise DataError(f"{p}: not a readable JSON file (nested too deeply)") from None
    except ValueError as err:
        raise DataError(f"{p}: not a readable JSON file ({err})") from None


def read_sealed_json(path: str | Path) -> dict[str, Any]:
    """The content of the sealed document at ``path``, without its digest.

    Parameters
    ----------
    path : str or Path
        The JSON file.

    Returns
    -------
    dict
        The JSON object without its :data:`SEAL` key.

    Raises
    ------
    Unsealed
        The file is a readable JSON object without a :data:`SEAL` key.
    DataError
        Missing, unreadable, not JSON, not an object, or its content does not match its
        digest: one line naming the file and the problem.
    """
    p = Path(path)
    data = _parse(p)
    if not isinstance(data, dict):
        raise DataError(f"{p}: not a sealed JSON document (a JSON object is expected, found "
                        f"{type(data).__name__})")  # fmt: skip
    if SEAL not in data:
        raise Unsealed(f"{p}: no {SEAL} digest (written by an older version of scenegen, "
                       "or edited)")  # fmt: skip
    stored = data.pop(SEAL)
    if not isinstance(stored, str) or not _HEX64.fullmatch(stored):
        raise DataError(f"{p}: malformed {SEAL} digest (damaged or edited)")
    try:
        actual = hashlib.sha256(canonical(data)).hexdigest()
    except (ValueError, TypeError, RecursionError) as err:
        raise DataError(f"{p}: not a sealed JSON document ({type(err).__name__})") from None
    if actual != stored:
        raise DataError(f"{p}: content does not match its {SEAL} digest (damaged or edited)")
    return data


def check_sealed_json(path: str | Path) -> list[str]:
    """Problems of the sealed document at ``path``: empty when it reads and matches its
    digest, else one line (see :func:`read_sealed_json`).

    Parameters
    ----------
    path : str or Path
        The JSON file.

    Returns
    -------
    list of str
        No line, or one naming the file and the problem (an unsealed file included).
    """
    try:
        read_sealed_json(path)
    except DataError as err:
        return [str(err)]
    return []
