"""Kernel profiles: which pixels a box holds and the fixed-point weight of each (numba).

The conventions (the pixel rule of a box, the uniform, Epanechnikov, cone and
nested-rectangle "box" profiles, the 32.32 fixed point) are those of
``trackers.kernels.histogram``'s module docstring. Here: the kernel codes, the box
kernel's levels and their fixed-point weights, the pixel ranges of a box and of the box
kernel's rectangles (used by both the direct and the integral path), and the compiled
helpers that write one row's weights (``trackers.kernels.direct``).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numba import njit
from numpy.typing import NDArray

from trackers.kernels.quantize import _is_integer

__all__ = [
    "DEFAULT_BOX_LEVELS",
    "KERNEL_BOX",
    "KERNEL_CONE",
    "KERNEL_EPANECHNIKOV",
    "KERNEL_UNIFORM",
    "KERNELS",
    "box_kernel_levels",
]

KERNEL_UNIFORM = 0
KERNEL_EPANECHNIKOV = 1
KERNEL_CONE = 2
KERNEL_BOX = 3
#: Levels of the nested-rectangle kernel when none is given (``trackers.kernels.histogram``).
DEFAULT_BOX_LEVELS = 3
_MAX_BOX_LEVELS = 16

#: Kernel profile names, as accepted by the observation models, mapped to their codes.
KERNELS: dict[str, int] = {
    "uniform": KERNEL_UNIFORM,
    "epanechnikov": KERNEL_EPANECHNIKOV,
    "cone": KERNEL_CONE,
    "box": KERNEL_BOX,
}


def _is_kernel_code(value: object, codes: Iterable[int]) -> bool:
    """Whether ``value`` is one of the kernel ``codes``: an integer (an integral float
    too, like every integer argument of the kernels), not a bool (True was
    ``KERNEL_EPANECHNIKOV``)."""
    return _is_integer(value) and int(value) in codes


# Weights are accumulated in 32.32 fixed point (int64): integer adds do not stall on
# store-to-load forwarding when neighbouring pixels share a bin (flat regions), which made
# float accumulation twice as slow there. Resolution 2**-32, far below any use here.
_ONE = 4294967296.0

_NO_LEVELS = np.zeros(0, dtype=np.int64)
_NO_FRACTIONS = np.zeros(0, dtype=np.float64)


def box_kernel_levels(levels: int = DEFAULT_BOX_LEVELS) -> tuple[NDArray[np.float64],
                                                                 NDArray[np.float64]]:
    """Scales and weights of the nested-rectangle kernel with ``levels`` levels.

    Parameters
    ----------
    levels : int, optional
        Levels L, in [1, 16].

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
    if not _is_integer(levels) or not 1 <= levels <= _MAX_BOX_LEVELS:
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
