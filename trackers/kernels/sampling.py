"""Compiled helpers of the particle filters' bookkeeping (numba).

A DPS step resamples seven times and measures its particle set once; done with a dozen
small numpy calls each, that bookkeeping cost as much as the likelihoods. Here each is one
compiled call:

- ``inverse_cdf_groups``: ancestor indices of every group of a weighted set at once, from
  uniforms drawn by the caller (so randomness stays with the caller's Generator);
- ``count_distinct``: distinct sub-states per object of a particle set (a hash set per
  object, O(N)).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

__all__ = ["MULTINOMIAL", "STRATIFIED", "SYSTEMATIC", "count_distinct", "inverse_cdf_groups"]

#: How ``inverse_cdf_groups`` turns uniforms into positions in [0, 1) of a group's CDF.
MULTINOMIAL = 0  # one uniform per draw, used as is
STRATIFIED = 1  # one uniform per draw, in stratum i: (i + u_i) / n
SYSTEMATIC = 2  # one uniform per group, shared: (i + u) / n


@njit(cache=True)
def _inverse_cdf_groups(weights, sizes, counts, uniforms, mode):
    n_groups = sizes.shape[0]
    cdf = np.empty(weights.shape[0])
    out = np.empty(counts.sum(), dtype=np.int64)
    start = 0
    j = 0
    for g in range(n_groups):
        stop = start + sizes[g]
        total = 0.0
        for i in range(start, stop):
            total += weights[i]
        acc = 0.0
        for i in range(start, stop):
            acc += weights[i]
            cdf[i] = acc / total
        # The group's last cdf value is never read: both searches below return the last
        # index when no earlier value exceeds u (so rounding cannot leave u past the end).
        m = counts[g]
        last_u = np.inf
        lo = start
        for i in range(m):
            if mode == MULTINOMIAL:
                u = uniforms[j]
            elif mode == STRATIFIED:
                u = (i + uniforms[j]) / m
            else:
                u = (i + uniforms[g]) / m
            # The first index of the group whose cumulative weight exceeds u (the last
            # index if none does). The cdf does not decrease, so when u does not either
            # (the sorted positions of STRATIFIED and SYSTEMATIC) the answer is at or
            # after the previous one: scan on from it. Otherwise bisect the group.
            if not u >= last_u:
                lo = start
                hi = stop - 1
                while lo < hi:
                    mid = (lo + hi) // 2
                    if cdf[mid] > u:
                        hi = mid
                    else:
                        lo = mid + 1
            else:
                while lo < stop - 1 and not cdf[lo] > u:
                    lo += 1
            out[j] = lo
            if mode != MULTINOMIAL:
                last_u = u
            j += 1
        start = stop
    return out


def inverse_cdf_groups(
    weights: NDArray[np.floating],
    sizes: NDArray[np.integer],
    counts: NDArray[np.integer],
    uniforms: NDArray[np.floating],
    mode: int,
) -> NDArray[np.int64]:
    """Inverse-CDF draws inside contiguous groups of a weighted set.

    Parameters
    ----------
    weights : ndarray of shape (N,)
        Non-negative weights with a positive sum in every group (not checked here: the
        callers in ``trackers.filters.resampling`` validate).
    sizes : ndarray of shape (C,)
        Group lengths, summing to N.
    counts : ndarray of shape (C,)
        Draws per group.
    uniforms : ndarray
        Uniforms in [0, 1): one per draw (``MULTINOMIAL``, ``STRATIFIED``) or one per group
        (``SYSTEMATIC``).
    mode : int
        ``MULTINOMIAL``, ``STRATIFIED`` or ``SYSTEMATIC``.

    Returns
    -------
    ndarray of shape (counts.sum(),), int64
        Indices into ``weights``, group by group; draws of group c lie in group c.

    Examples
    --------
    >>> inverse_cdf_groups(np.array([1.0, 3.0, 1.0, 1.0]), np.array([2, 2]),
    ...                    np.array([2, 2]), np.array([0.5, 0.5]), SYSTEMATIC).tolist()
    [1, 1, 2, 3]
    """
    return _inverse_cdf_groups(np.ascontiguousarray(weights, dtype=np.float64),
                               np.ascontiguousarray(sizes, dtype=np.int64),
                               np.ascontiguousarray(counts, dtype=np.int64),
                               np.ascontiguousarray(uniforms, dtype=np.float64), int(mode))


@njit(cache=True)
def _count_distinct(particles):
    # Open-addressing hash set of the rows (u, v, a) of each object, on the bits of the
    # values with −0.0 taken as 0.0 (they compare equal). A row is new unless an earlier
    # row equals it in every component (==); a row with a NaN equals no row, so it is
    # always new and is not stored.
    n, k = particles.shape[0], particles.shape[1]
    values = particles + 0.0  # −0.0 + 0.0 is 0.0
    bits = values.view(np.int64)
    out = np.zeros(k, dtype=np.int64)
    size = 16
    while size < 2 * n:
        size *= 2
    mask = np.uint64(size - 1)
    table = np.empty(size, dtype=np.int64)
    for obj in range(k):
        table[:] = -1
        for i in range(n):
            u = values[i, obj, 0]
            v = values[i, obj, 1]
            a = values[i, obj, 2]
            if u != u or v != v or a != a:
                out[obj] += 1
                continue
            h = np.uint64(1469598103934665603)
            for c in range(3):
                h = (h ^ np.uint64(bits[i, obj, c])) * np.uint64(1099511628211)
                h ^= h >> np.uint64(29)
            slot = h & mask
            while True:
                j = table[slot]
                if j < 0:
                    table[slot] = i
                    out[obj] += 1
                    break
                if values[j, obj, 0] == u and values[j, obj, 1] == v and values[j, obj, 2] == a:
                    break
                slot = (slot + np.uint64(1)) & mask
    return out


def count_distinct(particles: NDArray[np.floating]) -> NDArray[np.int64]:
    """Number of distinct rows (u, v, a) per object of particles (N, K, 3), shape (K,).

    Rows are compared with ``==`` (so -0.0 equals 0.0); a row holding a NaN equals no
    row and counts as distinct.

    Parameters
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a); converted to float64. The shape is not checked here
        (``trackers.filters.diagnostics.uniqueness`` checks it).

    Returns
    -------
    ndarray of int64, shape (K,)
        Distinct rows of each object, in [1, N] for N >= 1.

    Examples
    --------
    >>> p = np.zeros((4, 2, 3)); p[:, 1, 0] = [0.0, 1.0, 1.0, np.nan]
    >>> count_distinct(p).tolist()
    [1, 3]
    """
    return _count_distinct(np.ascontiguousarray(particles, dtype=np.float64))
