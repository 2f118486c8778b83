"""Direct path: kernel-weighted histograms accumulated pixel by pixel (numba).

``_region_histograms`` builds the histograms of many boxes; ``_direct_distance`` one box's
Bhattacharyya distance to its reference, from the whole histogram or, for a reference with
few support bins, from those bins' counts alone (the support path). Both visit every pixel
of the box; the weights come from ``trackers.kernels.profiles``. Called by the public
entry points of ``trackers.kernels.histogram``, whose module docstring gives the
conventions.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trackers.kernels.profiles import (
    _ONE,
    KERNEL_BOX,
    KERNEL_EPANECHNIKOV,
    KERNEL_UNIFORM,
    _box_row_weights,
    _cone_weights,
    _epanechnikov_weights,
    _level_rects,
    _next_change,
    _pixel_range,
)

__all__: list[str] = []

# A small histogram is kept in four copies (copy l at l * dim, "lanes") and four
# consecutive pixels of a row go to the four copies: on a flat region every pixel hits the
# same bin, and with one copy each add waits for the previous one's store; with four, four
# independent chains run at once (measured: a DPS frame's likelihoods 34% faster). The
# copies are summed when the histogram is read. Large histograms (RGB 10x10x10) keep one
# copy: clearing four copies of 1000 bins per box costs more than the chains it breaks.
# Indices are unsigned so that numba emits no negative-index wrap-around per pixel.
_SMALL_BINS = 256


def _lanes(dim):
    """Copies of a histogram of ``dim`` bins (see above)."""
    return 4 if dim <= _SMALL_BINS else 1


@njit(cache=True)
def _scatter(hist, dim, lanes, row, c0, c1, base, kbuf):
    """Add kbuf[c − c0] to bin base + row[c] for c in [c0, c1); returns Σ kbuf.

    With four lanes, pixel c goes to copy (c − c0) mod 4 of the histogram (copy l at
    l * dim); with one, to the single copy.
    """
    ub = np.uint64(base)
    acc = 0
    n = c1 - c0
    i = 0
    if lanes == 4:
        s1 = np.uint64(dim)
        s2 = np.uint64(2 * dim)
        s3 = np.uint64(3 * dim)
        while i + 4 <= n:
            k0 = kbuf[i]
            k1 = kbuf[i + 1]
            k2 = kbuf[i + 2]
            k3 = kbuf[i + 3]
            hist[ub + np.uint64(row[c0 + i])] += k0
            hist[s1 + ub + np.uint64(row[c0 + i + 1])] += k1
            hist[s2 + ub + np.uint64(row[c0 + i + 2])] += k2
            hist[s3 + ub + np.uint64(row[c0 + i + 3])] += k3
            acc += k0 + k1 + k2 + k3
            i += 4
    while i < n:
        k = kbuf[i]
        hist[ub + np.uint64(row[c0 + i])] += k
        acc += k
        i += 1
    return acc


@njit(cache=True)
def _scatter_unit(hist, row, c0, c1, base, unit):
    """As ``_scatter`` with one copy and the same weight ``unit`` for every pixel."""
    ub = np.uint64(base)
    for c in range(c0, c1):
        hist[ub + np.uint64(row[c])] += unit
    return (c1 - c0) * unit


# The support path of ``region_distances``' direct evaluation: a reference whose bands
# each have at most _SMALL_SUPPORT bins with q > 0 (flat-coloured targets: 1-3 bins) needs
# only those bins' counts and each band's total, not the whole histogram. Each row then
# costs one vectorised pass per two support bins (the weight of the pixels of either
# colour, and of all pixels), over the row's columns padded to a multiple of 8 with
# zero-weight pixels (so no scalar remainder), instead of one scattered add per pixel.
# The sums are the same integers as the scattered histogram's (integer adds in any order),
# so both paths give the same bits; measured on dps-synthetic and dps-occlusion frames, a
# box of a flat target about 2x faster.
_SMALL_SUPPORT = 8
_PAD = 8
# A dx² no fixed-point row weight reaches (at most _ONE): padding columns weigh 0.
_FAR = np.int64(1) << 40


@njit(cache=True)
def _pair_sums(kbuf, seg, ca, cb):
    """(Σ kbuf[i], Σ kbuf[i] [seg[i] = ca], Σ kbuf[i] [seg[i] = cb]) over i < len(seg)
    (vectorised loop; a colour of −1 matches nothing)."""
    tot = 0
    sa = 0
    sb = 0
    for i in range(seg.shape[0]):
        k = kbuf[i]
        v = seg[i]
        tot += k
        sa += k if v == ca else 0
        sb += k if v == cb else 0
    return tot, sa, sb


@njit(cache=True)
def _epanechnikov_pair_sums(tbuf, wr, seg, ca, cb):
    """``_pair_sums`` with the Epanechnikov weights max(wr − tbuf[i], 0) computed in the
    loop (``_epanechnikov_weights``)."""
    tot = 0
    sa = 0
    sb = 0
    for i in range(seg.shape[0]):
        k = max(wr - tbuf[i], 0)
        v = seg[i]
        tot += k
        sa += k if v == ca else 0
        sb += k if v == cb else 0
    return tot, sa, sb


@njit(cache=True)
def _accumulate(bin_img, x, y, w, h, n_bins, kernel, n_parts, hist, lanes, totals, tbuf,
                kbuf, fracs, a_fixed, rects):
    """Add the fixed-point weighted pixels of box [x, y, w, h] into ``hist``.

    ``hist`` (lanes * n_parts * n_bins, int64) receives the weights in ``lanes`` copies,
    ``totals`` (n_parts, int64) each band's total; ``tbuf`` and ``kbuf`` (W,) are
    scratch. Every pixel of the box's rows is visited; those outside the kernel's ellipse
    get weight 0 (finding each row's chord costs more than the pixels it skips). For the
    box kernel, ``fracs`` and ``a_fixed`` (L,) are its levels and ``rects`` (L, 4) scratch.
    """
    rows, cols = bin_img.shape
    r0, r1 = _pixel_range(y, h, rows)
    c0, c1 = _pixel_range(x, w, cols)
    for j in range(n_parts):
        totals[j] = 0
    if r0 >= r1 or c0 >= c1:
        return
    dim = n_parts * n_bins
    n = c1 - c0
    cx = x + 0.5 * w
    cy = y + 0.5 * h
    inv_hw = 2.0 / w
    inv_hh = 2.0 / h
    band = h / n_parts
    if kernel == KERNEL_UNIFORM:
        unit = np.int64(_ONE)
        for i in range(n):
            kbuf[i] = unit
    elif kernel == KERNEL_EPANECHNIKOV:
        # Separable: k = (1 − dy²) − dx², in fixed point, clamped to 0 outside the
        # ellipse; dx² is tabulated once per box.
        for c in range(c0, c1):
            dx = (c + 0.5 - cx) * inv_hw
            tbuf[c - c0] = np.int64(dx * dx * _ONE + 0.5)
    elif kernel == KERNEL_BOX:
        _level_rects(x, y, w, h, fracs, rows, cols, rects)
    # Box kernel: the rectangles covering a row change only at their first and last rows
    # (at most 2L times down the box), and the row's weights only then.
    change = r0
    for r in range(r0, r1):
        py = r + 0.5
        part = int((py - y) / band)
        if part >= n_parts:
            part = n_parts - 1
        if kernel == KERNEL_BOX:
            if r >= change:
                _box_row_weights(kbuf, n, c0, r, rects, a_fixed)
                change = _next_change(rects, r, r1)
        elif kernel != KERNEL_UNIFORM:
            dy = (py - cy) * inv_hh
            dy2 = dy * dy
            if dy2 >= 1.0:
                continue
            if kernel == KERNEL_EPANECHNIKOV:
                _epanechnikov_weights(kbuf, tbuf, n, np.int64((1.0 - dy2) * _ONE + 0.5))
            else:
                _cone_weights(kbuf, c0, c1, cx, inv_hw, dy2)
        if kernel == KERNEL_UNIFORM and lanes == 1:
            totals[part] += _scatter_unit(hist, bin_img[r], c0, c1, part * n_bins,
                                          np.int64(_ONE))
        else:
            totals[part] += _scatter(hist, dim, lanes, bin_img[r], c0, c1, part * n_bins,
                                     kbuf)


@njit(cache=True)
def _accumulate_support(bin_img, x, y, w, h, kernel, n_parts, colours, nz_start, sums,
                        totals, tbuf, kbuf, fracs, a_fixed, rects):
    """As ``_accumulate``, but only the weights of the support colours: band j's support
    bins t in [nz_start[j], nz_start[j + 1]) (colour ``colours[t]`` of the band) get their
    fixed-point weight in ``sums[t]``, each band its total in ``totals[j]`` (the support
    path, see ``_SMALL_SUPPORT``). ``tbuf`` and ``kbuf`` (W,) are scratch."""
    rows, cols = bin_img.shape
    r0, r1 = _pixel_range(y, h, rows)
    c0, c1 = _pixel_range(x, w, cols)
    for j in range(n_parts):
        totals[j] = 0
    for t in range(nz_start[n_parts]):
        sums[t] = 0
    if r0 >= r1 or c0 >= c1:
        return
    n = c1 - c0
    # Columns [s0, s0 + m) hold [c0, c1) and m is a multiple of _PAD (when the frame is that
    # wide); the added columns weigh 0.
    m = (n + _PAD - 1) // _PAD * _PAD
    if m <= cols:
        s0 = min(c0, cols - m)
    else:
        s0 = c0
        m = n
    off = c0 - s0
    cx = x + 0.5 * w
    cy = y + 0.5 * h
    inv_hw = 2.0 / w
    inv_hh = 2.0 / h
    band = h / n_parts
    fused = kernel == KERNEL_EPANECHNIKOV
    if fused:
        for i in range(m):
            tbuf[i] = _FAR
        for c in range(c0, c1):
            dx = (c + 0.5 - cx) * inv_hw
            tbuf[c - s0] = np.int64(dx * dx * _ONE + 0.5)
    else:
        for i in range(m):
            kbuf[i] = 0
        if kernel == KERNEL_UNIFORM:
            unit = np.int64(_ONE)
            for i in range(off, off + n):
                kbuf[i] = unit
        elif kernel == KERNEL_BOX:
            _level_rects(x, y, w, h, fracs, rows, cols, rects)
    kcols = kbuf[off:]
    wr = np.int64(0)
    change = r0
    for r in range(r0, r1):
        py = r + 0.5
        part = int((py - y) / band)
        if part >= n_parts:
            part = n_parts - 1
        if kernel == KERNEL_BOX:
            if r >= change:
                _box_row_weights(kcols, n, c0, r, rects, a_fixed)
                change = _next_change(rects, r, r1)
        elif kernel != KERNEL_UNIFORM:
            dy = (py - cy) * inv_hh
            dy2 = dy * dy
            if dy2 >= 1.0:
                continue
            if fused:
                wr = np.int64((1.0 - dy2) * _ONE + 0.5)
            else:
                _cone_weights(kcols, c0, c1, cx, inv_hw, dy2)
        seg = bin_img[r, s0:s0 + m]
        # One pass per two support colours (−1 matches nothing); the first also totals.
        ta = nz_start[part]
        tb = nz_start[part + 1]
        ca = colours[ta] if ta < tb else -1
        cb = colours[ta + 1] if ta + 1 < tb else -1
        if fused:
            row_tot, sa, sb = _epanechnikov_pair_sums(tbuf, wr, seg, ca, cb)
        else:
            row_tot, sa, sb = _pair_sums(kbuf, seg, ca, cb)
        totals[part] += row_tot
        if ta < tb:
            sums[ta] += sa
        if ta + 1 < tb:
            sums[ta + 1] += sb
        for t in range(ta + 2, tb, 2):
            ca = colours[t]
            cb = colours[t + 1] if t + 1 < tb else -1
            if fused:
                row_tot, sa, sb = _epanechnikov_pair_sums(tbuf, wr, seg, ca, cb)
            else:
                row_tot, sa, sb = _pair_sums(kbuf, seg, ca, cb)
            sums[t] += sa
            if t + 1 < tb:
                sums[t + 1] += sb


@njit(cache=True)
def _region_histograms(bin_img, boxes, n_bins, kernel, n_parts, lanes, fracs, a_fixed):
    n_boxes = boxes.shape[0]
    dim = n_parts * n_bins
    out = np.empty((n_boxes, dim))
    hist = np.zeros(lanes * dim, dtype=np.int64)
    totals = np.empty(n_parts, dtype=np.int64)
    tbuf = np.empty(bin_img.shape[1], dtype=np.int64)
    kbuf = np.empty(bin_img.shape[1], dtype=np.int64)
    rects = np.empty((max(fracs.shape[0], 1), 4), dtype=np.int64)
    for p in range(n_boxes):
        _accumulate(bin_img, boxes[p, 0], boxes[p, 1], boxes[p, 2], boxes[p, 3], n_bins,
                    kernel, n_parts, hist, lanes, totals, tbuf, kbuf, fracs, a_fixed, rects)
        for j in range(n_parts):
            lo = j * n_bins
            if totals[j] > 0:
                scale = 1.0 / (totals[j] * n_parts)
                for b in range(lo, lo + n_bins):
                    s = 0
                    for k in range(lanes):
                        s += hist[k * dim + b]
                    out[p, b] = s * scale
            else:
                fill = 1.0 / (n_bins * n_parts)
                for b in range(lo, lo + n_bins):
                    out[p, b] = fill
        hist[:] = 0
    return out


@njit(cache=True)
def _band_rho(hist, dim, lanes, sqrt_q, nz, i0, i1, scale):
    """Σ sqrt(h_b · scale) sqrt(q_b) over the bins nz[i0:i1] (those where q_b > 0)."""
    acc = 0.0
    for i in range(i0, i1):
        b = nz[i]
        s = 0
        for k in range(lanes):
            s += hist[k * dim + b]
        acc += np.sqrt(s * scale) * sqrt_q[b]
    return acc


@njit(cache=True)
def _sums_rho(sums, sqrt_q, nz, i0, i1, scale):
    """``_band_rho`` of the support path: the counts of support bins i0 … i1 − 1 are
    ``sums[i0:i1]``."""
    acc = 0.0
    for i in range(i0, i1):
        acc += np.sqrt(sums[i] * scale) * sqrt_q[nz[i]]
    return acc


@njit(cache=True)
def _direct_distance(bin_img, box, sqrt_q, nz, nz_start, empty_rho, n_bins, kernel,
                     n_parts, hist, lanes, totals, tbuf, kbuf, fracs, a_fixed, rects,
                     colours, sums, small):
    """Bhattacharyya distance of one box to one reference by accumulating its pixels:
    the whole histogram, or (``small``) only the reference's support bins, whose band
    colours are ``colours`` (the support path, ``_SMALL_SUPPORT``). Both give the same
    bits: the same fixed-point counts, read in the same order."""
    dim = n_parts * n_bins
    if small:
        _accumulate_support(bin_img, box[0], box[1], box[2], box[3], kernel, n_parts,
                            colours, nz_start, sums, totals, tbuf, kbuf, fracs, a_fixed,
                            rects)
    else:
        _accumulate(bin_img, box[0], box[1], box[2], box[3], n_bins, kernel, n_parts, hist,
                    lanes, totals, tbuf, kbuf, fracs, a_fixed, rects)
    rho = 0.0
    for j in range(n_parts):
        if totals[j] > 0:
            # Bins where the reference is 0 add nothing: only its support is read.
            scale = 1.0 / (totals[j] * n_parts)
            if small:
                rho += _sums_rho(sums, sqrt_q, nz, nz_start[j], nz_start[j + 1], scale)
            else:
                rho += _band_rho(hist, dim, lanes, sqrt_q, nz, nz_start[j], nz_start[j + 1],
                                 scale)
        else:
            # Uniform band (module docstring).
            rho += empty_rho[j]
    if not small:
        hist[:] = 0
    one_minus = 1.0 - rho
    return np.sqrt(one_minus) if one_minus > 0.0 else 0.0
