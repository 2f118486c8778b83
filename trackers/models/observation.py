"""Observation models: the protocol the particle filters score boxes with, and its models.

The protocol (``ObservationModel``)
-----------------------------------
The particle filters (``condensation``, ``joint-pf``, ``ps``, ``dps``) take their
observation model as the keyword ``observation`` (default None: the colour-histogram
``ColourModel`` built from ``lam``, ``model``, ``bins``, ``n_parts``, ``kernel``). Any object
with these two methods will do:

``set_references(frame, boxes) -> None``
    Called once by ``init`` with the first frame (H, W, 3) uint8 and the initial boxes
    (K, 4) [x, y, w, h], float64, one per object, in the tracker's object order
    (object k is row k). A model learns its templates here, or only resets itself.
``observe(frame) -> FrameLikelihood``
    Called exactly once per ``step``, in frame order (first for the frame after the
    init frame), with that frame (H, W, 3) uint8, before any box of the frame is scored.
    The returned object has one method:

    ``log_likelihoods(boxes, objects) -> ndarray of shape (P,)``
        ``boxes`` (P, 4) float64 candidate boxes [x, y, w, h] (any position, possibly
        outside the frame; w, h > 0), ``objects`` (P,) int64 the object index k of each
        box. Returns log p(Z_t | X_k = box), natural log, finite (use a large negative
        number, not -inf, for "impossible"). Only differences matter: a constant that
        depends on the frame and the object but not on the box cancels in every filter.
        A filter calls it once per sampling stage with every candidate of that stage:
        P = N K (all objects of all particles; condensation, joint-pf) or P = N (one
        object per particle; each PS/DPS stage, where under DPS different particles
        place different objects). For a set of shape (N, K, 4), pass
        ``boxes.reshape(-1, 4)`` with ``objects = np.tile(np.arange(K), N)`` and reshape
        the result to (N, K).

It must be deterministic given the frames (the filters own all randomness). A Gaussian
position likelihood p(Z_t | X_k) = N(c(X_k); z_{t,k}, R), with c the box centre and
z_{t,k} a measured centre, is ``PositionModel``::

    z = ...                                           # (T, K, 2) measured centres
    tracker = trackers.make("dps", observation=PositionModel(z, np.eye(2) * 4.0))

Colour-histogram models (``ColourModel``)
-----------------------------------------
A ``ColourModel`` turns a frame into a bin-index image once (``ColourModel.observe``),
then scores any number of candidate boxes of any of the tracked objects in one compiled
call (``FrameObservation.distances`` / ``log_likelihoods``; the likelihood is exp(−λ d²),
docs/algorithms.md §2.2)::

    model = ColourModel("hsv", lam=20.0)
    model.set_references(frame0, boxes0)            # (K, 4): one template per object
    obs = model.observe(frame)                       # quantises the frame once
    ll = obs.log_likelihoods(boxes, objects)         # (P, 4), (P,) -> (P,) = −λ d²

Two models:

- ``"rgb"``: 10x10x10 RGB histogram (``bins`` per channel) weighted by the KAMS cone
  kernel, one part (KAMS §2).
- ``"hsv"``: the HSV histogram of Pérez et al. 2002 used by DPS §3.2, ``bins`` × ``bins``
  hue–saturation bins plus ``bins`` value-only bins, with ``n_parts`` = 2 spatial
  components (upper and lower halves). **(open)** DPS does not give its bin counts or
  kernel; we take 10 bins per channel (as KAMS does for RGB) and the Epanechnikov kernel
  (Comaniciu et al.): on the dps-synthetic scenes it keeps more targets than the plain
  (uniform) region histogram, whose box corners are mostly background. All are
  parameters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from trackers.kernels.histogram import (
    DEFAULT_BOX_LEVELS,
    KERNELS,
    PreparedReferences,
    box_kernel_levels,
    hsv_n_bins,
    prepare_references,
    prepared_distances,
    quantize_hsv,
    quantize_rgb,
    region_histograms,
)
from trackers.kernels.meanshift import MEAN_SHIFT_KERNELS, MeanShiftResult, mean_shift
from trackers.kernels.quantize import _is_integer, _is_number

__all__ = [
    "MAX_HISTOGRAM_LENGTH",
    "MAX_PARTS",
    "MODELS",
    "ColourModel",
    "FrameLikelihood",
    "FrameObservation",
    "ObservationModel",
    "PositionModel",
]


@runtime_checkable
class FrameLikelihood(Protocol):
    """One frame seen by an observation model (module docstring: the protocol).

    Parameters
    ----------
    *args, **kwargs : Any
        None accepted: ``typing.Protocol`` refuses to instantiate a protocol (TypeError);
        it is checked with ``isinstance``.
    """

    def log_likelihoods(self, boxes: NDArray[np.floating], objects: NDArray[np.integer]
                        ) -> NDArray[np.float64]:
        """log p(Z | X) (P,) of boxes (P, 4) [x, y, w, h] for their objects (P,).

        Parameters
        ----------
        boxes : ndarray of float64, shape (P, 4)
            Candidate boxes [x, y, w, h] in px (any position, possibly outside the frame;
            w, h > 0).
        objects : ndarray of int64, shape (P,)
            The object index k of each box (row k of the ``set_references`` boxes).

        Returns
        -------
        ndarray of float64, shape (P,)
            log p(Z | X_k = box), natural log, finite; only differences between boxes of
            one object matter.
        """
        ...


@runtime_checkable
class ObservationModel(Protocol):
    """What the particle filters' ``observation`` keyword takes (module docstring).

    Parameters
    ----------
    *args, **kwargs : Any
        None accepted: ``typing.Protocol`` refuses to instantiate a protocol (TypeError);
        it is checked with ``isinstance``.
    """

    def set_references(self, frame: NDArray[np.uint8], boxes: NDArray[np.floating]) -> None:
        """Initialise on the first frame (H, W, 3) with the objects' boxes (K, 4).

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            The first frame, RGB.
        boxes : ndarray of float64, shape (K, 4)
            Initial box [x, y, w, h] of each object, in px, in the tracker's object order.
        """
        ...

    def observe(self, frame: NDArray[np.uint8]) -> FrameLikelihood:
        """See frame (H, W, 3) of the current step; score its boxes with the result.

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            The frame of the current step, RGB; called once per step, in frame order.

        Returns
        -------
        FrameLikelihood
            Whose ``log_likelihoods(boxes, objects)`` scores that frame's boxes.
        """
        ...

#: Largest ``n_parts``, as ``bins``: a band carries colour only while at least a pixel row
#: tall, so more bands only pay for boxes over 256 px tall. It was unbounded here, and
#: ``ParticleParams`` took up to 10⁶ (880 MB per "hsv" box histogram).
MAX_PARTS = 256

#: Largest histogram length ``n_parts * n_bins`` (128 MiB of float64): that of the largest
#: one-part model, "rgb" with 256 bins per channel.
MAX_HISTOGRAM_LENGTH = 256**3

#: Observation model names and their default (n_parts, kernel).
MODELS: dict[str, tuple[int, str]] = {
    "hsv": (2, "epanechnikov"),
    "rgb": (1, "cone"),
}


class ColourModel:
    """A kernel-weighted colour-histogram model with Bhattacharyya likelihood.

    Parameters
    ----------
    kind : {"hsv", "rgb"}
        Colour space and quantisation (module docstring).
    bins : int, optional
        Bins per channel (1–256).
    n_parts : int or None, optional
        Horizontal bands per region (spatial components), in [1, :data:`MAX_PARTS`], with
        ``n_parts * n_bins`` at most :data:`MAX_HISTOGRAM_LENGTH`; None takes the model's
        default (2 for "hsv", 1 for "rgb").
    kernel : {"uniform", "epanechnikov", "cone", "box"} or None, optional
        Kernel profile weighting the pixels of a region; None takes the model's default
        ("epanechnikov" for "hsv", "cone" for "rgb"). "box" is the nested-rectangle step
        approximation of the Epanechnikov profile, which an integral histogram computes
        exactly in O(levels × bins) per box (``trackers.kernels.histogram``).
    box_levels : int, optional
        Levels L of the "box" kernel, in [1, 16] (ignored by the other kernels).
    lam : float, optional
        λ of the likelihood p(Z | X) ∝ exp(−λ d²) (docs/algorithms.md §2.2), > 0.
    s_min, v_min : float, optional
        Saturation and value thresholds of the "hsv" model (fractions of the range).

    Raises
    ------
    ValueError
        For a bad value, naming the parameter: an unknown ``kind`` or ``kernel``, or a
        number out of its range (``n_parts`` above :data:`MAX_PARTS`, or a histogram
        longer than :data:`MAX_HISTOGRAM_LENGTH`, included).

    Attributes
    ----------
    n_bins : int
        Colour bins of one part.
    dim : int
        Length of a histogram, ``n_parts * n_bins``.
    references : ndarray of shape (K, dim) or None
        Reference histograms, one per object, after ``set_references``.

    Examples
    --------
    >>> frame = np.zeros((40, 40, 3), dtype=np.uint8); frame[10:20, 10:20] = (255, 0, 0)
    >>> model = ColourModel("rgb", lam=20.0)
    >>> model.set_references(frame, np.array([[10.0, 10.0, 10.0, 10.0]]))
    >>> obs = model.observe(frame)
    >>> np.round(obs.distances(np.array([[10.0, 10.0, 10.0, 10.0]]), np.array([0])), 6)
    array([0.])
    """

    def __init__(
        self,
        kind: str = "hsv",
        *,
        bins: int = 10,
        n_parts: int | None = None,
        kernel: str | None = None,
        lam: float = 20.0,
        s_min: float = 0.1,
        v_min: float = 0.2,
        box_levels: int = DEFAULT_BOX_LEVELS,
    ) -> None:
        if not isinstance(kind, str) or kind not in MODELS:
            raise ValueError(f"unknown observation model {kind!r}; valid: {', '.join(MODELS)}")
        default_parts, default_kernel = MODELS[kind]
        n_parts = default_parts if n_parts is None else n_parts
        kernel = default_kernel if kernel is None else kernel
        # Numbers only, checked without converting: None, text and NaN were TypeErrors or
        # int()'s own message, and True was one bin.
        if not (_is_integer(bins) and 1 <= bins <= 256):
            raise ValueError(f"bins must be an integer in [1, 256], got {bins!r}")
        if not (_is_integer(n_parts) and n_parts >= 1):
            raise ValueError(f"n_parts must be a positive integer, got {n_parts!r}")
        if n_parts > MAX_PARTS:
            raise ValueError(f"n_parts must be an integer in [1, {MAX_PARTS}], got {n_parts!r}")
        if not isinstance(kernel, str) or kernel not in KERNELS:
            raise ValueError(f"unknown kernel {kernel!r}; valid: {', '.join(KERNELS)}")
        if not (_is_number(lam) and np.isfinite(lam) and lam > 0):
            raise ValueError(f"lam must be a positive number, got {lam!r}")
        for name, val in (("s_min", s_min), ("v_min", v_min)):
            if not (_is_number(val) and 0.0 <= val <= 1.0):
                raise ValueError(f"{name} must lie in [0, 1], got {val!r}")
        self.kind = kind
        self.bins = int(bins)
        self.n_parts = int(n_parts)
        box_kernel_levels(box_levels)  # validates
        self.kernel = kernel
        self.box_levels = int(box_levels)
        self.lam = float(lam)
        self.s_min = float(s_min)
        self.v_min = float(v_min)
        self.n_bins = hsv_n_bins(self.bins, self.bins, self.bins) if kind == "hsv" else (
            self.bins ** 3)
        self.dim = self.n_parts * self.n_bins
        if self.dim > MAX_HISTOGRAM_LENGTH:
            raise ValueError(f"n_parts={self.n_parts} with bins={self.bins} makes a {kind!r} "
                             f"histogram of {self.dim} bins, more than "
                             f"MAX_HISTOGRAM_LENGTH = {MAX_HISTOGRAM_LENGTH}")
        self._prepared: PreparedReferences | None = None

    def quantize(self, frame: NDArray[np.uint8]) -> NDArray[np.int32]:
        """Bin-index image (H, W) int32 of an RGB frame (H, W, 3) uint8.

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            RGB frame.

        Returns
        -------
        ndarray of int32, shape (H, W)
            Bin index of every pixel, in [0, ``n_bins``): ``quantize_hsv`` with ``bins``
            bins of hue, saturation and value and thresholds ``s_min``, ``v_min`` for
            "hsv", ``quantize_rgb`` with ``bins`` per channel for "rgb"
            (``trackers.kernels.quantize``).

        Raises
        ------
        ValueError
            If ``frame`` is not uint8 of shape (H, W, 3).
        """
        if self.kind == "hsv":
            return quantize_hsv(frame, self.bins, self.bins, self.bins, self.s_min, self.v_min)
        return quantize_rgb(frame, self.bins)

    def histograms(self, frame: NDArray[np.uint8], boxes: NDArray[np.floating]
                   ) -> NDArray[np.float64]:
        """Histograms (P, dim) of ``boxes`` (P, 4) in ``frame`` (H, W, 3).

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            RGB frame (quantised by :meth:`quantize`).
        boxes : ndarray of float, shape (P, 4)
            Boxes [x, y, w, h] in px, finite, w, h > 0; they may leave the frame.

        Returns
        -------
        ndarray of float64, shape (P, dim)
            One kernel-weighted histogram per box, its ``n_parts`` bands of ``n_bins``
            concatenated top to bottom; each row sums to 1
            (``trackers.kernels.histogram.region_histograms``).

        Raises
        ------
        ValueError
            For a bad frame, or boxes of a bad shape, not finite or of non-positive size.
        """
        return region_histograms(self.quantize(frame), boxes, self.n_bins,
                                 KERNELS[self.kernel], self.n_parts,
                                 box_levels=self.box_levels)

    @property
    def references(self) -> NDArray[np.float64] | None:
        """The objects' template histograms (K, dim), or None before ``set_references``."""
        return None if self._prepared is None else self._prepared.refs

    @references.setter
    def references(self, refs: NDArray[np.floating]) -> None:
        if np.shape(refs)[-1:] != (self.dim,):
            raise ValueError(f"references must have shape (K, {self.dim}), got "
                             f"{np.shape(refs)}")
        self._prepared = prepare_references(refs, self.n_parts)

    def set_references(self, frame: NDArray[np.uint8], boxes: NDArray[np.floating]) -> None:
        """Take the histograms of ``boxes`` (K, 4) in ``frame`` as the objects' templates.

        Sets ``references`` (K, dim), replacing any earlier ones.

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            The first frame, RGB.
        boxes : ndarray of float, shape (K, 4)
            Box [x, y, w, h] of each object, in px, finite, w, h > 0.

        Raises
        ------
        ValueError
            As :meth:`histograms`.
        """
        self.references = self.histograms(frame, boxes)

    def observe(self, frame: NDArray[np.uint8]) -> FrameObservation:
        """Quantise ``frame`` (H, W, 3) once; score candidates with the result.

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            RGB frame of the current step.

        Returns
        -------
        FrameObservation
            This model and the frame's bin-index image (H, W) (:meth:`quantize`).

        Raises
        ------
        ValueError
            If ``set_references`` was not called, or for a frame that is not uint8 of
            shape (H, W, 3).
        """
        if self._prepared is None:
            raise ValueError("ColourModel.observe: call set_references() first")
        return FrameObservation(self, self.quantize(frame))


@dataclass
class FrameObservation:
    """One frame seen through a ``ColourModel``: its bin-index image and the templates.

    Attributes
    ----------
    model : ColourModel
        The model (bins, kernel, parts, λ and reference histograms).
    bin_img : ndarray of shape (H, W), int32
        The quantised frame.
    """

    model: ColourModel
    bin_img: NDArray[np.int32]

    def distances(self, boxes: NDArray[np.floating], objects: NDArray[np.integer]
                  ) -> NDArray[np.float64]:
        """Bhattacharyya distance of each box to its object's template, in one call.

        Parameters
        ----------
        boxes : ndarray of shape (P, 4)
            Candidate boxes [x, y, w, h] (any position; w, h > 0).
        objects : ndarray of shape (P,), integer
            Object index (row of ``model.references``) of each box.

        Returns
        -------
        ndarray of shape (P,)
            d in [0, 1].
        """
        m = self.model
        # The bin image is the model's own quantisation of the frame: in range.
        return prepared_distances(self.bin_img, boxes, m._prepared, objects,
                                  KERNELS[m.kernel], box_levels=m.box_levels)

    def log_likelihoods(self, boxes: NDArray[np.floating], objects: NDArray[np.integer]
                        ) -> NDArray[np.float64]:
        """log p(Z | X) = −λ d² of each box (P, 4) for its object (P,); shape (P,).

        Parameters
        ----------
        boxes : ndarray of shape (P, 4)
            Candidate boxes [x, y, w, h] in px (any position; w, h > 0).
        objects : ndarray of shape (P,), integer
            Object index (row of ``model.references``) of each box.

        Returns
        -------
        ndarray of float64, shape (P,)
            −λ d², in [−λ, 0], with d the Bhattacharyya distance of :meth:`distances`.

        Raises
        ------
        ValueError
            As :meth:`distances`: boxes not (P, 4), finite and of positive size, or an
            object index out of range.
        """
        d = self.distances(boxes, objects)
        return -self.model.lam * d * d

    def mean_shift(self, centres: NDArray[np.floating], sizes: NDArray[np.floating],
                   objects: NDArray[np.integer], *, max_iter: int, eps: float
                   ) -> MeanShiftResult:
        """Kernel mean shift of windows towards their objects' templates, in one call.

        Parameters
        ----------
        centres : ndarray of shape (P, 2)
            Start centres (x, y) of the windows, pixels.
        sizes : ndarray of shape (P, 2)
            Window (width, height); the window is the ellipse inscribed in that box.
        objects : ndarray of shape (P,), integer
            Object index (row of ``model.references``) of each window.
        max_iter : int
            Largest number of shifts per window.
        eps : float
            Stop when a shift moves the window by less than ``eps`` pixels.

        Returns
        -------
        MeanShiftResult
            Converged centres (P, 2), their Bhattacharyya distances (P,) and the shifts
            used (P,) (``trackers.kernels.meanshift``).

        Raises
        ------
        ValueError
            For a model of several parts or a kernel mean shift has no shadow for.
        """
        m = self.model
        if m.n_parts != 1 or m.kernel not in MEAN_SHIFT_KERNELS:
            raise ValueError(f"mean shift needs a one-part model with kernel "
                             f"{' or '.join(MEAN_SHIFT_KERNELS)}, got n_parts={m.n_parts}, "
                             f"kernel={m.kernel!r}")
        return mean_shift(self.bin_img, m.references, objects, centres, sizes,
                          kernel=KERNELS[m.kernel], max_iter=max_iter, eps=eps,
                          check_bins=False)


class PositionModel:
    """Gaussian position likelihood p(Z_t | X_k) = N(c(X_k); z_{t,k}, R) of measured centres.

    c(X_k) is the centre (x + w/2, y + h/2) of object k's box; the frame's pixels are not
    looked at. A model for testing the filters' sampling against known likelihoods, and
    the example of a model that is not a colour histogram.

    Parameters
    ----------
    measurements : array_like of shape (T, K, 2)
        z_{t,k}, the measured centre (x, y) of object k at frame t, in pixels; frame 0 is
        the init frame (not scored). NaN: no measurement (a constant log-likelihood).
    cov : array_like of shape (2, 2)
        R, the measurement covariance, px², symmetric positive definite.

    Notes
    -----
    ``set_references`` resets the frame counter; each ``observe`` advances it by one, so
    the t-th ``step`` after ``init`` scores against ``measurements[t]``. Observing more
    than T − 1 frames raises ``ValueError``.

    Examples
    --------
    >>> z = np.array([[[10.0, 10.0]], [[12.0, 10.0]]])         # T = 2, K = 1
    >>> model = PositionModel(z, np.eye(2))
    >>> model.set_references(np.zeros((20, 20, 3), np.uint8), np.array([[8.0, 8, 4, 4]]))
    >>> obs = model.observe(np.zeros((20, 20, 3), np.uint8))
    >>> np.round(obs.log_likelihoods(np.array([[10.0, 8, 4, 4], [8, 8, 4, 4]]),
    ...                              np.array([0, 0])), 3).tolist()
    [-1.838, -3.838]
    """

    def __init__(self, measurements: NDArray[np.floating], cov: NDArray[np.floating]) -> None:
        z = np.asarray(measurements, dtype=np.float64)
        r = np.asarray(cov, dtype=np.float64)
        if z.ndim != 3 or z.shape[2] != 2:
            raise ValueError(f"measurements must have shape (T, K, 2), got {z.shape}")
        if r.shape != (2, 2) or not np.allclose(r, r.T) or not np.all(np.isfinite(r)):
            raise ValueError(f"cov must be a symmetric finite (2, 2) matrix, got {r.tolist()}")
        try:
            chol = np.linalg.cholesky(r)
        except np.linalg.LinAlgError:
            raise ValueError(f"cov must be positive definite, got {r.tolist()}") from None
        self.measurements = z
        self.cov = r
        self._chol_inv = np.linalg.inv(chol)
        self._log_norm = -np.log(2.0 * np.pi) - np.log(np.diag(chol)).sum()
        self._t = 0

    def set_references(self, frame: NDArray[np.uint8], boxes: NDArray[np.floating]) -> None:
        """Reset to frame 0; ``boxes`` (K, 4) must match the measurements' K.

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            The first frame; not looked at.
        boxes : ndarray of float, shape (K, 4)
            Initial boxes [x, y, w, h]; only their number K is used.

        Raises
        ------
        ValueError
            If K differs from the measurements' (``measurements.shape[1]``).
        """
        k = np.shape(boxes)[0]
        if k != self.measurements.shape[1]:
            raise ValueError(f"PositionModel has measurements of {self.measurements.shape[1]} "
                             f"objects, init got {k} boxes")
        self._t = 0

    def observe(self, frame: NDArray[np.uint8]) -> _PositionFrame:
        """The next frame's measurements.

        Advances the frame counter t by one (also when it raises).

        Parameters
        ----------
        frame : ndarray of uint8, shape (H, W, 3)
            The frame of the current step; not looked at.

        Returns
        -------
        FrameLikelihood
            Whose ``log_likelihoods(boxes, objects)`` (P,) is log N(c(box); z_{t,k}, R)
            with ``measurements[t]`` (K, 2); a constant, log N at its mean, for a box whose
            object has a NaN measurement.

        Raises
        ------
        ValueError
            Once t reaches T (more than T − 1 frames observed since ``set_references``).
        """
        self._t += 1
        if self._t >= self.measurements.shape[0]:
            raise ValueError(f"PositionModel: frame {self._t} observed, but measurements "
                             f"hold {self.measurements.shape[0]} frames")
        return _PositionFrame(self, self.measurements[self._t])


@dataclass
class _PositionFrame:
    model: PositionModel
    z: NDArray[np.float64]  # (K, 2)

    def log_likelihoods(self, boxes: NDArray[np.floating], objects: NDArray[np.integer]
                        ) -> NDArray[np.float64]:
        """log N(c(box); z_k, R) (P,) of boxes (P, 4) of objects (P,).

        Parameters
        ----------
        boxes : ndarray of shape (P, 4)
            Candidate boxes [x, y, w, h] in px.
        objects : ndarray of shape (P,), integer
            Object index k of each box, in [0, K).

        Returns
        -------
        ndarray of float64, shape (P,)
            log N(c(box); z_k, R); log N at its mean where z_k is NaN.

        Raises
        ------
        ValueError
            If an object index is not an integer in [0, K) (naming the range given).
        """
        b = np.asarray(boxes, dtype=np.float64)
        idx = np.asarray(objects)
        n_objects = self.z.shape[0]
        # A raw IndexError (or a negative index read from the end) named nothing.
        if idx.size and idx.dtype.kind not in "iu":
            raise ValueError(f"objects must be integers in [0, {n_objects}), got dtype "
                             f"{idx.dtype}")
        if idx.size and (idx.min() < 0 or idx.max() >= n_objects):
            raise ValueError(f"objects must be integers in [0, {n_objects}) (the "
                             f"measurements' objects), got [{idx.min()}, {idx.max()}]")
        centres = b[:, :2] + b[:, 2:4] / 2
        dev = (centres - self.z[idx]) @ self.model._chol_inv.T
        ll = self.model._log_norm - 0.5 * np.einsum("pc,pc->p", dev, dev)
        return np.where(np.isnan(ll), self.model._log_norm, ll)
