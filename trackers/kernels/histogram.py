"""Batched kernel-weighted colour histograms on a bin-index image (numba).

Every particle tracker spends its time building the colour histograms of candidate
regions (docs/algorithms.md §2.2). The frame is quantised once into a bin-index image
(``quantize_rgb`` or ``quantize_hsv``); then one compiled call builds the histograms of
all candidate boxes of all objects (``region_histograms``), or directly their
Bhattacharyya distances to reference histograms (``region_distances``, which never
materialises the (P, B) histogram array).

Conventions shared by every function here (docs/algorithms.md, "Notation"):

- A box is [x, y, w, h]. Pixel (row r, column c) belongs to a box if its centre
  (c + 0.5, r + 0.5) lies in [x, x + w) × [y, y + h). Pixels outside the frame are
  skipped, so a region cut by the border is the histogram of its visible part.
- Kernel profiles, at the normalised elliptical radius
  r = sqrt(((px - cx) / (w / 2))² + ((py - cy) / (h / 2))²) of a pixel centre:
  ``KERNEL_UNIFORM`` weight 1 on the whole box; ``KERNEL_EPANECHNIKOV`` 1 − r²;
  ``KERNEL_CONE`` 1 − r (the linear kernel of KAMS §2); both elliptic kernels are 0 outside
  the ellipse inscribed in the box.
- ``KERNEL_BOX`` with L levels (``box_levels``): a step ("pyramid") approximation of the
  Epanechnikov profile made of L nested rectangles, rectangle l (l = 1 … L) being the box
  scaled by l / L about its centre (rectangle L is the box itself, with the same pixel
  rule). With the Chebyshev radius r∞ = max(|px − cx| / (w / 2), |py − cy| / (h / 2)), a
  pixel in the shell (l − 1) / L < r∞ ≤ l / L has weight 1 − ((l − ½) / L)², the
  Epanechnikov profile at the shell's mid-radius; as a sum of rectangles, rectangle l
  carries a_l = k_l − k_(l+1) (k_(L+1) = 0). A box's histogram is then a weighted sum of L
  rectangle histograms, which an integral histogram gives exactly in O(L · bins) per box
  whatever its size (``region_distances``' integral path). L = 1 is the uniform kernel.
- ``n_parts`` splits the box into that many horizontal bands of equal height (the
  "spatial components" of Pérez et al. 2002, DPS §3.2); the kernel is still the one of the
  whole box. Each band's histogram is normalised to sum 1, the bands are concatenated and
  divided by ``n_parts``, so the whole vector sums to 1.
- A band with no pixel of positive weight (box outside the frame, or smaller than a pixel)
  gets the uniform histogram 1 / n_bins: it carries no colour information, so it is
  neither attracted to nor repelled from any reference.
- Weights are summed in 32.32 fixed point (each pixel's weight rounded to 2**-32), so a
  histogram is exact to about 1e-9 of its band's total weight, and the same pixels give
  bit-identical sums in any order.
- No function here is compiled with ``fastmath``: a reassociated floating-point sum can
  depend on the memory alignment of its arrays (vector loops peel a different number of
  leading elements), which broke "same inputs, same bytes" between two processes. Every
  floating-point sum runs in a fixed order.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

__all__ = [
    "DEFAULT_BOX_LEVELS",
    "KERNEL_BOX",
    "KERNEL_CONE",
    "KERNEL_EPANECHNIKOV",
    "KERNEL_UNIFORM",
    "KERNELS",
    "METHODS",
    "PreparedReferences",
    "bhattacharyya_coefficient",
    "bhattacharyya_distance",
    "box_kernel_levels",
    "hsv_n_bins",
    "prepare_references",
    "prepared_distances",
    "quantize_hsv",
    "quantize_rgb",
    "region_distances",
    "region_histograms",
]

KERNEL_UNIFORM = 0
KERNEL_EPANECHNIKOV = 1
KERNEL_CONE = 2
KERNEL_BOX = 3
#: Levels of the nested-rectangle kernel when none is given (see the module docstring).
DEFAULT_BOX_LEVELS = 3
_MAX_BOX_LEVELS = 16

#: Kernel profile names, as accepted by the observation models, mapped to their codes.
KERNELS: dict[str, int] = {
    "uniform": KERNEL_UNIFORM,
    "epanechnikov": KERNEL_EPANECHNIKOV,
    "cone": KERNEL_CONE,
    "box": KERNEL_BOX,
}


_NO_LEVELS = np.zeros(0, dtype=np.int64)
_NO_FRACTIONS = np.zeros(0, dtype=np.float64)


def box_kernel_levels(levels: int = DEFAULT_BOX_LEVELS) -> tuple[NDArray[np.float64],
                                                                 NDArray[np.float64]]:
    """Scales and weights of the nested-rectangle kernel with ``levels`` levels.

    Returns
    -------
    fractions : ndarray of shape (L,)
        Rectangle l's size as a fraction l / L of the box's (innermost first).
    weights : ndarray of shape (L,)
        a_l: the weight rectangle l adds to each of its pixels, so that a pixel of shell l
        has Σ_(m ≥ l) a_m = 1 − ((l − ½) / L)².

    Raises
    ------
    ValueError
        If ``levels`` is not an integer in [1, 16].
    """
    if isinstance(levels, bool) or int(levels) != levels or not 1 <= levels <= _MAX_BOX_LEVELS:
        raise ValueError(f"box_levels must be an integer in [1, {_MAX_BOX_LEVELS}], got "
                         f"{levels!r}")
    n = int(levels)
    shell = 1.0 - ((np.arange(1, n + 1) - 0.5) / n) ** 2
    weights = shell - np.append(shell[1:], 0.0)
    return np.arange(1, n + 1) / n, weights


def _level_args(kernel: int, levels: int) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """(fractions, fixed-point weights) passed to the compiled code; empty unless box."""
    if kernel != KERNEL_BOX:
        return _NO_FRACTIONS, _NO_LEVELS
    fractions, weights = box_kernel_levels(levels)
    return fractions, np.round(weights * _ONE).astype(np.int64)


def _check_frame(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    arr = np.asarray(frame)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.dtype != np.uint8:
        raise ValueError(f"frame must be uint8 of shape (H, W, 3), got {arr.dtype} {arr.shape}")
    return np.ascontiguousarray(arr)


def _check_bin_count(name: str, value: int) -> int:
    if int(value) != value or not 1 <= value <= 256:
        raise ValueError(f"{name} must be an integer in [1, 256], got {value!r}")
    return int(value)


@njit(cache=True)
def _planes(src, red, green, blue):
    """Split one row (W, 3) into three int32 rows: the loops that follow vectorise."""
    for j in range(src.shape[0]):
        red[j] = src[j, 0]
        green[j] = src[j, 1]
        blue[j] = src[j, 2]


@njit(cache=True)
def _quantize_rgb(frame, bins):
    rows, cols = frame.shape[0], frame.shape[1]
    out = np.empty((rows, cols), dtype=np.int32)
    red = np.empty(cols, dtype=np.int32)
    green = np.empty(cols, dtype=np.int32)
    blue = np.empty(cols, dtype=np.int32)
    for i in range(rows):
        _planes(frame[i], red, green, blue)
        dst = out[i]
        for j in range(cols):
            # c * bins // 256 as a shift: exact for non-negative integers.
            dst[j] = (((red[j] * bins) >> 8) * bins + ((green[j] * bins) >> 8)) * bins + (
                (blue[j] * bins) >> 8)
    return out


def quantize_rgb(frame: NDArray[np.uint8], bins: int = 10) -> NDArray[np.int32]:
    """Bin index of every pixel of an RGB frame in a ``bins``³ RGB histogram.

    Parameters
    ----------
    frame : ndarray of shape (H, W, 3), uint8
        RGB frame.
    bins : int, optional
        Bins per channel (KAMS uses 10, giving 1000 bins).

    Returns
    -------
    ndarray of shape (H, W), int32
        ``r_bin * bins² + g_bin * bins + b_bin`` with ``c_bin = c * bins // 256``; values in
        [0, bins³).

    Example
    -------
    >>> quantize_rgb(np.array([[[255, 0, 128]]], dtype=np.uint8)).tolist()
    [[905]]
    """
    return _quantize_rgb(_check_frame(frame), np.int32(_check_bin_count("bins", bins)))


@njit(cache=True)
def _quantize_hsv(frame, h_bins, s_bins, v_bins, s_thr, v_thr):
    # Every bin is floor(a / b) of integers a < 2**24 and b <= 1530, from a float32
    # division: correctly rounded, it never reaches the next integer (a / b is at least
    # 1 / (b · bins) ≈ 2.6e-6 relatively below it, far more than float32's 6e-8), so the
    # bins are exact — checked on all 2**24 colours in the tests. No fastmath here: an
    # approximate reciprocal would break that. Branch-free selects, so the loop vectorises.
    rows, cols = frame.shape[0], frame.shape[1]
    out = np.empty((rows, cols), dtype=np.int32)
    red = np.empty(cols, dtype=np.int32)
    green = np.empty(cols, dtype=np.int32)
    blue = np.empty(cols, dtype=np.int32)
    hbf = np.float32(h_bins)
    sbf = np.float32(s_bins)
    vbf = np.float32(v_bins)
    v_offset = np.int32(h_bins * s_bins)
    h_top = np.int32(h_bins - 1)
    s_top = np.int32(s_bins - 1)
    v_top = np.int32(v_bins - 1)
    s_n = np.int32(s_bins)
    one = np.int32(1)
    for i in range(rows):
        _planes(frame[i], red, green, blue)
        dst = out[i]
        for j in range(cols):
            r = red[j]
            g = green[j]
            b = blue[j]
            mx = max(r, max(g, b))
            mn = min(r, min(g, b))
            d = mx - mn
            # Hue in sixths of the colour circle, times d (hexcone).
            h6r = g - b + (6 * d if g < b else 0)
            h6g = b - r + 2 * d
            h6b = r - g + 4 * d
            h6 = h6r if mx == r else (h6g if mx == g else h6b)
            hb = min(np.int32(np.float32(h6) * hbf / np.float32(6 * max(d, one))), h_top)
            sb = min(np.int32(np.float32(d) * sbf / np.float32(max(mx, one))), s_top)
            vb = min(np.int32(np.float32(mx) * vbf / np.float32(255)), v_top)
            # S >= s_min and V >= v_min, i.e. d / mx >= s_min and mx / 255 >= v_min, with
            # the thresholds pre-scaled to integers (d * 2**20 >= s_thr * mx).
            coloured = (d > 0) & (mx >= v_thr) & ((d << 20) >= s_thr * mx)
            dst[j] = hb * s_n + sb if coloured else v_offset + vb
    return out


def hsv_n_bins(h_bins: int = 10, s_bins: int = 10, v_bins: int = 10) -> int:
    """Number of bins of the HSV quantisation: ``h_bins * s_bins + v_bins``."""
    return h_bins * s_bins + v_bins


def quantize_hsv(
    frame: NDArray[np.uint8],
    h_bins: int = 10,
    s_bins: int = 10,
    v_bins: int = 10,
    s_min: float = 0.1,
    v_min: float = 0.2,
) -> NDArray[np.int32]:
    """Bin index of every pixel in the HSV histogram of Pérez et al. 2002.

    Pixels with saturation ≥ ``s_min`` and value ≥ ``v_min`` fall in an ``h_bins`` ×
    ``s_bins`` hue–saturation histogram; the others (greyish or dark, where hue is
    unreliable) fall in a value-only histogram of ``v_bins`` bins placed after it.

    HSV is the hexcone model of the 8-bit RGB values (as ``skimage.color.rgb2hsv``):
    V = max / 255, S = (max − min) / max, H in [0, 1) of the colour circle; a bin is
    floor(x · bins), with the top value in the last bin, computed exactly (integer floors) in
    one compiled pass (no 8-bit rounding of H and S as in ``cv2.cvtColor``). ``s_min`` is
    applied with a resolution of 2**-20, rounded down: S >= floor(s_min 2**20) / 2**20,
    so a pixel whose S is exactly ``s_min`` (S = 1/10 with the default 0.1, which no
    binary fraction represents) is coloured; no 8-bit S lies in the 2**-20 below a
    threshold of a few decimals.

    Parameters
    ----------
    frame : ndarray of shape (H, W, 3), uint8
        RGB frame.
    h_bins, s_bins, v_bins : int, optional
        Bins of hue, saturation and value.
    s_min, v_min : float, optional
        Saturation and value thresholds in [0, 1].

    Returns
    -------
    ndarray of shape (H, W), int32
        ``h_bin * s_bins + s_bin`` for coloured pixels, ``h_bins * s_bins + v_bin`` for the
        others; values in [0, ``hsv_n_bins(h_bins, s_bins, v_bins)``).

    Example
    -------
    >>> quantize_hsv(np.array([[[255, 0, 0], [128, 128, 128]]], dtype=np.uint8)).tolist()
    [[9, 105]]
    """
    h_bins = _check_bin_count("h_bins", h_bins)
    s_bins = _check_bin_count("s_bins", s_bins)
    v_bins = _check_bin_count("v_bins", v_bins)
    for name, val in (("s_min", s_min), ("v_min", v_min)):
        if not 0.0 <= val <= 1.0:
            raise ValueError(f"{name} must lie in [0, 1], got {val!r}")
    s_thr = int(np.floor(s_min * 2**20))
    v_thr = int(np.ceil(v_min * 255 - 1e-9))
    return _quantize_hsv(_check_frame(frame), np.int32(h_bins), np.int32(s_bins),
                         np.int32(v_bins), np.int32(s_thr), np.int32(v_thr))


@njit(cache=True)
def _first_inside(lo):
    """First pixel index whose centre i + 0.5 is >= lo."""
    return int(np.ceil(lo - 0.5))


@njit(cache=True)
def _pixel_range(lo, size, n):
    """Pixel indices [i0, i1) whose centres lie in [lo, lo + size), clipped to [0, n)."""
    i0 = _first_inside(lo)
    i1 = _first_inside(lo + size)
    if i0 < 0:
        i0 = 0
    if i1 > n:
        i1 = n
    return i0, i1


# Weights are accumulated in 32.32 fixed point (int64): integer adds do not stall on
# store-to-load forwarding when neighbouring pixels share a bin (flat regions), which made
# float accumulation twice as slow there. Resolution 2**-32, far below any use here.
_ONE = 4294967296.0
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
def _cone_weights(kbuf, c0, c1, cx, inv_hw, dy2):
    """Fixed-point cone weights 1 − r of pixels c0..c1-1 of one row (vectorised loop)."""
    for c in range(c0, c1):
        dx = (c + 0.5 - cx) * inv_hw
        # r >= 1 (outside the ellipse) gives a weight <= 0: clamped to 0, it adds nothing.
        kbuf[c - c0] = np.int64(max(1.0 - np.sqrt(dx * dx + dy2), 0.0) * _ONE + 0.5)


@njit(cache=True)
def _epanechnikov_weights(kbuf, tbuf, n, wr):
    """kbuf[i] = max(wr − tbuf[i], 0) for i < n (fixed point; vectorised loop)."""
    for i in range(n):
        kbuf[i] = max(wr - tbuf[i], 0)


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
def _level_rects(x, y, w, h, fracs, rows, cols, rects):
    """rects[l] = (r0, r1, c0, c1): the pixels of rectangle l of the box kernel (the box
    scaled by fracs[l] about its centre; fracs[-1] = 1 gives the box itself)."""
    for lv in range(fracs.shape[0]):
        f = fracs[lv]
        r0, r1 = _pixel_range(y + 0.5 * h * (1.0 - f), h * f, rows)
        c0, c1 = _pixel_range(x + 0.5 * w * (1.0 - f), w * f, cols)
        rects[lv, 0] = r0
        rects[lv, 1] = r1
        rects[lv, 2] = c0
        rects[lv, 3] = c1


@njit(cache=True)
def _box_row_weights(kbuf, n, c0, r, rects, a_fixed):
    """Fixed-point box-kernel weights of row r, columns c0 … c0 + n − 1.

    The rectangles are nested (each level's row and column ranges contain the previous
    level's: their bounds are monotone in the scale), so the rectangles covering row r
    are the levels from the first one that does; a column's weight is the sum of a_l over
    those of them that contain it, written once per column, from the outermost level
    (the box, c0 … c0 + n − 1) inwards, each level filling the columns it adds.
    """
    n_levels = a_fixed.shape[0]
    first = n_levels
    for lv in range(n_levels):
        if rects[lv, 0] <= r < rects[lv, 1]:
            first = lv
            break
    lo = c0
    hi = c0 + n
    acc = 0
    for lv in range(n_levels - 1, first - 1, -1):
        acc += a_fixed[lv]
        if lv > first:
            ilo = max(rects[lv - 1, 2], lo)
            ihi = min(rects[lv - 1, 3], hi)
            if ihi <= ilo:
                ilo = hi
                ihi = hi
        else:
            ilo = hi
            ihi = hi
        # Columns [lo, ilo) and [ihi, hi) of this level, not in the next inner level.
        for c in range(lo, ilo):
            kbuf[c - c0] = acc
        for c in range(ihi, hi):
            kbuf[c - c0] = acc
        lo = ilo
        hi = ihi
    # Columns of the box no covering rectangle holds (none when the box's row is covered).
    for c in range(lo, hi):
        kbuf[c - c0] = 0


@njit(cache=True)
def _next_change(rects, r, r1):
    """The first row after r (at most r1) where a rectangle of ``rects`` starts or ends."""
    nxt = r1
    for lv in range(rects.shape[0]):
        for e in range(2):
            b = rects[lv, e]
            if r < b < nxt:
                nxt = b
    return nxt


@njit(cache=True)
def _accumulate(bin_img, x, y, w, h, n_bins, kernel, n_parts, hist, lanes, totals, tbuf,
                kbuf, fracs, a_fixed, rects):
    """Add the fixed-point weighted pixels of box [x, y, w, h] into ``hist``.

    ``hist`` (lanes * n_parts * n_bins, int64) receives the weights in ``lanes`` copies,
    ``totals`` (n_parts, int64) each band's total; ``tbuf`` and ``kbuf`` (W + 2,) are
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
    path, see ``_SMALL_SUPPORT``). ``tbuf`` and ``kbuf`` (W + 2 + _PAD,) are scratch."""
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
    tbuf = np.empty(bin_img.shape[1] + 2, dtype=np.int64)
    kbuf = np.empty(bin_img.shape[1] + 2, dtype=np.int64)
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


# Relative costs of the two paths of one reference's boxes, in units of one pixel visit of
# the direct path, fitted (least squares, relative error) to the time of each path on the
# groups of boxes the particle filters score on dps-synthetic, dps-occlusion, dps-dancers
# and kams-d (box kernel, L = 3, one thread; median error 2 % direct, 4 % integral):
# direct = pixels + _COST_SWEEP · boxes · support + _COST_BOX_DIRECT · boxes;
# integral = _COST_CELL · ROI pixels · channels + _COST_ROI · ROI pixels
#            + _COST_CORNER · boxes · support · levels + _COST_BOX_INTEGRAL · boxes.
# "auto" takes the cheaper; both give the same bits, so the choice only changes the time
# (the fitted choice is within 0.5 % of the faster path's total on those groups).
_COST_PIXEL = 1.0
_COST_SWEEP = 2.6
_COST_BOX_DIRECT = 450.0
_COST_CELL = 0.146
_COST_ROI = 6.4
_COST_CORNER = 1.8
_COST_BOX_INTEGRAL = 270.0
_MAX_CELLS = 1 << 24

METHOD_AUTO = 0
METHOD_DIRECT = 1
METHOD_INTEGRAL = 2

#: Names of the evaluation paths of ``region_distances`` mapped to their codes.
METHODS: dict[str, int] = {"auto": METHOD_AUTO, "direct": METHOD_DIRECT,
                           "integral": METHOD_INTEGRAL}


@njit(cache=True)
def _reference_groups(ref_index):
    """Boxes sorted by reference (stable) and where each reference's run starts."""
    n_boxes = ref_index.shape[0]
    order = np.argsort(ref_index, kind="mergesort")
    starts = np.empty(n_boxes + 1, dtype=np.int64)
    n_groups = 0
    for i in range(n_boxes):
        if i == 0 or ref_index[order[i]] != ref_index[order[i - 1]]:
            starts[n_groups] = i
            n_groups += 1
    starts[n_groups] = n_boxes
    return order, starts[:n_groups + 1]


@njit(cache=True)
def _integral_group(bin_img, boxes, members, sqrt_refs, nz, nz_start, empty_rho, n_bins,
                    n_parts, method, kernel, fracs, a_fixed, n_levels, out):
    """Score one reference's boxes by the integral path if it is the cheaper (or asked
    for); returns whether it did."""
    rows, cols = bin_img.shape
    roi = np.empty(4, dtype=np.int64)
    # The union of the members' pixels, and what each path would cost.
    roi[0], roi[1], roi[2], roi[3] = rows, 0, cols, 0
    area = 0.0
    for m in members:
        r0, r1 = _pixel_range(boxes[m, 1], boxes[m, 3], rows)
        c0, c1 = _pixel_range(boxes[m, 0], boxes[m, 2], cols)
        if r0 < r1 and c0 < c1:
            area += (r1 - r0) * (c1 - c0)
            roi[0] = min(roi[0], r0)
            roi[1] = max(roi[1], r1)
            roi[2] = min(roi[2], c0)
            roi[3] = max(roi[3], c1)
    n_sup = nz_start[n_parts] - nz_start[0]
    # Channels of the integral: the distinct colours of the support (_integral_distances).
    seen = np.zeros(n_bins, dtype=np.bool_)
    n_chan = 0
    for j in range(n_parts):
        for t in range(nz_start[j], nz_start[j + 1]):
            colour = nz[t] - j * n_bins
            if not seen[colour]:
                seen[colour] = True
                n_chan += 1
    roi_pixels = max(roi[1] - roi[0], 0) * max(roi[3] - roi[2], 0) * 1.0
    cells = roi_pixels * n_chan
    k = members.shape[0]
    cost_direct = area * _COST_PIXEL + k * (n_sup * _COST_SWEEP + _COST_BOX_DIRECT)
    cost_integral = (cells * _COST_CELL + roi_pixels * _COST_ROI
                     + k * (n_sup * n_levels * _COST_CORNER + _COST_BOX_INTEGRAL))
    if roi[1] > roi[0] and cells <= _MAX_CELLS and (
            method == METHOD_INTEGRAL or cost_integral < cost_direct):
        _integral_distances(bin_img, boxes, members, sqrt_refs, nz, nz_start, empty_rho,
                            n_bins, n_parts, roi, out, kernel, fracs, a_fixed)
        return True
    return False


@njit(cache=True, parallel=True)
def _region_distances(bin_img, boxes, sqrt_refs, ref_index, nz, nz_start, empty_rho,
                      n_bins, kernel, n_parts, lanes, method, fracs, a_fixed, n_chunks,
                      max_support):
    """Distances of every box to its reference, in parallel over references (integral
    path) and over chunks of boxes (direct path). Every box is computed alone from zeroed
    scratch, with sums in a fixed order, so the result does not depend on the number of
    threads or on how the boxes are chunked. The direct path of a reference with at most
    ``max_support`` support bins in every band counts only those (``_SMALL_SUPPORT``; the
    same bits as the whole histogram)."""
    n_boxes = boxes.shape[0]
    cols = bin_img.shape[1]
    out = np.empty(n_boxes)
    direct = np.ones(n_boxes, dtype=np.bool_)
    integral_ok = kernel == KERNEL_UNIFORM or kernel == KERNEL_BOX
    n_levels = max(a_fixed.shape[0], 1)
    if integral_ok and method != METHOD_DIRECT and n_boxes > 0:
        order, starts = _reference_groups(ref_index)
        for g in prange(starts.shape[0] - 1):
            members = order[starts[g]:starts[g + 1]]
            ref = ref_index[members[0]]
            if _integral_group(bin_img, boxes, members, sqrt_refs[ref], nz[ref],
                               nz_start[ref], empty_rho[ref], n_bins, n_parts, method,
                               kernel, fracs, a_fixed, n_levels, out):
                for m in members:
                    direct[m] = False
    dim = n_parts * n_bins
    # Per reference: its support bins' colours within their band, and whether every band
    # has few enough of them for the support path (``_SMALL_SUPPORT``).
    n_refs = nz.shape[0]
    colours = np.empty_like(nz)
    small = np.empty(n_refs, dtype=np.bool_)
    for q in range(n_refs):
        small[q] = True
        for j in range(n_parts):
            if nz_start[q, j + 1] - nz_start[q, j] > max_support:
                small[q] = False
            for t in range(nz_start[q, j], nz_start[q, j + 1]):
                colours[q, t] = nz[q, t] - j * n_bins
    n_chunks = max(min(n_chunks, n_boxes), 1)
    for ch in prange(n_chunks):
        hist = np.zeros(lanes * dim, dtype=np.int64)
        totals = np.empty(n_parts, dtype=np.int64)
        tbuf = np.empty(cols + 2 + _PAD, dtype=np.int64)
        kbuf = np.empty(cols + 2 + _PAD, dtype=np.int64)
        rects = np.empty((n_levels, 4), dtype=np.int64)
        sums = np.empty(dim, dtype=np.int64)
        for p in range(ch * n_boxes // n_chunks, (ch + 1) * n_boxes // n_chunks):
            if direct[p]:
                ref = ref_index[p]
                out[p] = _direct_distance(bin_img, boxes[p], sqrt_refs[ref], nz[ref],
                                          nz_start[ref], empty_rho[ref], n_bins, kernel,
                                          n_parts, hist, lanes, totals, tbuf, kbuf, fracs,
                                          a_fixed, rects, colours[ref], sums, small[ref])
    return out


@njit(cache=True)
def _support(q, n_parts):
    """Per reference: its bins with q > 0 (rows of ``nz``, padded), where each band's
    start in them (``nz_start``, (R, n_parts + 1)), and the ρ of a uniform band."""
    n_refs, dim = q.shape
    n_bins = dim // n_parts
    nz = np.zeros((n_refs, dim), dtype=np.int64)
    nz_start = np.zeros((n_refs, n_parts + 1), dtype=np.int64)
    empty_rho = np.zeros((n_refs, n_parts))
    fill = np.sqrt(1.0 / (n_bins * n_parts))
    for r in range(n_refs):
        t = 0
        for j in range(n_parts):
            nz_start[r, j] = t
            for b in range(j * n_bins, (j + 1) * n_bins):
                if q[r, b] > 0:
                    nz[r, t] = b
                    t += 1
                    empty_rho[r, j] += fill * np.sqrt(q[r, b])
        nz_start[r, n_parts] = t
    return nz, nz_start, empty_rho


def _check_region_args(bin_img, boxes, n_bins, kernel, n_parts, check_bins=True):
    img = np.ascontiguousarray(bin_img)
    if img.ndim != 2 or not np.issubdtype(img.dtype, np.integer):
        raise ValueError(f"bin_img must be an integer array of shape (H, W), got "
                         f"{img.dtype} {img.shape}")
    if int(n_bins) != n_bins or n_bins < 1:
        raise ValueError(f"n_bins must be a positive integer, got {n_bins!r}")
    if check_bins and img.size and (img.min() < 0 or img.max() >= n_bins):
        raise ValueError(f"bin_img values must lie in [0, {n_bins}), got "
                         f"[{img.min()}, {img.max()}]")
    if kernel not in KERNELS.values():
        raise ValueError(f"kernel must be one of {sorted(KERNELS.values())} "
                         f"({', '.join(KERNELS)}), got {kernel!r}")
    if int(n_parts) != n_parts or n_parts < 1:
        raise ValueError(f"n_parts must be a positive integer, got {n_parts!r}")
    bx = np.ascontiguousarray(boxes, dtype=np.float64)
    if bx.ndim != 2 or bx.shape[1] != 4:
        raise ValueError(f"boxes must have shape (P, 4), got {bx.shape}")
    # A NaN or an infinity makes the sum non-finite.
    if bx.size and not (np.isfinite(bx.sum()) and bx[:, 2:].min() > 0):
        raise ValueError("boxes must be finite with positive width and height")
    if img.dtype not in (np.uint8, np.uint16, np.int32):
        img = img.astype(np.int32)
    return img, bx, int(n_bins), int(kernel), int(n_parts)


def region_histograms(
    bin_img: NDArray[np.integer],
    boxes: NDArray[np.floating],
    n_bins: int,
    kernel: int,
    n_parts: int = 1,
    *,
    box_levels: int = DEFAULT_BOX_LEVELS,
) -> NDArray[np.float64]:
    """Kernel-weighted histograms of many boxes of one bin-index image, in one call.

    Parameters
    ----------
    bin_img : ndarray of shape (H, W), integer
        Bin index of every pixel, in [0, ``n_bins``) (``quantize_rgb``, ``quantize_hsv``).
    boxes : ndarray of shape (P, 4)
        Boxes [x, y, w, h] in pixels, finite, w > 0 and h > 0; they may leave the frame.
    n_bins : int
        Number of colour bins B.
    kernel : int
        ``KERNEL_UNIFORM``, ``KERNEL_EPANECHNIKOV``, ``KERNEL_CONE`` or ``KERNEL_BOX``.
    n_parts : int, optional
        Horizontal bands (spatial components), concatenated top to bottom.
    box_levels : int, optional
        Levels L of ``KERNEL_BOX`` (ignored by the other kernels).

    Returns
    -------
    ndarray of shape (P, n_parts * n_bins)
        One histogram per box; each row sums to 1 (see the module docstring for bands and
        empty regions).

    Raises
    ------
    ValueError
        For bad shapes, bin indices outside [0, n_bins), an unknown kernel, or boxes that
        are not finite or have a non-positive size.

    Example
    -------
    >>> img = np.array([[0, 1], [1, 1]], dtype=np.int32)
    >>> region_histograms(img, np.array([[0.0, 0.0, 2.0, 2.0]]), 2, KERNEL_UNIFORM).tolist()
    [[0.25, 0.75]]
    """
    img, bx, n_bins, kernel, n_parts = _check_region_args(bin_img, boxes, n_bins, kernel,
                                                          n_parts)
    fracs, a_fixed = _level_args(kernel, box_levels)
    return _region_histograms(img, bx, n_bins, kernel, n_parts, _lanes(n_bins * n_parts),
                              fracs, a_fixed)


def region_distances(
    bin_img: NDArray[np.integer],
    boxes: NDArray[np.floating],
    refs: NDArray[np.floating],
    ref_index: NDArray[np.integer],
    kernel: int,
    n_parts: int = 1,
    *,
    check_bins: bool = True,
    method: str = "auto",
    box_levels: int = DEFAULT_BOX_LEVELS,
) -> NDArray[np.float64]:
    """Bhattacharyya distance of every box's histogram to its reference, in one call.

    Equal to ``bhattacharyya_distance(region_histograms(...), refs[ref_index])`` (to
    rounding) but without building the (P, B) histogram array. Two paths:

    - *direct*: each box's pixels are accumulated into one reused scratch histogram, and
      only the bins where the reference is positive are read back (the others add
      nothing to Σ sqrt(p q)); for a reference with few such bins in every band, only
      their counts are accumulated (the same integers, so the same bits); cost ∝ the
      boxes' total area.
    - *integral* (uniform and box kernels): per reference, the integral histogram
      (Porikli 2005) of the reference's support bins over the union of its boxes; each
      box then costs four reads per support bin (per level, for the box kernel) whatever
      its size. Particle clouds (hundreds of overlapping boxes of one object) are where
      this pays. For the box kernel both paths give bit-identical results (the same
      fixed-point histogram, summed in the same order).

    ``method="auto"`` picks, per reference, the path with the lower estimated cost; both
    give the same ρ to rounding (about 1e-15; d = sqrt(1 − ρ) magnifies that to about
    3e-8 where d is near 0).

    Parameters
    ----------
    bin_img : ndarray of shape (H, W), integer
        Bin index of every pixel, in [0, n_bins) with n_bins = ``refs.shape[1] // n_parts``.
    boxes : ndarray of shape (P, 4)
        Candidate boxes [x, y, w, h] (as in ``region_histograms``).
    refs : ndarray of shape (R, n_parts * n_bins)
        Reference histograms (each summing to 1), one per object.
    ref_index : ndarray of shape (P,), integer
        Row of ``refs`` that box p is compared with.
    kernel : int
        Kernel code, as in ``region_histograms``.
    n_parts : int, optional
        Horizontal bands, as in ``region_histograms``.
    check_bins : bool, optional
        Verify that every bin index lies in [0, n_bins) (a pass over the image). Callers
        that score one quantised frame many times (the partitioned samplers, once per
        object) check it once and pass False; an index out of range would then read
        out of bounds.
    method : {"auto", "direct", "integral"}, optional
        Evaluation path (see above); "integral" applies to the uniform and box kernels
        (the others always take the direct path), and falls back to "direct" for a
        reference whose integral histogram would exceed 2**24 cells.
    box_levels : int, optional
        Levels L of ``KERNEL_BOX`` (ignored by the other kernels).

    Returns
    -------
    ndarray of shape (P,)
        d = sqrt(max(0, 1 − Σ sqrt(p q))), in [0, 1].

    Raises
    ------
    ValueError
        For inconsistent shapes or indices, as well as the cases of ``region_histograms``.

    Example
    -------
    >>> img = np.array([[0, 1], [1, 1]], dtype=np.int32)
    >>> d = region_distances(img, np.array([[0.0, 0.0, 2.0, 2.0]]),
    ...                      np.array([[0.25, 0.75]]), np.array([0]), KERNEL_UNIFORM)
    >>> np.round(d, 6).tolist()
    [0.0]
    """
    prepared = prepare_references(refs, n_parts)
    img, bx, _, _, _ = _check_region_args(bin_img, boxes, prepared.n_bins, kernel,
                                          prepared.n_parts, check_bins)
    return prepared_distances(img, bx, prepared, ref_index, kernel, method=method,
                              box_levels=box_levels)


class PreparedReferences(NamedTuple):
    """Reference histograms with what ``region_distances`` derives from them once.

    Build with ``prepare_references``; pass to ``prepared_distances`` to score many sets
    of boxes against the same references (a tracker, every frame) without redoing it.
    """

    refs: NDArray[np.float64]
    """(R, n_parts * n_bins) reference histograms."""
    sqrt_refs: NDArray[np.float64]
    """(R, n_parts * n_bins) their square roots."""
    nz: NDArray[np.int64]
    """(R, n_parts * n_bins) each reference's bins with q > 0, first, in order."""
    nz_start: NDArray[np.int64]
    """(R, n_parts + 1) where each band's bins start in ``nz``."""
    empty_rho: NDArray[np.float64]
    """(R, n_parts) ρ of a band with no pixel (the uniform histogram)."""
    n_bins: int
    n_parts: int


def prepare_references(refs: NDArray[np.floating], n_parts: int = 1) -> PreparedReferences:
    """Check reference histograms and precompute their supports and square roots.

    Parameters
    ----------
    refs : ndarray of shape (R, n_parts * n_bins)
        Reference histograms (each summing to 1), one per object.
    n_parts : int, optional
        Horizontal bands, as in ``region_histograms``.

    Raises
    ------
    ValueError
        For a bad shape, or ``n_parts`` not dividing the number of bins.
    """
    q = np.ascontiguousarray(refs, dtype=np.float64)
    if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] < 1:
        raise ValueError(f"refs must have shape (R, n_parts * n_bins), got {q.shape}")
    if int(n_parts) != n_parts or n_parts < 1 or q.shape[1] % n_parts:
        raise ValueError(f"n_parts must be a positive divisor of refs.shape[1] = "
                         f"{q.shape[1]}, got {n_parts!r}")
    n_parts = int(n_parts)
    nz, nz_start, empty_rho = _support(q, n_parts)
    return PreparedReferences(q, np.sqrt(q), nz, nz_start, empty_rho, q.shape[1] // n_parts,
                              n_parts)


def prepared_distances(
    bin_img: NDArray[np.integer],
    boxes: NDArray[np.floating],
    prepared: PreparedReferences,
    ref_index: NDArray[np.integer],
    kernel: int,
    *,
    method: str = "auto",
    box_levels: int = DEFAULT_BOX_LEVELS,
) -> NDArray[np.float64]:
    """``region_distances`` against prepared references, with the per-call checks cut to
    what keeps the kernel in bounds.

    ``bin_img`` is trusted: a contiguous uint8, uint16 or int32 (H, W) array of bin indices
    in [0, ``prepared.n_bins``), as ``quantize_rgb`` / ``quantize_hsv`` give (an index out
    of range reads out of bounds). Boxes must be finite with positive sizes and
    ``ref_index`` must index ``prepared.refs``: both are checked.

    Returns
    -------
    ndarray of shape (P,)
        As ``region_distances``.

    Raises
    ------
    ValueError
        For boxes that are not (P, 4), finite and of positive size, a ``ref_index`` of the
        wrong shape or out of range, an unknown kernel or method.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; valid: {', '.join(METHODS)}")
    if kernel not in KERNELS.values():
        raise ValueError(f"kernel must be one of {sorted(KERNELS.values())} "
                         f"({', '.join(KERNELS)}), got {kernel!r}")
    bx = np.ascontiguousarray(boxes, dtype=np.float64)
    if bx.ndim != 2 or bx.shape[1] != 4:
        raise ValueError(f"boxes must have shape (P, 4), got {bx.shape}")
    # A NaN or an infinity makes the sum non-finite.
    if bx.size and not (np.isfinite(bx.sum()) and bx[:, 2:].min() > 0):
        raise ValueError("boxes must be finite with positive width and height")
    idx = np.ascontiguousarray(ref_index, dtype=np.int64)
    n_refs = prepared.refs.shape[0]
    if idx.shape != (bx.shape[0],):
        raise ValueError(f"ref_index must have shape ({bx.shape[0]},), got {idx.shape}")
    if idx.size and (idx.min() < 0 or idx.max() >= n_refs):
        raise ValueError(f"ref_index must lie in [0, {n_refs}), got "
                         f"[{idx.min()}, {idx.max()}]")
    fracs, a_fixed = _level_args(int(kernel), box_levels)
    return _region_distances(bin_img, bx, prepared.sqrt_refs, idx, prepared.nz,
                             prepared.nz_start, prepared.empty_rho, prepared.n_bins,
                             int(kernel), prepared.n_parts, _lanes(prepared.refs.shape[1]),
                             METHODS[method], fracs, a_fixed, numba.get_num_threads(),
                             _SMALL_SUPPORT)




def bhattacharyya_coefficient(
    hists: NDArray[np.floating], refs: NDArray[np.floating]
) -> NDArray[np.float64]:
    """ρ = Σ_u sqrt(p_u q_u) per row (docs/algorithms.md §2.2).

    Parameters
    ----------
    hists : ndarray of shape (P, B)
        Normalised histograms.
    refs : ndarray of shape (B,) or (P, B)
        One reference for all rows, or one per row.

    Returns
    -------
    ndarray of shape (P,)
    """
    p = np.asarray(hists, dtype=np.float64)
    q = np.asarray(refs, dtype=np.float64)
    if p.ndim != 2 or q.shape not in ((p.shape[1],), p.shape):
        raise ValueError(f"refs must have shape ({p.shape[-1]},) or {p.shape} for hists of "
                         f"shape (P, B); got hists {p.shape}, refs {q.shape}")
    return np.sqrt(p * q).sum(axis=1)


def bhattacharyya_distance(
    hists: NDArray[np.floating], refs: NDArray[np.floating]
) -> NDArray[np.float64]:
    """d = sqrt(max(0, 1 − ρ)) per row; what ``cv2.HISTCMP_BHATTACHARYYA`` gives for
    normalised histograms.

    Parameters
    ----------
    hists : ndarray of shape (P, B)
        Normalised histograms.
    refs : ndarray of shape (B,) or (P, B)
        One reference for all rows, or one per row.

    Returns
    -------
    ndarray of shape (P,)
        Distances in [0, 1].

    Example
    -------
    >>> bhattacharyya_distance(np.array([[0.5, 0.5], [1.0, 0.0]]), np.array([0.5, 0.5]))
    array([0.       , 0.5411961])
    """
    rho = bhattacharyya_coefficient(hists, refs)
    return np.sqrt(np.maximum(0.0, 1.0 - rho))
