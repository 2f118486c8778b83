"""Resampling corner cases the formulas must get right (found by the mutation run).

- residual resampling draws the remainder from the residual weights n w - floor(n w),
  also when exactly one draw is left;
- a group whose residuals are all zero (n_c w exact integers) next to a group that still
  has draws to make is resampled deterministically, and does not stop the other group;
- g must be finite and non-negative, checked as such.
"""

from __future__ import annotations

import numpy as np
import pytest

from trackers.filters.resampling import resample, resample_groups, weighted_resample


def test_residual_draws_the_last_particle_by_the_residual_weights():
    # n w = (1.65, 1.05, 0.3): copies (1, 1, 0), one draw left, by residuals
    # (0.65, 0.05, 0.3) (which sum to 1.0 exactly in floating point).
    w = np.array([0.55, 0.35, 0.1])
    rng = np.random.default_rng(5)
    reps = 4000
    counts = np.zeros(3)
    for _ in range(reps):
        counts += np.bincount(resample(w, method="residual", rng=rng), minlength=3)
    extra = counts / reps - np.array([1.0, 1.0, 0.0])
    # Standard error of each frequency <= 0.5 / sqrt(4000) = 0.008; uniform residuals
    # would give 1/3 each.
    np.testing.assert_allclose(extra, [0.65, 0.05, 0.3], atol=0.035)


def test_residual_group_with_nothing_left_to_draw_beside_one_with_draws():
    # Group 0: uniform, 4 x (1/4) -> one copy each, all residuals 0. Group 1 has draws left.
    w = np.array([0.25, 0.25, 0.25, 0.25, 0.7, 0.2, 0.1])
    sizes = np.array([4, 3])
    rng = np.random.default_rng(0)
    for _ in range(50):
        idx = resample_groups(w, sizes, method="residual", rng=rng)
        np.testing.assert_array_equal(idx[:4], [0, 1, 2, 3])
        assert np.all((idx[4:] >= 4) & (idx[4:] < 7))
        assert 4 in idx[4:]  # floor(3 * 0.7) = 2 copies of particle 4 at least
        assert np.count_nonzero(idx[4:] == 4) >= 2


@pytest.mark.parametrize("bad", [np.array([1.0, -0.5, 1.0]), np.array([1.0, np.nan, 1.0]),
                                 np.array([1.0, np.inf, 1.0])])
def test_g_must_be_finite_and_non_negative(bad):
    with pytest.raises(ValueError, match="g must be finite and non-negative"):
        weighted_resample(np.ones(3), bad, rng=np.random.default_rng(0))
