"""The statistics the experiments judge the papers' claims with (no scipy needed).

Intervals: :func:`wilson` for rates, :func:`newcombe_diff` for the difference of two rates
on independent samples and :func:`newcombe_paired_diff` on paired cases,
:func:`bootstrap_mean` and :func:`bootstrap_paired_diff` (percentile bootstrap, seeded) for
means, and :func:`bootstrap_clustered_diff` for the difference of two rates over paired
scenes (runs on one scene are not independent: the scene is resampled, not the run).
Tests (one-sided, in the paper's direction): :func:`two_proportion_z` (independent
samples), :func:`mcnemar_exact` (paired cases), :func:`chi2_homogeneity` (k rates equal?),
:func:`cochran_q` (k methods on the same cases equal?), :func:`binomial_greater` (one rate
above a level). :func:`verdict` turns a p-value and an
interval for the effect into "reproduced", "not reproduced" or "inconclusive":

- **reproduced**: p < ``alpha`` in the paper's direction;
- **not reproduced**: not significant, and our interval for the effect excludes the effect
  of interest ``delta`` (the paper's own effect where it prints one): an effect that large
  is ruled out by our runs — or the effect is significant the other way;
- **inconclusive**: neither, or fewer than :data:`MIN_RUNS` runs (cases) per compared
  arm: the runs are too few to tell.

Every function takes counts or arrays and returns plain floats, so results stay JSON-ready.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "ALPHA",
    "LEVEL",
    "MIN_RUNS",
    "Test",
    "binomial_greater",
    "bootstrap_mean",
    "bootstrap_clustered_diff",
    "bootstrap_paired_diff",
    "chi2_homogeneity",
    "chi2_sf",
    "cochran_q",
    "mcnemar_exact",
    "newcombe_diff",
    "newcombe_paired_diff",
    "norm_ppf",
    "norm_sf",
    "two_proportion_z",
    "verdict",
    "wilson",
]

ALPHA = 0.05
"""Significance level of every claim (one-sided, no correction for the number of claims)."""
LEVEL = 0.95
"""Coverage of every interval."""
N_BOOT = 2000
"""Bootstrap resamples."""
MIN_RUNS = 10
"""Fewest runs (or paired cases) per compared arm for a "not reproduced" verdict."""


@dataclass(frozen=True)
class Test:
    """A test's outcome.

    Attributes
    ----------
    name : str
        The test (e.g. ``"paired McNemar (exact, one-sided)"``).
    statistic : float
        Its statistic (z, χ², or the discordant count), NaN where none.
    p_value : float
        One-sided p-value in the paper's direction (χ²: upper tail).
    min_n : int
        Fewest cases for the p-value to be trusted: 0 for exact tests, :data:`MIN_RUNS`
        for resampling tests (a bootstrap over two scenes proves nothing).
    """

    name: str
    statistic: float
    p_value: float
    min_n: int = 0


def norm_sf(z: float) -> float:
    """P(Z > z) for a standard normal Z.

    Parameters
    ----------
    z : float
        The threshold.

    Returns
    -------
    float
        The upper-tail probability, in [0, 1].

    Examples
    --------
    >>> norm_sf(0.0)
    0.5
    """
    return 0.5 * math.erfc(z / math.sqrt(2.0))


def norm_ppf(q: float) -> float:
    """The standard normal quantile: z with P(Z <= z) = q, 0 < q < 1 (bisection, 1e-12).

    Parameters
    ----------
    q : float
        The probability, in (0, 1).

    Returns
    -------
    float
        The quantile z (within [-40, 40]).

    Raises
    ------
    ValueError
        For ``q`` outside (0, 1).

    Examples
    --------
    >>> round(norm_ppf(0.975), 4)
    1.96
    """
    if not 0.0 < q < 1.0:
        raise ValueError(f"q must be in (0, 1), got {q}")
    lo, hi = -40.0, 40.0
    while hi - lo > 1e-12:
        mid = 0.5 * (lo + hi)
        if 1.0 - norm_sf(mid) < q:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def wilson(k: int, n: int, level: float = LEVEL) -> tuple[float, float]:
    """Wilson score interval of a rate k/n, as fractions in [0, 1]; (nan, nan) for n = 0.

    Parameters
    ----------
    k : int
        Successes.
    n : int
        Trials.
    level : float, default LEVEL
        Coverage of the interval (0.95).

    Returns
    -------
    low, high : float
        The interval's bounds, clipped to [0, 1].

    Raises
    ------
    ValueError
        For ``k`` outside [0, n] (with n > 0).

    Examples
    --------
    >>> low, high = wilson(8, 10)
    >>> round(low, 3), round(high, 3)
    (0.49, 0.943)
    """
    if n <= 0:
        return (float("nan"), float("nan"))
    if not 0 <= k <= n:
        raise ValueError(f"need 0 <= k <= n, got k={k}, n={n}")
    z = norm_ppf(0.5 + level / 2.0)
    p = k / n
    den = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (max(0.0, centre - half), min(1.0, centre + half))


def newcombe_diff(k1: int, n1: int, k2: int, n2: int,
                  level: float = LEVEL) -> tuple[float, float]:
    """Newcombe's hybrid score interval of p1 − p2 (from the two Wilson intervals);
    (nan, nan) for an empty sample (n1 or n2 of 0), as :func:`wilson`.

    Parameters
    ----------
    k1, n1 : int
        Successes and trials of the first sample.
    k2, n2 : int
        Successes and trials of the second sample.
    level : float, default LEVEL
        Coverage of the interval (0.95).

    Returns
    -------
    low, high : float
        The interval's bounds for p1 − p2, as fractions.

    Raises
    ------
    ValueError
        For a ``k`` outside [0, n] (with n > 0).
    """
    if n1 <= 0 or n2 <= 0:
        return (float("nan"), float("nan"))
    p1, p2 = k1 / n1, k2 / n2
    l1, u1 = wilson(k1, n1, level)
    l2, u2 = wilson(k2, n2, level)
    d = p1 - p2
    return (d - math.sqrt((p1 - l1) ** 2 + (u2 - p2) ** 2),
            d + math.sqrt((u1 - p1) ** 2 + (p2 - l2) ** 2))


def newcombe_paired_diff(n_ss: int, n_sf: int, n_fs: int, n_ff: int,
                         level: float = LEVEL) -> tuple[float, float]:
    """Newcombe's square-and-add interval of p_A − p_B over paired cases.

    Newcombe (1998), "Improved confidence intervals for the difference between binomial
    proportions based on paired data", method 10: the two Wilson intervals of
    :func:`newcombe_diff`, combined with the correlation φ of the paired outcomes, so
    that cases which succeed or fail for both methods narrow the interval as they do the
    McNemar test. ``n_ss``: both succeed; ``n_sf``: A succeeds and B fails; ``n_fs``: the
    reverse; ``n_ff``: both fail. φ is (n_ss n_ff − n_sf n_fs − n/2) / √(row and column
    products) when the cross-product exceeds n/2, 0 when it lies in [0, n/2], and the
    plain correlation below 0; φ = 0 (the independent-sample interval) when a margin is
    empty. Returns (nan, nan) without cases.

    Parameters
    ----------
    n_ss, n_sf, n_fs, n_ff : int
        Counts of the paired cases by outcome, as above.
    level : float, default LEVEL
        Coverage of the interval (0.95).

    Returns
    -------
    low, high : float
        The interval's bounds for p_A − p_B, as fractions.
    """
    n = n_ss + n_sf + n_fs + n_ff
    if n <= 0:
        return (float("nan"), float("nan"))
    ka, kb = n_ss + n_sf, n_ss + n_fs
    p1, p2 = ka / n, kb / n
    l1, u1 = wilson(ka, n, level)
    l2, u2 = wilson(kb, n, level)
    margins = ka * (n - ka) * kb * (n - kb)
    phi = 0.0
    if margins > 0:
        cross = n_ss * n_ff - n_sf * n_fs
        if cross > n / 2:
            phi = (cross - n / 2) / math.sqrt(margins)
        elif cross < 0:
            phi = cross / math.sqrt(margins)
    d = p1 - p2
    dl1, du1, dl2, du2 = p1 - l1, u1 - p1, p2 - l2, u2 - p2
    return (d - math.sqrt(max(0.0, dl1 ** 2 + du2 ** 2 - 2 * phi * dl1 * du2)),
            d + math.sqrt(max(0.0, dl2 ** 2 + du1 ** 2 - 2 * phi * dl2 * du1)))


def two_proportion_z(k1: int, n1: int, k2: int, n2: int) -> Test:
    """Pooled two-proportion z test of p1 > p2 (one-sided).

    Parameters
    ----------
    k1, n1 : int
        Successes and trials of the first sample.
    k2, n2 : int
        Successes and trials of the second sample.

    Returns
    -------
    Test
        Statistic z (±inf for a difference with zero pooled variance, 0 for none) and
        p-value P(Z > z); statistic NaN and p-value 1.0 for an empty sample (``n1`` or
        ``n2`` of 0: no evidence), as :func:`bootstrap_paired_diff` without pairs.

    Raises
    ------
    ValueError
        If a sample has more successes than trials, or fewer than 0 (as :func:`wilson`).
    """
    name = "two-proportion z (pooled, one-sided)"
    if n1 <= 0 or n2 <= 0:
        return Test(name, float("nan"), 1.0)
    for k, n, which in ((k1, n1, "1"), (k2, n2, "2")):
        if not 0 <= k <= n:
            raise ValueError(f"need 0 <= k{which} <= n{which}, got k{which}={k}, n{which}={n}")
    p = (k1 + k2) / (n1 + n2)
    se = math.sqrt(p * (1 - p) * (1 / n1 + 1 / n2))
    d = k1 / n1 - k2 / n2
    if se == 0:
        z = 0.0 if d == 0 else math.copysign(math.inf, d)
    else:
        z = d / se
    return Test(name, z, norm_sf(z))


def mcnemar_exact(n_sf: int, n_fs: int) -> Test:
    """Exact McNemar test that A succeeds more often than B over paired cases.

    ``n_sf``: cases where A succeeds and B fails; ``n_fs``: the reverse. The p-value is
    P(X >= n_sf) for X ~ Binomial(n_sf + n_fs, 1/2); 1.0 without discordant pairs.

    Parameters
    ----------
    n_sf, n_fs : int
        Discordant counts, as above.

    Returns
    -------
    Test
        Statistic ``n_sf`` and the exact p-value.

    Examples
    --------
    >>> mcnemar_exact(5, 0).p_value
    0.03125
    """
    n = n_sf + n_fs
    p = sum(math.comb(n, i) for i in range(n_sf, n + 1)) / 2.0**n if n else 1.0
    return Test("paired McNemar (exact binomial, one-sided)", float(n_sf), min(1.0, p))


def binomial_greater(k: int, n: int, p0: float) -> Test:
    """Exact binomial test that a rate exceeds p0: P(X >= k) for X ~ Binomial(n, p0).

    Parameters
    ----------
    k : int
        Successes.
    n : int
        Trials.
    p0 : float
        The level the rate is tested against, in [0, 1].

    Returns
    -------
    Test
        Statistic ``k`` and the exact p-value.
    """
    p = sum(math.comb(n, i) * p0**i * (1 - p0) ** (n - i) for i in range(k, n + 1))
    return Test(f"exact binomial (rate > {p0:g}, one-sided)", float(k), min(1.0, p))


def chi2_sf(x: float, df: int) -> float:
    """P(X > x) for X ~ χ² with integer ``df`` >= 1 (closed forms, no special functions).

    Parameters
    ----------
    x : float
        The threshold (1.0 is returned for x <= 0).
    df : int
        Degrees of freedom, >= 1.

    Returns
    -------
    float
        The upper-tail probability, in [0, 1].

    Raises
    ------
    ValueError
        For ``df`` < 1.
    """
    if df < 1:
        raise ValueError(f"df must be >= 1, got {df}")
    if x <= 0:
        return 1.0
    h = x / 2.0
    if df % 2 == 0:
        term, total = 1.0, 1.0
        for k in range(1, df // 2):
            term *= h / k
            total += term
        return min(1.0, math.exp(-h) * total)
    total = math.erfc(math.sqrt(h))
    term = math.sqrt(h) * 2.0 / math.sqrt(math.pi) * math.exp(-h)
    for k in range(1, (df - 1) // 2 + 1):
        total += term
        term *= h / (k + 0.5)
    return min(1.0, total)


def chi2_homogeneity(successes: Sequence[int], totals: Sequence[int]) -> Test:
    """Pearson χ² test that k rates are equal (k x 2 table, df = k − 1).

    Parameters
    ----------
    successes : sequence of int, shape (k,)
        Successes per rate.
    totals : sequence of int, shape (k,)
        Trials per rate.

    Returns
    -------
    Test
        Statistic χ² and its upper-tail p-value (0 and 1 when the pooled rate is 0 or 1).

    Raises
    ------
    ValueError
        For fewer than two rates.
    """
    s = np.asarray(successes, dtype=np.float64)
    n = np.asarray(totals, dtype=np.float64)
    if s.size < 2:
        raise ValueError("need at least two rates")
    p = s.sum() / n.sum()
    exp_s, exp_f = n * p, n * (1 - p)
    if p in (0.0, 1.0):
        return Test("Pearson χ² homogeneity", 0.0, 1.0)
    chi2 = float(np.sum((s - exp_s) ** 2 / exp_s + ((n - s) - exp_f) ** 2 / exp_f))
    return Test(f"Pearson χ² homogeneity (df {s.size - 1})", chi2, chi2_sf(chi2, s.size - 1))


def cochran_q(outcomes: ArrayLike) -> Test:
    """Cochran's Q test that k methods succeed equally often on the same cases.

    ``outcomes`` (n, k) of 0/1: case i (a row: the same scene and run for every method)
    and method j. Q = (k − 1) (k Σ_j C_j² − T²) / (k T − Σ_i R_i²) with column totals C,
    row totals R and total T, referred to χ² with k − 1 degrees of freedom. Cases where
    every method agrees carry no information and drop out, so the scene's own difficulty,
    shared by the methods run on it, does not count as a difference between them.
    Q = 0, p = 1 when no case is discordant.

    Parameters
    ----------
    outcomes : array_like of 0/1, shape (n, k)
        Outcome of each case (row) for each method (column), k >= 2.

    Returns
    -------
    Test
        Statistic Q and its χ² upper-tail p-value.

    Raises
    ------
    ValueError
        For ``outcomes`` not two-dimensional or with fewer than two columns.
    """
    x = np.asarray(outcomes, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] < 2:
        raise ValueError(f"need (cases, k >= 2) outcomes, got shape {x.shape}")
    k = x.shape[1]
    name = f"Cochran's Q over paired cases (df {k - 1})"
    rows, cols, total = x.sum(axis=1), x.sum(axis=0), x.sum()
    den = k * total - float(np.sum(rows**2))
    if den <= 0:
        return Test(name, 0.0, 1.0)
    q = (k - 1) * (k * float(np.sum(cols**2)) - total**2) / den
    return Test(name, float(q), chi2_sf(float(q), k - 1))


def bootstrap_clustered_diff(a: dict[Any, Sequence[float]], b: dict[Any, Sequence[float]],
                             rng: int | np.random.Generator, *, n_boot: int = N_BOOT,
                             level: float = LEVEL) -> tuple[float, tuple[float, float], Test]:
    """Difference of two rates (or means) over paired clusters, resampling the clusters.

    ``a`` and ``b`` map a cluster (a scene) to its outcomes (0/1 or values) under the two
    arms; only clusters in both count. The effect is the mean over clusters of
    mean(a_c) − mean(b_c) (with equal runs per cluster, the difference of the overall
    rates); its interval and the one-sided test (share of resampled effects <= 0) come
    from resampling clusters with replacement, so runs that share a scene are not taken
    as independent evidence.

    Parameters
    ----------
    a, b : dict of hashable to sequence of float
        Per cluster, its outcomes under each arm.
    rng : int or numpy.random.Generator
        Seed or generator of the resampling (the same seed gives the same result).
    n_boot : int, default N_BOOT
        Bootstrap resamples (2000).
    level : float, default LEVEL
        Coverage of the interval (0.95).

    Returns
    -------
    effect : float
        The mean over shared clusters of mean(a_c) − mean(b_c).
    interval : (float, float)
        Its percentile bootstrap interval.
    test : Test
        One-sided test of effect > 0 (``min_n`` :data:`MIN_RUNS`).

    See Also
    --------
    bootstrap_paired_diff : the same over the per-cluster differences.
    """
    keys = sorted(set(a) & set(b))  # type: ignore[type-var]
    d = np.array([np.mean(a[c]) - np.mean(b[c]) for c in keys], dtype=np.float64)
    mean, ci, test = bootstrap_paired_diff(d, np.zeros(d.size), rng, n_boot=n_boot, level=level)
    return mean, ci, Test("paired bootstrap over scenes (one-sided)", test.statistic,
                          test.p_value, MIN_RUNS)


def _rng(seed: int | np.random.Generator) -> np.random.Generator:
    return seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)


_BLOCK = 1 << 22  # values drawn per block of bootstrap resamples


def bootstrap_mean(values: ArrayLike, rng: int | np.random.Generator, *,
                   n_boot: int = N_BOOT, level: float = LEVEL) -> tuple[float, float]:
    """Percentile bootstrap interval of the mean of ``values`` (shape (n,), NaN dropped).

    Seeded through ``rng``: the same seed gives the same interval. (nan, nan) if empty.

    Parameters
    ----------
    values : array_like of float, shape (n,)
        The values; non-finite ones (NaN, inf) are dropped.
    rng : int or numpy.random.Generator
        Seed or generator of the resampling.
    n_boot : int, default N_BOOT
        Bootstrap resamples (2000).
    level : float, default LEVEL
        Coverage of the interval (0.95).

    Returns
    -------
    low, high : float
        The percentile interval of the resampled means.
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return (float("nan"), float("nan"))
    # Drawn in blocks of rows (the same draws as one (n_boot, n) call, memory bounded
    # for long value lists such as a benchmark's thousands of sequences).
    gen = _rng(rng)
    block = max(1, _BLOCK // v.size)
    means = np.concatenate([
        v[gen.integers(0, v.size, size=(min(block, n_boot - i), v.size))].mean(axis=1)
        for i in range(0, n_boot, block)
    ])  # fmt: skip
    a = (1.0 - level) / 2.0
    return (float(np.quantile(means, a)), float(np.quantile(means, 1.0 - a)))


def bootstrap_paired_diff(a: ArrayLike, b: ArrayLike, rng: int | np.random.Generator, *,
                          n_boot: int = N_BOOT, level: float = LEVEL
                          ) -> tuple[float, tuple[float, float], Test]:
    """Mean of a − b over paired cases, its percentile bootstrap interval and a test.

    The test's p-value is the share of resampled means <= 0 (one-sided: mean(a − b) > 0),
    at least 1 / n_boot. Pairs with a NaN are dropped.

    Parameters
    ----------
    a, b : array_like of float, shape (n,)
        Paired values; pairs whose difference is not finite are dropped.
    rng : int or numpy.random.Generator
        Seed or generator of the resampling.
    n_boot : int, default N_BOOT
        Bootstrap resamples (2000).
    level : float, default LEVEL
        Coverage of the interval (0.95).

    Returns
    -------
    mean : float
        Mean of a − b (NaN without pairs).
    interval : (float, float)
        Its percentile bootstrap interval ((nan, nan) without pairs).
    test : Test
        Statistic the mean, p-value as above (1.0 without pairs), ``min_n``
        :data:`MIN_RUNS`.
    """
    d = np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)
    d = d[np.isfinite(d)]
    if d.size == 0:
        nan = float("nan")
        return nan, (nan, nan), Test("paired bootstrap of the mean difference", nan, 1.0,
                                     MIN_RUNS)
    idx = _rng(rng).integers(0, d.size, size=(n_boot, d.size))
    means = d[idx].mean(axis=1)
    al = (1.0 - level) / 2.0
    p = max(float(np.mean(means <= 0.0)), 1.0 / n_boot)
    return (float(d.mean()),
            (float(np.quantile(means, al)), float(np.quantile(means, 1.0 - al))),
            Test("paired bootstrap of the mean difference (one-sided)", float(d.mean()), p,
                 MIN_RUNS))


def verdict(p_value: float, interval: tuple[float, float], delta: float, n: int,
            alpha: float = ALPHA, *, min_n: int = 0) -> str:
    """Judge a claim "effect > 0" from its one-sided p-value and an interval for the effect.

    Parameters
    ----------
    p_value : float
        One-sided p-value in the claim's direction.
    interval : (float, float)
        Interval for the effect (positive = the paper's direction).
    delta : float
        Effect of interest (> 0): the paper's effect, or a stated smallest effect that
        matters where the paper prints none.
    n : int
        Runs (or paired cases) of the smaller compared arm.
    alpha : float, default ALPHA
        Significance level (0.05).
    min_n : int, default 0
        Fewest cases for a significant p-value to count (``Test.min_n``).

    Returns
    -------
    str
        ``"reproduced"`` (p < alpha and n >= min_n), ``"not reproduced"`` (n >=
        :data:`MIN_RUNS` and the interval lies below delta, i.e. an effect that large is
        ruled out, or wholly below 0), else ``"inconclusive"`` (too few runs to tell).
    """
    lo, hi = interval
    if p_value < alpha and n >= min_n:
        return "reproduced"
    if n >= MIN_RUNS and math.isfinite(hi) and (hi < delta or hi < 0):
        return "not reproduced"
    return "inconclusive"
