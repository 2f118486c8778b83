"""Reading and writing config files: :func:`load_config` and :func:`load_data` read YAML
(the YAML 1.2 core schema, parsed by libyaml when PyYAML has it) or JSON within the
limits of a file (:data:`MAX_CONFIG_BYTES`, :data:`MAX_VALUES`, :data:`MAX_ALIASES`,
:data:`MAX_NODES`), refusing duplicate keys; :func:`dump_yaml` writes YAML that reads
back the same."""

from __future__ import annotations

import functools
import json
import re
from pathlib import Path
from typing import Any

from scenegen.config.messages import _excerpt, _short
from scenegen.config.plain import from_dict
from scenegen.config.scene import SceneConfig
from scenegen.errors import ConfigError

__all__ = [
    "MAX_ALIASES",
    "MAX_CONFIG_BYTES",
    "MAX_NODES",
    "MAX_VALUES",
    "dump_yaml",
    "json_object",
    "load_config",
    "load_data",
]

MAX_CONFIG_BYTES = 4 * 2**20
"""Largest config (or family) file read, in bytes."""
MAX_ALIASES = 1000
"""Most YAML aliases (``*name``) in one config."""
MAX_NODES = 100_000
"""Most YAML nodes that aliases may add to a config once expanded: a few hundred bytes of
nested aliases ("billion laughs") would otherwise expand to billions of values. A document
without aliases is bounded by :data:`MAX_CONFIG_BYTES` and :data:`MAX_VALUES` alone, as a
JSON one is."""


MAX_VALUES = 250_000
"""Most values (mappings, lists, keys and scalars) in one config or family file, YAML or
JSON alike, counted as the file is read: a file of a million list items is refused up
front rather than taking a minute and a gigabyte to read (a YAML value costs about a
kilobyte while it is read). The largest preset has under 1,000."""

_YAML_CORE = (
    ("bool", r"true|True|TRUE|false|False|FALSE", "tTfF"),
    ("int", r"[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+", "-+0123456789"),
    ("float", r"[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
              r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN)", "-+0123456789."),
    ("null", r"~|null|Null|NULL|", "~nN"),
)  # fmt: skip
"""The plain scalars that are not strings in the YAML 1.2 core schema (tag, pattern, first
characters; an empty scalar is also null): ``010`` is 10, ``0o10`` 8, ``1e9`` a float,
and ``yes``, ``no``, ``on``, ``off``, ``1_000``, ``1:30`` and ``2024-01-01`` are strings
(YAML 1.1, PyYAML's default, reads them as booleans, numbers and dates)."""


@functools.cache
def _yaml_core() -> tuple[type, type]:
    """The YAML loader and dumper of configs: PyYAML's safe ones with the implicit scalars
    of the YAML 1.2 core schema (:data:`_YAML_CORE`). The dumper quotes a string that
    either YAML 1.1 or 1.2 would read as something else, so what it writes reads back the
    same here and in any YAML reader."""
    import yaml

    class CoreLoader(yaml.SafeLoader):
        pass

    class CoreDumper(yaml.SafeDumper):
        pass

    # YAML 1.1's implicit booleans, numbers, dates and '=' go; merge keys ('<<') stay.
    CoreLoader.yaml_implicit_resolvers = {
        first: [(tag, rx) for tag, rx in resolvers if tag == "tag:yaml.org,2002:merge"]
        for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
    }
    for name, pattern, first in _YAML_CORE:
        rx = re.compile(f"^(?:{pattern})$")
        starts = [*first, ""] if name == "null" else list(first)
        for cls in (CoreLoader, CoreDumper):
            cls.add_implicit_resolver(f"tag:yaml.org,2002:{name}", rx, starts)

    def construct_int(loader: Any, node: Any) -> int:
        text = loader.construct_scalar(node)
        if text[:2] in ("0o", "0x"):
            return int(text[2:], 8 if text[1] == "o" else 16)
        return int(text, 10)  # a leading zero is decimal: 010 is 10

    CoreLoader.add_constructor("tag:yaml.org,2002:int", construct_int)
    return CoreLoader, CoreDumper


def dump_yaml(data: Any) -> str:
    """``data`` (plain data, as :func:`to_dict` gives) as YAML text that :func:`load_data`
    reads back equal: a string such as ``'1e9'``, ``'no'`` or ``'010'`` is quoted.

    Parameters
    ----------
    data : Any
        Plain data: dicts, lists, strings, numbers, booleans and None.

    Returns
    -------
    str
        The YAML text, keys in their given order.
    """
    import yaml

    return yaml.dump(data, Dumper=_yaml_core()[1], sort_keys=False)


def _too_many_values() -> ConfigError:
    return ConfigError(f"more than {MAX_VALUES:,} values (lists, mappings, keys, scalars)")


def _count_values(data: Any) -> None:
    """Raise :func:`_too_many_values` if ``data`` (as JSON gives it) holds more than
    :data:`MAX_VALUES` values, counted as a YAML file's are."""
    count, stack = 0, [data]
    while stack:
        value = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise _too_many_values()
        if isinstance(value, dict):
            count += len(value)  # the keys
            stack.extend(value.values())
        elif isinstance(value, list):
            stack.extend(value)


def _core_parsing_loader() -> type:
    """The loader class :func:`_load_yaml` builds on: :func:`_yaml_core`'s loader, its
    scanning and parsing done by libyaml when PyYAML has it (the pure-Python scanner took
    about 17 of the 23 s a 240,000-value file cost; libyaml makes it 2.5 s). Composing
    stays in Python (PyYAML's ``Composer`` over libyaml's events), so the value and alias
    counts below see every node as it is composed and stop a large document early."""
    import yaml

    core = _yaml_core()[0]
    if not getattr(yaml, "__with_libyaml__", False):
        return core
    from yaml._yaml import CParser

    class CoreParsingLoader(
        yaml.composer.Composer, CParser, yaml.constructor.SafeConstructor, yaml.resolver.Resolver
    ):
        yaml_implicit_resolvers = core.yaml_implicit_resolvers
        yaml_constructors = core.yaml_constructors

        def __init__(self, stream: str) -> None:
            CParser.__init__(self, stream)
            yaml.composer.Composer.__init__(self)
            yaml.constructor.SafeConstructor.__init__(self)
            yaml.resolver.Resolver.__init__(self)

    return CoreParsingLoader


def _load_yaml(text: str) -> Any:
    """The data of a YAML document read with the YAML 1.2 core schema (:func:`_yaml_core`),
    at most :data:`MAX_VALUES` values, the alias count and the expansion bounded, and
    duplicate keys refused."""
    import yaml

    class Loader(_core_parsing_loader()):  # type: ignore[misc]
        aliases = 0
        values = 0

        def compose_node(self, parent: Any, index: Any) -> Any:
            if self.check_event(yaml.AliasEvent):
                Loader.aliases += 1
                if Loader.aliases > MAX_ALIASES:
                    raise ConfigError(f"more than {MAX_ALIASES} YAML aliases")
            else:
                Loader.values += 1
                if Loader.values > MAX_VALUES:
                    raise _too_many_values()
            return super().compose_node(parent, index)

        def construct_mapping(self, node: Any, deep: bool = False) -> Any:
            if isinstance(node, yaml.MappingNode):
                seen: set[Any] = set()
                for key_node, _ in node.value:
                    if key_node.tag == "tag:yaml.org,2002:merge":
                        continue  # '<<' merges keys that the mapping's own may override
                    key = self.construct_object(key_node, deep=True)
                    try:
                        if key in seen:
                            line = key_node.start_mark.line + 1
                            raise ConfigError(f"duplicate key {_short(key)} (line {line})")
                        seen.add(key)
                    except TypeError:  # an unhashable key: the constructor names it
                        pass
            return super().construct_mapping(node, deep=deep)

    loader = Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _expanded_size(node)
        return loader.construct_document(node)
    finally:
        loader.dispose()


def _expanded_size(root: Any) -> int:
    """Nodes of a composed YAML document with every alias expanded (shared nodes counted
    once per reference); raises ConfigError when the aliases add more than MAX_NODES to
    the document's own nodes, or on a recursive alias."""
    import yaml

    sizes: dict[int, int] = {}
    active: set[int] = set()
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            active.discard(key)
            if isinstance(node, yaml.MappingNode):
                children = [c for pair in node.value for c in pair]
            elif isinstance(node, yaml.SequenceNode):
                children = node.value
            else:
                children = []
            total = 1 + sum(sizes[id(c)] for c in children)
            # A node's subtree has at most len(sizes) + 1 distinct nodes so far: what the
            # aliases added is at least total minus that, and exactly so at the root.
            if total - (len(sizes) + 1) > MAX_NODES:
                raise ConfigError(f"the YAML's aliases expand to more than {MAX_NODES:,} values")
            sizes[key] = total
            continue
        if key in sizes:
            continue
        if key in active:
            raise ConfigError("a YAML alias refers to a node that contains it")
        active.add(key)
        stack.append((node, True))
        if isinstance(node, yaml.MappingNode):
            stack.extend((c, False) for pair in node.value for c in pair)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((c, False) for c in node.value)
    return sizes[id(root)]


def json_object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object, refusing a key given twice (``json.loads`` would keep the last): the
    ``object_pairs_hook`` of every JSON file scenegen reads.

    Parameters
    ----------
    pairs : list of tuple of (str, Any)
        The object's key-value pairs, in file order.

    Returns
    -------
    dict of str to Any
        The object.

    Raises
    ------
    ConfigError
        ``duplicate key 'NAME'``.
    """
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise ConfigError(f"duplicate key {_short(k)}")
        out[k] = v
    return out


def _parser_message(err: Exception) -> str:
    """One line of a YAML or JSON parser's error: what is wrong, and where."""
    problem, mark = getattr(err, "problem", None), getattr(err, "problem_mark", None)
    if isinstance(problem, str) and problem:  # yaml's MarkedYAMLError: several lines
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        return f"{problem}{where}"
    lines = [line.strip() for line in str(err).splitlines() if line.strip()]
    return " ".join(lines) or type(err).__name__


def load_data(path: str | Path, what: str = "config") -> Any:
    """The plain data of a YAML (``.yaml``/``.yml``) or JSON (``.json``) file, unvalidated.

    The file must be UTF-8 text (a byte-order mark is allowed, in JSON too) of at most
    :data:`MAX_CONFIG_BYTES` holding at most :data:`MAX_VALUES` values; YAML aliases are
    bounded (:data:`MAX_ALIASES`, :data:`MAX_NODES`) and a key given twice in one mapping
    is refused, in YAML and JSON alike. YAML is read with the YAML 1.2 core schema
    (:data:`_YAML_CORE`): ``010`` is 10 and ``no`` a string, where YAML 1.1 read 8 and
    false. Scenario configs (:func:`load_config`) and family files
    (:func:`scenegen.datasets.load_family`) are read by it.

    Parameters
    ----------
    path : str or Path
    what : str, default "config"
        What the file holds, for messages ("config", "family").

    Returns
    -------
    Any
        The file's data as parsed: dicts, lists, strings, numbers, booleans and None
        (never None itself: an empty YAML document or a bare ``null`` is refused).

    Raises
    ------
    ConfigError
        One line naming the file: not a regular file (a FIFO, a device), unreadable, too
        big, not UTF-8, another extension, empty (or a bare ``null``), not valid YAML/JSON
        (the parser's problem and its line and column), more than :data:`MAX_VALUES`
        values, an alias bomb or a duplicate key.
    """
    from scenegen.io.atomic import describe_special_file

    p = Path(path)
    special = describe_special_file(p)
    if special is not None:  # a FIFO waits for a writer; /dev/zero never ends
        raise ConfigError(special)
    try:
        if p.stat().st_size > MAX_CONFIG_BYTES:
            raise ConfigError(
                f"{p}: {what} is {p.stat().st_size:,} bytes, more than {MAX_CONFIG_BYTES:,}"
            )
        text = p.read_text(encoding="utf-8-sig")  # a byte-order mark (Notepad's) is dropped
    except OSError as err:
        raise ConfigError(f"{p}: cannot read {what}: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        raise ConfigError(f"{p}: {what} is not UTF-8 text ({err.reason})") from None
    try:
        if p.suffix.lower() in (".yaml", ".yml"):
            data = _load_yaml(text)
            if data is None:  # no document, or only comments, or a bare null
                raise ConfigError(f"{what} is empty (a YAML mapping of fields is expected)")
            return data
        if p.suffix.lower() == ".json":
            data = json.loads(text, object_pairs_hook=json_object)
            if data is None:  # a bare null, as in YAML
                raise ConfigError(f"{what} is empty (a JSON object of fields is expected)")
            _count_values(data)
            return data
        raise ConfigError(f"{p}: {what} must be .yaml, .yml or .json, got {_short(p.suffix)}")
    except ConfigError as err:
        raise ConfigError(str(err) if str(err).startswith(f"{p}: ") else f"{p}: {err}") from None
    except Exception as err:  # parser errors of yaml/json: report as one line
        msg = _excerpt(_parser_message(err))
        raise ConfigError(f"{p}: not valid {p.suffix[1:].upper()}: {msg}") from None


def load_config(path: str | Path, *, folder: str | Path | None = None) -> SceneConfig:
    """Read a YAML (``.yaml``/``.yml``) or JSON (``.json``) config file and validate it.

    A relative image file ``source`` is relative to the config file's folder, not to the
    current directory, and the config records it as an absolute path (so the scene can be
    generated, and its file re-rendered by ``validate --deep``, from any directory).

    Parameters
    ----------
    path : str or Path
    folder : str or Path, optional
        Join relative sources to this folder instead of the file's absolute folder (a
        family keeps them relative to its own file: :func:`from_dict`).

    Returns
    -------
    SceneConfig
        The validated config.

    Raises
    ------
    ConfigError
        If the file cannot be read or parsed (:func:`load_data`), or the config is
        invalid (message prefixed with the file name).
    """
    p = Path(path)
    data = load_data(p, "config")
    try:
        return from_dict(data, folder=p.absolute().parent if folder is None else folder)
    except ConfigError as err:
        raise ConfigError(f"{p}: {err}") from None
