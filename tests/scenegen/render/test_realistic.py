"""Realistic scenes (issue 18): image and texture appearances, camera pan, blur, light.

Ground truth is defined on the sharp silhouettes, so the independent re-derivation of
gtcheck still holds exactly on labels and boxes with every effect switched on.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from gtcheck import check_sequence
from hypothesis import given, settings
from hypothesis import strategies as st

import scenegen
from scenegen.cli import main
from scenegen.config import (
    AR2,
    Appearance,
    Background,
    Camera,
    EntitySpec,
    Motion,
    Photometric,
    SceneConfig,
    from_dict,
    to_dict,
)
from scenegen.errors import ConfigError
from scenegen.render import photometric
from scenegen.render.plan import plan
from scenegen.testing.strategies import scene_configs


def _scene(**kw) -> SceneConfig:
    walk = AR2(boundary="reflect", sigma=1.0)
    face = Appearance(
        shape="ellipse", size=(20, 24), pattern="image", source="skimage:lfw_subset[3]"
    )
    grass = Appearance(size=(30, 30), pattern="image", source="skimage:grass", fit="tile",
                       tint=(120, 200, 80))  # fmt: skip
    cfg = SceneConfig(
        width=64, height=48, n_frames=12,
        background=Background(kind="image", source="skimage:coffee", fit="crop"),
        entities=(
            EntitySpec(name="face", role="target", appearance=face, position=(20, 24),
                       motion=Motion(x=walk, y=walk, velocity=(3, 1)), depth=((0, 1),)),
            EntitySpec(name="bush", role="occluder", appearance=grass, position=(40, 24),
                       depth=((0, 0),)),
            EntitySpec(name="blob", role="distractor", position=(50, 10), depth=((0, 2),),
                       appearance=Appearance(pattern="perlin", colors=((200, 80, 0), (30, 30, 0))),
                       motion=Motion(x=walk, y=walk, velocity=(-2, 2))),
        ),
        camera=Camera(extent=(10, 6), x=AR2(boundary="reflect", sigma=2.0),
                      y=AR2(boundary="clamp", sigma=1.0), velocity=(2, -1)),
        photometric=Photometric(
            gain=AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.05, margin=0.3),
            motion_blur=1.0, jpeg_quality=70,
        ),
    )  # fmt: skip
    return replace(cfg, **kw)


def test_ground_truth_matches_pixels_with_camera_blur_and_light():
    cfg = _scene()
    scn = plan(cfg, 3)
    assert scn.moving_camera
    seq = scenegen.generate(cfg, seed=3)
    check_sequence(seq, scn)
    # Every effect off: the frames are exactly the reference composite.
    sharp = replace(cfg, photometric=None)
    check_sequence(scenegen.generate(sharp, seed=3), plan(sharp, 3), pixels=True)


def test_ground_truth_matches_pixels_with_zoom():
    cfg = _scene(photometric=None)
    assert cfg.camera is not None
    zoom = AR2(boundary="reflect", a1=1.9, a2=-0.9, sigma=0.03, margin=0.4)
    cfg = replace(cfg, camera=replace(cfg.camera, zoom=zoom))
    scn = plan(cfg, 2)
    assert scn.zoomed and len(set(scn.zoom.round(3).tolist())) > 3
    seq = scenegen.generate(cfg, seed=2)
    check_sequence(seq, scn)
    # The amodal size of the static occluder follows the zoom (nearest-neighbour scale).
    w = seq.gt.box[:, 1, 2]
    np.testing.assert_array_equal(w, np.round(30 * scn.zoom).astype(np.float32))


def test_the_camera_moves_the_static_layer_with_the_scene():
    cfg = _scene(photometric=None)
    seq = scenegen.generate(cfg, seed=3)
    scn = plan(cfg, 3)
    box = seq.gt.box[:, 1]  # the static occluder, in frame coordinates
    np.testing.assert_array_equal(box[:, 0], box[0, 0] - (scn.cam_x - scn.cam_x[0]))
    np.testing.assert_array_equal(box[:, 1], box[0, 1] - (scn.cam_y - scn.cam_y[0]))
    assert len(set(scn.cam_x.tolist())) > 1


def test_photometric_effects_change_pixels_only():
    cfg = _scene()
    a = scenegen.generate(cfg, seed=5)
    b = scenegen.generate(replace(cfg, photometric=None), seed=5)
    np.testing.assert_array_equal(a.labels, b.labels)
    for key, arr in a.gt.as_dict().items():
        np.testing.assert_array_equal(arr, b.gt.as_dict()[key], err_msg=key)
    assert not np.array_equal(a.frames, b.frames)


def test_motion_blur_smears_along_the_velocity():
    still = Background(kind="uniform", color=(0, 0, 0))
    ent = EntitySpec(name="t", role="target", position=(20, 20),
                     appearance=Appearance(size=(6, 6), colors=((255, 255, 255),)),
                     motion=Motion(x=AR2(boundary="free"), y=AR2(boundary="free"),
                                   velocity=(6, 0)))  # fmt: skip
    cfg = SceneConfig(width=48, height=40, n_frames=2, background=still, entities=(ent,),
                      photometric=Photometric(motion_blur=1.0))  # fmt: skip
    seq = scenegen.generate(cfg, seed=0)
    row = seq.frames[1, 20, :, 0].astype(int)
    lit = np.flatnonzero(row)
    box = seq.gt.box[1, 0]
    assert lit.min() < box[0] and lit.max() > box[0] + box[2] - 1  # wider than the box
    assert np.all(seq.frames[1, :14] == 0)  # no vertical smear



def test_a_smear_longer_than_the_frame_costs_no_more_than_the_frame():
    # A kernel as long as the smear (4001 x 4001 floats, 64 MB) was built and filtered
    # for a 16 x 20 frame; 10^6 px/frame asked for terabytes.
    import tracemalloc

    lab = np.zeros((16, 20), dtype=np.uint16)
    lab[6:10, 8:12] = 1
    rgb = np.zeros((16, 20, 3), dtype=np.uint8)
    rgb[lab == 1] = 255
    tracemalloc.start()
    try:
        photometric.motion_blur(rgb, lab, 1, (8, 6, 11, 9), (4000.0, 0.0), 1.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**20, peak
    # Spread over 4000 px, the entity's colour adds ~4/4001 of 255 next to it.
    assert rgb[lab == 1].min() >= 254 and rgb[lab == 0].max() <= 1



def test_an_unbounded_gain_that_grows_past_floats_keeps_black_defined():
    # The log gain (default a1=2, a2=-1: a drifting velocity, margin 0: unbounded) passed
    # 710 and exp gave inf: 0 x inf is NaN, cast to uint8 with a RuntimeWarning.
    import warnings

    cfg = SceneConfig(width=4, height=3, n_frames=3000,
                      background=Background(kind="uniform", color=(0, 0, 0)),
                      photometric=Photometric(gain=AR2(boundary="reflect", sigma=1.0),
                                              offset=AR2(boundary="reflect", a1=0.0, a2=0.0,
                                                         mean=9.0)))  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scn = plan(cfg, 3)
        frames = scn.render().frames
    assert np.all(np.isfinite(scn.gain)) and scn.gain.max() > 1e300
    np.testing.assert_array_equal(frames[np.argmax(scn.gain)], 9)  # 0 x gain + 9


def test_a_noise_scale_far_beyond_the_texture_costs_little():
    # The lattice was resized whole: (8 + 2 x 2000)^2 floats per octave to keep 8 x 6.
    import tracemalloc

    import cv2

    from scenegen.render import textures

    tracemalloc.start()
    try:
        v = textures.value_noise(8, 6, 2000.0, np.random.default_rng(4))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**22, peak
    # The same values as the whole 2-D resize, within float rounding.
    rng, ref = np.random.default_rng(4), np.zeros((6, 8), np.float32)
    for step, amp in ((2000.0, 1.0), (1000.0, 0.5), (500.0, 0.25)):
        g = rng.random((3, 3), dtype=np.float32)
        size = (round(3 * step), round(3 * step))
        ref += amp * cv2.resize(g, size, interpolation=cv2.INTER_CUBIC)[:6, :8]
    ref = (ref - ref.min()) / max(float(ref.max() - ref.min()), 1e-6)
    np.testing.assert_allclose(v, ref, atol=1e-4)

def test_a_cropped_blur_kernel_is_the_centre_of_the_whole_one():
    for dx, dy in ((-10.5, 7.75), (14.0, 0.0), (0.0, -9.0), (3.25, -2.5), (-1.5, -1.5)):
        full = photometric.line_kernel(dx, dy)
        r = full.shape[0] // 2
        for qx, qy in ((1, 2), (r - 1, 0), (0, 0), (3, 3)):
            qx, qy = min(max(qx, 0), r), min(qy, r)
            part = photometric.line_kernel(dx, dy, (qx, qy))
            np.testing.assert_array_equal(part, full[r - qy : r + qy + 1, r - qx : r + qx + 1])


def test_ground_truth_holds_for_an_entity_faster_than_the_frame():
    cfg = from_dict({
        "width": 40, "height": 30, "n_frames": 3,
        "entities": [{"name": "t", "role": "target", "position": [20, 15],
                      "appearance": {"size": [6, 6]}, "depth": 1,
                      "motion": {"x": {"boundary": "free"}, "y": {"boundary": "free"},
                                 "velocity": [-1e6, 3]}},
                     {"name": "o", "role": "occluder", "position": [22, 15], "depth": 0,
                      "appearance": {"size": [4, 4]}}],
        "photometric": {"motion_blur": 4.0},
    })  # fmt: skip
    seq = scenegen.generate(cfg, seed=1)
    check_sequence(seq, plan(cfg, 1))
    assert seq.gt.present[:, 0].tolist() == [True, False, False]


@settings(max_examples=12, deadline=None)
@given(cfg=scene_configs(realistic=True, occlusion=True, clutter=True, exits=True,
                         max_frames=5, max_width=80, max_height=60),
       seed=st.integers(0, 2**32 - 1))  # fmt: skip
def test_drawn_realistic_scenes_ground_truth(cfg, seed):
    check_sequence(scenegen.generate(cfg, seed=seed), plan(cfg, seed))


@settings(max_examples=6, deadline=None)
@given(cfg=scene_configs(realistic=True, clutter=True, max_frames=6, max_width=64, max_height=48),
       seed=st.integers(0, 2**32 - 1), size=st.integers(1, 4))  # fmt: skip
def test_realistic_chunked_equals_whole_and_same_seed_same_bytes(cfg, seed, size):
    scn = plan(cfg, seed)
    whole = scn.render()
    again = plan(cfg, seed).render()
    np.testing.assert_array_equal(whole.frames, again.frames)
    parts = list(scn.chunks(size))
    np.testing.assert_array_equal(np.concatenate([c.frames for c in parts]), whole.frames)
    np.testing.assert_array_equal(np.concatenate([c.labels for c in parts]), whole.labels)
    for key, arr in whole.gt.items():
        np.testing.assert_array_equal(np.concatenate([c.gt[key] for c in parts]), arr)


def test_config_round_trip_and_defaults_unchanged():
    cfg = _scene()
    assert from_dict(to_dict(cfg)) == cfg
    plain = to_dict(SceneConfig(width=8, height=8, n_frames=1))
    assert "camera" not in plain and "source" not in plain["background"]


@pytest.mark.parametrize(
    ("data", "field"),
    [
        ({"background": {"kind": "image", "source": "skimage:nope"}}, "background.source"),
        ({"background": {"kind": "image", "source": "/no/such/file.png"}}, "background.source"),
        ({"background": {"kind": "image"}}, "background.source"),
        ({"entities": [{"name": "a", "role": "target", "position": [4, 4],
                        "appearance": {"pattern": "image", "source": "skimage:lfw_subset[200]"}}]},
         "entities[0].appearance.source"),
        ({"entities": [{"name": "a", "role": "target", "position": [4, 4],
                        "appearance": {"pattern": "image", "source": "missing.jpg"}}]},
         "entities[0].appearance.source"),
        ({"entities": [{"name": "a", "role": "target", "position": [4, 4],
                        "appearance": {"pattern": "image", "source": "skimage:lfw_subset[1]",
                                       "crop": [20, 20, 10, 10]}}]},
         "entities[0].appearance.crop"),
    ],
)  # fmt: skip
def test_bad_image_sources_name_the_field(data, field):
    with pytest.raises(ConfigError, match=rf"^{field.replace('[', '.').replace(']', '.')}"):
        scenegen.generate({"width": 16, "height": 16, "n_frames": 1, **data}, seed=0)


def test_camera_extent_is_bounded():
    with pytest.raises(ConfigError, match=r"^camera\.extent: the background"):
        from_dict({"width": 100, "height": 10, "n_frames": 1, "camera": {"extent": [4050, 0]}})



@pytest.mark.parametrize("axis", ["x", "y", "zoom"])
def test_a_free_camera_axis_is_refused(axis):
    # The offset (zoom) was clipped to the extent (its limits) while the free path went on:
    # a pan at 1 px a frame stuck at the extent for good, a random walk until it came back.
    velocity = {"x": [1, 0], "y": [0, 1], "zoom": [0, 0]}[axis]  # only an AR2 axis has one
    camera = {"extent": [4, 4], axis: {"boundary": "free"}, "velocity": velocity}
    data = {"width": 40, "height": 30, "n_frames": 20, "camera": camera}
    with pytest.raises(ConfigError, match=rf"^camera\.{axis}\.boundary: free is not allowed on "
                                          r"a camera: the view cannot go beyond"):  # fmt: skip
        from_dict(data)
    # Within the extent, clamp moves as free would, and stops at the extent.
    data["camera"][axis] = {"boundary": "clamp"}
    if axis != "zoom":
        scn = plan(from_dict(data), 0)
        assert (scn.cam_x if axis == "x" else scn.cam_y).tolist() == [*range(5), *[4] * 15]


def test_scripted_pan_beyond_the_extent_is_refused():
    # It was clipped to the extent without a word: the scripted pan was not the one drawn.
    data = {"width": 40, "height": 30, "n_frames": 4,
            "camera": {"extent": [8, 4], "keyframes": [[0, 0, 0], [3, 20, -4]]}}  # fmt: skip
    with pytest.raises(ConfigError, match=r"^camera\.keyframes\[1\]: offset \(20, -4\) is "
                                          r"beyond the extent \[8, 4\]"):  # fmt: skip
        from_dict(data)
    data["camera"]["keyframes"] = [[0, -8, 4], [3, 8, -4]]  # on the edge: fine
    assert from_dict(data).camera.keyframes[1] == (3, 8, -4)

def test_cli_exits_2_naming_the_field_and_file(tmp_path, capsys):
    import yaml

    path = tmp_path / "bad.yaml"
    cfg = {"width": 16, "height": 16, "n_frames": 1,
           "background": {"kind": "image", "source": str(tmp_path / "gone.png")}}  # fmt: skip
    path.write_text(yaml.safe_dump(cfg))
    assert main(["generate", "--config", str(path), "-o", str(tmp_path / "out.h5")]) == 2
    err = capsys.readouterr().err
    assert "background.source" in err and "gone.png" in err


def test_user_image_file_is_read(tmp_path):
    import cv2

    img = np.zeros((10, 12, 3), dtype=np.uint8)
    img[:, :6] = (0, 0, 255)  # BGR red on the left half
    path = tmp_path / "red.png"
    cv2.imwrite(str(path), img)
    bg = Background(kind="image", source=str(path), fit="stretch")
    cfg = SceneConfig(width=12, height=10, n_frames=1, background=bg)
    seq = scenegen.generate(cfg, seed=0)
    np.testing.assert_array_equal(seq.frames[0, 0, 0], [255, 0, 0])
    np.testing.assert_array_equal(seq.frames[0, 0, 11], [0, 0, 0])


def test_a_16_bit_image_is_scaled_not_saturated(tmp_path):
    # Every 16-bit file was taken for floats in [0, 1]: all white.
    import cv2

    path = tmp_path / "g16.png"
    cv2.imwrite(str(path), np.full((10, 12), 40000, np.uint16))
    bg = Background(kind="image", source=str(path), fit="stretch")
    seq = scenegen.generate(SceneConfig(width=12, height=10, n_frames=1, background=bg), seed=0)
    assert np.unique(seq.frames[0]).tolist() == [round(40000 * 255 / 65535)]


@pytest.mark.parametrize("content", [b"", b"not an image\n"])
def test_an_unreadable_image_file_is_one_line(tmp_path, content):
    # skimage's reason was three lines, ending with a pip install command.
    from scenegen.errors import ConfigError

    path = tmp_path / "text.png"
    path.write_bytes(content)
    bg = Background(kind="image", source=str(path))
    with pytest.raises(ConfigError) as info:
        scenegen.generate(SceneConfig(width=12, height=10, n_frames=1, background=bg), seed=0)
    msg = str(info.value)
    assert "cannot read image file" in msg and "text.png" in msg and "\n" not in msg


def test_an_unreadable_image_file_leaves_no_file_open(tmp_path):
    # imageio's probing of its plugins opened the path and left it open when no plugin
    # could read it (a ResourceWarning once collected): the fallback now reads from memory.
    import gc
    import warnings

    from scenegen.render.textures import load_source

    path = tmp_path / "text.png"
    path.write_bytes(b"not an image\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(ConfigError, match="cannot read image file .*text.png"):
            load_source(str(path), "background.source")
        gc.collect()
    assert not [w for w in caught if issubclass(w.category, ResourceWarning)]


def test_an_image_opencv_refuses_is_read_by_scikit_image(tmp_path, monkeypatch):
    # OpenCV raises on some files (more pixels than it allows): scikit-image reads them.
    import cv2

    from scenegen.render import textures

    img = np.zeros((10, 12, 3), dtype=np.uint8)
    img[:, :6] = (0, 0, 255)  # BGR red on the left half
    path = tmp_path / "refused.png"
    cv2.imwrite(str(path), img)

    def refuse(*args, **kwargs):
        raise cv2.error("OpenCV(5.0.0) loadsave.cpp:1: error: (-215:Assertion failed) pixels")

    monkeypatch.setattr(textures.cv2, "imread", refuse)
    got = textures.load_source(str(path), "background.source")
    np.testing.assert_array_equal(got, img[..., ::-1])


@pytest.mark.parametrize("name", scenegen.presets.realistic_names())
def test_realistic_presets_ground_truth_and_round_trip(name):
    cfg = scenegen.presets.get(name)
    assert from_dict(to_dict(cfg)) == cfg
    assert "Differs from the paper" in scenegen.presets._REALISTIC[name].__doc__
    short = replace(cfg, n_frames=4)
    check_sequence(scenegen.generate(short, seed=1), plan(short, 1))
    assert name not in scenegen.presets.names() and name in scenegen.presets.all_names()


def test_readme_realistic_example_generates():
    import re
    from pathlib import Path

    import yaml

    text = (Path(__file__).parents[3] / "README.md").read_text(encoding="utf-8")
    block = text[text.index("## Realistic scenes") :]
    example = re.search(r"```yaml\n(.*?)```", block, re.S)
    assert example is not None
    seq = scenegen.generate(yaml.safe_load(example.group(1)), seed=0, frames=3)
    assert seq.frames.shape == (3, 240, 320, 3)



@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(cfg=scene_configs(realistic=True, occlusion=True, clutter=True, distractors=True,
                         exits=True, noise=True, max_frames=10, max_entities=5),
       seed=st.integers(0, 2**32 - 1))  # fmt: skip
def test_drawn_realistic_scenes_ground_truth_many(cfg, seed):
    check_sequence(scenegen.generate(cfg, seed=seed), plan(cfg, seed))


def test_textures_are_keyed_by_the_entity_name():
    cfg = _scene(photometric=None)
    extra = EntitySpec(name="extra", role="distractor", position=(10, 10), depth=((0, 5),),
                       appearance=Appearance(pattern="perlin", colors=((0, 0, 255),)))  # fmt: skip
    more = replace(cfg, entities=(extra, *cfg.entities))
    a, b = plan(cfg, 9), plan(more, 9)
    for k in range(len(cfg.entities)):
        np.testing.assert_array_equal(a.templates[k], b.templates[k + 1])
    np.testing.assert_array_equal(a.cam_x, b.cam_x)
    # Another seed draws another texture (Perlin noise, tile offset).
    c = plan(cfg, 10)
    assert not np.array_equal(a.templates[2], c.templates[2])
    assert not np.array_equal(a.templates[1], c.templates[1])


def test_a_config_files_relative_image_sources_are_read_from_its_folder(
    tmp_path, monkeypatch, capsys
):
    # Before, `generate --config scenes/x.yaml` from elsewhere failed with "no such image
    # file 'img/my.png'", and a file written from the config's folder recorded the
    # relative path, so `validate --deep` failed from any other directory.
    import cv2
    import yaml

    scenes, elsewhere = tmp_path / "scenes", tmp_path / "elsewhere"
    (scenes / "img").mkdir(parents=True)
    elsewhere.mkdir()
    img = (np.random.default_rng(0).random((20, 24, 3)) * 255).astype(np.uint8)
    cv2.imwrite(str(scenes / "img" / "my.png"), img)
    cfg = {"width": 32, "height": 24, "n_frames": 3,
           "background": {"kind": "image", "source": "img/my.png"},
           "entities": [{"name": "a", "role": "target", "position": [10, 10],
                         "appearance": {"size": [8, 8], "pattern": "image",
                                        "source": "img/my.png"}}]}  # fmt: skip
    (scenes / "x.yaml").write_text(yaml.safe_dump(cfg))
    monkeypatch.chdir(elsewhere)
    assert main(["generate", "--config", str(scenes / "x.yaml"), "-o", "out.h5"]) == 0
    stored = scenegen.read("out.h5").config
    expect = str(scenes / "img" / "my.png")
    assert stored.background.source == expect
    assert stored.entities[0].appearance.source == expect
    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert main(["validate", "--deep", str(elsewhere / "out.h5")]) == 0, capsys.readouterr()
    # Plain data (no file) keeps its relative paths: relative to the current directory,
    # which a missing file's error names.
    with pytest.raises(ConfigError, match=r"^entities\[0\]\.appearance\.source: no such image "
                       r"file 'img/my\.png' \(relative to the current directory '"):  # fmt: skip
        scenegen.generate(cfg, seed=0)
    monkeypatch.chdir(scenes)
    np.testing.assert_array_equal(
        scenegen.generate(cfg, seed=1).frames, scenegen.generate(stored, seed=1).frames
    )
