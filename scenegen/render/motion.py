"""AR2 trajectories with boundary rules (docs/algorithms.md §1)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from scenegen.config import AR2

__all__ = ["ar2_path", "ar2_stationary_moments"]


def ar2_path(
    params: AR2,
    start: float,
    velocity: float,
    n: int,
    *,
    rng: np.random.Generator,
    lo: float = -np.inf,
    hi: float = np.inf,
) -> NDArray[np.float64]:
    """Simulate ``n`` values of one AR2 coordinate.

    ``c_t = mean + a1 (c_{t-1} - mean) + a2 (c_{t-2} - mean) + sigma eps_t`` with
    ``c_0 = start`` and ``c_{-1} = start - velocity``.

    Parameters
    ----------
    params : AR2
    start, velocity : float
        Value at frame 0 and initial velocity (per frame).
    n : int
        Number of frames.
    rng : numpy.random.Generator
        The entity's own stream; exactly ``n - 1`` normal draws are taken when sigma > 0
        (none otherwise), so the stream's later use does not depend on the path.
    lo, hi : float
        Limits applied by ``params.boundary`` (``free`` ignores them).

    Returns
    -------
    ndarray of shape (n,)
    """
    mean = start if params.mean is None else params.mean
    eps = rng.standard_normal(max(n - 1, 0)) * params.sigma if params.sigma > 0 else None
    out = np.empty(n, dtype=np.float64)
    prev2, prev = start - velocity, start
    if n:
        out[0] = start
    bounded = params.boundary != "free" and lo <= hi
    for t in range(1, n):
        c = mean + params.a1 * (prev - mean) + params.a2 * (prev2 - mean)
        if eps is not None:
            c += eps[t - 1]
        if bounded and not lo <= c <= hi:
            if params.boundary == "reflect":
                # Mirror the new value and the previous one: the velocity reverses.
                limit = lo if c < lo else hi
                c = 2 * limit - c
                prev = 2 * limit - prev
                c = min(max(c, lo), hi)  # a step longer than the interval stays inside
            else:
                c = min(max(c, lo), hi)
                prev = c
        prev2, prev = prev, c
        out[t] = c
    return out


def ar2_stationary_moments(a1: float, a2: float, sigma: float) -> tuple[float, float]:
    """Stationary variance and lag-1 autocorrelation of an AR2 process.

    For ``|roots| < 1``: ``rho1 = a1 / (1 - a2)`` and
    ``var = sigma^2 (1 - a2) / ((1 + a2) ((1 - a2)^2 - a1^2))`` (Yule-Walker).

    Raises
    ------
    ValueError
        If the process is not stationary.
    """
    if not (abs(a2) < 1 and a2 + a1 < 1 and a2 - a1 < 1):
        raise ValueError(f"AR2 with a1={a1}, a2={a2} is not stationary")
    rho1 = a1 / (1 - a2)
    var = sigma**2 * (1 - a2) / ((1 + a2) * ((1 - a2) ** 2 - a1**2))
    return var, rho1
