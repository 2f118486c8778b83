"""Oracle: the batched mean shift against a plain-numpy transcription of Comaniciu, Ramesh
& Meer (2003), "Kernel-based object tracking", eq. (25)-(26).

The reference below is written from the paper, not from ``trackers.kernels.meanshift``:

- p_u(y) = C sum_i k(||(x_i - y) / h||^2) delta[b(x_i) - u], the kernel-weighted histogram
  of the window centred at y (eq. 21); the window is the ellipse inscribed in the box,
  pixels whose centre lies in the box and strictly inside the ellipse, inside the frame;
- w_i = sum_u sqrt(q_u / p_u(y0)) delta[b(x_i) - u]                                 (25)
- y1 = sum_i x_i w_i g(||(y0 - x_i) / h||^2) / sum_i w_i g(||(y0 - x_i) / h||^2)   (26)
  with g = -k' the profile's derivative: for the Epanechnikov profile k(x) = 1 - x,
  g = 1 inside the window; for the KAMS cone 1 - sqrt(x) the derivative is singular at
  the centre and KAMS (eq. 6-7) uses a constant g too (documented by the kernel module);
- step 5: while rho(y1) < rho(y0), y1 <- (y0 + y1) / 2 (here at most 8 times, then y0 is
  kept), with rho = sum_u sqrt(p_u q_u) the Bhattacharyya coefficient.
"""

from __future__ import annotations

import numpy as np
import pytest

from trackers.kernels.histogram import (
    KERNEL_CONE,
    KERNEL_EPANECHNIKOV,
    quantize_rgb,
    region_histograms,
)
from trackers.kernels.meanshift import mean_shift

KERNELS = [KERNEL_EPANECHNIKOV, KERNEL_CONE]


def profile(kernel: int, r2: np.ndarray) -> np.ndarray:
    """Kernel weight k at squared normalised radius r2 (0 outside the unit ellipse)."""
    if kernel == KERNEL_EPANECHNIKOV:
        k = 1.0 - r2
    else:
        k = 1.0 - np.sqrt(r2)
    return np.where(r2 < 1.0, np.maximum(k, 0.0), 0.0)


def shadow(kernel: int, r2: np.ndarray) -> np.ndarray:
    """g = -k' of the Epanechnikov profile (1 inside); the cone's constant g (KAMS)."""
    return np.where(r2 < 1.0, 1.0, 0.0)


def window(bin_img, centre, size, kernel):
    """Pixel centres (P, 2), bins (P,), r^2 (P,) and kernel weights (P,) of a window."""
    rows, cols = bin_img.shape
    (cx, cy), (w, h) = centre, size
    yy, xx = np.mgrid[0:rows, 0:cols] + 0.5
    x0, y0 = cx - w / 2, cy - h / 2
    in_box = (xx >= x0) & (xx < x0 + w) & (yy >= y0) & (yy < y0 + h)
    r2 = ((xx - cx) / (w / 2)) ** 2 + ((yy - cy) / (h / 2)) ** 2
    k = profile(kernel, r2)
    keep = in_box & (k > 0)
    return (np.column_stack([xx[keep], yy[keep]]), bin_img[keep], r2[keep], k[keep])


def histogram(bins, k, n_bins):
    """p_u = sum k delta[b - u] / sum k (eq. 21)."""
    p = np.bincount(bins, weights=k, minlength=n_bins)
    return p / p.sum()


def rho(bin_img, q, centre, size, kernel):
    _, b, _, k = window(bin_img, centre, size, kernel)
    return float(np.sqrt(histogram(b, k, q.size) * q).sum())


def reference_first_iterate(bin_img, q, centre, size, kernel):
    """One iteration of Comaniciu et al.'s algorithm: eq. 25-26 and step 5.

    Returns the new centre and whether eq. 26's point was kept without halving.
    """
    x, b, r2, k = window(bin_img, centre, size, kernel)
    p0 = histogram(b, k, q.size)
    w = np.sqrt(q[b] / p0[b])                                       # eq. 25
    g = shadow(kernel, r2)
    y0 = np.asarray(centre, dtype=np.float64)
    y1 = (x * (w * g)[:, None]).sum(axis=0) / (w * g).sum()         # eq. 26
    rho0 = rho(bin_img, q, y0, size, kernel)
    rho1 = rho(bin_img, q, y1, size, kernel)
    plain = rho1 >= rho0
    halvings = 0
    while rho1 < rho0 and halvings < 8:                             # step 5
        y1 = 0.5 * (y0 + y1)
        rho1 = rho(bin_img, q, y1, size, kernel)
        halvings += 1
    return (y1 if rho1 >= rho0 else y0), plain


def random_case(seed, kernel, n_windows=12):
    """A random 4-level RGB image (64 bins), a model from a random region, windows."""
    rng = np.random.default_rng(seed)
    h, w = rng.integers(30, 60, 2)
    img = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    # A smoother part, so that some windows hold structure rather than pure noise.
    img[h // 4: h // 2, w // 4: w // 2] = rng.integers(0, 256, 3, dtype=np.uint8)
    bins = quantize_rgb(img, 4)
    box = np.array([[rng.uniform(0, w / 2), rng.uniform(0, h / 2), rng.uniform(8, w / 2),
                     rng.uniform(8, h / 2)]])
    q = region_histograms(bins, box, 64, kernel)[0]
    # Windows anywhere, some cut by the border (but never entirely outside).
    sizes = rng.uniform(5.0, 25.0, (n_windows, 2))
    centres = np.column_stack([rng.uniform(0.0, w, n_windows), rng.uniform(0.0, h, n_windows)])
    return bins, q, centres, sizes


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("seed", range(4))
def test_first_iterate_equals_the_papers_equations(kernel, seed):
    bins, q, centres, sizes = random_case(seed, kernel)
    res = mean_shift(bins, q[None], np.zeros(len(centres), dtype=np.int64), centres, sizes,
                     kernel=kernel, max_iter=1, eps=0.0)
    plain = 0
    for p in range(len(centres)):
        expected, kept = reference_first_iterate(bins, q, centres[p], sizes[p], kernel)
        np.testing.assert_allclose(res.centres[p], expected, rtol=0, atol=1e-9)
        d = np.sqrt(max(1.0 - rho(bins, q, expected, sizes[p], kernel), 0.0))
        np.testing.assert_allclose(res.distances[p], d, rtol=0, atol=1e-9)
        plain += kept
    # Most windows keep eq. 26's point as is: the test is about eq. 25-26, not step 5.
    assert plain >= len(centres) // 3


@pytest.mark.parametrize("kernel", KERNELS)
def test_first_iterate_on_a_structured_scene_is_eq_26_exactly(kernel):
    # A two-tone disc: weights sqrt(q/p) differ strongly between the bins, so a wrong
    # exponent (q/p, or (q/p)^(1/4)) or an unweighted mean moves the point visibly.
    rows, cols = 60, 70
    yy, xx = np.mgrid[0:rows, 0:cols] + 0.5
    inside = (xx - 35.0) ** 2 + (yy - 30.0) ** 2 < 12.0 ** 2
    bins = np.where(inside, np.where(xx < 35.0, 2, 1), 0).astype(np.int32)
    bins[(xx - 35.0) ** 2 + (yy - 30.0) ** 2 < 4.0 ** 2] = 3
    q = region_histograms(bins, np.array([[23.0, 18.0, 24.0, 24.0]]), 4, kernel)[0]
    starts = np.array([[29.0, 26.0], [41.5, 33.2], [35.0, 40.0], [27.3, 30.0]])
    size = np.array([24.0, 24.0])
    res = mean_shift(bins, q[None], np.zeros(4, dtype=np.int64), starts,
                     np.tile(size, (4, 1)), kernel=kernel, max_iter=1, eps=0.0)
    for p, start in enumerate(starts):
        expected, kept = reference_first_iterate(bins, q, start, size, kernel)
        assert kept
        np.testing.assert_allclose(res.centres[p], expected, rtol=0, atol=1e-9)
        assert np.hypot(*(expected - start)) > 0.5  # a real step


def shift_at(bins, q, centre, size, kernel):
    """Eq. 26's displacement y1 - y0 from ``centre`` (the mean-shift vector)."""
    x, b, r2, k = window(bins, centre, size, kernel)
    p0 = histogram(b, k, q.size)
    wg = np.sqrt(q[b] / p0[b]) * shadow(kernel, r2)
    return (x * wg[:, None]).sum(axis=0) / wg.sum() - centre


@pytest.mark.parametrize("kernel", KERNELS)
def test_fixed_point_satisfies_the_mean_shift_condition(kernel):
    # A blob of graded colour rings: a smooth similarity surface with one maximum.
    rows, cols = 70, 80
    yy, xx = np.mgrid[0:rows, 0:cols] + 0.5
    r = np.hypot(xx - 41.3, yy - 33.8)
    bins = np.clip((r / 3.0).astype(np.int32), 0, 9)
    q = region_histograms(bins, np.array([[27.3, 19.8, 28.0, 28.0]]), 10, kernel)[0]
    rng = np.random.default_rng(11)
    starts = np.array([41.3, 33.8]) + rng.uniform(-7.0, 7.0, (6, 2))
    sizes = np.tile([28.0, 28.0], (6, 1))
    index = np.zeros(6, dtype=np.int64)
    res = mean_shift(bins, q[None], index, starts, sizes, kernel=kernel, max_iter=500,
                     eps=1e-4)
    assert np.all(res.n_iter < 500)
    for p in range(6):
        # y* = m(y*): the mean-shift vector of eq. 26 at the fixed point is a small
        # fraction of a pixel (measured: at most 0.0043 px on this scene); the window
        # histogram is piecewise constant in y, so it is not exactly zero.
        m = shift_at(bins, q, res.centres[p], sizes[p], kernel)
        assert np.hypot(*m) < 0.01
        assert np.hypot(*(res.centres[p] - (41.3, 33.8))) < 1.5
    # A fixed point of the whole iteration (eq. 26 and step 5): it does not move again.
    again = mean_shift(bins, q[None], index, res.centres, sizes, kernel=kernel, max_iter=500,
                       eps=1e-4)
    assert np.abs(again.centres - res.centres).max() < 0.01
    assert np.all(again.distances <= res.distances)


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("radius", [8.0, 14.0])
def test_converges_to_the_disc_centre_from_offsets_up_to_the_radius(kernel, radius):
    rows, cols = 80, 90
    cx, cy = 44.6, 39.2
    yy, xx = np.mgrid[0:rows, 0:cols] + 0.5
    dx, dy = xx - cx, yy - cy
    inside = dx * dx + dy * dy < radius * radius
    sector = ((np.arctan2(dy, dx) + np.pi) / (2 * np.pi) * 4).astype(int) % 4
    bins = np.where(inside, 1 + sector, 0).astype(np.int32)
    box = np.array([[cx - radius, cy - radius, 2 * radius, 2 * radius]])
    q = region_histograms(bins, box, 5, kernel)[0]
    angles = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
    offsets = np.array([0.25, 0.5, 0.75, 1.0]) * radius
    starts = np.array([[cx + o * np.cos(a), cy + o * np.sin(a)] for o in offsets
                       for a in angles])
    n = len(starts)
    res = mean_shift(bins, q[None], np.zeros(n, dtype=np.int64), starts,
                     np.tile(box[0, 2:], (n, 1)), kernel=kernel, max_iter=200, eps=0.01)
    err = np.hypot(res.centres[:, 0] - cx, res.centres[:, 1] - cy)
    assert err.max() < 0.5, err.max()
    assert res.distances.max() < 0.05


# Round 16: every mutant of the kernels (not a sample). The cases below are the exact
# boundaries the full run found unguarded; each is computed, not a tolerance.


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_window_without_the_models_colours_stays_put(kernel):
    # Every pixel is bin 0 and the model has no mass there: rho = 0, distance exactly 1,
    # and eq. 25's weights are all 0, so eq. 26 has no point to move to. The iteration
    # stops after its one attempt even with eps = 0 (which never stops on a step).
    bins = np.zeros((30, 40), dtype=np.int32)
    q = np.array([[0.0, 1.0]])
    start = np.array([[20.0, 15.0], [7.3, 22.6]])
    sizes = np.array([[10.0, 8.0], [12.0, 12.0]])
    res = mean_shift(bins, q, np.zeros(2, dtype=np.int64), start, sizes, kernel=kernel,
                     max_iter=5, eps=0.0)
    np.testing.assert_array_equal(res.centres, start)
    np.testing.assert_array_equal(res.distances, [1.0, 1.0])
    np.testing.assert_array_equal(res.n_iter, [1, 1])
    # A distance equal to min_distance is already good enough: no shift is attempted.
    res = mean_shift(bins, q, np.zeros(2, dtype=np.int64), start, sizes, kernel=kernel,
                     max_iter=5, eps=0.0, min_distance=1.0)
    np.testing.assert_array_equal(res.n_iter, [0, 0])


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_window_that_is_its_model_has_distance_zero_and_does_not_move(kernel):
    # One colour under the window and a model of that colour alone: p = total * (1 /
    # total) is exactly 1 for these windows (it can be 1 - 2^-53 for others, whose
    # distance is then 1e-8), so rho is 1, the distance exactly 0 and, with min_distance
    # 0, no shift is attempted.
    bins = np.ones((30, 40), dtype=np.int32)
    q = np.array([[0.0, 1.0]])
    start = np.array([[20.0, 15.0], [13.7, 11.2], [25.5, 14.5]])
    sizes = np.array([[10.0, 8.0], [9.3, 13.1], [6.0, 6.0]])
    res = mean_shift(bins, q, np.zeros(3, dtype=np.int64), start, sizes, kernel=kernel,
                     max_iter=5, eps=0.0)
    np.testing.assert_array_equal(res.distances, [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(res.n_iter, [0, 0, 0])
    np.testing.assert_array_equal(res.centres, start)


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("shared", [False, True])
@pytest.mark.parametrize("height", [7.0, 8.0])
def test_first_iterate_with_a_pixel_on_the_ellipse(kernel, shared, height):
    # A window of even width centred on a pixel centre: the pixel at the left end of its
    # middle row has r^2 = 1 exactly (dx = -1, dy = 0), so its weight is 0 and it is not
    # in the window. Its colour is either its own (a bin with no weight in the window) or
    # one that the window holds elsewhere; either way eq. 26 must leave it out. With an
    # even height the box's top row lies on the ellipse's top (dy = -1): no pixel of that
    # row is in the window, and the rows below it are.
    rng = np.random.default_rng(3)
    bins = rng.integers(0, 3, (30, 40)).astype(np.int32)
    centre, size = np.array([20.5, 15.5]), np.array([8.0, height])
    left = (15, 16)  # row 15 (centre 15.5), column 16 (centre 16.5 = 20.5 - 4)
    x, b, r2, k = window(bins, centre, size, kernel)
    assert not np.any(np.all(x == (16.5, 15.5), axis=1))
    bins[left] = 2 if shared else 3
    assert (bins[left] in window(bins, centre, size, kernel)[1]) == shared
    q = np.array([0.2, 0.3, 0.5, 0.0])
    res = mean_shift(bins, q[None], np.zeros(1, dtype=np.int64), centre[None], size[None],
                     kernel=kernel, max_iter=1, eps=0.0)
    expected, _ = reference_first_iterate(bins, q, centre, size, kernel)
    np.testing.assert_allclose(res.centres[0], expected, rtol=0, atol=1e-12)
    assert np.hypot(*(expected - centre)) > 0.01  # a real step


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_step_of_exactly_eps_does_not_stop_the_iteration(kernel):
    # "Stop when a shift moves the centre by less than eps": a first step whose length is
    # exactly eps (those whose squared length is the square of its square root) goes on
    # to a second shift; one ulp more of eps stops after the first.
    bins, q, centres, sizes = random_case(0, kernel)
    index = np.zeros(len(centres), dtype=np.int64)
    first = mean_shift(bins, q[None], index, centres, sizes, kernel=kernel, max_iter=1,
                       eps=0.0)
    checked = 0
    for p in range(len(centres)):
        (x0, y0), (x1, y1) = centres[p], first.centres[p]
        step2 = (x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0)
        eps = float(np.sqrt(step2))
        if step2 == 0.0 or eps * eps != step2:
            continue
        one = (bins, q[None], index[p:p + 1], centres[p:p + 1], sizes[p:p + 1])
        at = mean_shift(*one, kernel=kernel, max_iter=2, eps=eps)
        above = mean_shift(*one, kernel=kernel, max_iter=2, eps=float(np.nextafter(eps, 1e9)))
        assert (at.n_iter[0], above.n_iter[0]) == (2, 1)
        checked += 1
    assert checked >= 3


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_step_that_keeps_the_similarity_is_taken(kernel):
    # A window inside one colour and a model of two: rho is sqrt(1/2) wherever the window
    # goes, so eq. 26's step (to the centroid of the window's pixels) neither gains nor
    # loses; step 5 only rejects a step that lowers rho, so this one is taken.
    bins = np.zeros((40, 50), dtype=np.int32)
    q = np.array([0.5, 0.5])
    rng = np.random.default_rng(0)
    starts = np.column_stack([rng.uniform(15, 35, 12), rng.uniform(12, 28, 12)])
    sizes = rng.uniform(6, 14, (12, 2))
    checked = 0
    for p in range(12):
        # The window's total weight changes with the step, so rho may move by an ulp
        # either way: the windows where the kernel's own step leaves it exactly unchanged
        # are the boundary case.
        step2, d0, dists = kernel_first_step(bins, q, starts[p], sizes[p], kernel)
        if dists[0] != d0:
            continue
        res = mean_shift(bins, q[None], np.zeros(1, dtype=np.int64), starts[p:p + 1],
                         sizes[p:p + 1], kernel=kernel, max_iter=1, eps=0.0)
        expected, kept = reference_first_iterate(bins, q, starts[p], sizes[p], kernel)
        np.testing.assert_allclose(res.centres[0], expected, rtol=0, atol=1e-12)
        assert np.hypot(*(expected - starts[p])) > 1e-3
        checked += 1
    assert checked >= 3


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_window_outside_the_frame_attempts_no_shift(kernel):
    # Nothing under the window: the distance is the uniform histogram's, sqrt(1 - sqrt(1/B))
    # against a one-bin model, and there is no weight to shift by.
    bins = np.zeros((20, 20), dtype=np.int32)
    q = np.zeros((1, 4))
    q[0, 1] = 1.0
    start = np.array([[-30.0, 10.0], [10.0, 45.0]])
    res = mean_shift(bins, q, np.zeros(2, dtype=np.int64), start, np.full((2, 2), 8.0),
                     kernel=kernel, max_iter=5, eps=0.0)
    np.testing.assert_array_equal(res.n_iter, [0, 0])
    np.testing.assert_array_equal(res.centres, start)
    np.testing.assert_allclose(res.distances, np.sqrt(1.0 - np.sqrt(0.25)), rtol=0, atol=1e-15)


def kernel_first_step(bins, q, centre, size, kernel, cap=12):
    """The kernel's own eq. 26 step from ``centre`` (its squared length, bit for bit, from
    the compiled ``_window``/``_shift``), the start's distance, and the distance after
    0, 1, ..., ``cap`` halvings of the step; None if there is no step."""
    from trackers.kernels import meanshift as ms

    n_bins = q.size
    hist, totals = np.zeros(n_bins), np.empty(1)
    touched, weight = np.empty(n_bins, dtype=np.int64), np.empty(n_bins)
    kbuf = np.empty(bins.shape[1])
    (x0, y0), (w, h) = (float(v) for v in centre), (float(v) for v in size)
    n = ms._window(bins, x0, y0, w, h, kernel, hist, totals, touched, kbuf)
    d0 = ms._distance(q, hist, totals, touched, n, n_bins)
    if totals[0] <= 0.0:
        return None
    x1, y1, sw = ms._shift(bins, x0, y0, w, h, q, hist, totals[0], touched, n, weight)
    ms._clear(hist, touched, n)
    if sw <= 0.0:
        return None
    step2 = (x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0)
    dists = []
    for _ in range(cap + 1):
        n = ms._window(bins, x1, y1, w, h, kernel, hist, totals, touched, kbuf)
        dists.append(ms._distance(q, hist, totals, touched, n, n_bins))
        ms._clear(hist, touched, n)
        x1, y1 = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    return step2, d0, dists


def halved_steps(kernel, seeds):
    """(case, window, step2, halvings needed) of random cases whose step step 5 halves."""
    for seed in seeds:
        bins, q, centres, sizes = random_case(seed, kernel)
        bins = bins.astype(np.int32)
        for p in range(len(centres)):
            t = kernel_first_step(bins, q, centres[p], sizes[p], kernel)
            if t is None:
                continue
            step2, d0, dists = t
            need = next((k for k, d in enumerate(dists) if not d > d0), None)
            if need:
                yield (bins, q, centres[p:p + 1], sizes[p:p + 1]), step2, need


@pytest.mark.parametrize("kernel", KERNELS)
def test_step_5_halves_while_the_step_is_at_least_eps(kernel):
    # Step 5 halves a step that lowers rho while the step is at least eps. With eps equal
    # to the length of the last halving's step, that halving happens and the point moves;
    # with eps one ulp longer it does not, and the start is kept.
    checked = 0
    for case, step2, need in halved_steps(kernel, range(40)):
        length = float(np.sqrt(step2))
        if length * length != step2:
            continue
        eps = length / 2 ** (need - 1)   # exactly the step before the last halving
        longer = float(np.nextafter(eps, np.inf))
        if longer * longer <= eps * eps:
            continue
        bins, q, start, size = case
        index = np.zeros(1, dtype=np.int64)
        at = mean_shift(bins, q[None], index, start, size, kernel=kernel, max_iter=1, eps=eps)
        above = mean_shift(bins, q[None], index, start, size, kernel=kernel, max_iter=1,
                           eps=longer)
        assert np.any(at.centres != start)
        np.testing.assert_array_equal(above.centres, start)
        checked += 1
    assert checked >= 3


@pytest.mark.parametrize("kernel", KERNELS)
def test_the_stopping_test_uses_the_halved_step(kernel):
    # A step halved once, to a point that keeps rho, then shorter than eps: the iteration
    # stops there (a stopping test on the unhalved step would go on).
    checked = 0
    for case, step2, need in halved_steps(kernel, range(40)):
        if need != 1:
            continue
        bins, q, start, size = case
        eps = 0.75 * float(np.sqrt(step2))
        res = mean_shift(bins, q[None], np.zeros(1, dtype=np.int64), start, size,
                         kernel=kernel, max_iter=3, eps=eps)
        assert res.n_iter[0] == 1
        checked += 1
    assert checked >= 3


# Windows whose eq. 26 step needs exactly 8 or 9 halvings before rho stops dropping. Rare:
# of the 59,520 windows of the random cases of seeds 40-4999 with the Epanechnikov kernel,
# 6 need 8 and 7 need 9 (found with ``kernel_first_step``); the first three and the first
# two are here.
CAPPED = [(1355, 5, 8), (1688, 8, 8), (1867, 11, 8), (984, 1, 9), (1785, 2, 9)]


@pytest.mark.parametrize(("seed", "window_index", "need"), CAPPED)
def test_step_5_halves_at_most_eight_times(seed, window_index, need):
    kernel = KERNEL_EPANECHNIKOV
    bins, q, centres, sizes = random_case(seed, kernel)
    bins = bins.astype(np.int32)
    start, size = centres[window_index], sizes[window_index]
    step2, d0, dists = kernel_first_step(bins, q, start, size, kernel)
    assert next(k for k, d in enumerate(dists) if not d > d0) == need
    res = mean_shift(bins, q[None], np.zeros(1, dtype=np.int64), start[None], size[None],
                     kernel=kernel, max_iter=1, eps=0.0)
    if need == 8:   # the eighth halving is allowed: the point 1/256 of the way is taken
        expected, kept = reference_first_iterate(bins, q, start, size, kernel)
        assert not kept and np.any(expected != start)
        np.testing.assert_allclose(res.centres[0], expected, rtol=0, atol=1e-9)
    else:           # a ninth is not: the start is kept
        np.testing.assert_array_equal(res.centres[0], start)


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_one_pixel_window_moves_onto_its_pixel(kernel):
    # A 1.2 x 1 window holds one pixel, off its centre: the total kernel weight is below 1
    # and so is the sum of eq. 25's weights (sqrt(0.01) = 0.1); eq. 26's point is the
    # pixel's centre, and rho stays sqrt(0.01) there, so the step is taken.
    bins = np.zeros((12, 20), dtype=np.int32)
    q = np.array([[0.01, 0.99]])
    starts = np.array([[10.2, 5.5], [10.3, 5.5], [10.7, 5.5], [10.8, 5.5], [10.3, 5.3]])
    res = mean_shift(bins, q, np.zeros(5, dtype=np.int64), starts, np.tile([1.2, 1.0], (5, 1)),
                     kernel=kernel, max_iter=1, eps=0.0)
    np.testing.assert_array_equal(res.centres, np.tile([10.5, 5.5], (5, 1)))
    np.testing.assert_array_equal(res.n_iter, np.ones(5))


@pytest.mark.parametrize("kernel", KERNELS)
def test_first_iterate_of_windows_wider_than_the_frame(kernel):
    # The chord of the middle rows spans every column of the frame (the scratch row buffer
    # must hold them all).
    rng = np.random.default_rng(8)
    bins = rng.integers(0, 4, (12, 20)).astype(np.int32)
    bins[:, 12:] = 3
    q = np.array([0.1, 0.1, 0.1, 0.7])
    for centre, size in (((10.0, 6.0), (30.0, 9.0)), ((8.3, 5.1), (26.0, 14.0))):
        centre, size = np.array(centre), np.array(size)
        res = mean_shift(bins, q[None], np.zeros(1, dtype=np.int64), centre[None], size[None],
                         kernel=kernel, max_iter=1, eps=0.0)
        expected, _ = reference_first_iterate(bins, q, centre, size, kernel)
        np.testing.assert_allclose(res.centres[0], expected, rtol=0, atol=1e-9)
        assert np.hypot(*(expected - centre)) > 0.1
