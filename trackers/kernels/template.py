"""Masked template matching by mean squared difference, for all objects and orderings.

One compiled call measures every object of a frame under every depth ordering (the
layered hypothesized measurements of the SHM paper, §3.1): for ordering ``j`` the objects
are matched front to back, each one ignoring the pixels covered by the supports of the
objects already matched in front of it. With ``masking=False`` and a single ordering the
same call is plain, independent template matching of every object.

Matching an object (top-left corner ``(x, y)`` of its template, integer pixels):

    e(x, y) = Σ_{p ∈ V(x, y)} ||I(x + p) − T(p)||² / (3 |V(x, y)|)

where ``V(x, y)`` are the support pixels ``p`` of the template whose image pixel lies in
the frame and is not masked. A candidate is valid only if ``|V| ≥ min_visible · |support|``
(so a few stray pixels cannot win); the measurement is the valid candidate of smallest
``e`` in the search window ``[ox − r, ox + r] × [oy − r, oy + r]``. No valid candidate
(the object left the frame, or is hidden by the objects in front) is a missed measurement.

Search: candidates are visited nearest the window centre (the prediction) first; a
candidate whose partial sum already exceeds the best score times the largest possible
pixel count is abandoned after that template row (its mean can only be larger), which
never changes the result. Template rows are visited interleaved (0, 16, 8, 24, ...) so that
a partial sum is representative early. With ``step`` > 1 a coarse pass first scores the
candidates on a grid of stride ``step`` with the template subsampled by ``step``, then a
full-resolution pass scores the ``(2 step − 1)²`` candidates around the coarse winner:
faster, but it can miss the optimum of fine, high-frequency textures; ``step`` = 1 is
exhaustive.

Measured on ``shm-crossing`` (two ~40x40 objects, radius 12, all 2 orderings, the calls
of a ``shm-fast`` run replayed, CPU time per call): step 1 1.6 ms, without the early
exit 7.0 ms; step 2 0.3 ms, without the early exit 0.8 ms. A branch-free row loop (0/1
weights on a padded copy of the window) measured slower, 2.5 ms for step 1.

Orderings that cannot differ are not recomputed: the match of object ``m`` depends only on
the front objects whose footprint intersects ``m``'s search region and on where they were
matched, so results are memoised on (``m``, those objects, their positions). Objects that
never come close are matched once per frame whatever the number of orderings.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["layered_match"]


@njit(cache=True)
def _fill_valid(h, w, rx, ry, valid, support, sizes, front, n_front, front_pos):  # pragma: no cover
    """valid[i, j]: region pixel (ry + i, rx + j) lies in the frame and is not masked."""
    rh, rw = valid.shape
    for i in range(rh):
        r = ry + i
        for j in range(rw):
            c = rx + j
            valid[i, j] = r >= 0 and r < h and c >= 0 and c < w
    for k in range(n_front):
        f = front[k]
        fx = front_pos[k, 0]
        fy = front_pos[k, 1]
        for a in range(sizes[f, 0]):
            i = fy + a - ry
            if i < 0 or i >= rh:
                continue
            for b in range(sizes[f, 1]):
                j = fx + b - rx
                if j >= 0 and j < rw and support[f, a, b]:
                    valid[i, j] = False


@njit(cache=True)
def _score(
    frame, rx, ry, valid, tpl, sup, rows, tw, dx, dy, s, n_max, min_count, best
):  # pragma: no cover
    """(mean squared difference, pixels compared) of one candidate.

    The score is inf if too few pixels are compared or the candidate cannot beat ``best``.
    """
    acc = np.int64(0)
    cnt = 0
    # A partial sum above this bound can never beat ``best``: the mean divides by at most
    # 3 n_max.
    bound = best * 3.0 * n_max
    for k in range(rows.shape[0]):
        a = rows[k]
        i = dy + a
        r = ry + i
        for b in range(0, tw, s):
            j = dx + b
            if sup[a, b] and valid[i, j]:
                c = rx + j
                d0 = np.int64(frame[r, c, 0]) - np.int64(tpl[a, b, 0])
                d1 = np.int64(frame[r, c, 1]) - np.int64(tpl[a, b, 1])
                d2 = np.int64(frame[r, c, 2]) - np.int64(tpl[a, b, 2])
                acc += d0 * d0 + d1 * d1 + d2 * d2
                cnt += 1
        if acc > bound:
            return np.inf, cnt
    if cnt < min_count or cnt == 0:
        return np.inf, cnt
    return acc / (3.0 * cnt), cnt


@njit(cache=True)
def _row_order(th, s):  # pragma: no cover - compiled
    """Template rows 0, s, 2s, ... in coarse-to-fine interleaved order (0, 16s, 8s, ...).

    Spread-out rows make a partial sum representative early, so that a poor candidate is
    abandoned after fewer rows.
    """
    n = (th + s - 1) // s
    out = np.empty(n, dtype=np.int64)
    taken = np.zeros(n, dtype=np.bool_)
    k = 0
    g = 1
    while g * 2 < n:
        g *= 2
    while g >= 1:
        for q in range(0, n, g):
            if not taken[q]:
                taken[q] = True
                out[k] = q * s
                k += 1
        g //= 2
    return out


@njit(cache=True)
def _centre_out(radius):  # pragma: no cover - compiled
    """Window offsets (dx, dy) in [0, 2 radius]², nearest the window centre first."""
    span = 2 * radius + 1
    d2 = np.empty(span * span, dtype=np.int64)
    for dy in range(span):
        for dx in range(span):
            d2[dy * span + dx] = (dx - radius) ** 2 + (dy - radius) ** 2
    idx = np.argsort(d2, kind="mergesort")
    out = np.empty((span * span, 2), dtype=np.int64)
    for k in range(span * span):
        out[k, 0] = idx[k] % span
        out[k, 1] = idx[k] // span
    return out


@njit(cache=True)
def _match(
    frame, tpl, sup, th, tw, radius, step, min_visible, valid, rx, ry, offsets
):  # pragma: no cover - compiled
    """Best top-left (x, y), its score and pixel count; score inf if none is valid.

    Candidates are visited nearest the predicted position first, so that a good score is
    found early and most other candidates are abandoned after a few template rows.
    """
    span = 2 * radius
    n_full = 0
    n_sub = 0
    for a in range(th):
        for b in range(tw):
            if sup[a, b]:
                n_full += 1
                if a % step == 0 and b % step == 0:
                    n_sub += 1
    rows_sub = _row_order(th, step)
    rows_full = _row_order(th, 1)
    bx = -1
    by = -1
    lo_x = 0
    hi_x = span
    lo_y = 0
    hi_y = span
    if step > 1:
        best = np.inf
        min_sub = min_visible * n_sub
        for k in range(offsets.shape[0]):
            dx = offsets[k, 0]
            dy = offsets[k, 1]
            if dx % step != 0 or dy % step != 0:
                continue
            e, _ = _score(frame, rx, ry, valid, tpl, sup, rows_sub, tw, dx, dy, step, n_sub,
                          min_sub, best)
            if e < best:
                best = e
                bx = dx
                by = dy
        if bx < 0:
            return 0, 0, np.inf, 0
        lo_x = max(bx - step + 1, 0)
        hi_x = min(bx + step - 1, span)
        lo_y = max(by - step + 1, 0)
        hi_y = min(by + step - 1, span)
    best = np.inf
    best_n = 0
    bx = -1
    by = -1
    min_full = min_visible * n_full
    for k in range(offsets.shape[0]):
        dx = offsets[k, 0]
        dy = offsets[k, 1]
        if dx < lo_x or dx > hi_x or dy < lo_y or dy > hi_y:
            continue
        e, n = _score(frame, rx, ry, valid, tpl, sup, rows_full, tw, dx, dy, 1, n_full, min_full,
                      best)
        if e < best:
            best = e
            best_n = n
            bx = dx
            by = dy
    if bx < 0:
        return 0, 0, np.inf, 0
    return rx + bx, ry + by, best, best_n


@njit(cache=True)
def layered_match(
    frame, templates, support, sizes, origins, active, radius, step, orderings, masking,
    min_visible, out_pos, out_mse, out_count,
):  # pragma: no cover - compiled
    """Match every object under every depth ordering, front to back.

    Parameters
    ----------
    frame : ndarray of shape (H, W, 3), uint8
    templates : ndarray of shape (M, TH, TW, 3), uint8
        Reference images, padded to the largest template size.
    support : ndarray of shape (M, TH, TW), bool
        Template pixels that are matched and, once matched, mask the objects behind.
    sizes : ndarray of shape (M, 2), int64
        Template (height, width) of each object.
    origins : ndarray of shape (M, 2), int64
        Centre (x, y) of each search window, as a template top-left corner.
    active : ndarray of shape (M,), bool
        Objects to measure; the others are missed under every ordering (and mask nothing).
    radius, step : int
        Search window half-size in pixels; coarse-to-fine stride (1 = exhaustive).
    orderings : ndarray of shape (L, M), int64
        Each row lists object indices nearest first.
    masking : bool
        Mask the pixels of objects matched in front (False: independent matching).
    min_visible : float
        Smallest fraction of a template's support that must be compared.
    out_pos : ndarray of shape (L, M, 2), int64
        Written: matched top-left (x, y) of object m under ordering l (0 if missed).
    out_mse : ndarray of shape (L, M), float64
        Written: mean squared difference per channel, NaN for a missed measurement.
    out_count : ndarray of shape (L, M), int64
        Written: number of pixels compared by each match (0 if missed).

    Returns
    -------
    int
        Number of template searches actually run (memoised repeats excluded).
    """
    h = frame.shape[0]
    w = frame.shape[1]
    n_order, m_obj = orderings.shape
    # Memo of the searches run: (object, front objects and their positions) -> result.
    n_memo_max = n_order * m_obj
    memo_obj = np.empty(n_memo_max, dtype=np.int64)
    memo_bits = np.empty(n_memo_max, dtype=np.int64)
    memo_fpos = np.zeros((n_memo_max, m_obj, 2), dtype=np.int64)
    memo_pos = np.empty((n_memo_max, 2), dtype=np.int64)
    memo_mse = np.empty(n_memo_max, dtype=np.float64)
    memo_cnt = np.empty(n_memo_max, dtype=np.int64)
    n_memo = 0
    front = np.empty(m_obj, dtype=np.int64)
    front_pos = np.empty((m_obj, 2), dtype=np.int64)
    matched = np.zeros(m_obj, dtype=np.bool_)
    pos = np.zeros((m_obj, 2), dtype=np.int64)
    th_max = templates.shape[1]
    tw_max = templates.shape[2]
    valid = np.empty((th_max + 2 * radius, tw_max + 2 * radius), dtype=np.bool_)
    offsets = _centre_out(radius)
    n_run = 0
    for l in range(n_order):
        matched[:] = False
        for d in range(m_obj):
            m = orderings[l, d]
            th = sizes[m, 0]
            tw = sizes[m, 1]
            rx = origins[m, 0] - radius
            ry = origins[m, 1] - radius
            if not active[m]:
                _write_missed(out_pos, out_mse, out_count, l, m)
                continue
            n_front = 0
            bits = np.int64(0)
            if masking:
                n_front, bits = _front_objects(orderings[l], d, matched, pos, sizes, rx, ry,
                                               tw + 2 * radius, th + 2 * radius, front,
                                               front_pos)
            hit = _memo_find(memo_obj, memo_bits, memo_fpos, n_memo, m, bits, front,
                             front_pos, n_front)
            if hit < 0:
                sub = valid[: th + 2 * radius, : tw + 2 * radius]
                _fill_valid(h, w, rx, ry, sub, support, sizes, front, n_front, front_pos)
                x, y, e, cnt = _match(frame, templates[m], support[m], th, tw, radius, step,
                                      min_visible, sub, rx, ry, offsets)
                n_run += 1
                hit = n_memo
                _memo_store(memo_obj, memo_bits, memo_fpos, memo_pos, memo_mse, memo_cnt,
                            hit, m, bits, front, front_pos, n_front, x, y, e, cnt)
                n_memo += 1
            e = memo_mse[hit]
            if np.isfinite(e):
                matched[m] = True
                pos[m, 0] = memo_pos[hit, 0]
                pos[m, 1] = memo_pos[hit, 1]
                out_pos[l, m, 0] = pos[m, 0]
                out_pos[l, m, 1] = pos[m, 1]
                out_mse[l, m] = e
                out_count[l, m] = memo_cnt[hit]
            else:
                _write_missed(out_pos, out_mse, out_count, l, m)
    return n_run


@njit(cache=True)
def _front_objects(order, d, matched, pos, sizes, rx, ry, rw, rh, front,
                   front_pos):  # pragma: no cover - compiled
    """The objects before position ``d`` of ``order`` that were matched and whose
    footprint meets the search region [rx, rx + rw) × [ry, ry + rh).

    Writes them and their matched top-left corners into ``front`` and ``front_pos``;
    returns their number and their set as a bit mask (bit f for object f).
    """
    n_front = 0
    bits = np.int64(0)
    for dd in range(d):
        f = order[dd]
        if not matched[f]:
            continue
        fx = pos[f, 0]
        fy = pos[f, 1]
        overlap_x = fx < rx + rw and fx + sizes[f, 1] > rx
        if overlap_x and fy < ry + rh and fy + sizes[f, 0] > ry:
            front[n_front] = f
            front_pos[n_front, 0] = fx
            front_pos[n_front, 1] = fy
            n_front += 1
            bits |= np.int64(1) << f
    return n_front, bits


@njit(cache=True)
def _memo_find(memo_obj, memo_bits, memo_fpos, n_memo, m, bits, front, front_pos,
               n_front):  # pragma: no cover - compiled
    """Index of the memoised search of object ``m`` behind the same front objects at the
    same positions, or -1."""
    for k in range(n_memo):
        if memo_obj[k] != m or memo_bits[k] != bits:
            continue
        same = True
        for q in range(n_front):
            f = front[q]
            if memo_fpos[k, f, 0] != front_pos[q, 0] or memo_fpos[k, f, 1] != front_pos[q, 1]:
                same = False
                break
        if same:
            return k
    return -1


@njit(cache=True)
def _memo_store(memo_obj, memo_bits, memo_fpos, memo_pos, memo_mse, memo_cnt, k, m, bits,
                front, front_pos, n_front, x, y, e, cnt):  # pragma: no cover - compiled
    """Record the search of object ``m`` behind ``front`` as memo entry ``k``."""
    memo_obj[k] = m
    memo_bits[k] = bits
    for q in range(n_front):
        memo_fpos[k, front[q], 0] = front_pos[q, 0]
        memo_fpos[k, front[q], 1] = front_pos[q, 1]
    memo_pos[k, 0] = x
    memo_pos[k, 1] = y
    memo_mse[k] = e
    memo_cnt[k] = cnt


@njit(cache=True)
def _write_missed(out_pos, out_mse, out_count, l, m):  # pragma: no cover - compiled
    """Object ``m`` is missed under ordering ``l``."""
    out_pos[l, m, 0] = 0
    out_pos[l, m, 1] = 0
    out_mse[l, m] = np.nan
    out_count[l, m] = 0

