"""Compiled stages of the particle filters' step: dynamics, weighted resampling, estimate.

A partitioned-sampling step (PS, DPS) runs one sampling stage per object; done with numpy,
each stage's gathers, AR2 propagation, box conversion and weighted resampling took about
twenty small array calls, as much time as the stage's histograms. Here each stage is a
few compiled calls over all particles at once (docs/algorithms.md, implementation notes):

- ``propagate_objects``: AR2 step of one object per particle (the stage's object of each
  particle's group), in place;
- ``state_boxes``: boxes of those states;
- ``stage_log_weights``: record a stage's log-likelihoods and return the shifted
  log-weights whose exponentials the weighted resampling needs;
- ``weighted_resample_gather``: weighted resampling of every group and the gather of the
  particle arrays by the drawn ancestors;
- ``normalise_groups``: weights normalised per group (the plain resamplers' first step);
- ``weighted_mean_states``: the weighted mean state per object, and the unweighted
  variance of the set (the diagnostics), for the estimate.

**Bit-identical to the numpy code they replace.** The results are the ones the numpy
expressions give, to the last bit, because every operation is the same IEEE operation in
the same order: elementwise arithmetic as written; sums in numpy's own order
(``_numpy_sum`` is numpy's pairwise summation, 8 accumulators in blocks of up to 128,
halving above; ``np.sum`` adds it to 0, ``np.add.reduceat`` adds it to the group's
first element); reductions over the particle axis of an (N, K, 3) array run row by row as
numpy's iterator does. Transcendental functions are *not* compiled: numpy's ``exp`` and
``log`` (SIMD on AVX-512 machines) and the C library's, which numba calls, differ in the
last bit for a few percent of arguments, so the callers take exp/log with numpy between
kernel calls. Randomness stays with the caller's Generator: the kernels take the
uniforms and normals the numpy code drew, in the same order.
tests/trackers/test_stage_kernels.py compares every kernel with its numpy expression
exactly, and the trackers' steps with a numpy reference step.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from trackers.kernels.sampling import _inverse_cdf_groups

__all__ = [
    "normalise_groups",
    "numpy_reduceat_sum",
    "numpy_sum",
    "propagate_objects",
    "stage_log_weights",
    "state_boxes",
    "weighted_mean_states",
    "weighted_resample_gather",
]

_BLOCK = 128  # numpy's PW_BLOCKSIZE


@njit(cache=True)
def _pairwise(a, lo, n):
    """numpy's pairwise summation of a[lo:lo + n] (``pairwise_sum`` in its add loop)."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    if n <= _BLOCK:
        r0 = a[lo]
        r1 = a[lo + 1]
        r2 = a[lo + 2]
        r3 = a[lo + 3]
        r4 = a[lo + 4]
        r5 = a[lo + 5]
        r6 = a[lo + 6]
        r7 = a[lo + 7]
        i = 8
        stop = n - n % 8
        while i < stop:
            r0 += a[lo + i]
            r1 += a[lo + i + 1]
            r2 += a[lo + i + 2]
            r3 += a[lo + i + 3]
            r4 += a[lo + i + 4]
            r5 += a[lo + i + 5]
            r6 += a[lo + i + 6]
            r7 += a[lo + i + 7]
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < n:
            res += a[lo + i]
            i += 1
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return _pairwise(a, lo, n2) + _pairwise(a, lo + n2, n - n2)


@njit(cache=True)
def _numpy_sum(a, lo, n):
    """``np.sum(a[lo:lo + n])`` of a contiguous float64 slice, to the bit."""
    return 0.0 + _pairwise(a, lo, n)


@njit(cache=True)
def _numpy_reduceat_sum(a, lo, n):
    """One group of ``np.add.reduceat``: the first element plus the rest's pairwise sum."""
    res = a[lo]
    if n > 1:
        res += _pairwise(a, lo + 1, n - 1)
    return res


def numpy_sum(a: NDArray[np.float64]) -> float:
    """``np.sum`` of a 1-D float64 array computed by the compiled replica (tests)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    return float(_numpy_sum(a, 0, a.shape[0]))


def numpy_reduceat_sum(a: NDArray[np.float64], sizes: NDArray[np.integer]
                       ) -> NDArray[np.float64]:
    """``np.add.reduceat(a, starts)`` of contiguous groups of lengths ``sizes`` (C,), shape
    (C,), computed by the compiled replica (tests)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    sizes = np.asarray(sizes, dtype=np.int64)
    out = np.empty(sizes.shape[0])
    start = 0
    for g, s in enumerate(sizes):
        out[g] = _numpy_reduceat_sum(a, start, int(s))
        start += int(s)
    return out


@njit(cache=True)
def _propagate_objects(x, prev, obj, noise, mean, sigma, a1, a2):
    n = x.shape[0]
    out = np.empty((n, 3))
    for r in range(n):
        o = obj[r]
        for c in range(3):
            cur = x[r, o, c]
            mu = mean[o, c]
            # numpy: mean + a1 (x − mean) + a2 (x_prev − mean) + noise σ, left to right.
            new = mu + a1 * (cur - mu) + a2 * (prev[r, o, c] - mu) + noise[r, c] * sigma[c]
            prev[r, o, c] = cur
            x[r, o, c] = new
            out[r, c] = new
    return out


def propagate_objects(
    x: NDArray[np.float64],
    prev: NDArray[np.float64],
    obj: NDArray[np.int64],
    noise: NDArray[np.float64],
    mean: NDArray[np.float64],
    sigma: NDArray[np.float64],
    a1: float,
    a2: float,
) -> NDArray[np.float64]:
    """AR2 step of object ``obj[r]`` of every particle r, in place (``AR2.propagate``).

    Parameters
    ----------
    x, prev : ndarray of shape (N, K, 3), C-contiguous float64
        X_{t−1} and X_{t−2} of every particle; on return x[r, obj[r]] holds the new state
        and prev[r, obj[r]] the old x[r, obj[r]].
    obj : ndarray of shape (N,), int64
        The object each particle moves.
    noise : ndarray of shape (N, 3)
        Standard normals, as ``AR2.propagate`` draws them for an (N, 3) state.
    mean : ndarray of shape (K, 3)
        X̄ per object.
    sigma : ndarray of shape (3,)
        σ of (u, v, a).
    a1, a2 : float
        AR2 coefficients.

    Returns
    -------
    ndarray of shape (N, 3)
        The new states x[r, obj[r]].
    """
    return _propagate_objects(x, prev, obj, noise, mean, sigma, float(a1), float(a2))


@njit(cache=True)
def _state_boxes(states, scale, sizes, obj):
    n = states.shape[0]
    out = np.empty((n, 4))
    for r in range(n):
        w = sizes[obj[r], 0] * scale[r]
        h = sizes[obj[r], 1] * scale[r]
        out[r, 0] = states[r, 0] - w / 2
        out[r, 1] = states[r, 1] - h / 2
        out[r, 2] = w
        out[r, 3] = h
    return out


def state_boxes(states: NDArray[np.float64], scale: NDArray[np.float64],
                sizes: NDArray[np.float64], obj: NDArray[np.int64]) -> NDArray[np.float64]:
    """Boxes (N, 4) of states (N, 3) of objects ``obj`` (N,) (``boxes_from_states``).

    ``scale`` (N,) is exp(a) of each state, taken by the caller with numpy's exp;
    ``sizes`` (K, 2) the objects' base (w0, h0).
    """
    return _state_boxes(states, scale, sizes, obj)


@njit(cache=True)
def _stage_log_weights(stage, ll, log_g, logpi, obj):
    n = stage.shape[0]
    out = np.empty((2, n))
    top_pi = -np.inf
    top_g = -np.inf
    ok = True
    for r in range(n):
        ll[r, obj[r]] = stage[r]
        log_g[r] += stage[r]
        if logpi[r] != logpi[r] or log_g[r] != log_g[r]:
            ok = False
        top_pi = max(top_pi, logpi[r])
        top_g = max(top_g, log_g[r])
    for r in range(n):
        out[0, r] = logpi[r] - top_pi
        out[1, r] = log_g[r] - top_g
    return out, ok


def stage_log_weights(stage: NDArray[np.float64], ll: NDArray[np.float64],
                      log_g: NDArray[np.float64], logpi: NDArray[np.float64],
                      obj: NDArray[np.int64]) -> tuple[NDArray[np.float64], bool]:
    """Record a stage's log-likelihoods and shift the log-weights for exponentiation.

    Sets ll[r, obj[r]] = stage[r] and log_g += stage in place, and returns the (2, N)
    array [logpi − max logpi, log_g − max log_g] (the exponents of the weighted
    resampling, DPS §3), and False if a log-weight is NaN (the caller then takes the
    checked numpy path, which raises). Shapes: stage, log_g, logpi (N,), ll (N, K).
    """
    return _stage_log_weights(stage, ll, log_g, logpi, obj)


@njit(cache=True)
def _normalise_groups(w, sizes):
    n = w.shape[0]
    out = np.empty(n)
    start = 0
    for g in range(sizes.shape[0]):
        s = sizes[g]
        total = _numpy_reduceat_sum(w, start, s)
        if not total > 0.0:
            return out, False
        for i in range(start, start + s):
            out[i] = w[i] / total
        start += s
    return out, True


def normalise_groups(w: NDArray[np.float64], sizes: NDArray[np.int64]
                     ) -> tuple[NDArray[np.float64], bool]:
    """Weights (N,) divided by their group's sum (``np.add.reduceat``), and whether every
    group's sum was positive. ``sizes`` (C,) are the contiguous groups' lengths."""
    return _normalise_groups(w, sizes)


@njit(cache=True)
def _valid(a):
    for i in range(a.shape[0]):
        if not (a[i] >= 0.0 and a[i] < np.inf):
            return False
    return True


@njit(cache=True)
def _weighted_resample_gather(a, b, sizes, uniforms, mode, x, prev, ll, log_g):
    n = a.shape[0]
    if not (_valid(a) and _valid(b)):
        return np.empty(0), np.empty(0, dtype=np.int64), x, prev, ll, log_g
    rho = a * b
    rho_n, ok = _normalise_groups(rho, sizes)
    if not ok:
        return np.empty(0), np.empty(0, dtype=np.int64), x, prev, ll, log_g
    idx = _inverse_cdf_groups(rho_n, sizes, sizes, uniforms, mode)
    new = np.empty(n)
    for i in range(n):
        new[i] = 1.0 / b[idx[i]]
    w, _ = _normalise_groups(new, sizes)
    x2 = np.empty_like(x)
    prev2 = np.empty_like(prev)
    ll2 = np.empty_like(ll)
    g2 = np.empty_like(log_g)
    for i in range(n):
        k = idx[i]
        x2[i] = x[k]
        prev2[i] = prev[k]
        ll2[i] = ll[k]
        g2[i] = log_g[k]
    return w, idx, x2, prev2, ll2, g2


def weighted_resample_gather(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    sizes: NDArray[np.int64],
    uniforms: NDArray[np.float64],
    mode: int,
    x: NDArray[np.float64],
    prev: NDArray[np.float64],
    ll: NDArray[np.float64],
    log_g: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64],
           NDArray[np.float64], NDArray[np.float64]] | None:
    """Weighted resampling of every group (``weighted_resample_groups``) and the gather.

    Parameters
    ----------
    a : ndarray of shape (N,)
        Current weights π (any positive scale per group).
    b : ndarray of shape (N,)
        The weighting function g at each particle.
    sizes : ndarray of shape (C,), int64
        Lengths of the contiguous groups.
    uniforms : ndarray
        The uniforms ``trackers.filters.resampling`` draws for ``mode``: one per group
        (systematic) or one per particle (multinomial, stratified).
    mode : int
        ``trackers.kernels.sampling`` MULTINOMIAL, STRATIFIED or SYSTEMATIC.
    x, prev : ndarray of shape (N, K, 3)
    ll : ndarray of shape (N, K)
    log_g : ndarray of shape (N,)
        Per-particle arrays to gather by the drawn ancestors.

    Returns
    -------
    tuple or None
        (new weights (N,) normalised per group, ancestors (N,), x, prev, ll, log_g
        gathered); None if ``a`` or ``b`` is negative or not finite or a group's π g sums
        to zero (the caller then takes the checked numpy path, which raises).
    """
    out = _weighted_resample_gather(a, b, sizes, uniforms, int(mode), x, prev, ll, log_g)
    return None if out[0].shape[0] == 0 else out


@njit(cache=True)
def _weighted_mean_states(weights, particles):
    n, k = particles.shape[0], particles.shape[1]
    mean = np.zeros((k, 3))
    total = np.zeros((k, 3))
    for r in range(n):
        for o in range(k):
            for c in range(3):
                mean[o, c] += weights[r] * particles[r, o, c]
                total[o, c] += particles[r, o, c]
    # numpy's var: the mean Σx / N, then Σ (x − mean)² / N, sums row by row.
    avg = total / n
    var = np.zeros((k, 3))
    for r in range(n):
        for o in range(k):
            for c in range(3):
                d = particles[r, o, c] - avg[o, c]
                var[o, c] += d * d
    return mean, var / n


def weighted_mean_states(weights: NDArray[np.float64], particles: NDArray[np.float64]
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Weighted mean (K, 3) of particles (N, K, 3) under weights (N,), shared by all
    objects, and the unweighted variance (K, 3) over the set (``particles.var(axis=0)``)."""
    return _weighted_mean_states(weights, particles)
