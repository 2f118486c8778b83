"""Batched kernel mean shift (Comaniciu, Ramesh & Meer 2003) on a bin-index image.

Every start point of a frame (all particles of all targets) runs in one compiled call.
Each start point climbs the Bhattacharyya coefficient between its target model ``q`` and
the kernel-weighted colour histogram ``p(y)`` of the window centred at ``y``:

1. ``p(y0)`` and ``rho0 = sum_b sqrt(p_b(y0) q_b)`` at the current centre ``y0``;
2. every pixel ``x_i`` of the window gets the weight ``w_i = sqrt(q_b(i) / p_b(i)(y0))``
   (Comaniciu et al. 2003, eq. 25);
3. ``y1 = sum_i x_i w_i g_i / sum_i w_i g_i`` (eq. 26), with ``g`` the shadow profile;
4. if ``rho`` dropped, move ``y1`` half-way back to ``y0`` (Comaniciu et al.'s step 5, at
   most 8 times); if it still dropped, keep ``y0`` and stop: the distance
   ``d = sqrt(1 - rho)`` stopped improving (KAMS §2);
5. stop also when ``d`` falls to ``min_distance`` or below, when the shift ``|y1 - y0|``
   falls below ``eps`` pixels, or after ``max_iter`` shifts.

The window of a start point is the ellipse inscribed in its box (``sizes`` = box width and
height); pixels outside the frame are skipped and the histogram is normalised over the
pixels inside, with the pixel rule and kernel weights of
``trackers.kernels.histogram.region_histograms``: a window cut by the frame border is
handled, and the distances agree with ``region_distances`` to about 1e-10 (that kernel
accumulates in fixed point). The window histograms are accumulated here, not by that
kernel, because each iteration needs the list of bins a window touches, to clear them and
to weight pixels without sweeping all B bins.

Kernels (KAMS §2 and Comaniciu et al. §4.1):

- ``KERNEL_EPANECHNIKOV``: profile ``k(r²) = 1 - r²``; its shadow ``g`` is constant, so
  the new centre is the ``w``-weighted mean of the pixel positions (eq. 26).
- ``KERNEL_CONE``: the KAMS linear kernel ``1 - r`` (weight 1 at the centre, 0 on the
  boundary). Its exact shadow ``g(r²) ∝ 1 / r`` is singular at the centre, so, as KAMS
  does (its eq. 6–7), the shift uses a constant ``g``: the cone weights the histograms,
  the shift is the ``w``-weighted mean of the pixel positions.

A window with no pixel inside the frame, or whose pixels all fall in bins empty in ``q``,
does not move; an empty window has the uniform histogram, as in ``region_distances``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from numpy.typing import NDArray

from trackers.kernels.histogram import KERNEL_CONE, KERNEL_EPANECHNIKOV
from trackers.kernels.profiles import _is_kernel_code
from trackers.kernels.quantize import _is_integer, _is_number

__all__ = ["MEAN_SHIFT_KERNELS", "MeanShiftResult", "mean_shift"]

#: Kernel names accepted by the mean-shift trackers, mapped to the kernel constants.
MEAN_SHIFT_KERNELS: dict[str, int] = {
    "epanechnikov": KERNEL_EPANECHNIKOV,
    "cone": KERNEL_CONE,
}


class MeanShiftResult(NamedTuple):
    """What ``mean_shift`` returns.

    Attributes
    ----------
    centres : ndarray of shape (P, 2)
        Converged window centres (x, y), in pixels.
    distances : ndarray of shape (P,)
        Bhattacharyya distance between the model and the window at ``centres``.
    n_iter : ndarray of shape (P,)
        Shifts attempted per start point (a rejected shift counts).
    """

    centres: NDArray[np.float64]
    distances: NDArray[np.float64]
    n_iter: NDArray[np.int64]


# Comaniciu et al.'s step 5 halves a step that lowered the similarity; eight halvings
# shrink it 256-fold, below any useful eps.
_MAX_HALVINGS = 8


@njit(cache=True)
def _pixel_range(lo, size, n):
    """Pixel indices [i0, i1) whose centres i + 0.5 lie in [lo, lo + size), within [0, n)."""
    i0 = int(np.ceil(lo - 0.5))
    i1 = int(np.ceil(lo + size - 0.5))
    return max(i0, 0), min(i1, n)


@njit(cache=True)
def _chord(ex, half_w, dy2, c0, c1):
    """Columns [ca, cb) of the ellipse's chord on a row with normalised dy² < 1, widened by
    one pixel on each side so rounding never drops a pixel (the exact test is per pixel)."""
    half = half_w * np.sqrt(1.0 - dy2)
    ca = int(np.ceil(ex - half - 0.5)) - 1
    cb = int(np.ceil(ex + half - 0.5)) + 1
    return max(ca, c0), min(cb, c1)


@njit(cache=True)
def _row_weights(kbuf, ca, cb, ex, inv_hw, dy2, kernel):
    """Kernel weights of pixels ca..cb-1 of one row into kbuf[0:cb-ca]; <= 0 outside the
    ellipse. A loop without branches on the data, so it vectorises (square roots too)."""
    if kernel == KERNEL_CONE:
        for c in range(ca, cb):
            dx = (c + 0.5 - ex) * inv_hw
            kbuf[c - ca] = 1.0 - np.sqrt(dx * dx + dy2)
    else:
        for c in range(ca, cb):
            dx = (c + 0.5 - ex) * inv_hw
            kbuf[c - ca] = 1.0 - (dx * dx + dy2)


@njit(cache=True)
def _window(bin_img, cx, cy, w, h, kernel, hist, totals, touched, kbuf):
    """Accumulate the kernel-weighted histogram of the window of size (w, h) centred at
    (cx, cy) into ``hist`` (zero on entry), with ``region_histograms``' pixel rule: pixel
    centres inside the box and strictly inside its ellipse, positive weight.

    The bins that become non-zero are listed in ``touched`` so that the distance and the
    clearing cost the window's size, not the number of bins. ``totals[0]`` receives the
    total weight; ``kbuf`` (W,) is scratch. Returns the number of touched bins.
    """
    rows, cols = bin_img.shape
    x = cx - 0.5 * w
    y = cy - 0.5 * h
    r0, r1 = _pixel_range(y, h, rows)
    c0, c1 = _pixel_range(x, w, cols)
    ex = x + 0.5 * w
    ey = y + 0.5 * h
    inv_hw = 2.0 / w
    inv_hh = 2.0 / h
    n = 0
    total = 0.0
    for r in range(r0, r1):
        dy = (r + 0.5 - ey) * inv_hh
        dy2 = dy * dy
        if dy2 >= 1.0:
            continue
        ca, cb = _chord(ex, 0.5 * w, dy2, c0, c1)
        _row_weights(kbuf, ca, cb, ex, inv_hw, dy2, kernel)
        row = bin_img[r]
        for c in range(ca, cb):
            # r² >= 1 (outside the ellipse) gives k <= 0 for both kernels.
            k = kbuf[c - ca]
            if k <= 0.0:
                continue
            b = row[c]
            if hist[b] == 0.0:
                touched[n] = b
                n += 1
            hist[b] += k
            total += k
    totals[0] = total
    return n


@njit(cache=True)
def _distance(q, hist, totals, touched, n_touched, n_bins):
    """Bhattacharyya distance of the accumulated window to ``q``, computed exactly as
    ``region_distances`` does (an empty window is the uniform histogram)."""
    rho = 0.0
    if totals[0] > 0.0:
        scale = 1.0 / totals[0]
    else:
        scale = 0.0
        fill = 1.0 / n_bins
        for b in range(n_bins):
            rho += np.sqrt(fill * q[b])
    for t in range(n_touched):
        b = touched[t]
        rho += np.sqrt(hist[b] * scale * q[b])
    one_minus = 1.0 - rho
    return np.sqrt(one_minus) if one_minus > 0.0 else 0.0


@njit(cache=True)
def _clear(hist, touched, n_touched):
    for t in range(n_touched):
        hist[touched[t]] = 0.0


@njit(cache=True)
def _shift(bin_img, cx, cy, w, h, q, hist, total, touched, n_touched, weight):
    """New centre by eq. 26 with a constant shadow; returns (x, y, sum of weights).

    Visits the pixels ``_window`` weighted (same box range, same ellipse test r^2 < 1).
    Each of them carried a positive weight there (1 - r^2, or 1 - sqrt(r^2) with
    sqrt(r^2) < 1 for every double r^2 < 1), so its bin is among the touched ones and
    ``weight`` holds its eq. 25 weight. ``weight`` (B,) is scratch space for the per-bin
    weights, so the pixel loop takes no square root.
    """
    for t in range(n_touched):
        b = touched[t]
        # eq. 25: w_i = sqrt(q_b / p_b(y0)) with p_b = hist_b / total.
        weight[b] = np.sqrt(q[b] * total / hist[b])
    rows, cols = bin_img.shape
    x = cx - 0.5 * w
    y = cy - 0.5 * h
    r0, r1 = _pixel_range(y, h, rows)
    c0, c1 = _pixel_range(x, w, cols)
    ex = x + 0.5 * w
    ey = y + 0.5 * h
    inv_hw = 2.0 / w
    inv_hh = 2.0 / h
    # Offsets from the centre rather than absolute positions: a scene shifted by whole
    # pixels gives the same sums, so exact ties stay exact (no 64.50000000000001).
    sx = 0.0
    sy = 0.0
    sw = 0.0
    for r in range(r0, r1):
        py = r + 0.5
        dy = (py - ey) * inv_hh
        dy2 = dy * dy
        if dy2 >= 1.0:
            continue
        ca, cb = _chord(ex, 0.5 * w, dy2, c0, c1)
        row_w = 0.0
        row_x = 0.0
        for c in range(ca, cb):
            px = c + 0.5
            dx = (px - ex) * inv_hw
            if dx * dx + dy2 >= 1.0:
                continue
            wi = weight[bin_img[r, c]]
            row_x += wi * (px - cx)
            row_w += wi
        sx += row_x
        sy += row_w * (py - cy)
        sw += row_w
    if sw <= 0.0:
        return cx, cy, 0.0
    return cx + sx / sw, cy + sy / sw, sw


@njit(cache=True)
def _mean_shift(bin_img, models, model_index, centres, sizes, kernel, max_iter, eps,
                min_distance):
    n_points = centres.shape[0]
    n_bins = models.shape[1]
    out = np.empty((n_points, 2))
    dist = np.empty(n_points)
    iters = np.zeros(n_points, dtype=np.int64)
    hist = np.zeros(n_bins)
    totals = np.empty(1)
    touched = np.empty(n_bins, dtype=np.int64)
    weight = np.empty(n_bins)
    kbuf = np.empty(bin_img.shape[1])
    eps2 = eps * eps
    for p in range(n_points):
        q = models[model_index[p]]
        w = sizes[p, 0]
        h = sizes[p, 1]
        x0 = centres[p, 0]
        y0 = centres[p, 1]
        n = _window(bin_img, x0, y0, w, h, kernel, hist, totals, touched, kbuf)
        d0 = _distance(q, hist, totals, touched, n, n_bins)
        it = 0
        while it < max_iter and d0 > min_distance and totals[0] > 0.0:
            x1, y1, sw = _shift(bin_img, x0, y0, w, h, q, hist, totals[0], touched, n,
                                weight)
            it += 1
            if sw <= 0.0:
                break
            _clear(hist, touched, n)
            n = _window(bin_img, x1, y1, w, h, kernel, hist, totals, touched, kbuf)
            d1 = _distance(q, hist, totals, touched, n, n_bins)
            step2 = (x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0)
            halvings = 0
            while d1 > d0 and step2 >= eps2 and halvings < _MAX_HALVINGS:
                # Step 5 of Comaniciu et al.'s algorithm: eq. 26 maximises a linear
                # approximation of rho, so move half-way back until rho does not drop.
                _clear(hist, touched, n)
                x1 = 0.5 * (x0 + x1)
                y1 = 0.5 * (y0 + y1)
                step2 *= 0.25
                halvings += 1
                n = _window(bin_img, x1, y1, w, h, kernel, hist, totals, touched, kbuf)
                d1 = _distance(q, hist, totals, touched, n, n_bins)
            if d1 > d0:
                # The similarity stopped improving: y0 is the converged point.
                break
            x0 = x1
            y0 = y1
            d0 = d1
            if step2 < eps2:
                break
        _clear(hist, touched, n)
        out[p, 0] = x0
        out[p, 1] = y0
        dist[p] = d0
        iters[p] = it
    return out, dist, iters


def mean_shift(
    bin_img: NDArray[np.integer],
    models: NDArray[np.floating],
    model_index: NDArray[np.integer],
    centres: NDArray[np.floating],
    sizes: NDArray[np.floating],
    *,
    kernel: int = KERNEL_CONE,
    max_iter: int = 20,
    eps: float = 0.5,
    min_distance: float = 0.0,
    check_bins: bool = True,
) -> MeanShiftResult:
    """Run kernel mean shift from every start point of a frame in one compiled call.

    Parameters
    ----------
    bin_img : ndarray of shape (H, W), integer
        Bin index of every pixel (``trackers.kernels.histogram.quantize_rgb``).
    models : ndarray of shape (K, B)
        Normalised target histograms ``q``, one per target, built with the same ``kernel``.
    model_index : ndarray of shape (P,), integer
        Which row of ``models`` each start point climbs towards.
    centres : ndarray of shape (P, 2)
        Start centres (x, y) in pixels.
    sizes : ndarray of shape (P, 2)
        Window width and height of each start point, in pixels (> 0).
    kernel : int, optional
        ``KERNEL_EPANECHNIKOV`` or ``KERNEL_CONE`` (default, the KAMS kernel).
    max_iter : int, optional
        Maximum shifts per start point (>= 0); 0 returns the start points and their
        distances.
    eps : float, optional
        Stop when one shift moves the centre by less than ``eps`` pixels (>= 0).
    min_distance : float, optional
        Stop when the Bhattacharyya distance falls to this value or below (>= 0).
    check_bins : bool, optional
        Check that every bin index lies in [0, B); callers passing a bin image from the
        matching quantiser skip this full-frame scan.

    Returns
    -------
    MeanShiftResult
        ``centres`` (P, 2), ``distances`` (P,) and ``n_iter`` (P,).

    Raises
    ------
    ValueError
        For inconsistent shapes, a bin index outside ``models``' bins, an unknown kernel,
        non-positive sizes or negative ``max_iter``, ``eps`` or ``min_distance``.

    Examples
    --------
    A two-colour disc of radius 10 centred at (20, 20) on a background of bin 0:

    >>> import numpy as np
    >>> from trackers.kernels.histogram import region_histograms
    >>> yy, xx = np.mgrid[0:40, 0:40] + 0.5
    >>> disc = (xx - 20) ** 2 + (yy - 20) ** 2 < 100
    >>> bins = np.where(disc, np.where(xx < 20, 2, 1), 0).astype(np.int32)
    >>> q = region_histograms(bins, np.array([[10.0, 10.0, 20.0, 20.0]]), 3, KERNEL_CONE)
    >>> r = mean_shift(bins, q, np.array([0]), np.array([[14.0, 23.0]]),
    ...                np.array([[20.0, 20.0]]), max_iter=30, eps=0.01)
    >>> np.round(r.centres, 1).tolist()
    [[20.0, 20.0]]
    """
    img, q, idx, y, hw = _checked_inputs(bin_img, models, model_index, centres, sizes,
                                         kernel=kernel, max_iter=max_iter, eps=eps,
                                         min_distance=min_distance, check_bins=check_bins)
    out, dist, iters = _mean_shift(img.astype(np.int32, copy=False), q, idx, y, hw,
                                   int(kernel), int(max_iter), float(eps),
                                   float(min_distance))
    return MeanShiftResult(out, dist, iters)


def _checked_inputs(bin_img, models, model_index, centres, sizes, *, kernel, max_iter, eps,
                    min_distance, check_bins):
    """``mean_shift``'s arguments validated and made contiguous (bin image, models,
    model index, centres, sizes), or ``ValueError`` naming the first bad one."""
    img = np.ascontiguousarray(bin_img)
    if img.ndim != 2 or not np.issubdtype(img.dtype, np.integer):
        raise ValueError(f"bin_img must be an integer array of shape (H, W), got {img.dtype}"
                         f" {img.shape}")
    q = np.ascontiguousarray(models, dtype=np.float64)
    if q.ndim != 2 or q.shape[0] < 1 or q.shape[1] < 1:
        raise ValueError(f"models must have shape (K, B), got {q.shape}")
    idx = np.ascontiguousarray(model_index, dtype=np.int64)
    y = np.ascontiguousarray(centres, dtype=np.float64)
    hw = np.ascontiguousarray(sizes, dtype=np.float64)
    if y.ndim != 2 or y.shape[1] != 2:
        raise ValueError(f"centres must have shape (P, 2), got {y.shape}")
    n_points = y.shape[0]
    if idx.shape != (n_points,):
        raise ValueError(f"model_index must have shape ({n_points},), got {idx.shape}")
    if hw.shape != (n_points, 2):
        raise ValueError(f"sizes must have shape ({n_points}, 2), got {hw.shape}")
    if n_points and (idx.min() < 0 or idx.max() >= q.shape[0]):
        raise ValueError(f"model_index must lie in [0, {q.shape[0]}), got "
                         f"[{idx.min()}, {idx.max()}]")
    if not np.all(np.isfinite(y)):
        raise ValueError("centres must be finite")
    if not np.all(np.isfinite(hw) & (hw > 0)):
        raise ValueError(f"sizes must be finite and positive, got min {hw.min()}")
    if check_bins and img.size and (img.min() < 0 or img.max() >= q.shape[1]):
        raise ValueError(f"bin_img values must lie in [0, {q.shape[1]}), got "
                         f"[{img.min()}, {img.max()}]")
    if not _is_kernel_code(kernel, MEAN_SHIFT_KERNELS.values()):
        raise ValueError(f"kernel must be KERNEL_EPANECHNIKOV ({KERNEL_EPANECHNIKOV}) or "
                         f"KERNEL_CONE ({KERNEL_CONE}), got {kernel!r}")
    if not _is_integer(max_iter) or max_iter < 0:
        raise ValueError(f"max_iter must be an integer >= 0, got {max_iter!r}")
    if not (_is_number(eps) and eps >= 0.0):
        raise ValueError(f"eps must be >= 0, got {eps!r}")
    if not (_is_number(min_distance) and min_distance >= 0.0):
        raise ValueError(f"min_distance must be >= 0, got {min_distance!r}")
    return img, q, idx, y, hw
