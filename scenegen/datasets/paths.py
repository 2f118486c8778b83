"""Field paths into plain config data: ``entities[0].motion.x.sigma``, ``clutter[0].count``.

A path is a dotted list of field names with list indices in brackets. An index is a
number, or (for ``entities`` and ``clutter``) the ``name`` of an item, so
``entities[walker].position_noise`` keeps working when a preset reorders its entities.
Paths are checked against the config's dataclass types, so an unknown field names the
valid ones.

Examples
--------
>>> from scenegen import presets
>>> from scenegen.config import to_dict
>>> data = to_dict(presets.get("kams-a"))
>>> leaf_type(data, "clutter[0].count")
<class 'int'>
>>> set_path(data, "clutter[0].count", 5)
>>> data["clutter"][0]["count"]
5
"""

from __future__ import annotations

import dataclasses
import re
import types
import typing
from typing import Any, get_args, get_origin

from scenegen.config import SceneConfig
from scenegen.errors import ConfigError

__all__ = ["canonical_path", "get_path", "leaf_type", "parse_path", "set_path"]

_TOKEN = re.compile(r"\.?([A-Za-z_][A-Za-z0-9_]*)|\[([^\[\]]+)\]")


def parse_path(path: str) -> list[str | int]:
    """Split a field path into names (str) and list indices (int, or str for ``[name]``).

    Indices by name are returned as ``"[name]"`` strings.

    Parameters
    ----------
    path : str
        A field path, such as ``entities[walker].motion.x.sigma``.

    Returns
    -------
    list of (str or int)
        The tokens: ``["entities", "[walker]", "motion", "x", "sigma"]``.

    Raises
    ------
    ConfigError
        If ``path`` is not a well-formed path.
    """
    if not isinstance(path, str) or not path:
        raise ConfigError(f"field path must be a non-empty string, got {path!r}")
    out: list[str | int] = []
    pos = 0
    while pos < len(path):
        m = _TOKEN.match(path, pos)
        if m is None or (pos == 0 and path.startswith(".")):
            raise ConfigError(
                f"{path}: not a field path (expected e.g. entities[0].motion.x.sigma)"
            )
        if m.group(1) is not None:
            out.append(m.group(1))
        else:
            idx = m.group(2).strip()
            out.append(int(idx) if re.fullmatch(r"\d+", idx) else f"[{idx}]")
        pos = m.end()
    if not isinstance(out[0], str) or out[0].startswith("["):
        raise ConfigError(f"{path}: a field path starts with a field name")
    return out


def _unwrap(tp: Any) -> Any:
    origin = get_origin(tp)
    if origin is typing.Union or origin is types.UnionType:
        inner = [a for a in get_args(tp) if a is not type(None)]
        return inner[0] if len(inner) == 1 else tp
    return tp


def _walk(data: Any, path: str) -> tuple[Any, str | int, Any, str]:
    """(container, key, leaf type, path with every index a number) of ``path`` in ``data``;
    raises naming what is wrong."""
    tokens = parse_path(path)
    tp: Any = SceneConfig
    cur: Any = data
    done = ""
    canon = ""
    for i, tok in enumerate(tokens):
        last = i == len(tokens) - 1
        if isinstance(tok, str) and not tok.startswith("["):
            if not dataclasses.is_dataclass(tp):
                raise ConfigError(f"{path}: {done} has no fields (it is a value)")
            names = [f.name for f in dataclasses.fields(tp)]
            if tok not in names:
                where = done or "a scenario"
                raise ConfigError(
                    f"{path}: unknown field {tok!r} in {where}; valid fields: {', '.join(names)}"
                )
            hint = _unwrap(typing.get_type_hints(tp)[tok])
            if not isinstance(cur, dict):
                raise ConfigError(f"{path}: {done} is not a mapping")
            key: str | int = tok
            done = f"{done}.{tok}" if done else tok
            canon = f"{canon}.{tok}" if canon else tok
        else:
            if get_origin(tp) is not tuple:
                raise ConfigError(f"{path}: {done} is not a list")
            if not isinstance(cur, list):
                raise ConfigError(f"{path}: {done} is null or not a list in the base scenario")
            args = get_args(tp)
            if isinstance(tok, str):  # [name]
                wanted = tok[1:-1]
                hits = [
                    j for j, v in enumerate(cur) if isinstance(v, dict) and v.get("name") == wanted
                ]
                if not hits:
                    have = [v.get("name") for v in cur if isinstance(v, dict)]
                    raise ConfigError(
                        f"{path}: no item named {wanted!r} in {done}; names: "
                        f"{', '.join(map(str, have)) or 'none'}"
                    )
                key = hits[0]
            else:
                key = tok
                if key >= len(cur):
                    raise ConfigError(
                        f"{path}: index {key} out of range; {done} has {len(cur)} items"
                    )
            hint = args[0] if len(args) == 2 and args[1] is Ellipsis else args[key]
            hint = _unwrap(hint)
            done = f"{done}[{tok if isinstance(tok, int) else tok[1:-1]}]"
            canon = f"{canon}[{key}]"
        if last:
            return cur, key, hint, canon
        nxt = cur[key] if isinstance(cur, list) else cur.get(key)
        if nxt is None:
            raise ConfigError(f"{path}: {done} is null in the base scenario; set it first")
        cur, tp = nxt, hint
    raise AssertionError("unreachable")  # pragma: no cover


def leaf_type(data: dict[str, Any], path: str) -> Any:
    """The declared type of the field at ``path`` (Optional unwrapped).

    Parameters
    ----------
    data : dict
        Plain config data (as :func:`scenegen.config.to_dict` gives).
    path : str
        A field path into it.

    Returns
    -------
    type
        The field's type hint (``int``, ``tuple[int, int]``, a config dataclass, ...),
        ``X | None`` given as ``X``.

    Raises
    ------
    ConfigError
        Naming the path and what is wrong (unknown field, index out of range, ...).
    """
    return _walk(data, path)[2]


def canonical_path(data: dict[str, Any], path: str) -> str:
    """The field ``path`` names in ``data``, with every index a number:
    ``clutter[clutter].count`` -> ``clutter[0].count`` (two paths set the same field when
    these are equal).

    Parameters
    ----------
    data : dict
        Plain config data (as :func:`scenegen.config.to_dict` gives).
    path : str
        A field path into it.

    Returns
    -------
    str
        The path with every ``[name]`` index replaced by its item's position.

    Raises
    ------
    ConfigError
        As :func:`leaf_type`.
    """
    return _walk(data, path)[3]


def get_path(data: dict[str, Any], path: str) -> Any:
    """The value at ``path`` in plain config data.

    Parameters
    ----------
    data : dict
        Plain config data (as :func:`scenegen.config.to_dict` gives).
    path : str
        A field path into it.

    Returns
    -------
    Any
        The value (None for a field missing from a mapping).

    Raises
    ------
    ConfigError
        As :func:`leaf_type`.
    """
    cont, key, _, _ = _walk(data, path)
    return cont[key] if isinstance(cont, list) else cont.get(key)


def set_path(data: dict[str, Any], path: str, value: Any) -> None:
    """Set the value at ``path`` in plain config data, in place.

    Parameters
    ----------
    data : dict
        Plain config data (as :func:`scenegen.config.to_dict` gives); changed in place.
    path : str
        A field path into it; every field above the last must be present and not null.
    value : Any
        The new value (not validated here: :func:`scenegen.config.from_dict` does).

    Raises
    ------
    ConfigError
        As :func:`leaf_type`.
    """
    cont, key, _, _ = _walk(data, path)
    cont[key] = value
