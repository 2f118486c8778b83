"""Colour quantisation of a frame into a bin-index image (numba).

A tracker quantises each frame once; the region kernels (``trackers.kernels.histogram``)
then read the bin of every pixel. ``quantize_rgb`` gives a ``bins``³ RGB histogram's bin,
``quantize_hsv`` the hue–saturation/value bin of Pérez et al. 2002 (``hsv_n_bins`` bins).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from trackers.numbers import is_integral, is_number

__all__ = ["hsv_n_bins", "quantize_hsv", "quantize_rgb"]


def _check_frame(frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
    arr = np.asarray(frame)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.dtype != np.uint8:
        raise ValueError(f"frame must be uint8 of shape (H, W, 3), got {arr.dtype} {arr.shape}")
    return np.ascontiguousarray(arr)


_is_number = is_number  # trackers.numbers: the one definition
_is_integer = is_integral


def _check_bin_count(name: str, value: int) -> int:
    if not _is_integer(value) or not 1 <= value <= 256:
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

    Examples
    --------
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
            # No clamp: h6 <= 6 d - 1 (where r is the largest and g < b, h6 = 6 d - (b - g);
            # otherwise h6 <= 5 d), so h6 h_bins / (6 d) lies at least 1 / 1530 below
            # h_bins, far more than float32's rounding: the floor is below h_bins.
            hb = np.int32(np.float32(h6) * hbf / np.float32(6 * max(d, one)))
            sb = min(np.int32(np.float32(d) * sbf / np.float32(max(mx, one))), s_top)
            vb = min(np.int32(np.float32(mx) * vbf / np.float32(255)), v_top)
            # S >= s_min and V >= v_min, i.e. d / mx >= s_min and mx / 255 >= v_min, with
            # the thresholds pre-scaled to integers (d * 2**20 >= s_thr * mx).
            coloured = (d > 0) & (mx >= v_thr) & ((d << 20) >= s_thr * mx)
            dst[j] = hb * s_n + sb if coloured else v_offset + vb
    return out


def hsv_n_bins(h_bins: int = 10, s_bins: int = 10, v_bins: int = 10) -> int:
    """Number of bins of the HSV quantisation: ``h_bins * s_bins + v_bins``.

    Parameters
    ----------
    h_bins, s_bins, v_bins : int, optional
        Hue, saturation and value bins, as in ``quantize_hsv``.

    Returns
    -------
    int
        The hue-saturation bins of coloured pixels followed by the value bins of the
        greyish or dark ones.

    Examples
    --------
    >>> hsv_n_bins()
    110
    """
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
    unreliable) fall in a value-only histogram of ``v_bins`` bins placed after it. A grey
    pixel (S = 0, no hue) is never coloured, even with ``s_min`` = 0.

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

    Examples
    --------
    >>> quantize_hsv(np.array([[[255, 0, 0], [128, 128, 128]]], dtype=np.uint8)).tolist()
    [[9, 105]]
    """
    h_bins = _check_bin_count("h_bins", h_bins)
    s_bins = _check_bin_count("s_bins", s_bins)
    v_bins = _check_bin_count("v_bins", v_bins)
    for name, val in (("s_min", s_min), ("v_min", v_min)):
        if not (_is_number(val) and 0.0 <= val <= 1.0):
            raise ValueError(f"{name} must lie in [0, 1], got {val!r}")
    s_thr = int(np.floor(s_min * 2**20))
    v_thr = int(np.ceil(v_min * 255 - 1e-9))
    return _quantize_hsv(_check_frame(frame), np.int32(h_bins), np.int32(s_bins),
                         np.int32(v_bins), np.int32(s_thr), np.int32(v_thr))
