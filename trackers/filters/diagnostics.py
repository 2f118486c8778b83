"""Impoverishment diagnostics of a particle set (DPS §3.1; docs/algorithms.md §2.7).

- Uniqueness of object i: the number of distinct hypotheses of its sub-state X_i among
  the N particles, divided by N. Resampling copies particles; only propagation makes new
  values, so an object that went through many weighted-resampling stages since it was
  last propagated (early in a PS ordering) has few distinct values.
- Effective dynamics of object i and parameter c ∈ (u, v, a): the variance of c over the
  particle set at the end of a step divided by σ_c² of the tracking dynamics (DPS
  reports it in %; it may exceed 1 because particles follow the observations).
  **(open)** The variance is unweighted — the spread of the sample itself, which is what
  impoverishment shrinks; the weighted variance estimates the posterior's spread, which
  weighted resampling leaves unchanged by design. A parameter with σ_c = 0 has effective
  dynamics 1: the dynamics add no spread to it, so there is none for the sampler to thin
  (the particle filters start every particle on its box, so such a parameter never
  spreads; its variance is 0 up to rounding, and 0 / 0 was NaN).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from trackers.kernels.sampling import count_distinct

__all__ = ["effective_dynamics", "uniqueness"]


def _check_particles(particles):
    p = np.asarray(particles, dtype=np.float64)
    if p.ndim != 3 or p.shape[2] != 3 or p.shape[0] < 1:
        raise ValueError(f"particles must have shape (N, K, 3) with N >= 1, got {p.shape}")
    return p


def uniqueness(particles: NDArray[np.floating]) -> NDArray[np.float64]:
    """Distinct sub-states per object over N, shape (K,), in (0, 1].

    Parameters
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a), N >= 1.

    Returns
    -------
    ndarray of float64, shape (K,)
        Number of distinct (u, v, a) rows of each object over N, in (0, 1].

    Raises
    ------
    ValueError
        If ``particles`` is not of shape (N, K, 3) with N >= 1.

    Examples
    --------
    >>> p = np.zeros((4, 2, 3)); p[:, 1, 0] = [0.0, 1.0, 1.0, 2.0]
    >>> uniqueness(p).tolist()
    [0.25, 0.75]
    """
    p = _check_particles(particles)
    return count_distinct(p) / p.shape[0]


def effective_dynamics(particles: NDArray[np.floating], sigma: NDArray[np.floating]
                       ) -> NDArray[np.float64]:
    """Unweighted variance of each parameter over the set divided by σ², shape (K, 3).

    Parameters
    ----------
    particles : ndarray of shape (N, K, 3)
        Particle states (u, v, a), N >= 1.
    sigma : array_like of shape (3,)
        σ of the tracking dynamics per parameter; a parameter with σ = 0 gives 1 (no
        spread to lose).

    Returns
    -------
    ndarray of float64, shape (K, 3)
        Population variance (ddof 0) of u, v, a over the N particles divided by σ²;
        1 where σ = 0.

    Raises
    ------
    ValueError
        If ``particles`` is not of shape (N, K, 3) with N >= 1, or ``sigma`` not (3,).

    Examples
    --------
    >>> p = np.zeros((2, 1, 3)); p[:, 0, 0] = [0.0, 4.0]
    >>> effective_dynamics(p, [2.0, 2.0, 1.0]).tolist()
    [[1.0, 0.0, 0.0]]
    >>> effective_dynamics(p, [2.0, 2.0, 0.0]).tolist()
    [[1.0, 0.0, 1.0]]
    """
    p = _check_particles(particles)
    sig2 = np.asarray(sigma, dtype=np.float64) ** 2
    if sig2.shape != (3,):
        raise ValueError(f"sigma must have shape (3,), got {np.shape(sigma)}")
    var = p.var(axis=0)
    return np.where(sig2 > 0, var / np.where(sig2 > 0, sig2, 1.0), 1.0)
