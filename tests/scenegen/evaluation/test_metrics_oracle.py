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
