"""Configs to and from plain data (dicts and lists, as YAML and JSON give them):
:func:`from_dict`, :func:`from_stored` and :func:`to_dict`. Every error names the field
path (``entities[1].motion.x.boundary``) and the bad value."""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from pathlib import Path
from typing import Any, Literal, get_args, get_origin

from scenegen.config.entities import EntitySpec
from scenegen.config.fields import _STORED
from scenegen.config.limits import _MAX_ENTITIES, MAX_MAGNITUDE
from scenegen.config.messages import _fail, _key, _short
from scenegen.config.scene import SceneConfig
from scenegen.config.sources import _sources_relative_to
from scenegen.errors import ConfigError

__all__ = ["from_dict", "from_stored", "to_dict"]


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


def _convert(value: Any, tp: Any, path: str) -> Any:
    origin = get_origin(tp)
    if origin is typing.Union or origin is types.UnionType:
        args = get_args(tp)
        if value is None:
            if type(None) in args:
                return None
            _fail(path, "must not be null")
        inner = [a for a in args if a is not type(None)]
        return _convert(value, inner[0], path)
    if origin is Literal:
        choices = get_args(tp)
        if value not in choices:
            _fail(path, f"must be one of {', '.join(map(str, choices))}; got {_short(value)}")
        return value
    if dataclasses.is_dataclass(tp):
        if isinstance(value, tp):
            return value
        return _build(tp, value, path)
    if origin is tuple:
        args = get_args(tp)
        if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__iter__"):
            _fail(path, f"must be a list, got {_short(value)}")
        items = list(value)
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{path}[{i}]") for i, v in enumerate(items))
        if len(items) != len(args):
            _fail(path, f"must have {len(args)} items, got {_short(items)}")
        return tuple(
            _convert(v, a, f"{path}[{i}]") for i, (v, a) in enumerate(zip(items, args, strict=True))
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
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            _fail(path, f"must be a string, got {_short(value)}")
        return value
    _fail(path, f"cannot read a value of type {_type_name(tp)}")


def _check_count(path: str, value: Any) -> None:
    """Refuse a list of more entities or clutter groups than a scene may hold before its
    items are read (a million of them would take minutes and gigabytes to refuse)."""
    if isinstance(value, (list, tuple)) and len(value) > _MAX_ENTITIES:
        _fail(
            path,
            f"at most {_MAX_ENTITIES} items, got {len(value):,} (a scene holds at most "
            f"{_MAX_ENTITIES} entities)",
        )


def _normalise_depth(value: Any) -> Any:
    # A single number is shorthand for a constant depth from frame 0.
    if _is_number(value):
        return [[0, value]]
    return value


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    """The field types of a config dataclass (resolving them costs more than a field)."""
    return typing.get_type_hints(cls)


def _build(cls: type, data: Any, path: str) -> Any:
    if not isinstance(data, dict):
        _fail(path, f"must be a mapping, got {_short(data)}")
    hints = _hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            _fail(
                f"{path}.{_key(key)}" if path else _key(key),
                f"unknown field; valid fields: {', '.join(fields)}",
            )
    kwargs = {}
    for name, f in fields.items():
        sub = f"{path}.{name}" if path else name
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                _fail(sub, "is required")
            continue
        value = data[name]
        if cls is EntitySpec and name == "depth":
            value = _normalise_depth(value)
        if cls is SceneConfig and name in ("entities", "clutter"):
            _check_count(sub, value)
        kwargs[name] = _convert(value, hints[name], sub)
    try:
        return cls(**kwargs)
    except ConfigError as err:
        msg = str(err)
        raise ConfigError(f"{path}.{msg}" if path else msg) from None


def from_dict(data: Any, *, folder: str | Path | None = None) -> SceneConfig:
    """Build and validate a :class:`SceneConfig` from plain data (as read from YAML/JSON).

    Parameters
    ----------
    data : dict
    folder : str or Path, optional
        The folder that relative image file ``source`` paths are relative to (the file the
        data came from: :func:`load_config` passes its folder): they are recorded joined
        to it (:func:`relative_to`). ``None`` leaves them as given: relative to the current
        directory when the scene is planned.

    Returns
    -------
    SceneConfig
        The validated config.

    Raises
    ------
    ConfigError
        Naming the field path and the bad value.
    """
    config = _build(SceneConfig, data, "")
    return config if folder is None else _sources_relative_to(config, Path(folder))


def from_stored(data: Any) -> SceneConfig:
    """:func:`from_dict` for a config read back from a file's ``config`` attribute.

    A field that holds a value the scene ignores (``not used by ...``; refused in a new
    config since it would be silently ignored) is tolerated here: files written before
    such a refusal existed stay readable and valid, and render as they did. Every other
    check applies.

    Parameters
    ----------
    data : dict
        The config as plain data (the parsed ``config`` attribute). Relative image file
        sources are left as given.

    Returns
    -------
    SceneConfig
        The validated config.

    Raises
    ------
    ConfigError
        Naming the field path and the bad value.
    """
    token = _STORED.set(True)
    try:
        return _build(SceneConfig, data, "")
    finally:
        _STORED.reset(token)


def _plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value):
        return {
            f.name: _plain(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if not (f.metadata.get("omit_default") and getattr(value, f.name) == f.default)
        }
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def to_dict(config: SceneConfig) -> dict[str, Any]:
    """The fully resolved config as plain data; ``from_dict(to_dict(c)) == c``.

    Parameters
    ----------
    config : SceneConfig
        The config.

    Returns
    -------
    dict of str to Any
        Every field, defaults included (but a field added after the first release, left
        out while it holds its default), nested configs as dicts and tuples as lists.
    """
    return _plain(config)
