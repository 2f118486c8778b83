"""Kernel mean-shift tracker (Comaniciu, Ramesh & Meer 2003) and the colour model it shares
with the KAMS family (``annealed``, ``hybrid``, ``sok``, ``kams``).

Every tracker of the family describes a target by the kernel-weighted RGB histogram of its
initial box (KAMS §2: 10x10x10 bins, linear cone kernel over the inscribed ellipse) and
tracks its centre only: box sizes stay those of ``init``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, Tracker
from trackers.kernels.histogram import KERNELS
from trackers.kernels.meanshift import MEAN_SHIFT_KERNELS, MeanShiftResult, mean_shift
from trackers.models.observation import ColourModel, FrameObservation
from trackers.params import TrackerParams

__all__ = [
    "ColourParams",
    "ColourTargets",
    "MeanShiftParams",
    "MeanShiftTracker",
    "check_kernel_bins",
    "check_mean_shift",
    "keep_inside",
]


class ColourTargets:
    """The targets' colour models (the shared ``ColourModel``, "rgb") plus their window
    sizes, and the batched operations the trackers of the family compose.

    Parameters
    ----------
    frame : ndarray of shape (H, W, 3), uint8
        The first frame.
    boxes : ndarray of shape (K, 4)
        Initial boxes [x, y, w, h]; their histograms become the target models.
    kernel : str
        ``"cone"`` (KAMS linear kernel) or ``"epanechnikov"``.
    bins : int
        Bins per RGB channel (``bins**3`` histogram bins).
    lam : float, optional
        λ of the likelihood exp(−λ d²).

    Raises
    ------
    ValueError
        For an unknown kernel name, a bin count outside [1, 32] or λ <= 0.
    """

    def __init__(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64], *,
                 kernel: str, bins: int, lam: float = 20.0) -> None:
        check_kernel_bins(kernel, bins)
        self.model = ColourModel("rgb", bins=bins, n_parts=1, kernel=kernel, lam=lam)
        self.model.set_references(frame, boxes)
        self.sizes = np.array(boxes[:, 2:4], dtype=np.float64)

    @property
    def n_targets(self) -> int:
        return self.sizes.shape[0]

    def observe(self, frame: NDArray[np.uint8]) -> FrameObservation:
        """The frame quantised once, for every later call on this frame."""
        return self.model.observe(frame)

    def boxes(self, centres: NDArray[np.float64]) -> NDArray[np.float64]:
        """Boxes (K, N, 4) of the targets' sizes at ``centres`` (K, N, 2)."""
        size = np.broadcast_to(self.sizes[:, None, :], centres.shape)
        return np.concatenate([centres - 0.5 * size, size], axis=-1)

    def log_likelihoods(self, obs: FrameObservation,
                        centres: NDArray[np.float64]) -> NDArray[np.float64]:
        """log w = −λ d² (K, N) of windows at ``centres`` (K, N, 2), in one call."""
        k, n = centres.shape[:2]
        return obs.log_likelihoods(self.boxes(centres).reshape(k * n, 4),
                                   np.repeat(np.arange(k), n)).reshape(k, n)

    def distances(self, obs: FrameObservation,
                  centres: NDArray[np.float64]) -> NDArray[np.float64]:
        """Bhattacharyya distances (K, N) of windows at ``centres`` (K, N, 2), one call."""
        k, n = centres.shape[:2]
        return obs.distances(self.boxes(centres).reshape(k * n, 4),
                             np.repeat(np.arange(k), n)).reshape(k, n)

    def shift(self, obs: FrameObservation, centres: NDArray[np.float64], *,
              max_iter: int, eps: float,
              which: NDArray[np.integer] | None = None) -> MeanShiftResult:
        """Mean shift from every start (K', N, 2) in one call.

        ``which`` (K',) lists the targets the rows of ``centres`` belong to (default: all
        K, in order). Returns the converged centres (K', N, 2), their Bhattacharyya
        distances (K', N) and the iterations used (K', N).
        """
        k, n = centres.shape[:2]
        rows = np.arange(k) if which is None else np.asarray(which)
        res = mean_shift(obs.bin_img, self.model.references, np.repeat(rows, n),
                         centres.reshape(k * n, 2), np.repeat(self.sizes[rows], n, axis=0),
                         kernel=KERNELS[self.model.kernel], max_iter=max_iter, eps=eps,
                         check_bins=False)
        return MeanShiftResult(res.centres.reshape(k, n, 2), res.distances.reshape(k, n),
                               res.n_iter.reshape(k, n))


def check_kernel_bins(kernel: str, bins: int) -> None:
    """Raise ``ValueError`` for an unknown kernel name or a bin count outside [1, 32]."""
    if kernel not in MEAN_SHIFT_KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; valid kernels: "
                         f"{', '.join(MEAN_SHIFT_KERNELS)}")
    if int(bins) != bins or not 1 <= bins <= 32:
        raise ValueError(f"bins must be an integer in [1, 32], got {bins!r}")


def check_mean_shift(max_iter: int, eps: float) -> None:
    """Raise ``ValueError`` for a negative or non-integer ``max_iter`` or negative ``eps``."""
    if int(max_iter) != max_iter or max_iter < 0:
        raise ValueError(f"max_iter must be an integer >= 0, got {max_iter!r}")
    if not eps >= 0.0:
        raise ValueError(f"eps must be >= 0 (pixels), got {eps!r}")


def keep_inside(centres: NDArray[np.float64], frame_shape: tuple[int, ...]) -> None:
    """Clip centres (..., 2) into the frame in place, so windows never leave it entirely."""
    np.clip(centres[..., 0], 0.0, frame_shape[1], out=centres[..., 0])
    np.clip(centres[..., 1], 0.0, frame_shape[0], out=centres[..., 1])


@dataclass(frozen=True)
class ColourParams(TrackerParams):
    """The colour model's parameters, shared by every tracker of the KAMS family.

    Parameters
    ----------
    kernel : {"cone", "epanechnikov"}, optional
        Histogram kernel: ``"cone"`` (KAMS linear kernel) or ``"epanechnikov"``.
    bins : int, optional
        Bins per RGB channel, in [1, 32] (KAMS: 10).
    """

    kernel: str = "cone"
    bins: int = 10

    def __post_init__(self) -> None:
        check_kernel_bins(self.kernel, self.bins)
        self._set("bins", int(self.bins))


@dataclass(frozen=True)
class MeanShiftParams(ColourParams):
    """Parameters of the mean-shift tracker: ``ColourParams`` and the mean-shift loop.

    Parameters
    ----------
    max_iter : int, optional
        Maximum mean-shift iterations per start point and frame (Comaniciu et al. use 20).
    eps : float, optional
        Stop when a shift moves the window by less than ``eps`` pixels (>= 0).
    """

    max_iter: int = 20
    eps: float = 0.5

    def __post_init__(self) -> None:
        super().__post_init__()
        check_mean_shift(self.max_iter, self.eps)
        self._set("max_iter", int(self.max_iter))
        self._set("eps", float(self.eps))


class MeanShiftTracker(Tracker):
    """Kernel mean-shift tracker: one window per target climbs the Bhattacharyya coefficient.

    Each frame every target's window starts at the previous estimate and shifts by
    Comaniciu et al.'s re-weighting (``trackers.kernels.meanshift``) until it converges;
    all targets run in one compiled call. Deterministic: ``rng`` is accepted for the common
    protocol and not used.

    Parameters: ``MeanShiftParams`` (kernel, bins, max_iter, eps) as keywords, and
    ``rng`` (unused: the tracker is deterministic).

    Notes
    -----
    ``Estimate.extras``: ``confidence`` (K,) = 1 − Bhattacharyya distance at the estimate
    (SOK's C_t, KAMS eq. 8) and ``n_iter`` (K,) mean-shift iterations used.

    Example
    -------
    >>> import trackers
    >>> tracker = trackers.make("meanshift", max_iter=20)
    """

    name = "meanshift"
    Params = MeanShiftParams

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self.targets = ColourTargets(frame, boxes, kernel=self.kernel, bins=self.bins)
        self.centres = boxes[:, :2] + 0.5 * boxes[:, 2:4]

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        res = self.targets.shift(self.targets.observe(frame), self.centres[:, None, :],
                                 max_iter=self.max_iter, eps=self.eps)
        self.centres = res.centres[:, 0]
        keep_inside(self.centres, frame.shape)
        return Estimate(self.targets.boxes(self.centres[:, None, :])[:, 0],
                        {"confidence": 1.0 - res.distances[:, 0], "n_iter": res.n_iter[:, 0]})
