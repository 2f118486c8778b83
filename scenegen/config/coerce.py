"""Values to their field's type: the one reading of a value as a config field's type,
used by :func:`scenegen.config.from_dict` (plain data) and by every config class on
construction (a config built in Python: ``SceneConfig(width=np.int64(320), ...)``)."""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Callable
from typing import Any, Literal, get_args, get_origin

from scenegen.config.limits import MAX_MAGNITUDE
from scenegen.config.messages import _fail, _short

__all__: list[str] = []


def _type_name(tp: Any) -> str:
    return getattr(tp, "__name__", str(tp))


def _is_integer(value: Any) -> bool:
    """An int or a numpy integer scalar, not a bool."""
    import numpy as np

    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def _is_number(value: Any) -> bool:
    """An int or float, or a numpy integer or floating scalar; not a bool."""
    import numpy as np

    return _is_integer(value) or isinstance(value, (float, np.floating))


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    """The field types of a config dataclass (resolving them costs more than a field)."""
    return typing.get_type_hints(cls)


def _convert(
    value: Any,
    tp: Any,
    path: str,
    build: Callable[[type, Any, str], Any] | None = None,
    *,
    keep_int: bool = False,
) -> Any:
    """``value`` read as type ``tp`` (int, float, bool, str, a Literal, a tuple, a union
    with None, a config dataclass); ConfigError naming ``path`` and the value otherwise.
    ``build(cls, data, path)`` makes a dataclass from a mapping (None: only an instance
    is accepted); ``keep_int`` leaves a Python int given for a float as it is (a config
    built in Python stores what it was given)."""
    origin = get_origin(tp)
    if origin is typing.Union or origin is types.UnionType:
        args = get_args(tp)
        if value is None:
            if type(None) in args:
                return None
            _fail(path, "must not be null")
        inner = [a for a in args if a is not type(None)]
        return _convert(value, inner[0], path, build, keep_int=keep_int)
    if origin is Literal:
        choices = get_args(tp)
        if not isinstance(value, str) or value not in choices:
            _fail(path, f"must be one of {', '.join(map(str, choices))}; got {_short(value)}")
        return value
    if dataclasses.is_dataclass(tp):
        if isinstance(value, tp):
            return value
        if build is None:
            _fail(path, f"must be of type {_type_name(tp)}, got {_short(value)}")
        return build(tp, value, path)
    if origin is tuple:
        args = get_args(tp)
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__iter__"):
            _fail(path, f"must be a list, got {_short(value)}")
        items = list(value)
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(
                _convert(v, args[0], f"{path}[{i}]", build, keep_int=keep_int)
                for i, v in enumerate(items)
            )
        if len(items) != len(args):
            _fail(path, f"must have {len(args)} items, got {_short(items)}")
        return tuple(
            _convert(v, a, f"{path}[{i}]", build, keep_int=keep_int)
            for i, (v, a) in enumerate(zip(items, args, strict=True))
        )
    if tp is bool:
        if not isinstance(value, bool):
            _fail(path, f"must be true or false, got {_short(value)}")
        return value
    if tp is int:
        if not _is_number(value):
            _fail(path, f"must be an integer, got {_short(value)}")
        if not _is_integer(value) and not float(value).is_integer():
            _fail(path, f"must be an integer, got {_short(value)}")
        return int(value)
    if tp is float:
        if not _is_number(value):
            _fail(path, f"must be a number, got {_short(value)}")
        if _is_integer(value) and abs(int(value)) > MAX_MAGNITUDE:
            _fail(path, f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {_short(value)}")
        if not math.isfinite(value):
            _fail(path, f"must be finite, got {_short(value)}")
        if keep_int and type(value) is int:
            return value
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            _fail(path, f"must be a string, got {_short(value)}")
        return value
    _fail(path, f"cannot read a value of type {_type_name(tp)}")


def _coerce_fields(obj: Any) -> None:
    """Read every field of config dataclass ``obj`` as its type (:func:`_convert`), in
    place: numpy scalars become Python numbers and lists tuples (else the config could
    not be written: JSON has no int64), and a value of another type or outside a
    Literal's choices is a ConfigError naming the field (it was a TypeError from a
    comparison, or accepted and ignored). The first step of every ``__post_init__``."""
    hints = _hints(type(obj))
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        new = _convert(value, hints[f.name], f.name, keep_int=True)
        if new is not value:
            object.__setattr__(obj, f.name, new)
