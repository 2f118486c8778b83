"""Hand-worked cases for every metric in scenegen.evaluation.metrics."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from scenegen.evaluation import metrics as m

NAN4 = [np.nan] * 4


def test_iou_and_areas_hand_worked():
    a = np.array([0.0, 0.0, 10.0, 10.0])
    b = np.array([5.0, 0.0, 10.0, 10.0])
    assert m.intersection_area(a, b) == 50.0
    assert m.iou(a, b) == pytest.approx(50.0 / 150.0)
    assert m.iou(a, a) == 1.0
    assert m.iou(a, [20, 20, 5, 5]) == 0.0
    assert np.isnan(m.iou(a, NAN4))
    # broadcasting (2, 4) against (4,)
    out = m.iou(np.array([[0, 0, 10, 10], [0, 5, 10, 10.0]]), a)
    np.testing.assert_allclose(out, [1.0, 50.0 / 150.0])


def test_centre_error_hand_worked():
    assert m.centre_error([0, 0, 10, 10], [3, 4, 10, 10]) == pytest.approx(5.0)
    # different sizes: centres (5, 5) and (6, 5)
    assert m.centre_error([0, 0, 10, 10], [4, 3, 4, 4]) == pytest.approx(1.0)
    assert np.isnan(m.centre_error([0, 0, 1, 1], NAN4))


def test_track_state_precision_recall():
    gt = np.array([0.0, 0.0, 10.0, 10.0])
    est = np.array([[5.0, 5.0, 10.0, 20.0], [10.0, 0.0, 5.0, 5.0], NAN4])
    np.testing.assert_array_equal(m.track_state(est, gt), [True, False, False])
    p, r = m.precision_recall(est, gt)
    # intersection 5x5 = 25; |E| = 200, |G| = 100
    assert p[0] == pytest.approx(25 / 200)
    assert r[0] == pytest.approx(25 / 100)
    assert p[1] == 0.0 and r[1] == 0.0  # touching edge only
    assert np.isnan(p[2]) and np.isnan(r[2])


def test_success_and_recovery_rates():
    state = np.array(
        [
            [1, 1, 1, 1, 1, 1],  # tracked throughout
            [1, 0, 0, 1, 1, 1],  # lost, recovered for the last 3 frames
            [1, 0, 0, 0, 1, 1],  # recovered for the last 2 frames only
            [1, 1, 1, 1, 1, 0],  # lost at the end
        ],
        dtype=bool,
    )
    assert m.success_rate(state) == 25.0
    assert m.recovery_rate(state, last_k=3) == 50.0
    assert m.recovery_rate(state, last_k=2) == 75.0
    assert m.recovery_rate(state, last_k=1) == 75.0
    # last_k larger than T means "tracked throughout"
    assert m.recovery_rate(state, last_k=100) == 25.0
    with pytest.raises(ValueError, match="last_k"):
        m.recovery_rate(state, last_k=0)
    with pytest.raises(ValueError, match="shape"):
        m.success_rate(np.ones(3, dtype=bool))


def test_mean_over_tracked():
    p = np.array([[0.5, 0.0, 1.0], [np.nan, 0.25, 0.75]])
    t = np.array([[True, False, True], [True, True, False]])
    # tracked and finite: 0.5, 1.0, 0.25 -> mean 0.58333
    assert m.mean_over_tracked(p, t) == pytest.approx(100 * 1.75 / 3)
    assert m.mean_over_tracked(p) == pytest.approx(100 * 2.5 / 5)
    assert math.isnan(m.mean_over_tracked(p, np.zeros_like(t)))


def test_uniqueness_and_effective_dynamics_aggregation():
    # two runs, three frames (frame 0 NaN as trackers report it), two objects
    u = np.array(
        [
            [[np.nan, np.nan], [0.1, 0.5], [0.3, 0.5]],
            [[np.nan, np.nan], [0.2, 1.0], [0.2, 1.0]],
        ]
    )
    np.testing.assert_allclose(m.uniqueness_percent(u), [20.0, 75.0])
    e = np.stack([u, 2 * u], axis=-1)  # (R, T, K, C=2)
    np.testing.assert_allclose(
        m.effective_dynamics_percent(e, components=True), [[20.0, 40.0], [75.0, 150.0]]
    )
    np.testing.assert_allclose(m.effective_dynamics_percent(u), [20.0, 75.0])


def test_otb_curves_hand_worked():
    gt = np.array([[0, 0, 10, 10.0]] * 4)
    est = np.array(
        [
            [0, 0, 10, 10.0],  # IoU 1, error 0
            [5, 0, 10, 10.0],  # IoU 1/3, error 5
            [30, 0, 10, 10.0],  # IoU 0, error 30
            NAN4,  # missing: IoU 0, error inf
        ]
    )
    c = m.otb_curves(est, gt, n_overlap=5)
    np.testing.assert_allclose(c.overlap_thresholds, [0, 0.25, 0.5, 0.75, 1.0])
    # IoU > th: th=0 -> 2, 0.25 -> 2, 0.5 -> 1, 0.75 -> 1, 1.0 -> 0
    np.testing.assert_allclose(c.success, [0.5, 0.5, 0.25, 0.25, 0.0])
    assert c.auc == pytest.approx(0.3)
    assert c.precision_20 == 0.5
    assert c.precision[0] == 0.25 and c.precision[5] == 0.5 and c.precision[30] == 0.75
    # frames without ground truth are left out
    c2 = m.otb_curves(np.vstack([est, [[0, 0, 10, 10.0]]]), np.vstack([gt, [NAN4]]), n_overlap=5)
    assert c2.auc == pytest.approx(0.3)


def test_otb_curves_refuse_boxes_that_would_broadcast():
    """One estimated box is not scored against every frame, and too few frames are named
    (a numpy broadcast error before)."""
    gt = np.array([[0, 0, 10, 10.0], [50, 0, 10, 10.0], [100, 0, 10, 10.0]])
    for est in (gt[:1], gt[:2], gt[None]):
        with pytest.raises(ValueError, match=r"est has shape .* and gt \(3, 4\)"):
            m.otb_curves(est, gt)


def test_otb_precision_thresholds_stop_at_max_error():
    """The centre-error thresholds are whole pixels up to ``max_error``, never beyond it (a
    fractional ``max_error`` gave a threshold past it); a negative one is refused."""
    gt = np.array([[0, 0, 10, 10.0]])
    c = m.otb_curves(np.array([[30.5, 0, 10, 10.0]]), gt, max_error=30.5)
    np.testing.assert_array_equal(c.error_thresholds, np.arange(31.0))
    assert c.precision[-1] == 0.0  # error 30.5 > 30.5's largest threshold, 30
    assert m.otb_curves(gt, gt, max_error=0).error_thresholds.tolist() == [0.0]
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError, match="max_error"):
            m.otb_curves(gt, gt, max_error=bad)


@pytest.mark.parametrize(("name", "bad"), [
    ("max_error", float("inf")), ("max_error", 1e12), ("max_error", 16384.5),
    ("max_error", "50"), ("max_error", True), ("n_overlap", 10**9), ("n_overlap", 2.5),
    ("n_overlap", True), ("n_overlap", "3"), ("precision_at", float("nan")),
    ("precision_at", float("inf")), ("precision_at", -1.0), ("precision_at", "20"),
    ("precision_at", True),
])  # fmt: skip
def test_otb_thresholds_out_of_range_are_refused_naming_the_value(name, bad):
    """A huge or infinite ``max_error`` / ``n_overlap`` tried to allocate that many
    thresholds (numpy's MemoryError or "Maximum allowed size exceeded"); a NaN, infinite or
    negative ``precision_at`` gave a silent 0 or 1; strings and bools were numpy's errors
    or taken as numbers."""
    gt = np.array([[0, 0, 10, 10.0]])
    with pytest.raises(ValueError, match=rf"^{name} must be .*, got {re.escape(repr(bad))}$"):
        m.otb_curves(gt, gt, **{name: bad})
    c = m.otb_curves(gt, gt, max_error=16384, n_overlap=10001, precision_at=0)
    assert len(c.error_thresholds) == 16385 and c.precision_20 == 1.0


def test_failure_frame_and_tracked_fraction():
    err = np.array([1, 9, 12, 3, 11, 12, 13, 2, 1, 1.0])
    assert m.failure_frame(err, 10.0, persist=1) == 2
    assert m.failure_frame(err, 10.0, persist=3) == 4
    assert m.failure_frame(err, 10.0, persist=4) == -1
    assert m.failure_frame([1, 2, np.nan, np.nan], 10.0, persist=2) == 2
    assert m.tracked_fraction(err, 10.0, persist=3) == pytest.approx(0.4)
    assert m.tracked_fraction(err, 10.0, persist=4) == 1.0
    with pytest.raises(ValueError, match="persist"):
        m.failure_frame(err, 10.0, persist=0)
    # A fractional count never equalled the run length: the run never failed.
    for bad in (2.5, True, "3"):
        with pytest.raises(ValueError, match="^persist must be an integer >= 1, got "):
            m.failure_frame(err, 10.0, persist=bad)
        with pytest.raises(ValueError, match="^last_k must be an integer >= 1, got "):
            m.recovery_rate(np.ones((2, 4), bool), last_k=bad)
    assert m.failure_frame(err, 10.0, persist=np.int64(3)) == 4


def test_mcnemar_hand_worked():
    r = m.mcnemar(10, 2)
    assert r.chi2 == pytest.approx(49 / 12)
    assert r.z == pytest.approx(7 / math.sqrt(12))
    assert m.mcnemar(2, 10).z == pytest.approx(-7 / math.sqrt(12))
    assert m.mcnemar(3, 3) == m.McNemar(0.0, 0.0)
    assert m.mcnemar(0, 0) == m.McNemar(0.0, 0.0)
    assert m.mcnemar_counts([1.0, 0.5, 0.2, 0.7], [0.3, 0.5, 0.9, 0.1]) == (2, 1)


def test_clear_mot_perfect_and_hand_worked():
    gt = np.array(
        [
            [[0, 0, 10, 10], [50, 50, 10, 10]],
            [[1, 0, 10, 10], [50, 50, 10, 10]],
            [[2, 0, 10, 10], NAN4],
        ],
        dtype=float,
    )
    perfect = m.clear_mot(gt, gt)
    assert perfect.mota == 1.0 and perfect.motp == 1.0
    assert (perfect.n_gt, perfect.matches, perfect.fn, perfect.fp, perfect.idsw) == (5, 5, 0, 0, 0)
    # swap the hypotheses in frame 1 (2 switches) and put a false positive in frame 2
    est = gt.copy()
    est[1] = gt[1, ::-1]
    est[2, 1] = [100, 100, 10, 10]
    r = m.clear_mot(gt, est)
    # frame 1: both objects switch identity (2 IDSW); frame 2: object 0 switches back
    # (1 IDSW), hypothesis 1 is a false positive.
    assert (r.n_gt, r.matches, r.fn, r.fp, r.idsw) == (5, 5, 0, 1, 3)
    assert r.mota == pytest.approx(1 - 4 / 5)
    # a miss: hypothesis far away
    est2 = gt.copy()
    est2[0, 0] = [200, 200, 10, 10]
    r2 = m.clear_mot(gt, est2)
    assert (r2.fn, r2.fp, r2.idsw) == (1, 1, 0)
    assert r2.mota == pytest.approx(1 - 2 / 5)
    # MOTP is the mean IoU of matches
    est3 = gt.copy()
    est3[0, 0] = [5, 0, 10, 10]
    r3 = m.clear_mot(gt, est3, iou_threshold=0.3)
    assert r3.motp == pytest.approx((1 / 3 + 4) / 5)


def test_clear_mot_keeps_previous_match():
    # frame 1: hypothesis 1 overlaps object 0 slightly better than hypothesis 0 does, but
    # the earlier correspondence 0-0 is still valid, so it is kept (no switch).
    gt = np.array([[[0, 0, 10, 10]], [[0, 0, 10, 10]]], dtype=float)
    est = np.array(
        [[[0, 0, 10, 10], [40, 40, 10, 10]], [[2, 0, 10, 10], [1, 0, 10, 10]]], dtype=float
    )
    r = m.clear_mot(gt, est)
    assert (r.idsw, r.fp, r.matches) == (0, 2, 2)
    assert r.motp == pytest.approx((1 + 80 / 120) / 2)


def test_idf1_hand_worked():
    gt = np.array([[[0, 0, 10, 10]], [[0, 0, 10, 10]], [[0, 0, 10, 10]], [[0, 0, 10, 10]]], float)
    # hypothesis 0 covers frames 0-2, hypothesis 1 covers frame 3
    est = np.full((4, 2, 4), np.nan)
    est[:3, 0] = [0, 0, 10, 10]
    est[3, 1] = [0, 0, 10, 10]
    # best matching: gt-hyp0 with IDTP 3; IDF1 = 2*3 / (4 + 4)
    assert m.idf1(gt, est) == pytest.approx(0.75)
    assert m.idf1(gt, gt) == 1.0
    assert m.idf1(gt, np.full((4, 1, 4), np.nan)) == 0.0
    with pytest.raises(ValueError, match="shapes"):
        m.idf1(gt, est[:2])


def test_ordering_index_and_depth_order_accuracy():
    orderings = np.array([[0, 1], [1, 0]])
    depth = np.array([[0, 1], [1, 0], [0, 1]])
    np.testing.assert_array_equal(m.ordering_index(depth, orderings), [0, 1, 0])
    np.testing.assert_array_equal(m.ordering_index(depth, orderings[:1]), [0, -1, 0])
    boxes = np.array(
        [
            [[0, 0, 10, 10], [5, 0, 10, 10]],  # overlap half of the smaller box
            [[0, 0, 10, 10], [5, 0, 10, 10]],
            [[0, 0, 10, 10], [9.5, 0, 10, 10]],  # 5% overlap: below min_overlap
        ],
        dtype=float,
    )
    assert m.overlap_fraction(boxes[0, 0], boxes[0, 1]) == pytest.approx(0.5)
    prob = np.array([[0.9, 0.1], [0.3, 0.7], [0.0, 1.0]])
    # frames 0 and 1 right, frame 2 does not count
    assert m.depth_order_accuracy(prob, orderings, depth, boxes) == 100.0
    wrong = prob[:, ::-1]
    assert m.depth_order_accuracy(wrong, orderings, depth, boxes) == 0.0
    # with a lower bar, frame 2 counts too and is wrong: 2 right out of 3
    assert m.depth_order_accuracy(prob, orderings, depth, boxes, min_overlap=0.01) == (
        pytest.approx(200 / 3)
    )
    # NaN probabilities (frame 0 of a tracker) are skipped
    prob_nan = prob.copy()
    prob_nan[0] = np.nan
    assert m.depth_order_accuracy(prob_nan, orderings, depth, boxes) == 100.0
    far = boxes.copy()
    far[:, 1, 0] = 50
    assert math.isnan(m.depth_order_accuracy(prob, orderings, depth, far))


@pytest.mark.parametrize("bad", [0.0, -0.1, 1.01])
def test_iou_threshold_outside_0_1_is_refused_by_every_metric(bad: float) -> None:
    # IoU is never negative, so a threshold of 0 would match disjoint boxes (IDF1 > 1).
    gt = np.array([[[0.0, 0.0, 10.0, 10.0]], [[0.0, 0.0, 10.0, 10.0]]])
    est = np.array([[[50.0, 50.0, 10.0, 10.0]], [[50.0, 50.0, 10.0, 10.0]]])
    with pytest.raises(ValueError, match="iou_threshold must be in"):
        m.idf1(gt, est, iou_threshold=bad)
    with pytest.raises(ValueError, match="iou_threshold must be in"):
        m.clear_mot(gt, est, iou_threshold=bad)


def test_iou_threshold_of_one_is_allowed_and_disjoint_boxes_never_match() -> None:
    gt = np.array([[[0.0, 0.0, 10.0, 10.0]]])
    assert m.idf1(gt, gt.copy(), iou_threshold=1.0) == pytest.approx(1.0)
    far = np.array([[[50.0, 50.0, 10.0, 10.0]]])
    assert m.idf1(gt, far, iou_threshold=0.01) == 0.0
