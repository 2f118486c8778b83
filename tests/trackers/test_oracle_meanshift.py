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
