"""Batched kernel-weighted colour histograms on a bin-index image (numba).

Every particle tracker spends its time building the colour histograms of candidate
regions (docs/algorithms.md §2.2). The frame is quantised once into a bin-index image
(``quantize_rgb`` or ``quantize_hsv``); then one compiled call builds the histograms of
all candidate boxes of all objects (``region_histograms``), or directly their
Bhattacharyya distances to reference histograms (``region_distances``, which never
materialises the (P, B) histogram array).

This module holds those entry points and, per reference, the choice between the two
evaluation paths (a fitted cost model; ``region_paths`` tells which path each box takes);
the work is in four modules it re-exports from:
``quantize`` (the bin-index image), ``profiles`` (kernel codes, box-kernel levels, the
pixel rule of a box and each row's fixed-point weights), ``direct`` (pixel-by-pixel
accumulation) and ``integral`` (integral histograms).

Conventions shared by every function of these modules (docs/algorithms.md, "Notation"):

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
- No function of these modules is compiled with ``fastmath``: a reassociated
  floating-point sum can depend on the memory alignment of its arrays (vector loops peel a
  different number of leading elements), which broke "same inputs, same bytes" between two
  processes. Every floating-point sum runs in a fixed order.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from trackers.kernels.direct import (
    _SMALL_SUPPORT,
    _direct_distance,
    _lanes,
    _region_histograms,
)
from trackers.kernels.integral import _integral_distances
from trackers.kernels.profiles import (
    DEFAULT_BOX_LEVELS,
    KERNEL_BOX,
    KERNEL_CONE,
    KERNEL_EPANECHNIKOV,
    KERNEL_UNIFORM,
    KERNELS,
    _is_kernel_code,
    _level_args,
    _pixel_range,
    box_kernel_levels,
)
from trackers.kernels.quantize import _is_integer, hsv_n_bins, quantize_hsv, quantize_rgb

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
    "region_paths",
]


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
def _integral_cheaper(rows, cols, boxes, members, nz, nz_start, n_bins, n_parts, method,
                      n_levels, roi):
    """Whether one reference's boxes ``members`` take the integral path: it is asked for,
    or the cost model finds it cheaper; and the integral fits in ``_MAX_CELLS`` cells.
    Fills ``roi`` (r0, r1, c0, c1) with the union of the members' pixels."""
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
    return roi[1] > roi[0] and cells <= _MAX_CELLS and (
        method == METHOD_INTEGRAL or cost_integral < cost_direct)


@njit(cache=True)
def _plan_paths(rows, cols, boxes, ref_index, nz, nz_start, n_bins, n_parts, kernel,
                method, a_fixed):
    """The boxes grouped by reference, and per group whether it takes the integral path
    (``_integral_cheaper``) and its ROI.

    ``a_fixed`` (L,) are the box kernel's level weights (empty for the other kernels,
    whose integral reads one rectangle a box: L counts as 1 in the cost).

    Returns ``order`` (P,) (a permutation of the boxes, sorted by reference), ``starts``
    (G + 1,) (where each group's run starts in ``order``), ``integral`` (G,) bool and
    ``rois`` (G, 4); the direct path alone (``method`` direct, an elliptic kernel) gives
    no group.
    """
    if (kernel != KERNEL_UNIFORM and kernel != KERNEL_BOX) or method == METHOD_DIRECT:
        return (np.arange(boxes.shape[0]), np.zeros(1, dtype=np.int64),
                np.zeros(0, dtype=np.bool_), np.zeros((0, 4), dtype=np.int64))
    n_levels = max(a_fixed.shape[0], 1)
    order, starts = _reference_groups(ref_index)
    n_groups = starts.shape[0] - 1
    integral = np.zeros(n_groups, dtype=np.bool_)
    rois = np.zeros((n_groups, 4), dtype=np.int64)
    for g in range(n_groups):
        members = order[starts[g]:starts[g + 1]]
        ref = ref_index[members[0]]
        integral[g] = _integral_cheaper(rows, cols, boxes, members, nz[ref], nz_start[ref],
                                        n_bins, n_parts, method, n_levels, rois[g])
    return order, starts, integral, rois


@njit(cache=True)
def _support_colours(nz, nz_start, n_bins, n_parts, max_support):
    """Per reference, its support bins' colours within their band (``colours``, shaped
    as ``nz``) and whether every band has at most ``max_support`` of them (``small``,
    (R,) bool): the references whose direct path is the support path (``_SMALL_SUPPORT``).
    """
    n_refs = nz.shape[0]
    colours = np.zeros_like(nz)
    small = np.empty(n_refs, dtype=np.bool_)
    for q in range(n_refs):
        small[q] = True
        for j in range(n_parts):
            if nz_start[q, j + 1] - nz_start[q, j] > max_support:
                small[q] = False
            for t in range(nz_start[q, j], nz_start[q, j + 1]):
                colours[q, t] = nz[q, t] - j * n_bins
    return colours, small


@njit(cache=True, parallel=True)
def _region_distances(bin_img, boxes, sqrt_refs, ref_index, nz, nz_start, empty_rho,
                      n_bins, kernel, n_parts, lanes, method, fracs, a_fixed, n_chunks,
                      max_support):
    """Distances of every box to its reference, in parallel over references (integral
    path) and over chunks of boxes (direct path). Every box is computed alone from zeroed
    scratch, with sums in a fixed order, so the result does not depend on the number of
    threads or on how the boxes are chunked. The direct path of a reference with at most
    ``max_support`` support bins in every band counts only those (``_SMALL_SUPPORT``; the
    same bits as the whole histogram).

    Returns the distances (P,) and, per box, whether the direct path scored it (P,) bool
    (``region_paths``' complement: the scoring follows ``_plan_paths``)."""
    n_boxes = boxes.shape[0]
    rows, cols = bin_img.shape
    out = np.empty(n_boxes)
    direct = np.ones(n_boxes, dtype=np.bool_)
    order, starts, integral, rois = _plan_paths(rows, cols, boxes, ref_index, nz, nz_start,
                                                n_bins, n_parts, kernel, method, a_fixed)
    for g in prange(integral.shape[0]):
        if integral[g]:
            members = order[starts[g]:starts[g + 1]]
            ref = ref_index[members[0]]
            _integral_distances(bin_img, boxes, members, sqrt_refs[ref], nz[ref],
                                nz_start[ref], empty_rho[ref], n_bins, n_parts, rois[g],
                                out, kernel, fracs, a_fixed)
            for m in members:
                direct[m] = False
    dim = n_parts * n_bins
    colours, small = _support_colours(nz, nz_start, n_bins, n_parts, max_support)
    n_chunks = max(min(n_chunks, n_boxes), 1)
    for ch in prange(n_chunks):
        hist = np.zeros(lanes * dim, dtype=np.int64)
        totals = np.empty(n_parts, dtype=np.int64)
        # A row's weights and squared offsets: at most the frame's width (``direct``).
        tbuf = np.empty(cols, dtype=np.int64)
        kbuf = np.empty(cols, dtype=np.int64)
        rects = np.empty((a_fixed.shape[0], 4), dtype=np.int64)
        sums = np.empty(dim, dtype=np.int64)
        for p in range(ch * n_boxes // n_chunks, (ch + 1) * n_boxes // n_chunks):
            if direct[p]:
                ref = ref_index[p]
                out[p] = _direct_distance(bin_img, boxes[p], sqrt_refs[ref], nz[ref],
                                          nz_start[ref], empty_rho[ref], n_bins, kernel,
                                          n_parts, hist, lanes, totals, tbuf, kbuf, fracs,
                                          a_fixed, rects, colours[ref], sums, small[ref])
    return out, direct


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
    if not _is_integer(n_bins) or n_bins < 1:
        raise ValueError(f"n_bins must be a positive integer, got {n_bins!r}")
    if check_bins and img.size and (img.min() < 0 or img.max() >= n_bins):
        raise ValueError(f"bin_img values must lie in [0, {n_bins}), got "
                         f"[{img.min()}, {img.max()}]")
    if not _is_kernel_code(kernel, KERNELS.values()):
        raise ValueError(f"kernel must be one of {sorted(KERNELS.values())} "
                         f"({', '.join(KERNELS)}), got {kernel!r}")
    if not _is_integer(n_parts) or n_parts < 1:
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

    Examples
    --------
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

    Examples
    --------
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

    Attributes
    ----------
    refs : ndarray of shape (R, n_parts * n_bins)
        The reference histograms, float64, C-contiguous.
    sqrt_refs : ndarray of shape (R, n_parts * n_bins)
        Their square roots.
    nz : ndarray of shape (R, n_parts * n_bins), int64
        Each reference's bins with q > 0, first, in order.
    nz_start : ndarray of shape (R, n_parts + 1), int64
        Where each band's bins start in ``nz``.
    empty_rho : ndarray of shape (R, n_parts)
        ρ of a band with no pixel (the uniform histogram).
    n_bins : int
        Bins per band.
    n_parts : int
        Horizontal bands.
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

    Returns
    -------
    PreparedReferences
        The references with their square roots, supports and empty-band ρ.

    Raises
    ------
    ValueError
        For a bad shape, or ``n_parts`` not dividing the number of bins.
    """
    q = np.ascontiguousarray(refs, dtype=np.float64)
    if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] < 1:
        raise ValueError(f"refs must have shape (R, n_parts * n_bins), got {q.shape}")
    if not _is_integer(n_parts) or n_parts < 1 or q.shape[1] % n_parts:
        raise ValueError(f"n_parts must be a positive divisor of refs.shape[1] = "
                         f"{q.shape[1]}, got {n_parts!r}")
    n_parts = int(n_parts)
    nz, nz_start, empty_rho = _support(q, n_parts)
    return PreparedReferences(q, np.sqrt(q), nz, nz_start, empty_rho, q.shape[1] // n_parts,
                              n_parts)


def _check_prepared_args(boxes, prepared, ref_index, kernel, method):
    """The checks of ``prepared_distances`` and ``region_paths``; the boxes and indices as
    contiguous float64 and int64 arrays."""
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; valid: {', '.join(METHODS)}")
    if not _is_kernel_code(kernel, KERNELS.values()):
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
    return bx, idx


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

    Parameters
    ----------
    bin_img : ndarray of shape (H, W), uint8, uint16 or int32
        Bin index of every pixel, in [0, ``prepared.n_bins``) (not checked).
    boxes : ndarray of shape (P, 4)
        Candidate boxes [x, y, w, h] in pixels.
    prepared : PreparedReferences
        From ``prepare_references``.
    ref_index : ndarray of shape (P,), integer
        Row of ``prepared.refs`` that box p is compared with.
    kernel : int
        Kernel code, as in ``region_histograms``.
    method : {"auto", "direct", "integral"}, optional
        Evaluation path, as in ``region_distances``.
    box_levels : int, optional
        Levels L of ``KERNEL_BOX`` (ignored by the other kernels).

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
    bx, idx = _check_prepared_args(boxes, prepared, ref_index, kernel, method)
    fracs, a_fixed = _level_args(int(kernel), box_levels)
    return _region_distances(bin_img, bx, prepared.sqrt_refs, idx, prepared.nz,
                             prepared.nz_start, prepared.empty_rho, prepared.n_bins,
                             int(kernel), prepared.n_parts, _lanes(prepared.refs.shape[1]),
                             METHODS[method], fracs, a_fixed, numba.get_num_threads(),
                             _SMALL_SUPPORT)[0]


def region_paths(
    bin_img: NDArray[np.integer],
    boxes: NDArray[np.floating],
    prepared: PreparedReferences,
    ref_index: NDArray[np.integer],
    kernel: int,
    *,
    method: str = "auto",
    box_levels: int = DEFAULT_BOX_LEVELS,
) -> NDArray[np.bool_]:
    """Which boxes ``prepared_distances`` scores by the integral path.

    The same compiled choice the scoring makes (one definition): per reference, the
    integral path when ``method`` is "integral", or when it is "auto" and the fitted cost
    model finds it cheaper than the direct path; never for the elliptic kernels, and not
    for a reference whose integral histogram would exceed 2**24 cells. Both paths give the
    same distances (to rounding), so this only tells where the time goes: a profiler's and
    a test's view of the dispatch.

    Parameters
    ----------
    bin_img : ndarray of shape (H, W), integer
        The bin-index image (only its shape is read).
    boxes : ndarray of shape (P, 4)
        Candidate boxes [x, y, w, h] in pixels.
    prepared : PreparedReferences
        From ``prepare_references``.
    ref_index : ndarray of shape (P,), integer
        Row of ``prepared.refs`` that box p is compared with.
    kernel : int
        Kernel code, as in ``region_histograms``.
    method : {"auto", "direct", "integral"}, optional
        Evaluation path, as in ``region_distances``.
    box_levels : int, optional
        Levels L of ``KERNEL_BOX`` (ignored by the other kernels).

    Returns
    -------
    ndarray of shape (P,), bool
        True where box p takes the integral path, False where it takes the direct path.

    Raises
    ------
    ValueError
        As ``prepared_distances``, and for a ``bin_img`` that is not two-dimensional.

    Examples
    --------
    >>> img = np.zeros((100, 100), dtype=np.int32)
    >>> prepared = prepare_references(np.array([[0.5, 0.5]]))
    >>> cloud = np.tile([20.0, 20.0, 40.0, 40.0], (300, 1))
    >>> bool(region_paths(img, cloud, prepared, np.zeros(300), KERNEL_BOX).all())
    True
    >>> bool(region_paths(img, cloud[:1], prepared, np.zeros(1), KERNEL_BOX).any())
    False
    """
    bx, idx = _check_prepared_args(boxes, prepared, ref_index, kernel, method)
    shape = np.shape(bin_img)
    if len(shape) != 2:
        raise ValueError(f"bin_img must have shape (H, W), got {shape}")
    _, a_fixed = _level_args(int(kernel), box_levels)
    order, starts, integral, _ = _plan_paths(
        int(shape[0]), int(shape[1]), bx, idx, prepared.nz, prepared.nz_start,
        prepared.n_bins, prepared.n_parts, int(kernel), METHODS[method], a_fixed)
    taken = np.zeros(bx.shape[0], dtype=np.bool_)
    for g in np.flatnonzero(integral):
        taken[order[starts[g]:starts[g + 1]]] = True
    return taken


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

    Examples
    --------
    >>> bhattacharyya_distance(np.array([[0.5, 0.5], [1.0, 0.0]]), np.array([0.5, 0.5]))
    array([0.       , 0.5411961])
    """
    rho = bhattacharyya_coefficient(hists, refs)
    return np.sqrt(np.maximum(0.0, 1.0 - rho))
