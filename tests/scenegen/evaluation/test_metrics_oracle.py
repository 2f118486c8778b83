"""Edge cases of the metric formulas that the mutation run found unguarded."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from scenegen.evaluation.metrics import (
    depth_order_accuracy,
    idf1,
    intersection_area,
    mcnemar,
    ordering_index,
    overlap_fraction,
    recovery_rate,
    success_rate,
)


def test_intersection_of_boxes_apart_in_one_direction_is_zero():
    a = np.array([0.0, 0.0, 10.0, 10.0])
    # Overlapping rows, columns 0.5 px or 5 px apart; and the mirrored cases.
    for b in ([10.5, 2.0, 10.0, 10.0], [15.0, 2.0, 10.0, 10.0], [2.0, 10.5, 10.0, 10.0],
              [2.0, 15.0, 10.0, 10.0]):
        assert intersection_area(a, np.array(b)) == 0.0
        assert intersection_area(np.array(b), a) == 0.0
    assert intersection_area(a, np.array([5.0, 2.0, 10.0, 10.0])) == 5.0 * 8.0


def test_overlap_fraction_of_an_empty_box_is_zero():
    a = np.array([0.0, 0.0, 10.0, 10.0])
    assert overlap_fraction(a, np.array([2.0, 2.0, 0.0, 5.0])) == 0.0
    assert overlap_fraction(a, np.array([5.0, 5.0, 10.0, 10.0])) == 0.25


def test_idf1_with_a_single_detection_is_zero_and_with_none_nan():
    gt = np.full((3, 1, 4), np.nan)
    est = np.full((3, 1, 4), np.nan)
    assert np.isnan(idf1(gt, est))
    gt[1, 0] = (0.0, 0.0, 10.0, 10.0)   # one ground-truth detection, no hypothesis
    assert idf1(gt, est) == 0.0


def test_success_and_recovery_rates_of_no_runs_are_nan_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(success_rate(np.zeros((0, 5), dtype=bool)))
        assert np.isnan(recovery_rate(np.zeros((0, 5), dtype=bool)))


def test_mcnemar_rejects_each_negative_count():
    for counts in ((-1, 3), (3, -1)):
        with pytest.raises(ValueError, match="counts must be >= 0"):
            mcnemar(*counts)


def test_ordering_index_rejects_a_one_dimensional_depth():
    with pytest.raises(ValueError, match="disagree"):
        ordering_index(np.array([0, 1]), np.array([[0, 1], [1, 0]]))
    with pytest.raises(ValueError, match="disagree"):
        ordering_index(np.array([[0, 1]]), np.array([0, 1]))


def test_depth_order_counts_a_pair_overlapping_exactly_min_overlap():
    # Two 10x10 boxes overlapping by half of each: overlap fraction exactly 0.5.
    boxes = np.array([[[0.0, 0.0, 10.0, 10.0], [5.0, 0.0, 10.0, 10.0]]])
    orderings = np.array([[0, 1], [1, 0]])
    depth = np.array([[0, 1]])
    prob = np.array([[0.9, 0.1]])
    assert depth_order_accuracy(prob, orderings, depth, boxes, min_overlap=0.5) == 100.0
    assert np.isnan(depth_order_accuracy(prob, orderings, depth, boxes, min_overlap=0.6))


def test_overlapping_pairs_counts_exactly_min_overlap_and_no_absent_box():
    from scenegen.evaluation.metrics import overlapping_pairs

    # Frame 0: a 10x10 box and a 20x20 box covering 5x10 of it (half the smaller box);
    # frame 1: the second box absent.
    boxes = np.array([[[0.0, 0.0, 10.0, 10.0], [5.0, 0.0, 20.0, 20.0], [50.0, 50, 5, 5]],
                      [[0.0, 0.0, 10.0, 10.0], [np.nan] * 4, [50.0, 50, 5, 5]]])
    pairs = overlapping_pairs(boxes, min_overlap=0.5)
    want = np.zeros((2, 3, 3), dtype=bool)
    want[0, 0, 1] = want[0, 1, 0] = True
    np.testing.assert_array_equal(pairs, want)
    assert not overlapping_pairs(boxes, min_overlap=0.51).any()
    # A box overlaps itself fully, yet is not a pair.
    assert not overlapping_pairs(boxes[:, :1], min_overlap=1.0).any()
    with pytest.raises(ValueError, match="min_overlap"):
        overlapping_pairs(boxes, min_overlap=0.0)


# Round 16: every mutant of the module (not a sample); the cases below are the ones the
# full run found unguarded.


def test_areas_below_one_pixel_keep_their_iou_and_recall():
    from scenegen.evaluation.metrics import iou, precision_recall

    # Boxes of 0.5 x 0.5 px (area 0.25) overlapping by half: the ratios are defined.
    a = np.array([0.0, 0.0, 0.5, 0.5])
    b = np.array([0.25, 0.0, 0.5, 0.5])
    assert iou(a, b) == pytest.approx(0.125 / 0.375)
    p, r = precision_recall(a, b)
    assert p == pytest.approx(0.5) and r == pytest.approx(0.5)
    # Two boxes of zero area: IoU 0, not a negative or NaN placeholder.
    flat = np.array([3.0, 3.0, 0.0, 4.0])
    assert iou(flat, flat) == 0.0


def test_otb_curves_of_one_frame_and_of_no_frame():
    from scenegen.evaluation.metrics import otb_curves

    gt = np.array([[0.0, 0.0, 10.0, 10.0]])
    est = np.array([[0.0, 0.0, 10.0, 20.0]])  # IoU 0.5; centre error exactly 5 px
    c = otb_curves(est, gt, n_overlap=3)
    np.testing.assert_array_equal(c.success, [1.0, 0.0, 0.0])  # IoU > 0, > 0.5, > 1
    assert c.precision_20 == 1.0
    # The default thresholds: 0, 1, ..., 50 px; 21 overlap thresholds.
    d = otb_curves(est, gt)
    np.testing.assert_array_equal(d.error_thresholds, np.arange(51.0))
    assert d.overlap_thresholds.size == 21
    np.testing.assert_array_equal(d.precision, np.arange(51.0) >= 5.0)
    # A centre error of exactly the headline threshold counts as precise.
    at = otb_curves(np.array([[20.0, 0.0, 10.0, 10.0]]), gt, precision_at=20.0)
    assert at.precision_20 == 1.0
    # The headline threshold is 20 px: an error of 20.5 px is not precise.
    assert otb_curves(np.array([[20.5, 0.0, 10.0, 10.0]]), gt).precision_20 == 0.0
    assert otb_curves(np.array([[20.0, 0.0, 10.0, 10.0]]), gt, max_error=3.0
                      ).error_thresholds.tolist() == [0.0, 1.0, 2.0, 3.0]
    # Two overlap thresholds (0 and 1) are allowed, one is not.
    assert otb_curves(est, gt, n_overlap=2).success.tolist() == [1.0, 0.0]
    with pytest.raises(ValueError, match=r"n_overlap must be an integer in \[2, 10001\], got 1"):
        otb_curves(est, gt, n_overlap=1)
    assert otb_curves(np.array([[19.5, 0.0, 10.0, 10.0]]), gt).precision_20 == 1.0
    # No frame with ground truth: NaN curves, without a warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        empty = otb_curves(est, np.full((1, 4), np.nan))
    assert np.isnan(empty.success).all() and np.isnan(empty.precision).all()
    assert np.isnan(empty.precision_20) and np.isnan(empty.auc)


def test_failure_frame_default_persistence_and_a_run_from_the_first_frame():
    from scenegen.evaluation.metrics import failure_frame, tracked_fraction

    # Above the threshold from frame 0: the run fails at frame 0.
    assert failure_frame([50.0, 50.0, 1.0], 10.0, persist=2) == 0
    assert failure_frame([50.0] * 5, 10.0, persist=1) == 0
    # An error equal to the threshold is not above it.
    assert failure_frame([10.0] * 5, 10.0, persist=1) == -1
    assert tracked_fraction([50.0] * 5, 10.0, persist=1) == 0.0
    # The default persistence is 10 frames: 9 frames above are a transient.
    nine = [1.0] * 3 + [50.0] * 9 + [1.0] * 3
    ten = [1.0] * 3 + [50.0] * 10 + [1.0] * 2
    assert failure_frame(nine, 10.0) == -1 and tracked_fraction(nine, 10.0) == 1.0
    assert failure_frame(ten, 10.0) == 3 and tracked_fraction(ten, 10.0) == 3 / 15


def test_depth_order_accuracy_counts_each_pair_once_and_checks_every_shape():
    # Four targets all overlapping; the MAP ordering (0, 1, 2, 3) against true depths that
    # put 1 in front of 0: of the six pairs, (0, 1) is wrong -> 5 of 6.
    boxes = np.array([[[0.0, 0.0, 10.0, 10.0], [2.0, 0.0, 10.0, 10.0],
                       [4.0, 0.0, 10.0, 10.0], [6.0, 0.0, 10.0, 10.0]]])
    orderings = np.array([[0, 1, 2, 3], [3, 2, 1, 0]])
    depth = np.array([[1, 0, 2, 3]])
    prob = np.array([[0.8, 0.2]])
    assert depth_order_accuracy(prob, orderings, depth, boxes) == pytest.approx(500.0 / 6)
    bad = {
        "order_prob": (np.array([[0.8, 0.2], [0.5, 0.5]]), orderings, depth, boxes),
        "boxes": (prob, orderings, depth, boxes[:, :2]),
        "orderings": (prob, orderings[:, :3], depth, boxes),
    }
    for args in bad.values():
        with pytest.raises(ValueError, match="shapes disagree"):
            depth_order_accuracy(*args)


def test_overlapping_pairs_rejects_min_overlap_above_one():
    from scenegen.evaluation.metrics import overlapping_pairs

    boxes = np.zeros((1, 2, 4))
    for bad in (1.5, 2.0):
        with pytest.raises(ValueError, match="min_overlap must be in"):
            overlapping_pairs(boxes, min_overlap=bad)


def test_mcnemar_of_equal_counts_has_a_positive_zero_z():
    # Printed as "0.00", not "-0.00".
    assert np.copysign(1.0, mcnemar(3, 3).z) == 1.0
    assert mcnemar(3, 3).chi2 == 0.0


def test_effective_dynamics_needs_time_and_object_axes():
    from scenegen.evaluation.metrics import effective_dynamics_percent

    # (T, K) is enough without components; (T, K, C) with them.
    np.testing.assert_allclose(effective_dynamics_percent(np.full((3, 2), 0.5)), [50, 50])
    np.testing.assert_allclose(
        effective_dynamics_percent(np.full((3, 2, 2), 0.5), components=True), [[50, 50]] * 2)
    with pytest.raises(ValueError, match=r"at least 2 axes, got shape \(3,\)"):
        effective_dynamics_percent(np.ones(3))
    with pytest.raises(ValueError, match=r"at least 3 axes, got shape \(3, 2\)"):
        effective_dynamics_percent(np.ones((3, 2)), components=True)


def test_centres_and_intersections_of_boxes_that_are_not_square():
    from scenegen.evaluation.metrics import centre_error, centres

    # Width and height differ, so a formula that reads one for the other is wrong.
    np.testing.assert_array_equal(centres([2.0, 4.0, 10.0, 30.0]), [7.0, 19.0])
    assert centre_error([0.0, 0.0, 10.0, 30.0], [0.0, 0.0, 30.0, 10.0]) == pytest.approx(
        np.hypot(10.0, 10.0))
    tall = np.array([0.0, 0.0, 10.0, 30.0])   # right edge 10, bottom 30
    wide = np.array([0.0, 0.0, 30.0, 10.0])   # right edge 30, bottom 10
    # Each order: the right edge comes from the tall box, the bottom from the wide one.
    assert intersection_area(tall, wide) == 100.0
    assert intersection_area(wide, tall) == 100.0
    assert intersection_area(tall, np.array([5.0, 25.0, 40.0, 40.0])) == 5.0 * 5.0
    assert intersection_area(np.array([5.0, 25.0, 40.0, 40.0]), tall) == 5.0 * 5.0


def test_precision_and_recall_of_a_box_without_area_are_nan():
    from scenegen.evaluation.metrics import precision_recall

    box = np.array([0.0, 0.0, 10.0, 10.0])
    line = np.array([2.0, 2.0, 0.0, 5.0])
    p, r = precision_recall(box, line)     # ground truth of zero area: recall undefined
    assert p == 0.0 and np.isnan(r)
    p, r = precision_recall(line, box)     # estimate of zero area: precision undefined
    assert np.isnan(p) and r == 0.0


def test_per_object_means_over_frames_with_one_finite_value_or_none():
    from scenegen.evaluation.metrics import effective_dynamics_percent, uniqueness_percent

    u = np.array([[np.nan, np.nan, np.nan], [0.5, np.nan, np.nan], [np.nan, 0.25, np.nan],
                  [np.nan, np.nan, np.nan]])   # (T, K) = (4, 3)
    np.testing.assert_array_equal(uniqueness_percent(u), [50.0, 25.0, np.nan])
    np.testing.assert_array_equal(effective_dynamics_percent(u), [50.0, 25.0, np.nan])
    with pytest.raises(ValueError, match="uniqueness must have shape"):
        uniqueness_percent(np.ones(3))


def test_recovery_needs_the_last_five_frames_whatever_the_number_of_runs():
    from scenegen.evaluation.metrics import recovery_rate

    # Two runs of ten frames, lost at frame 6 and tracked again for the last 3 frames:
    # not recovered with the default of 5 frames (fewer runs than frames must not matter).
    s = np.ones((2, 10), dtype=bool)
    s[:, 6] = False
    assert recovery_rate(s) == 0.0
    assert recovery_rate(s, last_k=3) == 100.0
    s[:, 6] = True
    s[:, 5] = False                          # the last 4 frames tracked, not the last 5
    assert recovery_rate(s) == 0.0
    assert recovery_rate(s, last_k=4) == 100.0
    s[:, 5] = True
    s[:, 4] = False                          # the last 5 frames tracked
    assert recovery_rate(s) == 100.0
    assert recovery_rate(s, last_k=6) == 0.0


def test_overlapping_pairs_default_is_a_tenth_of_the_smaller_box():
    from scenegen.evaluation.metrics import overlapping_pairs

    # A 10x10 box covered over 10 % and over 9 % by a larger one.
    boxes = np.array([[[0.0, 0.0, 10.0, 10.0], [9.0, 0.0, 20.0, 20.0]],
                      [[0.0, 0.0, 10.0, 10.0], [9.1, 0.0, 20.0, 20.0]]])
    pairs = overlapping_pairs(boxes)
    assert pairs[0, 0, 1] and pairs[0, 1, 0]
    assert not pairs[1].any()


def test_areas_below_one_pixel_keep_their_overlap_and_track_state():
    from scenegen.evaluation.metrics import track_state

    # A 0.5 x 0.5 box half inside a large one: overlap 0.5 of the smaller box; and an
    # intersection of 0.25 px^2 is still a non-empty one.
    small = np.array([9.75, 0.0, 0.5, 0.5])
    big = np.array([0.0, 0.0, 10.0, 10.0])
    assert overlap_fraction(small, big) == 0.5
    assert overlap_fraction(big, small) == 0.5
    assert bool(track_state(np.array([9.5, 0.0, 0.5, 0.5]), big))


def test_mcnemar_counts_rejects_scores_of_different_lengths():
    from scenegen.evaluation.metrics import mcnemar_counts

    with pytest.raises(ValueError, match="scores must be two"):
        mcnemar_counts([0.5, 1.0, 0.2], [0.5, 1.0])
    with pytest.raises(ValueError, match="scores must be two"):
        mcnemar_counts([[0.5, 1.0]], [[0.5, 1.0]])
    assert mcnemar_counts([0.5, 1.0, 0.2], [0.4, 1.0, 0.3]) == (1, 1)


def test_depth_order_accuracy_reads_every_ordering_of_three_targets():
    import itertools

    # The six orderings of three overlapping targets: whichever is the MAP ordering, the
    # depths it implies are all right and the reversed depths all wrong.
    orderings = np.array(list(itertools.permutations(range(3))))
    boxes = np.array([[[0.0, 0.0, 10.0, 10.0], [2.0, 0.0, 10.0, 10.0],
                       [4.0, 0.0, 10.0, 10.0]]])
    for best, order in enumerate(orderings):
        prob = np.full((1, 6), 0.1)
        prob[0, best] = 0.5
        depth = np.argsort(order)[None]          # depth rank of each target, 0 = nearest
        assert depth_order_accuracy(prob, orderings, depth, boxes) == 100.0
        assert depth_order_accuracy(prob, orderings, 2 - depth, boxes) == 0.0
