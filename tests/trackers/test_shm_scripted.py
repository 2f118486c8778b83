"""The SHM trackers' updates from scripted measurements, against the formulas.

The template matcher is replaced by a script of ``LayeredMeasurement`` values, so each
test sets exactly what every ordering measured: centres that differ between orderings
(the spread terms of the moment matching), objects missed under some orderings (the
fast filter's half-probability rule) and frames where nothing is measured (the GPB2
collapse of the predictions alone). Each result is recomputed here from the Kalman
equations and compared.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import trackers
from trackers.models.layered import LayeredMeasurement

H, W = 90, 160
BOXES = np.array([[20.0, 30.0, 30.0, 18.0], [100.0, 40.0, 24.0, 24.0]])  # (x, y, w, h)
CENTRES = BOXES[:, :2] + BOXES[:, 2:] / 2


class Script:
    """A matcher that returns the scripted measurements one frame after another."""

    def __init__(self, steps: list[LayeredMeasurement]) -> None:
        self.steps = list(steps)
        self.asked: list[np.ndarray] = []

    def measure(self, frame, centres, order, **_):
        self.asked.append(np.array(centres, dtype=np.float64))
        return self.steps.pop(0)


def measurement(shift: np.ndarray, mse: np.ndarray) -> LayeredMeasurement:
    """Centres at the first centres + ``shift`` (L, M, 2); NaN mse = missed."""
    centres = CENTRES[None] + shift
    missed = np.isnan(mse)
    centres[missed] = np.nan
    counts = np.where(missed, 0, 400).astype(np.int64)
    return LayeredMeasurement(centres, np.asarray(mse, dtype=np.float64), counts, 1)


def started(name: str, steps: list[LayeredMeasurement], **params):
    frame = np.random.default_rng(0).integers(0, 256, (H, W, 3)).astype(np.uint8)
    tracker = trackers.make(name, **params)
    tracker.init(frame, BOXES)
    tracker.matcher = Script(steps)
    return tracker, frame


def kalman(x, p, f, q, h, z, r):
    """One predict + update of one filter; z None: missed."""
    x, p = f @ x, f @ p @ f.T + q
    if z is None:
        return x, p
    s = h @ p @ h.T + r
    k = p @ h.T @ np.linalg.inv(s)
    return x + k @ (z - h @ x), (np.eye(len(x)) - k @ h) @ p


def test_the_first_centres_are_the_boxes_centres_for_boxes_that_are_not_square():
    for name in ("shm", "shm-fast"):
        still = measurement(np.zeros((2, 2, 2)), np.full((2, 2), 5.0))
        tracker, frame = started(name, [still])
        np.testing.assert_array_equal(tracker.order_prob, [0.5, 0.5])  # no belief yet
        est = tracker.step(frame)
        np.testing.assert_allclose(tracker.matcher.asked[0], CENTRES, atol=1e-9)
        np.testing.assert_allclose(est.boxes, BOXES, atol=1e-9)


def test_a_missed_object_has_the_uniform_density_of_the_frame():
    tracker, _ = started("shm", [])
    assert tracker._log_u == pytest.approx(-np.log(H * W))


def test_fast_shm_mixes_ordering_dependent_measurements_with_their_spread():
    # Equal evidence: P = (1/2, 1/2); object 0 is measured 4 px right under ordering 0
    # and 4 px left under ordering 1, so y = 0 and R = r I + 16 e_x e_x'.
    shift = np.zeros((2, 2, 2))
    shift[0, 0, 0], shift[1, 0, 0] = 4.0, -4.0
    shift[:, 1] = [1.0, 2.0]
    mse = np.full((2, 2), 30.0)
    tracker, frame = started("shm-fast", [measurement(shift, mse)], r_gain=0.01, r_floor=0.5)
    kf = tracker.kf
    x0, p0, f, q, h = kf.x.copy(), kf.P.copy(), kf.F, kf.Q, kf.H
    est = tracker.step(frame)
    np.testing.assert_allclose(est.extras["order_prob"], [0.5, 0.5])
    r = (0.5 + 0.01 * 30.0) * np.eye(2)
    want = [kalman(x0[0], p0[0], f, q, h, np.zeros(2), r + np.diag([16.0, 0.0])),
            kalman(x0[1], p0[1], f, q, h, np.array([1.0, 2.0]), r)]
    for m, (x, p) in enumerate(want):
        np.testing.assert_allclose(kf.x[m], x, atol=1e-9)
        np.testing.assert_allclose(kf.P[m], p, atol=1e-9)


@pytest.mark.parametrize("mse_hidden, seen", [(30.0, True), (10.0, False)])
def test_fast_shm_uses_an_object_measured_under_at_least_half_the_probability(
        mse_hidden, seen):
    # Object 1 is missed under ordering 0. With equal evidence it is measured under
    # half the probability: its measurement (3 px right, from ordering 1) is used. When
    # ordering 0 explains the frame better, it is measured under less than half: missed.
    shift = np.zeros((2, 2, 2))
    shift[1, 1, 0] = 3.0
    mse = np.array([[mse_hidden, np.nan], [30.0, 30.0]])
    tracker, frame = started("shm-fast", [measurement(shift, mse)], r_gain=0.0, r_floor=0.5)
    kf = tracker.kf
    x0, p0, f, q, h = kf.x[1].copy(), kf.P[1].copy(), kf.F, kf.Q, kf.H
    est = tracker.step(frame)
    prob = est.extras["order_prob"]
    assert (prob[1] >= 0.5) == seen and (prob[1] == 0.5) == seen
    x, p = kalman(x0, p0, f, q, h, np.array([3.0, 0.0]) if seen else None, 0.5 * np.eye(2))
    np.testing.assert_allclose(kf.x[1], x, atol=1e-9)
    np.testing.assert_allclose(kf.P[1], p, atol=1e-9)


def test_fast_shm_uses_a_measurement_of_half_the_probability_whatever_its_rounding():
    # Four objects, equal evidence for the 24 orderings, object 3 missed under the 12
    # that put object 0 in front of it: measured under half the probability, so used.
    # The sum of 12 probabilities of 1/24 is 0.49999999999999994: it was dropped.
    from trackers.models.layered import orderings

    boxes = np.array([[10.0, 10, 20, 20], [60.0, 10, 20, 20], [110.0, 10, 20, 20],
                      [30.0, 60, 20, 20]])  # fmt: skip
    c0 = boxes[:, :2] + boxes[:, 2:] / 2
    order = orderings(4)
    hidden = np.argsort(order, axis=1)[:, 0] < np.argsort(order, axis=1)[:, 3]
    assert hidden.sum() == 12
    centres = np.repeat((c0 + 6.0)[None], len(order), axis=0)
    mse = np.full((len(order), 4), 20.0)
    centres[hidden, 3], mse[hidden, 3] = np.nan, np.nan
    counts = np.where(np.isnan(mse), 0, 300).astype(np.int64)
    tracker = trackers.make("shm-fast")
    tracker.init(np.zeros((H, W, 3), np.uint8), boxes)
    tracker.matcher = Script([LayeredMeasurement(centres, mse, counts, 4)])
    est = tracker.step(np.zeros((H, W, 3), np.uint8))
    shift = est.boxes[:, :2] + boxes[:, 2:] / 2 - c0
    assert np.allclose(shift[3], shift[0]) and shift[0, 0] > 5  # object 3 moved as the others


def test_shm_collapses_each_ordering_s_predictions_by_moment_matching():
    # Frame 1: object 0 measured at +4 / -4 px under the two orderings, so the two
    # Gaussians part. Frame 2: nothing measured (both objects hidden under both
    # orderings): every pair (i, j) keeps prediction i, weighted P(i | j) ∝ Π_ij P(i), and
    # ordering j's Gaussian is their moment match, spread term included.
    shift = np.zeros((2, 2, 2))
    shift[0, 0, 0], shift[1, 0, 0] = 4.0, -4.0
    first = measurement(shift, np.array([[20.0, 20.0], [60.0, 20.0]]))
    nothing = measurement(np.zeros((2, 2, 2)), np.full((2, 2), np.nan))
    tracker, frame = started("shm", [first, nothing], use_mse=True, p_stay=0.8)
    tracker.step(frame)
    kf = tracker.kf
    prob = tracker.order_prob.copy()
    assert abs(prob[0] - prob[1]) > 0.05  # the first frame told the orderings apart
    x_pred = kf.x @ kf.F.T
    p_pred = kf.F @ kf.P @ kf.F.T + kf.Q
    assert np.abs(x_pred[0] - x_pred[1]).max() > 1.0
    tracker.params = dataclasses.replace(tracker.params, use_mse=False)
    tracker.step(frame)
    pi = np.array([[0.8, 0.2], [0.2, 0.8]])
    joint = pi * prob[:, None]  # [i, j]
    np.testing.assert_allclose(tracker.order_prob, joint.sum(axis=0), atol=1e-12)
    for j in range(2):
        w = joint[:, j] / joint[:, j].sum()
        mean = w @ x_pred
        cov = sum(w[i] * (p_pred[i] + np.outer(x_pred[i] - mean, x_pred[i] - mean))
                  for i in range(2))
        np.testing.assert_allclose(kf.x[j], mean, atol=1e-9)
        np.testing.assert_allclose(kf.P[j], cov, atol=1e-9)


def test_one_object_has_one_ordering_that_always_holds():
    np.testing.assert_array_equal(trackers.shm.transition_matrix(1, 0.9), [[1.0]])
    frame = np.zeros((H, W, 3), np.uint8)
    frame[30:48, 20:50] = (200, 40, 40)
    for name in ("shm", "shm-fast"):
        tracker = trackers.make(name)
        tracker.init(frame, BOXES[:1])
        for _ in range(3):
            est = tracker.step(frame)
            np.testing.assert_allclose(est.extras["order_prob"], [1.0])
            np.testing.assert_allclose(est.boxes, BOXES[:1], atol=0.5)


def test_an_ordering_that_measures_nothing_scores_one_scale():
    # Union evidence: E_j = Σ_m n e / Σ_m n over the pixels compared under ordering j.
    # Ordering 0 measures nothing (E undefined: it counts as the scale, ratio 1);
    # ordering 1 compares a single pixel of object 0 (E = its mse) and nothing of object
    # 1. On the first frame the scale is max(min_j E_j, mse_floor) = E_1, so both
    # orderings score -lam and stay equally probable.
    mse = np.array([[np.nan, np.nan], [40.0, np.nan]])
    step = measurement(np.zeros((2, 2, 2)), mse)
    step.counts[1, 0] = 1
    tracker, frame = started("shm-fast", [step], lam=2.0, mse_floor=25.0)
    est = tracker.step(frame)
    np.testing.assert_allclose(est.extras["order_prob"], [0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(tracker._evidence.scale, [0.9 * 40.0 + 0.1 * 40.0])
