"""Kernel mean-shift tracker (Comaniciu, Ramesh & Meer 2003) and the colour model it shares
with the KAMS family (``annealed``, ``hybrid``, ``sok``, ``kams``).

Every tracker of the family describes a target by the kernel-weighted RGB histogram of its
initial box (KAMS §2: 10x10x10 bins, linear cone kernel over the inscribed ellipse) and
tracks its centre only: box sizes stay those of ``init``. The colour model is the shared
``trackers.models.observation.ColourModel`` ("rgb", one part; ``colour_model``), whose
``FrameObservation`` scores windows and runs mean shift, as for the DPS filters.

Per-object sets (the family's internal layout; ``trackers.base`` gives the convention):
the samplers of the family run K independent sets of N particles and compute on
object-major arrays, centres (K, N, 2) and weights (K, N), because their reductions over
the particles (survival rate, β search, estimate) and their noise draws run in that
memory order; the trackers' public ``particles`` (N, K, 2) and ``weights`` (N, K) are
views of them with the axes swapped. The ``set_*`` functions are the boundary between the
object-major sets and the observation model's flat rows (P = K N boxes, object index per
row).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, Tracker
from trackers.kernels.meanshift import MEAN_SHIFT_KERNELS, MeanShiftResult
from trackers.models.observation import ColourModel, FrameObservation
from trackers.params import RNG_UNUSED, FieldDoc, TrackerParams, choices, documented

__all__ = [
    "ColourParams",
    "MeanShiftParams",
    "MeanShiftTracker",
    "check_kernel_bins",
    "check_mean_shift",
    "colour_model",
    "keep_inside",
    "set_distances",
    "set_log_likelihoods",
    "set_mean_shift",
    "window_boxes",
]


def colour_model(frame: NDArray[np.uint8], boxes: NDArray[np.float64],
                 params: ColourParams, *, lam: float = 20.0) -> ColourModel:
    """The family's colour model: ``ColourModel("rgb")`` of one part with the templates of
    ``boxes`` (K, 4) in ``frame`` (H, W, 3).

    Parameters
    ----------
    frame : ndarray of uint8, shape (H, W, 3)
        The frame the templates are taken from (RGB).
    boxes : ndarray of float64, shape (K, 4)
        One box [x, y, w, h] per target, in px.
    params : ColourParams
        ``kernel`` and ``bins`` of the model.
    lam : float, default 20.0
        λ of the model's likelihood exp(−λ d²), > 0.

    Returns
    -------
    ColourModel
        The model, its references (K, bins³) set.

    Raises
    ------
    ValueError
        For a ``lam`` that is not a finite number > 0.
    """
    model = ColourModel("rgb", bins=params.bins, n_parts=1, kernel=params.kernel, lam=lam)
    model.set_references(frame, boxes)
    return model


def window_boxes(centres: NDArray[np.float64], sizes: NDArray[np.float64]
                 ) -> NDArray[np.float64]:
    """Boxes (K, N, 4) of per-object sets of centres (K, N, 2), sizes (K, 2) per object.

    Parameters
    ----------
    centres : ndarray of float64, shape (K, N, 2)
        Window centres (x, y) in px, N per object.
    sizes : ndarray of float64, shape (K, 2)
        Window (w, h) of each object, in px.

    Returns
    -------
    ndarray of float64, shape (K, N, 4)
        Boxes [x - w/2, y - h/2, w, h], in px.

    Examples
    --------
    >>> window_boxes(np.array([[[10.0, 20.0]]]), np.array([[4.0, 6.0]])).tolist()
    [[[8.0, 17.0, 4.0, 6.0]]]
    """
    size = np.broadcast_to(sizes[:, None, :], centres.shape)
    return np.concatenate([centres - 0.5 * size, size], axis=-1)


def set_log_likelihoods(obs: FrameObservation, centres: NDArray[np.float64],
                        sizes: NDArray[np.float64]) -> NDArray[np.float64]:
    """log w = −λ d² (K, N) of windows at per-object centres (K, N, 2), in one call.

    Parameters
    ----------
    obs : FrameObservation
        The frame seen through the family's colour model (``ColourModel.observe``).
    centres : ndarray of float64, shape (K, N, 2)
        Window centres (x, y) in px, N per object, object k's windows in row k.
    sizes : ndarray of float64, shape (K, 2)
        Window (w, h) of each object, in px.

    Returns
    -------
    ndarray of float64, shape (K, N)
        −λ d², d the Bhattacharyya distance of each window to its object's template.
    """
    k, n = centres.shape[:2]
    return obs.log_likelihoods(window_boxes(centres, sizes).reshape(k * n, 4),
                               np.repeat(np.arange(k), n)).reshape(k, n)


def set_distances(obs: FrameObservation, centres: NDArray[np.float64],
                  sizes: NDArray[np.float64]) -> NDArray[np.float64]:
    """Bhattacharyya distances (K, N) of windows at per-object centres (K, N, 2).

    Parameters
    ----------
    obs : FrameObservation
        The frame seen through the family's colour model (``ColourModel.observe``).
    centres : ndarray of float64, shape (K, N, 2)
        Window centres (x, y) in px, N per object, object k's windows in row k.
    sizes : ndarray of float64, shape (K, 2)
        Window (w, h) of each object, in px.

    Returns
    -------
    ndarray of float64, shape (K, N)
        Distance d in [0, 1] of each window to its object's template.
    """
    k, n = centres.shape[:2]
    return obs.distances(window_boxes(centres, sizes).reshape(k * n, 4),
                         np.repeat(np.arange(k), n)).reshape(k, n)


def set_mean_shift(obs: FrameObservation, centres: NDArray[np.float64],
                   sizes: NDArray[np.float64], *, max_iter: int, eps: float,
                   which: NDArray[np.integer] | None = None) -> MeanShiftResult:
    """Mean shift from per-object starts (K', N, 2) in one call (``FrameObservation``).

    ``which`` (K',) lists the objects the rows of ``centres`` belong to (default: all K,
    in order); ``sizes`` (K, 2) are every object's window sizes. Returns the converged
    centres (K', N, 2), their Bhattacharyya distances (K', N) and the shifts used (K', N).

    Parameters
    ----------
    obs : FrameObservation
        The frame seen through the family's colour model (one part, a kernel of
        ``MEAN_SHIFT_KERNELS``).
    centres : ndarray of float64, shape (K', N, 2)
        Start centres (x, y) in px, N per row.
    sizes : ndarray of float64, shape (K, 2)
        Window (w, h) of every object, in px.
    max_iter : int
        Largest number of shifts per window.
    eps : float
        Stop when a shift moves the window by less than ``eps`` px.
    which : ndarray of int, shape (K',), optional
        Object index of each row of ``centres``; None (the default): ``arange(K)``.

    Returns
    -------
    MeanShiftResult
        ``centres`` (K', N, 2), ``distances`` (K', N) and ``n_iter`` (K', N).

    Raises
    ------
    ValueError
        From ``FrameObservation.mean_shift``, for a model of several parts or a kernel
        without a mean-shift shadow.
    """
    k, n = centres.shape[:2]
    rows = np.arange(k) if which is None else np.asarray(which)
    res = obs.mean_shift(centres.reshape(k * n, 2), np.repeat(sizes[rows], n, axis=0),
                         np.repeat(rows, n), max_iter=max_iter, eps=eps)
    return MeanShiftResult(res.centres.reshape(k, n, 2), res.distances.reshape(k, n),
                           res.n_iter.reshape(k, n))


def check_kernel_bins(kernel: str, bins: int) -> None:
    """Raise ``ValueError`` for an unknown kernel name or a bin count outside [1, 32].

    Parameters
    ----------
    kernel : str
        A name of ``MEAN_SHIFT_KERNELS`` (``"epanechnikov"``, ``"cone"``).
    bins : int
        Bins per RGB channel, an integer (or integral float) in [1, 32]; not a bool.

    Raises
    ------
    ValueError
        Naming the parameter and its value.
    """
    if not isinstance(kernel, str) or kernel not in MEAN_SHIFT_KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; valid kernels: "
                         f"{', '.join(MEAN_SHIFT_KERNELS)}")
    if not _whole(bins, 1, 32):
        raise ValueError(f"bins must be an integer in [1, 32], got {bins!r}")


def check_mean_shift(max_iter: int, eps: float) -> None:
    """Raise ``ValueError`` for a ``max_iter`` that is not an integer in [0, MAX_ITER] or an
    ``eps`` that is not a finite number >= 0.

    Parameters
    ----------
    max_iter : int
        Mean-shift iterations, an integer (or integral float) in [0, ``MAX_ITER``].
    eps : float
        Stopping shift in px, a finite number >= 0 (not a bool).

    Raises
    ------
    ValueError
        Naming the parameter and its value.
    """
    if not _whole(max_iter, 0, MAX_ITER):
        raise ValueError(f"max_iter must be an integer in [0, {MAX_ITER}], got {max_iter!r}")
    ok = not isinstance(eps, bool) and isinstance(eps, (int, float, np.integer, np.floating))
    if not (ok and np.isfinite(eps) and eps >= 0.0):
        raise ValueError(f"eps must be a finite number >= 0 (pixels), got {eps!r}")


#: Largest ``max_iter`` of a mean-shift search (the papers use 20-50 iterations).
MAX_ITER = 10_000


def _whole(value: object, low: int, high: int) -> bool:
    """Whether ``value`` is an integer (or an integral float) in [low, high]; never raises."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    return bool(np.isfinite(value)) and int(value) == value and low <= value <= high


def keep_inside(centres: NDArray[np.float64], frame_shape: tuple[int, ...]) -> None:
    """Clip centres (..., 2) into the frame in place, so windows never leave it entirely.

    Parameters
    ----------
    centres : ndarray of float64, shape (..., 2)
        Centres (x, y) in px; x is clipped to [0, W] and y to [0, H], in place.
    frame_shape : tuple of int
        Shape of the frame, (H, W, ...).
    """
    np.clip(centres[..., 0], 0.0, frame_shape[1], out=centres[..., 0])
    np.clip(centres[..., 1], 0.0, frame_shape[0], out=centres[..., 1])


@documented()
@dataclass(frozen=True)
class ColourParams(TrackerParams):
    """The colour model's parameters, shared by every tracker of the KAMS family.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "kernel": (choices(MEAN_SHIFT_KERNELS),
                   'Histogram kernel of the target\'s colour model: "cone" (the KAMS paper\'s '
                   'linear kernel over the inscribed ellipse) or "epanechnikov".'),
        "bins": ("int", "Bins per RGB channel, in [1, 32] (KAMS: 10)."),
    }

    kernel: str = "cone"
    bins: int = 10

    def __post_init__(self) -> None:
        check_kernel_bins(self.kernel, self.bins)
        self._set("bins", int(self.bins))


@documented()
@dataclass(frozen=True)
class MeanShiftParams(ColourParams):
    """Parameters of the mean-shift tracker: ``ColourParams`` and the mean-shift loop.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "max_iter": ("int", "Maximum mean-shift iterations per start point and frame, in "
                            "[0, ``trackers.meanshift.MAX_ITER``] (Comaniciu et al. use 20)."),
        "eps": ("float", "Stop when a shift moves the window by less than ``eps`` px; finite "
                         "and >= 0."),
    }

    max_iter: int = 20
    eps: float = 0.5

    def __post_init__(self) -> None:
        super().__post_init__()
        check_mean_shift(self.max_iter, self.eps)
        self._set("max_iter", int(self.max_iter))
        self._set("eps", float(self.eps))


@documented(extra=RNG_UNUSED)
class MeanShiftTracker(Tracker):
    """Kernel mean-shift tracker: one window per target climbs the Bhattacharyya coefficient.

    Each frame every target's window starts at the previous estimate and shifts by
    Comaniciu et al.'s re-weighting (``trackers.kernels.meanshift``) until it converges;
    all targets run in one compiled call. Deterministic: ``rng`` is accepted for the common
    protocol and not used.

    The parameters are the fields of ``MeanShiftParams``, and ``rng``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    centres : ndarray of shape (K, 2)
        The targets' window centres (x, y) after the last step, in px.

    Notes
    -----
    ``Estimate.extras``: ``confidence`` (K,) = 1 − Bhattacharyya distance at the estimate
    (SOK's C_t, KAMS eq. 8) and ``n_iter`` (K,) mean-shift iterations used.

    Examples
    --------
    >>> import trackers
    >>> tracker = trackers.make("meanshift", max_iter=20)
    """

    name = "meanshift"
    Params = MeanShiftParams

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self.model = colour_model(frame, boxes, self.params)
        self.sizes = boxes[:, 2:4].copy()
        self.centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        p = self.params
        res = set_mean_shift(self.model.observe(frame), self.centres[:, None, :], self.sizes,
                             max_iter=p.max_iter, eps=p.eps)
        self.centres = res.centres[:, 0]
        keep_inside(self.centres, frame.shape)
        return Estimate(window_boxes(self.centres[:, None, :], self.sizes)[:, 0],
                        {"confidence": 1.0 - res.distances[:, 0], "n_iter": res.n_iter[:, 0]})
