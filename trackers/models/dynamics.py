"""Particle state (u, v, a) and its second-order autoregressive dynamics (DPS §3.2).

The state of one object is X = (u, v, a): u, v the box centre in pixels (x = column,
y = row) and a the log scale, so that the box of a state is

    w = w0 · exp(a),  h = h0 · exp(a),  x = u − w / 2,  y = v − h / 2,

with (w0, h0) the object's initial box size. A particle carries X_t and X_{t−1}, since
the AR2 model (docs/algorithms.md §1.1) predicts from both:

    X_t = X̄ + A1 (X_{t−1} − X̄) + A2 (X_{t−2} − X̄) + σ ε_t,   ε_t ~ N(0, I).

A1 = 2, A2 = −1 (the defaults) is constant velocity with acceleration noise, for which
X̄ drops out; with a damped or stationary choice X̄ is the object's initial state.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["AR2", "boxes_from_states", "states_from_boxes"]


def states_from_boxes(boxes: NDArray[np.floating]) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64]]:
    """States (K, 3) = (u, v, 0) and base sizes (K, 2) = (w0, h0) of boxes (K, 4)."""
    b = np.asarray(boxes, dtype=np.float64)
    states = np.column_stack([b[:, 0] + b[:, 2] / 2, b[:, 1] + b[:, 3] / 2,
                              np.zeros(b.shape[0])])
    return states, b[:, 2:4].copy()


def boxes_from_states(states: NDArray[np.floating], sizes: NDArray[np.floating]
                      ) -> NDArray[np.float64]:
    """Boxes [x, y, w, h] (..., 4) of states (..., 3) with base sizes (..., 2).

    ``sizes`` broadcasts against ``states[..., :2]`` (e.g. (K, 2) for states (N, K, 3)).

    Example
    -------
    >>> boxes_from_states(np.array([[10.0, 20.0, 0.0]]), np.array([[4.0, 6.0]])).tolist()
    [[8.0, 17.0, 4.0, 6.0]]
    """
    s = np.asarray(states, dtype=np.float64)
    wh = np.asarray(sizes, dtype=np.float64) * np.exp(s[..., 2:3])
    return np.concatenate([s[..., :2] - wh / 2, wh], axis=-1)


@dataclass(frozen=True)
class AR2:
    """AR2 dynamics of (u, v, a) with per-coordinate noise (docs/algorithms.md §1.1, §2.1).

    Parameters
    ----------
    sigma : tuple of 3 floats, optional
        Noise standard deviations (σ_u, σ_v, σ_a): pixels, pixels, log scale per frame.
        DPS tracks with (2, 2, 0.001).
    a1, a2 : float, optional
        AR coefficients A1, A2.

    Example
    -------
    >>> dyn = AR2(sigma=(0.0, 0.0, 0.0))
    >>> dyn.propagate(np.array([[3.0, 1.0, 0.0]]), np.array([[1.0, 1.0, 0.0]]),
    ...               np.zeros(3), rng=np.random.default_rng(0)).tolist()
    [[5.0, 1.0, 0.0]]
    """

    sigma: tuple[float, float, float] = (2.0, 2.0, 0.001)
    a1: float = 2.0
    a2: float = -1.0
    _sigma: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        sig = np.asarray(self.sigma, dtype=np.float64)
        if sig.shape != (3,) or not np.all(np.isfinite(sig)) or np.any(sig < 0):
            raise ValueError(f"sigma must be 3 finite non-negative numbers (u, v, a), got "
                             f"{self.sigma!r}")
        for name, val in (("a1", self.a1), ("a2", self.a2)):
            if not np.isfinite(val):
                raise ValueError(f"{name} must be finite, got {val!r}")
        object.__setattr__(self, "_sigma", sig)

    def propagate(
        self,
        x: NDArray[np.floating],
        x_prev: NDArray[np.floating],
        mean: NDArray[np.floating],
        *,
        rng: np.random.Generator,
    ) -> NDArray[np.float64]:
        """One AR2 step: X_t from X_{t−1} = ``x`` and X_{t−2} = ``x_prev``.

        Parameters
        ----------
        x, x_prev : ndarray of shape (..., 3)
            Current and previous states.
        mean : ndarray broadcasting to (..., 3)
            X̄ (irrelevant when A1 + A2 = 1).
        rng : numpy.random.Generator
            Draws one standard normal per coordinate, in C order of ``x``.

        Returns
        -------
        ndarray of shape (..., 3)
        """
        noise = rng.standard_normal(np.shape(x)) * self._sigma
        return mean + self.a1 * (x - mean) + self.a2 * (x_prev - mean) + noise
