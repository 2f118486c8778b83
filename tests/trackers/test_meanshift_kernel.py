"""The batched kernel mean shift (trackers.kernels.meanshift)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackers.kernels.histogram import (
    KERNEL_CONE,
    KERNEL_EPANECHNIKOV,
    KERNEL_UNIFORM,
    quantize_rgb,
    region_distances,
    region_histograms,
)
from trackers.kernels.meanshift import mean_shift

PALETTE = np.array(
    [(200, 30, 30), (30, 160, 40), (40, 40, 200), (220, 200, 30), (150, 40, 160),
     (20, 180, 190)], dtype=np.uint8)


def disc_frame(height, width, cx, cy, radius, rng):
    """A disc of 3-6 coloured sectors on white; sector colours drawn from ``rng``."""
    frame = np.full((height, width, 3), 255, dtype=np.uint8)
    yy, xx = np.mgrid[0:height, 0:width] + 0.5
    dx, dy = xx - cx, yy - cy
    inside = dx * dx + dy * dy < radius * radius
    n_sectors = int(rng.integers(3, 7))
    colours = PALETTE[rng.permutation(len(PALETTE))[:n_sectors]]
    sector = ((np.arctan2(dy, dx) + np.pi) / (2 * np.pi) * n_sectors).astype(int)
    sector = np.minimum(sector, n_sectors - 1)
    for i, colour in enumerate(colours):
        frame[inside & (sector == i)] = colour
    return frame


@settings(max_examples=60, deadline=None)
@given(
    radius=st.floats(6.0, 30.0),
    start_radius=st.floats(0.0, 0.97),
    start_angle=st.floats(0.0, 2 * np.pi),
    kernel=st.sampled_from([KERNEL_EPANECHNIKOV, KERNEL_CONE]),
    seed=st.integers(0, 2**32 - 1),
)
def test_converges_to_disc_centre_from_any_start_inside(radius, start_radius, start_angle,
                                                        kernel, seed):
    rng = np.random.default_rng(seed)
    cx, cy = rng.uniform(40.0, 120.0), rng.uniform(40.0, 80.0)
    bins = quantize_rgb(disc_frame(120, 160, cx, cy, radius, rng))
    box = np.array([[cx - radius, cy - radius, 2 * radius, 2 * radius]])
    model = region_histograms(bins, box, 1000, kernel)
    r = start_radius * radius
    start = np.array([[cx + r * np.cos(start_angle), cy + r * np.sin(start_angle)]])
    res = mean_shift(bins, model, np.array([0]), start, box[:, 2:], kernel=kernel,
                     max_iter=100, eps=0.05)
    assert np.hypot(*(res.centres[0] - (cx, cy))) < 0.5
    assert res.distances[0] < 0.05


@pytest.mark.parametrize("kernel", [KERNEL_EPANECHNIKOV, KERNEL_CONE])
def test_distances_equal_the_shared_region_kernel_border_cases_included(kernel):
    rng = np.random.default_rng(7)
    bins = quantize_rgb(rng.integers(0, 256, (60, 80, 3), dtype=np.uint8), 4)
    models = region_histograms(bins, np.array([[10.0, 10, 20, 20], [30, 20, 15, 25]]), 64,
                               kernel)
    n = 400
    centres = rng.uniform(-15.0, 95.0, (n, 2))  # many windows cut by or outside the border
    sizes = rng.uniform(0.5, 30.0, (n, 2))
    index = rng.integers(0, 2, n)
    res = mean_shift(bins, models, index, centres, sizes, kernel=kernel, max_iter=0)
    boxes = np.concatenate([centres - 0.5 * sizes, sizes], axis=1)
    expected = region_distances(bins, boxes, models, index, kernel)
    # The shared kernel accumulates in fixed point: agreement to ~1e-10, not bit for bit.
    np.testing.assert_allclose(res.distances, expected, rtol=0, atol=1e-8)
    np.testing.assert_array_equal(res.centres, centres)
    np.testing.assert_array_equal(res.n_iter, 0)


def test_batched_call_equals_one_call_per_start_and_never_worsens():
    rng = np.random.default_rng(3)
    frame = disc_frame(120, 160, 70.0, 60.0, 15.0, rng)
    frame[20:40, 100:140] = disc_frame(20, 40, 20.0, 10.0, 9.0, rng)
    bins = quantize_rgb(frame)
    models = region_histograms(bins, np.array([[55.0, 45, 30, 30], [110, 20, 18, 18]]), 1000,
                               KERNEL_CONE)
    n = 50
    centres = np.concatenate([rng.normal((70, 60), 8, (n, 2)), rng.normal((120, 30), 6, (n, 2))])
    sizes = np.repeat([[30.0, 30.0], [18.0, 18.0]], n, axis=0)
    index = np.repeat([0, 1], n)
    batched = mean_shift(bins, models, index, centres, sizes, max_iter=10)
    start = mean_shift(bins, models, index, centres, sizes, max_iter=0)
    assert np.all(batched.distances <= start.distances)
    for p in range(0, 2 * n, 7):
        one = mean_shift(bins, models, index[p:p + 1], centres[p:p + 1], sizes[p:p + 1],
                         max_iter=10)
        np.testing.assert_array_equal(one.centres[0], batched.centres[p])
        assert one.distances[0] == batched.distances[p]


def test_iteration_cap_and_stopping_threshold():
    rng = np.random.default_rng(5)
    bins = quantize_rgb(disc_frame(100, 100, 50.0, 50.0, 20.0, rng))
    box = np.array([[30.0, 30.0, 40.0, 40.0]])
    model = region_histograms(bins, box, 1000, KERNEL_CONE)
    start = np.array([[38.0, 57.0]])
    capped = mean_shift(bins, model, np.array([0]), start, box[:, 2:], max_iter=1)
    assert capped.n_iter[0] == 1
    loose = mean_shift(bins, model, np.array([0]), start, box[:, 2:], max_iter=50, eps=5.0)
    tight = mean_shift(bins, model, np.array([0]), start, box[:, 2:], max_iter=50, eps=0.01)
    assert loose.n_iter[0] < tight.n_iter[0]
    early = mean_shift(bins, model, np.array([0]), start, box[:, 2:], max_iter=50, eps=0.01,
                       min_distance=0.5)
    assert early.n_iter[0] < tight.n_iter[0]


def test_window_outside_the_frame_stays_put():
    bins = quantize_rgb(np.full((40, 40, 3), 255, dtype=np.uint8))
    model = np.full((1, 1000), 1e-3)
    start = np.array([[-50.0, 20.0], [20.0, 90.0]])
    res = mean_shift(bins, model, np.array([0, 0]), start, np.full((2, 2), 10.0), max_iter=5)
    np.testing.assert_array_equal(res.centres, start)
    assert np.all(np.isfinite(res.distances))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"kernel": KERNEL_UNIFORM}, "kernel"),
        ({"max_iter": -1}, "max_iter"),
        ({"eps": -0.1}, "eps"),
        ({"min_distance": float("nan")}, "min_distance"),
        ({"sizes": np.array([[0.0, 5.0]])}, "sizes"),
        ({"centres": np.array([[np.nan, 5.0]])}, "centres"),
        ({"centres": np.zeros((1, 3))}, "centres"),
        ({"model_index": np.array([1])}, "model_index"),
        ({"bin_img": np.full((5, 5), 7, dtype=np.int32)}, "bin_img"),
        ({"bin_img": np.zeros((5, 5))}, "bin_img"),
        ({"models": np.zeros(4)}, "models"),
        # Not numbers: int()'s "cannot convert float NaN to integer", TypeErrors of None
        # and of text compared with a float.
        ({"max_iter": float("nan")}, "max_iter must be an integer >= 0, got nan"),
        ({"max_iter": None}, "max_iter must be an integer >= 0, got None"),
        ({"eps": "0.5"}, "eps must be >= 0, got '0.5'"),
        ({"min_distance": None}, "min_distance must be >= 0, got None"),
        # True was KERNEL_EPANECHNIKOV (1).
        ({"kernel": True}, "kernel must be KERNEL_EPANECHNIKOV .*, got True"),
    ],
)
def test_bad_input_raises_value_error_naming_it(kwargs, message):
    args = {
        "bin_img": np.zeros((5, 5), dtype=np.int32),
        "models": np.full((1, 4), 0.25),
        "model_index": np.array([0]),
        "centres": np.array([[2.0, 2.0]]),
        "sizes": np.array([[3.0, 3.0]]),
    }
    options = {}
    for key, value in kwargs.items():
        (args if key in args else options)[key] = value
    with pytest.raises(ValueError, match=message):
        mean_shift(**args, **options)
