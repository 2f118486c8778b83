"""AR2 trajectories with boundary rules (docs/algorithms.md §1)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from scenegen.config import AR2, MAX_PATH
from scenegen.errors import ConfigError

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
    field: str = "motion",
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
    field : str
        The AR2's field path, for the error (``entities[0].motion.x``).

    Returns
    -------
    ndarray of shape (n,)

    Raises
    ------
    ConfigError
        ``field: the AR2 path reaches V at frame t, ...`` when a value goes beyond
        :data:`~scenegen.config.MAX_PATH` in magnitude (or overflows): an explosive AR2
        on an unbounded axis.
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
        if not -MAX_PATH <= c <= MAX_PATH:  # also NaN
            raise ConfigError(_runaway(params, field, c, t))
        prev2, prev = prev, c
        out[t] = c
    return out


def _runaway(params: AR2, field: str, value: float, t: int) -> str:
    """The one-line message of a path that went beyond MAX_PATH at frame ``t``."""
    a1, a2 = params.a1, params.a2
    # Roots of z^2 - a1 z - a2; their largest modulus says whether the AR2 explodes.
    radius = float(np.max(np.abs(np.roots([1.0, -a1, -a2]))))
    if radius > 1 + 1e-6:  # a double root at 1 may come out a hair above
        why = (
            f"a1={a1:g}, a2={a2:g} is explosive (a root of z^2 - a1 z - a2 has modulus "
            f"{radius:.3g} > 1): damp it (a1 = 1 + d, a2 = -d, 0 <= d <= 1), bound it "
            "(reflect or clamp) or use fewer frames"
        )
    else:
        why = f"sigma={params.sigma:g} over that many frames: use a smaller sigma or fewer frames"
    shown = f"{value:.3g}" if np.isfinite(value) else "infinity"
    return f"{field}: the AR2 path reaches {shown} at frame {t}, beyond +-{MAX_PATH:g}; {why}"


def ar2_stationary_moments(a1: float, a2: float, sigma: float) -> tuple[float, float]:
    """Stationary variance and lag-1 autocorrelation of an AR2 process.

    For ``|roots| < 1``: ``rho1 = a1 / (1 - a2)`` and
    ``var = sigma^2 (1 - a2) / ((1 + a2) ((1 - a2)^2 - a1^2))`` (Yule-Walker).

    Parameters
    ----------
    a1, a2 : float
        The AR2 coefficients.
    sigma : float
        Std of the noise.

    Returns
    -------
    var : float
        Stationary variance (in the coordinate's units squared).
    rho1 : float
        Lag-1 autocorrelation.

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
