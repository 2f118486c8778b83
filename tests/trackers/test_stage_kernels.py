"""The compiled stages of the particle filters equal the numpy code they replace, exactly.

``trackers.kernels.stages`` promises the same floating-point results to the last bit (same
operations in the same order, numpy's pairwise summation replicated, exp/log left to
numpy). Each kernel is compared here with its numpy expression with ``array_equal``, and
a PS/DPS step with a pure-numpy reference step (the partitioned-sampling step as it was
written before it was compiled) on the same seeds: particles, weights, estimates and the
state of the random stream all equal.
"""

from __future__ import annotations

import numpy as np
import pytest

from trackers.base import clip_boxes
from trackers.filters.diagnostics import effective_dynamics, uniqueness
from trackers.filters.resampling import (
    RESAMPLE_MODES,
    RESAMPLERS,
    resample,
    weighted_resample_groups,
)
from trackers.filters.weights import log_sum_exp_groups, normalised_weights
from trackers.kernels.sampling import (
    MULTINOMIAL,
    STRATIFIED,
    SYSTEMATIC,
    count_distinct,
    inverse_cdf_groups,
)
from trackers.kernels.stages import (
    add_row_sums,
    clip_centres,
    effective_uv,
    gather_pair,
    group_weights,
    normalise_groups_checked,
    normalise_rows,
    numpy_reduceat_sum,
    numpy_sum,
    propagate_objects,
    reassemble,
    resample_propagate,
    row_max_shift,
    stage_log_weights,
    state_boxes,
    weighted_mean_states,
    weighted_resample_gather,
)
from trackers.models.dynamics import AR2, boxes_from_states
from trackers.particle import DistributedPartitionedSampling, PartitionedSampling

SIZES = [1, 2, 7, 8, 9, 15, 16, 17, 127, 128, 129, 130, 255, 256, 257, 300, 1000, 2100, 9001]


def _values(rng, n):
    # Wide dynamic range, so that any change of summation order shows in the last bits.
    return rng.random(n) * rng.choice([1e-6, 1.0, 1e6], n)


@pytest.mark.parametrize("n", SIZES)
def test_sums_replicate_numpy_to_the_bit(n):
    rng = np.random.default_rng(n)
    x = _values(rng, n)
    assert numpy_sum(x) == np.sum(x)
    cuts = np.sort(rng.choice(np.arange(1, n), min(5, n - 1), replace=False)) if n > 1 else []
    starts = np.concatenate([[0], cuts]).astype(np.int64)
    sizes = np.diff(np.append(starts, n))
    assert np.array_equal(numpy_reduceat_sum(x, sizes), np.add.reduceat(x, starts))


def test_reduceat_sum_keeps_the_sign_of_zero_groups():
    # A group whose terms are all -0.0 sums to -0.0 in numpy at every size (its rest
    # starts at -0.0 below 8 terms); a group of +0.0 and -0.0 to +0.0. array_equal cannot
    # tell the zeros apart: the sign bits are compared too.
    x = np.concatenate([np.full(n, -0.0) for n in range(1, 20)] + [[0.0, -0.0, -0.0]])
    sizes = np.array([*range(1, 20), 3], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    want = np.add.reduceat(x, starts)
    got = numpy_reduceat_sum(x, sizes)
    assert np.array_equal(got, want)
    assert np.array_equal(np.signbit(got), np.signbit(want))
    assert np.signbit(want[:-1]).all() and not np.signbit(want[-1])


@pytest.mark.parametrize("k", [1, 2, 3, 7, 8, 9, 16, 17, 128, 129, 300])
def test_add_row_sums_is_numpy_row_sums(k):
    # Rows of 8 or more terms are summed pairwise by numpy, shorter ones in order; both,
    # and a row longer than numpy's 128-term block, to the bit (-0.0 terms included: a
    # likelihood of exactly 1 gives log -0.0).
    rng = np.random.default_rng(k)
    m = _values(rng, 40 * k).reshape(40, k) * rng.choice([-1.0, 1.0], (40, k))
    m[rng.random((40, k)) < 0.1] = -0.0
    m[0] = -0.0
    a = _values(rng, 40)
    got = add_row_sums(a, m)
    assert np.array_equal(got, a + m.sum(axis=1))
    assert not np.signbit(got[0] - a[0])


def _clip_numpy(boxes, width, height):
    # The numpy expression clip_centres replaced.
    b = np.array(boxes, dtype=np.float64, copy=True)
    cx = np.clip(b[:, 0] + b[:, 2] / 2, 0.0, width)
    cy = np.clip(b[:, 1] + b[:, 3] / 2, 0.0, height)
    b[:, 0] = cx - b[:, 2] / 2
    b[:, 1] = cy - b[:, 3] / 2
    return b


def test_clip_centres_is_the_numpy_clip():
    rng = np.random.default_rng(3)
    for trial in range(300):
        boxes = rng.normal(100, 150, (int(rng.integers(0, 8)), 4))
        boxes[:, 2:] = np.abs(boxes[:, 2:])
        if trial % 5 == 0 and boxes.size:
            boxes.flat[rng.integers(0, boxes.size)] = rng.choice([np.nan, np.inf, -np.inf])
        width, height = int(rng.integers(1, 400)), int(rng.integers(1, 400))
        want = _clip_numpy(boxes, width, height)
        got = clip_centres(boxes, width, height)
        assert np.array_equal(got, want, equal_nan=True)
        assert np.array_equal(clip_boxes(boxes, (height, width, 3)), want, equal_nan=True)
    # Each side: centres left of, right of, above and below the frame, and inside.
    boxes = np.array([[-30.0, 5.0, 10, 4], [95.0, 5.0, 10, 4], [5.0, -9.0, 4, 6],
                      [5.0, 48.0, 4, 6], [20.0, 20.0, 4, 6]])
    got = clip_centres(boxes, 100, 50)
    assert got[:, 0] + got[:, 2] / 2 == pytest.approx([0, 100, 7, 7, 22])
    assert got[:, 1] + got[:, 3] / 2 == pytest.approx([7, 7, 0, 50, 23])
    assert np.array_equal(got[:, 2:], boxes[:, 2:])
    assert not np.shares_memory(got, boxes)


def _inverse_cdf_numpy(weights, sizes, counts, uniforms, mode):
    # Each group's cdf (cumulative sums in order over their total, the last set to 1) and,
    # per position u, the first index whose cdf exceeds u, the last index if none does.
    out, start, j = [], 0, 0
    for g, (size, count) in enumerate(zip(sizes, counts, strict=True)):
        acc = np.cumsum(weights[start:start + size])
        cdf = acc / acc[-1]
        cdf[-1] = 1.0
        for i in range(count):
            if mode == MULTINOMIAL:
                u = uniforms[j]
            elif mode == STRATIFIED:
                u = (i + uniforms[j]) / count
            else:
                u = (i + uniforms[g]) / count
            out.append(start + min(int(np.searchsorted(cdf, u, side="right")), size - 1))
            j += 1
        start += size
    return np.array(out, dtype=np.int64)


@pytest.mark.parametrize("mode", [MULTINOMIAL, STRATIFIED, SYSTEMATIC])
def test_inverse_cdf_groups_is_a_search_of_each_groups_cdf(mode):
    # Sorted positions (stratified, systematic) are found by scanning on from the last
    # answer, unsorted ones by bisection: both must be numpy's search, with zero weights
    # (flat stretches of the cdf), uniforms at 0 and just below 1, and counts unlike the
    # sizes.
    rng = np.random.default_rng(11 + mode)
    for trial in range(200):
        sizes = rng.integers(1, 40, int(rng.integers(1, 5)))
        counts = sizes if trial % 2 else rng.integers(1, 60, sizes.size)
        weights = rng.random(sizes.sum()) ** int(rng.integers(1, 6))
        weights[rng.random(weights.size) < 0.4] = 0.0
        weights[np.cumsum(sizes) - sizes] = 1e-3  # every group has some weight
        n_u = sizes.size if mode == SYSTEMATIC else int(counts.sum())
        uniforms = rng.random(n_u)
        if trial % 7 == 0:
            uniforms[:] = np.nextafter(1.0, 0.0)
        elif trial % 7 == 1:
            uniforms[:] = 0.0
        got = inverse_cdf_groups(weights, sizes, counts, uniforms, mode)
        assert np.array_equal(got, _inverse_cdf_numpy(weights, sizes, counts, uniforms, mode))
    # Positions that go back (uniforms outside [0, 1)) are bisected afresh, not scanned.
    weights, sizes = np.ones(6), np.array([6])
    uniforms = np.array([5.0, -5.0, 0.5, 0.1, 0.9, 0.2])
    got = inverse_cdf_groups(weights, sizes, sizes, uniforms, mode)
    assert np.array_equal(got, _inverse_cdf_numpy(weights, sizes, sizes, uniforms, mode))


def test_a_naive_sum_would_fail_the_comparison():
    # The test above can fail: a left-to-right sum differs from numpy's in the last bit.
    x = _values(np.random.default_rng(0), 1000)
    naive = 0.0
    for v in x:
        naive += v
    assert naive != np.sum(x) and numpy_sum(x) == np.sum(x)


def test_a_half_of_exactly_128_terms_is_summed_as_one_block():
    # 256 terms split into halves of 128, and numpy sums each as one block of eight
    # accumulators; summed as two blocks of 64, a block of 128 differs in the last bit
    # about 3 times in 10. The zeros make the total the first half's sum itself (the
    # sizes above hit halves of 128 too, but their totals hid the difference).
    rng = np.random.default_rng(128)
    for _ in range(20):
        x = np.concatenate([rng.random(128), np.zeros(128)])
        assert numpy_sum(x) == np.sum(x)


def _set(rng, n=300, k=4):
    return (rng.normal(50, 10, (n, k, 3)), rng.normal(50, 10, (n, k, 3)),
            rng.integers(0, k, n).astype(np.int64))


@pytest.mark.parametrize("a1,a2", [(2.0, -1.0), (1.3, -0.45)])
def test_propagate_objects_is_ar2_propagate(a1, a2):
    rng = np.random.default_rng(1)
    x, prev, obj = _set(rng)
    mean = rng.normal(40, 5, (x.shape[1], 3))
    dyn = AR2(sigma=(2.0, 3.0, 0.01), a1=a1, a2=a2)
    rows = np.arange(x.shape[0])
    ref_x, ref_prev = x.copy(), prev.copy()
    cur = ref_x[rows, obj]
    want = dyn.propagate(cur, ref_prev[rows, obj], mean[obj], rng=np.random.default_rng(5))
    ref_prev[rows, obj] = cur
    ref_x[rows, obj] = want
    noise = np.random.default_rng(5).standard_normal((x.shape[0], 3))
    got = propagate_objects(x, prev, obj, noise, mean, dyn._sigma, a1, a2)
    assert np.array_equal(got, want)
    assert np.array_equal(x, ref_x) and np.array_equal(prev, ref_prev)


def test_state_boxes_are_boxes_from_states():
    rng = np.random.default_rng(2)
    states = np.column_stack([rng.normal(50, 20, (500, 2)), rng.normal(0, 0.3, 500)])
    sizes = rng.uniform(3, 40, (5, 2))
    obj = rng.integers(0, 5, 500).astype(np.int64)
    want = boxes_from_states(states, sizes[obj])
    assert np.array_equal(state_boxes(states, np.exp(states[:, 2]), sizes, obj), want)


@pytest.mark.parametrize("method", ["systematic", "multinomial", "stratified"])
@pytest.mark.parametrize("sizes", [[300], [43, 43, 43, 43, 43, 43, 42], [1, 5, 94]])
def test_weighted_resample_gather_is_weighted_resample_groups(method, sizes):
    rng = np.random.default_rng(3)
    sizes = np.array(sizes, dtype=np.int64)
    n = int(sizes.sum())
    x, prev, _ = _set(rng, n)
    ll = rng.normal(size=(n, 4))
    log_g = rng.normal(size=n)
    pi_g = np.exp(np.stack([rng.normal(size=n), rng.normal(0, 3, n)]))
    k, w = weighted_resample_groups(pi_g[0], pi_g[1], sizes, method=method,
                                    rng=np.random.default_rng(7))
    mode = RESAMPLE_MODES[method]
    uniforms = np.random.default_rng(7).random(sizes.size if mode == SYSTEMATIC else n)
    out = weighted_resample_gather(pi_g[0], pi_g[1], sizes, uniforms, mode, x, prev, ll,
                                   log_g)
    assert out is not None
    got_w, got_k, gx, gp, gll, gg = out
    assert np.array_equal(got_k, k) and np.array_equal(got_w, w)
    for a, b in ((gx, x[k]), (gp, prev[k]), (gll, ll[k]), (gg, log_g[k])):
        assert np.array_equal(a, b)
    # Fused with the next stage's AR2:
    obj = rng.integers(0, 4, n).astype(np.int64)
    noise = rng.standard_normal((n, 3))
    mean = np.zeros((4, 3))
    sig = np.array([2.0, 2.0, 0.001])
    fused = resample_propagate(pi_g[0], pi_g[1], sizes, uniforms, mode, x, prev, ll, log_g,
                               obj, noise, mean, sig, 2.0, -1.0)
    gx2, gp2 = x[k], prev[k]
    new = propagate_objects(gx2, gp2, obj, noise, mean, sig, 2.0, -1.0)
    assert np.array_equal(fused[0], w) and np.array_equal(fused[5], new)
    assert np.array_equal(fused[1], gx2) and np.array_equal(fused[2], gp2)


@pytest.mark.parametrize("fused", [False, True])
def test_the_placed_scope_gathers_only_the_placed_objects(fused):
    # resample_scope "placed": a row's placed objects (x, prev, ll) come from its
    # ancestor, the others stay the row's own; log_g always comes from the ancestor.
    rng = np.random.default_rng(5)
    sizes = np.array([40, 40, 20], dtype=np.int64)
    n = int(sizes.sum())
    x, prev, _ = _set(rng, n)
    ll = rng.normal(size=(n, 4))
    log_g = rng.normal(size=n)
    placed = rng.random((n, 4)) < 0.5
    pi_g = np.exp(np.stack([rng.normal(size=n), rng.normal(0, 3, n)]))
    uniforms = np.random.default_rng(7).random(sizes.size)
    k, w = weighted_resample_groups(pi_g[0], pi_g[1], sizes, method="systematic",
                                    rng=np.random.default_rng(7))
    want_x = np.where(placed[:, :, None], x[k], x)
    want_p = np.where(placed[:, :, None], prev[k], prev)
    if fused:
        obj = rng.integers(0, 4, n).astype(np.int64)
        noise = rng.standard_normal((n, 3))
        mean, sig = np.zeros((4, 3)), np.array([2.0, 2.0, 0.001])
        out = resample_propagate(pi_g[0], pi_g[1], sizes, uniforms, SYSTEMATIC, x, prev, ll,
                                 log_g, obj, noise, mean, sig, 2.0, -1.0, placed)
        new = propagate_objects(want_x, want_p, obj, noise, mean, sig, 2.0, -1.0)
        assert out is not None and np.array_equal(out[5], new)
        got_w, gx, gp, gll, gg = out[:5]
    else:
        out = weighted_resample_gather(pi_g[0], pi_g[1], sizes, uniforms, SYSTEMATIC, x, prev,
                                       ll, log_g, placed)
        assert out is not None
        got_w, got_k, gx, gp, gll, gg = out
        assert np.array_equal(got_k, k)
    assert np.array_equal(got_w, w)
    for a, b in ((gx, want_x), (gp, want_p), (gll, np.where(placed, ll[k], ll)),
                 (gg, log_g[k])):
        assert np.array_equal(a, b)
    assert not np.array_equal(gx, x[k])  # the scope changed something


def test_invalid_weights_leave_the_kernels_for_the_checked_path():
    a = np.array([1.0, np.nan, 1.0])
    out = weighted_resample_gather(a, np.ones(3), np.array([3]), np.array([0.5]), SYSTEMATIC,
                                   np.zeros((3, 1, 3)), np.zeros((3, 1, 3)), np.zeros((3, 1)),
                                   np.zeros(3))
    assert out is None
    assert not normalise_groups_checked(np.array([1.0, -1.0]), np.array([2]))[1]
    assert not normalise_groups_checked(np.array([1e308, 1e308]), np.array([2]))[1]
    assert not normalise_groups_checked(np.array([0.0, 1.0]), np.array([1, 1]))[1]
    with pytest.raises(ValueError, match="finite"), np.errstate(over="ignore"):
        resample(np.array([1e308, 1e308]), rng=np.random.default_rng(0))
    shifted, finite = stage_log_weights(np.zeros(2), np.zeros((2, 1)), np.zeros(2),
                                        np.array([0.0, np.nan]), np.zeros(2, dtype=np.int64),
                                        np.array([2]))
    assert not finite


def _both_kernels_leave(a, b, sizes, uniforms):
    """Whether weighted_resample_gather and resample_propagate both return None (hand the
    set to the checked numpy path) for π ``a`` and g ``b`` of N one-object particles."""
    n = a.shape[0]
    x, prev = np.zeros((n, 1, 3)), np.zeros((n, 1, 3))
    ll, log_g = np.zeros((n, 1)), np.zeros(n)
    gathered = weighted_resample_gather(a, b, sizes, uniforms, SYSTEMATIC, x, prev, ll,
                                        log_g)
    fused = resample_propagate(a, b, sizes, uniforms, SYSTEMATIC, x, prev, ll, log_g,
                               np.zeros(n, dtype=np.int64), np.zeros((n, 3)),
                               np.zeros((1, 3)), np.ones(3), 2.0, -1.0)
    return gathered is None and fused is None


@pytest.mark.parametrize("bad", ["pi", "g"])
@pytest.mark.parametrize("value", [-1.0, np.inf])
def test_one_invalid_factor_leaves_the_kernels_though_the_product_sums_positive(bad, value):
    # Either π or g alone is invalid (a negative or infinite entry) while the other is
    # valid and the group's π g still sums to a positive, finite-looking total: both
    # factors are checked, not just their product, and the checked numpy path raises.
    a, b = np.array([2.0, 1.0, 1.0]), np.array([1.0, 1.0, 1.0])
    if bad == "pi":
        a[1] = value
    else:
        b[1] = value
    sizes = np.array([3], dtype=np.int64)
    assert _both_kernels_leave(a, b, sizes, np.array([0.5]))
    with pytest.raises(ValueError), np.errstate(invalid="ignore"):
        weighted_resample_groups(a, b, sizes, rng=np.random.default_rng(0))


def test_a_single_particle_is_resampled_and_propagated():
    # N = 1 (one group of one particle): its own ancestor, weight 1, and the next stage's
    # AR2 states of that one particle.
    rng = np.random.default_rng(11)
    x, prev, _ = _set(rng, 1)
    x0, p0 = x.copy(), prev.copy()
    ll, log_g = rng.normal(size=(1, 4)), rng.normal(size=1)
    sizes, uniforms = np.array([1], dtype=np.int64), np.array([0.3])
    obj = np.array([2], dtype=np.int64)
    noise = rng.standard_normal((1, 3))
    mean, sig = np.zeros((4, 3)), np.array([2.0, 2.0, 0.001])
    out = resample_propagate(np.array([0.7]), np.array([1.3]), sizes, uniforms, SYSTEMATIC,
                             x, prev, ll, log_g, obj, noise, mean, sig, 2.0, -1.0)
    assert out is not None
    w, gx, gp, gll, gg, new = out
    assert np.array_equal(w, [1.0]) and np.array_equal(gll, ll) and np.array_equal(gg, log_g)
    # The inputs are left alone; the gathered copies are propagated (in place, as
    # propagate_objects does).
    assert np.array_equal(x, x0) and np.array_equal(prev, p0)
    want = propagate_objects(x0, p0, obj, noise, mean, sig, 2.0, -1.0)
    assert new.shape == (1, 3) and np.array_equal(new, want)
    assert np.array_equal(gx, x0) and np.array_equal(gp, p0)
    assert not np.array_equal(gx, x)  # the stage's object moved


def test_a_group_whose_weights_times_g_sum_to_zero_leaves_the_kernels():
    # π and g are each finite and non-negative, but no particle of group 1 has both
    # positive: π g sums to 0 there, nothing can be drawn, and the kernels must hand the
    # set to the checked numpy path (which raises) instead of returning weights.
    a, b = np.array([1.0, 2.0, 1.0, 0.0]), np.array([1.0, 1.0, 0.0, 3.0])
    sizes = np.array([2, 2], dtype=np.int64)
    assert _both_kernels_leave(a, b, sizes, np.array([0.5, 0.5]))
    with pytest.raises(ValueError, match="positive sum"):
        weighted_resample_groups(a, b, sizes, rng=np.random.default_rng(0))


def test_normalise_groups_checked_is_the_numpy_division():
    rng = np.random.default_rng(4)
    w = _values(rng, 300)
    sizes = np.array([100, 57, 143], dtype=np.int64)
    starts = np.cumsum(sizes) - sizes
    out, ok = normalise_groups_checked(w, sizes)
    assert ok and np.array_equal(out, w / np.repeat(np.add.reduceat(w, starts), sizes))


def _reassemble_numpy(logw, logpi, sizes):
    starts = np.cumsum(sizes) - sizes
    log_total = log_sum_exp_groups(logw, starts, sizes)
    log_evidence = log_total - log_sum_exp_groups(logpi, starts, sizes)
    mixture = normalised_weights(np.log(sizes / sizes.sum()) + log_evidence)
    logw_final = logw + np.repeat(np.log(mixture) - log_total, sizes)
    return normalised_weights(logw_final), mixture


@pytest.mark.parametrize("sizes", [[150, 150], [43, 43, 43, 43, 43, 43, 42], [1, 2, 297]])
def test_reassemble_is_the_numpy_mixture_reassembly(sizes):
    rng = np.random.default_rng(5)
    sizes = np.array(sizes, dtype=np.int64)
    n = int(sizes.sum())
    logpi = rng.normal(0, 2, n)
    logw = logpi + rng.normal(-30, 10, n)
    want_w, want_m = _reassemble_numpy(logw, logpi, sizes)
    got_w, got_m, got_log = reassemble(logw, logpi, sizes, np.log(sizes / sizes.sum()))
    assert np.array_equal(got_w, want_w) and np.array_equal(got_m, want_m)
    np.testing.assert_allclose(np.exp(got_log), want_m, rtol=1e-12)


@pytest.mark.parametrize("place", [0, 1, -1])
def test_group_shifts_take_each_groups_maximum_wherever_it_is(place):
    # The maximum of each group at its first, second or last place: a scan that skipped
    # a place left a largest weight above 1 there, and the reassembly's shifts (the same
    # kernel) off the maximum.
    rng = np.random.default_rng(9)
    sizes = np.array([1, 2, 3, 4, 150], dtype=np.int64)
    starts = np.cumsum(sizes) - sizes
    x = rng.normal(0, 5, int(sizes.sum()))
    for s, n in zip(starts, sizes, strict=True):
        x[s + place % n] = x[s : s + n].max() + 1.0
    top = np.repeat(np.maximum.reduceat(x, starts), sizes)
    got = group_weights(x, sizes)
    assert np.array_equal(got, np.exp(x - top))
    assert np.array_equal(np.maximum.reduceat(got, starts), np.ones(sizes.size))
    logpi = x + rng.normal(0, 1, x.size)
    want_w, want_m = _reassemble_numpy(x, logpi, sizes)
    got_w, got_m, _ = reassemble(x, logpi, sizes, np.log(sizes / sizes.sum()))
    assert np.array_equal(got_w, want_w) and np.array_equal(got_m, want_m)


def test_weighted_mean_and_diagnostics_are_the_numpy_ones():
    rng = np.random.default_rng(6)
    particles = rng.normal(100, 30, (300, 7, 3))
    particles = particles[rng.integers(0, 300, 300)]
    w = normalised_weights(rng.normal(0, 3, 300))
    mean, var = weighted_mean_states(w[:, None], particles)
    wk = np.repeat(w[:, None], 7, axis=1)
    assert np.array_equal(mean, (wk[:, :, None] * particles).sum(axis=0))
    assert np.array_equal(var, particles.var(axis=0))
    wk = normalised_weights(rng.normal(0, 3, (300, 7)), axis=0)  # one column per object
    mean, _ = weighted_mean_states(wk, particles)
    assert np.array_equal(mean, (wk[:, :, None] * particles).sum(axis=0))
    # σ below 1 px too: a kernel that took σ² <= 1 for σ = 0 left var / σ² out there.
    for sigma in ([2.0, 2.0, 0.001], [0.0, 3.0, 1.0], [0.5, 1.0, 0.5]):
        want = effective_dynamics(particles, sigma)[:, :2].mean(axis=1)
        assert np.array_equal(effective_uv(var, np.array(sigma)), want, equal_nan=True)
    x2, p2 = gather_pair(particles, particles * 2, np.array([3, 3, 0], dtype=np.int64))
    assert np.array_equal(x2, particles[[3, 3, 0]])
    assert np.array_equal(p2, (particles * 2)[[3, 3, 0]])


def test_row_max_shift_and_normalise_rows_are_the_numpy_ones():
    # The per-object weights of the bootstrap filter: each row minus its maximum, then
    # numpy's exp, then each row over its sum. The maximum sits in the first column, in
    # the second (a scan that began at column 2 missed it), in the last, inside, and alone
    # (N = 1); and N = 2.
    rng = np.random.default_rng(9)
    x = rng.normal(0, 50, (5, 40))
    x[0, 0], x[1, -1], x[2, 17], x[3, 1] = 900.0, 900.0, 900.0, 900.0
    for logw in (x, x[:, :1], x[:, :2]):
        want = logw - logw.max(axis=1, keepdims=True)
        assert np.array_equal(row_max_shift(logw), want)
        e = np.exp(want)
        got = normalise_rows(e)
        assert np.array_equal(got, e / e.sum(axis=1, keepdims=True))
        for row, w in zip(logw, got, strict=True):
            assert np.array_equal(w, normalised_weights(row))


def _distinct_brute(p):
    out = []
    for o in range(p.shape[1]):
        rows = []
        for r in p[:, o]:
            if not any(np.array_equal(r, q) for q in rows):  # NaN equals nothing
                rows.append(r)
        out.append(len(rows))
    return np.array(out)


def test_count_distinct_against_brute_force():
    rng = np.random.default_rng(7)
    for _ in range(100):
        n, k = rng.integers(1, 50), rng.integers(1, 4)
        p = rng.choice([0.0, -0.0, 1.0, 2.5, np.nan], size=(n, k, 3),
                       p=[0.3, 0.2, 0.2, 0.2, 0.1])
        assert np.array_equal(count_distinct(p), _distinct_brute(p))
    p = rng.normal(size=(300, 3, 3))[rng.integers(0, 300, 300)]
    assert np.array_equal(uniqueness(p) * 300, _distinct_brute(p))


def test_count_distinct_tells_values_apart_closer_than_any_shift_keeps():
    # Rows that differ by one unit in the last place, or by a subnormal: any arithmetic
    # on the values before comparing them (a shift, a scale) would merge some of them.
    tiny = np.nextafter(0.0, 1.0)
    one_up = np.nextafter(1.0, 2.0)
    p = np.zeros((6, 2, 3))
    p[:, 0, 0] = [0.0, tiny, 2 * tiny, -tiny, -0.0, 0.0]
    p[:, 1, 1] = [1.0, one_up, 1.0, 1e-300, 2e-300, one_up]
    assert count_distinct(p).tolist() == [4, 4] == _distinct_brute(p).tolist()


# --- the whole step against a pure-numpy reference -------------------------------------


def _scene(n_frames=6, seed=2):
    """Three two-colour 20x20 squares drifting on noise; frames (T, H, W, 3), boxes (3, 4)."""
    rng = np.random.default_rng(seed)
    start = np.array([[15.0, 15.0], [70.0, 20.0], [30.0, 50.0]])
    vel = rng.uniform(-1.5, 1.5, (3, 2))
    colours = [((220, 40, 40), (40, 60, 200)), ((30, 160, 60), (250, 220, 60)),
               ((200, 40, 200), (90, 230, 230))]
    frames = []
    for t in range(n_frames):
        f = rng.integers(0, 256, (80, 110, 3), dtype=np.uint8)
        for k, (x, y) in enumerate(np.round(start + t * vel).astype(int)):
            f[y:y + 10, x:x + 20] = colours[k][0]
            f[y + 10:y + 20, x:x + 20] = colours[k][1]
        frames.append(f)
    return np.stack(frames), np.column_stack([start, np.full((3, 2), 20.0)])


def _reference_step(tr, frame):
    """The partitioned-sampling step of ``tr`` (PS or DPS) in numpy, as before compiling."""
    obs = tr.model.observe(frame)
    n, m = tr.params.n_particles, tr.n_targets
    idx = resample(tr.weights, method=tr.params.resampler, rng=tr.rng)
    x, prev = tr.particles[idx], tr._prev[idx]
    sizes = tr._sizes_c
    orderings = tr._order if isinstance(tr, PartitionedSampling) else tr._orders
    if sizes.size > 1:
        order = (tr.rng.permutation(n) if tr.params.assignment == "random"
                 else tr._interleave)
        x, prev = x[order], prev[order]
    group = np.repeat(np.arange(sizes.size), sizes)
    rows = np.arange(n)
    logpi = np.zeros(n)
    ll = np.zeros((n, m))
    log_g = np.zeros(n)
    for j in range(m):
        obj = orderings[group, j]
        cur = x[rows, obj]
        new = tr.dynamics.propagate(cur, prev[rows, obj], tr._mean[obj], rng=tr.rng)
        prev[rows, obj] = cur
        x[rows, obj] = new
        stage = obs.log_likelihoods(boxes_from_states(new, tr._sizes[obj]), obj)
        ll[rows, obj] = stage
        if j < m - 1:
            log_g = stage.copy() if tr.params.weighting == "stage" else log_g + stage
            starts = np.cumsum(sizes) - sizes
            a = logpi - np.repeat(np.maximum.reduceat(logpi, starts), sizes)
            b = log_g - np.repeat(np.maximum.reduceat(log_g, starts), sizes)
            if tr.params.weighting == "g-only":  # ρ ∝ g: weighting function g / π
                b = (b - a) - np.repeat(np.maximum.reduceat(b - a, starts), sizes)
            k, w = weighted_resample_groups(np.exp(a), np.exp(b), sizes,
                                            method=tr.params.resampler, rng=tr.rng)
            x, prev, ll, log_g = x[k], prev[k], ll[k], log_g[k]
            logpi = np.log(w)
    logw = logpi + ll.sum(axis=1)
    if sizes.size == 1:
        weights = normalised_weights(logw)
    else:
        weights, _ = _reassemble_numpy(logw, logpi, sizes)
    tr.particles, tr._prev, tr.weights = x, prev, weights
    wk = np.repeat(weights[:, None], m, axis=1)
    mean_state = (wk[:, :, None] * x).sum(axis=0)
    return boxes_from_states(mean_state, tr._sizes)


@pytest.mark.parametrize("name,params", [
    ("dps", {}),
    ("dps", {"n_groups": 3, "assignment": "interleaved", "resampler": "stratified"}),
    ("dps", {"resampler": "residual"}),
    ("ps", {"ordering": 1, "resampler": "multinomial", "a1": 1.5, "a2": -0.6}),
    ("ps", {"weighting": "placed"}),
    ("dps", {"weighting": "placed", "resampler": "residual"}),
    ("ps", {"weighting": "g-only", "ordering": 2}),
    ("dps", {"weighting": "g-only", "n_groups": 2}),
])
def test_compiled_step_equals_the_numpy_reference_step(name, params):
    frames, boxes0 = _scene()
    cls = DistributedPartitionedSampling if name == "dps" else PartitionedSampling
    kw = dict(n_particles=97, rng=11, model="rgb", bins=6, **params)
    fast, ref = cls(**kw), cls(**kw)
    fast.init(frames[0], boxes0)
    ref.init(frames[0], boxes0)
    for f in frames[1:]:
        est = fast._step(f)
        want = _reference_step(ref, f)
        assert np.array_equal(est.boxes, want)
        assert np.array_equal(fast.particles, ref.particles)
        assert np.array_equal(fast._prev, ref._prev)
        assert np.array_equal(fast.weights, ref.weights)
    assert fast.rng.random() == ref.rng.random()  # the same draws, in the same order


def test_every_resampler_is_covered():
    assert set(RESAMPLE_MODES) | {"residual"} == set(RESAMPLERS)


def test_stage_weights_are_shifted_per_group():
    # Group 1's log-weights are all ~2000 below group 0's: with one shift for the whole
    # set its weights underflow to 0 and it cannot be resampled within itself.
    logpi = np.array([0.0, -1.0, -2000.0, -2001.0])
    log_g = np.array([-1.0, 0.0, -3000.0, -3002.0])
    shifted, finite = stage_log_weights(np.zeros(4), np.zeros((4, 1)), log_g.copy(), logpi,
                                        np.zeros(4, dtype=np.int64), np.array([2, 2]))
    assert finite
    assert np.array_equal(shifted, [[0.0, -1.0, 0.0, -1.0], [-1.0, 0.0, 0.0, -2.0]])


@pytest.mark.parametrize("weighting", ["stage", "g-only"])
def test_dps_with_a_very_peaked_likelihood_keeps_every_group(weighting):
    # λ = 1e5: the groups' likelihoods differ by far more than exp's range (before the
    # per-group shift the step raised "weights * g must have a positive sum").
    frames, boxes0 = _scene(12)
    tr = DistributedPartitionedSampling(n_particles=90, rng=1, model="rgb", bins=6,
                                        lam=1e5, weighting=weighting)
    tr.init(frames[0], boxes0)
    for f in frames[1:]:
        est = tr.step(f)
        assert np.isfinite(est.boxes).all()
    assert np.isfinite(tr.weights).all() and np.isclose(tr.weights.sum(), 1.0)
