"""Particle weights from log-weights: the one normaliser every tracker uses.

Likelihoods travel as natural logs (``trackers.models.observation``); a tracker turns
them into normalised linear weights here, subtracting the largest log-weight first so
that exp never overflows and the largest weight is exp(0) = 1 before normalising. The
same functions normalise the SHM trackers' ordering probabilities.

Examples
--------
>>> import numpy as np
>>> normalised_weights(np.array([0.0, np.log(3.0)])).tolist()
[0.25, 0.75]
>>> normalised_weights(np.array([[0.0, 0.0], [1000.0, 1000.0]]), axis=1).tolist()
[[0.5, 0.5], [0.5, 0.5]]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["log_sum_exp_groups", "normalised_weights"]


def normalised_weights(log_w: NDArray[np.float64], axis: int = -1) -> NDArray[np.float64]:
    """exp(log_w) / Σ exp(log_w) along ``axis``, computed without overflow.

    Parameters
    ----------
    log_w : ndarray of any shape
        Log-weights, finite (at least one finite value per normalised slice).
    axis : int, optional
        The axis that sums to 1 (the particle axis).

    Returns
    -------
    ndarray of the shape of ``log_w``
    """
    w = np.exp(log_w - np.max(log_w, axis=axis, keepdims=True))
    return w / np.sum(w, axis=axis, keepdims=True)


def log_sum_exp_groups(x: NDArray[np.float64], starts: NDArray[np.int64],
                       sizes: NDArray[np.int64]) -> NDArray[np.float64]:
    """log Σ exp(x) over each contiguous group of ``x`` (N,), shape (C,), without overflow.

    ``starts`` (C,) and ``sizes`` (C,) give each group's first index and length (the
    groups of ``trackers.filters.resampling``).

    Parameters
    ----------
    x : ndarray of float64, shape (N,)
        Values (log-weights), grouped in contiguous slices.
    starts : ndarray of int64, shape (C,)
        First index of each group, increasing (``group_starts(sizes)``).
    sizes : ndarray of int64, shape (C,)
        Length of each group, >= 1, summing to N. Not checked against ``starts``.

    Returns
    -------
    ndarray of float64, shape (C,)
        log Σ exp(x) of each group (the group's maximum subtracted first); NaN for a
        group that is all -inf.

    Examples
    --------
    >>> from trackers.filters.resampling import group_starts
    >>> sizes = np.array([2, 1])
    >>> x = np.log(np.array([1.0, 3.0, 5.0]))
    >>> np.exp(log_sum_exp_groups(x, group_starts(sizes), sizes)).round(12).tolist()
    [4.0, 5.0]
    """
    m = np.maximum.reduceat(x, starts)
    return m + np.log(np.add.reduceat(np.exp(x - np.repeat(m, sizes)), starts))
