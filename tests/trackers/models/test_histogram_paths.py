"""Which path ``region_distances`` takes: the compiled choice (``region_paths``) against a
transcription of the documented cost model, the scoring following it, and the particle
filters' clouds taking the integral path on the presets the model was fitted on."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import trackers
import trackers.models.observation as observation
from scenegen.render.plan import generate
from trackers.kernels import histogram as hist
from trackers.kernels.direct import _SMALL_SUPPORT, _lanes
from trackers.kernels.histogram import (
    DEFAULT_BOX_LEVELS,
    KERNEL_BOX,
    KERNEL_CONE,
    KERNEL_EPANECHNIKOV,
    KERNEL_UNIFORM,
    METHODS,
    _plan_paths,
    _region_distances,
    _support_colours,
    prepare_references,
    prepared_distances,
    quantize_rgb,
    region_histograms,
    region_paths,
)
from trackers.kernels.profiles import _level_args


def _pixel_range(lo, size, n):
    """Pixels [i0, i1) whose centres i + 0.5 lie in [lo, lo + size), clipped to [0, n]."""
    return max(int(np.ceil(lo - 0.5)), 0), min(int(np.ceil(lo + size - 0.5)), n)


def _expected_integral(shape, boxes, q, n_parts, method, n_levels):
    """The documented choice for one reference's boxes, in the kernel's order of
    operations (the histogram module's comment above its cost constants)."""
    cost_direct, cost_integral, cells, has_pixel = _costs(shape, boxes, q, n_parts,
                                                          n_levels)
    return bool(has_pixel and cells <= hist._MAX_CELLS
                and (method == "integral" or cost_integral < cost_direct))


def _costs(shape, boxes, q, n_parts, n_levels):
    """(direct cost, integral cost, integral cells, whether a box has a pixel) of one
    reference's boxes, as the histogram module's comment above its constants states."""
    rows, cols = shape
    r_lo, r_hi, c_lo, c_hi = rows, 0, cols, 0
    area = 0.0
    for x, y, w, h in boxes:
        r0, r1 = _pixel_range(y, h, rows)
        c0, c1 = _pixel_range(x, w, cols)
        if r0 < r1 and c0 < c1:
            area += (r1 - r0) * (c1 - c0)
            r_lo, r_hi = min(r_lo, r0), max(r_hi, r1)
            c_lo, c_hi = min(c_lo, c0), max(c_hi, c1)
    bands = q.reshape(n_parts, -1) > 0
    n_sup = int(bands.sum())
    n_chan = int(bands.any(axis=0).sum())  # a colour in two bands' supports: one channel
    roi_pixels = max(r_hi - r_lo, 0) * max(c_hi - c_lo, 0) * 1.0
    cells = roi_pixels * n_chan
    k = len(boxes)
    cost_direct = area * hist._COST_PIXEL + k * (n_sup * hist._COST_SWEEP
                                                 + hist._COST_BOX_DIRECT)
    cost_integral = (cells * hist._COST_CELL + roi_pixels * hist._COST_ROI
                     + k * (n_sup * n_levels * hist._COST_CORNER + hist._COST_BOX_INTEGRAL))
    return cost_direct, cost_integral, cells, r_hi > r_lo


@st.composite
def _groups(draw):
    """Boxes of 1-4 references on a frame: clouds or scattered boxes, some leaving it."""
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    rows, cols = draw(st.integers(8, 300)), draw(st.integers(8, 300))
    n_refs = draw(st.integers(1, 4))
    n_parts = draw(st.sampled_from([1, 2, 3]))
    n_bins = draw(st.sampled_from([8, 64, 512]))
    sparsity = draw(st.sampled_from([0.0, 0.5, 0.9, 0.99]))
    q = rng.random((n_refs, n_parts * n_bins)) * (rng.random((n_refs, n_parts * n_bins))
                                                  >= sparsity)
    q[:, 0] += 1e-3
    q /= q.sum(axis=1, keepdims=True)
    counts = [draw(st.integers(0, 400)) for _ in range(n_refs)]
    boxes, index = [], []
    for r, n in enumerate(counts):
        size = rng.uniform(0.5, 1.2 * max(rows, cols), 2)
        centre = rng.uniform(-0.2, 1.2, 2) * (cols, rows)
        spread = draw(st.sampled_from([0.0, 2.0, 10.0, 80.0]))
        b = np.column_stack([centre + rng.normal(0.0, spread, (n, 2)) - size / 2,
                             size * np.exp(rng.normal(0.0, 0.2, (n, 2)))])
        boxes.append(b)
        index.append(np.full(n, r))
    order = rng.permutation(sum(counts))  # references interleaved, as a DPS step has them
    boxes = np.concatenate(boxes)[order] if order.size else np.zeros((0, 4))
    index = np.concatenate(index)[order] if order.size else np.zeros(0, dtype=np.int64)
    kernel = draw(st.sampled_from([KERNEL_UNIFORM, KERNEL_BOX]))
    levels = draw(st.integers(1, 6))
    return (rows, cols), boxes, q, index, n_parts, kernel, levels


@settings(max_examples=150, deadline=None)
@given(_groups(), st.sampled_from(["auto", "integral"]))
def test_the_path_is_the_cost_models_choice(case, method):
    shape, boxes, q, index, n_parts, kernel, levels = case
    prepared = prepare_references(q, n_parts)
    taken = region_paths(np.zeros(shape, dtype=np.int32), boxes, prepared, index, kernel,
                         method=method, box_levels=levels)
    n_levels = levels if kernel == KERNEL_BOX else 1
    for r in np.unique(index):
        members = index == r
        expected = _expected_integral(shape, boxes[members], q[r], n_parts, method, n_levels)
        assert taken[members].tolist() == [expected] * int(members.sum()), r


@pytest.mark.parametrize("kernel", [KERNEL_UNIFORM, KERNEL_BOX, KERNEL_EPANECHNIKOV,
                                    KERNEL_CONE])
def test_direct_and_elliptic_kernels_never_take_the_integral_path(kernel):
    prepared = prepare_references(np.full((1, 8), 1 / 8))
    cloud = np.tile([20.0, 20.0, 40.0, 40.0], (500, 1))
    img = np.zeros((100, 100), dtype=np.int32)
    index = np.zeros(500, dtype=np.int64)
    elliptic = kernel in (KERNEL_EPANECHNIKOV, KERNEL_CONE)
    for method in ("auto", "integral"):
        assert region_paths(img, cloud, prepared, index, kernel, method=method).all() \
            == (not elliptic)
    assert not region_paths(img, cloud, prepared, index, kernel, method="direct").any()
    assert region_paths(img, np.zeros((0, 4)), prepared, np.zeros(0), kernel).shape == (0,)


def test_the_integral_path_is_bounded_by_its_cells_and_needs_a_pixel():
    """2**24 cells at most: a 4096 x 4096 ROI of one channel is the largest."""
    prepared = prepare_references(np.array([[1.0, 0.0], [0.5, 0.5]]))
    for width, ref, expected in ((4096, 0, True), (4097, 0, False), (2048, 1, True),
                                 (2049, 1, False)):
        img = np.broadcast_to(np.int32(0), (4096, width))  # only the shape is read
        box = np.array([[0.0, 0.0, float(width), 4096.0]])
        assert region_paths(img, box, prepared, np.array([ref]), KERNEL_UNIFORM,
                            method="integral").tolist() == [expected], (width, ref)
    outside = np.array([[200.0, 10.0, 30.0, 30.0], [10.0, -50.0, 30.0, 30.0]])
    assert not region_paths(np.zeros((100, 100), dtype=np.int32), outside, prepared,
                            np.zeros(2), KERNEL_BOX, method="integral").any()
    # A frame with no rows or no columns has no pixel to integrate, even when asked; its
    # boxes are empty regions (distance 0 to a uniform reference) on either path.
    uniform = prepare_references(np.full((1, 2), 0.5))
    box = np.array([[1.0, 1.0, 3.0, 3.0]])
    for shape in ((0, 8), (8, 0), (0, 0)):
        img = np.zeros(shape, dtype=np.int32)
        for kernel in (KERNEL_UNIFORM, KERNEL_BOX):
            assert not region_paths(img, box, uniform, np.zeros(1), kernel,
                                    method="integral").any(), shape
            for method in ("integral", "direct"):
                assert prepared_distances(img, box, uniform, np.zeros(1), kernel,
                                          method=method).tolist() == [0.0], shape


@pytest.mark.parametrize("kernel", [KERNEL_UNIFORM, KERNEL_BOX])
@pytest.mark.parametrize("method", ["auto", "integral", "direct"])
def test_the_scoring_follows_the_chosen_path_box_by_box(kernel, method):
    """The compiled scoring reports which path scored each box: exactly the complement
    of ``region_paths`` (two clouds take the integral path, two references of a few
    boxes the direct one, under ``auto``), and its distances are the same either way."""
    rng = np.random.default_rng(7)
    frame = rng.integers(0, 256, (120, 160, 3), dtype=np.uint8)
    bin_img = quantize_rgb(frame, 4)  # 64 colours: a template's support, not a noise's
    truth = np.array([[20.0, 20.0, 30.0, 30.0], [90.0, 30.0, 30.0, 30.0],
                      [60.0, 70.0, 40.0, 40.0], [5.0, 90.0, 6.0, 6.0]])
    refs = region_histograms(bin_img, truth, 64, KERNEL_UNIFORM)
    counts = np.array([300, 2, 250, 3])
    index = np.repeat(np.arange(4), counts)
    boxes = truth[index] + np.column_stack([rng.normal(0.0, 3.0, (index.size, 2)),
                                            np.zeros((index.size, 2))])
    order = rng.permutation(index.size)
    boxes, index = boxes[order], index[order]
    prepared = prepare_references(refs)
    taken = region_paths(bin_img, boxes, prepared, index, kernel, method=method)
    expected = {"auto": {0, 2}, "integral": {0, 1, 2, 3}, "direct": set()}[method]
    assert set(index[taken]) == expected and not set(index[~taken]) & expected
    fracs, a_fixed = _level_args(kernel, DEFAULT_BOX_LEVELS)
    for threads in (1, 2):
        d, direct = _region_distances(
            bin_img, boxes, prepared.sqrt_refs, index, prepared.nz, prepared.nz_start,
            prepared.empty_rho, prepared.n_bins, kernel, 1, _lanes(refs.shape[1]),
            METHODS[method], fracs, a_fixed, threads, _SMALL_SUPPORT)
        np.testing.assert_array_equal(direct, ~taken)
        np.testing.assert_allclose(
            d**2, prepared_distances(bin_img, boxes, prepared, index, kernel,
                                     method="direct")**2, rtol=0, atol=1e-13)


@pytest.mark.parametrize("preset", ["dps-synthetic", "dps-occlusion", "dps-dancers"])
def test_the_particle_filters_clouds_take_the_integral_path(monkeypatch, preset):
    """With the box kernel (L = 3), every set of boxes that PS, the joint filter and
    condensation score on a preset the cost model was fitted on takes the integral path
    for every object: the path the bench's box-kernel rows time."""
    seq = generate(preset, seed=3, frames=4)
    init = seq.gt.box[0][seq.target_indices()]
    calls = []

    def spy(bin_img, boxes, prepared, ref_index, kernel, **kw):
        calls.append(region_paths(bin_img, boxes, prepared, ref_index, kernel, **kw))
        return prepared_distances(bin_img, boxes, prepared, ref_index, kernel, **kw)

    monkeypatch.setattr(observation, "prepared_distances", spy)
    for name in ("condensation", "joint-pf", "ps"):
        calls.clear()
        tracker = trackers.make(name, kernel="box", box_levels=3, rng=0)
        tracker.init(seq.frames[0], init)
        for frame in seq.frames[1:]:
            tracker.step(frame)
        assert len(calls) >= 3
        assert all(taken.all() for taken in calls), name


def _near_tie(kernel, levels, lo, hi):
    """A reference's boxes (k boxes of w x h, each shifted dx right of the last, on a
    200 x 200 frame) and its histogram (n colours of equal weight) whose direct cost
    minus integral cost lies in [lo, hi]: the first such in a fixed search order."""
    n_levels = levels if kernel == KERNEL_BOX else 1
    for n in (1, 2, 3):
        q = np.zeros(8)
        q[:n] = 1.0 / n
        for k in range(1, 13):
            for dx in (0, 1, 2):
                for w in range(1, 31):
                    for h in range(1, 31):
                        boxes = np.array([[10.0 + i * dx, 10.0, w, h] for i in range(k)])
                        direct, integral, _, _ = _costs((200, 200), boxes, q, 1, n_levels)
                        if lo <= direct - integral <= hi:
                            return boxes, q
    raise AssertionError(f"no configuration with a cost margin in [{lo}, {hi}]")


@pytest.mark.parametrize(("kernel", "levels"), [(KERNEL_UNIFORM, 3), (KERNEL_BOX, 1),
                                                (KERNEL_BOX, 3)])
def test_the_choice_at_the_cost_models_tie(kernel, levels):
    """Either side of a tie, within a pixel visit: the integral path when it is cheaper
    by 0.05-0.95 of a pixel visit, the direct path when it costs 0.05-0.95 more (the
    uniform kernel's integral reads one rectangle a box, however many levels are asked)."""
    img = np.zeros((200, 200), dtype=np.int32)
    for lo, hi, expected in ((0.05, 0.95, True), (-0.95, -0.05, False)):
        boxes, q = _near_tie(kernel, levels, lo, hi)
        prepared = prepare_references(q[None, :])
        index = np.zeros(len(boxes), dtype=np.int64)
        taken = region_paths(img, boxes, prepared, index, kernel, box_levels=levels)
        assert taken.tolist() == [expected] * len(boxes), (lo, hi, boxes[0], len(boxes))


@pytest.mark.parametrize("kernel", [KERNEL_UNIFORM, KERNEL_BOX, KERNEL_EPANECHNIKOV,
                                    KERNEL_CONE])
@pytest.mark.parametrize("method", ["auto", "integral", "direct"])
@pytest.mark.parametrize("n_boxes", [0, 1, 7])
def test_the_plan_orders_every_box_once(kernel, method, n_boxes):
    """``_plan_paths``' order is a permutation of the boxes, sorted by reference and
    stable, whatever path they take; its groups cover it."""
    rng = np.random.default_rng(n_boxes)
    prepared = prepare_references(np.array([[0.5, 0.5], [0.25, 0.75], [1.0, 0.0]]))
    boxes = np.column_stack([rng.uniform(0, 40, (n_boxes, 2)), rng.uniform(1, 20, (n_boxes, 2))])
    index = rng.integers(0, 3, n_boxes)
    _, a_fixed = _level_args(kernel, 3)
    order, starts, integral, rois = _plan_paths(
        50, 60, boxes, index, prepared.nz, prepared.nz_start, prepared.n_bins,
        prepared.n_parts, kernel, METHODS[method], a_fixed)
    assert sorted(order.tolist()) == list(range(n_boxes))
    assert integral.shape == (starts.shape[0] - 1,) and rois.shape == (integral.shape[0], 4)
    if integral.shape[0]:
        np.testing.assert_array_equal(order, np.argsort(index, kind="stable"))
        assert starts[0] == 0 and starts[-1] == n_boxes
        assert len(set(index[order[starts[:-1]]].tolist())) == integral.shape[0]


def test_the_support_path_is_for_references_of_few_colours_in_every_band():
    """A reference takes the support path when each band has at most ``max_support``
    colours of positive weight (here 8 and 9 around the limit, in either band), and its
    support bins are given by their colour within their band."""
    n_bins = 16
    cases = []
    for first, second in ((8, 8), (9, 1), (1, 9), (8, 0), (16, 16), (1, 1)):
        q = np.zeros(2 * n_bins)
        q[n_bins - first:n_bins] = 1.0  # the last colours of band 0
        q[n_bins:n_bins + second] = 1.0
        q[0] += (first + second == 0)
        cases.append(q / q.sum())
    prepared = prepare_references(np.array(cases), 2)
    colours, small = _support_colours(prepared.nz, prepared.nz_start, n_bins, 2,
                                      _SMALL_SUPPORT)
    assert _SMALL_SUPPORT == 8
    assert small.tolist() == [True, False, False, True, False, True]
    for r, (first, second) in enumerate(((8, 8), (9, 1), (1, 9), (8, 0), (16, 16), (1, 1))):
        used = prepared.nz_start[r, 2]
        assert colours[r, :used].tolist() == [*range(n_bins - first, n_bins),
                                              *range(second)], r


@pytest.mark.parametrize("kernel", [KERNEL_UNIFORM, KERNEL_BOX, KERNEL_EPANECHNIKOV,
                                    KERNEL_CONE])
def test_the_direct_path_scores_boxes_as_wide_as_the_frame(kernel):
    """A row's scratch spans the frame: boxes covering every column (and beyond), of
    widths that are and are not multiples of the support path's 8-column padding, score
    as their histograms do on both direct paths."""
    rng = np.random.default_rng(5)
    for width in (8, 13, 64, 67):
        bin_img = rng.integers(0, 4, (20, width)).astype(np.int32)
        boxes = np.array([[0.0, 0.0, width, 20.0], [-3.0, 2.0, width + 6.0, 9.0],
                          [0.5, 1.0, width - 0.5, 7.0], [-1.0, -1.0, width + 1.0, 30.0]])
        refs = region_histograms(bin_img, boxes[[1, 0]], 4, kernel)
        index = np.array([0, 1, 0, 1])
        hists = region_histograms(bin_img, boxes, 4, kernel)
        expected = hist.bhattacharyya_distance(hists, refs[index])
        fracs, a_fixed = _level_args(kernel, 3)
        prepared = prepare_references(refs)
        for max_support in (-1, _SMALL_SUPPORT):
            d = _region_distances(bin_img, boxes, prepared.sqrt_refs, index, prepared.nz,
                                  prepared.nz_start, prepared.empty_rho, 4, kernel, 1,
                                  _lanes(4), METHODS["direct"], fracs, a_fixed, 2,
                                  max_support)[0]
            np.testing.assert_allclose(d**2, expected**2, rtol=0, atol=1e-12)
