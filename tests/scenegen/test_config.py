"""Config validation: every invalid config raises ConfigError naming the field and value."""

from __future__ import annotations

import copy
import json
import re

import numpy as np
import pytest
import yaml

import scenegen
from scenegen.config import from_dict, from_stored, load_config, to_dict
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


@pytest.mark.parametrize(("value", "kind"), [
    ({"width": 64}, "dict"), ("kams-a", "str"), (None, "NoneType"),
    (scenegen.presets.get("kams-a").entities[0], "EntitySpec"),
])  # fmt: skip
def test_to_dict_refuses_what_is_not_a_scene_config(value, kind):
    # Was returned unchanged: to_dict(plain data) looked like a resolved config.
    with pytest.raises(ConfigError, match=rf"^to_dict takes a SceneConfig, got a {kind}$"):
        to_dict(value)


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


def test_yaml_exponents_without_a_dot_are_numbers(tmp_path):
    # YAML 1.2 (the core schema the loader follows): 2e-1 and 1E2 are floats. PyYAML's
    # YAML 1.1 read them as strings, and the config was refused ("must be a number").
    path = tmp_path / "e.yaml"
    path.write_text("width: 40\nheight: 30\nn_frames: 1E2\nsensor_noise: 2e-1\n")
    assert (load_config(path).n_frames, load_config(path).sensor_noise) == (100, 0.2)
    path.write_text("width: 40\nheight: 30\nn_frames: 1.0e+2\nsensor_noise: 2.0e-1\n")
    assert (load_config(path).n_frames, load_config(path).sensor_noise) == (100, 0.2)
    # A string stays a string: no number is made of it.
    with pytest.raises(ConfigError, match=r"^sensor_noise: must be a number, got 'x'$"):
        from_dict({**base(), "sensor_noise": "x"})
    with pytest.raises(ConfigError, match=r"^sensor_noise: must be a number, got '1e9'$"):
        from_dict({**base(), "sensor_noise": "1e9"})


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
         "not valid YAML: did not find expected '-' indicator (line 6, column 4)"
         if yaml.__with_libyaml__  # libyaml's words (it parses); PyYAML's own parser's:
         else "not valid YAML: expected <block end>, but found '<block mapping start>' "
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


def _app(**fields) -> dict:
    return mutate(["entities", 0, "appearance"], {"size": [9, 9], **fields})


def _image_clutter(**fields) -> dict:
    app = {"size": [6, 6], "pattern": "image", "source": "skimage:brick"}
    return mutate(["clutter"], [{"count": 3, "appearance": app, **fields}])


def _image_mimic(**fields) -> dict:
    """A distractor mimicking target ``a``, whose appearance is an image."""
    d = _app(pattern="image", source="skimage:coffee")
    d["entities"][1] = {"name": "m", "role": "distractor", "mimic": "a", "depth": 3, **fields}
    return d


_UNUSED_CASES = [
        (_app(crop=[0, 0, 4, 4]), "entities[0].appearance.crop: not used by pattern 'solid' "
                                  "(it applies to pattern: image)"),
        (_app(pattern="stripes", fit="tile"), "entities[0].appearance.fit: not used by "
                                              "pattern 'stripes' (it applies to pattern: image)"),
        (_app(pattern="rings", tint=[255, 0, 0]), "entities[0].appearance.tint: not used by "
                                                  "pattern 'rings'"),
        (_app(noise_scale=4), "entities[0].appearance.noise_scale: not used by pattern "
                              "'solid' (it applies to pattern: perlin)"),
        (_app(pattern="perlin", texture_sigma=5), "entities[0].appearance.texture_sigma: not "
                                                  "used by pattern 'perlin'"),
        (_app(source="skimage:coffee"), "entities[0].appearance.source: not used by pattern "
                                        "'solid' (it applies to pattern: image)"),
        (_app(pattern="image", source="skimage:coffee", colors=[[0, 255, 0]]),
         "entities[0].appearance.colors: not used by pattern 'image' (it applies to pattern: "
         "solid | rings | sectors | stripes | bands | checker | texture | perlin)"),
        (mutate(["clutter"], [{"count": 1, "appearance": {"crop": [0, 0, 2, 2]}}]),
         "clutter[0].appearance.crop: not used by pattern 'solid'"),
        (mutate(["background"], {"kind": "uniform", "low": 10}),
         "background.low: not used by kind 'uniform' (it applies to kind: noise | texture | "
         "perlin)"),
        (mutate(["background"], {"kind": "noise", "color": [9, 9, 9]}),
         "background.color: not used by kind 'noise'"),
        (mutate(["background"], {"kind": "texture", "fit": "tile"}),
         "background.fit: not used by kind 'texture' (it applies to kind: image)"),
        # Image clutter takes its pixels from the image, not colours from the palette.
        (_image_clutter(palette=[[0, 0, 255]]),
         "clutter[0].palette: not used by pattern 'image' (it applies to pattern: solid | "
         "rings | sectors | stripes | bands | checker | texture | perlin)"),
        (_image_clutter(n_colors=2), "clutter[0].n_colors: not used by pattern 'image'"),
        # An image has no colours to jitter.
        (_image_mimic(color_jitter=8),
         "entities[1].color_jitter: not used by pattern 'image' of the mimicked 'a', which "
         "has no colours to jitter (it applies to pattern: solid | rings | sectors | "),
        # Only a mimic is jittered or offset from its model; one with a position starts there.
        (mutate(["entities", 0, "color_jitter"], 5),
         "entities[0].color_jitter: not used without mimic"),
        (mutate(["entities", 1, "mimic_offset"], [3, 0]),
         "entities[1].mimic_offset: not used without mimic"),
        (_image_mimic(position=[40, 30], mimic_offset=[3, 0]),
         "entities[1].mimic_offset: not used with a position"),
        # A free axis has no limits for a margin to move.
        (mutate(["entities", 0, "motion", "x"], {"boundary": "free", "margin": 2}),
         "entities[0].motion.x.margin: not used by boundary 'free' (it applies to boundary: "
         "reflect | clamp)"),
        (mutate(["entities", 0, "motion", "scale"], {"boundary": "free", "margin": 0.5}),
         "entities[0].motion.scale.margin: not used by boundary 'free'"),
        # The camera's velocity starts its x / y AR2: keyframes or no AR2 never read it.
        (mutate(["camera"], {"keyframes": [[0, 1, 1]], "velocity": [2, 0]}),
         "camera.velocity: the x velocity is not used without x motion"),
        (mutate(["camera"], {"x": {"boundary": "reflect"}, "velocity": [2, 1]}),
         "camera.velocity: the y velocity is not used without y motion"),
]  # fmt: skip
"""Configs with a field their scene would silently ignore, and the start of the refusal."""


@pytest.mark.parametrize(("data", "message"), _UNUSED_CASES)
def test_a_field_the_pattern_does_not_use_is_refused(tmp_path, capsys, data, message):
    # It was silently ignored: a crop on a solid pattern drew the solid colour.
    from scenegen.cli import main

    with pytest.raises(ConfigError) as info:
        from_dict(data)
    assert str(info.value).startswith(message)
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["generate", "--config", str(path), "-o", str(tmp_path / "o.h5")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and message in err and not (tmp_path / "o.h5").exists()


@pytest.mark.parametrize(("data", "message"), _UNUSED_CASES)
def test_a_stored_config_keeps_an_unused_field_ignored(data, message):
    # A file written before a refusal existed holds such a field: reading it back must
    # not make it invalid; every other check still applies.
    config = from_stored(data)
    assert from_stored(to_dict(config)) == config
    with pytest.raises(ConfigError, match=r"^n_frames: "):
        from_stored({**copy.deepcopy(data), "n_frames": -1})
    with pytest.raises(ConfigError) as info:
        from_dict(to_dict(config))  # the refusal itself is unchanged for a new config
    assert str(info.value).startswith(message)


def test_a_file_with_a_field_refused_since_it_was_written_stays_valid(tmp_path):
    # As a dps-synthetic-real file written with color_jitter 6 on its image mimic.
    from scenegen.cli import main

    data = {**_image_mimic(color_jitter=8), "n_frames": 3}
    with pytest.raises(ConfigError):
        from_dict(data)
    path = tmp_path / "old.h5"
    scenegen.write(path, scenegen.generate(from_stored(data), seed=3))
    seq = scenegen.read(path)
    assert seq.config.entities[1].color_jitter == 8 and seq.frames.shape[0] == 3
    assert main(["validate", "--deep", str(path)]) == 0


def test_an_unused_field_at_its_default_and_stripe_width_are_accepted():
    # Nothing is ignored that would change the frames; the fixtures record a scaled
    # stripe_width (and background scale) on every pattern, so they stay valid.
    data = _app(fit="stretch", noise_scale=8.0, tint=None, texture_sigma=20, stripe_width=2)
    data["background"] = {"kind": "noise", "color": [255, 255, 255], "fit": "crop", "scale": 2}
    cfg = from_dict(data)
    assert cfg.entities[0].appearance.stripe_width == 2 and cfg.background.scale == 2.0
    assert from_dict(to_dict(cfg)) == cfg


def test_mimic_clutter_ar2_and_camera_fields_at_their_defaults_are_accepted():
    data = _image_mimic(color_jitter=0, mimic_offset=[0, 0], position=[40, 30])
    data["entities"][0]["color_jitter"] = 0.0
    data["entities"][0]["motion"]["x"] = {"boundary": "free", "margin": 0}
    data["clutter"] = _image_clutter(palette=[[255, 0, 0], [0, 160, 0], [0, 0, 255],
                                              [255, 200, 0]], n_colors=1)["clutter"]
    data["camera"] = {"keyframes": [[0, 1, 1]], "velocity": [0, 0]}
    cfg = from_dict(data)
    assert from_dict(to_dict(cfg)) == cfg
    # A mimic of a coloured pattern is jittered and offset; clutter of a coloured
    # pattern takes its palette; a camera AR2 its velocity.
    data = mutate(["entities", 1], {"name": "m", "role": "distractor", "mimic": "a",
                                    "color_jitter": 8, "mimic_offset": [3, 0], "depth": 3})
    data["clutter"] = [{"count": 3, "palette": [[0, 0, 255]], "n_colors": 2}]
    data["camera"] = {"x": {"boundary": "reflect"}, "velocity": [2, 0]}
    assert from_dict(data).entities[1].color_jitter == 8.0


def test_clutter_appearance_colors_are_tolerated_though_unused():
    # Clutter items take their colours from the palette; the single-frame regression
    # fixture records appearance colours on its clutter, so they are accepted (ignored).
    data = mutate(["clutter"], [{"count": 4, "appearance": {"colors": [[1, 2, 3]]}}])
    plain = mutate(["clutter"], [{"count": 4}])
    a, b = scenegen.generate(data, seed=2), scenegen.generate(plain, seed=2)
    assert np.array_equal(a.frames, b.frames)


def test_yaml_follows_the_core_schema_of_yaml_1_2(tmp_path):
    # YAML 1.1 (PyYAML's default) read 010 as 8, and no/yes/on/off as booleans.
    path = tmp_path / "c.yaml"
    path.write_text("width: 0x40\nheight: 010\nn_frames: +3\nname: no\n"
                    "entities:\n  - {name: on, role: target, position: [1e1, 2.], depth: 0o7}\n"
                    "clutter:\n  - {count: 0, name: 2024-01-01}\n")  # fmt: skip
    cfg = load_config(path)
    assert (cfg.width, cfg.height, cfg.n_frames, cfg.name) == (64, 10, 3, "no")
    assert cfg.entities[0].name == "on" and cfg.entities[0].position == (10.0, 2.0)
    assert cfg.entities[0].depth == ((0, 7),) and cfg.clutter[0].name == "2024-01-01"
    # A value whose type is then wrong for its field: the field is named.
    for text, message in (
        ("sensor_noise: yes\nn_frames: 1", "sensor_noise: must be a number, got 'yes'"),
        ("n_frames: 1_000", "n_frames: must be an integer, got '1_000'"),
        ("n_frames: 1:30", "n_frames: must be an integer, got '1:30'"),
    ):
        path.write_text(f"width: 8\nheight: 8\n{text}\n")
        with pytest.raises(ConfigError, match=f"^{path}: {message}$"):
            load_config(path)
    # A family file is read by the same loader.
    from scenegen.datasets import load_family

    fam = tmp_path / "f.yaml"
    fam.write_text("name: no\nbase: kams-a\nseed: 010\ncount: 2\n")
    family = load_family(fam)
    assert (family.name, family.seed) == ("no", 10)


def test_dump_yaml_quotes_what_either_yaml_would_misread(tmp_path):
    from scenegen.config import dump_yaml

    cfg = from_dict({**base(), "name": "1e9", "clutter": [
        {"count": 0, "name": name} for name in ("no", "010", "0o7", "yes", "1_000", "null")]})
    text = dump_yaml(to_dict(cfg))
    path = tmp_path / "c.yaml"
    path.write_text(text)
    assert load_config(path) == cfg
    assert yaml.safe_load(text) == to_dict(cfg)  # and by a YAML 1.1 reader


def test_a_byte_order_mark_is_allowed_in_json_as_in_yaml(tmp_path):
    # Notepad writes one; the JSON was refused ("Unexpected UTF-8 BOM (decode using
    # utf-8-sig)"), the same config in YAML read.
    for suffix, text in ((".json", json.dumps(base())), (".yaml", yaml.safe_dump(base()))):
        path = tmp_path / f"c{suffix}"
        path.write_bytes(b"\xef\xbb\xbf" + text.encode())
        assert load_config(path) == from_dict(base())


def test_config_classes_check_their_field_types_on_construction(tmp_path):
    """A config built in Python is read as from_dict reads plain data: a bad choice or type
    is a ConfigError naming the field (role 'zz' and boundary 'x' were accepted, the
    first written to files; width 32.5 was a TypeError at generation), and numpy numbers
    and lists are stored as Python numbers and tuples (np.int64 made write fail: JSON has
    no int64)."""
    from scenegen.config import AR2, Appearance, Background, EntitySpec, Motion, SceneConfig

    def ent(**kw):
        base = dict(name="a", role="target", position=(10.0, 10.0),
                    appearance=Appearance(shape="ellipse", size=(5, 5)))  # fmt: skip
        return EntitySpec(**(base | kw))

    for build, message in (
        (lambda: AR2(boundary="x"), "boundary: must be one of reflect, clamp, free; got 'x'"),
        (lambda: ent(role="zz"), "role: must be one of target, distractor, occluder, clutter"),
        (lambda: Background(kind="zz"), "kind: must be one of uniform, noise, texture"),
        (lambda: SceneConfig(width=32.5, height=24, n_frames=3),
         "width: must be an integer, got 32.5"),
        (lambda: SceneConfig(width=None, height=24, n_frames=3),
         "width: must be an integer, got None"),
        (lambda: SceneConfig(width=3, height=3, n_frames=1, entities=({"name": "a"},)),
         "entities[0]: must be of type EntitySpec, got {'name': 'a'}"),
        (lambda: AR2(boundary="free", sigma="1"), "sigma: must be a number, got '1'"),
        (lambda: Motion(x=AR2(boundary="free"), y=None), "y: must be of type AR2, got None"),
        (lambda: ent(position="ab"), "position: must be a list, got 'ab'"),
    ):  # fmt: skip
        with pytest.raises(ConfigError, match=f"^{re.escape(message)}"):
            build()
    cfg = SceneConfig(width=np.int64(32), height=24, n_frames=np.uint8(3),
                      sensor_noise=np.float32(0.5), entities=[ent()])  # fmt: skip
    assert type(cfg.width) is int and type(cfg.sensor_noise) is float
    assert isinstance(cfg.entities, tuple) and from_dict(to_dict(cfg)) == cfg
    path = tmp_path / "s.h5"
    scenegen.write(path, scenegen.generate(cfg, seed=0))
    assert scenegen.read(path).config == cfg
    # A Python int given for a float is kept as given (configs built in Python, such as
    # the presets, store what they hold).
    assert AR2(boundary="free", sigma=1).sigma.__class__ is int
