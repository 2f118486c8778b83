"""Batched kernel-weighted colour histograms on a bin-index image (numba).

Every particle tracker spends its time building the colour histograms of candidate
regions (ALGORITHMS.md §2.2). The frame is quantised once into a bin-index image
(``quantize_rgb`` or ``quantize_hsv``); then one compiled call builds the histograms of
all candidate boxes of all objects (``region_histograms``), or directly their
Bhattacharyya distances to reference histograms (``region_distances``, which never
materialises the (P, B) histogram array).

Conventions shared by every function here (CONTRACT.md "Coordinates"):

- A box is [x, y, w, h]. Pixel (row r, column c) belongs to a box if its centre
  (c + 0.5, r + 0.5) lies in [x, x + w) × [y, y + h). Pixels outside the frame are
  skipped, so a region cut by the border is the histogram of its visible part.
- Kernel profiles, at the normalised elliptical radius
  r = sqrt(((px - cx) / (w / 2))² + ((py - cy) / (h / 2))²) of a pixel centre:
  ``KERNEL_UNIFORM`` weight 1 on the whole box; ``KERNEL_EPANECHNIKOV`` 1 − r²;
  ``KERNEL_CONE`` 1 − r (the linear kernel of KAMS §2); both elliptic kernels are 0 outside
  the ellipse inscribed in the box.
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
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = [
    "KERNEL_CONE",
    "KERNEL_EPANECHNIKOV",
    "KERNEL_UNIFORM",
    "KERNELS",
    "bhattacharyya_coefficient",
    "bhattacharyya_distance",
    "hsv_n_bins",
    "quantize_hsv",
    "quantize_rgb",
    "region_distances",
    "region_histograms",
]

KERNEL_UNIFORM = 0
KERNEL_EPANECHNIKOV = 1
KERNEL_CONE = 2

#: Kernel profile names, as accepted by the observation models, mapped to their codes.
KERNELS: dict[str, int] = {
    "uniform": KERNEL_UNIFORM,
    "epanechnikov": KERNEL_EPANECHNIKOV,
    "cone": KERNEL_CONE,
}


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
def _quantize_rgb(frame, bins):
    rows, cols = frame.shape[0], frame.shape[1]
    out = np.empty((rows, cols), dtype=np.int32)
    for r in range(rows):
        for c in range(cols):
            rb = np.int32(frame[r, c, 0]) * bins // 256
            gb = np.int32(frame[r, c, 1]) * bins // 256
            bb = np.int32(frame[r, c, 2]) * bins // 256
            out[r, c] = (rb * bins + gb) * bins + bb
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
def _floor_ratio(num, den, inv_den):
    """floor(num / den) for integers 0 <= num, 0 < den, from an approximate reciprocal.

    A multiplication by a tabulated 1/den is much cheaper than an integer division; the
    integer checks correct the one-off errors of rounding at exact multiples.
    """
    q = np.int64(num * inv_den)
    if q * den > num:
        q -= 1
    elif (q + 1) * den <= num:
        q += 1
    return q


@njit(cache=True)
def _quantize_hsv(frame, h_bins, s_bins, v_bins, s_thr, v_thr):
    # Integer arithmetic throughout: every bin is an exact floor of a ratio of integers,
    # so the quantisation does not depend on floating-point rounding at bin edges.
    rows, cols = frame.shape[0], frame.shape[1]
    out = np.empty((rows, cols), dtype=np.int32)
    v_offset = h_bins * s_bins
    inv = np.empty(256)
    inv[0] = 1.0
    for k in range(1, 256):
        inv[k] = 1.0 / k
    for i in range(rows):
        for j in range(cols):
            r = np.int64(frame[i, j, 0])
            g = np.int64(frame[i, j, 1])
            b = np.int64(frame[i, j, 2])
            mx = r if r > g else g
            mx = mx if mx > b else b
            mn = r if r < g else g
            mn = mn if mn < b else b
            d = mx - mn
            # Every candidate is computed and the right one selected, without branches:
            # on noisy frames which channel is largest is a coin flip that a branch
            # predictor loses. Hue in sixths of the colour circle, times d (hexcone).
            h6r = g - b + (6 * d if g < b else 0)
            h6g = b - r + 2 * d
            h6b = r - g + 4 * d
            h6 = h6r if mx == r else (h6g if mx == g else h6b)
            dd = d if d > 0 else 1
            hb = min(_floor_ratio(h6 * h_bins, 6 * dd, inv[dd] / 6.0), h_bins - 1)
            mxx = mx if mx > 0 else 1
            sb = min(_floor_ratio(d * s_bins, mxx, inv[mxx]), s_bins - 1)
            vb = min(mx * v_bins // 255, v_bins - 1)
            # S >= s_min and V >= v_min, i.e. d / mx >= s_min and mx / 255 >= v_min, with
            # the thresholds pre-scaled to integers (d * 2**20 >= s_thr * mx).
            coloured = (d > 0) & (mx >= v_thr) & ((d << 20) >= s_thr * mx)
            out[i, j] = hb * s_bins + sb if coloured else v_offset + vb
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
    floor(x · bins), with the top value in the last bin, computed exactly in integers in
    one compiled pass (no 8-bit rounding of H and S as in ``cv2.cvtColor``). ``s_min`` is
    applied with a resolution of 2**-20.

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
    s_thr = int(np.ceil(s_min * 2**20))
    v_thr = int(np.ceil(v_min * 255 - 1e-9))
    return _quantize_hsv(_check_frame(frame), np.int64(h_bins), np.int64(s_bins),
                         np.int64(v_bins), np.int64(s_thr), np.int64(v_thr))


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
_INV_ONE = 1.0 / _ONE
# Bins are grouped into at most 64 blocks whose "touched" bits live in one register, so
# the Bhattacharyya sweep skips the blocks a box never touched (most of a 1000-bin RGB
# histogram on a natural image) without a per-pixel memory dependency.
_MAX_BLOCKS = 64
_DENSE_BINS = 256


@njit(cache=True, fastmath=True)
def _cone_weights(wbuf, ca, cb, cx, inv_hw, dy2):
    """Fixed-point cone weights 1 − r of pixels ca..cb-1 of one row (vectorised loop)."""
    for c in range(ca, cb):
        dx = (c + 0.5 - cx) * inv_hw
        # r >= 1 (outside the ellipse) gives a weight <= 0: clamped to 0, it adds nothing.
        wbuf[c - ca] = np.int64(max(1.0 - np.sqrt(dx * dx + dy2), 0.0) * _ONE + 0.5)


@njit(cache=True)
def _accumulate(bin_img, x, y, w, h, n_bins, kernel, n_parts, hist, totals, wbuf, shift):
    """Add the fixed-point weighted pixels of box [x, y, w, h] into ``hist``.

    ``hist`` (n_parts * n_bins, int64) receives the weights, ``totals`` (n_parts, int64)
    each band's total; ``wbuf`` (W,) is scratch. Returns the bit mask of touched blocks of
    ``2**shift`` bins.
    """
    rows, cols = bin_img.shape
    r0, r1 = _pixel_range(y, h, rows)
    c0, c1 = _pixel_range(x, w, cols)
    for j in range(n_parts):
        totals[j] = 0
    mask = np.uint64(0)
    one = np.uint64(1)
    if r0 >= r1 or c0 >= c1:
        return mask
    cx = x + 0.5 * w
    cy = y + 0.5 * h
    inv_hw = 2.0 / w
    inv_hh = 2.0 / h
    band = h / n_parts
    unit = np.int64(_ONE)
    if kernel == KERNEL_EPANECHNIKOV:
        for c in range(c0, c1):
            dx = (c + 0.5 - cx) * inv_hw
            wbuf[c - c0] = np.int64(dx * dx * _ONE + 0.5)
    for r in range(r0, r1):
        py = r + 0.5
        part = int((py - y) / band)
        if part >= n_parts:
            part = n_parts - 1
        offset = part * n_bins
        row = bin_img[r]
        if kernel == KERNEL_UNIFORM:
            if shift < 0:
                for c in range(c0, c1):
                    hist[offset + row[c]] += unit
            else:
                for c in range(c0, c1):
                    b = offset + row[c]
                    hist[b] += unit
                    mask |= one << np.uint64(b >> shift)
            totals[part] += (c1 - c0) * unit
            continue
        dy = (py - cy) * inv_hh
        dy2 = dy * dy
        if dy2 >= 1.0:
            continue
        acc = 0
        if kernel == KERNEL_EPANECHNIKOV:
            # Separable: k = (1 − dy²) − dx², in fixed point, clamped to 0 outside the
            # ellipse; dx² was tabulated once per box.
            wr = np.int64((1.0 - dy2) * _ONE + 0.5)
            if shift < 0:
                for c in range(c0, c1):
                    k = max(wr - wbuf[c - c0], 0)
                    hist[offset + row[c]] += k
                    acc += k
            else:
                for c in range(c0, c1):
                    k = max(wr - wbuf[c - c0], 0)
                    b = offset + row[c]
                    hist[b] += k
                    acc += k
                    mask |= one << np.uint64(b >> shift)
            totals[part] += acc
            continue
        # Cone: columns of the ellipse's chord on this row, widened by one pixel so that
        # rounding never drops a pixel (those outside get weight 0).
        half = 0.5 * w * np.sqrt(1.0 - dy2)
        ca = max(c0, _first_inside(cx - half) - 1)
        cb = min(c1, _first_inside(cx + half) + 1)
        _cone_weights(wbuf, ca, cb, cx, inv_hw, dy2)
        if shift < 0:
            for c in range(ca, cb):
                k = wbuf[c - ca]
                hist[offset + row[c]] += k
                acc += k
        else:
            for c in range(ca, cb):
                k = wbuf[c - ca]
                b = offset + row[c]
                hist[b] += k
                acc += k
                mask |= one << np.uint64(b >> shift)
        totals[part] += acc
    return mask


def _block_shift(dim):
    """Smallest block size 2**shift that splits ``dim`` bins into <= 64 blocks.

    -1 (no blocks, dense sweep) for histograms of at most ``_DENSE_BINS`` bins, where
    keeping the mask costs more than sweeping every bin.
    """
    if dim <= _DENSE_BINS:
        return -1
    shift = 0
    while (dim + (1 << shift) - 1) >> shift > _MAX_BLOCKS:
        shift += 1
    return shift


@njit(cache=True)
def _region_histograms(bin_img, boxes, n_bins, kernel, n_parts, shift):
    n_boxes = boxes.shape[0]
    dim = n_parts * n_bins
    out = np.empty((n_boxes, dim))
    hist = np.zeros(dim, dtype=np.int64)
    totals = np.empty(n_parts, dtype=np.int64)
    wbuf = np.empty(bin_img.shape[1] + 2, dtype=np.int64)
    for p in range(n_boxes):
        _accumulate(bin_img, boxes[p, 0], boxes[p, 1], boxes[p, 2], boxes[p, 3], n_bins,
                    kernel, n_parts, hist, totals, wbuf, shift)
        for j in range(n_parts):
            lo = j * n_bins
            if totals[j] > 0:
                scale = 1.0 / (totals[j] * n_parts)
                for b in range(lo, lo + n_bins):
                    out[p, b] = hist[b] * scale
            else:
                fill = 1.0 / (n_bins * n_parts)
                for b in range(lo, lo + n_bins):
                    out[p, b] = fill
            hist[lo:lo + n_bins] = 0
    return out


@njit(cache=True, fastmath=True)
def _sweep(hist, sqrt_q, lo, hi, scale, mask, shift):
    """Σ sqrt(hist_b · scale) sqrt(q_b) over the touched blocks of bins [lo, hi).

    Clears ``hist`` there. Blocks not in ``mask`` are zero and contribute nothing; with
    ``shift`` < 0 every bin is swept.
    """
    acc = 0.0
    if shift < 0:
        for b in range(lo, hi):
            acc += np.sqrt(hist[b] * scale) * sqrt_q[b]
            hist[b] = 0
        return acc
    size = 1 << shift
    blk = lo >> shift
    last = (hi - 1) >> shift
    while blk <= last:
        if mask & (np.uint64(1) << np.uint64(blk)):
            b0 = max(lo, blk * size)
            b1 = min(hi, (blk + 1) * size)
            for b in range(b0, b1):
                acc += np.sqrt(hist[b] * scale) * sqrt_q[b]
                hist[b] = 0
        blk += 1
    return acc


@njit(cache=True)
def _region_distances(bin_img, boxes, sqrt_refs, ref_index, n_bins, kernel, n_parts, shift):
    n_boxes = boxes.shape[0]
    out = np.empty(n_boxes)
    hist = np.zeros(n_parts * n_bins, dtype=np.int64)
    totals = np.empty(n_parts, dtype=np.int64)
    wbuf = np.empty(bin_img.shape[1] + 2, dtype=np.int64)
    fill = np.sqrt(1.0 / (n_bins * n_parts))
    for p in range(n_boxes):
        sqrt_q = sqrt_refs[ref_index[p]]
        mask = _accumulate(bin_img, boxes[p, 0], boxes[p, 1], boxes[p, 2], boxes[p, 3],
                           n_bins, kernel, n_parts, hist, totals, wbuf, shift)
        rho = 0.0
        for j in range(n_parts):
            lo = j * n_bins
            if totals[j] > 0:
                rho += _sweep(hist, sqrt_q, lo, lo + n_bins, 1.0 / (totals[j] * n_parts),
                              mask, shift)
            else:
                # Uniform band (module docstring).
                rho += fill * sqrt_q[lo:lo + n_bins].sum()
        one_minus = 1.0 - rho
        out[p] = np.sqrt(one_minus) if one_minus > 0.0 else 0.0
    return out


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
    return img.astype(np.int32, copy=False), bx, int(n_bins), int(kernel), int(n_parts)


def region_histograms(
    bin_img: NDArray[np.integer],
    boxes: NDArray[np.floating],
    n_bins: int,
    kernel: int,
    n_parts: int = 1,
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
        ``KERNEL_UNIFORM``, ``KERNEL_EPANECHNIKOV`` or ``KERNEL_CONE``.
    n_parts : int, optional
        Horizontal bands (spatial components), concatenated top to bottom.

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
    return _region_histograms(img, bx, n_bins, kernel, n_parts, _block_shift(n_bins * n_parts))


def region_distances(
    bin_img: NDArray[np.integer],
    boxes: NDArray[np.floating],
    refs: NDArray[np.floating],
    ref_index: NDArray[np.integer],
    kernel: int,
    n_parts: int = 1,
    *,
    check_bins: bool = True,
) -> NDArray[np.float64]:
    """Bhattacharyya distance of every box's histogram to its reference, in one call.

    Equal to ``bhattacharyya_distance(region_histograms(...), refs[ref_index])`` (to
    rounding) but without building the (P, B) histogram array: one scratch histogram is
    reused, which is what makes a frame of thousands of candidates cheap.

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
    q = np.ascontiguousarray(refs, dtype=np.float64)
    if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] < 1:
        raise ValueError(f"refs must have shape (R, n_parts * n_bins), got {q.shape}")
    if int(n_parts) != n_parts or n_parts < 1 or q.shape[1] % n_parts:
        raise ValueError(f"n_parts must be a positive divisor of refs.shape[1] = "
                         f"{q.shape[1]}, got {n_parts!r}")
    img, bx, n_bins, kernel, n_parts = _check_region_args(bin_img, boxes,
                                                          q.shape[1] // int(n_parts),
                                                          kernel, n_parts, check_bins)
    idx = np.ascontiguousarray(ref_index, dtype=np.int64)
    if idx.shape != (bx.shape[0],):
        raise ValueError(f"ref_index must have shape ({bx.shape[0]},), got {idx.shape}")
    if idx.size and (idx.min() < 0 or idx.max() >= q.shape[0]):
        raise ValueError(f"ref_index must lie in [0, {q.shape[0]}), got "
                         f"[{idx.min()}, {idx.max()}]")
    return _region_distances(img, bx, np.sqrt(q), idx, n_bins, kernel, n_parts,
                             _block_shift(q.shape[1]))


def bhattacharyya_coefficient(
    hists: NDArray[np.floating], refs: NDArray[np.floating]
) -> NDArray[np.float64]:
    """ρ = Σ_u sqrt(p_u q_u) per row (ALGORITHMS.md §2.1).

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
