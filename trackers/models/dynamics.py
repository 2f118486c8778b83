"""Particle state (u, v, a) and its second-order autoregressive dynamics (DPS §3.2).

The state of one object is X = (u, v, a): u, v the box centre in pixels (x = column,
y = row) and a the log scale, so that the box of a state is

    w = w0 · exp(a),  h = h0 · exp(a),  x = u − w / 2,  y = v − h / 2,

with (w0, h0) the object's initial box size. A particle carries X_t and X_{t−1}, since
the AR2 model (docs/algorithms.md §1.1) predicts from both:

    X_t = X̄ + A1 (X_{t−1} − X̄) + A2 (X_{t−2} − X̄) + σ ε_t,   ε_t ~ N(0, I).

A1 = 2, A2 = −1 (the defaults) is constant velocity with acceleration noise, for which
X̄ drops out; with a damped or stationary choice X̄ is the object's initial state.

The valid parameters (:func:`check_ar2`) keep the propagated state finite: A1, A2 must not
be explosive (every root of z² − A1 z − A2 in the closed unit disk, i.e. |A2| <= 1 and
|A1| <= 1 − A2; an explosive AR2 pushes every particle away from X̄ geometrically, and
A1 = 1e200 overflowed at the second step), σ_u, σ_v <= :data:`MAX_SIGMA_UV` pixels and
σ_a <= :data:`MAX_SIGMA_A` (a larger σ_a overflowed exp(a) at the first step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from trackers.base import MAX_BOX_VALUE, check_generator

__all__ = ["AR2", "MAX_SIGMA_A", "MAX_SIGMA_UV", "boxes_from_states", "check_ar2",
           "check_ar2_coefficients", "states_from_boxes"]

MAX_SIGMA_UV = MAX_BOX_VALUE
"""Largest σ_u, σ_v (pixels per frame): a noise step beyond the largest box coordinate
(:data:`trackers.base.MAX_BOX_VALUE`) says nothing about where a target is."""

MAX_SIGMA_A = math.log(MAX_BOX_VALUE)
"""Largest σ_a (log scale per frame), about 20.7: one σ then scales a box by
:data:`trackers.base.MAX_BOX_VALUE`. exp(a) overflows beyond 709."""


def check_ar2(sigma: object, a1: object, a2: object
              ) -> tuple[tuple[float, float, float], float, float]:
    """Validate AR2 tracking dynamics; return (σ_u, σ_v, σ_a), A1, A2 as floats.

    Parameters
    ----------
    sigma : sequence of 3 float
        Noise standard deviations (σ_u, σ_v, σ_a): px, px, log scale per frame.
    a1, a2 : float
        AR coefficients A1, A2.

    Returns
    -------
    sigma : tuple of 3 float
        (σ_u, σ_v, σ_a).
    a1, a2 : float
        A1, A2.

    Raises
    ------
    ValueError
        One line naming the parameter and its value: ``sigma`` not three finite numbers
        in [0, :data:`MAX_SIGMA_UV`] (u, v) and [0, :data:`MAX_SIGMA_A`] (a); ``a1`` or
        ``a2`` not a finite number; ``a1, a2`` explosive (a root of z² − A1 z − A2
        outside the unit circle; :func:`check_ar2_coefficients`).

    Examples
    --------
    >>> check_ar2((2, 2, 0.001), 2, -1)
    ((2.0, 2.0, 0.001), 2.0, -1.0)
    >>> check_ar2((2, 2, 0.001), 3.0, -1.0)
    Traceback (most recent call last):
    ...
    ValueError: a1, a2 must not be explosive (|a2| <= 1 and |a1| <= 1 - a2), got a1=3, ...
    """
    try:
        items = [] if isinstance(sigma, (str, bytes)) else list(sigma)  # type: ignore[call-overload]
        # True was read as 1 px, and "2" as 2 px: a number field takes numbers only.
        sig = tuple(math.nan if isinstance(v, (bool, str, bytes)) else float(v)
                    for v in items)
    except (TypeError, ValueError):
        sig = ()
    if len(sig) != 3 or not all(math.isfinite(v) and v >= 0 for v in sig):
        raise ValueError(f"sigma must be 3 finite non-negative numbers (u, v, a), got "
                         f"{sigma!r}")
    if max(sig[:2]) > MAX_SIGMA_UV or sig[2] > MAX_SIGMA_A:
        raise ValueError(f"sigma must be (u, v, a) with u, v <= {MAX_SIGMA_UV:g} px and "
                         f"a <= {MAX_SIGMA_A:.3g}, got {sigma!r}")
    c1, c2 = check_ar2_coefficients(a1, a2)
    return sig, c1, c2  # type: ignore[return-value]


def check_ar2_coefficients(a1: object, a2: object) -> tuple[float, float]:
    """Validate AR2 coefficients A1, A2 (finite, not explosive); return them as floats.

    The one definition of "explosive" for every tracker with AR2 dynamics: the particle
    trackers (through :func:`check_ar2`) and the Kalman and SHM trackers
    (``trackers.kalman.KalmanParams``), whose covariance grew without bound (NaN boxes)
    under an explosive model.

    Parameters
    ----------
    a1, a2 : float
        AR coefficients A1, A2 (booleans and numbers written as text are refused).

    Returns
    -------
    a1, a2 : float
        A1, A2 as floats.

    Raises
    ------
    ValueError
        One line naming the parameter and its value: ``a1`` or ``a2`` not a finite
        number; ``a1, a2`` explosive (a root of z² − A1 z − A2 outside the unit circle).

    Examples
    --------
    >>> check_ar2_coefficients(1.9, -0.9)
    (1.9, -0.9)
    >>> check_ar2_coefficients(2.5, -0.5)
    Traceback (most recent call last):
    ...
    ValueError: a1, a2 must not be explosive (|a2| <= 1 and |a1| <= 1 - a2), got a1=2.5, ...
    """
    coef = []
    for name, val in (("a1", a1), ("a2", a2)):
        try:
            x = float(val)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            x = math.nan
        # Text ("2") was read as a number; booleans too (True as 1).
        if isinstance(val, (bool, str, bytes)) or not math.isfinite(x):
            raise ValueError(f"{name} must be finite, got {val!r}")
        coef.append(x)
    c1, c2 = coef
    # Schur-Cohn for a real quadratic: both roots of z^2 - a1 z - a2 in |z| <= 1.
    if not (abs(c2) <= 1 and abs(c1) <= 1 - c2):
        radius = float(np.max(np.abs(np.roots([1.0, -c1, -c2]))))
        raise ValueError(f"a1, a2 must not be explosive (|a2| <= 1 and |a1| <= 1 - a2), "
                         f"got a1={c1:g}, a2={c2:g} (a root of z^2 - a1 z - a2 has modulus "
                         f"{radius:.3g})")
    return c1, c2


def states_from_boxes(boxes: NDArray[np.floating]) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64]]:
    """States (K, 3) = (u, v, 0) and base sizes (K, 2) = (w0, h0) of boxes (K, 4).

    Parameters
    ----------
    boxes : array_like of float, shape (K, 4)
        Boxes [x, y, w, h] in px (not checked).

    Returns
    -------
    states : ndarray of float64, shape (K, 3)
        (u, v, a) = box centre in px, log scale 0.
    sizes : ndarray of float64, shape (K, 2)
        Base size (w0, h0) in px, a copy of ``boxes[:, 2:4]``.

    Examples
    --------
    >>> states, sizes = states_from_boxes(np.array([[8.0, 17.0, 4.0, 6.0]]))
    >>> states.tolist(), sizes.tolist()
    ([[10.0, 20.0, 0.0]], [[4.0, 6.0]])
    """
    b = np.asarray(boxes, dtype=np.float64)
    states = np.column_stack([b[:, 0] + b[:, 2] / 2, b[:, 1] + b[:, 3] / 2,
                              np.zeros(b.shape[0])])
    return states, b[:, 2:4].copy()


def boxes_from_states(states: NDArray[np.floating], sizes: NDArray[np.floating]
                      ) -> NDArray[np.float64]:
    """Boxes [x, y, w, h] (..., 4) of states (..., 3) with base sizes (..., 2).

    ``sizes`` broadcasts against ``states[..., :2]`` (e.g. (K, 2) for states (N, K, 3)).

    Parameters
    ----------
    states : array_like of float, shape (..., 3)
        States (u, v, a): centre in px, log scale.
    sizes : array_like of float, shape (..., 2)
        Base sizes (w0, h0) in px, broadcasting against ``states[..., :2]``.

    Returns
    -------
    ndarray of float64, shape (..., 4)
        Boxes [u - w/2, v - h/2, w, h] with (w, h) = (w0, h0) exp(a), in px.

    Examples
    --------
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
        AR coefficients A1, A2, not explosive (:func:`check_ar2`).

    Raises
    ------
    ValueError
        For parameters :func:`check_ar2` refuses, naming the parameter.

    Examples
    --------
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
        sig, _, _ = check_ar2(self.sigma, self.a1, self.a2)
        object.__setattr__(self, "_sigma", np.asarray(sig, dtype=np.float64))

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

        Raises
        ------
        ValueError
            If ``rng`` is not a Generator (``trackers.base.check_generator``).
        """
        check_generator(rng)
        noise = rng.standard_normal(np.shape(x)) * self._sigma
        return mean + self.a1 * (x - mean) + self.a2 * (x_prev - mean) + noise
