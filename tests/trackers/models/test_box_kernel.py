"""The nested-rectangle ("box") kernel: exact against a per-pixel numpy transcription, the
integral path bit-identical to the direct one, and thread counts that change nothing."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import trackers
from trackers.kernels.histogram import (
    KERNEL_BOX,
    KERNEL_EPANECHNIKOV,
    KERNEL_UNIFORM,
    box_kernel_levels,
    prepare_references,
    prepared_distances,
    region_distances,
    region_histograms,
)
from trackers.kernels.profiles import _box_row_weights, _level_args, _level_rects, _pixel_range


def _pixels(lo: float, size: float, n: int) -> np.ndarray:
    """Pixel indices whose centres lie in [lo, lo + size), inside [0, n)."""
    centres = np.arange(n) + 0.5
    return np.flatnonzero((centres >= lo) & (centres < lo + size))


def _numpy_box_histogram(bin_img, box, n_bins, levels, n_parts):
    """Per-pixel transcription of the box kernel (module docstring of the kernel)."""
    rows, cols = bin_img.shape
    x, y, w, h = box
    fractions, weights = box_kernel_levels(levels)
    weight = np.zeros((rows, cols))
    for f, a in zip(fractions, weights, strict=True):
        rr = _pixels(y + 0.5 * h * (1 - f), h * f, rows)
        cc = _pixels(x + 0.5 * w * (1 - f), w * f, cols)
        weight[np.ix_(rr, cc)] += a
    band = h / n_parts
    part = np.minimum(((np.arange(rows) + 0.5 - y) / band).astype(int), n_parts - 1)
    out = np.empty(n_parts * n_bins)
    for j in range(n_parts):
        wj = weight * (part == j)[:, None]
        hist = np.bincount(bin_img.ravel(), weights=wj.ravel(), minlength=n_bins)
        total = hist.sum()
        out[j * n_bins:(j + 1) * n_bins] = (
            hist / (total * n_parts) if total > 0 else 1.0 / (n_bins * n_parts)
        )
    return out


def _scene(seed: int, height: int, width: int, n_bins: int, n_boxes: int):
    rng = np.random.default_rng(seed)
    coarse = rng.integers(0, n_bins, size=(height // 4 + 1, width // 4 + 1))
    bin_img = np.kron(coarse, np.ones((4, 4), dtype=np.int64))[:height, :width]
    boxes = np.column_stack([
        rng.uniform(-15, width, n_boxes), rng.uniform(-15, height, n_boxes),
        rng.uniform(0.6, 50, n_boxes), rng.uniform(0.6, 50, n_boxes),
    ])  # fmt: skip
    return np.ascontiguousarray(bin_img, dtype=np.int32), boxes, rng


def test_level_weights_follow_the_epanechnikov_profile_at_mid_radius():
    fractions, weights = box_kernel_levels(4)
    np.testing.assert_allclose(fractions, [0.25, 0.5, 0.75, 1.0])
    shell = np.cumsum(weights[::-1])[::-1]  # weight of a pixel in shell l
    np.testing.assert_allclose(shell, 1 - ((np.arange(1, 5) - 0.5) / 4) ** 2, rtol=0, atol=1e-15)
    assert np.all(weights > 0)


@pytest.mark.parametrize("levels", [1, 16])
def test_the_extreme_level_counts_are_accepted(levels):
    fractions, weights = box_kernel_levels(levels)
    np.testing.assert_array_equal(fractions, np.arange(1, levels + 1) / levels)
    shell = np.cumsum(weights[::-1])[::-1]
    np.testing.assert_allclose(shell, 1 - ((np.arange(1, levels + 1) - 0.5) / levels) ** 2,
                               rtol=0, atol=1e-15)


def _level_rectangles(box, levels, rows, cols):
    fracs, a_fixed = _level_args(KERNEL_BOX, levels)
    rects = np.empty((levels, 4), dtype=np.int64)
    _level_rects(*map(float, box), fracs, rows, cols, rects)
    return rects, a_fixed


@given(x=st.floats(-20, 70), y=st.floats(-20, 50), w=st.floats(0.6, 60),
       h=st.floats(0.6, 60), levels=st.integers(1, 16))
def test_the_outermost_rectangle_is_the_box_and_the_rectangles_nest(x, y, w, h, levels):
    # The histogram paths visit the rows and columns _pixel_range gives the box and take a
    # row's weights from _box_row_weights: every row they visit is covered by the
    # outermost rectangle, and the inner ones lie inside the outer ones.
    rects, _ = _level_rectangles((x, y, w, h), levels, 41, 63)
    assert tuple(rects[-1]) == _pixel_range(y, h, 41) + _pixel_range(x, w, 63)
    inner, outer = rects[:-1], rects[1:]
    assert np.all((outer[:, 0] <= inner[:, 0]) & (inner[:, 1] <= outer[:, 1]))
    assert np.all((outer[:, 2] <= inner[:, 2]) & (inner[:, 3] <= outer[:, 3]))


@pytest.mark.parametrize("levels", [1, 3, 16])
def test_a_rows_weights_sum_the_levels_covering_each_pixel(levels):
    # Every column of the row is written (the buffer starts as garbage): the sum of a_l
    # over the rectangles holding the pixel, and 0 on rows no rectangle covers (just above
    # and below the box).
    rects, a_fixed = _level_rectangles((7.3, 5.8, 31.4, 22.7), levels, 48, 64)
    r0, r1, c0, c1 = rects[-1]
    n = c1 - c0
    cols = np.arange(c0, c1)
    for r in range(r0 - 2, r1 + 2):
        kbuf = np.full(n, -7, dtype=np.int64)
        _box_row_weights(kbuf, n, c0, r, rects, a_fixed)
        inside = ((rects[:, 0] <= r) & (r < rects[:, 1]))[:, None] & (
            (rects[:, 2:3] <= cols) & (cols < rects[:, 3:4]))
        np.testing.assert_array_equal(kbuf, (inside * a_fixed[:, None]).sum(axis=0))
        if not r0 <= r < r1:
            assert not kbuf.any()


@pytest.mark.parametrize("bad", [0, 17, 2.5, True, -1])
def test_bad_level_counts_are_refused(bad):
    with pytest.raises(ValueError, match="box_levels"):
        box_kernel_levels(bad)


@given(seed=st.integers(0, 2**32 - 1), levels=st.integers(1, 6), n_parts=st.integers(1, 3))
def test_histograms_equal_the_per_pixel_transcription(seed, levels, n_parts):
    bin_img, boxes, _ = _scene(seed, 37, 53, 7, 12)
    hists = region_histograms(bin_img, boxes, 7, KERNEL_BOX, n_parts, box_levels=levels)
    expected = np.array([_numpy_box_histogram(bin_img, b, 7, levels, n_parts) for b in boxes])
    # Level weights are held in 32.32 fixed point: exact to ~2**-32 of a band's weight.
    np.testing.assert_allclose(hists, expected, rtol=0, atol=1e-9)


@given(seed=st.integers(0, 2**32 - 1), levels=st.integers(1, 6), n_parts=st.integers(1, 3))
def test_integral_path_is_bit_identical_to_the_direct_path(seed, levels, n_parts):
    bin_img, boxes, rng = _scene(seed, 61, 83, 9, 120)
    refs = region_histograms(bin_img, boxes[:4], 9, KERNEL_BOX, n_parts, box_levels=levels)
    index = rng.integers(0, 4, len(boxes))
    direct = region_distances(bin_img, boxes, refs, index, KERNEL_BOX, n_parts,
                              method="direct", box_levels=levels)
    integral = region_distances(bin_img, boxes, refs, index, KERNEL_BOX, n_parts,
                                method="integral", box_levels=levels)
    np.testing.assert_array_equal(direct, integral)
    hist = region_histograms(bin_img, boxes, 9, KERNEL_BOX, n_parts, box_levels=levels)
    rho = np.sqrt(hist * refs[index]).sum(axis=1)
    np.testing.assert_allclose(1 - direct**2, np.minimum(rho, 1.0), rtol=0, atol=1e-12)


@pytest.mark.parametrize("kernel", [KERNEL_UNIFORM, KERNEL_BOX])
@pytest.mark.parametrize("spread", [30.0, 300.0])
def test_integral_is_exact_for_16_and_32_bit_counts_and_colours_shared_by_bands(kernel,
                                                                              spread):
    # Clouds of boxes whose union is below (16-bit integral) or above (32-bit) 2**16
    # pixels; five colours, so that both bands' supports hold the same colours (one channel
    # per colour, read by both bands).
    rng = np.random.default_rng(7)
    bin_img = np.ascontiguousarray(rng.integers(0, 5, size=(290, 310)), dtype=np.int32)
    centre = np.array([150.0, 140.0])
    xy = centre + rng.uniform(-spread / 2, spread / 2, (200, 2))
    wh = rng.uniform(8, 60, (200, 2))
    boxes = np.column_stack([xy - wh / 2, wh])
    refs = region_histograms(bin_img, boxes[:3], 5, kernel, 2)
    index = rng.integers(0, 3, len(boxes))
    direct = region_distances(bin_img, boxes, refs, index, kernel, 2, method="direct")
    integral = region_distances(bin_img, boxes, refs, index, kernel, 2, method="integral")
    np.testing.assert_array_equal(direct, integral)
    np.testing.assert_array_equal(
        direct, region_distances(bin_img, boxes, refs, index, kernel, 2, method="auto"))


def test_one_level_is_the_uniform_kernel():
    bin_img, boxes, _ = _scene(3, 40, 60, 5, 30)
    np.testing.assert_allclose(
        region_histograms(bin_img, boxes, 5, KERNEL_BOX, 2, box_levels=1),
        region_histograms(bin_img, boxes, 5, KERNEL_UNIFORM, 2), rtol=0, atol=1e-15,
    )  # fmt: skip


def test_more_levels_weight_the_centre_more():
    # A box whose centre is colour 1 and whose rim is colour 0.
    bin_img = np.zeros((40, 40), dtype=np.int32)
    bin_img[15:25, 15:25] = 1
    box = np.array([[10.0, 10.0, 20.0, 20.0]])
    centre = [region_histograms(bin_img, box, 2, KERNEL_BOX, box_levels=n)[0, 1]
              for n in (1, 2, 4, 8)]
    assert centre[0] == pytest.approx(0.25)
    assert np.all(np.diff(centre) > 0)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs two threads")
@pytest.mark.parametrize("kernel", [KERNEL_EPANECHNIKOV, KERNEL_BOX, KERNEL_UNIFORM])
def test_results_do_not_depend_on_the_thread_count(kernel):
    bin_img, boxes, rng = _scene(11, 120, 160, 30, 700)
    refs = region_histograms(bin_img, boxes[:7], 30, kernel, 2)
    prepared = prepare_references(refs, 2)
    index = rng.integers(0, 7, len(boxes))
    before = numba.get_num_threads()
    try:
        out = []
        for threads in (1, 2):
            numba.set_num_threads(threads)
            out.append(prepared_distances(bin_img, boxes, prepared, index, kernel))
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(out[0], out[1])


def test_particle_filters_accept_the_box_kernel():
    rng = np.random.default_rng(0)
    frame = np.full((60, 80, 3), 255, dtype=np.uint8)
    frame[20:40, 30:46] = (200, 30, 30)
    frames = [frame, np.roll(frame, 2, axis=1), np.roll(frame, 4, axis=1)]
    boxes = np.array([[30.0, 20.0, 16.0, 20.0]])
    for name in ("condensation", "ps", "dps"):
        tracker = trackers.make(name, kernel="box", box_levels=3, n_particles=60, rng=rng)
        result = trackers.track(tracker, frames, boxes)
        assert abs(result.boxes[-1, 0, 0] - 34.0) < 3.0, name
    with pytest.raises(ValueError, match="box_levels"):
        trackers.make("dps", kernel="box", box_levels=0)
