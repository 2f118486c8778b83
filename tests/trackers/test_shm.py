"""SHM trackers (shm, shm-fast): depth order and positions through occlusions."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import trackers
from scenegen.evaluation.metrics import box_area, intersection_area
from trackers.models.layered import orderings
from trackers.shm import transition_matrix


def _texture(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    t = rng.integers(0, 256, (h // 4 + 2, w // 4 + 2, 3)).astype(np.float32)
    big = cv2.resize(t, (w + 8, h + 8), interpolation=cv2.INTER_CUBIC)
    return big[4 : 4 + h, 4 : 4 + w].clip(0, 255).astype(np.uint8)


def _crossing(seed: int, n_frames: int = 80, period: int = 40, size: int = 30, n_static=0):
    """Two textured squares oscillating in antiphase; the front one swaps at each crossing.

    ``n_static`` more squares stand still in the bottom row, behind the moving ones.
    Returns frames (T, H, W, 3), boxes0 (M, 4), true centres (T, M, 2), depth (T, M).
    """
    rng = np.random.default_rng(seed)
    h, w = 120, 200
    bg = _texture(rng, h, w)
    tpl = [_texture(rng, size, size) for _ in range(2 + n_static)]
    t = np.arange(n_frames)
    x = np.stack([85 + 55 * np.cos(2 * np.pi * t / period),
                  85 - 55 * np.cos(2 * np.pi * t / period)], axis=1)
    y = np.array([40.0, 44.0])
    # Crossings at t = period/4 + k period/2; the order swaps halfway between crossings.
    a_front = ((t + period // 4) // (period // 2)) % 2 == 0
    x = np.concatenate([x, np.tile(10.0 + 45 * np.arange(n_static), (n_frames, 1))], axis=1)
    y = np.concatenate([y, np.full(n_static, 85.0)])
    depth = np.where(a_front[:, None], [0, 1], [1, 0])
    depth = np.concatenate([depth, np.tile(2 + np.arange(n_static), (n_frames, 1))], axis=1)
    frames = np.empty((n_frames, h, w, 3), np.uint8)
    for k in range(n_frames):
        f = bg.astype(np.float64)
        for m in np.argsort(-depth[k]):  # far first
            xi, yi = int(round(x[k, m])), int(y[m])
            f[yi : yi + size, xi : xi + size] = tpl[m]
        frames[k] = np.clip(f + rng.normal(0, 3.0, f.shape), 0, 255).astype(np.uint8)
    xr = np.round(x)
    centres = np.stack([xr + size / 2, np.broadcast_to(y + size / 2, xr.shape)], axis=2)
    boxes0 = np.column_stack([xr[0], y, np.full_like(y, size), np.full_like(y, size)])
    return frames, boxes0, centres, depth


def _overlap(boxes: np.ndarray) -> np.ndarray:
    """Overlap of the two targets' boxes (T, 2, 4) as a fraction of the smaller box."""
    inter = intersection_area(boxes[:, 0], boxes[:, 1])
    return inter / np.minimum(box_area(boxes[:, 0]), box_area(boxes[:, 1]))


def _ordering_index(orderings: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """Index of the ordering (rows nearest first) matching each frame's depth (T, M)."""
    truth = np.argsort(depth, axis=1, kind="stable")
    return np.array([np.flatnonzero((orderings == row).all(axis=1))[0] for row in truth])


def _centre_error(result, centres):
    est = result.boxes[:, :, :2] + result.boxes[:, :, 2:] / 2
    return np.linalg.norm(est - centres, axis=2)


@pytest.mark.parametrize(
    "name, params",
    [
        ("shm", {}),
        ("shm-fast", {}),
        ("shm", {"evidence": "objects"}),
        ("shm-fast", {"evidence": "objects"}),
        ("shm", {"use_mse": False}),
        ("shm-fast", {"motion": "ar2", "step": 1}),
    ],
)
def test_synthetic_crossing_order_and_positions(name, params):
    frames, boxes0, centres, depth = _crossing(0)
    tracker = trackers.make(name, **params)
    res = trackers.track(tracker, frames, boxes0)
    assert tracker.orderings.dtype == np.int16 and tracker.orderings.shape == (2, 2)
    prob = res.extras["order_prob"]
    assert prob.shape == (len(frames), 2)
    np.testing.assert_allclose(prob[1:].sum(axis=1), 1.0)
    boxes = np.concatenate([centres - 15, np.full_like(centres, 30)], axis=2)
    occl = _overlap(boxes) >= 0.2
    occl[0] = False
    truth = _ordering_index(tracker.orderings, depth)
    assert occl.sum() >= 8
    assert (prob.argmax(axis=1) == truth)[occl].mean() >= 0.9
    assert _centre_error(res, centres)[1:].max() < 3.0


@pytest.mark.parametrize("name", ["shm", "shm-fast"])
def test_probabilities_relax_to_equal_once_objects_are_apart(name):
    frames, boxes0, centres, depth = _crossing(0)
    boxes = np.concatenate([centres - 15, np.full_like(centres, 30)], axis=2)
    touching = _overlap(boxes) > 0
    since = np.zeros(len(frames), int)  # frames since the boxes last touched
    for t in range(1, len(frames)):
        since[t] = 0 if touching[t] else since[t - 1] + 1
    prob = trackers.track(trackers.make(name), frames, boxes0).extras["order_prob"]
    apart = (since >= 8) & (np.arange(len(frames)) > 20)
    assert apart.sum() >= 10
    assert np.abs(prob[apart] - 0.5).max() < 0.05
    # ... while during the crossings one ordering clearly dominated.
    assert np.abs(prob[1:] - 0.5).max() > 0.45


@pytest.mark.parametrize("name, n_static", [("shm-fast", 1), ("shm-fast", 2), ("shm", 1)])
def test_pairwise_order_among_more_objects(name, n_static):
    frames, boxes0, centres, depth = _crossing(3, n_frames=60, n_static=n_static)
    tracker = trackers.make(name)
    res = trackers.track(tracker, frames, boxes0)
    n_obj = 2 + n_static
    assert tracker.orderings.shape == (len(np.unique(tracker.orderings, axis=0)), n_obj)
    prob = res.extras["order_prob"]
    assert prob.shape == (60, 6 if n_obj == 3 else 24)
    # P(object 0 in front of object 1): orderings listing 0 before 1.
    pos = np.argsort(tracker.orderings, axis=1)
    p01 = prob[:, pos[:, 0] < pos[:, 1]].sum(axis=1)
    boxes = np.concatenate([centres - 15, np.full_like(centres, 30)], axis=2)
    occl = _overlap(boxes[:, :2]) >= 0.2
    occl[0] = False
    assert ((p01 > 0.5) == (depth[:, 0] < depth[:, 1]))[occl].mean() >= 0.9
    assert _centre_error(res, centres)[1:].max() < 3.0


def test_fast_shm_beats_kalman_during_synthetic_occlusions():
    frames, boxes0, centres, depth = _crossing(1)
    boxes = np.concatenate([centres - 15, np.full_like(centres, 30)], axis=2)
    occl = _overlap(boxes) >= 0.2
    err_fast = _centre_error(trackers.track(trackers.make("shm-fast"), frames, boxes0), centres)
    err_kal = _centre_error(trackers.track(trackers.make("kalman"), frames, boxes0), centres)
    assert err_fast[occl].mean() < err_kal[occl].mean()


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n_obj=st.integers(2, 3),
       name=st.sampled_from(["shm", "shm-fast"]))
def test_non_overlapping_objects_keep_equal_ordering_probabilities(seed, n_obj, name):
    rng = np.random.default_rng(seed)
    h, w, size = 90, 240, 20
    bg = _texture(rng, h, w)
    tpls = [_texture(rng, size, size) for _ in range(n_obj)]
    x0 = 10 + 80 * np.arange(n_obj)
    vx = rng.uniform(-1.5, 1.5, n_obj)
    frames = np.empty((20, h, w, 3), np.uint8)
    for t in range(20):
        f = bg.copy()
        for m in range(n_obj):
            xi = int(round(x0[m] + 20 + vx[m] * t))
            f[35 : 35 + size, xi : xi + size] = tpls[m]
        frames[t] = f
    boxes0 = np.array([[x0[m] + 20, 35, size, size] for m in range(n_obj)], float)
    res = trackers.track(trackers.make(name), frames, boxes0)
    prob = res.extras["order_prob"][1:]
    assert prob.shape[1] == (2 if n_obj == 2 else 6)
    np.testing.assert_allclose(prob, 1.0 / prob.shape[1], rtol=0, atol=1e-6)


def test_shm_with_one_object_equals_kalman():
    frames, boxes0, _, _ = _crossing(2, n_frames=40)
    for k in range(2):
        a = trackers.track(trackers.make("shm"), frames, boxes0[k : k + 1])
        b = trackers.track(trackers.make("kalman"), frames, boxes0[k : k + 1])
        np.testing.assert_allclose(a.boxes, b.boxes, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(a.extras["order_prob"][1:], 1.0)


@pytest.mark.parametrize("name", ["shm", "shm-fast"])
def test_object_leaving_the_frame_does_not_crash(name):
    rng = np.random.default_rng(5)
    h, w, size = 80, 120, 20
    bg = _texture(rng, h, w)
    ta, tb = _texture(rng, size, size), _texture(rng, size, size)
    frames = np.empty((40, h, w, 3), np.uint8)
    for t in range(40):
        f = bg.copy()
        xa = 80 + 4 * t  # leaves on the right after ~10 frames
        if xa < w:
            f[10 : 10 + size, xa : min(xa + size, w)] = ta[:, : min(size, w - xa)]
        f[50 : 50 + size, 20 : 20 + size] = tb
        frames[t] = f
    boxes0 = np.array([[80, 10, size, size], [20, 50, size, size]], float)
    tracker = trackers.make(name)
    res = trackers.track(tracker, frames, boxes0)
    assert np.all(np.isfinite(res.boxes))
    est = res.boxes[:, :, :2] + res.boxes[:, :, 2:] / 2
    assert np.all(est[:, 0, 0] <= w)  # clipped into the frame
    np.testing.assert_allclose(est[:, 1], [[30.0, 60.0]] * 40, atol=0.5)
    assert np.all(np.isfinite(res.extras["order_prob"][1:]))


@pytest.mark.parametrize("name", ["shm", "shm-fast"])
def test_more_than_four_objects_is_refused(name):
    frame = np.zeros((100, 200, 3), np.uint8)
    boxes = [[10 + 35 * k, 10, 20, 20] for k in range(5)]
    with pytest.raises(ValueError, match=r"5 objects give 120 depth orderings.*at most 4"):
        trackers.make(name).init(frame, boxes)


@pytest.mark.parametrize("name", ["shm", "shm-fast"])
@pytest.mark.parametrize(
    "params, match",
    [
        (dict(p_stay=0.0), "p_stay"),
        (dict(p_stay=1.5), "p_stay"),
        (dict(lam=-1.0), "lam"),
        (dict(mse_rate=0.0), "mse_rate"),
        (dict(mse_floor=0.0), "mse_floor"),
        (dict(evidence="pixels"), "unknown evidence 'pixels'; valid: union, objects"),
        (dict(motion="jerk"), "unknown motion"),
        (dict(support="disc"), "unknown support"),
    ],
)
def test_bad_parameters(name, params, match):
    with pytest.raises(ValueError, match=match):
        trackers.make(name, **params)


def test_unknown_parameter_is_rejected_by_name():
    with pytest.raises(ValueError, match="unknown parameter 'n_particles'"):
        trackers.make("shm-fast", n_particles=10)


def test_transition_matrix_rows_sum_to_one():
    for n in (1, 2, 6, 24):
        pi = transition_matrix(n, 0.8)
        np.testing.assert_allclose(pi.sum(axis=1), 1.0)
        assert pi[0, 0] == pytest.approx(0.8 if n > 1 else 1.0)


# --- the shm-crossing preset -------------------------------------------------------------


def _preset_run(scenegen_sequence, seed, names):
    seq = scenegen_sequence("shm-crossing", seed=seed)
    ti = seq.target_indices()
    frames = np.asarray(seq.frames)
    gt_box = np.asarray(seq.gt.box)[:, ti]
    out = {n: trackers.track(trackers.make(n), frames, gt_box[0]) for n in names}
    return seq, ti, gt_box, out


@pytest.mark.scenegen
@pytest.mark.parametrize("seed", [0, 1])
def test_shm_crossing_depth_order_and_occlusion_error(scenegen_sequence, seed):
    seq, ti, gt_box, res = _preset_run(scenegen_sequence, seed, ["kalman", "shm", "shm-fast"])
    depth = np.asarray(seq.gt.depth)[:, ti]
    centres = np.asarray(seq.gt.center)[:, ti]
    occl = _overlap(gt_box) >= 0.2
    occl[0] = False
    assert occl.sum() >= 10
    for name in ("shm", "shm-fast"):
        prob = res[name].extras["order_prob"]
        truth = _ordering_index(orderings(2), depth)
        accuracy = (prob.argmax(axis=1) == truth)[occl].mean()
        assert accuracy >= 0.9, (name, accuracy)
    err = {n: _centre_error(r, centres) for n, r in res.items()}
    assert err["shm-fast"][occl].mean() < err["kalman"][occl].mean()
