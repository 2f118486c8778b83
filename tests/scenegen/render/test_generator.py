"""Generator invariants over many drawn configs (issue 2, item 7)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from gtcheck import check_sequence
from hypothesis import given, settings
from hypothesis import strategies as st

import scenegen
from scenegen.config import (
    AR2,
    Appearance,
    Background,
    ClutterSpec,
    EntitySpec,
    Motion,
    SceneConfig,
    Variation,
)
from scenegen.errors import ConfigError
from scenegen.render.motion import ar2_path, ar2_stationary_moments
from scenegen.render.plan import plan

SHAPES = ["rect", "ellipse", "triangle", "diamond"]
PATTERNS = ["solid", "rings", "sectors", "stripes", "bands", "checker", "texture"]
BOUNDS = ["reflect", "clamp", "free"]


def build_config(p: dict) -> SceneConfig:
    """A scene from drawn parameters: entities that cross, occlude, enter and leave."""
    rng = np.random.default_rng(p["layout_seed"])
    w, h = p["width"], p["height"]
    ents = []
    depths = rng.permutation(3 * p["n_entities"] + 1)
    for i in range(p["n_entities"]):
        size = (int(rng.integers(1, w // 2 + 1)), int(rng.integers(1, h // 2 + 1)))
        colors = tuple(tuple(int(v) for v in rng.integers(0, 256, 3)) for _ in range(3))
        app = Appearance(
            shape=SHAPES[int(rng.integers(len(SHAPES)))],
            size=size,
            pattern=PATTERNS[int(rng.integers(len(PATTERNS)))],
            colors=colors,
            stripe_width=int(rng.integers(1, 5)),
        )
        bound = BOUNDS[int(rng.integers(len(BOUNDS)))]
        motion = None
        if rng.random() < 0.8:
            sig = float(rng.uniform(0, 4))
            scale = (
                AR2(boundary="reflect", a1=1.0, a2=0.0, sigma=0.05, margin=0.4)
                if p["scale"] and rng.random() < 0.5
                else None
            )
            motion = Motion(
                # A bounded axis needs 2 x margin + size <= the side (a config error else);
                # a free one has no margin (refused). The draw is kept: same scenes else.
                x=AR2(boundary=bound, sigma=sig,
                      margin=float(rng.uniform(0, min(3.0, (w - size[0]) / 2)))
                      * (bound != "free")),
                y=AR2(boundary=bound, a1=1.5, a2=-0.5, sigma=sig),
                scale=scale,
                velocity=(float(rng.uniform(-4, 4)), float(rng.uniform(-4, 4))),
            )
        appear = int(rng.integers(0, max(p["n_frames"] // 2, 1)))
        disappear = appear + int(rng.integers(1, p["n_frames"] + 1)) if rng.random() < 0.3 else None
        d0, d1 = int(depths[3 * i]), int(depths[3 * i + 1])
        depth = ((0, d0),) if rng.random() < 0.5 else ((0, d0), (p["n_frames"] // 2 + 1, d1))
        ents.append(
            EntitySpec(
                name=f"e{i}",
                role=["target", "distractor", "occluder"][i % 3],
                appearance=app,
                position=(float(rng.uniform(-5, w + 5)), float(rng.uniform(-5, h + 5))),
                motion=motion,
                position_noise=float(rng.uniform(0, 2)) if rng.random() < 0.3 else 0.0,
                appear=appear,
                disappear=disappear,
                depth=depth,
                variation=Variation(rotation=10.0, shading=0.1, period=7.0)
                if p["pose"] and i == 0
                else None,
            )
        )
    clutter = ()
    if p["n_clutter"]:
        clutter = (
            ClutterSpec(
                count=p["n_clutter"],
                appearance=Appearance(shape="ellipse", size=(7, 5), pattern="sectors"),
                n_colors=2,
                min_size=1,
            ),
        )
    return SceneConfig(
        width=w,
        height=h,
        n_frames=p["n_frames"],
        background=Background(kind=["uniform", "noise", "texture"][p["bg"]]),
        entities=tuple(ents),
        clutter=clutter,
        sensor_noise=0.0,
    )


scene_params = st.fixed_dictionaries(
    {
        "width": st.integers(8, 72),
        "height": st.integers(8, 56),
        "n_frames": st.integers(1, 8),
        "n_entities": st.integers(1, 5),
        "n_clutter": st.integers(0, 12),
        "scale": st.booleans(),
        "pose": st.booleans(),
        "bg": st.integers(0, 2),
        "layout_seed": st.integers(0, 2**32 - 1),
    }
)


@settings(max_examples=40)
@given(p=scene_params, seed=st.integers(0, 2**31))
def test_ground_truth_matches_pixels(p, seed):
    cfg = build_config(p)
    scn = plan(cfg, seed)
    seq = scenegen.generate(cfg, seed=seed)
    check_sequence(seq, scn)


@settings(max_examples=10)
@given(p=scene_params, seed=st.integers(0, 2**31), size=st.integers(1, 5))
def test_chunked_rendering_equals_whole(p, seed, size):
    scn = plan(build_config(p), seed)
    whole = scn.render()
    parts = list(scn.chunks(size))
    np.testing.assert_array_equal(np.concatenate([c.frames for c in parts]), whole.frames)
    np.testing.assert_array_equal(np.concatenate([c.labels for c in parts]), whole.labels)
    for key, arr in whole.gt.items():
        np.testing.assert_array_equal(np.concatenate([c.gt[key] for c in parts]), arr)


@pytest.mark.parametrize("size", [0, -3, 2.5, True])
def test_chunks_of_a_bad_size_are_refused_at_the_call(size):
    # size 0 raised numpy's range error at the first chunk; a negative size gave no chunk.
    scn = plan(scenegen.presets.get("kams-a"), 0)
    with pytest.raises(ValueError, match=r"^size must be an integer >= 1, got "):
        scn.chunks(size)


def test_sensor_noise_is_keyed_per_frame():
    cfg = build_config(
        {"width": 40, "height": 30, "n_frames": 6, "n_entities": 2, "n_clutter": 0,
         "scale": False, "pose": False, "bg": 0, "layout_seed": 3}
    )  # fmt: skip
    # Mid-grey background so that clipping at 0/255 does not shrink the noise.
    cfg = replace(cfg, sensor_noise=10.0, background=Background(color=(128, 128, 128)))
    scn = plan(cfg, 5)
    whole = scn.render()
    tail = scn.render(3, 6)
    np.testing.assert_array_equal(whole.frames[3:], tail.frames)
    clean = plan(replace(cfg, sensor_noise=0.0), 5).render()
    np.testing.assert_array_equal(whole.labels, clean.labels)
    diff = whole.frames.astype(int) - clean.frames.astype(int)
    bg = clean.labels == 0
    assert 9 < diff[bg].std() < 11


@pytest.mark.parametrize("preset", scenegen.presets.names())
def test_presets_ground_truth(preset):
    seq = scenegen.generate(preset, seed=11, frames=6)
    scn = plan(seq.config, 11, preset=preset)
    check_sequence(seq, scn)
    assert seq.preset == preset and seq.name == preset


@settings(max_examples=10)
@given(p=scene_params, seed=st.integers(0, 2**31))
def test_same_seed_same_bytes_other_seed_differs(p, seed):
    cfg = build_config(p)
    a = scenegen.generate(cfg, seed=seed)
    b = scenegen.generate(cfg, seed=seed)
    for x, y in ((a.frames, b.frames), (a.labels, b.labels), (a.gt.box, b.gt.box)):
        assert x.tobytes() == y.tobytes()


def test_different_seed_differs():
    for preset in scenegen.presets.names():
        a = scenegen.generate(preset, seed=1)
        b = scenegen.generate(preset, seed=2)
        assert a.frames.tobytes() != b.frames.tobytes(), preset
        assert not np.array_equal(a.gt.box, b.gt.box, equal_nan=True), preset


@settings(max_examples=15)
@given(p=scene_params, seed=st.integers(0, 2**31), at=st.integers(0, 5))
def test_adding_an_entity_keeps_the_others(p, seed, at):
    cfg = build_config(p)
    extra = EntitySpec(
        name="newcomer",
        role="distractor",
        appearance=Appearance(shape="ellipse", size=(5, 5), pattern="texture"),
        position=(3.0, 3.0),
        motion=Motion(x=AR2(boundary="free", sigma=2.0), y=AR2(boundary="free", sigma=2.0)),
        depth=((0, 10_000),),
    )
    ents = list(cfg.entities)
    ents.insert(min(at, len(ents)), extra)
    bigger = replace(cfg, entities=tuple(ents))
    a, b = plan(cfg, seed), plan(bigger, seed)
    for k, name in enumerate(a.names):
        j = b.names.index(name)
        for field in ("cx", "cy", "scale", "angle", "shade", "alive"):
            np.testing.assert_array_equal(getattr(a, field)[:, k], getattr(b, field)[:, j])
        np.testing.assert_array_equal(a.templates[k], b.templates[j])


@pytest.mark.parametrize(
    ("a1", "a2", "sigma"), [(0.5, 0.2, 1.0), (1.5, -0.6, 3.0), (-0.3, 0.1, 2.0), (1.0, -0.5, 0.5)]
)
def test_ar2_moments_match_theory(a1, a2, sigma):
    var, rho1 = ar2_stationary_moments(a1, a2, sigma)
    rng = np.random.default_rng(1234)
    x = ar2_path(
        AR2(boundary="free", a1=a1, a2=a2, sigma=sigma, mean=5.0), 5.0, 0.0, 200_000, rng=rng
    )
    x = x[1000:]  # burn-in
    assert abs(x.mean() - 5.0) < 0.05 * np.sqrt(var) + 0.02
    assert x.var() == pytest.approx(var, rel=0.04)
    c = x - x.mean()
    assert np.dot(c[1:], c[:-1]) / np.dot(c, c) == pytest.approx(rho1, abs=0.015)


def test_ar2_nonstationary_rejected():
    with pytest.raises(ValueError, match="not stationary"):
        ar2_stationary_moments(2.0, -1.0, 1.0)


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
def test_bounded_motion_stays_inside(boundary):
    rng = np.random.default_rng(0)
    x = ar2_path(AR2(boundary=boundary, sigma=5.0), 50.0, 3.0, 5000, rng=rng, lo=10.0, hi=90.0)
    assert x.min() >= 10.0 and x.max() <= 90.0


def test_a_runaway_free_path_is_a_config_error_naming_the_field_and_frame(recwarn):
    # a1 = 1000 explodes: before, the path overflowed to inf/NaN with RuntimeWarnings and
    # a NaN cast to int64 when drawn; now the frame where it passes MAX_PATH is named.
    ar = AR2(boundary="free", a1=1000.0, a2=-1.0, sigma=1.0)
    with pytest.raises(ConfigError, match=r"^entities\[2\]\.motion\.x: the AR2 path reaches "
                       r"\S+ at frame \d+, beyond \+-1e\+18; a1=1000, a2=-1 is explosive"):
        ar2_path(ar, 5.0, 0.0, 500, rng=np.random.default_rng(0), field="entities[2].motion.x")
    # Oscillating growth (complex roots of modulus sqrt(1.1)) is caught as well.
    with pytest.raises(ConfigError, match="is explosive"):
        ar2_path(AR2(boundary="free", a1=0.0, a2=-1.1, sigma=1.0), 0.0, 1.0, 2000,
                 rng=np.random.default_rng(0))  # fmt: skip
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@pytest.mark.parametrize("boundary", ["reflect", "clamp"])
def test_an_explosive_ar2_on_a_bounded_axis_stays_inside(boundary):
    ar = AR2(boundary=boundary, a1=1e9, a2=-1e9, sigma=1e9)
    x = ar2_path(ar, 50.0, 3.0, 3000, rng=np.random.default_rng(0), lo=10.0, hi=90.0)
    assert x.min() >= 10.0 and x.max() <= 90.0


def test_the_unit_root_default_with_the_largest_drift_is_allowed():
    # a1 = 2, a2 = -1 (a random walk of the velocity) is not explosive: a path that drifts
    # by the largest velocity for 100,000 frames (1e14 px) is planned, off the frame.
    ar = AR2(boundary="free", sigma=1e3)
    x = ar2_path(ar, 0.0, 1e9, 100_000, rng=np.random.default_rng(0))
    assert np.isfinite(x).all() and x[-1] > 9e13
    cfg = SceneConfig(width=20, height=20, n_frames=500, entities=(EntitySpec(
        name="a", role="target", position=(10.0, 10.0),
        motion=Motion(x=ar, y=AR2(boundary="free"), velocity=(1e9, 0.0))),))  # fmt: skip
    seq = scenegen.generate(cfg, seed=0)
    assert seq.gt.present[0, 0] and not seq.gt.present[1:, 0].any()


def test_depth_keyframes_change_the_order():
    seq = scenegen.generate("shm-crossing", seed=0)
    a, b = seq.entities.index_of("hand-a"), seq.entities.index_of("hand-b")
    assert seq.gt.depth[10, a] < seq.gt.depth[10, b]
    assert seq.gt.depth[50, b] < seq.gt.depth[50, a]
    assert seq.gt.depth[100, a] < seq.gt.depth[100, b]
    # Clutter always lies behind both hands.
    clutter = np.flatnonzero(seq.entities.role == "clutter")
    assert seq.gt.depth[:, clutter].min() > seq.gt.depth[:, [a, b]].max()


def test_dps_distractor_starts_on_object1():
    seq = scenegen.generate("dps-synthetic", seed=4)
    d, o = seq.entities.index_of("distractor1"), seq.entities.index_of("object1")
    assert not seq.gt.present[:3, d].any() and seq.gt.present[3:9, d].all()
    assert not seq.gt.present[9:, d].any()
    np.testing.assert_allclose(seq.gt.center[3, d], seq.gt.center[3, o], atol=1.0)
    # By its last frame it has drifted ~40 px away: far enough that a track that followed
    # it no longer overlaps object 1 (30x30), so object 1 must be re-acquired.
    gap = np.linalg.norm(seq.gt.center[8, d] - seq.gt.center[8, o])
    assert gap > 30
    assert seq.gt.depth[3, d] == 0


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_dps_distractor_overlaps_object1_for_a_few_frames(seed):
    # The preset's docstring (issue 14) relies on this: the distractor's box meets object
    # 1's for 2-6 frames from frame 3 (longer than one frame, so a track can be pulled
    # along), then they are apart until it vanishes at frame 9.
    seq = scenegen.generate("dps-synthetic", seed=seed)
    d, o = seq.entities.index_of("distractor1"), seq.entities.index_of("object1")
    bd, bo = np.asarray(seq.gt.box[:, d], float), np.asarray(seq.gt.box[:, o], float)
    w = np.minimum(bd[:, 0] + bd[:, 2], bo[:, 0] + bo[:, 2]) - np.maximum(bd[:, 0], bo[:, 0])
    h = np.minimum(bd[:, 1] + bd[:, 3], bo[:, 1] + bo[:, 3]) - np.maximum(bd[:, 1], bo[:, 1])
    meet = np.nan_to_num(w) > 0
    meet &= np.nan_to_num(h) > 0
    frames = np.flatnonzero(meet)
    assert 2 <= frames.size <= 6
    assert frames[0] == 3 and np.all(np.diff(frames) == 1)


def test_dps_occlusion_has_total_occlusion():
    seq = scenegen.generate("dps-occlusion", seed=0)
    walker = seq.entities.index_of("walker")
    vis = seq.gt.visibility[:, walker]
    hidden = np.flatnonzero(vis == 0)
    assert hidden.size >= 6
    # Two separate occlusions, each behind one stationary person.
    assert np.any(np.diff(hidden) > 10)


@pytest.mark.parametrize(("preset", "sigma", "n"), [("kams-a", 4, 100), ("kams-d", 14, 600)])
def test_kams_levels(preset, sigma, n):
    seq = scenegen.generate(preset, seed=0)
    assert (seq.entities.role == "clutter").sum() == n
    cfg = seq.config
    assert cfg.entities[0].position_noise == sigma
    assert (cfg.width, cfg.height, cfg.n_frames) == (320, 240, 140)


def test_templates_are_the_entities_alone():
    seq = scenegen.generate("kams-a", seed=0, frames=2)
    assert set(seq.templates) == set(seq.entities.id.tolist())
    for eid, tpl in seq.templates.items():
        assert tpl.dtype == np.uint8 and tpl.ndim == 3 and tpl.shape[2] == 4
        alpha = tpl[..., 3] > 0
        assert alpha.any(axis=0).all() and alpha.any(axis=1).all(), eid  # tight


def test_one_pixel_entity_and_single_frame():
    cfg = SceneConfig(
        width=9,
        height=7,
        n_frames=1,
        entities=(
            EntitySpec(
                name="dot",
                role="target",
                appearance=Appearance(size=(1, 1), colors=((10, 20, 30),)),
                position=(4.5, 3.5),
            ),
        ),
    )
    seq = scenegen.generate(cfg, seed=0)
    np.testing.assert_array_equal(seq.gt.box[0, 0], [4, 3, 1, 1])
    np.testing.assert_array_equal(seq.gt.visible_box[0, 0], [4, 3, 1, 1])
    assert seq.labels[0, 3, 4] == 1 and seq.labels.sum() == 1
    assert tuple(seq.frames[0, 3, 4]) == (10, 20, 30)


def test_path_center_is_the_centre_before_position_noise():
    # gt/path_center: the AR2 path; gt/center: the path plus per-frame noise, rounded to pixels.
    walk = Motion(
        x=AR2(boundary="reflect", sigma=0.5, margin=20),
        y=AR2(boundary="reflect", sigma=0.5, margin=20),
    )
    app = Appearance(shape="rect", size=(5, 5))
    cfg = SceneConfig(
        width=400,
        height=400,
        n_frames=400,
        background=Background(kind="uniform"),
        entities=(
            EntitySpec(name="calm", role="target", appearance=app, position=(100.0, 200.0),
                       motion=walk, depth=((0, 0),)),
            EntitySpec(name="noisy", role="target", appearance=app, position=(300.0, 200.0),
                       motion=walk, position_noise=3.0, depth=((0, 1),)),
            EntitySpec(name="late", role="distractor", appearance=app, position=(200.0, 50.0),
                       appear=100, disappear=300, depth=((0, 2),)),
        ),
    )  # fmt: skip
    gt = scenegen.generate(cfg, seed=4).gt
    present = gt.present
    assert np.array_equal(np.isnan(gt.path_center).any(axis=-1), ~present)
    off = gt.center - gt.path_center
    assert np.abs(off[:, 0]).max() <= 0.5  # no noise: rounding only
    noisy = off[:, 1]
    assert np.abs(noisy.mean(axis=0)).max() < 0.5
    np.testing.assert_allclose(noisy.std(axis=0), np.hypot(3.0, 12**-0.5), rtol=0.15)
    np.testing.assert_array_equal(gt.path_center[100:300, 2], np.float32([[200.0, 50.0]] * 200))


def test_dps_dancers_partial_occlusion_and_erratic_sway():
    # The tuned dps-dancers (see its docstring): dancer 4 passes partly behind dancer 3
    # (less than half visible at the closest point, mostly not totally hidden), and the
    # sway is erratic (acceleration noise σ = 2 px/frame²).
    mins, acc = [], []
    for seed in (101, 102, 103, 104):
        seq = scenegen.generate("dps-dancers", seed=seed)
        vis = np.asarray(seq.gt.visibility)[:, 3]
        mins.append(vis.min())
        assert vis[0] == 1.0 and vis[15:21].min() > 0.9  # visible between the crossings
        cx = np.asarray(seq.gt.center)[:, :, 0]
        acc.append(np.nanstd(np.diff(cx, 2, axis=0)))
    assert np.median(mins) < 0.5 and max(mins) > 0.0
    assert min(acc) > 1.5


@pytest.mark.parametrize("appear", [6, 7, 11, 12])
def test_a_mimic_appearing_at_or_past_the_end_is_never_present(appear):
    # n_frames <= appear < 2 n_frames was an internal error (a negative slice stop).
    from scenegen.config import from_dict
    from scenegen.render.plan import generate

    cfg = from_dict({"width": 40, "height": 30, "n_frames": 6, "entities": [
        {"name": "t", "role": "target", "position": [10, 10]},
        {"name": "m", "role": "distractor", "mimic": "t", "appear": appear, "depth": 1},
    ]})  # fmt: skip
    seq = generate(cfg, seed=1)
    assert not seq.gt.present[:, 1].any() and seq.gt.present[:, 0].all()


@pytest.mark.parametrize("frames", ["3", 2.5, True, 0])
def test_generate_frames_must_be_a_positive_integer(frames):
    # "3" was a raw TypeError; 2.5 silently made 2 frames.
    from scenegen.errors import ConfigError

    with pytest.raises(ConfigError, match="frames must be an integer >= 1"):
        scenegen.generate("kams-a", seed=1, frames=frames)


@pytest.mark.parametrize("position", [[-9, -7], [49, 37], [49, -7], [-9, 37]])
def test_an_entity_whose_shape_is_wholly_outside_the_frame_is_not_present(position):
    # Only a transparent corner pixel of the ellipse's template rectangle overlaps the
    # frame, at one of its corners: it
    # was "present" with visibility 0 and no pixel, and trackers were started on it.
    from scenegen.config import from_dict
    from scenegen.render.plan import generate

    cfg = from_dict({"width": 40, "height": 30, "n_frames": 2, "entities": [
        {"name": "t", "role": "target", "position": [20, 15]},
        {"name": "b", "role": "target", "position": position, "depth": 1,
         "appearance": {"shape": "ellipse", "size": [20, 16]}},
    ]})  # fmt: skip
    seq = generate(cfg, seed=0)
    assert not seq.gt.present[:, 1].any() and np.isnan(seq.gt.box[:, 1]).all()
    assert seq.initial_targets().tolist() == [0]


@pytest.mark.parametrize(("boundary", "frame1"), [("reflect", 63.0), ("clamp", 35.0)])
def test_a_start_outside_a_bounded_axis_is_brought_inside_at_frame_1(boundary, frame1):
    # Documented in AR2's docstring and the README: the limits [margin + w/2,
    # width - margin - w/2] apply from frame 1; an explicit start outside them is kept
    # at frame 0 (an entity may enter from outside, as the testing strategies draw).
    ar = AR2(boundary=boundary, a1=2.0, a2=-1.0, sigma=0.0, margin=20)
    motion = Motion(x=ar, y=ar, velocity=(2.0, 0.0))
    e = EntitySpec(name="t", role="target", appearance=Appearance(size=(30, 30)),
                   position=(5.0, 60.0), motion=motion)  # fmt: skip
    cfg = SceneConfig(width=320, height=120, n_frames=3, entities=(e,))
    path = scenegen.generate(cfg, seed=0).gt.path_center[:, 0, 0]
    assert path[0] == 5.0 and path[1] == frame1 and 35.0 <= path[2] <= 285.0


@pytest.mark.parametrize(("frame", "error"), [
    (5, IndexError), (-6, IndexError), (1.5, TypeError), (True, TypeError),
    ("0", TypeError), ([0, 1], TypeError), (None, TypeError),
])  # fmt: skip
def test_a_frame_outside_the_sequence_is_one_line_naming_frame_and_the_range(frame, error):
    # Was numpy's IndexError naming neither ([0, 1] even returned boxes of two frames).
    seq = scenegen.generate("shm-crossing", seed=3, frames=5)
    for method in (seq.init_boxes, seq.initial_targets):
        with pytest.raises(error, match=r"^frame must be an integer in \[-5, 4\], got "):
            method(frame)
    assert seq.init_boxes(np.int64(-5)).tolist() == seq.init_boxes(0).tolist()
