"""Resamplers by name, and weighted resampling (docs/algorithms.md §2.4).

Every resampler maps normalised weights to ancestor indices. Four schemes (Douc, Cappé &
Moulines 2005), all inverse-CDF except the deterministic part of ``residual``:

- ``multinomial``: i.i.d. uniforms;
- ``stratified``: one uniform in each of the n strata [i/n, (i+1)/n);
- ``systematic``: one uniform shifted by i/n (lowest variance in practice; the default);
- ``residual``: floor(n w_i) copies of each particle, the rest multinomially on the
  residual weights.

The particle sets of DPS are mixtures of groups that are resampled separately; a group is
a contiguous slice of the weight vector (``sizes`` lists the slice lengths) and every
function here resamples all groups in one vectorised pass, each group within itself and
to its own size. One group is the usual case.

Examples
--------
>>> import numpy as np
>>> rng = np.random.default_rng(0)
>>> resample(np.array([0.0, 1.0, 0.0]), rng=rng).tolist()
[1, 1, 1]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from trackers.base import check_generator
from trackers.kernels.sampling import MULTINOMIAL, STRATIFIED, SYSTEMATIC, inverse_cdf_groups
from trackers.kernels.stages import normalise_groups_checked

__all__ = [
    "RESAMPLERS",
    "RESAMPLE_MODES",
    "group_starts",
    "resample",
    "resample_groups",
    "weighted_resample",
    "weighted_resample_groups",
]


# Uniforms per group (systematic) or per draw, and how the kernel turns them into
# positions of the groups' CDFs.
_MODES: dict[str, int] = {
    "multinomial": MULTINOMIAL,
    "stratified": STRATIFIED,
    "systematic": SYSTEMATIC,
}


#: The inverse-CDF resamplers' kernel modes (``trackers.kernels.sampling``), by name; the
#: compiled stages of the particle filters draw their uniforms as ``_draw`` does.
RESAMPLE_MODES: dict[str, int] = dict(_MODES)

#: Resampler names (``resampler`` parameter of the particle trackers).
RESAMPLERS: tuple[str, ...] = ("multinomial", "systematic", "stratified", "residual")


def group_starts(sizes: NDArray[np.integer]) -> NDArray[np.int64]:
    """First index of each group, shape (C,), for group lengths ``sizes`` (C,).

    Parameters
    ----------
    sizes : array_like of int, shape (C,)
        Lengths of the contiguous groups (not checked).

    Returns
    -------
    ndarray of int64, shape (C,)
        The exclusive cumulative sum of ``sizes``: 0, sizes[0], sizes[0] + sizes[1], ...

    Examples
    --------
    >>> group_starts([3, 1, 2]).tolist()
    [0, 3, 4]
    """
    sizes = np.asarray(sizes, dtype=np.int64)
    return np.cumsum(sizes) - sizes


def _finite_non_negative(x):
    # One sum and one min instead of elementwise masks: a NaN or an infinity makes the
    # sum non-finite (inf − inf is NaN), a negative entry the minimum negative.
    return bool(np.isfinite(x.sum())) and x.min() >= 0


def _check_sizes(sizes, n):
    if sizes is None and n >= 1:
        return np.array([n], dtype=np.int64)  # one group: nothing to check
    sizes = np.asarray([n] if sizes is None else sizes, dtype=np.int64)
    if sizes.ndim != 1 or sizes.size < 1 or sizes.min() < 1 or sizes.sum() != n:
        raise ValueError(f"group sizes must be positive and sum to {n}, got {sizes.tolist()}")
    return sizes


def _checked_weights(weights, name):
    """``weights`` as float64 (N,), checked finite and non-negative."""
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 1 or w.size < 1:
        raise ValueError(f"{name} must have shape (N,) with N >= 1, got {w.shape}")
    if not _finite_non_negative(w):
        raise ValueError(f"{name} must be finite and non-negative")
    return w


def _normalise_groups(weights, sizes, name):
    if (isinstance(weights, np.ndarray) and weights.dtype == np.float64 and weights.ndim == 1
            and weights.size and weights.flags.c_contiguous):
        # Compiled: the same checks and the same division by np.add.reduceat, to the bit.
        out, ok = normalise_groups_checked(weights, sizes)
        if ok:
            return out
    w = _checked_weights(weights, name)
    totals = np.add.reduceat(w, group_starts(sizes))
    if totals.min() <= 0:
        raise ValueError(f"{name} must have a positive sum in every group, got sums "
                         f"{totals.tolist()}")
    return w / np.repeat(totals, sizes)


def _draw(w, counts, sizes, method, rng):
    """Indices into ``w`` (normalised per group): ``counts[c]`` draws inside group c."""
    mode = _MODES[method]
    uniforms = rng.random(sizes.size if mode == SYSTEMATIC else int(counts.sum()))
    return inverse_cdf_groups(w, sizes, counts, uniforms, mode)


def resample_groups(
    weights: NDArray[np.floating],
    sizes: NDArray[np.integer] | None = None,
    *,
    method: str = "systematic",
    rng: np.random.Generator,
) -> NDArray[np.int64]:
    """Resample every group of a weighted set within itself, to its own size.

    Parameters
    ----------
    weights : ndarray of shape (N,)
        Non-negative weights (normalised here, per group).
    sizes : ndarray of shape (C,), optional
        Lengths of the contiguous groups, summing to N; None is one group.
    method : {"multinomial", "systematic", "stratified", "residual"}, optional
        Resampling scheme (module docstring).
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    ndarray of shape (N,), int64
        Ancestor index of each new particle; entries of group c lie in group c.

    Raises
    ------
    ValueError
        For an unknown method, weights not of shape (N,) with N >= 1, negative or
        non-finite weights, a group of zero total weight, sizes that do not sum to N, or
        an ``rng`` that is not a Generator (a seed is refused:
        ``trackers.base.check_generator``).
    """
    _check_method(method)
    check_generator(rng)
    w = _weights_shape(weights, "weights")
    sizes = _check_sizes(sizes, w.shape[0])
    return _resample_normalised(_normalise_groups(w, sizes, "weights"), sizes, method, rng)


def _weights_shape(weights, name):
    """``weights`` as an array, checked (N,) with N >= 1 (a (N, 1) or an empty array was
    "group sizes must be positive and sum to -1" or "to 0", naming no argument)."""
    w = np.asarray(weights)
    if w.ndim != 1 or w.size < 1:
        raise ValueError(f"{name} must have shape (N,) with N >= 1, got {w.shape}")
    return w


def _check_method(method):
    if method not in RESAMPLERS:
        raise ValueError(f"unknown resampler {method!r}; valid: {', '.join(RESAMPLERS)}")


def _resample_normalised(w, sizes, method, rng):
    """``resample_groups`` on weights already normalised per group."""
    if method != "residual":
        return _draw(w, sizes, sizes, method, rng)
    # Residual: floor(n_c w_i) deterministic copies, the remainder multinomially on the
    # residual weights n_c w_i − floor(n_c w_i).
    scaled = w * np.repeat(sizes, sizes)
    copies = np.floor(scaled).astype(np.int64)
    fixed = np.repeat(np.arange(w.size), copies)
    rest = sizes - np.add.reduceat(copies, group_starts(sizes))
    if not rest.any():
        return fixed
    resid = scaled - copies
    # A group with nothing left to draw may have all-zero residuals: give it dummy mass,
    # it receives no draw anyway.
    totals = np.add.reduceat(resid, group_starts(sizes))
    resid[np.repeat(totals <= 0, sizes)] = 1.0
    drawn = _draw(_normalise_groups(resid, sizes, "residual weights"), rest, sizes,
                  "multinomial", rng)
    # Keep each group's new particles contiguous, in group order.
    group_of = np.repeat(np.arange(sizes.size), sizes)
    groups = np.concatenate([group_of[fixed], np.repeat(np.arange(sizes.size), rest)])
    out = np.concatenate([fixed, drawn])
    return out[np.argsort(groups, kind="stable")]


def resample(
    weights: NDArray[np.floating],
    *,
    method: str = "systematic",
    rng: np.random.Generator,
) -> NDArray[np.int64]:
    """Draw N ancestor indices from weights (N,) by ``method`` (one group).

    Parameters
    ----------
    weights : ndarray of shape (N,)
        Non-negative weights, N >= 1 (normalised here).
    method : {"multinomial", "systematic", "stratified", "residual"}, optional
        Resampling scheme (module docstring); default ``"systematic"``.
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    ndarray of shape (N,), int64
        Ancestor index of each new particle.

    Raises
    ------
    ValueError
        As ``resample_groups``.
    """
    return resample_groups(weights, method=method, rng=rng)


def weighted_resample_groups(
    weights: NDArray[np.floating],
    g: NDArray[np.floating],
    sizes: NDArray[np.integer] | None = None,
    *,
    method: str = "systematic",
    rng: np.random.Generator,
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Weighted resampling (MacCormick & Blake 2000; docs/algorithms.md §2.4), per group.

    Draws ancestors k with probability ρ_k ∝ π_k g(x_k) inside each group and gives the
    new particle the weight π_k / ρ_k, renormalised in its group: the set represents the
    same distribution as before, with its particles moved to where ``g`` is high.

    Parameters
    ----------
    weights : ndarray of shape (N,)
        Current weights π (normalised here, per group).
    g : ndarray of shape (N,)
        Non-negative weighting function at each particle (e.g. one object's likelihood),
        with π g of positive sum in every group; it may be scaled by any constant per
        group. A particle with g = 0 is never drawn.
    sizes : ndarray of shape (C,), optional
        Lengths of the contiguous groups; None is one group.
    method : str, optional
        Resampler for the draw (``RESAMPLERS``).
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    indices : ndarray of shape (N,), int64
        Ancestor of each new particle (inside its group).
    new_weights : ndarray of shape (N,)
        π_k / ρ_k, normalised to sum 1 in each group.

    Raises
    ------
    ValueError
        For weights or ``g`` that are negative or not finite, ``g`` not of the shape of
        the weights, a group where π g sums to zero, or the cases of ``resample_groups``.
    """
    _check_method(method)
    check_generator(rng)
    w = _weights_shape(weights, "weights")
    gv = np.asarray(g, dtype=np.float64)
    if gv.shape != w.shape:
        raise ValueError(f"g must have the shape of weights {w.shape}, got {gv.shape}")
    if not _finite_non_negative(gv):
        raise ValueError("g must be finite and non-negative")
    sizes = _check_sizes(sizes, w.shape[0])
    # ρ ∝ π g per group; the new weight π_k / ρ_k = (Σ_c π g) / g_k is 1 / g_k up to the
    # group's constant, which the final normalisation removes. Drawn ancestors have
    # ρ_k > 0, hence g_k > 0.
    rho = _checked_weights(w, "weights") * gv
    totals = np.add.reduceat(rho, group_starts(sizes))
    if not totals.min() > 0:
        raise ValueError(f"weights * g must have a positive sum in every group, got sums "
                         f"{totals.tolist()}")
    idx = _resample_normalised(rho / np.repeat(totals, sizes), sizes, method, rng)
    new = 1.0 / gv[idx]
    return idx, new / np.repeat(np.add.reduceat(new, group_starts(sizes)), sizes)


def weighted_resample(
    weights: NDArray[np.floating],
    g: NDArray[np.floating],
    *,
    method: str = "systematic",
    rng: np.random.Generator,
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Weighted resampling of one set: ``weighted_resample_groups`` with one group.

    Parameters
    ----------
    weights : ndarray of shape (N,)
        Current weights π, non-negative (normalised here).
    g : ndarray of shape (N,)
        Non-negative weighting function at each particle (e.g. one object's likelihood),
        up to a constant factor.
    method : {"multinomial", "systematic", "stratified", "residual"}, optional
        Resampler for the draw; default ``"systematic"``.
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    indices : ndarray of shape (N,), int64
        Ancestor of each new particle, drawn with probability ∝ π g.
    new_weights : ndarray of shape (N,)
        π_k / ρ_k, normalised to sum 1.

    Raises
    ------
    ValueError
        As ``weighted_resample_groups``.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> idx, w = weighted_resample(np.full(4, 0.25), np.array([1.0, 1.0, 1.0, 3.0]), rng=rng)
    >>> idx.tolist(), np.round(w * 8, 6).tolist()
    ([0, 2, 3, 3], [3.0, 3.0, 1.0, 1.0])
    """
    return weighted_resample_groups(weights, g, method=method, rng=rng)
