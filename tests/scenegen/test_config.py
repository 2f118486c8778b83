"""Config validation: every invalid config raises ConfigError naming the field and value."""

from __future__ import annotations

import copy
import json

import pytest
import yaml

import scenegen
from scenegen.config import from_dict, load_config, to_dict
from scenegen.errors import ConfigError


def base() -> dict:
    return {
        "width": 64,
        "height": 48,
        "n_frames": 5,
        "entities": [
            {
                "name": "a",
                "role": "target",
                "position": [20, 20],
                "appearance": {"shape": "ellipse", "size": [9, 9]},
                "motion": {
                    "x": {"sigma": 1, "boundary": "reflect"},
                    "y": {"sigma": 1, "boundary": "clamp"},
                },  # fmt: skip
                "depth": 1,
            },
            {"name": "b", "role": "occluder", "position": [30, 30], "depth": 2},
        ],
    }


def mutate(path: list, value=None, delete: bool = False) -> dict:
    d = copy.deepcopy(base())
    node = d
    for key in path[:-1]:
        node = node[key]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (mutate(["width"], -3), r"^width: must be >= 1, got -3"),
        (mutate(["height"], 0), r"^height: must be >= 1, got 0"),
        (mutate(["n_frames"], 2.5), r"^n_frames: must be an integer, got 2.5"),
        (mutate(["entities", 0, "role"], "hero"), r"^entities\[0\]\.role: must be one of .*'hero'"),
        (mutate(["entities", 1, "depth"], 1), r"^entities\[1\]\.depth: depth tie: 'b' and 'a'"),
        (mutate(["entities", 0, "motion", "x", "boundary"], delete=True),
         r"^entities\[0\]\.motion\.x\.boundary: is required"),
        (mutate(["entities", 0, "motion", "y", "boundary"], "bounce"),
         r"^entities\[0\]\.motion\.y\.boundary: must be one of reflect, clamp, free; got 'bounce'"),
        (mutate(["entities", 0, "motion", "x", "sigma"], -1),
         r"^entities\[0\]\.motion\.x\.sigma: must be >= 0, got -1"),
        (mutate(["entities", 0, "appearance", "size"], [0, 4]),
         r"^entities\[0\]\.appearance\.size: width and height must be >= 1"),
        (mutate(["entities", 0, "appearance", "colors"], [[300, 0, 0]]),
         r"^entities\[0\]\.appearance\.colors\[0\]: colour must be three integers in 0\.\.255"),
        (mutate(["entities", 0, "speed"], 3), r"^entities\[0\]\.speed: unknown field"),
        (mutate(["entities", 1, "name"], "a"), r"^entities\[1\]\.name: duplicate name 'a'"),
        (mutate(["entities", 1, "mimic"], "zed"), r"^entities\[1\]\.mimic: no entity named 'zed'"),
        (mutate(["entities", 1, "position"], delete=True),
         r"^entities\[1\]\.position: is required"),
        (mutate(["entities", 0, "disappear"], 0), r"^entities\[0\]\.disappear: must be > appear"),
        (mutate(["entities", 0, "depth"], [[2, 1]]), r"^entities\[0\]\.depth: the first keyframe"),
        (mutate(["background"], {"kind": "plaid"}), r"^background\.kind: must be one of"),
        (mutate(["clutter"], [{"count": -1}]), r"^clutter\[0\]\.count: must be >= 0, got -1"),
        (mutate(["sensor_noise"], float("nan")), r"^sensor_noise: must be finite"),
        (mutate(["entities"], "many"), r"^entities: must be a list, got 'many'"),
        ([1, 2], r"must be a mapping"),
    ],
)  # fmt: skip
def test_invalid_configs_name_the_field(data, match):
    with pytest.raises(ConfigError, match=match):
        from_dict(data)


def test_depth_tie_after_a_keyframe():
    d = base()
    d["entities"][1]["depth"] = [[0, 2], [3, 1]]
    with pytest.raises(ConfigError, match=r"depth tie: .* at frame 3"):
        from_dict(d)


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
def test_a_bounded_axis_without_room_is_refused(boundary):
    # 2 x margin + width > the frame's width: the limits crossed and the entity moved
    # freely out of the frame, without a word.
    d = {"width": 40, "height": 30, "n_frames": 3, "entities": [
        {"name": "b", "role": "target", "position": [20, 15], "appearance": {"size": [10, 10]},
         "motion": {"x": {"boundary": boundary, "margin": 15.5},
                    "y": {"boundary": boundary, "margin": 10.5}}}]}  # fmt: skip
    with pytest.raises(ConfigError, match=r"^entities\[0\]\.motion\.x\.margin: "
                       rf"{boundary} needs 2 x margin .* 2 x 15.5 \+ 10 > 40$"):
        from_dict(d)
    d["entities"][0]["motion"]["x"]["margin"] = 15  # exactly fits: the centre is pinned
    with pytest.raises(ConfigError, match=r"motion\.y\.margin: .* 2 x 10.5 \+ 10 > 30$"):
        from_dict(d)
    d["entities"][0]["motion"]["y"]["boundary"] = "free"
    d["entities"][0]["motion"]["y"]["margin"] = 0
    seq = scenegen.generate(from_dict(d), seed=0)
    assert (seq.gt.center[:, 0, 0] == 20).all()


def test_depth_shorthand_and_defaults():
    cfg = from_dict(base())
    assert cfg.entities[0].depth == ((0, 1),)
    assert cfg.entities[0].motion.x.a1 == 2.0 and cfg.entities[0].motion.x.a2 == -1.0


@pytest.mark.parametrize("name", scenegen.presets.names())
def test_presets_round_trip_through_plain_data(name):
    cfg = scenegen.presets.get(name)
    data = json.loads(json.dumps(to_dict(cfg)))
    assert from_dict(data) == cfg


def test_unknown_preset_lists_valid_ones():
    with pytest.raises(ConfigError, match="unknown preset 'nope'; valid presets: dps-synthetic"):
        scenegen.presets.get("nope")


def test_every_preset_has_a_paper_docstring():
    for name in scenegen.presets.names():
        text = scenegen.presets.describe(name)
        assert "paper" in text, name
        doc = scenegen.presets._PRESETS[name].__doc__
        assert "Differs from the paper" in doc, name


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_load_config_files(tmp_path, suffix):
    path = tmp_path / f"scene{suffix}"
    text = yaml.safe_dump(base()) if suffix == ".yaml" else json.dumps(base())
    path.write_text(text)
    assert load_config(path) == from_dict(base())


def test_load_config_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ConfigError, match=r"bad\.json: not valid JSON"):
        load_config(bad)
    wrong = tmp_path / "scene.txt"
    wrong.write_text("{}")
    with pytest.raises(ConfigError, match=r"scene\.txt: config must be \.yaml"):
        load_config(wrong)
    with pytest.raises(ConfigError, match="cannot read config"):
        load_config(tmp_path / "missing.yaml")
    inv = tmp_path / "inv.yaml"
    inv.write_text(yaml.safe_dump(mutate(["width"], -1)))
    with pytest.raises(ConfigError, match=r"inv\.yaml: width: must be >= 1"):
        load_config(inv)


def test_numpy_scalars_are_numbers():
    import numpy as np

    cfg = from_dict({**base(), "width": np.int64(40), "height": np.uint8(30),
                     "sensor_noise": np.float32(1.5), "n_frames": np.float64(2.0)})  # fmt: skip
    assert (cfg.width, cfg.height, cfg.n_frames, cfg.sensor_noise) == (40, 30, 2, 1.5)
    assert type(cfg.width) is int and type(cfg.sensor_noise) is float
    assert from_dict(to_dict(cfg)) == cfg
    for field, value, message in (("width", np.bool_(True), "must be an integer"),
                                  ("width", np.float32(3.5), "must be an integer"),
                                  ("sensor_noise", np.True_, "must be a number")):  # fmt: skip
        with pytest.raises(ConfigError, match=f"^{field}: {message}"):
            from_dict({**base(), field: value})


def test_a_yaml_1_1_exponent_without_a_dot_says_how_to_write_the_number(tmp_path):
    # PyYAML reads 1e9 (no dot, unsigned exponent) as a string: before, the message was
    # only "must be a number, got '1e9'", for what the user wrote as a number.
    path = tmp_path / "e.yaml"
    path.write_text("width: 40\nheight: 30\nn_frames: 5\nsensor_noise: 2e-1\n")
    with pytest.raises(ConfigError, match=r"^\S+e\.yaml: sensor_noise: must be a number, "
                       r"got '2e-1' \(a string: YAML reads 2e-1 as text; write 2\.0e-1\)$"):
        load_config(path)
    path.write_text("width: 40\nheight: 30\nn_frames: 1E2\n")
    with pytest.raises(ConfigError, match=r"n_frames: must be an integer, got '1E2' "
                       r"\(a string: YAML reads 1E2 as text; write 1\.0e\+2\)$"):
        load_config(path)
    path.write_text("width: 40\nheight: 30\nn_frames: 1.0e+2\nsensor_noise: 2.0e-1\n")
    assert (load_config(path).n_frames, load_config(path).sensor_noise) == (100, 0.2)
    # A string that is no such number gets no hint.
    with pytest.raises(ConfigError, match=r"^sensor_noise: must be a number, got 'x'$"):
        from_dict({**base(), "sensor_noise": "x"})


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("dup.yaml", "width: 40\nheight: 30\nn_frames: 5\nn_frames: 7\n",
         "duplicate key 'n_frames' (line 4)"),
        ("dup.json", '{"width": 40, "height": 30, "n_frames": 5, "n_frames": 7}',
         "duplicate key 'n_frames'"),
        ("nested.yaml", "width: 40\nheight: 30\nn_frames: 5\nbackground:\n  low: 1\n"
         "  low: 2\n", "duplicate key 'low' (line 6)"),
        ("y2.yaml", "width: 40\nheight: 30\nn_frames: 5\nentities:\n  - name: a\n"
         "   role: target\n",
         "not valid YAML: expected <block end>, but found '<block mapping start>' "
         "(line 6, column 4)"),
        ("bad.json", '{"width": 40,\n "height"}',
         "not valid JSON: Expecting ':' delimiter: line 2 column 10 (char 23)"),
    ],
)  # fmt: skip
def test_duplicate_keys_and_parser_errors_are_one_line_with_where(tmp_path, capsys, name,
                                                                    text, message):  # fmt: skip
    from scenegen.cli import main

    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_config(path)
    assert str(info.value) == f"{path}: {message}"
    assert main(["generate", "--config", str(path), "--seed", "1",
                 "-o", str(tmp_path / "d.h5")]) == 2  # fmt: skip
    assert capsys.readouterr().err == f"scenegen: error: {path}: {message}\n"
    assert not (tmp_path / "d.h5").exists()


def test_yaml_merge_keys_may_be_overridden(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text("<<: {width: 40, height: 30, n_frames: 3}\nwidth: 20\n")
    assert load_config(path) == from_dict({"width": 20, "height": 30, "n_frames": 3})
