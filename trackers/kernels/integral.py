"""Integral-histogram path: uniform- and box-kernel distances in O(levels × bins) per box.

Per reference, ``_integral_distances`` builds the integral histogram (Porikli 2005) of the
reference's support bins over the union of its boxes, then scores every box from four
corner reads per support bin and level, whatever its size. The counts are the direct
path's (``trackers.kernels.direct``) up to a power-of-two scale, read in the same order,
so both paths give the same bits. Called by ``trackers.kernels.histogram``, which chooses
the path per reference.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from trackers.kernels.profiles import KERNEL_BOX, _level_rects, _pixel_range

__all__: list[str] = []


@njit(cache=True)
def _band_rows(y, h, n_parts, r0, r1, bounds):
    """Rows [bounds[j], bounds[j + 1]) of band j of a box whose rows are [r0, r1)."""
    band = h / n_parts
    for j in range(n_parts + 1):
        bounds[j] = r0
    for r in range(r0, r1):
        part = int((r + 0.5 - y) / band)
        if part >= n_parts:
            part = n_parts - 1
        # Bands are monotone in r: every band after this one starts below r.
        for j in range(part + 1, n_parts + 1):
            bounds[j] = r + 1


@njit(cache=True)
def _corner_rho(i11, i01, i10, i00, sq, scale):
    """Σ_t sqrt((i11 − i01 − i10 + i00)[t] · scale) · sq[t] (vectorised loop; counts in
    int64 whatever the integral's integer type)."""
    acc = 0.0
    for t in range(sq.shape[0]):
        acc += np.sqrt((np.int64(i11[t]) - i01[t] - i10[t] + i00[t]) * scale) * sq[t]
    return acc


@njit(cache=True)
def _gather_rho(i11, i01, i10, i00, chan, ta, tb, sq, scale):
    """As ``_corner_rho`` for the support bins ta … tb − 1 read through ``chan``."""
    acc = 0.0
    for t in range(ta, tb):
        k = chan[t]
        acc += np.sqrt((np.int64(i11[k]) - i01[k] - i10[k] + i00[k]) * scale) * sq[t]
    return acc


@njit(cache=True)
def _box_band_rho(integ, rects, a_fixed, ra, rb, R0, C0, ta, tb, sq, sums, scale_parts,
                  chan):
    """ρ of one band (rows [ra, rb)) of a box-kernel box from the integral histogram.

    Band histogram h_t = Σ_l a_l · (pixels of colour t in rectangle l ∩ the band), total
    Σ_l a_l · (pixels of rectangle l ∩ the band); both in fixed point, so they equal what
    the direct path accumulates pixel by pixel, and ρ is summed in the same order. Support
    bin t is read from channel chan[t] of ``integ``. Returns −1 for a band without pixels.
    """
    n = tb - ta
    for t in range(n):
        sums[t] = 0
    total = 0
    for lv in range(a_fixed.shape[0]):
        ya = max(ra, rects[lv, 0]) - R0
        yb = min(rb, rects[lv, 1]) - R0
        xa = rects[lv, 2] - C0
        xb = rects[lv, 3] - C0
        if yb <= ya or xb <= xa:
            continue
        a = a_fixed[lv]
        total += a * (yb - ya) * (xb - xa)
        i11 = integ[yb, xb]
        i01 = integ[ya, xb]
        i10 = integ[yb, xa]
        i00 = integ[ya, xa]
        for t in range(n):
            k = chan[ta + t]
            sums[t] += a * (np.int64(i11[k]) - i01[k] - i10[k] + i00[k])
    if total <= 0:
        return -1.0
    scale = 1.0 / (total * scale_parts)
    acc = 0.0
    for t in range(n):
        acc += np.sqrt(sums[t] * scale) * sq[ta + t]
    return acc


@njit(cache=True)
def _integral_distances(bin_img, boxes, members, sqrt_q, nz, nz_start, empty_rho, n_bins,
                        n_parts, roi, out, kernel, fracs, a_fixed):
    """Uniform- or box-kernel distances of the boxes ``members`` to one reference (integral
    path).

    Builds, over ``roi`` (r0, r1, c0, c1: the union of the boxes' pixels), the integral
    histogram of the reference's support only: one channel per colour in the support of
    any band (a colour in the support of two bands is counted once), support bin t
    (running over all bands' support bins in order; band j's are [nz_start[j],
    nz_start[j + 1])) reading channel chan[t]. A box's band count is then four corner
    reads per bin (Porikli 2005), whatever the box's size.
    """
    R0, R1, C0, C1 = roi[0], roi[1], roi[2], roi[3]
    rows, cols = bin_img.shape
    t0 = nz_start[0]
    n_sup = nz_start[n_parts] - t0
    # channel of colour c, or -1; channel of support bin t; sqrt q of support bin t
    cmap = np.full(n_bins, -1, dtype=np.int64)
    chan = np.empty(n_sup, dtype=np.int64)
    sq = np.empty(n_sup)
    n_chan = 0
    for j in range(n_parts):
        for t in range(nz_start[j], nz_start[j + 1]):
            colour = nz[t] - j * n_bins
            if cmap[colour] < 0:
                cmap[colour] = n_chan
                n_chan += 1
            chan[t - t0] = cmap[colour]
            sq[t - t0] = sqrt_q[nz[t]]
    hgt = R1 - R0
    wid = C1 - C0
    # Counts never exceed the ROI's pixels: 16 bits hold them for ROIs below 2**16 pixels
    # (half the memory traffic of 32 bits), the same integers either way.
    if (hgt + 1) * (wid + 1) < 65536:
        _integral_score(np.empty((hgt + 1, wid + 1, n_chan), dtype=np.uint16), bin_img,
                        boxes, members, nz_start, empty_rho, n_parts, roi, out, kernel,
                        fracs, a_fixed, cmap, chan, sq, n_chan, n_sup)
    else:
        _integral_score(np.empty((hgt + 1, wid + 1, n_chan), dtype=np.int32), bin_img,
                        boxes, members, nz_start, empty_rho, n_parts, roi, out, kernel,
                        fracs, a_fixed, cmap, chan, sq, n_chan, n_sup)


@njit(cache=True)
def _integral_score(integ, bin_img, boxes, members, nz_start, empty_rho, n_parts, roi, out,
                    kernel, fracs, a_fixed, cmap, chan, sq, n_chan, n_sup):
    """Fill the integral histogram ``integ`` of ``roi`` and score the boxes ``members``
    (the second half of ``_integral_distances``)."""
    R0, R1, C0, C1 = roi[0], roi[1], roi[2], roi[3]
    rows, cols = bin_img.shape
    t0 = nz_start[0]
    hgt = R1 - R0
    wid = C1 - C0
    integ[0] = 0
    racc = np.zeros(n_chan, dtype=np.int32)
    for yy in range(hgt):
        racc[:] = 0
        row = bin_img[R0 + yy]
        integ[yy + 1, 0] = 0
        for xx in range(wid):
            k = cmap[row[C0 + xx]]
            if k >= 0:
                racc[k] += 1
            above = integ[yy, xx + 1]
            here = integ[yy + 1, xx + 1]
            for t in range(n_chan):
                here[t] = above[t] + racc[t]
    bounds = np.empty(n_parts + 1, dtype=np.int64)
    rects = np.empty((max(fracs.shape[0], 1), 4), dtype=np.int64)
    sums = np.empty(max(n_sup, 1), dtype=np.int64)
    for m in members:
        x, y, w, h = boxes[m, 0], boxes[m, 1], boxes[m, 2], boxes[m, 3]
        r0, r1 = _pixel_range(y, h, rows)
        c0, c1 = _pixel_range(x, w, cols)
        rho = 0.0
        if r0 >= r1 or c0 >= c1:
            for j in range(n_parts):
                rho += empty_rho[j]
        else:
            _band_rows(y, h, n_parts, r0, r1, bounds)
            xa = c0 - C0
            xb = c1 - C0
            if kernel == KERNEL_BOX:
                _level_rects(x, y, w, h, fracs, rows, cols, rects)
            for j in range(n_parts):
                ra = bounds[j]
                rb = bounds[j + 1]
                if rb <= ra:
                    rho += empty_rho[j]
                    continue
                ta = nz_start[j] - t0
                tb = nz_start[j + 1] - t0
                if kernel == KERNEL_BOX:
                    band_rho = _box_band_rho(integ, rects, a_fixed, ra, rb, R0, C0, ta, tb,
                                             sq, sums, n_parts, chan)
                    rho += empty_rho[j] if band_rho < 0.0 else band_rho
                    continue
                ya = ra - R0
                yb = rb - R0
                scale = 1.0 / ((rb - ra) * (c1 - c0) * n_parts)
                if n_chan == n_sup:
                    # No colour shared between bands: channel t is support bin t.
                    rho += _corner_rho(integ[yb, xb, ta:tb], integ[ya, xb, ta:tb],
                                       integ[yb, xa, ta:tb], integ[ya, xa, ta:tb],
                                       sq[ta:tb], scale)
                else:
                    rho += _gather_rho(integ[yb, xb], integ[ya, xb], integ[yb, xa],
                                       integ[ya, xa], chan, ta, tb, sq, scale)
        one_minus = 1.0 - rho
        out[m] = np.sqrt(one_minus) if one_minus > 0.0 else 0.0
