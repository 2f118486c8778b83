"""Configs to and from plain data (dicts and lists, as YAML and JSON give them):
:func:`from_dict`, :func:`from_stored` and :func:`to_dict`. Every error names the field
path (``entities[1].motion.x.boundary``) and the bad value."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from scenegen.config import coerce
from scenegen.config.entities import EntitySpec
from scenegen.config.fields import _STORED
from scenegen.config.limits import _MAX_ENTITIES
from scenegen.config.messages import _fail, _key, _short
from scenegen.config.scene import SceneConfig
from scenegen.config.sources import _sources_relative_to
from scenegen.errors import ConfigError

__all__ = ["from_dict", "from_stored", "to_dict"]


def _convert(value: Any, tp: Any, path: str) -> Any:
    return coerce._convert(value, tp, path, _build)


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
    if coerce._is_number(value):
        return [[0, value]]
    return value


def _build(cls: type, data: Any, path: str) -> Any:
    if not isinstance(data, dict):
        _fail(path, f"must be a mapping, got {_short(data)}")
    hints = coerce._hints(cls)
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

    Raises
    ------
    ConfigError
        If ``config`` is not a :class:`SceneConfig` (plain data, a preset name, ...; it
        was returned unchanged), naming its type.
    """
    if not isinstance(config, SceneConfig):
        raise ConfigError(f"to_dict takes a SceneConfig, got a {type(config).__name__}")
    return _plain(config)
