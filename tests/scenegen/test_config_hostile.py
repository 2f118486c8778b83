"""Hostile configs: every rejection is one escaped line under 300 characters, values are
echoed as short excerpts, YAML alias expansion is bounded, and names are what HDF5
accepts (no NUL, no '/', not '.' or '..'); the CLI exits 2 on all of them.

The fuzz tests run a few hundred examples in the fast suite and 10,000 in the slow one.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import re
import time

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegen import presets
from scenegen.cli import main
from scenegen.config import MAX_ALIASES, MAX_NAME, SceneConfig, from_dict, load_config
from scenegen.config import to_dict as plain
from scenegen.config.messages import _short
from scenegen.errors import ConfigError

SMALL = {
    "name": "s", "width": 32, "height": 24, "n_frames": 2,
    "entities": [{"name": "a", "role": "target", "position": [10, 10]},
                 {"name": "b", "role": "distractor", "position": [20, 10], "depth": 1}],
    "clutter": [{"count": 2, "name": "c"}],
}  # fmt: skip
BASES = [SMALL, *(plain(presets.get(n)) for n in ("dps-synthetic", "kams-a", "shm-crossing"))]

NASTY = [".", "..", "a/b", "/", "a\x00b", "\x00", "x\ny", "\r", "\u2028", "\t", "", " ", "'",
         '"', "\\", "é", "\ud7ff", "x" * 5000, "{value!r}", "%s", "a" * (MAX_NAME + 1)]  # fmt: skip
hostile_text = st.text(max_size=40) | st.sampled_from(NASTY)
hostile_leaves = (
    hostile_text
    | st.integers(min_value=-(10**600), max_value=10**600)
    | st.floats()
    | st.none()
    | st.booleans()
)
hostile_values = st.recursive(
    hostile_leaves,
    lambda inner: st.lists(inner, max_size=6) | st.dictionaries(hostile_text, inner, max_size=4),
    max_leaves=30,
)


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*prefix, i))


@st.composite
def hostile_configs(draw):
    """A valid config with one to three values, keys or names replaced by hostile ones."""
    data = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(list(_paths(data))[1:]))
        parent = data
        for p in path[:-1]:
            parent = parent[p]
        key = path[-1]
        op = draw(st.sampled_from(["value", "key", "name", "deep"]))
        if op == "value":
            parent[key] = draw(hostile_values)
        elif op == "key" and isinstance(parent, dict):
            parent[draw(hostile_text)] = parent.pop(key)
        elif op == "name" and isinstance(parent, dict) and "name" in parent:
            parent["name"] = draw(hostile_text)
        elif op == "deep":
            value = draw(hostile_leaves)
            for _ in range(draw(st.integers(50, 400))):
                value = [value]
            parent[key] = value
    return data


def one_line(message: str) -> None:
    assert message and "\n" not in message and "\r" not in message and "\u2028" not in message
    assert len(message) < 300, message


TIMES: list[float] = []


def check(data) -> None:
    start = time.perf_counter()
    try:
        cfg = from_dict(data)
    except ConfigError as err:
        one_line(str(err))
    else:
        assert isinstance(cfg, SceneConfig)
        for name in [cfg.name, *(e.name for e in cfg.entities), *(c.name for c in cfg.clutter)]:
            assert name not in (".", "..") and "/" not in name and "\x00" not in name
    TIMES.append(time.perf_counter() - start)


@settings(max_examples=200)
@given(hostile_configs())
def test_hostile_configs_are_valid_or_one_short_line(data):
    check(data)


@settings(max_examples=100)
@given(st.dictionaries(hostile_text, hostile_values, max_size=6))
def test_hostile_top_level_data(data):
    check(data)


@pytest.mark.slow
@settings(max_examples=10_000)
@given(hostile_configs() | st.dictionaries(hostile_text, hostile_values, max_size=6))
def test_ten_thousand_hostile_configs(data):
    check(data)


@pytest.mark.slow
def test_slowest_config_of_the_slow_run_is_reported(capsys):
    """Not a timing assertion: prints how many examples ran and the slowest one."""
    with capsys.disabled():
        print(f"\nhostile configs: {len(TIMES)} examples, slowest {max(TIMES):.3f} s")
    assert len(TIMES) >= 10_000


def test_short_is_short_and_escaped():
    assert _short("abc") == "'abc'"
    assert _short([1, 2]) == "[1, 2]"
    for value in ["x\ny" * 10_000, list(range(10**5)), 10**5000, [[[[[[1]]]]]] * 10**4,
                  {"k\n": "v"}, "\x00\u2028"]:  # fmt: skip
        text = _short(value)
        assert len(text) < 100 and text.isascii() and "\n" not in text
    deep: list = []
    for _ in range(100_000):
        deep = [deep]
    assert len(_short(deep)) < 100


@pytest.mark.parametrize(
    ("name", "needle"),
    [
        (".", "must not be '.' or '..'"),
        ("..", "must not be '.' or '..'"),
        ("a/b", "must not contain '/'"),
        ("a\x00b", "must not contain a NUL character, got 'a\\x00b'"),
        ("x\ny", "must be printable"),
        ("", "must not be empty"),
        ("n" * (MAX_NAME + 1), f"must be at most {MAX_NAME} characters"),
    ],
)
@pytest.mark.parametrize("where", ["name", "entities[0].name", "clutter[0].name"])
def test_names_hdf5_refuses_are_rejected(name, needle, where):
    data = copy.deepcopy(SMALL)
    if where == "name":
        data["name"] = name
    elif where.startswith("entities"):
        data["entities"][0]["name"] = name
    else:
        data["clutter"][0]["name"] = name
    with pytest.raises(ConfigError) as err:
        from_dict(data)
    one_line(str(err.value))
    assert str(err.value).startswith(f"{where}: ") and needle in str(err.value)


def test_keys_are_escaped():
    with pytest.raises(ConfigError) as err:
        from_dict({**SMALL, "bo\ngus" * 100: 1})
    one_line(str(err.value))
    assert str(err.value).startswith("'bo\\ngusbo\\ng")


def test_a_huge_value_is_an_excerpt():
    with pytest.raises(ConfigError) as err:
        from_dict({**SMALL, "width": "w" * 10**6})
    assert str(err.value).startswith("width: must be an integer, got 'wwww")
    assert "(1000000 characters)" in str(err.value)
    one_line(str(err.value))


LAUGHS = "\n".join(
    ["width: 32", "height: 24", "n_frames: 2", 'l0: &l0 ["lol","lol","lol","lol","lol","lol"]']
    + [f"l{i}: &l{i} [" + ",".join([f"*l{i - 1}"] * 9) + "]" for i in range(1, 9)]
)


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        (LAUGHS, "the YAML's aliases expand to more than 100,000 values"),
        ("a: &a [1]\nb: [" + ",".join(["*a"] * (MAX_ALIASES + 1)) + "]",
         f"more than {MAX_ALIASES} YAML aliases"),
        ("a: &a\n  - *a\n", "a YAML alias refers to a node that contains it"),
    ],
)  # fmt: skip
def test_yaml_alias_expansion_is_bounded(tmp_path, text, needle, capsys):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_config(path)
    assert str(err.value) == f"{path}: {needle}"
    assert main(["generate", "--config", str(path), "-o", str(tmp_path / "o.h5")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and needle in lines[0]


def test_six_levels_of_aliases_inside_a_field_give_a_short_line(tmp_path):
    levels = ['x: &l0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    levels += [f"x{i}: &l{i} [" + ",".join([f"*l{i - 1}"] * 9) + "]" for i in range(1, 4)]
    text = "\n".join(levels) + "\nwidth: *l3\nheight: 10\nn_frames: 1\n"
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_config(path)
    one_line(str(err.value))
    assert "unknown field" in str(err.value) or "must be an integer" in str(err.value)


@pytest.mark.parametrize("name", [".", "a\x00b", "a/b"])
def test_generate_exits_2_on_names_hdf5_refuses(tmp_path, name):
    path = tmp_path / "c.json"
    path.write_text(json.dumps({**SMALL, "name": name}))
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["generate", "--config", str(path), "-o", str(tmp_path / "o.h5")])
    assert code == 2 and len(err.getvalue().splitlines()) == 1
    assert not (tmp_path / "o.h5").exists()


def test_a_config_file_that_is_too_big_or_not_text(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"#" * (5 * 2**20))
    with pytest.raises(ConfigError, match="more than 4,194,304"):
        load_config(path)
    path.write_bytes(b"width: \xff\xfe\n")
    with pytest.raises(ConfigError, match="not UTF-8 text"):
        load_config(path)


@settings(max_examples=50)
@given(hostile_configs())
def test_hostile_configs_through_yaml_files(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("h") / "c.yaml"
    try:
        path.write_text(yaml.safe_dump(data), encoding="utf-8")
    except (UnicodeEncodeError, yaml.YAMLError, RecursionError):
        return  # not representable as a YAML file (lone surrogates, too deep)
    try:
        load_config(path)
    except ConfigError as err:
        one_line(str(err))


def test_huge_numbers_in_messages_are_cut_short():
    # Found by the slow fuzz run: background.low/high echoed a 300-digit integer in full.
    import scenegen

    huge = 10**300
    for cfg in ({"width": 64, "height": 48, "n_frames": 2,
                 "background": {"low": 0, "high": huge}},):
        try:
            from_dict(cfg)
        except ConfigError as err:
            assert len(str(err)) < 300 and "background.low" in str(err)
        else:
            raise AssertionError("accepted a high of 10**300")
    for kwargs in ({"seed": -huge}, {"seed": 0, "frames": -huge}):
        with pytest.raises(ConfigError) as info:
            scenegen.generate("kams-a", **kwargs)
        assert len(str(info.value)) < 300


def test_a_large_document_without_aliases_reads_as_its_json_does(tmp_path):
    # 40,000 depth keyframes: ~120,000 YAML nodes, no alias; the byte limit bounds it.
    data = {**SMALL, "n_frames": 3}
    data["entities"] = [{**SMALL["entities"][0], "depth": [[2 * i, i] for i in range(40_000)]},
                        {**SMALL["entities"][1], "depth": [[0, 10**6]]}]  # fmt: skip
    as_yaml, as_json = tmp_path / "c.yaml", tmp_path / "c.json"
    as_yaml.write_text(yaml.safe_dump(data))
    as_json.write_text(json.dumps(data))
    assert 400_000 < as_yaml.stat().st_size < 4 * 2**20
    from_yaml = load_config(as_yaml)  # once: composing 120,000 nodes takes seconds
    assert from_yaml == load_config(as_json)
    assert len(from_yaml.entities[0].depth) == 40_000


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_a_million_list_items_are_refused_up_front(tmp_path, suffix, capsys):
    # 3 MB of "{}" items: the YAML took 90 s and 1.2 GB to compose before the first item
    # was found wanting; now both formats stop at MAX_VALUES, in seconds.
    from scenegen.config import MAX_VALUES

    path = tmp_path / f"c{suffix}"
    items = ",".join(["{}"] * 10**6)
    path.write_text(f'{{"width": 40, "height": 30, "n_frames": 3, "entities": [{items}]}}')
    start = time.perf_counter()
    with pytest.raises(ConfigError) as err:
        load_config(path)
    # With libyaml's parser the composer reaches 250,000 values in seconds; PyYAML's own
    # parser takes longer.
    assert time.perf_counter() - start < (20 if yaml.__with_libyaml__ else 120)
    needle = f"more than {MAX_VALUES:,} values (lists, mappings, keys, scalars)"
    assert str(err.value) == f"{path}: {needle}"
    assert main(["generate", "--config", str(path), "-o", str(tmp_path / "o.h5")]) == 2
    assert len(capsys.readouterr().err.splitlines()) == 1


@pytest.mark.parametrize("libyaml", [True, False])
def test_the_value_limit_is_counted_while_composing(monkeypatch, libyaml):
    # With libyaml's parser or PyYAML's own, the composer counts every node it makes.
    from scenegen.config import files

    if libyaml and not yaml.__with_libyaml__:
        pytest.skip("PyYAML without libyaml")
    monkeypatch.setattr(yaml, "__with_libyaml__", libyaml)
    monkeypatch.setattr(files, "MAX_VALUES", 50)
    with pytest.raises(ConfigError, match="^more than 50 values"):
        files._load_yaml("a: [" + ",".join(["1"] * 60) + "]")
    assert files._load_yaml("a: [" + ",".join(["1"] * 40) + "]") == {"a": [1] * 40}


def test_libyaml_and_pyyaml_parse_a_config_alike():
    # The loader parses with libyaml when PyYAML has it: the same data, the same core
    # schema scalars, merge keys and duplicate-key refusal as PyYAML's own parser.
    from scenegen.config import files

    if not yaml.__with_libyaml__:
        pytest.skip("PyYAML without libyaml")
    assert files._core_parsing_loader() is not files._yaml_core()[0]
    text = (
        "base: &b {x: 1, on: yes, n: 010, h: 0x1f, f: 1e3, d: 2024-01-01, z: ~, t: true}\n"
        "a:\n  <<: *b\n  x: 2\n  list: [1, 'two', -3.5, .inf, null, 0o17]\n"
    )
    fast = files._load_yaml(text)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(yaml, "__with_libyaml__", False)
        assert files._core_parsing_loader() is files._yaml_core()[0]
        slow = files._load_yaml(text)
        with pytest.raises(ConfigError, match=r"^duplicate key 'x' \(line 2\)"):
            files._load_yaml("x: 1\nx: 2\n")
    assert fast == slow
    assert fast["a"] == {**fast["base"], "x": 2, "list": [1, "two", -3.5, float("inf"), None, 15]}
    base = fast["base"]
    assert base["on"] == "yes" and base["n"] == 10 and base["d"] == "2024-01-01"
    with pytest.raises(ConfigError, match=r"^duplicate key 'x' \(line 2\)"):
        files._load_yaml("x: 1\nx: 2\n")


def test_a_million_entities_from_python_are_refused_before_they_are_read():
    start = time.perf_counter()
    for field in ("entities", "clutter"):
        with pytest.raises(ConfigError, match=rf"^{field}: at most 65535 items, got 1,000,000 "):
            from_dict({**SMALL, field: [{"name": "a", "role": "target"}] * 10**6})
    assert time.perf_counter() - start < 5


@pytest.mark.parametrize(
    ("text", "message"),
    [("", "config is empty (a YAML mapping of fields is expected)"),
     ("# only a comment\n", "config is empty (a YAML mapping of fields is expected)"),
     ("- 1\n- 2\n", "must be a mapping, got [1, 2]")],
)  # fmt: skip
def test_an_empty_file_or_a_list_is_one_line(tmp_path, text, message):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_config(path)
    assert str(err.value) == f"{path}: {message}"


def test_load_data_never_returns_none(tmp_path):
    """A JSON file holding ``null`` is refused as an empty YAML file is: load_data
    documents that it never returns None (it did for JSON)."""
    from scenegen.config import load_data

    for name in ("c.json", "c.yaml"):
        path = tmp_path / name
        path.write_text("null\n")
        with pytest.raises(ConfigError, match=rf"^{re.escape(str(path))}: config is empty \("):
            load_data(path)


def test_an_unhashable_preset_name_is_a_config_error():
    # presets.get(["kams-a"]) was a TypeError (unhashable type: 'list').
    from scenegen import presets

    with pytest.raises(ConfigError, match=r"^unknown preset \['kams-a'\]; valid presets: "):
        presets.get(["kams-a"])
