"""Oracle: the depth-ordering posterior of the SHM trackers (Wang, Tan & Loe 2007).

Two exact statements of the model (§2.2, §3.2, §3.3):

- with no evidence (objects apart: every ordering gives the same measurements and the
  same squared differences), the posterior is the previous one pushed through the Markov
  chain, P_t = P_{t-1} Pi. With L orderings, Pi = p_stay I + (1 - p_stay) (J - I) / (L - 1)
  moves every deviation from the uniform 1/L by the factor (L p_stay - 1) / (L - 1),
  which is 2 p_stay - 1 for two objects; exactly, frame after frame;
- with evidence (a known overlap, one object in front), the true ordering wins.

A filter that drops the previous posterior forgets to 1/L at once; one that drops the
Markov prior never relaxes: both fail the first test.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import trackers
from trackers.models.layered import LayeredMatcher

NAMES = ["shm", "shm-fast"]


def texture(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    t = rng.integers(0, 256, (h // 4 + 2, w // 4 + 2, 3)).astype(np.float32)
    big = cv2.resize(t, (w + 8, h + 8), interpolation=cv2.INTER_CUBIC)
    return big[4: 4 + h, 4: 4 + w].clip(0, 255).astype(np.uint8)


def scene(seed: int, xs: np.ndarray, ys: np.ndarray, size: int = 24,
          h: int = 100, w: int = 180) -> tuple[np.ndarray, np.ndarray]:
    """Textured squares at top-left corners (T, M) ``xs``, ``ys``; object 0 in front.

    Returns frames (T, H, W, 3) and the initial boxes (M, 4).
    """
    rng = np.random.default_rng(seed)
    bg = texture(rng, h, w)
    n_frames, n_obj = xs.shape
    tpl = [texture(rng, size, size) for _ in range(n_obj)]
    frames = np.empty((n_frames, h, w, 3), np.uint8)
    for t in range(n_frames):
        f = bg.astype(np.float64)
        for m in reversed(range(n_obj)):  # far first: object 0 is painted last
            x, y = int(xs[t, m]), int(ys[t, m])
            f[y: y + size, x: x + size] = tpl[m]
        frames[t] = np.clip(f + rng.normal(0, 2.0, f.shape), 0, 255).astype(np.uint8)
    boxes0 = np.column_stack([xs[0], ys[0], np.full(n_obj, size), np.full(n_obj, size)])
    return frames, boxes0.astype(np.float64)


def apart(n_obj: int, n_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """Static objects far apart."""
    xs = np.tile(10.0 + 55.0 * np.arange(n_obj), (n_frames, 1))
    ys = np.tile(20.0 + 25.0 * (np.arange(n_obj) % 2), (n_frames, 1))
    return xs, ys


def relaxation_factor(n_orderings: int, p_stay: float) -> float:
    return (n_orderings * p_stay - 1.0) / (n_orderings - 1.0)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("p_stay", [0.6, 0.8, 0.95])
def test_without_evidence_the_posterior_relaxes_by_2p_minus_1_per_frame(name, p_stay):
    frames, boxes0 = scene(1, *apart(2, 8))
    tracker = trackers.make(name, p_stay=p_stay)
    tracker.init(frames[0], boxes0)
    tracker.step(frames[1])
    np.testing.assert_allclose(tracker.order_prob, 0.5, rtol=0, atol=1e-12)
    # Put a belief in: object 1 in front with probability 0.9 (ordering row 1 = (1, 0)).
    tracker.order_prob = np.array([0.1, 0.9])
    dev = 0.4
    for frame in frames[2:]:
        est = tracker.step(frame)
        dev *= 2 * p_stay - 1
        np.testing.assert_allclose(est.extras["order_prob"], [0.5 - dev, 0.5 + dev], rtol=0,
                                   atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_with_three_objects_the_factor_is_l_p_minus_1_over_l_minus_1(name):
    frames, boxes0 = scene(2, *apart(3, 5))
    tracker = trackers.make(name, p_stay=0.7)
    tracker.init(frames[0], boxes0)
    tracker.step(frames[1])
    start = np.array([0.5, 0.2, 0.1, 0.1, 0.05, 0.05])
    tracker.order_prob = start.copy()
    f = relaxation_factor(6, 0.7)
    for n, frame in enumerate(frames[2:], start=1):
        prob = tracker.step(frame).extras["order_prob"]
        np.testing.assert_allclose(prob, 1 / 6 + f**n * (start - 1 / 6), rtol=0, atol=1e-12)


def approach_and_overlap(n_frames: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """Object 0 moves 2 px a frame onto object 1 (in front of it), then stops with half of
    object 1 hidden; a third object far away never overlaps."""
    x0 = np.minimum(20.0 + 2.0 * np.arange(n_frames), 58.0)
    xs = np.column_stack([x0, np.full(n_frames, 70.0)])
    ys = np.column_stack([np.full(n_frames, 30.0), np.full(n_frames, 34.0)])
    return xs, ys


@pytest.mark.parametrize("name", NAMES)
def test_known_overlap_gives_the_true_ordering_high_probability(name):
    xs, ys = approach_and_overlap()
    frames, boxes0 = scene(3, xs, ys)
    tracker = trackers.make(name)
    result = trackers.track(tracker, frames, boxes0)
    prob = result.extras["order_prob"]
    true_row = int(np.flatnonzero((tracker.orderings == [0, 1]).all(axis=1))[0])
    overlap = np.clip(24 - np.abs(xs[:, 0] - xs[:, 1]), 0, None) / 24
    settled = overlap >= 0.4
    assert settled.sum() >= 8
    assert prob[settled, true_row].min() > 0.9
    # Positions stay on the objects, the hidden one included.
    centres = np.stack([xs + 12, ys + 12], axis=2)
    est = result.boxes[:, :, :2] + result.boxes[:, :, 2:] / 2
    assert np.abs(est - centres)[1:].max() < 3.0


@pytest.mark.parametrize("name", NAMES)
def test_after_the_overlap_the_belief_fades_at_the_markov_rate(name):
    # Overlap, then object 0 jumps back out of the way: from then on no evidence, and
    # shm-fast's posterior follows the chain exactly; shm's Gaussians per ordering still
    # differ from the overlap, so for it the fade is only required to be monotone.
    n = 36
    xs, ys = approach_and_overlap(n)
    xs[26:, 0] = xs[26:, 0] - 4.0 * np.arange(1, n - 25)  # moves off again
    frames, boxes0 = scene(4, xs, ys)
    tracker = trackers.make(name, p_stay=0.8)
    prob = trackers.track(tracker, frames, boxes0).extras["order_prob"][:, 0]
    free = np.clip(24 - np.abs(xs[:, 0] - xs[:, 1]), 0, None) == 0
    free[:26] = False
    t0 = int(np.flatnonzero(free)[0])
    assert prob[25] > 0.9 and t0 < n - 4
    dev = prob[t0:] - 0.5
    if name == "shm-fast":
        np.testing.assert_allclose(dev[1:], 0.6 * dev[:-1], rtol=1e-9, atol=1e-12)
    else:
        assert np.all(np.diff(dev) < 0) and np.all(dev > 0)


@pytest.mark.parametrize("evidence", ["union", "objects"])
@pytest.mark.parametrize("lam", [0.5, 2.0])
def test_first_overlap_posterior_is_the_squared_difference_evidence(evidence, lam):
    # Frame 0 apart, frame 1 object 0 jumps 10 px onto object 1 (in front). From rest the
    # prediction is the initial centres, so the measurements are those of the matcher at
    # the initial centres; with a uniform prior P(j) ∝ exp(-lam E_j / e_bar) (§3.3), e_bar
    # the first frame's smallest mean (floored), per object for "objects".
    xs = np.array([[40.0, 70.0], [50.0, 70.0]])
    ys = np.array([[30.0, 34.0], [30.0, 34.0]])
    frames, boxes0 = scene(5, xs, ys)
    tracker = trackers.make("shm-fast", lam=lam, evidence=evidence, mse_floor=1.0)
    tracker.init(frames[0], boxes0)
    prob = tracker.step(frames[1]).extras["order_prob"]
    matcher = LayeredMatcher(frames[0], boxes0, search_radius=12, step=2, min_visible=0.25,
                             support="ellipse", blur=2.0)
    centres0 = boxes0[:, :2] + boxes0[:, 2:] / 2
    meas = matcher.measure(frames[1], centres0, tracker.orderings.astype(np.int64))
    if evidence == "union":
        e = (meas.mse * meas.counts).sum(axis=1) / meas.counts.sum(axis=1)  # (L,)
        log_ev = -lam * e / max(e.min(), 1.0)
    else:
        e = meas.mse                                                         # (L, M)
        scale = np.maximum(e.min(axis=0), 1.0)
        log_ev = -lam * (e / scale).sum(axis=1)
    expected = np.exp(log_ev - log_ev.max())
    np.testing.assert_allclose(prob, expected / expected.sum(), rtol=1e-9)
    assert prob[0] > prob[1]  # object 0 in front explains the overlap better



def test_fast_shm_update_is_the_kalman_update_with_the_moment_matched_measurement():
    # As above, frame 1 overlaps (by half); each object's measurement is the mixture over
    # orderings moment-matched: y = sum_j P_j y^j, R = sum_j P_j (R^j + (y^j - y)(y^j - y)'),
    # fed to the object's Kalman filter; on frame 2 the evidence scale is the moving
    # average of frame 1's. (Here both orderings find the same centres, so the spread
    # term (y^j - y)(y^j - y)' is zero; test_shm_scripted.py sets centres that differ.)
    xs = np.array([[46.0, 70.0], [58.0, 70.0], [59.0, 70.0]])
    ys = np.array([[30.0, 34.0], [30.0, 34.0], [30.0, 34.0]])
    frames, boxes0 = scene(5, xs, ys)
    lam, rate = 1.0, 0.3
    tracker = trackers.make("shm-fast", lam=lam, mse_rate=rate, mse_floor=1.0)
    tracker.init(frames[0], boxes0)
    matcher = LayeredMatcher(frames[0], boxes0, search_radius=12, step=2, min_visible=0.25,
                             support="ellipse", blur=2.0)
    centres0 = boxes0[:, :2] + boxes0[:, 2:] / 2
    rows = tracker.orderings.astype(np.int64)
    kf = tracker.kf
    scale = None
    prob = np.full(2, 0.5)
    for frame in frames[1:3]:
        x_pred = kf.x @ kf.F.T
        p_pred = kf.F @ kf.P @ kf.F.T + kf.Q
        meas = matcher.measure(frame, centres0 + x_pred[:, :2], rows)
        e = (meas.mse * meas.counts).sum(axis=1) / meas.counts.sum(axis=1)
        scale = max(e.min(), 1.0) if scale is None else scale
        prior = prob @ np.array([[0.8, 0.2], [0.2, 0.8]])
        post = prior * np.exp(-lam * e / scale)
        prob = post / post.sum()
        scale = max((1 - rate) * scale + rate * e.min(), 1.0)
        est = tracker.step(frame)
        np.testing.assert_allclose(est.extras["order_prob"], prob, rtol=1e-9)
        for m in range(2):
            y_j = meas.centres[:, m] - centres0[m]                       # (L, 2)
            y = prob @ y_j
            dev = y_j - y
            r = sum(prob[j] * ((0.5 + 0.01 * meas.mse[j, m]) * np.eye(2)
                               + np.outer(dev[j], dev[j])) for j in range(2))
            h = kf.H
            s = h @ p_pred[m] @ h.T + r
            gain = p_pred[m] @ h.T @ np.linalg.inv(s)
            np.testing.assert_allclose(kf.x[m], x_pred[m] + gain @ (y - h @ x_pred[m]),
                                       rtol=0, atol=1e-9)
