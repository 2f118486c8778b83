"""Config fuzzing: arbitrary JSON-like values and mutated valid configs, given to
``from_dict`` and (as JSON and YAML files) to ``load_config``, give a valid config or a
``ConfigError`` -- never another exception. Configs beyond the documented limits
(``MAX_SIDE``, ``MAX_FRAMES``, ``MAX_FRAME_ENTITIES``, ``MAX_MAGNITUDE``, ...) are rejected
instead of attempted, and small valid outcomes plan and render.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import io
import json
import math

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegen import presets
from scenegen.cli import main
from scenegen.config import (
    AR2,
    MAX_BLUR,
    MAX_FRAME_ENTITIES,
    MAX_FRAMES,
    MAX_MAGNITUDE,
    MAX_SIDE,
    MAX_TEMPLATE_PIXELS,
    Appearance,
    Background,
    ClutterSpec,
    EntitySpec,
    Motion,
    SceneConfig,
    Variation,
    from_dict,
    load_config,
    to_dict,
)
from scenegen.errors import ConfigError
from scenegen.io.validate import check_file
from scenegen.render.plan import plan

# A small config that uses every feature: scale motion, pose variation, a mimic that
# appears late, depth keyframes, a disappearing occluder, grid clutter in a region.
RICH = {
    "name": "rich", "width": 64, "height": 48, "n_frames": 6, "sensor_noise": 3,
    "background": {"kind": "texture", "color": [200, 180, 160], "scale": 3},
    "entities": [
        {"name": "t", "role": "target", "position": [20, 20], "position_noise": 1,
         "depth": [[0, 1], [3, 3]],
         "appearance": {"shape": "ellipse", "size": [12, 10], "pattern": "sectors",
                        "colors": [[255, 0, 0], [0, 0, 255]]},
         "motion": {"x": {"boundary": "reflect", "sigma": 2, "margin": 1},
                    "y": {"boundary": "clamp", "sigma": 1, "a1": 1.5, "a2": -0.5},
                    "scale": {"boundary": "reflect", "sigma": 0.05, "margin": 0.3},
                    "velocity": [2, 1]},
         "variation": {"rotation": 10, "shading": 0.2, "period": 4}},
        {"name": "d", "role": "distractor", "mimic": "t", "mimic_offset": [5, 3],
         "appear": 2, "depth": 2, "color_jitter": 10,
         "motion": {"x": {"boundary": "free", "sigma": 1}, "y": {"boundary": "free"}}},
        {"name": "o", "role": "occluder", "position": [40, 24], "depth": [[0, 0], [3, 2]],
         "disappear": 5, "appearance": {"size": [8, 30], "pattern": "stripes",
                                        "colors": [[9, 9, 9], [200, 200, 0]]}},
    ],
    "clutter": [{"count": 12, "placement": "grid", "region": [0, 0, 64, 24], "n_colors": 2,
                 "min_size": 2, "appearance": {"shape": "diamond", "size": [6, 6]}}],
}  # fmt: skip

BASES = [RICH, *(to_dict(presets.get(name)) for name in presets.names())]

FIELD_NAMES = sorted(
    {
        f.name
        for cls in (
            SceneConfig,
            EntitySpec,
            Appearance,
            Motion,
            AR2,
            Variation,
            Background,
            ClutterSpec,
        )  # fmt: skip
        for f in dataclasses.fields(cls)
    }
)
EXTREMES = [
    0, -1, 1, 0.5, -0.0, 1e-300, 5e-324, 2**31, 2**63, 10**9, -(10**9), 10**18, 10**400,
    -(10**400), 1e308, -1e308, math.inf, -math.inf, math.nan, MAX_SIDE + 1, MAX_FRAMES + 1,
]  # fmt: skip

leaves = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.sampled_from(EXTREMES)
    | st.floats()
    | st.text(max_size=8)
    | st.sampled_from(["target", "clutter", "ellipse", "reflect", "free", "noise", "grid"])
)
keys = st.text(max_size=8) | st.sampled_from(FIELD_NAMES)
json_values = st.recursive(
    leaves,
    lambda children: st.lists(children, max_size=4) | st.dictionaries(keys, children, max_size=5),
    max_leaves=16,
)


def outcome(data):
    """``from_dict(data)``: a config or None for a ConfigError; anything else fails."""
    try:
        cfg = from_dict(data)
    except ConfigError as err:
        assert str(err) and "\n" not in str(err)
        return None
    assert isinstance(cfg, SceneConfig)
    return cfg


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*prefix, i))


def _at(node, path):
    for p in path:
        node = node[p]
    return node


MUTATIONS = ["delete", "replace", "negate", "extreme", "unknown_key", "role", "duplicate",
             "wrap", "unwrap"]  # fmt: skip


@st.composite
def mutated_configs(draw):
    """A valid config's plain data with one to three random mutations at random paths."""
    data = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 3))):
        paths = list(_paths(data))[1:]
        path = draw(st.sampled_from(paths))
        parent, key = _at(data, path[:-1]), path[-1]
        value = parent[key]
        op = draw(st.sampled_from(MUTATIONS))
        if op == "delete":
            del parent[key]
        elif op == "replace":
            parent[key] = draw(json_values)
        elif op == "negate" and isinstance(value, (int, float)) and not isinstance(value, bool):
            parent[key] = -value
        elif op == "extreme":
            parent[key] = draw(st.sampled_from(EXTREMES))
        elif op == "unknown_key" and isinstance(value, dict):
            value[draw(st.sampled_from(["bogus", "colour", "Width", ""]))] = draw(leaves)
        elif op == "role" and isinstance(value, dict) and "role" in value:
            value["role"] = draw(st.text(max_size=10) | st.sampled_from(["Target", "camera"]))
        elif op == "duplicate" and isinstance(value, list) and value:
            value.append(copy.deepcopy(value[draw(st.integers(0, len(value) - 1))]))
        elif op == "wrap":
            parent[key] = [value]
        elif op == "unwrap" and isinstance(value, list) and value:
            parent[key] = value[0]
    return data


def _small(cfg: SceneConfig) -> bool:
    k = len(cfg.entities) + sum(c.count for c in cfg.clutter)
    big = max([max(e.appearance.size) for e in cfg.entities] + [1])
    return cfg.width * cfg.height <= 400 * 300 and cfg.n_frames <= 200 and k <= 700 and big <= 256


@settings(max_examples=300)
@given(json_values)
def test_arbitrary_values(data):
    outcome(data)


@settings(max_examples=300)
@given(st.dictionaries(st.sampled_from([*FIELD_NAMES, "bogus"]), json_values, max_size=8))
def test_arbitrary_top_level_fields(data):
    outcome(data)


@settings(max_examples=150)
@given(mutated_configs())
def test_mutated_configs_are_valid_or_config_errors_and_valid_ones_render(data):
    cfg = outcome(data)
    if cfg is not None and _small(cfg):
        scn = plan(cfg, 0)
        chunk = scn.render(0, min(2, cfg.n_frames))
        assert chunk.frames.shape == (min(2, cfg.n_frames), cfg.height, cfg.width, 3)
        assert from_dict(to_dict(cfg)) == cfg


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@settings(max_examples=60)
@given(data=mutated_configs() | json_values)
def test_load_config_from_json_and_yaml_files(folder, data):
    expect = outcome(data)
    files = {"c.json": json.dumps(data), "c.yaml": yaml.safe_dump(data)}
    for name, text in files.items():
        path = folder / name
        path.write_text(text)
        try:
            cfg = load_config(path)
        except ConfigError as err:
            assert str(err).startswith(f"{path}: ") and "\n" not in str(err)
            assert expect is None
            continue
        assert cfg == expect


@settings(max_examples=60)
@given(text=st.text(max_size=200), suffix=st.sampled_from([".json", ".yaml", ".yml"]))
def test_load_config_of_arbitrary_text(folder, text, suffix):
    path = folder / f"t{suffix}"
    path.write_text(text)
    try:
        assert isinstance(load_config(path), SceneConfig)
    except ConfigError as err:
        assert str(err).startswith(f"{path}: ") and "\n" not in str(err)


def base(**changes):
    return {"width": 64, "height": 48, "n_frames": 5, **changes}


ENTITY = {"name": "a", "role": "target", "position": [10, 10]}


@pytest.mark.parametrize(
    ("data", "field", "needle"),
    [
        (base(width=10**9), "width", f"must be <= {MAX_SIDE}"),
        (base(height=MAX_SIDE + 1), "height", f"must be <= {MAX_SIDE}"),
        (base(n_frames=MAX_FRAMES + 1), "n_frames", f"must be <= {MAX_FRAMES}"),
        (base(n_frames=20_000, clutter=[{"count": 1001}]), "n_frames",
         f"20000 frames x 1001 entities exceeds {MAX_FRAME_ENTITIES:,}"),
        (base(entities=[{**ENTITY, "appearance": {"size": [10**5, 3]}}]),
         "entities[0].appearance.size", f"must be <= {MAX_SIDE}"),
        (base(entities=[{**ENTITY, "position": [10**400, 0]}]), "entities[0].position[0]",
         "must be at most 1e+09 in magnitude"),
        (base(entities=[{**ENTITY, "depth": 10**12}]), "entities[0].depth[0][1]",
         "must be at most 1e+09 in magnitude"),
        (base(entities=[{**ENTITY, "position": [math.nan, 0]}]), "entities[0].position[0]",
         "must be finite"),
        (base(sensor_noise=math.inf), "sensor_noise", "must be finite"),
        (base(background={"kind": "texture", "scale": 10**6}), "background.scale",
         f"must be in (0, {MAX_BLUR:g}]"),
        (base(clutter=[{"count": 3, "n_colors": 10**9}]), "clutter[0].n_colors",
         "must be in 1..256"),
        (base(entities=[{**ENTITY, "appearance": {"size": [8192, 8192]}}]),
         "entities[0].appearance.size", "the appearance templates (entities, and clutter "
         f"count x size) would hold 67,108,864 pixels, more than {MAX_TEMPLATE_PIXELS:,}"),
        (base(entities=[{**ENTITY, "appearance": {"size": [4096, 4096]}},
                        {**ENTITY, "name": "b", "role": "distractor", "position": None,
                         "mimic": "a", "depth": 1}]),
         "entities[1].appearance.size", "would hold 33,554,432 pixels"),
        (base(clutter=[{"count": 200, "appearance": {"size": [8192, 8192]}}]),
         "clutter[0].appearance.size", "would hold 13,421,772,800 pixels"),
    ],
)  # fmt: skip
def test_absurd_sizes_are_rejected_not_attempted(data, field, needle):
    with pytest.raises(ConfigError) as err:
        from_dict(data)
    assert str(err.value).startswith(f"{field}: ") and needle in str(err.value)


def test_limits_hold_for_python_objects_and_frame_overrides():
    cfg = presets.get("kams-d")  # hundreds of clutter items
    k = len(cfg.entities) + sum(c.count for c in cfg.clutter)
    frames = MAX_FRAME_ENTITIES // k + 1
    with pytest.raises(ConfigError, match=f"n_frames: {frames} frames x {k} entities exceeds"):
        dataclasses.replace(cfg, n_frames=frames)
    assert dataclasses.replace(cfg, n_frames=frames - 1).n_frames == frames - 1
    with pytest.raises(ConfigError, match=r"sensor_noise: must be at most 1e\+09"):
        dataclasses.replace(cfg, sensor_noise=MAX_MAGNITUDE * 10)
    with pytest.raises(ConfigError, match="width: must be <= 8192"):
        SceneConfig(width=MAX_SIDE + 1, height=10, n_frames=1)


@settings(max_examples=20)
@given(data=mutated_configs())
def test_generate_cli_on_mutated_configs_exits_0_or_2_with_one_line(folder, data):
    config, out = folder / "cli.json", folder / "cli.h5"
    config.write_text(json.dumps(data))
    out.unlink(missing_ok=True)
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        code = main(["generate", "--config", str(config), "--frames", "2", "--seed", "0",
                     "-o", str(out)])  # fmt: skip
    err = stderr.getvalue()
    if code == 2:
        assert len(err.splitlines()) == 1 and err.startswith("scenegen: error: ")
        assert not out.exists()
    else:
        assert code == 0 and check_file(out) == []


def test_the_template_limit_leaves_room_for_every_preset():
    for name in presets.names():
        cfg = presets.get(name)
        pixels = sum(e.appearance.size[0] * e.appearance.size[1] for e in cfg.entities)
        pixels += sum(c.count * c.appearance.size[0] * c.appearance.size[1] for c in cfg.clutter)
        assert pixels * 100 < MAX_TEMPLATE_PIXELS, name
    big = base(entities=[{**ENTITY, "appearance": {"size": [4096, 4096]}}])
    assert from_dict(big).entities[0].appearance.size == (4096, 4096)  # exactly the limit
