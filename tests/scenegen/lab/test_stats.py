"""The experiments' statistics against reference values computed by hand or printed in
standard tables (Wilson 1927; Newcombe 1998; χ² critical values), and against
``scipy.stats`` over drawn counts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import stats as sps

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


@pytest.mark.parametrize(("n1", "n2"), [(0, 10), (10, 0), (0, 0)])
def test_an_empty_sample_gives_no_evidence_like_the_other_functions(n1, n2):
    # Both divided by zero (ZeroDivisionError) where wilson and newcombe_paired_diff give
    # (nan, nan) and bootstrap_paired_diff p = 1 for no cases.
    assert all(math.isnan(x) for x in stats.newcombe_diff(0, n1, 0, n2))
    t = stats.two_proportion_z(0, n1, 0, n2)
    assert math.isnan(t.statistic) and t.p_value == 1.0
    assert stats.verdict(t.p_value, stats.newcombe_diff(0, n1, 0, n2), 0.1, 0) == \
        "inconclusive"


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


# ---------------------------------------------------------------------------------------
# Against scipy.stats, over drawn counts (scipy is the oracle; the module does not use it)

counts = st.integers(1, 400).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n)))


@given(counts)
def test_wilson_is_scipys_wilson_interval(kn):
    k, n = kn
    ci = sps.binomtest(k, n).proportion_ci(0.95, method="wilson")
    assert stats.wilson(k, n) == pytest.approx((ci.low, ci.high), abs=1e-9)
    ci = sps.binomtest(k, n).proportion_ci(0.8, method="wilson")
    assert stats.wilson(k, n, 0.8) == pytest.approx((ci.low, ci.high), abs=1e-9)


@given(st.integers(0, 60), st.integers(0, 60))
def test_exact_mcnemar_is_scipys_one_sided_binomial_test(n_sf, n_fs):
    p = (sps.binomtest(n_sf, n_sf + n_fs, 0.5, alternative="greater").pvalue
         if n_sf + n_fs else 1.0)
    assert stats.mcnemar_exact(n_sf, n_fs).p_value == pytest.approx(p, rel=1e-9, abs=1e-300)


@given(counts, st.floats(0.05, 0.95))
def test_binomial_greater_is_scipys(kn, p0):
    k, n = kn
    p = sps.binomtest(k, n, p0, alternative="greater").pvalue
    assert stats.binomial_greater(k, n, p0).p_value == pytest.approx(p, rel=1e-7, abs=1e-12)


@given(st.floats(0.0, 80.0), st.integers(1, 12))
def test_chi2_tail_is_scipys(x, df):
    assert stats.chi2_sf(x, df) == pytest.approx(sps.chi2.sf(x, df), rel=1e-9, abs=1e-15)


@given(st.lists(st.integers(1, 80).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))),
                min_size=2, max_size=7))
def test_chi2_homogeneity_is_scipys_uncorrected_contingency_test(rates):
    s = [k for k, _ in rates]
    n = [m for _, m in rates]
    t = stats.chi2_homogeneity(s, n)
    if sum(s) in (0, sum(n)):
        assert (t.statistic, t.p_value) == (0.0, 1.0)
        return
    chi2, p, dof, _ = sps.chi2_contingency(np.array([s, [m - k for k, m in rates]]).T,
                                           correction=False)
    assert t.statistic == pytest.approx(chi2, rel=1e-9, abs=1e-12)
    assert t.p_value == pytest.approx(p, rel=1e-7, abs=1e-15)
    assert f"df {dof}" in t.name


@given(st.floats(-8.0, 8.0), st.floats(1e-6, 1 - 1e-6))
def test_normal_tail_and_quantile_are_scipys(z, q):
    assert stats.norm_sf(z) == pytest.approx(sps.norm.sf(z), rel=1e-9, abs=1e-300)
    assert stats.norm_ppf(q) == pytest.approx(sps.norm.ppf(q), abs=1e-9)


@given(counts, counts)
def test_two_proportion_z_is_the_pooled_score_statistic(a, b):
    (k1, n1), (k2, n2) = a, b
    p = (k1 + k2) / (n1 + n2)
    se = math.sqrt(p * (1 - p) * (1 / n1 + 1 / n2))
    t = stats.two_proportion_z(k1, n1, k2, n2)
    if se == 0:
        assert t.p_value == 0.5 and t.statistic == 0.0
        return
    z = (k1 / n1 - k2 / n2) / se
    assert t.statistic == pytest.approx(z) and t.p_value == pytest.approx(sps.norm.sf(z))


@given(st.lists(st.tuples(*[st.booleans()] * 4), min_size=1, max_size=60))
def test_cochran_q_is_the_textbook_form_and_scipys_tail(rows):
    x = np.array(rows, dtype=float)
    k = x.shape[1]
    c, r = x.sum(axis=0), x.sum(axis=1)
    den = float(np.sum(r * (k - r)))
    t = stats.cochran_q(x)
    if den == 0:
        assert (t.statistic, t.p_value) == (0.0, 1.0)
        return
    q = k * (k - 1) * float(np.sum((c - c.mean()) ** 2)) / den
    assert t.statistic == pytest.approx(q, abs=1e-9)
    assert t.p_value == pytest.approx(sps.chi2.sf(q, k - 1), rel=1e-9, abs=1e-15)


def test_bootstrap_without_pairs_and_the_verdicts_boundaries():
    m, (lo, hi), t = stats.bootstrap_paired_diff([np.nan], [1.0], 0)
    assert math.isnan(m) and math.isnan(lo) and math.isnan(hi) and t.p_value == 1.0
    # p exactly alpha is not significant; an interval reaching delta does not rule it out
    assert stats.verdict(stats.ALPHA, (-1.0, 1.0), 2.0, 50) == "not reproduced"
    assert stats.verdict(stats.ALPHA, (-1.0, 2.0), 2.0, 50) == "inconclusive"
    assert stats.verdict(0.5, (-1.0, float("nan")), 2.0, 50) == "inconclusive"
    assert stats.verdict(0.5, (-1.0, 1.0), 2.0, stats.MIN_RUNS) == "not reproduced"
    assert stats.verdict(0.5, (-1.0, 1.0), 2.0, stats.MIN_RUNS - 1) == "inconclusive"


def test_percentile_bootstrap_level_and_draws():
    # 95 %: about mean ± 1.96 s / sqrt(n) for a large normal sample; 80 %: ± 1.28
    v = np.random.default_rng(8).normal(10.0, 2.0, 400)
    se = v.std() / math.sqrt(v.size)
    for level, z in ((0.95, 1.959964), (0.8, 1.281552)):
        lo, hi = stats.bootstrap_mean(v, 1, level=level)
        assert (hi - lo) / 2 == pytest.approx(z * se, rel=0.08)
        assert (lo + hi) / 2 == pytest.approx(v.mean(), abs=0.15 * se)
        m, (plo, phi_), _ = stats.bootstrap_paired_diff(v, np.zeros_like(v), 1, level=level)
        assert (phi_ - plo) / 2 == pytest.approx(z * se, rel=0.08) and plo < m < phi_
    # Every case is drawn with probability 1/n: one 1 among 19 zeros, first or last. A
    # resampled mean is 0 with probability (19/20)^20 = 0.358, and 3/20 is the 97.5 %
    # quantile of Binomial(20, 1/20) / 20.
    for d in (np.r_[1.0, np.zeros(19)], np.r_[np.zeros(19), 1.0]):
        _, _, t = stats.bootstrap_paired_diff(d, np.zeros(20), 2)
        assert t.p_value == pytest.approx(0.95**20, abs=0.035)
        assert stats.bootstrap_mean(d, 2) == (0.0, 0.15)
    assert stats.bootstrap_mean([3.0], 0) == (3.0, 3.0)
    assert all(math.isnan(x) for x in stats.bootstrap_mean([], 0))
    assert all(math.isnan(x) for x in stats.bootstrap_mean([np.nan], 0))


def test_the_edges_of_the_closed_forms():
    assert stats.chi2_sf(-0.5, 1) == 1.0 and stats.chi2_sf(-0.5, 2) == 1.0
    with pytest.raises(ValueError, match="df must be >= 1"):
        stats.chi2_sf(1.0, 0)
    for q in (0.0, 1.0, -0.5, 1.5):
        with pytest.raises(ValueError, match="q must be in"):
            stats.norm_ppf(q)
    with pytest.raises(ValueError, match="0 <= k <= n"):
        stats.wilson(-1, 3)
    # all successes or all failures: no difference to test
    for s in ([5, 7], [0, 0]):
        t = stats.chi2_homogeneity(s, [5, 7])
        assert (t.statistic, t.p_value) == (0.0, 1.0)
    with pytest.raises(ValueError, match="two rates"):
        stats.chi2_homogeneity([3], [5])
    # one discordant case between two methods: McNemar's χ² (1 − 0)² / 1
    assert stats.cochran_q([[1, 0]]).statistic == pytest.approx(1.0)
    assert stats.cochran_q([[0, 1], [1, 1]]).statistic == pytest.approx(1.0)


def test_newcombe_paired_interval_and_the_correlation_of_the_outcomes():
    def independent(n_ss, n_sf, n_fs, n_ff):
        n = n_ss + n_sf + n_fs + n_ff
        return stats.newcombe_diff(n_ss + n_sf, n, n_ss + n_fs, n)

    def with_phi(n_ss, n_sf, n_fs, n_ff, phi):
        n = n_ss + n_sf + n_fs + n_ff
        ka, kb = n_ss + n_sf, n_ss + n_fs
        (l1, u1), (l2, u2) = stats.wilson(ka, n), stats.wilson(kb, n)
        p1, p2 = ka / n, kb / n
        dl1, du1, dl2, du2 = p1 - l1, u1 - p1, p2 - l2, u2 - p2
        return (p1 - p2 - math.sqrt(dl1**2 + du2**2 - 2 * phi * dl1 * du2),
                p1 - p2 + math.sqrt(dl2**2 + du1**2 - 2 * phi * dl2 * du1))

    # cross-product n_ss n_ff − n_sf n_fs within [0, n/2]: φ = 0 (7 cases, cross 3)
    assert stats.newcombe_paired_diff(4, 1, 1, 1) == pytest.approx(independent(4, 1, 1, 1))
    # above n/2 (5 cases, cross 3): φ = (3 − 2.5) / √(4·1·3·2)
    assert stats.newcombe_paired_diff(3, 1, 0, 1) == pytest.approx(
        with_phi(3, 1, 0, 1, 0.5 / math.sqrt(24)))
    # below 0: the plain correlation, φ = −80 / √(10⁴) = −0.8 and φ = −1
    assert stats.newcombe_paired_diff(1, 9, 9, 1) == pytest.approx(
        with_phi(1, 9, 9, 1, -0.8))
    assert stats.newcombe_paired_diff(0, 1, 1, 0) == pytest.approx(with_phi(0, 1, 1, 0, -1.0))
    # one case is a case
    assert all(math.isfinite(x) for x in stats.newcombe_paired_diff(1, 0, 0, 0))


@pytest.mark.parametrize("n", [1, 7, 500])
def test_bootstrap_mean_in_blocks_draws_as_one_array(monkeypatch, n):
    # Memory is bounded by drawing resamples in blocks; the interval is that of one
    # (n_boot, n) draw, whatever the block.
    v = np.random.default_rng(n).normal(size=n)
    idx = np.random.default_rng(9).integers(0, n, size=(stats.N_BOOT, n))
    means = v[idx].mean(axis=1)
    want = (float(np.quantile(means, 0.025)), float(np.quantile(means, 0.975)))
    for block in (1, 3 * n + 1, 1 << 22):
        monkeypatch.setattr(stats, "_BLOCK", block)
        assert stats.bootstrap_mean(v, 9) == want


def test_two_proportion_z_refuses_more_successes_than_trials():
    with pytest.raises(ValueError, match="k1 <= n1, got k1=5, n1=3"):
        stats.two_proportion_z(5, 3, 1, 2)
    with pytest.raises(ValueError, match="k2=-1"):
        stats.two_proportion_z(1, 3, -1, 2)
    assert stats.two_proportion_z(3, 3, 0, 2).p_value < 0.05
