"""Tests of ``scenegen.testing.strategies``: drawn values are valid, arguments are validated,
switches do what they say, and failures shrink to simple scenes."""

import math

import numpy as np
import pytest
from hypothesis import Phase, find, given, settings
from hypothesis import strategies as st
from hypothesis.errors import InvalidArgument

from scenegen.config import AR2, EntitySpec, SceneConfig, from_dict, to_dict
from scenegen.render.plan import generate
from scenegen.testing.strategies import ar2_params, boxes, entity_specs, scene_configs, sequences

EVERYTHING = {
    "occlusion": True,
    "clutter": True,
    "distractors": True,
    "noise": True,
    "exits": True,
}


def _check_renders(config: SceneConfig, seed: int) -> None:
    assert from_dict(to_dict(config)) == config
    seq = generate(config, seed=seed)
    t, h, w = config.n_frames, config.height, config.width
    assert seq.frames.shape == (t, h, w, 3)
    assert seq.labels.shape == (t, h, w)
    assert seq.entities.role[0] == "target"
    assert seq.gt.present[0, 0], "the first target must be present at frame 0"


@settings(max_examples=40)
@given(config=scene_configs(**EVERYTHING, min_size=1, max_entities=5), seed=st.integers(0, 99))
def test_scene_configs_validate_and_render(config, seed):
    _check_renders(config, seed)
    assert 1 <= len(config.entities) <= 5
    assert 32 <= config.width <= 120 and 24 <= config.height <= 90
    assert 1 <= config.n_frames <= 8
    for e in config.entities:
        assert 1 <= min(e.appearance.size) and max(e.appearance.size) <= 24 or e.role == "occluder"


@settings(max_examples=25)
@given(config=scene_configs(max_entities=4))
def test_switches_off_mean_none_of_the_features(config):
    assert {e.role for e in config.entities} == {"target"}
    assert config.clutter == ()
    assert config.sensor_noise == 0
    assert config.background.kind == "uniform"
    for e in config.entities:
        assert e.position_noise == 0 and e.appear == 0 and e.disappear is None
        if e.motion is not None:
            assert e.motion.x.boundary != "free" and e.motion.y.boundary != "free"


@pytest.mark.parametrize(
    ("switch", "feature"),
    [
        ("occlusion", lambda c: any(e.role == "occluder" for e in c.entities)),
        ("distractors", lambda c: any(e.mimic is not None for e in c.entities)),
        ("clutter", lambda c: sum(s.count for s in c.clutter) > 0),
        ("noise", lambda c: c.sensor_noise > 0),
        ("exits", lambda c: any(e.disappear is not None for e in c.entities)),
    ],
)
def test_each_switch_can_produce_its_feature(switch, feature):
    first = settings(database=None, max_examples=500, phases=[Phase.generate])
    config = find(scene_configs(**{switch: True}), feature, settings=first)
    _check_renders(config, 0)


def test_minimal_scene_is_simple():
    first = settings(database=None, max_examples=1, phases=[Phase.generate])
    config = find(scene_configs(), lambda c: True, settings=first)
    assert (config.width, config.height, config.n_frames) == (32, 24, 1)
    assert len(config.entities) == 1 and config.clutter == ()
    (e,) = config.entities
    assert e.motion is None and e.appearance.size == (3, 3)
    assert e.appearance.pattern == "solid"


def test_failures_shrink_to_few_entities():
    config = find(
        scene_configs(max_entities=3, occlusion=True, distractors=True),
        lambda c: any(e.role == "distractor" for e in c.entities),
        settings=settings(database=None),
    )
    assert [e.role for e in config.entities] == ["target", "distractor"]
    assert config.n_frames == 1 and (config.width, config.height) == (32, 24)


@settings(max_examples=25)
@given(config=scene_configs(min_width=64, min_height=48, margin=12, occlusion=True, clutter=True))
def test_margin_keeps_every_entity_inside(config):
    seq = generate(config, seed=0)
    labels = np.asarray(seq.labels)
    k_user = len(config.entities)
    for k in range(k_user):
        boxes_k = seq.gt.box[:, k][seq.gt.present[:, k]]
        assert np.all(boxes_k[:, :2] >= 12 - 1e-9)
        assert np.all(boxes_k[:, 0] + boxes_k[:, 2] <= config.width - 12 + 1e-9)
        assert np.all(boxes_k[:, 1] + boxes_k[:, 3] <= config.height - 12 + 1e-9)
    assert labels.shape[0] == config.n_frames


@settings(max_examples=20)
@given(spec=entity_specs(width=50, height=40, n_frames=6, roles=("target", "occluder"), exits=True))
def test_entity_specs_are_valid(spec):
    assert isinstance(spec, EntitySpec)
    assert spec.role in ("target", "occluder")
    assert 3 <= min(spec.appearance.size) and max(spec.appearance.size) <= 24
    assert 0 <= spec.appear < 6
    assert spec.disappear is None or spec.appear < spec.disappear <= 6
    cfg = SceneConfig(width=50, height=40, n_frames=6, entities=(spec,))
    generate(cfg, seed=1)


@settings(max_examples=30)
@given(ar2=ar2_params(boundaries=("clamp",), max_sigma=0.5, margin=3))
def test_ar2_params_respect_their_bounds(ar2):
    assert isinstance(ar2, AR2)
    assert ar2.boundary == "clamp" and ar2.margin == 3
    assert 0 <= ar2.sigma <= 0.5
    assert 1 <= ar2.a1 <= 2 and math.isclose(ar2.a1 + ar2.a2, 1.0)


@settings(max_examples=50)
@given(
    box=boxes(width=20, height=10, min_size=0.5, max_size=6),
    whole=boxes(width=20, height=10, integer=True),
    loose=boxes(width=20, height=10, inside=False),
)
def test_boxes_lie_where_asked(box, whole, loose):
    x, y, w, h = box
    assert box.shape == (4,) and box.dtype == np.float64
    assert 0.5 <= w <= 6 and 0.5 <= h <= 6
    assert 0 <= x and x + w <= 20 and 0 <= y and y + h <= 10
    assert np.all(whole == np.round(whole)) and 0 <= whole[0] <= whole[0] + whole[2] <= 20
    lx, ly, lw, lh = loose
    assert lx < 20 and ly < 10 and lx + lw > 0 and ly + lh > 0


@settings(max_examples=10)
@given(seq=sequences(scene_configs(max_frames=3), seeds=st.integers(5, 9)))
def test_sequences_are_rendered_from_a_drawn_seed(seq):
    assert 5 <= seq.seed <= 9
    assert seq.frames.dtype == np.uint8 and seq.frames.shape[0] <= 3
    again = generate(seq.config, seed=seq.seed)
    np.testing.assert_array_equal(again.frames, seq.frames)


@pytest.mark.parametrize(
    ("strategy", "kwargs", "message"),
    [
        (ar2_params, {"boundaries": ()}, "boundaries"),
        (ar2_params, {"boundaries": ("bounce",)}, "bounce"),
        (ar2_params, {"boundaries": "reflect"}, "boundaries"),
        (ar2_params, {"boundaries": ("clamp", "clamp")}, "duplicates"),
        (ar2_params, {"max_sigma": -1}, "max_sigma"),
        (ar2_params, {"max_sigma": math.nan}, "max_sigma"),
        (ar2_params, {"margin": 2}, "margin"),
        (entity_specs, {"width": 0, "height": 10}, "width"),
        (entity_specs, {"width": 10, "height": 10.5}, "height"),
        (entity_specs, {"width": 10, "height": 10, "n_frames": 0}, "n_frames"),
        (entity_specs, {"width": 10, "height": 10, "name": ""}, "name"),
        (entity_specs, {"width": 10, "height": 10, "roles": ("clutter",)}, "clutter"),
        (entity_specs, {"width": 10, "height": 10, "min_size": 5, "max_size": 4}, "min_size"),
        (entity_specs, {"width": 10, "height": 10, "min_size": 11}, "does not fit"),
        (entity_specs, {"width": 10, "height": 10, "noise": 1}, "noise"),
        (entity_specs, {"width": 10, "height": 10, "exits": True, "margin": 1}, "margin"),
        (entity_specs, {"width": 10, "height": 10, "max_speed": -0.5}, "max_speed"),
        (scene_configs, {"min_width": 50, "max_width": 40}, "min_width"),
        (scene_configs, {"min_height": 0}, "min_height"),
        (scene_configs, {"max_frames": True}, "max_frames"),
        (scene_configs, {"min_frames": 3, "max_frames": 2}, "min_frames"),
        (scene_configs, {"min_entities": 0}, "min_entities"),
        (scene_configs, {"min_entities": 3, "max_entities": 2}, "min_entities"),
        (scene_configs, {"max_size": 0}, "max_size"),
        (scene_configs, {"margin": 20}, "does not fit"),
        (scene_configs, {"occlusion": True, "max_entities": 1}, "occlusion"),
        (scene_configs, {"distractors": True, "max_entities": 1}, "distractors"),
        (scene_configs, {"clutter": "yes"}, "clutter"),
        (scene_configs, {"max_sigma": math.inf}, "max_sigma"),
        (sequences, {"configs": 3}, "configs"),
        (sequences, {"seeds": range(3)}, "seeds"),
        (boxes, {"width": 10, "height": 10, "min_size": 0}, "min_size"),
        (boxes, {"width": 10, "height": 10, "min_size": 4, "max_size": 3}, "min_size"),
        (boxes, {"width": 10, "height": 20, "min_size": 11}, "does not fit"),
        (boxes, {"width": 10, "height": 10, "min_size": 1.2, "max_size": 1.8, "integer": True},
         "whole-pixel"),
        (boxes, {"width": -1, "height": 10}, "width"),
        (boxes, {"width": 10, "height": 10, "inside": None}, "inside"),
    ],
)  # fmt: skip
def test_bad_arguments_raise_invalid_argument_at_call(strategy, kwargs, message):
    with pytest.raises(InvalidArgument, match=message):
        strategy(**kwargs)


@pytest.mark.parametrize("seed", [-1, True, 1.5])  # True and 1.5 found by mutation testing
def test_bad_drawn_seed_is_reported(seed):
    @settings(database=None, max_examples=1, phases=[Phase.generate])
    @given(sequences(scene_configs(max_frames=1), seeds=st.just(seed)))
    def draw(seq):
        raise AssertionError("not reached: drawing must fail")

    with pytest.raises(InvalidArgument, match="seeds must be non-negative integers"):
        draw()


@settings(max_examples=20)
@given(
    config=scene_configs(
        min_width=10, max_width=11, min_height=10, max_height=11, margin=0.002, min_size=9,
        max_size=10, occlusion=True,
    )
)  # fmt: skip
def test_tight_odd_margins_still_draw_valid_scenes(config):
    seq = generate(config, seed=0)
    assert seq.gt.present[0, 0]
