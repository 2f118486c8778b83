"""The experiments' statistics against reference values computed by hand or printed in
standard tables (Wilson 1927; Newcombe 1998; χ² critical values)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from scenegen.lab.experiments import stats


def test_normal_tail_and_quantile():
    assert stats.norm_sf(1.959963984540054) == pytest.approx(0.025, abs=1e-12)
    assert stats.norm_ppf(0.975) == pytest.approx(1.959963984540054, abs=1e-9)
    assert stats.norm_ppf(0.995) == pytest.approx(2.5758293035489, abs=1e-9)


@pytest.mark.parametrize(
    ("k", "n", "lo", "hi"),
    [
        (5, 10, 0.236593, 0.763407),
        (0, 10, 0.0, 0.277533),
        (10, 10, 0.722467, 1.0),
        (81, 263, 0.255289, 0.366210),  # Newcombe 1998, Table I: 0.2553-0.3662
    ],
)
def test_wilson_interval(k, n, lo, hi):
    a, b = stats.wilson(k, n)
    assert a == pytest.approx(lo, abs=1e-5) and b == pytest.approx(hi, abs=1e-5)


def test_wilson_empty_and_bad_counts():
    assert all(math.isnan(x) for x in stats.wilson(0, 0))
    with pytest.raises(ValueError, match="0 <= k <= n"):
        stats.wilson(4, 3)


def test_newcombe_difference_interval():
    # Newcombe 1998, example (h): 56/70 vs 48/80 -> [0.0524, 0.3339].
    lo, hi = stats.newcombe_diff(56, 70, 48, 80)
    assert lo == pytest.approx(0.0524, abs=5e-4) and hi == pytest.approx(0.3339, abs=5e-4)


def test_two_proportion_z_by_hand():
    t = stats.two_proportion_z(30, 50, 20, 50)  # pooled p 0.5, se 0.1, z 2
    assert t.statistic == pytest.approx(2.0)
    assert t.p_value == pytest.approx(0.0227501, abs=1e-6)
    assert stats.two_proportion_z(5, 5, 5, 5).p_value == 0.5


def test_exact_mcnemar_and_binomial():
    assert stats.mcnemar_exact(8, 2).p_value == pytest.approx(56 / 1024)
    assert stats.mcnemar_exact(0, 0).p_value == 1.0
    assert stats.mcnemar_exact(5, 0).p_value == pytest.approx(1 / 32)
    assert stats.binomial_greater(9, 10, 0.5).p_value == pytest.approx(11 / 1024)


@pytest.mark.parametrize(
    ("x", "df"), [(3.841459, 1), (5.991465, 2), (7.814728, 3), (11.070498, 5), (12.591587, 6)]
)
def test_chi2_tail_at_the_5_percent_critical_values(x, df):
    assert stats.chi2_sf(x, df) == pytest.approx(0.05, abs=1e-6)


def test_chi2_homogeneity_by_hand():
    # 10/20 vs 20/20: expected 15 and 5 per row, chi2 = 2 * (25/15 + 25/5) = 13.333...
    t = stats.chi2_homogeneity([10, 20], [20, 20])
    assert t.statistic == pytest.approx(40 / 3)
    assert t.p_value == pytest.approx(stats.chi2_sf(40 / 3, 1))
    assert stats.chi2_homogeneity([0, 0, 0], [5, 5, 5]).p_value == 1.0


def test_bootstrap_is_seeded_and_sensible():
    v = np.arange(20.0)
    a = stats.bootstrap_mean(v, 3)
    assert a == stats.bootstrap_mean(v, 3)
    assert a[0] < v.mean() < a[1] and a[1] - a[0] < 6
    assert stats.bootstrap_mean([4.0, 4.0, np.nan], 0) == (4.0, 4.0)
    m, (lo, hi), t = stats.bootstrap_paired_diff(v + 5, v, 0)
    assert m == 5.0 and lo == hi == 5.0 and t.p_value == 1 / stats.N_BOOT
    m, (lo, hi), t = stats.bootstrap_paired_diff(v, v + 1, 0)
    assert m == -1.0 and t.p_value == 1.0


def test_verdicts():
    assert stats.verdict(0.01, (0.1, 0.5), 0.3, 3) == "reproduced"
    assert stats.verdict(0.4, (-0.1, 0.1), 0.3, 20) == "not reproduced"  # 0.3 ruled out
    assert stats.verdict(0.4, (-0.1, 0.1), 0.3, 9) == "inconclusive"  # too few runs
    assert stats.verdict(0.4, (-0.5, -0.2), 0.1, 20) == "not reproduced"  # the other way
    assert stats.verdict(0.2, (-0.1, 0.6), 0.3, 50) == "inconclusive"
