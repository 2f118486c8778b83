"""Error messages of configs: the one-line ConfigError naming a field path, and the short
escaped excerpts of bad values (and keys, and parser messages) that messages echo."""

from __future__ import annotations

import reprlib
import typing
from typing import Any

from scenegen.errors import ConfigError

__all__ = ["SHORT"]


def _fail(path: str, msg: str) -> typing.NoReturn:
    raise ConfigError(f"{path}: {msg}" if path else msg)


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxstring, _REPR.maxlong, _REPR.maxother = 2, 30, 30, 30
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = _REPR.maxset = 4
SHORT = 60
"""Most characters of a value echoed in an error message (:func:`_short`)."""


def _short(value: Any) -> str:
    """A short, escaped, one-line excerpt of ``value`` for error messages.

    Never longer than :data:`SHORT` characters plus a length note, never more than one
    line (``repr`` escapes newlines and other control characters), and cheap on huge or
    deeply nested values (only the first few items of the first levels are looked at).
    """
    try:
        text = _REPR.repr(value)
    except Exception:  # a value whose repr fails or recurses without end
        text = f"<{type(value).__name__}>"
    text = text.encode("ascii", "backslashreplace").decode("ascii")
    if len(text) > SHORT:
        text = f"{text[: SHORT - 3]}..."
    if isinstance(value, (str, bytes)) and len(value) > _REPR.maxstring:
        text += f" ({len(value)} characters)"
    elif isinstance(value, (list, tuple, dict, set)) and len(value) > _REPR.maxlist:
        text += f" ({len(value)} items)"
    return text


def _excerpt(text: str, limit: int = 150) -> str:
    """A message of a parser, escaped to one ASCII line and cut to ``limit`` characters."""
    text = text.encode("ascii", "backslashreplace").decode("ascii")
    return text if len(text) <= limit else f"{text[: limit - 3]}..."


def _key(key: Any) -> str:
    """A mapping key as it appears in a field path: plain when it is a simple name,
    else a short escaped excerpt (a key may hold newlines, quotes or megabytes)."""
    if isinstance(key, str) and key.isidentifier() and len(key) <= 40 and key.isascii():
        return key
    return _short(key)
