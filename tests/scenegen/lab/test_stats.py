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


def test_newcombe_paired_interval():
    # Fagerland, Lydersen & Laake (2017), ch. 8, Cavo et al. 2012 (paired 2 x 2 [[59, 6],
    # [16, 80]]): estimate -0.0621, 95 % CI -0.1186 to -0.0046.
    lo, hi = stats.newcombe_paired_diff(59, 6, 16, 80)
    assert lo == pytest.approx(-0.1186, abs=5e-5) and hi == pytest.approx(-0.0046, abs=5e-5)
    # The same margins as independent samples give a wider interval that covers 0.
    ulo, uhi = stats.newcombe_diff(65, 161, 75, 161)
    assert ulo < lo and uhi > 0 > hi
    # No association beyond chance (cross-product within [0, n/2]), or an empty margin:
    # the independent-sample interval.
    assert stats.newcombe_paired_diff(5, 5, 5, 5) == \
        pytest.approx(stats.newcombe_diff(10, 20, 10, 20))
    assert stats.newcombe_paired_diff(38, 2, 0, 0) == \
        pytest.approx(stats.newcombe_diff(40, 40, 38, 40))
    # Negatively associated outcomes widen it.
    nlo, nhi = stats.newcombe_paired_diff(1, 9, 9, 1)
    wlo, whi = stats.newcombe_diff(10, 20, 10, 20)
    assert nlo < wlo and nhi > whi
    assert all(math.isnan(x) for x in stats.newcombe_paired_diff(0, 0, 0, 0))


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


def test_cochran_q_by_hand():
    # C = (5, 3, 1), T = 9, Σ R² = 19: Q = 2 (3·35 − 81) / (27 − 19) = 6, p = e^−3.
    rows = [[1, 1, 0], [1, 0, 0], [1, 1, 1], [0, 0, 0], [1, 0, 0], [1, 1, 0]]
    t = stats.cochran_q(rows)
    assert t.statistic == pytest.approx(6.0)
    assert t.p_value == pytest.approx(math.exp(-3.0))
    assert "df 2" in t.name


@pytest.mark.parametrize(("b", "c", "same"), [(9, 3, 20), (4, 4, 0), (0, 7, 5)])
def test_cochran_q_of_two_methods_is_mcnemars_chi2(b, c, same):
    rows = [[1, 0]] * b + [[0, 1]] * c + [[1, 1]] * same + [[0, 0]] * same
    assert stats.cochran_q(rows).statistic == pytest.approx((b - c) ** 2 / (b + c))


def test_cochran_q_ignores_cases_every_method_agrees_on():
    rows = [[1, 0, 0], [0, 1, 1], [1, 1, 0]]
    more = rows + [[1, 1, 1]] * 30 + [[0, 0, 0]] * 30
    assert stats.cochran_q(more).statistic == pytest.approx(stats.cochran_q(rows).statistic)
    assert stats.cochran_q([[1, 1], [0, 0]]).p_value == 1.0
    with pytest.raises(ValueError, match="k >= 2"):
        stats.cochran_q([[1], [0]])


def test_clustered_bootstrap_does_not_count_repeated_runs_as_evidence():
    rng = np.random.default_rng(4)
    a = {s: [float(v)] for s, v in enumerate(rng.random(12) < 0.7)}
    b = {s: [float(v)] for s, v in enumerate(rng.random(12) < 0.4)}
    one = stats.bootstrap_clustered_diff(a, b, 11)
    five = stats.bootstrap_clustered_diff({s: v * 5 for s, v in a.items()},
                                          {s: v * 5 for s, v in b.items()}, 11)
    assert one == five  # five identical runs per scene: no more evidence than one
    mean, ci, t = one
    d = [a[s][0] - b[s][0] for s in range(12)]
    ref = stats.bootstrap_paired_diff(d, [0.0] * 12, 11)
    assert (mean, ci, t.p_value) == (ref[0], ref[1], ref[2].p_value)
    assert t.name == "paired bootstrap over scenes (one-sided)"
    # Unpaired scenes are dropped; per-scene means are compared, not pooled runs.
    m, _, _ = stats.bootstrap_clustered_diff({0: [1, 1, 1, 0], 1: [0, 0], 2: [1]},
                                             {0: [0, 0], 1: [1, 0]}, 0)
    assert m == pytest.approx(((0.75 - 0.0) + (0.0 - 0.5)) / 2)


def test_a_resampling_test_needs_enough_cases_to_reproduce():
    assert stats.verdict(0.001, (5.0, 20.0), 10.0, 9) == "reproduced"        # exact tests
    assert stats.verdict(0.001, (5.0, 20.0), 10.0, 9, min_n=10) == "inconclusive"
    assert stats.verdict(0.001, (5.0, 20.0), 10.0, 10, min_n=10) == "reproduced"
    _, _, t = stats.bootstrap_paired_diff([1.0, 2.0], [0.0, 0.0], 0)
    assert t.min_n == stats.MIN_RUNS and stats.mcnemar_exact(5, 0).min_n == 0
