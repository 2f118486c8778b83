"""Annealed particle filter (Deutscher, Blake & Reid 2000), as used in the KAMS paper.

State of a particle: a target's centre (x, y); sizes stay those of ``init``. Weighting
function w = exp(−λ d²) of the Bhattacharyya distance d between the target's colour model
and the window at the particle (KAMS §2: Bhattacharyya distance throughout). Annealing
layers m = M … 0 weight by w^β_m with β_M ≤ … ≤ β_0 = 1 (KAMS eq. 1–4): β never decreases
from one layer to the next (``AnnealedPF``, ``schedule``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, Tracker
from trackers.filters.resampling import RESAMPLERS, resample_groups
from trackers.filters.weights import normalised_weights
from trackers.meanshift import (
    ColourParams,
    colour_model,
    keep_inside,
    set_distances,
    set_log_likelihoods,
    window_boxes,
)
from trackers.models.observation import FrameObservation
from trackers.params import (
    RNG_RANDOM,
    FieldDoc,
    TrackerParams,
    check_choice,
    check_integer,
    check_number,
    check_particle_count,
    choices,
    documented,
)

__all__ = [
    "ESTIMATES",
    "SCHEDULES",
    "AnnealedPF",
    "AnnealedParams",
    "check_particles",
    "resample_targets",
    "survival_beta",
    "survival_rate",
    "weighted_estimate",
]

#: Largest number of annealing layers (the papers use up to 10; each layer is a full
#: weighting of every particle).
MAX_LAYERS = 1000

#: β schedules of ``AnnealedPF``.
SCHEDULES = ("adaptive", "geometric")

#: Estimators of ``AnnealedPF``.
ESTIMATES = ("mean", "mode")


def survival_rate(log_w: NDArray[np.float64]) -> NDArray[np.float64]:
    """Survival rate α = (Σ w)² / (N Σ w²) of each row of log-weights (K, N), shape (K,).

    Parameters
    ----------
    log_w : ndarray of float64, shape (K, N)
        Log-weights (unnormalised) of each target's N particles; the row's maximum is
        subtracted before exp.

    Returns
    -------
    ndarray of float64, shape (K,)
        α in [1/N, 1]: 1 for equal weights, 1/N for a single non-zero weight.

    Examples
    --------
    >>> survival_rate(np.array([[0.0, 0.0], [0.0, -np.inf]])).tolist()
    [1.0, 0.5]
    """
    w = np.exp(log_w - log_w.max(axis=1, keepdims=True))
    return w.sum(axis=1) ** 2 / (log_w.shape[1] * (w * w).sum(axis=1))


# The search grids of ``survival_beta`` (constants, computed once).
_COARSE = np.logspace(-8.0, 0.0, 65)
_FINE = np.linspace(0.0, 1.0, 65)


def survival_beta(log_lik: NDArray[np.float64], alpha: float) -> NDArray[np.float64]:
    """Largest β in (0, 1] whose weights w^β keep a survival rate of at least ``alpha``.

    The rule of the PARSEC bodytrack annealed filter (Deutscher et al.'s adaptive
    annealing): a smaller β flattens the weights and raises the survival rate, which is 1
    at β = 0. Searched on a geometric grid of 65 values over [1e-8, 1], then on 65 values
    between the bracketing grid points (relative precision about 0.5 %), all targets and
    candidates in one vectorised evaluation per stage.

    Parameters
    ----------
    log_lik : ndarray of shape (K, N)
        log w of every particle of every target.
    alpha : float
        Target survival rate in (0, 1).

    Returns
    -------
    ndarray of shape (K,)
        β per target, in [1e-8, 1]: 1e-8 (the smallest candidate) when even that β
        leaves a survival rate below ``alpha``.
    """
    log_w = log_lik - log_lik.max(axis=1, keepdims=True)
    coarse = np.broadcast_to(_COARSE, (log_w.shape[0], 65))
    lo, hi = _bracket(log_w, coarse, alpha)
    fine = lo[:, None] + (hi - lo)[:, None] * _FINE
    lo, _ = _bracket(log_w, fine, alpha)
    return lo


def _bracket(log_w: NDArray[np.float64], betas: NDArray[np.float64],
             alpha: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per row of candidates ``betas`` (K, G), increasing: the last β of the leading run
    whose survival rate is >= alpha, and the next candidate (the same β at the end)."""
    w = np.exp(betas[:, :, None] * log_w[:, None, :])
    rate = w.sum(axis=2) ** 2 / (log_w.shape[1] * (w * w).sum(axis=2))
    ok = rate >= alpha
    ok[:, 0] = True  # the smallest candidate is the floor of β
    last = np.where(ok.all(axis=1), ok.shape[1] - 1, np.argmin(ok, axis=1) - 1)
    rows = np.arange(betas.shape[0])
    return betas[rows, last], betas[rows, np.minimum(last + 1, ok.shape[1] - 1)]


def weighted_estimate(particles: NDArray[np.float64], weights: NDArray[np.float64],
                      radius: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """Weighted mean (K, 2) of each target's particles (K, N, 2) with weights (K, N).

    With ``radius`` (K,), only the particles within that distance of the target's heaviest
    particle count (the weighted mean of its mode), so that a set split between the target
    and a distractor is not averaged into the empty space between them.

    Parameters
    ----------
    particles : ndarray of float64, shape (K, N, 2)
        Particle centres (x, y) of each target, in px.
    weights : ndarray of float64, shape (K, N)
        Normalised weights (each row sums to 1).
    radius : ndarray of float64, shape (K,), optional
        Radius in px of each target's mode around its heaviest particle; None (the
        default): all particles.

    Returns
    -------
    ndarray of float64, shape (K, 2)
        The weighted mean centre of each target (with ``radius``, the weights of the
        particles within it renormalised).

    Examples
    --------
    >>> x = np.array([[[0.0, 0.0], [2.0, 0.0], [40.0, 0.0]]])
    >>> w = np.array([[0.4, 0.3, 0.3]])
    >>> weighted_estimate(x, w).round(6).tolist()
    [[12.6, 0.0]]
    >>> weighted_estimate(x, w, np.array([5.0])).round(6).tolist()
    [[0.857143, 0.0]]
    """
    if radius is not None:
        best = particles[np.arange(particles.shape[0]), np.argmax(weights, axis=1)]
        gap = particles - best[:, None, :]
        near = np.einsum("knc,knc->kn", gap, gap) <= radius[:, None] ** 2
        weights = weights * near
        weights = weights / weights.sum(axis=1, keepdims=True)
    return np.einsum("kn,knc->kc", weights, particles)


def resample_targets(particles: NDArray[np.float64], weights: NDArray[np.float64],
                     rng: np.random.Generator, method: str) -> NDArray[np.float64]:
    """Resample every target's particles (K, N, D) by its weights (K, N), in one call.

    Each target is a group of the shared resampler (``resample_groups``), resampled
    within itself; returns the new particles (K, N, D).

    Parameters
    ----------
    particles : ndarray of float64, shape (K, N, D)
        Each target's particles (C-contiguous or reshapeable to (K N, D)).
    weights : ndarray of float64, shape (K, N)
        Non-negative weights, a positive sum per row (normalised here).
    rng : numpy.random.Generator
        Source of randomness.
    method : {"multinomial", "systematic", "stratified", "residual"}
        Resampling scheme (``trackers.filters.resampling``).

    Returns
    -------
    ndarray of float64, shape (K, N, D)
        The resampled particles, a new array; row k draws only from target k.

    Raises
    ------
    ValueError
        As ``resample_groups``: an unknown method, negative or non-finite weights, a row
        of zero total weight.
    """
    k, n = weights.shape
    idx = resample_groups(weights.ravel(), np.full(k, n), method=method, rng=rng)
    return particles.reshape(k * n, -1)[idx].reshape(particles.shape)


def check_particles(params: TrackerParams) -> None:
    """Check and store ``n_particles`` (:func:`trackers.params.check_particle_count`),
    ``lam`` (finite, > 0) and ``resampler`` (one of ``RESAMPLERS``) of ``params``.

    Parameters
    ----------
    params : TrackerParams
        A dataclass with fields ``n_particles``, ``lam`` and ``resampler`` (from its
        ``__post_init__``); ``n_particles`` is stored as ``int``, ``lam`` as ``float``.

    Raises
    ------
    ValueError
        One line naming the parameter and its value.
    """
    check_particle_count(params)
    check_number(params, "lam", low=0.0, low_open=True)
    check_choice(params, "resampler", RESAMPLERS)


@documented()
@dataclass(frozen=True)
class AnnealedParams(ColourParams):
    """Parameters of the annealed particle filter.

    ``sigma`` is stored as a float, or as a tuple of ``n_layers`` floats.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "n_particles": ("int", "Particles per target, N, in [1, "
                              "``trackers.params.MAX_PARTICLES``]."),
        "n_layers": ("int", "Annealing layers per frame, M + 1 (each one weighting), in "
                            "[1, ``trackers.annealed.MAX_LAYERS``]."),
        "lam": ("float", "λ of the weighting function exp(−λ d²), finite and > 0. **(open)** "
                         "The KAMS paper gives none; we default to 1000, not the DPS value "
                         "20: on the kams presets the target's window matches its model to "
                         "d ≈ 0–0.02 and the nearest clutter discs to d ≈ 0.03–0.2, so "
                         "λ = 20 weights them within a factor of 2 and the weighted mean "
                         "straddles modes (kams-a, seeds 0–9, runs tracked: annealed 1/10 at "
                         "λ = 20, 7/10 at λ = 1000; kams 6/10 at λ = 20, 10/10 at λ = 400 and "
                         "1000; hybrid 7/10 at λ = 200, 9/10 at λ = 1000)."),
        "sigma": ("float or tuple of float",
                  "**(open)** Noise per layer, in px, finite and >= 0. A sequence gives each "
                  "layer's standard deviation, first layer first (``n_layers`` numbers); a "
                  "number is the first layer's, each later layer multiplying it by "
                  "``sigma_decay`` (noise shrinks as the weighting sharpens, as Deutscher et "
                  "al.'s P_m does). The default 12 px suits the kams presets, whose target "
                  "jumps by about 6–12 px a frame on kams-a (annealed on kams-a, seeds 0–9, "
                  "λ = 1000: 7/10 runs tracked at 12 px, 6/10 at 8 px)."),
        "sigma_decay": ("float", "Ratio between successive layers' noise when ``sigma`` is a "
                                 "number, in (0, 1]."),
        "schedule": (choices(SCHEDULES),
                     "**(open)** How β_m is chosen for the layers m > 0 (β_0 = 1 always): "
                     '"adaptive": per layer and target, the largest β in (0, 1] keeping the '
                     "survival rate (Σ w)² / (N Σ w²) at least ``alpha`` (the PARSEC "
                     "bodytrack rule), but never below the previous layer's β; "
                     '"geometric": fixed β_m = ``beta_ratio`` ** m. **(open, decided)** The '
                     "survival rule alone can lower β from one layer to the next (the new "
                     "layer's particles, moved by noise or mean shift, may be spread over "
                     "worse likelihoods than the last layer's were): on kams-a/b/d, seeds "
                     "0–2, 40 frames, β fell between consecutive adaptive layers in 0–8 % of "
                     'cases for "annealed" and 7–27 % for "kams". An annealing schedule '
                     "sharpens the weighting monotonically (Deutscher et al.: β_M < … < β_0), "
                     "so such a layer keeps the previous β instead; its survival rate is then "
                     'below ``alpha`` (``Estimate.extras["survival"]`` reports it), every '
                     "other adaptive layer's is ``alpha`` to the search's precision (0.5 %)."),
        "alpha": ("float", "Survival rate of the adaptive schedule, in (0, 1)."),
        "beta_ratio": ("float", "Ratio of the geometric schedule, in (0, 1]."),
        "estimate": (choices(ESTIMATES),
                     '**(open)** "mean" (KAMS): the weighted mean of the last layer; "mode": '
                     "the weighted mean of the particles within half the target's smaller "
                     "box side of the heaviest particle, which does not average a set split "
                     "between the target and a distractor (kams on kams-b, seeds 0–9: 4/10 "
                     'runs tracked to the end with "mean", 6/10 with "mode").'),
        "resampler": (choices(RESAMPLERS), "Resampling method (``trackers.filters.resampling``)."),
    }

    n_particles: int = 100
    n_layers: int = 3
    lam: float = 1000.0
    sigma: float | tuple[float, ...] = 12.0
    sigma_decay: float = 0.5
    schedule: str = "adaptive"
    alpha: float = 0.5
    beta_ratio: float = 0.5
    estimate: str = "mean"
    resampler: str = "systematic"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_particles(self)
        check_integer(self, "n_layers", low=1, high=MAX_LAYERS)
        check_choice(self, "schedule", SCHEDULES)
        check_choice(self, "estimate", ESTIMATES)
        check_number(self, "alpha", low=0.0, high=1.0, low_open=True, high_open=True)
        check_number(self, "beta_ratio", low=0.0, high=1.0, low_open=True)
        check_number(self, "sigma_decay", low=0.0, high=1.0, low_open=True)
        sigmas = _layer_sigmas(self.sigma, self.sigma_decay, self.n_layers)
        self._set("sigma", float(self.sigma) if np.ndim(self.sigma) == 0
                  else tuple(sigmas.tolist()))

    def layer_sigmas(self) -> NDArray[np.float64]:
        """Noise standard deviation (n_layers,) of each layer, first layer first.

        Returns
        -------
        ndarray of float64, shape (n_layers,)
            In px: ``sigma * sigma_decay ** j`` for layer j when ``sigma`` is a number,
            else ``sigma`` itself (a new array).
        """
        return _layer_sigmas(self.sigma, self.sigma_decay, self.n_layers)


@documented(extra=RNG_RANDOM)
class AnnealedPF(Tracker):
    """Annealed particle filter on colour histograms, one particle set per target.

    Each frame runs ``n_layers`` annealing layers on every target's N particles. Layer j
    (j = 0 first; the paper's index m = n_layers − 1 − j):

    1. resample N particles by the current weights (at the first layer: the previous
       frame's final weights);
    2. add Gaussian noise B_m of standard deviation ``sigma[j]`` pixels per coordinate
       (KAMS eq. 4), then keep the centres inside the frame;
    3. ``_move`` the particles (the identity here; KAMS runs mean shift);
    4. weight by w^β_m with w = exp(−λ d²) (KAMS eq. 1, 3).

    There is no motion model: particles start where the previous frame ended (KAMS §2).
    The estimate is the weighted mean of the last layer (β_0 = 1), or of its main mode
    (``estimate``). With one layer this is
    the bootstrap (SIR) filter with random-walk noise ``sigma``.

    The parameters are the fields of ``AnnealedParams``, and ``rng``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    particles : ndarray of shape (N, K, 2)
        Particle centres after the last step.
    weights : ndarray of shape (N, K)
        Their normalised weights of the last layer (each column sums to 1).

    Notes
    -----
    ``Estimate.extras``: ``confidence`` (K,) = 1 − d at the estimate; ``beta`` (K, n_layers)
    the β used per layer, first layer first (non-decreasing along a row, last column 1);
    ``survival`` (K, n_layers) the survival rate 1 / (N Σ w²) of the normalised weights w
    each layer resampled by (or, for the last layer, returned).

    Examples
    --------
    >>> import trackers
    >>> tracker = trackers.make("annealed", n_particles=100, n_layers=3, rng=0)
    """

    name = "annealed"
    Params = AnnealedParams

    def _configure(self, params: AnnealedParams) -> None:
        self.sigmas = params.layer_sigmas()

    @property
    def particles(self) -> NDArray[np.float64]:
        """Particle centres (N, K, 2) after the last step (a view of the object-major sets)."""
        return self._sets.swapaxes(0, 1)

    @property
    def weights(self) -> NDArray[np.float64]:
        """Normalised weights (N, K) of the last layer; each column sums to 1."""
        return self._set_weights.swapaxes(0, 1)

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        p = self.params
        self.model = colour_model(frame, boxes, p, lam=p.lam)
        self.sizes = boxes[:, 2:4].copy()
        centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]
        # Object-major sets (K, N, 2) and weights (K, N) (``trackers.meanshift``).
        self._sets = np.repeat(centres[:, None, :], p.n_particles, axis=1)
        self._set_weights = np.full((self.n_targets, p.n_particles), 1.0 / p.n_particles)

    def _move(self, obs: FrameObservation, sets: NDArray[np.float64]) -> None:
        """Move the per-object sets (K, N, 2) in place after a layer's noise; the annealed
        PF does not."""

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        p = self.params
        obs = self.model.observe(frame)
        x, w = self._sets, self._set_weights
        betas = np.empty((self.n_targets, p.n_layers))
        survival = np.empty((self.n_targets, p.n_layers))
        floor = np.zeros(self.n_targets)
        for j in range(p.n_layers):
            m = p.n_layers - 1 - j
            x = resample_targets(x, w, self.rng, p.resampler)
            x += self.sigmas[j] * self.rng.standard_normal(x.shape)
            keep_inside(x, frame.shape)
            self._move(obs, x)
            log_lik = set_log_likelihoods(obs, x, self.sizes)
            betas[:, j] = floor = self._beta(log_lik, m, floor)
            w = normalised_weights(betas[:, j, None] * log_lik)
            survival[:, j] = 1.0 / (p.n_particles * (w * w).sum(axis=1))
        self._sets, self._set_weights = x, w
        radius = 0.5 * self.sizes.min(axis=1) if p.estimate == "mode" else None
        centres = weighted_estimate(x, w, radius)[:, None, :]
        confidence = 1.0 - set_distances(obs, centres, self.sizes)[:, 0]
        return Estimate(window_boxes(centres, self.sizes)[:, 0],
                        {"confidence": confidence, "beta": betas, "survival": survival})

    def _beta(self, log_lik: NDArray[np.float64], m: int,
              floor: NDArray[np.float64]) -> NDArray[np.float64]:
        """β_m (K,) of layer m for the current log-likelihoods (K, N), at least the
        previous layer's β ``floor`` (K,)."""
        k = log_lik.shape[0]
        if m == 0:
            return np.ones(k)
        if self.params.schedule == "geometric":
            return np.full(k, self.params.beta_ratio**m)
        return np.maximum(survival_beta(log_lik, self.params.alpha), floor)


def _layer_sigmas(sigma: float | Sequence[float], decay: float,
                  n_layers: int) -> NDArray[np.float64]:
    """Noise standard deviation (n_layers,) of each layer, first layer first."""
    try:
        # True was read as 1 px, and "12" (or ("12", "6", "3")) as 12 px: numbers only.
        if np.asarray(sigma).dtype.kind in "bUS":
            raise TypeError(sigma)
        if np.ndim(sigma) == 0:
            sigmas = float(sigma) * decay ** np.arange(n_layers)  # type: ignore[arg-type]
        else:
            sigmas = np.asarray(sigma, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"sigma must be a number or {n_layers} numbers (one per layer), "
                         f"got {sigma!r}") from None
    if np.ndim(sigma) != 0:
        if sigmas.shape != (n_layers,):
            raise ValueError(f"sigma must be a number or {n_layers} numbers (one per layer), "
                             f"got {np.ravel(sigma).tolist()}")
    if not np.all(np.isfinite(sigmas) & (sigmas >= 0.0)):
        raise ValueError(f"sigma must be finite and >= 0, got {sigma!r}")
    return sigmas
