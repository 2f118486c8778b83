"""Histogram kernel and colour observation models against plain per-patch oracles."""

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skimage.color import rgb2hsv

from trackers.kernels.histogram import (
    KERNEL_BOX,
    KERNEL_CONE,
    KERNEL_EPANECHNIKOV,
    KERNEL_UNIFORM,
    METHODS,
    _lanes,
    _level_args,
    _region_distances,
    bhattacharyya_distance,
    hsv_n_bins,
    prepare_references,
    prepared_distances,
    quantize_hsv,
    quantize_rgb,
    region_distances,
    region_histograms,
    region_paths,
)
from trackers.models.observation import ColourModel

KERNELS = (KERNEL_UNIFORM, KERNEL_EPANECHNIKOV, KERNEL_CONE)


def _reference_histogram(bin_img, box, n_bins, kernel, n_parts):
    """One box's histogram the slow, obvious way: every pixel centre tested."""
    rows, cols = bin_img.shape
    x, y, w, h = box
    rr, cc = np.mgrid[0:rows, 0:cols]
    px, py = cc + 0.5, rr + 0.5
    inside = (px >= x) & (px < x + w) & (py >= y) & (py < y + h)
    r2 = ((px - (x + w / 2)) / (w / 2)) ** 2 + ((py - (y + h / 2)) / (h / 2)) ** 2
    if kernel == KERNEL_UNIFORM:
        weight = np.ones_like(r2)
    elif kernel == KERNEL_EPANECHNIKOV:
        weight = np.clip(1.0 - r2, 0.0, None)
    else:
        weight = np.clip(1.0 - np.sqrt(r2), 0.0, None)
    weight = np.where(inside, weight, 0.0)
    part = np.minimum(((py - y) / (h / n_parts)).astype(int), n_parts - 1)
    out = []
    for j in range(n_parts):
        wj = np.where(part == j, weight, 0.0)
        hist = np.bincount(bin_img.ravel(), weights=wj.ravel(), minlength=n_bins)
        total = hist.sum()
        out.append(hist / total if total > 0 else np.full(n_bins, 1.0 / n_bins))
    return np.concatenate(out) / n_parts


def _frame(seed, height, width):
    """A noise frame with a few flat rectangles (flat regions and noise both matter)."""
    rng = np.random.default_rng(seed)
    frame = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    for _ in range(3):
        x0, y0 = rng.integers(0, width), rng.integers(0, height)
        frame[y0:y0 + rng.integers(1, 20), x0:x0 + rng.integers(1, 20)] = rng.integers(0, 256, 3)
    return frame


@settings(max_examples=40)
@given(seed=st.integers(0, 2**32 - 1), n_bins=st.integers(2, 300),
       n_hists=st.integers(1, 20), common_ref=st.booleans())
def test_bhattacharyya_equals_opencv(seed, n_bins, n_hists, common_ref):
    rng = np.random.default_rng(seed)
    # Sparse histograms too: zero bins are where sqrt(p q) formulas usually slip.
    p = rng.dirichlet(np.full(n_bins, 0.3), n_hists) * (rng.random((n_hists, n_bins)) > 0.3)
    p[:, 0] += 1e-3
    p /= p.sum(axis=1, keepdims=True)
    q = rng.dirichlet(np.ones(n_bins), 1 if common_ref else n_hists)
    ours = bhattacharyya_distance(p, q[0] if common_ref else q)
    theirs = [cv2.compareHist(p[i].astype(np.float32), q[0 if common_ref else i]
                              .astype(np.float32), cv2.HISTCMP_BHATTACHARYYA)
              for i in range(n_hists)]
    np.testing.assert_allclose(ours, theirs, atol=2e-6)


@pytest.mark.parametrize("hists, refs", [((3, 4), (5,)), ((3, 4), (4, 4)), ((3, 4), (3, 5)),
                                          ((4,), (4,))])
def test_bhattacharyya_names_the_reference_shapes_it_accepts(hists, refs):
    # One reference of B bins for every row, or one per row; a row's bins are the last axis.
    want = (r"refs must have shape \(4,\) or \(3, 4\) for hists of shape \(P, B\); "
            if len(hists) == 2 else r"refs must have shape \(4,\) or \(4,\) ")
    with pytest.raises(ValueError, match=want):
        bhattacharyya_distance(np.ones(hists), np.ones(refs))


@settings(max_examples=25)
@given(seed=st.integers(0, 2**32 - 1), height=st.integers(5, 40), width=st.integers(5, 40),
       model=st.sampled_from(["rgb", "hsv"]), bins=st.integers(1, 12),
       kernel=st.sampled_from(KERNELS), n_parts=st.integers(1, 3))
def test_region_histograms_equal_per_patch_numpy(seed, height, width, model, bins, kernel,
                                                  n_parts):
    rng = np.random.default_rng(seed)
    frame = _frame(seed, height, width)
    if model == "rgb":
        bin_img, n_bins = quantize_rgb(frame, bins), bins ** 3
    else:
        bin_img, n_bins = quantize_hsv(frame, bins, bins, bins), hsv_n_bins(bins, bins, bins)
    n = 12
    # Boxes anywhere: inside, cut by every border, wholly outside, sub-pixel and huge.
    boxes = np.column_stack([
        rng.uniform(-0.5 * width, 1.2 * width, n), rng.uniform(-0.5 * height, 1.2 * height, n),
        rng.uniform(0.3, 1.5 * width, n), rng.uniform(0.3, 1.5 * height, n)])
    boxes[0] = [0.0, 0.0, width, height]
    boxes[1] = [-3.0, -2.0, 8.0, 7.0]
    boxes[2] = [width - 2.5, height - 3.5, 6.0, 7.0]
    boxes[3] = [width + 1.0, 1.0, 5.0, 5.0]
    hists = region_histograms(bin_img, boxes, n_bins, kernel, n_parts)
    expected = np.stack([_reference_histogram(bin_img, b, n_bins, kernel, n_parts)
                         for b in boxes])
    # Weights are accumulated in 2**-32 fixed point: exact to ~1e-9 of a small total.
    np.testing.assert_allclose(hists, expected, rtol=0, atol=1e-8)
    np.testing.assert_allclose(hists.sum(axis=1), 1.0, atol=1e-12)
    refs = rng.dirichlet(np.ones(n_bins * n_parts), 3)
    index = rng.integers(0, 3, n)
    dist = region_distances(bin_img, boxes, refs, index, kernel, n_parts)
    np.testing.assert_allclose(dist, bhattacharyya_distance(expected, refs[index]),
                               rtol=0, atol=1e-7)


@settings(max_examples=30)
@given(seed=st.integers(0, 2**32 - 1), height=st.integers(5, 60), width=st.integers(5, 60),
       bins=st.integers(1, 6), n_parts=st.integers(1, 3), n_refs=st.integers(1, 3),
       spread=st.floats(0.5, 30.0), sparsity=st.floats(0.0, 0.95))
def test_distance_paths_agree_with_per_patch_numpy(seed, height, width, bins, n_parts, n_refs,
                                                   spread, sparsity):
    """The integral and direct paths of the uniform kernel, and "auto", give the oracle's
    distances: clustered and scattered boxes, boxes cut by the border or wholly outside,
    thinner than a band, and references that are zero on most bins."""
    rng = np.random.default_rng(seed)
    frame = _frame(seed, height, width)
    bin_img, n_bins = quantize_rgb(frame, bins), bins ** 3
    n = 40
    centre = rng.uniform(0, [width, height])
    size = rng.uniform(0.3, 0.8 * max(width, height), 2)
    boxes = np.column_stack([centre + rng.normal(0.0, spread, (n, 2)) - size / 2,
                             size * np.exp(rng.normal(0.0, 0.2, (n, 2)))])
    boxes[0] = [-3.0, -2.0, 8.0, 7.0]
    boxes[1] = [width + 1.0, 1.0, 5.0, 5.0]
    boxes[2] = [1.2, 1.2, 4.0, 0.8]
    refs = rng.dirichlet(np.ones(n_bins * n_parts), n_refs)
    refs *= rng.random(refs.shape) >= sparsity
    refs[:, 0] += 1e-3
    refs /= refs.sum(axis=1, keepdims=True)
    index = rng.integers(0, n_refs, n)
    expected = bhattacharyya_distance(
        np.stack([_reference_histogram(bin_img, b, n_bins, KERNEL_UNIFORM, n_parts)
                  for b in boxes]), refs[index])
    for method in ("direct", "integral", "auto"):
        dist = region_distances(bin_img, boxes, refs, index, KERNEL_UNIFORM, n_parts,
                                method=method)
        np.testing.assert_allclose(dist, expected, rtol=0, atol=1e-7, err_msg=method)


def test_integral_path_is_taken_for_particle_clouds_and_matches_direct():
    """A tracker's cloud: 300 boxes around each of 3 objects on a noise frame."""
    rng = np.random.default_rng(0)
    frame = rng.integers(0, 256, (120, 160, 3), dtype=np.uint8)
    bin_img = quantize_rgb(frame)
    truth = np.array([[20.0, 20.0, 30.0, 30.0], [90.0, 30.0, 30.0, 30.0],
                      [60.0, 80.0, 30.0, 30.0]])
    refs = region_histograms(bin_img, truth, 1000, KERNEL_UNIFORM)
    boxes = np.repeat(truth, 300, axis=0)
    boxes[:, :2] += rng.normal(0.0, 4.0, (900, 2))
    index = np.repeat(np.arange(3), 300)
    taken = region_paths(bin_img, boxes, prepare_references(refs), index, KERNEL_UNIFORM)
    assert taken.all()  # "auto" takes the integral path for every cloud
    direct = region_distances(bin_img, boxes, refs, index, KERNEL_UNIFORM, method="direct")
    assert np.sum(direct < 1e-6) >= 3  # boxes on the references: d = 0 up to rounding
    for method in ("integral", "auto"):
        d = region_distances(bin_img, boxes, refs, index, KERNEL_UNIFORM, method=method)
        # Compare 1 − ρ = d²: near d = 0 the square root turns a 1e-15 rounding of ρ
        # into 3e-8 of d.
        np.testing.assert_allclose(d**2, direct**2, rtol=0, atol=1e-13)


def test_the_integral_counts_past_16_bits_on_a_roi_of_more_than_2_16_pixels():
    """A 300 x 300 ROI: 77,142 pixels of colour 0 at the integral's far corner, past what
    16-bit counts hold (the integral uses them only below 2**16 ROI pixels); both kernels
    of the integral path agree with the per-pixel path, box by box."""
    bin_img = (np.arange(300)[:, None] % 7 == 0).astype(np.int32).repeat(300, axis=1)
    assert np.sum(bin_img == 0) > 2**16
    boxes = np.array([[0.0, 0.0, 300.0, 300.0], [10.0, 250.0, 280.0, 50.0],
                      [150.0, 150.0, 150.0, 150.0], [0.0, 0.0, 20.0, 20.0]])
    refs = np.array([[0.5, 0.5], [0.9, 0.1]])
    index = np.array([0, 1, 0, 1])
    prepared = prepare_references(refs)
    for kernel in (KERNEL_UNIFORM, KERNEL_BOX):
        assert region_paths(bin_img, boxes, prepared, index, kernel, method="integral").all()
        direct = prepared_distances(bin_img, boxes, prepared, index, kernel, method="direct")
        got = prepared_distances(bin_img, boxes, prepared, index, kernel, method="integral")
        np.testing.assert_allclose(got**2, direct**2, rtol=0, atol=1e-13, err_msg=kernel)


def test_empty_region_is_uniform():
    bins = np.zeros((10, 10), dtype=np.int32)
    hist = region_histograms(bins, np.array([[20.0, 20.0, 5.0, 5.0], [3.2, 3.2, 0.2, 0.2]]),
                             4, KERNEL_CONE, 2)
    np.testing.assert_allclose(hist, 1.0 / 8)


def test_a_last_row_that_rounds_into_a_band_past_the_last_counts_in_the_last():
    """Row 3's centre (3.5) is inside a box of height 3.5 + 1 ulp, but 3.5 / (h / 3) rounds
    to 3.0: a band index one past the last, which every path clamps to band 2."""
    h = np.nextafter(3.5, 4.0)
    assert int(3.5 / (h / 3)) == 3
    bins = np.repeat(np.arange(4, dtype=np.int32)[:, None], 5, axis=1)  # row r: colour r
    box = np.array([[0.0, 0.0, 5.0, h]])
    expected = np.zeros(12)
    expected[[0, 5]] = 1 / 3  # bands 0 and 1: rows 0 and 1
    expected[[10, 11]] = 1 / 6  # band 2: rows 2 and 3
    np.testing.assert_allclose(region_histograms(bins, box, 4, KERNEL_UNIFORM, 3), [expected],
                               rtol=0, atol=1e-15)
    prepared = prepare_references(expected[None], 3)  # at most 8 colours a band: support path
    for method in ("auto", "direct", "integral"):
        np.testing.assert_allclose(prepared_distances(bins, box, prepared, np.zeros(1),
                                                      KERNEL_UNIFORM, method=method), [0.0],
                                   rtol=0, atol=1e-7, err_msg=method)


def _rim_box(dx):
    """A 2 x 2 box whose centre is dx left of pixel (0, 0)'s centre, on a 1 x 4 bin image
    whose pixels 1-3 are outside the box's ellipse."""
    return (np.array([[0.5 - dx - 1.0, -0.5, 2.0, 2.0]]),
            np.array([[3, 1, 2, 0]], dtype=np.int32))


def _assert_region_is_the_rim_pixel(box, bins, kernel):
    """The region is pixel (0, 0)'s colour (bin 3), not the uniform histogram of an empty
    region, on every path."""
    np.testing.assert_array_equal(region_histograms(bins, box, 4, kernel),
                                  [[0.0, 0.0, 0.0, 1.0]])
    prepared = prepare_references(np.array([[0.0, 0.0, 0.0, 1.0], [0.25, 0.25, 0.25, 0.25]]))
    for method in ("auto", "direct"):
        got = prepared_distances(bins, np.repeat(box, 2, axis=0), prepared, np.array([0, 1]),
                                 kernel, method=method)
        np.testing.assert_allclose(got, [0.0, np.sqrt(0.5)], rtol=0, atol=1e-12)


def test_a_region_of_one_fixed_point_unit_of_weight_is_not_empty():
    """The one pixel inside the box's ellipse lies on its rim, where the Epanechnikov weight
    is one fixed-point unit (1 - dx^2 = 2**-32)."""
    one = 2.0**32
    dx = np.sqrt(1.0 - 1.0 / one)
    assert np.int64(dx * dx * one + 0.5) == one - 1  # the pixel's weight is exactly 1
    _assert_region_is_the_rim_pixel(*_rim_box(dx), KERNEL_EPANECHNIKOV)


def test_a_cone_weight_below_one_fixed_point_unit_rounds_to_one():
    """The one pixel inside the box's ellipse lies so near its rim that its cone weight
    1 - r is 0.6 of a fixed-point unit (2**-32): rounded to the nearest unit it weighs 1
    (truncated, it would weigh 0 and leave the region empty)."""
    one = 2.0**32
    box, bins = _rim_box(1.0 - 0.6 / one)
    x, w = box[0, 0], box[0, 2]
    r = abs((0 + 0.5 - (x + 0.5 * w)) * (2.0 / w))  # as the kernel computes it
    assert 0.5 < (1.0 - r) * one < 1.0
    _assert_region_is_the_rim_pixel(box, bins, KERNEL_CONE)


def test_quantize_rgb_formula():
    rng = np.random.default_rng(3)
    frame = rng.integers(0, 256, (7, 9, 3), dtype=np.uint8)
    b = frame.astype(int) * 10 // 256
    np.testing.assert_array_equal(quantize_rgb(frame), b[..., 0] * 100 + b[..., 1] * 10 + b[..., 2])


def _reference_hsv(frame, hb, sb, vb, s_min, v_min):
    f = frame.astype(np.int64)
    r, g, b = f[..., 0], f[..., 1], f[..., 2]
    mx, mn = f.max(-1), f.min(-1)
    d = mx - mn
    h6 = np.where(mx == r, np.where(g < b, g - b + 6 * d, g - b),
                  np.where(mx == g, b - r + 2 * d, r - g + 4 * d))
    hbin = h6 * hb // np.maximum(6 * d, 1)
    assert hbin.max() < hb  # H < 1: the hue needs no clamp (the kernel has none)
    sbin = np.minimum(d * sb // np.maximum(mx, 1), sb - 1)
    vbin = np.minimum(mx * vb // 255, vb - 1)
    # The documented rule, in exact rationals: S >= floor(s_min 2**20) / 2**20, i.e.
    # d / mx >= k / 2**20, compared cross-multiplied in integers (exact, as Fractions
    # would be, without a Python call per colour).
    k = int(np.floor(s_min * 2**20))
    sat_ok = d * 2**20 >= k * np.maximum(mx, 1)
    coloured = (d > 0) & sat_ok & (mx >= v_min * 255 - 1e-9)
    return np.where(coloured, hbin * sb + sbin, hb * sb + vbin)


@settings(max_examples=20)
@given(seed=st.integers(0, 2**32 - 1), hb=st.integers(1, 40), sb=st.integers(1, 40),
       vb=st.integers(1, 40), s_min=st.floats(0.0, 1.0), v_min=st.floats(0.0, 1.0))
def test_quantize_hsv_equals_integer_reference(seed, hb, sb, vb, s_min, v_min):
    frame = _frame(seed, 30, 30)
    out = quantize_hsv(frame, hb, sb, vb, s_min, v_min)
    np.testing.assert_array_equal(out, _reference_hsv(frame, hb, sb, vb, s_min, v_min))
    assert out.min() >= 0 and out.max() < hsv_n_bins(hb, sb, vb)


_ALL_COLOURS = None


def _all_colours():
    """Every 8-bit RGB colour once, as a (4096, 4096, 3) frame."""
    global _ALL_COLOURS
    if _ALL_COLOURS is None:
        c = np.arange(2**24, dtype=np.uint32)
        _ALL_COLOURS = np.stack([c >> 16, (c >> 8) & 255, c & 255], axis=-1).astype(
            np.uint8).reshape(4096, 4096, 3)
    return _ALL_COLOURS


@pytest.mark.parametrize("hb, sb, vb, s_min, v_min", [(10, 10, 10, 0.1, 0.2)])
def test_quantize_hsv_exact_on_every_colour(hb, sb, vb, s_min, v_min):
    """The float32 divisions of the kernel give the exact integer floors on all 2**24
    colours (the default model; more bin counts in the slow suite)."""
    frame = _all_colours()
    for rows in range(0, 4096, 512):  # in slices: the int64 reference is memory-hungry
        part = frame[rows:rows + 512]
        np.testing.assert_array_equal(quantize_hsv(part, hb, sb, vb, s_min, v_min),
                                      _reference_hsv(part, hb, sb, vb, s_min, v_min))


@pytest.mark.slow
@pytest.mark.parametrize("hb, sb, vb, s_min, v_min", [
    (1, 1, 1, 0.0, 0.0), (8, 8, 8, 0.3, 0.1), (37, 91, 5, 0.55, 0.9),
    (256, 255, 256, 1.0, 1.0)])
def test_quantize_hsv_exact_on_every_colour_slow(hb, sb, vb, s_min, v_min):
    test_quantize_hsv_exact_on_every_colour(hb, sb, vb, s_min, v_min)


def test_quantize_rgb_exact_on_every_colour():
    frame = _all_colours()[::4]  # every colour's channels appear in a quarter of the rows
    for bins in (10, 7, 256):
        b = frame.astype(np.int64) * bins // 256
        np.testing.assert_array_equal(quantize_rgb(frame, bins),
                                      (b[..., 0] * bins + b[..., 1]) * bins + b[..., 2])


def test_quantize_hsv_agrees_with_skimage():
    frame = _frame(5, 64, 64)
    hsv = rgb2hsv(frame)
    h, s, v = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    coloured = (s >= 0.1) & (v >= 0.2)
    ref = np.where(coloured, np.minimum((h * 10).astype(int), 9) * 10
                   + np.minimum((s * 10).astype(int), 9), 100 + np.minimum((v * 10).astype(int), 9))
    # skimage's floating-point rounding can put an exact bin edge on either side.
    assert np.mean(quantize_hsv(frame) == ref) > 0.995


@pytest.mark.parametrize("kind", ["hsv", "rgb"])
def test_model_scores_template_at_zero_and_shifted_worse(kind):
    frame = _frame(1, 60, 80)
    frame[20:40, 30:50] = (200, 30, 30)
    frame[30:40, 30:50] = (30, 30, 200)
    model = ColourModel(kind, lam=20.0)
    box = np.array([[30.0, 20.0, 20.0, 20.0]])
    model.set_references(frame, box)
    obs = model.observe(frame)
    boxes = np.array([[30.0, 20.0, 20.0, 20.0], [36.0, 24.0, 20.0, 20.0], [0.0, 0.0, 20.0, 20.0]])
    d = obs.distances(boxes, np.zeros(3, dtype=int))
    assert d[0] == pytest.approx(0.0, abs=1e-7)
    assert d[0] < d[1] < d[2]
    np.testing.assert_allclose(obs.log_likelihoods(boxes, np.zeros(3, dtype=int)), -20.0 * d**2)


@pytest.mark.parametrize("kwargs, match", [
    ({"kind": "lab"}, "unknown observation model 'lab'; valid: hsv, rgb"),
    ({"kernel": "gauss"}, "unknown kernel 'gauss'"),
    ({"lam": 0.0}, "lam"),
    ({"bins": 0}, "bins"),
    ({"n_parts": 0}, "n_parts"),
    # Not numbers: numpy's or int()'s own TypeError/ValueError, naming nothing; True was
    # one bin.
    ({"bins": None}, "bins must be an integer in \\[1, 256\\], got None"),
    ({"bins": float("nan")}, "bins must be an integer in \\[1, 256\\], got nan"),
    ({"bins": True}, "bins must be an integer in \\[1, 256\\], got True"),
    ({"n_parts": "2"}, "n_parts must be a positive integer, got '2'"),
    # Unbounded: 10**9 parts asked for an 880 GB histogram per box.
    ({"n_parts": 10**9}, "n_parts must be an integer in \\[1, 256\\], got 1000000000"),
    ({"n_parts": 257}, "n_parts must be an integer in \\[1, 256\\], got 257"),
    ({"kind": "rgb", "bins": 64, "n_parts": 65},
     "n_parts=65 with bins=64 makes a 'rgb' histogram of 17039360 bins, more than "
     "MAX_HISTOGRAM_LENGTH = 16777216"),
    ({"lam": "20"}, "lam must be a positive number, got '20'"),
    ({"lam": None}, "lam must be a positive number, got None"),
    ({"s_min": "0.1"}, "s_min must lie in \\[0, 1\\], got '0.1'"),
    ({"kernel": ["cone"]}, "unknown kernel \\['cone'\\]"),
    ({"kind": ["hsv"]}, "unknown observation model \\['hsv'\\]"),
])
def test_model_rejects_bad_parameters(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ColourModel(**kwargs)


def test_kernel_rejects_bad_input():
    bins = np.zeros((10, 10), dtype=np.int32)
    with pytest.raises(ValueError, match="positive width and height"):
        region_histograms(bins, np.array([[1.0, 1.0, 0.0, 3.0]]), 4, KERNEL_UNIFORM)
    with pytest.raises(ValueError, match="bin_img values"):
        region_histograms(bins + 4, np.array([[1.0, 1.0, 2.0, 3.0]]), 4, KERNEL_UNIFORM)
    with pytest.raises(ValueError, match="kernel"):
        region_histograms(bins, np.array([[1.0, 1.0, 2.0, 3.0]]), 4, 7)
    with pytest.raises(ValueError, match="ref_index"):
        region_distances(bins, np.array([[1.0, 1.0, 2.0, 3.0]]), np.full((1, 4), 0.25),
                         np.array([1]), KERNEL_UNIFORM)
    with pytest.raises(ValueError, match="unknown method 'fast'; valid: auto, direct, integral"):
        region_distances(bins, np.array([[1.0, 1.0, 2.0, 3.0]]), np.full((1, 4), 0.25),
                         np.array([0]), KERNEL_UNIFORM, method="fast")
    with pytest.raises(ValueError, match="observe"):
        ColourModel("rgb").observe(np.zeros((4, 4, 3), dtype=np.uint8))


@pytest.mark.parametrize("call, match", [
    # Counts and thresholds that are not numbers: int()'s TypeError for None, its "cannot
    # convert float NaN to integer" naming no argument, a TypeError comparing text; True
    # was one bin.
    (lambda b, f: region_histograms(b, np.ones((1, 4)), None, KERNEL_UNIFORM),
     "n_bins must be a positive integer, got None"),
    (lambda b, f: region_histograms(b, np.ones((1, 4)), float("nan"), KERNEL_UNIFORM),
     "n_bins must be a positive integer, got nan"),
    (lambda b, f: region_histograms(b, np.ones((1, 4)), 4, KERNEL_UNIFORM, None),
     "n_parts must be a positive integer, got None"),
    (lambda b, f: prepare_references(np.full((1, 4), 0.25), None),
     "n_parts must be a positive divisor of refs.shape"),
    (lambda b, f: quantize_rgb(f, None), "bins must be an integer in \\[1, 256\\], got None"),
    (lambda b, f: quantize_rgb(f, True), "bins must be an integer in \\[1, 256\\], got True"),
    (lambda b, f: quantize_hsv(f, s_bins=float("nan")), "s_bins must be an integer in"),
    (lambda b, f: quantize_hsv(f, s_min="0.1"), "s_min must lie in \\[0, 1\\], got '0.1'"),
    (lambda b, f: ColourModel(kernel="box", box_levels=None), "box_levels must be an integer"),
    # A bool is not a kernel code: True was KERNEL_EPANECHNIKOV, at every entry point.
    (lambda b, f: region_histograms(b, np.ones((1, 4)), 4, True),
     "kernel must be one of .*, got True"),
    (lambda b, f: region_distances(b, np.ones((1, 4)), np.full((1, 4), 0.25), np.array([0]),
                                   np.True_), "kernel must be one of .*, got np.True_"),
    (lambda b, f: prepared_distances(b, np.ones((1, 4)),
                                     prepare_references(np.full((1, 4), 0.25)),
                                     np.array([0]), True), "kernel must be one of .*, got True"),
])
def test_kernel_entry_points_name_a_bad_number(call, match):
    with pytest.raises(ValueError, match=match):
        call(np.zeros((10, 10), dtype=np.int32), np.zeros((4, 4, 3), dtype=np.uint8))


def test_an_integral_float_kernel_code_is_the_code():
    # As every integer argument of the kernels (n_bins=4.0), a kernel code may be 4.0.
    bins = np.zeros((10, 10), dtype=np.int32)
    boxes = np.array([[1.0, 1.0, 3.0, 3.0]])
    np.testing.assert_array_equal(region_histograms(bins, boxes, 4, float(KERNEL_CONE)),
                                  region_histograms(bins, boxes, 4, KERNEL_CONE))


_DETERMINISM_SCRIPT = """
import hashlib, sys
import numpy as np
junk = [np.empty(int(n)) for n in sys.argv[1:]]  # a different heap in each process
from trackers.kernels.histogram import (KERNEL_CONE, KERNEL_EPANECHNIKOV, KERNEL_UNIFORM,
                                        quantize_rgb, region_distances, region_histograms)
rng = np.random.default_rng(0)
frame = rng.integers(0, 256, (120, 160, 3), dtype=np.uint8)
bins = quantize_rgb(frame)
truth = np.array([[20.0, 20.0, 30.0, 30.0], [90.0, 30.0, 30.0, 30.0]])
boxes = np.repeat(truth, 200, axis=0)
boxes[:, :2] += rng.normal(0.0, 4.0, (400, 2))
index = np.repeat(np.arange(2), 200)
h = hashlib.sha256()
for kernel in (KERNEL_UNIFORM, KERNEL_EPANECHNIKOV, KERNEL_CONE):
    refs = region_histograms(bins, truth, 1000, kernel)
    h.update(refs.tobytes())
    for method in ("direct", "integral"):
        h.update(region_distances(bins, boxes, refs, index, kernel, method=method).tobytes())
print(h.hexdigest())
"""


def test_distances_are_the_same_bytes_in_another_process():
    """Same inputs, same bytes, whatever the heap (and so the arrays' alignment) is."""
    import subprocess
    import sys

    digests = {subprocess.run([sys.executable, "-c", _DETERMINISM_SCRIPT, *sizes],
                              capture_output=True, text=True, check=True).stdout
               for sizes in ([], ["1", "3", "1001"], ["17", "4099", "5"])}
    assert len(digests) == 1, digests


def test_prepared_distances_equal_region_distances_and_check_their_input():
    rng = np.random.default_rng(4)
    frame = _frame(4, 40, 50)
    bin_img = quantize_hsv(frame)
    n_bins = hsv_n_bins()
    refs = rng.dirichlet(np.ones(2 * n_bins), 3) * (rng.random((3, 2 * n_bins)) > 0.5)
    refs /= refs.sum(axis=1, keepdims=True)
    boxes = np.column_stack([rng.uniform(-5, 45, 30), rng.uniform(-5, 35, 30),
                             rng.uniform(2, 20, 30), rng.uniform(2, 20, 30)])
    index = rng.integers(0, 3, 30)
    prepared = prepare_references(refs, 2)
    for kernel in KERNELS:
        np.testing.assert_array_equal(
            prepared_distances(bin_img, boxes, prepared, index, kernel),
            region_distances(bin_img, boxes, refs, index, kernel, 2))
    bad = boxes.copy()
    bad[3, 2] = np.nan
    with pytest.raises(ValueError, match="finite with positive width"):
        prepared_distances(bin_img, bad, prepared, index, KERNEL_UNIFORM)
    with pytest.raises(ValueError, match=r"ref_index must lie in \[0, 3\)"):
        prepared_distances(bin_img, boxes, prepared, index + 1, KERNEL_UNIFORM)
    with pytest.raises(ValueError, match="n_parts must be a positive divisor"):
        prepare_references(refs, 7)
    model = ColourModel("hsv")
    with pytest.raises(ValueError, match=r"references must have shape \(K, 220\)"):
        model.references = refs[:, :100]


def test_a_saturation_of_exactly_s_min_is_coloured():
    # S = 1/10 exactly (60, 54, 54) and (100, 90, 90) went to the value-only bins: the
    # threshold was rounded up, past 1/10. 25/251 < 1/10 stays out; so with s_min 0.3.
    from trackers.kernels.histogram import quantize_hsv

    px = np.array([[[60, 54, 54], [100, 90, 90], [251, 226, 226], [61, 54, 54]]], np.uint8)
    assert quantize_hsv(px).tolist() == [[1, 1, 100 + 9, 1]]  # value-only bin 9 of V 251
    px3 = np.array([[[100, 70, 70], [250, 176, 176]]], np.uint8)  # S = 3/10, 74/250
    q = quantize_hsv(px3, s_min=0.3).tolist()[0]
    assert q[0] < 100 and q[1] >= 100


@settings(max_examples=60)
@given(seed=st.integers(0, 2**32 - 1), width=st.integers(1, 70), n_parts=st.integers(1, 3),
       kernel=st.sampled_from([*KERNELS, KERNEL_BOX]))
def test_support_path_is_bit_identical_to_the_whole_histogram(seed, width, n_parts, kernel):
    """The trackers' bin images (int32); other integer types in the slow suite (each
    costs numba a compilation of the kernel, about 40 s on a cold cache)."""
    _check_support_path(seed, width, n_parts, kernel, np.int32)


@pytest.mark.slow
@settings(max_examples=60)
@given(seed=st.integers(0, 2**32 - 1), width=st.integers(1, 70), n_parts=st.integers(1, 3),
       kernel=st.sampled_from([*KERNELS, KERNEL_BOX]),
       dtype=st.sampled_from([np.uint8, np.uint16]))
def test_support_path_is_bit_identical_for_other_bin_image_types(seed, width, n_parts, kernel,
                                                                 dtype):
    _check_support_path(seed, width, n_parts, kernel, dtype)


def _check_support_path(seed, width, n_parts, kernel, dtype):
    """References with few support bins per band are scored from those bins' counts alone
    (``_SMALL_SUPPORT``): the same bits as from the whole scattered histogram, for 0 to 10
    support bins in a band, boxes cut by every border and frames narrower than the
    padding."""
    rng = np.random.default_rng(seed)
    n_bins, height, n_refs = 12, 23, 11
    coarse = rng.integers(0, n_bins, (height // 3 + 1, width // 3 + 1))
    bin_img = np.ascontiguousarray(np.kron(coarse, np.ones((3, 3), dtype=np.int64))
                                   [:height, :width], dtype=dtype)
    refs = rng.random((n_refs, n_parts * n_bins))
    for r in range(n_refs):  # reference r has r - 1 support bins per band (all for r = 0)
        for j in range(n_parts):
            if r:
                refs[r, j * n_bins + rng.permutation(n_bins)[r - 1:]] = 0.0
    refs[:, 0] += (refs.sum(axis=1) == 0)  # r = 1: no support at all but one bin
    refs /= refs.sum(axis=1, keepdims=True)
    boxes = np.column_stack([rng.uniform(-12, width + 2, 150), rng.uniform(-12, height + 2, 150),
                             rng.uniform(0.3, 40, 150), rng.uniform(0.3, 30, 150)])
    index = rng.integers(0, n_refs, 150)
    prepared = prepare_references(refs, n_parts)
    fracs, a_fixed = _level_args(kernel, 3)
    args = (bin_img, boxes, prepared.sqrt_refs, index, prepared.nz, prepared.nz_start,
            prepared.empty_rho, n_bins, kernel, n_parts, _lanes(n_parts * n_bins),
            METHODS["direct"], fracs, a_fixed, 1)
    whole = _region_distances(*args, -1)[0]
    support = _region_distances(*args, n_bins)[0]
    np.testing.assert_array_equal(support, whole)
    np.testing.assert_array_equal(
        region_distances(bin_img, boxes, refs, index, kernel, n_parts, method="direct"), whole)


@pytest.mark.parametrize("kernel", [*KERNELS, KERNEL_BOX])
@pytest.mark.parametrize("method", ["direct", "integral"])
def test_a_box_scored_against_its_own_histogram_has_distance_zero(kernel, method):
    """d = sqrt(max(0, 1 − ρ)): a box against its own histogram has ρ = 1 up to rounding,
    d = 0 exactly where ρ rounds to 1 or above (never NaN, never 1), and a box of one
    colour has ρ = 1 exactly. Bands of 1, 2 and 3; whole, support and integral paths."""
    rng = np.random.default_rng(21)
    bin_img = rng.integers(0, 3, (24, 30)).astype(np.int32)
    bin_img[4:12, 8:16] = 1  # a flat square: 8 x 8 pixels of colour 1
    boxes = np.column_stack([rng.uniform(-2, 26, 200), rng.uniform(-2, 20, 200),
                             rng.uniform(1, 9, 200), rng.uniform(1, 9, 200)])
    boxes[0] = [8.0, 4.0, 8.0, 8.0]
    boxes[1] = [10.0, 6.0, 4.0, 4.0]
    for n_parts in (1, 2, 3):
        refs = region_histograms(bin_img, boxes, 3, kernel, n_parts)
        for max_support in (-1, 3):  # the whole histogram, then the support path
            prepared = prepare_references(refs, n_parts)
            fracs, a_fixed = _level_args(kernel, 3)
            d = _region_distances(bin_img, boxes, prepared.sqrt_refs, np.arange(200),
                                  prepared.nz, prepared.nz_start, prepared.empty_rho, 3,
                                  kernel, n_parts, _lanes(3 * n_parts), METHODS[method],
                                  fracs, a_fixed, 1, max_support)[0]
            assert np.all(np.isfinite(d)) and np.all(d >= 0.0)
            assert d.max() < 1e-7, (n_parts, max_support)
            assert d[0] == 0.0 and d[1] == 0.0
            if n_parts == 1:
                # Exact where ρ rounds to 1 or above: at least one box of the cloud.
                assert np.sum(d == 0.0) > 2


@pytest.mark.parametrize("kernel", [*KERNELS, KERNEL_BOX])
def test_more_bands_than_bins_equal_per_patch_numpy(kernel):
    """Two bins in three or five bands: each band's bins lie n_bins apart, fewer than the
    bands (the histogram's four copies, at multiples of the whole length, must not
    overlap)."""
    rng = np.random.default_rng(8)
    bin_img = rng.integers(0, 2, (20, 26)).astype(np.int32)
    boxes = np.column_stack([rng.uniform(-3, 22, 30), rng.uniform(-3, 16, 30),
                             rng.uniform(2, 14, 30), rng.uniform(2, 14, 30)])
    for n_parts in (3, 5):
        hists = region_histograms(bin_img, boxes, 2, kernel, n_parts)
        if kernel == KERNEL_BOX:
            assert np.all(np.isfinite(hists)) and np.allclose(hists.sum(axis=1), 1.0)
            continue  # the box kernel's transcription is in test_box_kernel.py
        expected = np.stack([_reference_histogram(bin_img, b, 2, kernel, n_parts)
                             for b in boxes])
        np.testing.assert_allclose(hists, expected, rtol=0, atol=1e-8)
        refs = rng.dirichlet(np.ones(2 * n_parts), 2)
        index = rng.integers(0, 2, 30)
        np.testing.assert_allclose(
            region_distances(bin_img, boxes, refs, index, kernel, n_parts, method="direct"),
            bhattacharyya_distance(expected, refs[index]), rtol=0, atol=1e-7)


@pytest.mark.parametrize("s_min, v_min", [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0)])
def test_quantize_hsv_at_the_thresholds_extremes(s_min, v_min):
    """s_min and v_min of exactly 0 and 1 are accepted; with 0 a grey or black pixel
    (no hue, d = 0) still falls in the value bins, with 1 only fully saturated, full
    value pixels are coloured."""
    frame = _frame(9, 24, 24)
    frame[0, :6] = [(0, 0, 0), (255, 255, 255), (7, 7, 7), (255, 0, 0), (0, 255, 1),
                    (128, 0, 0)]
    out = quantize_hsv(frame, 6, 5, 4, s_min, v_min)
    np.testing.assert_array_equal(out, _reference_hsv(frame, 6, 5, 4, s_min, v_min))
    assert out[0, 0] == 6 * 5 and out[0, 1] == 6 * 5 + 3 and out[0, 2] == 6 * 5


@pytest.mark.parametrize("kwargs", [{"s_min": -0.1}, {"v_min": -1e-9}, {"s_min": 1.0 + 1e-9},
                                    {"v_min": 2.0}, {"s_min": float("nan")}])
def test_quantize_hsv_refuses_thresholds_outside_0_1(kwargs):
    with pytest.raises(ValueError, match="must lie in \\[0, 1\\]"):
        quantize_hsv(np.zeros((2, 2, 3), dtype=np.uint8), **kwargs)
