"""Scenario families: parsing, field paths, draws, and one-line errors for bad families."""

import json

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from scenegen import presets
from scenegen.config import to_dict
from scenegen.datasets import builtin_names, family_from_dict, load_family, resolve_family
from scenegen.datasets.paths import get_path, leaf_type, set_path
from scenegen.errors import ConfigError

FAMILY = {
    "name": "t",
    "base": "kams-a",
    "set": {"n_frames": 4, "width": 64, "height": 48, "entities[0].position": [30, 24],
            "entities[target].motion.x.margin": 2, "entities[target].motion.y.margin": 2},
    "sweep": {"clutter[0].count": [0, 4, 8]},
    "vary": {"entities[0].position_noise": {"uniform": [0.0, 3.0]},
             "clutter[clutter].min_size": {"randint": [2, 8]},
             "background.kind": {"choice": ["uniform", "noise"]}},
    "count": 7,
}  # fmt: skip


def test_paths_name_fields_by_index_or_name():
    data = to_dict(presets.get("dps-occlusion"))
    assert leaf_type(data, "entities[walker].appearance.size[0]") is int
    assert leaf_type(data, "entities[1].position_noise") is float
    set_path(data, "entities[standing2].appearance.size[0]", 50)
    assert get_path(data, "entities[2].appearance.size") == [50, 50]


def test_every_builtin_family_draws_valid_sequences():
    for name in builtin_names():
        fam = resolve_family(name)
        draws = fam.draws(min(fam.count, 5))
        assert len({d.seed for d in draws}) == len(draws), name
        assert all(d.name == f"{name}-{d.index:05d}" for d in draws)


def test_kams_family_sweeps_the_four_levels():
    fam = resolve_family("kams")
    assert [d.params["preset"] for d in fam.draws(8)] == ["kams-a", "kams-b", "kams-c",
                                                           "kams-d"] * 2  # fmt: skip
    d = fam.draw(3)
    assert d.preset == "kams-d" and d.config["clutter"][0]["count"] == 600


def test_a_preset_name_is_a_family_of_seeds():
    fam = resolve_family("kams-c")
    assert fam.grid_size == 1
    a, b = fam.draws(2)
    assert a.params == {} and a.seed != b.seed and a.preset == "kams-c"


@pytest.mark.parametrize("name", presets.realistic_names())
def test_every_preset_is_a_family_and_a_base(name):
    # The realistic presets were "unknown" to dataset (names() instead of all_names()).
    assert resolve_family(name).draws(1)[0].preset == name
    assert family_from_dict({"name": "b", "base": name}).draws(1)[0].preset == name
    swept = family_from_dict({"name": "s", "sweep": {"preset": [name, "kams-a"]}})
    assert [d.preset for d in swept.draws(2)] == [name, "kams-a"]


def test_grid_and_draws():
    fam = family_from_dict(FAMILY)
    draws = fam.draws()
    assert [d.params["clutter[0].count"] for d in draws] == [0, 4, 8, 0, 4, 8, 0]
    for d in draws:
        assert 0.0 <= d.params["entities[0].position_noise"] <= 3.0
        assert d.config["entities"][0]["position_noise"] == d.params["entities[0].position_noise"]
        assert d.config["clutter"][0]["min_size"] == d.params["clutter[clutter].min_size"]
        assert d.config["n_frames"] == 4
    assert fam.param_names == ["clutter[0].count", "entities[0].position_noise",
                               "clutter[clutter].min_size", "background.kind"]  # fmt: skip


@given(seed=st.integers(0, 2**32), index=st.integers(0, 50))
def test_a_draw_depends_on_family_seed_and_index_only(seed, index):
    fam = family_from_dict(FAMILY)
    alone = fam.draw(index, seed)
    assert fam.draws(index + 1, seed)[index] == alone
    bigger = family_from_dict({**FAMILY, "count": 500})  # the count is not part of it
    assert bigger.draw(index, seed) == alone
    assert fam.draw(index, seed + 1).seed != alone.seed


@pytest.mark.parametrize("index", [-1, 1.5, True, "3", None])
def test_a_draw_of_a_bad_index_is_one_config_error_naming_it(index):
    # -1 was numpy's bare "expected non-negative integer"; 1.5 a TypeError of its own.
    with pytest.raises(ConfigError, match=r"^index must be an integer >= 0, got "):
        family_from_dict(FAMILY).draw(index)
    assert family_from_dict(FAMILY).draw(np.int64(2)) == family_from_dict(FAMILY).draw(2)


def test_family_file(tmp_path):
    p = tmp_path / "f.json"
    p.write_text(json.dumps(FAMILY))
    y = tmp_path / "f.yaml"
    y.write_text("name: t\nbase: kams-a\nsweep:\n  clutter[0].count: [1, 2]\n")
    assert load_family(p).draws() == family_from_dict(FAMILY, source=str(p)).draws()
    assert load_family(y).grid_size == 2


MOTION = to_dict(presets.get("kams-a"))["entities"][0]["motion"]

BAD = [
    ({"sweep": {"clutter[0].cnt": [1]}}, "sweep.clutter[0].cnt: unknown field 'cnt'"),
    ({"vary": {"entities[0].motion.z": {"uniform": [0, 1]}}},
     "vary.entities[0].motion.z: unknown field 'z'"),
    ({"vary": {"entities[5].position_noise": {"uniform": [0, 1]}}}, "index 5 out of range"),
    ({"vary": {"entities[nobody].position_noise": {"uniform": [0, 1]}}}, "no item named"),
    ({"sweep": {"clutter[0].count": []}}, "sweep.clutter[0].count: empty sweep"),
    ({"vary": {"entities[0].position_noise": {"uniform": [3, 1]}}},
     "vary.entities[0].position_noise: empty range [3, 1]"),
    ({"vary": {"clutter[0].count": {"randint": [9, 2]}}}, "clutter[0].count: empty range"),
    ({"vary": {"background.kind": {"choice": []}}}, "background.kind: empty choice"),
    ({"vary": {"clutter[0].count": {"uniform": [1, 5]}}},
     "vary.clutter[0].count: uniform draws real numbers but clutter[0].count is an integer"),
    ({"vary": {"background.kind": {"normal": [1, 5]}}},
     "vary.background.kind: normal draws numbers but background.kind is one of"),
    ({"vary": {"sensor_noise": {"gauss": [1, 5]}}}, "vary.sensor_noise: unknown distribution"),
    ({"vary": {"sensor_noise": {"loguniform": [0, 5]}}}, "loguniform needs low > 0"),
    ({"vary": {"sensor_noise": {"uniform": ["a", 5]}}}, "bounds must be finite numbers"),
    ({"sweep": {"entities[0].position_noise": [-1]}}, "entities[0].position_noise: must be >= 0"),
    ({"vary": {"entities[0].position_noise": {"normal": [0, 5]}}, "count": 20},
     "entities[0].position_noise: must be >= 0"),
    ({"colour": 1}, "colour: unknown key"),
    ({"count": 0}, "count: must be an integer >= 1"),
    ({"base": "kams-z"}, "base: unknown preset 'kams-z'"),
    ({"name": "a/b"}, "name: is required"),
    ({"set": {"n_frames": -10}}, "f.yaml: set: n_frames: must be >= 1, got -10"),
    ({"set": {"n_frames": -10}, "sweep": {"clutter[0].count": [1, 2]}},
     "f.yaml: set: n_frames: must be >= 1, got -10"),
    ({"sweep": {"clutter[0].count": [0, 600]}, "vary": {"clutter[0].count": {"randint": [1, 2]}}},
     "f.yaml: vary.clutter[0].count: set by two axes or distributions (also by "
     "sweep.clutter[0].count)"),
    ({"sweep": {"clutter[clutter].count": [0, 600]},
      "vary": {"clutter[0].count": {"randint": [100, 110]}}},
     "f.yaml: vary.clutter[0].count: set by two axes or distributions (also by "
     "sweep.clutter[clutter].count)"),
    ({"sweep": {"w": {"entities[target].appearance.size[0]": [9, 10], "n_frames": [3, 4]},
                "entities[0].appearance.size[0]": [5, 6]}},
     "f.yaml: sweep.entities[0].appearance.size[0]: set by two axes or distributions (also "
     "by sweep.w.entities[target].appearance.size[0])"),
    # A sub-config and a field inside it (by whole components, by index or by name).
    ({"sweep": {"entities[0].motion": [MOTION]},
      "vary": {"entities[0].motion.x.margin": {"uniform": [1, 2]}}},
     "f.yaml: vary.entities[0].motion.x.margin: set by two axes or distributions (also by "
     "sweep.entities[0].motion, which holds it)"),
    ({"sweep": {"entities[0].motion.x.margin": [1, 2]},
      "vary": {"entities[target].motion": {"choice": [MOTION]}}},
     "f.yaml: vary.entities[target].motion: set by two axes or distributions (also by "
     "sweep.entities[0].motion.x.margin, a field inside it)"),
    ({"sweep": {"w": {"entities[0].motion.x.sigma": [1, 2], "entities": [[], []]}}},
     "f.yaml: sweep.w.entities: set by two axes or distributions (also by "
     "sweep.w.entities[0].motion.x.sigma, a field inside it)"),
    ({"seed": 2**64}, "f.yaml: seed: must be an integer in [0, 2**64 - 1], got "
     "18446744073709551616"),
    ({"seed": -1}, "f.yaml: seed: must be an integer in [0, 2**64 - 1], got -1"),
    ({"seed": 10**5000}, "f.yaml: seed: must be an integer in [0, 2**64 - 1], got an integer "
     "of 16610 bits"),
]  # fmt: skip


@pytest.mark.parametrize(("change", "message"), BAD)
def test_bad_family_is_one_line_naming_the_field(change, message):
    data = {"name": "t", "base": "kams-a", **change}
    with pytest.raises(ConfigError) as info:
        family_from_dict(data, source="f.yaml").draws()
    text = str(info.value)
    assert message in text
    assert text.startswith("f.yaml: ") and "\n" not in text


def test_paths_overlap_by_whole_components_only():
    from scenegen.datasets.family import _inside

    assert _inside("entities[0].motion.x", "entities[0].motion")
    assert _inside("entities[0].motion", "entities")
    assert not _inside("clutter[10].count", "clutter[1]")
    assert not _inside("entities[0].motion", "entities[0].motion")
    assert not _inside("sensor_noise_x", "sensor_noise")
    # Two fields of one sub-config do not overlap.
    fam = family_from_dict({
        "name": "t", "base": "kams-a", "sweep": {"entities[0].motion.x.sigma": [1, 2]},
        "vary": {"entities[target].motion.y.sigma": {"uniform": [1, 2]}},
    })  # fmt: skip
    assert fam.draws(2)[1].config["entities"][0]["motion"]["x"]["sigma"] == 2


@pytest.mark.parametrize("sweep", [{"preset": ["kams-a", "kams-zz"]},
                                   {"lvl": {"preset": ["kams-a", "kams-zz"], "n_frames": [3, 4]}},
                                   {"preset": ["kams-a", "kams-zz.yaml"]}])  # fmt: skip
def test_an_unknown_preset_in_a_preset_axis_names_the_axis(sweep):
    where = "sweep.lvl.preset" if "lvl" in sweep else "sweep.preset"
    name = sweep["preset"][1] if "preset" in sweep else "kams-zz"
    with pytest.raises(ConfigError) as info:
        family_from_dict({"name": "t", "sweep": sweep}, source="f.yaml")
    assert str(info.value).startswith(f"f.yaml: {where}: unknown preset {name!r}; valid presets: ")
    assert "kams-a" in str(info.value) and "\n" not in str(info.value)


def test_the_largest_seed_is_accepted():
    fam = family_from_dict({"name": "t", "base": "kams-a", "seed": 2**64 - 1})
    assert fam.seed == 2**64 - 1 and fam.draws(1)[0].seed >= 0


def test_unknown_family_name_lists_the_valid_ones():
    with pytest.raises(ConfigError, match="built-in families: kams"):
        resolve_family("nope")


def test_overrides_keep_the_family_as_given_and_refuse_swept_fields():
    fam = family_from_dict(FAMILY)
    more = fam.with_overrides({"n_frames": 3}).with_overrides({"width": 60})
    assert more.spec == FAMILY and dict(more.overrides)["n_frames"] == 3
    assert more.draw(0).config["n_frames"] == 3 and more.draw(0).config["width"] == 60
    with pytest.raises(ConfigError, match=r"^family: sweep.clutter\[0\].count: sets "
                       r"clutter\[clutter\].count per sequence; it cannot be overridden$"):
        fam.with_overrides({"clutter[clutter].count": 3})
    # A sub-config holding a swept field, or a field inside a swept sub-config.
    with pytest.raises(ConfigError, match=r"^family: sweep.clutter\[0\].count: sets a field "
                       r"of clutter\[clutter\] per sequence; it cannot be overridden$"):
        fam.with_overrides({"clutter[clutter]": to_dict(presets.get("kams-a"))["clutter"][0]})
    sub = family_from_dict({"name": "s", "base": "kams-a",
                            "sweep": {"entities[0].motion": [MOTION]}})  # fmt: skip
    with pytest.raises(ConfigError, match=r"^family: sweep.entities\[0\].motion: sets "
                       r"entities\[0\].motion.x.sigma per sequence; it cannot be overridden$"):
        sub.with_overrides({"entities[0].motion.x.sigma": 3.0})


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (b"name: f\ndescription: caf\xe9\nbase: kams-a\n",
         "family is not UTF-8 text (invalid continuation byte)"),
        (b"name: f\nbase: kams-a\nname: g\n", "duplicate key 'name' (line 3)"),
        (b"name: f\nbase: kams-a\nsweep:\n  a: [1]\n b: [2]\n",
         "not valid YAML: did not find expected key (line 5, column 2)"
         if yaml.__with_libyaml__  # libyaml parses; PyYAML's own parser words it so:
         else "not valid YAML: expected <block end>, but found '<block mapping start>' "
         "(line 5, column 2)"),
        ("\n".join(["name: f", "base: kams-a", 'l0: &l0 ["lol","lol","lol","lol","lol"]']
                   + [f"l{i}: &l{i} [" + ",".join([f"*l{i - 1}"] * 9) + "]"
                      for i in range(1, 9)]).encode(),
         "the YAML's aliases expand to more than 100,000 values"),
    ],
)  # fmt: skip
def test_a_family_file_is_read_as_a_config_is(tmp_path, text, message):
    path = tmp_path / "f.yaml"
    path.write_bytes(text)
    with pytest.raises(ConfigError) as info:
        load_family(path)
    assert str(info.value) == f"{path}: {message}"
    dup = tmp_path / "f.json"
    dup.write_text('{"name": "f", "base": "kams-a", "name": "g"}')
    with pytest.raises(ConfigError, match=r"f\.json: duplicate key 'name'$"):
        load_family(dup)


def test_an_axis_level_is_the_value_its_fields_share():
    from scenegen.datasets.family import Axis

    axis = Axis("w", ("a", "b"), ((36, 36), (44, 50)))
    assert axis.level(0) == 36 and axis.level(1) == [44, 50]
    assert Axis("p", ("p",), ((1,), (2,))).level(1) == 2


def test_relative_image_sources_are_read_from_their_files_folder_wherever_it_is(tmp_path):
    # A base config file's relative image source is relative to that file, a family's
    # own (set/sweep) to the family file; drawn configs record them absolute. The seeds
    # do not depend on where the folder is (the family's digest keeps them relative).
    import cv2

    draws = []
    for root in (tmp_path / "a", tmp_path / "b" / "deeper"):
        (root / "configs").mkdir(parents=True)
        cv2.imwrite(str(root / "configs" / "my.png"), np.zeros((8, 8, 3), np.uint8))
        cv2.imwrite(str(root / "bg.png"), np.zeros((8, 8, 3), np.uint8))
        (root / "configs" / "x.yaml").write_text(
            "width: 16\nheight: 16\nn_frames: 2\nentities:\n"
            "  - {name: a, role: target, position: [8, 8],\n"
            "     appearance: {size: [4, 4], pattern: image, source: my.png}}\n"
        )
        (root / "f.yaml").write_text(
            "name: f\nbase: configs/x.yaml\ncount: 2\n"
            "set: {background.kind: image, background.source: bg.png}\n"
        )
        fam = load_family(root / "f.yaml")
        d = fam.draws()
        assert d[0].config["entities"][0]["appearance"]["source"] == str(
            root / "configs" / "my.png"
        )
        assert d[1].config["background"]["source"] == str(root / "bg.png")
        draws.append((fam.digest(), [x.seed for x in d]))
    assert draws[0] == draws[1]
