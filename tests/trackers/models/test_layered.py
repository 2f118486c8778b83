"""trackers.models.layered and trackers.kernels.template: masked MSD matching per depth ordering."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackers.models.layered import MAX_OBJECTS, LayeredMatcher, orderings


def _texture(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    t = rng.integers(0, 256, (h // 4 + 2, w // 4 + 2, 3)).astype(np.float32)
    big = cv2.resize(t, (w + 8, h + 8), interpolation=cv2.INTER_CUBIC)
    return big[4 : 4 + h, 4 : 4 + w].clip(0, 255).astype(np.uint8)


def _reference(frame, matcher, centres, order, masking):
    """Plain numpy layered matching, exhaustive (step 1), nearest-centre tie-break."""
    h, w = frame.shape[:2]
    r = matcher.search_radius
    n_order, m_obj = order.shape
    pos = np.full((n_order, m_obj, 2), np.nan)
    mse = np.full((n_order, m_obj), np.nan)
    offs = [(dx, dy) for dy in range(-r, r + 1) for dx in range(-r, r + 1)]
    offs.sort(key=lambda o: o[0] ** 2 + o[1] ** 2)  # stable: row-major within a distance
    for l in range(n_order):
        masked = np.zeros((h, w), bool)
        for m in order[l]:
            th, tw = matcher.sizes[m]
            tpl = matcher.templates[m, :th, :tw].astype(np.int64)
            sup = matcher.support[m, :th, :tw]
            ox = matcher._tl0[m, 0] + int(np.round(centres[m, 0] - matcher._centre0[m, 0]))
            oy = matcher._tl0[m, 1] + int(np.round(centres[m, 1] - matcher._centre0[m, 1]))
            best, bpos = np.inf, None
            for dx, dy in offs:
                x, y = ox + dx, oy + dy
                acc, cnt = 0, 0
                for a in range(th):
                    for b in range(tw):
                        rr, cc = y + a, x + b
                        if sup[a, b] and 0 <= rr < h and 0 <= cc < w and not masked[rr, cc]:
                            d = frame[rr, cc].astype(np.int64) - tpl[a, b]
                            acc += int((d * d).sum())
                            cnt += 1
                if cnt >= matcher.min_visible * sup.sum() and cnt > 0 and acc / (3 * cnt) < best:
                    best, bpos = acc / (3 * cnt), (x, y)
            if bpos is None:
                continue
            mse[l, m] = best
            pos[l, m] = bpos
            if masking:
                x, y = bpos
                for a in range(th):
                    for b in range(tw):
                        if sup[a, b] and 0 <= y + a < h and 0 <= x + b < w:
                            masked[y + a, x + b] = True
    centres_out = matcher._centre0[None] + pos - matcher._tl0[None]
    return centres_out, mse


@settings(max_examples=12, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_obj=st.integers(1, 3),
    support=st.sampled_from(["box", "ellipse"]),
    masking=st.booleans(),
)
def test_kernel_matches_numpy_reference(seed, n_obj, support, masking):
    rng = np.random.default_rng(seed)
    h, w, size = 40, 48, 10
    frame0 = _texture(rng, h, w)
    boxes = np.column_stack(
        [rng.uniform(-3, w - size + 3, n_obj), rng.uniform(-3, h - size + 3, n_obj),
         np.full(n_obj, size), np.full(n_obj, size)]
    )
    matcher = LayeredMatcher(frame0, boxes, search_radius=3, step=1, support=support,
                             min_visible=0.3)
    frame = np.clip(frame0.astype(int) + rng.integers(-20, 21, frame0.shape), 0, 255)
    frame = frame.astype(np.uint8)
    centres = boxes[:, :2] + boxes[:, 2:] / 2 + rng.uniform(-2, 2, (n_obj, 2))
    order = orderings(n_obj)
    got = matcher.measure(frame, centres, order, masking=masking)
    want_c, want_e = _reference(frame, matcher, centres, order.astype(np.int64), masking)
    np.testing.assert_array_equal(np.isnan(got.mse), np.isnan(want_e))
    np.testing.assert_allclose(got.mse, want_e, rtol=1e-12)
    np.testing.assert_allclose(got.centres, want_c)


def _two_squares(rng, xa, xb, a_front, h=100, w=160, size=30, noise=3.0):
    bg = _texture(rng, h, w)
    ta, tb = _texture(rng, size, size), _texture(rng, size, size)

    def render(xa, xb, a_front, ya=30, yb=40):
        f = bg.copy()
        layers = [(xb, yb, tb), (xa, ya, ta)] if a_front else [(xa, ya, ta), (xb, yb, tb)]
        for x, y, t in layers:
            f[y : y + size, x : x + size] = t
        return np.clip(f + rng.normal(0, noise, f.shape), 0, 255).astype(np.uint8)

    boxes = np.array([[xa, 30, size, size], [xb, 40, size, size]], float)
    return render, boxes


def test_true_ordering_explains_the_overlap_best():
    rng = np.random.default_rng(0)
    render, boxes = _two_squares(rng, 20, 110, True)
    matcher = LayeredMatcher(render(20, 110, True), boxes, search_radius=6, blur=0.0)
    order = orderings(2)  # row 0: object 0 in front
    for a_front in (True, False):
        frame = render(60, 75, a_front)
        centres = np.array([[75.0, 45.0], [90.0, 55.0]])
        meas = matcher.measure(frame, centres, order)
        sse = (meas.mse * meas.counts).sum(axis=1) / meas.counts.sum(axis=1)
        truth = 0 if a_front else 1
        assert sse[truth] < 0.5 * sse[1 - truth]
        # Under the true ordering both objects are found where they are drawn.
        np.testing.assert_allclose(meas.centres[truth], centres)
        assert meas.n_searches == 4


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n_obj=st.integers(1, MAX_OBJECTS))
def test_distant_objects_are_matched_once_per_frame(seed, n_obj):
    rng = np.random.default_rng(seed)
    frame = _texture(rng, 120, 60 * n_obj)
    # One object per 60 px column: windows (radius 5) of 20 px objects never meet.
    x = 60 * np.arange(n_obj) + rng.uniform(8, 32, n_obj)
    y = rng.uniform(8, 92, n_obj)
    boxes = np.column_stack([x, y, np.full(n_obj, 20.0), np.full(n_obj, 20.0)])
    matcher = LayeredMatcher(frame, boxes, search_radius=5)
    moved = np.roll(frame, (int(rng.integers(-3, 4)), int(rng.integers(-3, 4))), axis=(0, 1))
    meas = matcher.measure(moved, boxes[:, :2] + 10, orderings(n_obj))
    assert meas.n_searches == n_obj
    assert (meas.mse == meas.mse[0]).all() and (meas.centres == meas.centres[0]).all()


def test_orderings_are_all_permutations():
    for n in range(1, MAX_OBJECTS + 1):
        o = orderings(n)
        assert o.dtype == np.int16 and o.shape == (math.factorial(n), n)
        assert len({tuple(r) for r in o}) == len(o)
        assert (np.sort(o, axis=1) == np.arange(n)).all()
        assert (o[0] == np.arange(n)).all()


def test_more_than_four_objects_is_refused_with_advice():
    with pytest.raises(ValueError, match=r"5 objects give 120 depth orderings.*at most 4.*group"):
        orderings(5)


def test_object_outside_the_frame_is_missed():
    rng = np.random.default_rng(2)
    frame = _texture(rng, 60, 80)
    matcher = LayeredMatcher(frame, [[30, 20, 16, 16]], search_radius=4)
    meas = matcher.measure(frame, [[200.0, 28.0]], orderings(1))
    assert np.isnan(meas.mse).all() and np.isnan(meas.centres).all()
    far = matcher.measure(frame, [[1e9, -1e9]], orderings(1))
    assert np.isnan(far.mse).all()


def test_coarse_to_fine_finds_smooth_texture_exactly():
    rng = np.random.default_rng(3)
    frame0 = _texture(rng, 100, 120)
    boxes = np.array([[40.0, 30.0, 30.0, 30.0]])
    matcher = LayeredMatcher(frame0, boxes, search_radius=8, step=2, blur=1.0)
    for dx, dy in [(3, -5), (-7, 2), (1, 1)]:
        frame = np.roll(frame0, (dy, dx), axis=(0, 1))
        meas = matcher.measure(frame, [[55.0, 45.0]], orderings(1))
        np.testing.assert_allclose(meas.centres[0, 0], [55 + dx, 45 + dy])
        assert meas.mse[0, 0] == 0.0


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(search_radius=0), "search_radius"),
        (dict(step=9), "step"),
        (dict(min_visible=1.5), "min_visible"),
        (dict(support="disc"), "unknown support 'disc'"),
        (dict(blur=np.inf), "blur"),
        # Booleans are refused, as documented (True was a radius, a stride of 1).
        (dict(search_radius=True), "search_radius must be an int in \\[1, 200\\], got True"),
        (dict(step=True), "step must be an int in \\[1, 8\\], got True"),
    ],
)
def test_bad_matcher_parameters(kwargs, match):
    frame = np.zeros((20, 20, 3), np.uint8)
    with pytest.raises(ValueError, match=match):
        LayeredMatcher(frame, [[2, 2, 5, 5]], **kwargs)


def test_window_blur_equals_whole_frame_blur():
    rng = np.random.default_rng(6)
    frame0 = _texture(rng, 90, 140)
    boxes = np.array(
        [[-5.0, 10.0, 24.0, 20.0], [60.0, 40.0, 30.0, 30.0], [110.0, 62.0, 26.0, 26.0]]
    )
    sigma = 1.7
    blurred = LayeredMatcher(frame0, boxes, search_radius=6, blur=sigma, step=1)
    plain = LayeredMatcher(
        cv2.GaussianBlur(frame0, (0, 0), sigma, borderType=cv2.BORDER_REPLICATE), boxes,
        search_radius=6, blur=0.0, step=1,
    )
    np.testing.assert_array_equal(blurred.templates, plain.templates)
    frame = np.roll(frame0, (2, -3), axis=(0, 1))
    centres = boxes[:, :2] + boxes[:, 2:] / 2 + [[-2.0, 1.0], [1.0, 2.0], [-3.0, 3.0]]
    order = orderings(3)
    a = blurred.measure(frame, centres, order)
    b = plain.measure(
        cv2.GaussianBlur(frame, (0, 0), sigma, borderType=cv2.BORDER_REPLICATE), centres, order
    )
    np.testing.assert_array_equal(a.mse, b.mse)
    np.testing.assert_array_equal(a.centres, b.centres)


def _uncut(matcher, frame, boxes, support):
    """``matcher`` with templates the size of the whole boxes (the matcher before its
    templates were cut to frame 0): pixels outside frame 0 present but not in support."""
    b = np.asarray(boxes, dtype=np.float64)
    h, w = frame.shape[:2]
    tl = np.round(b[:, :2]).astype(np.int64)
    size = np.maximum(np.round(b[:, 2:]).astype(np.int64), 1)
    tl[:, 0] = np.clip(tl[:, 0], 1 - size[:, 0], w - 1)
    tl[:, 1] = np.clip(tl[:, 1], 1 - size[:, 1], h - 1)
    m = len(b)
    tpl = np.zeros((m, size[:, 1].max(), size[:, 0].max(), 3), np.uint8)
    sup = np.zeros(tpl.shape[:3], bool)
    for k in range(m):
        tw, th = size[k]
        yy, xx = np.mgrid[0:th, 0:tw]
        s = (np.ones((th, tw), bool) if support == "box" else
             ((xx + 0.5) / tw * 2 - 1) ** 2 + ((yy + 0.5) / th * 2 - 1) ** 2 <= 1)
        if support != "box":
            s[th // 2, tw // 2] = True
        rows, cols = np.arange(tl[k, 1], tl[k, 1] + th), np.arange(tl[k, 0], tl[k, 0] + tw)
        inside = ((rows >= 0) & (rows < h))[:, None] & ((cols >= 0) & (cols < w))[None, :]
        s = s & inside if (s & inside).any() else inside
        tpl[k, :th, :tw] = frame[rows.clip(0, h - 1)[:, None], cols.clip(0, w - 1)[None, :]]
        sup[k, :th, :tw] = s
    matcher.templates, matcher.support = tpl, sup
    matcher.sizes = np.stack([size[:, 1], size[:, 0]], axis=1).astype(np.int64)
    matcher._tl0, matcher._n_support = tl, sup.sum(axis=(1, 2))
    return matcher


@pytest.mark.parametrize("support", ["box", "ellipse"])
@pytest.mark.parametrize("seed", range(4))
def test_templates_cut_to_frame_zero_match_as_the_whole_boxes(seed, support):
    rng = np.random.default_rng(seed)
    frame = _texture(rng, 60, 80)
    # Boxes half outside frame 0 on every side, and one inside.
    boxes = np.array([[-9.0, 10, 20, 16], [70, 30, 18, 20], [30, -8, 16, 18],
                      [25, 50, 22, 17], [30, 20, 14, 12]])[rng.permutation(5)[:4]]
    kw = dict(search_radius=6, step=1, support=support, min_visible=0.2)
    cut = LayeredMatcher(frame, boxes, **kw)
    whole = _uncut(LayeredMatcher(frame, boxes, **kw), frame, boxes, support)
    assert cut.templates.shape[1] <= 60 and cut.templates.shape[2] <= 80
    nxt = np.roll(frame, (int(rng.integers(-3, 4)), int(rng.integers(-3, 4))), axis=(0, 1))
    order = orderings(4)
    for _ in range(5):
        centres = boxes[:, :2] + boxes[:, 2:] / 2 + rng.uniform(-12, 12, (4, 2))
        a, b = cut.measure(nxt, centres, order), whole.measure(nxt, centres, order)
        assert np.array_equal(a.centres, b.centres, equal_nan=True)
        assert np.array_equal(a.mse, b.mse, equal_nan=True)
        assert np.array_equal(a.counts, b.counts)


def test_a_box_far_larger_than_the_frame_takes_the_frame_s_memory():
    frame = _texture(np.random.default_rng(0), 60, 80)
    matcher = LayeredMatcher(frame, [[-1e6, -1e6, 3e6, 3e6]], step=1)
    assert matcher.templates.shape == (1, 60, 80, 3)
    meas = matcher.measure(frame, [[5e5, 5e5]], orderings(1))
    assert meas.centres.shape == (1, 1, 2)
