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
  particle arrays by the drawn ancestors (every object's sub-state, or only the placed
  objects', ``resample_scope``);
- ``normalise_groups``: weights normalised per group (the plain resamplers' first step);
- ``weighted_mean_states``: the weighted mean state per object, and the unweighted
  variance of the set (the diagnostics), for the estimate;
- ``add_row_sums``: the posterior log-weights, log π' plus each particle's summed
  log-likelihoods;
- ``clip_centres``: every returned box moved so that its centre lies in the frame.

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
    "add_row_sums",
    "clip_centres",
    "effective_uv",
    "gather_pair",
    "group_weights",
    "normalise_groups",
    "normalise_groups_checked",
    "normalise_rows",
    "numpy_reduceat_sum",
    "numpy_sum",
    "propagate_objects",
    "reassemble",
    "resample_propagate",
    "row_max_shift",
    "stage_log_weights",
    "state_boxes",
    "weighted_mean_states",
    "weighted_resample_gather",
]

_BLOCK = 128  # numpy's PW_BLOCKSIZE


@njit(cache=True)
def _pairwise_block(a, lo, n):
    """numpy's pairwise sum of a[lo:lo + n] for n <= 128: sequential below 8, else eight
    interleaved accumulators combined as a tree, then the remainder."""
    if n < 8:
        # numpy starts this loop at -0.0, so that terms that are all -0.0 sum to -0.0:
        # np.add.reduceat's group (first + the rest's pairwise sum) keeps that sign.
        res = -0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
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


@njit(cache=True)
def _pairwise(a, lo, n):
    """numpy's pairwise summation of a[lo:lo + n] (``pairwise_sum`` of its add loop):
    blocks of at most 128, above that the sum of the halves split at a multiple of 8.
    The recursion runs on an explicit stack (numba's cache and recursion do not mix)."""
    if n <= _BLOCK:
        return _pairwise_block(a, lo, n)
    f_lo = np.empty(64, dtype=np.int64)
    f_n = np.empty(64, dtype=np.int64)
    f_state = np.empty(64, dtype=np.int64)
    vals = np.empty(64)
    top = 0
    vtop = 0
    f_lo[0] = lo
    f_n[0] = n
    f_state[0] = 0
    while top >= 0:
        m = f_n[top]
        if m <= _BLOCK:
            vals[vtop] = _pairwise_block(a, f_lo[top], m)
            vtop += 1
            top -= 1
            continue
        n2 = m // 2
        n2 -= n2 % 8
        if f_state[top] == 0:  # first the left half
            f_state[top] = 1
            f_lo[top + 1] = f_lo[top]
            f_n[top + 1] = n2
            f_state[top + 1] = 0
            top += 1
        elif f_state[top] == 1:  # then the right half
            f_state[top] = 2
            f_lo[top + 1] = f_lo[top] + n2
            f_n[top + 1] = m - n2
            f_state[top + 1] = 0
            top += 1
        else:  # left + right
            vals[vtop - 2] = vals[vtop - 2] + vals[vtop - 1]
            vtop -= 1
            top -= 1
    return vals[0]


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
    """``np.sum`` of a 1-D float64 array computed by the compiled replica (tests).

    Parameters
    ----------
    a : array_like of float, shape (N,)
        The values (converted to C-contiguous float64).

    Returns
    -------
    float
        ``np.sum(a)``, to the bit (0.0 for N = 0).
    """
    a = np.ascontiguousarray(a, dtype=np.float64)
    return float(_numpy_sum(a, 0, a.shape[0]))


def numpy_reduceat_sum(a: NDArray[np.float64], sizes: NDArray[np.integer]
                       ) -> NDArray[np.float64]:
    """``np.add.reduceat(a, starts)`` of contiguous groups of lengths ``sizes`` (C,), shape
    (C,), computed by the compiled replica (tests).

    Parameters
    ----------
    a : array_like of float, shape (N,)
        The values (converted to C-contiguous float64).
    sizes : array_like of int, shape (C,)
        Lengths of the contiguous groups, each >= 1, summing to at most N (not checked).

    Returns
    -------
    ndarray of float64, shape (C,)
        The sum of each group: its first element plus the pairwise sum of the rest.
    """
    a = np.ascontiguousarray(a, dtype=np.float64)
    sizes = np.asarray(sizes, dtype=np.int64)
    out = np.empty(sizes.shape[0])
    start = 0
    for g, s in enumerate(sizes):
        out[g] = _numpy_reduceat_sum(a, start, int(s))
        start += int(s)
    return out


@njit(cache=True)
def _add_row_sums(a, m):
    k = m.shape[1]
    flat = m.reshape(m.shape[0] * k)
    out = np.empty(a.shape[0])
    for r in range(a.shape[0]):
        # _numpy_sum of the row; a block-sized row straight to its block sum (a call of
        # _pairwise per row costs more than the sum).
        row = _pairwise_block(flat, r * k, k) if k <= _BLOCK else _pairwise(flat, r * k, k)
        out[r] = a[r] + (0.0 + row)
    return out


def add_row_sums(a: NDArray[np.float64], m: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a + m.sum(axis=1)``, to the bit, in one call.

    numpy sums each row of a C-contiguous (N, K) array as ``np.sum`` sums a vector
    (``_numpy_sum``: sequential below 8 terms, pairwise above).

    Parameters
    ----------
    a : ndarray of float64, shape (N,)
        The terms added to the row sums (log π').
    m : ndarray of float64, shape (N, K)
        The rows to sum (per-object log-likelihoods); made C-contiguous.

    Returns
    -------
    ndarray of float64, shape (N,)
        a[r] + Σ_k m[r, k].
    """
    return _add_row_sums(np.ascontiguousarray(a, dtype=np.float64),
                         np.ascontiguousarray(m, dtype=np.float64))


@njit(cache=True)
def _clip_corner(corner, size, top):
    """clip(corner + size / 2, 0, top) − size / 2, as numpy's clip (NaN stays NaN)."""
    half = size / 2
    centre = corner + half
    if centre < 0.0:
        centre = 0.0
    elif centre > top:
        centre = top
    return centre - half


@njit(cache=True)
def _clip_centres(b, w, h):
    for r in range(b.shape[0]):
        b[r, 0] = _clip_corner(b[r, 0], b[r, 2], w)
        b[r, 1] = _clip_corner(b[r, 1], b[r, 3], h)


def clip_centres(boxes: NDArray[np.floating], width: float, height: float
                 ) -> NDArray[np.float64]:
    """A copy of ``boxes`` with each centre moved into [0, width] x [0, height].

    The sizes are unchanged; x becomes clip(x + w / 2, 0, width) − w / 2 and y the same
    with h and ``height``, the numpy expression's operations in its order.

    Parameters
    ----------
    boxes : array_like of float, shape (K, 4)
        Boxes [x, y, w, h], px.
    width, height : float
        The frame's size, px.

    Returns
    -------
    ndarray of float64, shape (K, 4)
        A new C-contiguous array.
    """
    b = np.array(boxes, dtype=np.float64, order="C", copy=True)
    _clip_centres(b, float(width), float(height))
    return b


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

    Parameters
    ----------
    states : ndarray of float64, shape (N, 3)
        States (u, v, a): centre in px and log scale (only u and v are read).
    scale : ndarray of float64, shape (N,)
        exp(a) of each state.
    sizes : ndarray of float64, shape (K, 2)
        Base size (w0, h0) of each object, in px.
    obj : ndarray of int64, shape (N,)
        The object of each state, in [0, K) (not checked).

    Returns
    -------
    ndarray of float64, shape (N, 4)
        Boxes [u - w/2, v - h/2, w, h] with (w, h) = scale * sizes[obj], in px.
    """
    return _state_boxes(states, scale, sizes, obj)


@njit(cache=True)
def _stage_log_weights(stage, ll, log_g, logpi, obj, sizes):
    n = stage.shape[0]
    out = np.empty((2, n))
    ok = True
    for r in range(n):
        ll[r, obj[r]] = stage[r]
        log_g[r] += stage[r]
        if logpi[r] != logpi[r] or log_g[r] != log_g[r]:
            ok = False
    start = 0
    for c in range(sizes.shape[0]):
        top_pi = -np.inf
        top_g = -np.inf
        for r in range(start, start + sizes[c]):
            top_pi = max(top_pi, logpi[r])
            top_g = max(top_g, log_g[r])
        for r in range(start, start + sizes[c]):
            out[0, r] = logpi[r] - top_pi
            out[1, r] = log_g[r] - top_g
        start += sizes[c]
    return out, ok


def stage_log_weights(stage: NDArray[np.float64], ll: NDArray[np.float64],
                      log_g: NDArray[np.float64], logpi: NDArray[np.float64],
                      obj: NDArray[np.int64], sizes: NDArray[np.int64]
                      ) -> tuple[NDArray[np.float64], bool]:
    """Record a stage's log-likelihoods and shift the log-weights for exponentiation.

    Sets ll[r, obj[r]] = stage[r] and log_g += stage in place, and returns the (2, N)
    array [logpi − its group's max, log_g − its group's max] (the exponents of the
    weighted resampling, DPS §3, which resamples inside each group: a group whose
    weights are all far below another group's still has a largest weight of 1), and
    False if a log-weight is NaN (the caller then takes the checked numpy path, which
    raises). Shapes: stage, log_g, logpi (N,), ll (N, K); ``sizes`` (C,) the contiguous
    groups' lengths.

    Parameters
    ----------
    stage : ndarray of float64, shape (N,)
        The stage's log-likelihood of each particle's stage object.
    ll : ndarray of float64, shape (N, K)
        Per-object log-likelihoods of every particle, updated in place.
    log_g : ndarray of float64, shape (N,)
        Accumulated log weighting function of every particle, updated in place.
    logpi : ndarray of float64, shape (N,)
        Log-weights log π of every particle.
    obj : ndarray of int64, shape (N,)
        The stage's object of each particle, in [0, K).
    sizes : array_like of int, shape (C,)
        Lengths of the contiguous groups, summing to N.

    Returns
    -------
    shifted : ndarray of float64, shape (2, N)
        Row 0: logpi minus its group's maximum; row 1: the updated log_g minus its
        group's maximum.
    ok : bool
        False if an entry of ``logpi`` or of the updated ``log_g`` is NaN.
    """
    return _stage_log_weights(stage, ll, log_g, logpi, obj,
                              np.ascontiguousarray(sizes, dtype=np.int64))


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
    group's sum was positive. ``sizes`` (C,) are the contiguous groups' lengths.

    Parameters
    ----------
    w : ndarray of float64, shape (N,)
        Weights (not checked).
    sizes : ndarray of int64, shape (C,)
        Lengths of the contiguous groups, each >= 1, summing to N.

    Returns
    -------
    weights : ndarray of float64, shape (N,)
        ``w`` normalised to sum 1 in each group; when ``ok`` is False, only the groups
        before the first failing one are filled (the rest is uninitialised).
    ok : bool
        False at the first group whose sum is not > 0 (zero, negative or NaN).
    """
    return _normalise_groups(w, sizes)


@njit(cache=True)
def _normalise_groups_checked(w, sizes):
    # The checks of ``trackers.filters.resampling``: finite, non-negative, a finite total
    # (numpy's sum) and a positive sum per group; False sends the caller to the checked
    # numpy path, which raises.
    if not (_valid(w) and np.isfinite(_numpy_sum(w, 0, w.shape[0]))):
        return np.empty(0), False
    return _normalise_groups(w, sizes)


def normalise_groups_checked(w: NDArray[np.float64], sizes: NDArray[np.int64]
                             ) -> tuple[NDArray[np.float64], bool]:
    """``normalise_groups`` for C-contiguous float64 weights (N,), also False unless every
    weight is finite and >= 0 and their sum finite.

    Parameters
    ----------
    w : ndarray of float64, shape (N,)
        Weights, C-contiguous.
    sizes : ndarray of int64, shape (C,)
        Lengths of the contiguous groups, each >= 1, summing to N.

    Returns
    -------
    weights : ndarray of float64, shape (N,) or (0,)
        As ``normalise_groups``; empty when a weight or the total failed the checks.
    ok : bool
        True when every check passed and every group's sum was positive.
    """
    return _normalise_groups_checked(w, sizes)


@njit(cache=True)
def _valid(a):
    for i in range(a.shape[0]):
        if not (a[i] >= 0.0 and a[i] < np.inf):
            return False
    return True


@njit(cache=True)
def _gather_pair(x, prev, idx):
    n = idx.shape[0]
    m = x.shape[1] * x.shape[2]
    xf = x.reshape(x.shape[0], m)
    pf = prev.reshape(prev.shape[0], m)
    x2 = np.empty((n, m))
    p2 = np.empty((n, m))
    for i in range(n):
        k = idx[i]
        for c in range(m):
            x2[i, c] = xf[k, c]
        for c in range(m):
            p2[i, c] = pf[k, c]
    return x2.reshape((n, x.shape[1], x.shape[2])), p2.reshape((n, x.shape[1], x.shape[2]))


def gather_pair(x: NDArray[np.float64], prev: NDArray[np.float64], idx: NDArray[np.int64]
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``x[idx]``, ``prev[idx]`` of two (N, K, D) arrays by ancestors ``idx`` (P,), as new
    C-contiguous float64 arrays (P, K, D).

    Parameters
    ----------
    x, prev : array_like of float, shape (N, K, D)
        The two particle arrays (X_{t−1} and X_{t−2}).
    idx : array_like of int, shape (P,)
        Ancestor indices, in [0, N) (not checked).

    Returns
    -------
    x_new, prev_new : ndarray of float64, shape (P, K, D)
        ``x[idx]`` and ``prev[idx]``.
    """
    return _gather_pair(np.ascontiguousarray(x, dtype=np.float64),
                        np.ascontiguousarray(prev, dtype=np.float64),
                        np.ascontiguousarray(idx, dtype=np.int64))


@njit(cache=True)
def _gather_placed(x, prev, ll, idx, placed):
    """x, prev, ll of every row with the placed objects' columns from the row's ancestor
    and the others from the row itself (``resample_scope="placed"``)."""
    n, m, d = x.shape
    x2 = np.empty((n, m, d))
    p2 = np.empty((n, m, d))
    ll2 = np.empty((n, m))
    for i in range(n):
        for o in range(m):
            src = idx[i] if placed[i, o] else i
            for c in range(d):
                x2[i, o, c] = x[src, o, c]
                p2[i, o, c] = prev[src, o, c]
            ll2[i, o] = ll[src, o]
    return x2, p2, ll2


@njit(cache=True)
def _weighted_resample_gather(a, b, sizes, uniforms, mode, x, prev, ll, log_g, scoped,
                              placed):
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
    g2 = np.empty_like(log_g)
    for i in range(n):
        g2[i] = log_g[idx[i]]
    if scoped:
        x2, prev2, ll2 = _gather_placed(x, prev, ll, idx, placed)
        return w, idx, x2, prev2, ll2, g2
    x2, prev2 = _gather_pair(x, prev, idx)
    m = ll.shape[1]
    ll2 = np.empty_like(ll)
    for i in range(n):
        k = idx[i]
        for o in range(m):
            ll2[i, o] = ll[k, o]
    return w, idx, x2, prev2, ll2, g2


_JOINT = np.empty((0, 0), dtype=np.bool_)


def _scope(placed: NDArray[np.bool_] | None) -> tuple[bool, NDArray[np.bool_]]:
    if placed is None:
        return False, _JOINT
    return True, np.ascontiguousarray(placed, dtype=np.bool_)


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
    placed: NDArray[np.bool_] | None = None,
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
    placed : ndarray of shape (N, K), bool, optional
        None (``resample_scope="joint"``): every object of a row comes from its ancestor.
        Otherwise only the objects marked True (those placed so far in the row's
        ordering) do, and the others keep the row's own x, prev and ll
        (``resample_scope="placed"``); ``log_g`` always comes from the ancestor.

    Returns
    -------
    tuple or None
        (new weights (N,) normalised per group, ancestors (N,), x, prev, ll, log_g
        gathered); None if ``a`` or ``b`` is negative or not finite or a group's π g sums
        to zero (the caller then takes the checked numpy path, which raises).
    """
    out = _weighted_resample_gather(a, b, sizes, uniforms, int(mode), x, prev, ll, log_g,
                                    *_scope(placed))
    return None if out[0].shape[0] == 0 else out


@njit(cache=True)
def _resample_propagate(a, b, sizes, uniforms, mode, x, prev, ll, log_g, obj, noise, mean,
                        sigma, a1, a2, scoped, placed):
    w, idx, x2, prev2, ll2, g2 = _weighted_resample_gather(a, b, sizes, uniforms, mode, x,
                                                           prev, ll, log_g, scoped, placed)
    if w.shape[0] == 0:
        return w, x2, prev2, ll2, g2, np.empty((0, 3))
    new = _propagate_objects(x2, prev2, obj, noise, mean, sigma, a1, a2)
    return w, x2, prev2, ll2, g2, new


def resample_propagate(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    sizes: NDArray[np.int64],
    uniforms: NDArray[np.float64],
    mode: int,
    x: NDArray[np.float64],
    prev: NDArray[np.float64],
    ll: NDArray[np.float64],
    log_g: NDArray[np.float64],
    obj: NDArray[np.int64],
    noise: NDArray[np.float64],
    mean: NDArray[np.float64],
    sigma: NDArray[np.float64],
    a1: float,
    a2: float,
    placed: NDArray[np.bool_] | None = None,
) -> tuple[NDArray[np.float64], ...] | None:
    """``weighted_resample_gather`` then ``propagate_objects`` of the next stage, one call.

    The arguments are those of the two functions (``noise`` (N, 3) the next stage's
    normals, drawn after ``uniforms``; ``obj`` (N,) its objects; ``placed`` (N, K) or
    None, the scope of the gather). Returns (new weights
    (N,), x, prev, ll, log_g gathered, with x and prev propagated, and the new states
    (N, 3) of the stage's objects), or None where ``weighted_resample_gather`` is None.

    Parameters
    ----------
    a : ndarray of float64, shape (N,)
        Current weights π (any positive scale per group).
    b : ndarray of float64, shape (N,)
        The weighting function g at each particle.
    sizes : ndarray of int64, shape (C,)
        Lengths of the contiguous groups.
    uniforms : ndarray of float64, shape (C,) or (N,)
        One uniform per group (systematic) or per particle (multinomial, stratified).
    mode : int
        ``trackers.kernels.sampling`` MULTINOMIAL, STRATIFIED or SYSTEMATIC.
    x, prev : ndarray of float64, shape (N, K, 3)
        X_{t−1} and X_{t−2} of every particle (not modified: the gathered copies are
        propagated).
    ll : ndarray of float64, shape (N, K)
        Per-object log-likelihoods, gathered.
    log_g : ndarray of float64, shape (N,)
        Accumulated log weighting function, gathered.
    obj : ndarray of int64, shape (N,)
        The next stage's object of each particle.
    noise : ndarray of float64, shape (N, 3)
        The next stage's standard normals.
    mean : ndarray of float64, shape (K, 3)
        X̄ per object (the AR2 mean).
    sigma : ndarray of float64, shape (3,)
        σ of (u, v, a).
    a1, a2 : float
        AR2 coefficients.
    placed : ndarray of bool, shape (N, K), optional
        The scope of the gather, as in ``weighted_resample_gather``; None: joint.

    Returns
    -------
    tuple of ndarray or None
        (weights (N,), x (N, K, 3), prev (N, K, 3), ll (N, K), log_g (N,), new states
        (N, 3)); None when ``a`` or ``b`` is negative or not finite or a group's π g
        sums to zero.
    """
    out = _resample_propagate(a, b, sizes, uniforms, int(mode), x, prev, ll, log_g, obj,
                              noise, mean, sigma, float(a1), float(a2), *_scope(placed))
    return None if out[0].shape[0] == 0 else out


@njit(cache=True)
def _group_max_shift(x, sizes):
    """x minus its group's maximum (``x − np.repeat(np.maximum.reduceat(x), sizes)``) and
    the maxima (C,)."""
    out = np.empty(x.shape[0])
    top = np.empty(sizes.shape[0])
    start = 0
    for g in range(sizes.shape[0]):
        m = x[start]
        for i in range(start + 1, start + sizes[g]):
            m = max(m, x[i])
        top[g] = m
        for i in range(start, start + sizes[g]):
            out[i] = x[i] - m
        start += sizes[g]
    return out, top


def group_weights(logw: NDArray[np.float64], sizes: NDArray[np.int64]) -> NDArray[np.float64]:
    """exp(log w − its group's maximum) (N,): weights that never sum to 0 in a group.

    ``logw`` (N,) holds contiguous groups of lengths ``sizes`` (C,); the largest weight
    of every group is 1, so a group far below the others (log π_c → −∞) can still be
    resampled within itself.

    Parameters
    ----------
    logw : array_like of float, shape (N,)
        Log-weights.
    sizes : array_like of int, shape (C,)
        Lengths of the contiguous groups, each >= 1, summing to N (not checked).

    Returns
    -------
    ndarray of float64, shape (N,)
        The shifted weights, in [0, 1], not normalised.
    """
    shifted, _ = _group_max_shift(np.ascontiguousarray(logw, dtype=np.float64),
                                  np.ascontiguousarray(sizes, dtype=np.int64))
    return np.exp(shifted)


@njit(cache=True)
def _reassemble_shift(logw, logpi, sizes):
    n = logw.shape[0]
    shifted = np.empty((2, n))
    sw, top_w = _group_max_shift(logw, sizes)
    sp, top_p = _group_max_shift(logpi, sizes)
    shifted[0] = sw
    shifted[1] = sp
    return shifted, top_w, top_p


@njit(cache=True)
def _reassemble_sums(e, sizes):
    c = sizes.shape[0]
    sums = np.empty((2, c))
    start = 0
    for g in range(c):
        sums[0, g] = _numpy_reduceat_sum(e[0], start, sizes[g])
        sums[1, g] = _numpy_reduceat_sum(e[1], start, sizes[g])
        start += sizes[g]
    return sums


@njit(cache=True)
def _max_shift(x):
    m = x[0]
    for i in range(1, x.shape[0]):
        m = max(m, x[i])
    out = np.empty(x.shape[0])
    for i in range(x.shape[0]):
        out[i] = x[i] - m
    return out


@njit(cache=True)
def _divide_by_sum(e):
    total = _numpy_sum(e, 0, e.shape[0])
    return e / total


@njit(cache=True)
def _final_log_weights(logw, log_mixture, log_total, sizes):
    out = np.empty(logw.shape[0])
    start = 0
    for g in range(sizes.shape[0]):
        shift = log_mixture[g] - log_total[g]
        for i in range(start, start + sizes[g]):
            out[i] = logw[i] + shift
        start += sizes[g]
    return _max_shift(out)


def reassemble(logw: NDArray[np.float64], logpi: NDArray[np.float64],
               sizes: NDArray[np.int64], log_prior: NDArray[np.float64],
               evidence: bool = True
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The DPS mixture reassembly (``_Partitioned._reassemble``) with compiled glue.

    Parameters
    ----------
    logw, logpi : ndarray of shape (N,)
        log w̃ and log π' of every particle.
    sizes : ndarray of shape (C,), int64, C >= 2
        Group lengths.
    log_prior : ndarray of shape (C,)
        log π_c,t−1: log(N_c / N), ``np.log(sizes / sizes.sum())``, for groups drawn
        afresh, or the previous step's log mixture weights for groups that keep their
        particles.
    evidence : bool, optional
        True: π_c,t ∝ π_c,t−1 times the group's evidence (DPS ``mixture="evidence"``);
        False: π_c,t = π_c,t−1, every group keeps its share (``mixture="prior"``).

    Returns
    -------
    weights : ndarray of shape (N,)
        The posterior weights, summing to 1.
    mixture : ndarray of shape (C,)
        The mixture weights π_c,t.
    log_mixture : ndarray of shape (C,)
        log π_c,t, normalised (finite where π_c,t underflows to 0).

    Notes
    -----
    The numpy expression it replaces: log_total = LSE_c(logw), log_evidence = log_total −
    LSE_c(logpi) (``log_sum_exp_groups``), mixture = normalised(log(N_c / N) +
    log_evidence), weights = normalised(logw + log mixture_c − log_total_c); the exp and
    log calls are numpy's, the rest compiled, in the same order.
    """
    logw = np.ascontiguousarray(logw, dtype=np.float64)
    logpi = np.ascontiguousarray(logpi, dtype=np.float64)
    shifted, top_w, top_p = _reassemble_shift(logw, logpi, sizes)
    logs = np.log(_reassemble_sums(np.exp(shifted), sizes))
    log_total = top_w + logs[0]
    log_evidence = log_total - (top_p + logs[1])
    top = _max_shift(log_prior + log_evidence if evidence else log_prior)
    e = np.exp(top)
    mixture = _divide_by_sum(e)
    with np.errstate(divide="ignore"):  # a component far below the others: π_c = 0
        log_mixture = np.log(mixture)
    final = np.exp(_final_log_weights(logw, log_mixture, log_total, sizes))
    return _divide_by_sum(final), mixture, top - np.log(e.sum())


@njit(cache=True)
def _weighted_mean_states(weights, particles):
    n, k = particles.shape[0], particles.shape[1]
    shared = weights.shape[1] == 1
    mean = np.zeros((k, 3))
    total = np.zeros((k, 3))
    for r in range(n):
        for o in range(k):
            wr = weights[r, 0] if shared else weights[r, o]
            for c in range(3):
                mean[o, c] += wr * particles[r, o, c]
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


@njit(cache=True)
def _row_max_shift(x):
    out = np.empty(x.shape)
    for i in range(x.shape[0]):
        m = x[i, 0]
        for j in range(1, x.shape[1]):
            m = max(m, x[i, j])
        for j in range(x.shape[1]):
            out[i, j] = x[i, j] - m
    return out


def row_max_shift(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each row of x (K, N) minus its maximum, as a new C-contiguous array (K, N).

    Parameters
    ----------
    x : array_like of float, shape (K, N)
        Log-weights, one row per object, N >= 1.

    Returns
    -------
    ndarray of float64, shape (K, N)
        ``x - x.max(axis=1, keepdims=True)``.
    """
    return _row_max_shift(np.asarray(x, dtype=np.float64))


@njit(cache=True)
def _normalise_rows(e):
    out = np.empty(e.shape)
    for i in range(e.shape[0]):
        total = _numpy_sum(e[i], 0, e.shape[1])
        for j in range(e.shape[1]):
            out[i, j] = e[i, j] / total
    return out


def normalise_rows(e: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each row of e (K, N) divided by its ``np.sum``; with ``row_max_shift`` and numpy's
    exp between them, ``normalised_weights`` of every row.

    Parameters
    ----------
    e : array_like of float, shape (K, N)
        Non-negative weights, one row per object (not checked).

    Returns
    -------
    ndarray of float64, shape (K, N)
        ``e / e.sum(axis=1, keepdims=True)``, to the bit.
    """
    return _normalise_rows(np.ascontiguousarray(e, dtype=np.float64))


@njit(cache=True)
def _effective_uv(var, sig2):
    k = var.shape[0]
    out = np.empty(k)
    for o in range(k):
        e = np.empty(2)
        for c in range(2):
            e[c] = var[o, c] / sig2[c] if sig2[c] > 0 else 1.0
        out[o] = (e[0] + e[1]) / 2
    return out


def effective_uv(var: NDArray[np.float64], sigma: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mean over (u, v) of the effective dynamics var / σ² (1 where σ = 0), shape (K,),
    from the variances ``var`` (K, 3) and σ (3,) (``effective_dynamics(...)[:, :2]
    .mean(axis=1)``).

    Parameters
    ----------
    var : ndarray of float64, shape (K, 3)
        Variance of (u, v, a) of each object over the particle set (only u and v read).
    sigma : array_like of float, shape (3,)
        σ of the tracking dynamics per parameter (only u and v read).

    Returns
    -------
    ndarray of float64, shape (K,)
        (var_u / σ_u² + var_v / σ_v²) / 2, a term being 1 where its σ is 0.
    """
    return _effective_uv(var, np.asarray(sigma, dtype=np.float64) ** 2)


def weighted_mean_states(weights: NDArray[np.float64], particles: NDArray[np.float64]
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Weighted mean (K, 3) of particles (N, K, 3) and their unweighted variance (K, 3).

    ``weights`` is (N, K) (column k weights object k: ``(weights[:, :, None] *
    particles).sum(axis=0)``) or (N, 1), one column shared by every object; the variance
    is ``particles.var(axis=0)``.

    Parameters
    ----------
    weights : array_like of float, shape (N, K) or (N, 1)
        Normalised weights (not checked).
    particles : array_like of float, shape (N, K, 3)
        Particle states (u, v, a), N >= 1.

    Returns
    -------
    mean : ndarray of float64, shape (K, 3)
        Σ_n weights[n, k] particles[n, k] per object.
    var : ndarray of float64, shape (K, 3)
        The unweighted population variance (ddof 0) over the N particles.
    """
    return _weighted_mean_states(np.asarray(weights, dtype=np.float64),
                                 np.ascontiguousarray(particles, dtype=np.float64))
