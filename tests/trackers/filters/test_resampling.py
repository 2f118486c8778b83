"""Resamplers and weighted resampling: unbiasedness, group confinement, bad input."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackers.filters.resampling import (
    RESAMPLERS,
    resample,
    resample_groups,
    weighted_resample,
    weighted_resample_groups,
)

methods = st.sampled_from(RESAMPLERS)
seeds = st.integers(0, 2**32 - 1)


@settings(max_examples=20)
@given(seed=seeds, method=methods, n=st.integers(1, 60))
def test_resampler_counts_are_unbiased(seed, method, n):
    rng = np.random.default_rng(seed)
    w = rng.dirichlet(np.full(n, 0.5))
    reps = 400
    counts = np.zeros(n)
    for _ in range(reps):
        idx = resample(w, method=method, rng=rng)
        assert idx.shape == (n,) and idx.min() >= 0 and idx.max() < n
        counts += np.bincount(idx, minlength=n)
    # E[count_i] = n w_i; the multinomial variance bounds the other schemes' too.
    se = np.sqrt(n * w * (1 - w) / reps) + 1e-9
    assert np.all(np.abs(counts / reps - n * w) <= 5 * se + 1e-9)


@settings(max_examples=15)
@given(seed=seeds, n=st.integers(1, 60))
def test_low_variance_schemes_keep_floor_and_ceiling(seed, n):
    rng = np.random.default_rng(seed)
    w = rng.dirichlet(np.ones(n))
    for method in ("systematic", "residual"):
        counts = np.bincount(resample(w, method=method, rng=rng), minlength=n)
        assert np.all(counts >= np.floor(n * w - 1e-9))
        if method == "systematic":
            assert np.all(counts <= np.ceil(n * w + 1e-9))


@settings(max_examples=20)
@given(seed=seeds, method=methods, sizes=st.lists(st.integers(1, 30), min_size=1, max_size=6))
def test_groups_are_resampled_within_themselves(seed, method, sizes):
    rng = np.random.default_rng(seed)
    sizes = np.array(sizes)
    w = rng.random(sizes.sum()) + 1e-3
    idx = resample_groups(w, sizes, method=method, rng=rng)
    group = np.repeat(np.arange(sizes.size), sizes)
    np.testing.assert_array_equal(group[idx], group)


@settings(max_examples=12)
@given(seed=seeds, method=methods, n_groups=st.integers(1, 3))
def test_weighted_resampling_preserves_weighted_means(seed, method, n_groups):
    """§3.2: after weighted resampling the set represents the same distribution."""
    rng = np.random.default_rng(seed)
    n = 400
    sizes = np.full(n_groups, n)
    x = rng.normal(0.0, 1.0, n * n_groups)
    pi = rng.random(n * n_groups) + 0.1
    # Peaked away from the bulk of the particles, but bounded below: the new weights are
    # ∝ 1 / g, and a g that vanishes where π has mass gives them unbounded variance.
    g = 0.2 + np.exp(-((x - 1.0) ** 2))
    tests = (lambda v: v, lambda v: v**2, np.sin, lambda v: (v > 0.5).astype(float))
    starts = np.arange(n_groups) * n

    def means(values, weights):
        return np.array([[np.sum(weights[s:s + n] * f(values[s:s + n])) / np.sum(weights[s:s + n])
                          for s in starts] for f in tests])

    before = means(x, pi)
    reps = 40
    after = np.zeros_like(before)
    for _ in range(reps):
        idx, w = weighted_resample_groups(pi, g, sizes, method=method, rng=rng)
        np.testing.assert_allclose(np.add.reduceat(w, starts), 1.0)
        after += means(x[idx], w) / reps
    # Monte-Carlo tolerance: ~5 standard errors of a mean over reps x n particles.
    assert np.all(np.abs(after - before) < 0.06)


def test_weighted_resampling_moves_particles_to_high_g():
    rng = np.random.default_rng(0)
    x = np.linspace(-3, 3, 300)
    g = np.exp(-4 * x**2)
    idx, w = weighted_resample(np.full(300, 1 / 300), g, rng=rng)
    assert np.mean(np.abs(x[idx])) < 0.5 * np.mean(np.abs(x))
    # New weights are pi / rho, i.e. proportional to 1 / g of the ancestor.
    np.testing.assert_allclose(w * g[idx], (w * g[idx])[0])


def test_same_seed_same_draw():
    w = np.random.default_rng(1).random(50)
    for method in RESAMPLERS:
        a = resample(w, method=method, rng=np.random.default_rng(7))
        b = resample(w, method=method, rng=np.random.default_rng(7))
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("call, match", [
    (lambda rng: resample(np.ones(3), method="bogus", rng=rng),
     "unknown resampler 'bogus'; valid: multinomial, systematic, stratified, residual"),
    (lambda rng: resample(np.array([1.0, -1.0]), rng=rng), "non-negative"),
    (lambda rng: resample(np.zeros(3), rng=rng), "positive sum"),
    (lambda rng: resample(np.array([1.0, np.nan]), rng=rng), "finite"),
    (lambda rng: resample_groups(np.ones(4), [2, 3], rng=rng), "sum to 4"),
    (lambda rng: weighted_resample(np.ones(3), np.ones(2), rng=rng), "shape"),
    (lambda rng: weighted_resample(np.ones(3), np.zeros(3), rng=rng), "positive sum"),
    # Weights of another shape named the group sizes ("must ... sum to -1", "to 0").
    (lambda rng: resample(np.ones((3, 2)), rng=rng),
     r"weights must have shape \(N,\) with N >= 1, got \(3, 2\)"),
    (lambda rng: resample(np.ones(0), rng=rng),
     r"weights must have shape \(N,\) with N >= 1, got \(0,\)"),
    (lambda rng: weighted_resample(np.ones((2, 2)), np.ones((2, 2)), rng=rng),
     r"weights must have shape \(N,\)"),
    # A seed for rng was "'int' object has no attribute 'random'" (AttributeError).
    (lambda rng: resample(np.ones(3), rng=0), "rng must be a numpy Generator .*got int"),
    (lambda rng: resample_groups(np.ones(3), rng=None), "rng must be a numpy Generator"),
    (lambda rng: weighted_resample(np.ones(3), np.ones(3), rng=1),
     "rng must be a numpy Generator"),
])
def test_bad_input_raises(call, match):
    with pytest.raises(ValueError, match=match):
        call(np.random.default_rng(0))


# Inputs that are not float64, 1-d and C-contiguous are normalised by numpy instead of
# the compiled kernel: both paths must give the same bits, and the definition.
INPUT_FORMS = {
    "float32": lambda w: w.astype(np.float32),
    "strided": lambda w: np.repeat(w, 2)[::2],
    "list": lambda w: w.tolist(),
}


@pytest.mark.parametrize("form", sorted(INPUT_FORMS))
def test_every_input_form_is_normalised_per_group_as_the_compiled_path(form):
    from trackers.filters.resampling import _normalise_groups

    sizes = np.array([3, 5, 4])
    w = np.random.default_rng(3).random(12) * 0.1  # group sums below 1: the division shows
    given_ = INPUT_FORMS[form](w)
    plain = np.ascontiguousarray(given_, dtype=np.float64)
    starts = np.cumsum(sizes) - sizes
    want = np.concatenate([plain[s:s + n] / plain[s:s + n].sum()
                           for s, n in zip(starts, sizes, strict=True)])
    compiled = _normalise_groups(plain, sizes, "weights")
    np.testing.assert_allclose(compiled, want, rtol=1e-15)
    np.testing.assert_array_equal(_normalise_groups(given_, sizes, "weights"), compiled)
    for method in RESAMPLERS:
        np.testing.assert_array_equal(
            resample_groups(given_, sizes, method=method, rng=np.random.default_rng(4)),
            resample_groups(plain, sizes, method=method, rng=np.random.default_rng(4)))
    zero = np.array(plain)
    zero[3:8] = 0.0
    with pytest.raises(ValueError, match=r"positive sum in every group.*0\.0"):
        _normalise_groups(INPUT_FORMS[form](zero), sizes, "weights")
