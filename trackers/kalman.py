"""Plain Kalman tracker: template matching per object, no occlusion reasoning.

The baseline of the SHM paper (§5): every object is measured independently by template
matching (mean squared difference, ``trackers.models.layered``) on the unmasked frame, and its
position is filtered by a Kalman filter (``trackers.filters.kalman``). Under heavy occlusion the
occluded object's template matches the occluder or the clutter, and the filter follows.

Shared with the SHM trackers (``trackers.shm``):

- Motion (``motion``): ``"cv"`` constant velocity with white acceleration noise of std
  ``process_std`` px/frame², or ``"ar2"`` (``a1``, ``a2``, noise std ``process_std``).
- Measurement noise (**open**; the paper says only "proportional to the squared
  difference mean", §3.1): ``R_m = (r_floor + r_gain · e_m) I₂`` px², with ``e_m`` the
  match's mean squared difference per channel (intensity²). The floor keeps a perfect
  match (e = 0) from freezing the filter.
- A missed measurement (the object left the frame or is hidden) is ``update(None)`` for
  that object: the filter keeps predicting.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, Tracker
from trackers.filters.kalman import KalmanFilter, MotionModel
from trackers.models.dynamics import check_ar2_coefficients
from trackers.models.layered import SUPPORTS, LayeredMatcher, check_matcher_params
from trackers.params import (
    RNG_UNUSED,
    FieldDoc,
    TrackerParams,
    check_choice,
    check_integer,
    check_number,
    choices,
    documented,
)

__all__ = ["MOTIONS", "KalmanParams", "KalmanTracker"]

MOTIONS = ("cv", "ar2")

#: Upper bound of the motion noise stds (pixels): far above any use, and low enough that no
#: accepted value overflows the filter. The AR2 coefficients must not be explosive
#: (``trackers.models.dynamics.check_ar2_coefficients``, as for the particle trackers):
#: a bound of 100 on each still let the covariance grow without bound (NaN boxes).
MAX_STD = 1e6

#: Bounds of the measurement variance (px²): ``r_floor`` in [MIN_R_FLOOR, MAX_R] and
#: ``r_gain`` in [0, MAX_R], so that R = r_floor + r_gain e (e <= 255²) is at most about
#: 6.5e16 px² and the innovation covariance S >= r_floor is invertible. r_gain = 1e308
#: overflowed R (NaN boxes at the first frame); r_floor = 1e-310 left S singular (NaN
#: boxes, and a LinAlgError in "shm-fast", at the second). Both are far beyond any use:
#: 1e-6 px² is a measurement std of 0.001 px, 1e12 px² one of 1e6 px.
MIN_R_FLOOR = 1e-6
MAX_R = MAX_STD**2


def motion_model(
    motion: str, process_std: float, a1: float, a2: float, velocity_std: float
) -> MotionModel:
    """The per-object model named by ``motion`` (``"cv"`` or ``"ar2"``).

    Raises
    ------
    ValueError
        For an unknown ``motion`` or a bad parameter value.
    """
    if motion == "cv":
        return MotionModel.constant_velocity(accel_std=process_std, velocity_std=velocity_std)
    if motion == "ar2":
        return MotionModel.ar2(a1=a1, a2=a2, noise_std=process_std, velocity_std=velocity_std)
    raise ValueError(f"unknown motion {motion!r}; valid: {', '.join(MOTIONS)}")


def measurement_cov(mse: NDArray[np.float64], r_gain: float, r_floor: float) -> NDArray[np.float64]:
    """``R = (r_floor + r_gain e) I₂`` for every match, shape (..., 2, 2) from (...,).

    A missed match (NaN) gets ``r_floor``; its measurement is skipped anyway.
    """
    var = r_floor + r_gain * np.nan_to_num(mse, nan=0.0)
    return var[..., None, None] * np.eye(2)


def boxes_at(centres: NDArray[np.float64], sizes: NDArray[np.float64]) -> NDArray[np.float64]:
    """Boxes (K, 4) of sizes (K, 2) = (w, h) centred at ``centres`` (K, 2)."""
    return np.concatenate([centres - sizes / 2, sizes], axis=1)


@documented()
@dataclass(frozen=True)
class KalmanParams(TrackerParams):
    """Motion, measurement noise and matching: the parameters of the Kalman tracker and of
    the SHM trackers (``trackers.shm``).

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "motion": (choices(MOTIONS),
                   'Motion model: "cv" constant velocity, "ar2" AR2 (``a1``, ``a2``); see '
                   "the ``trackers.kalman`` module docstring."),
        "process_std": ("float", "Process noise std: acceleration (cv) or AR2 noise, "
                                 "px/frame², in [0, ``trackers.kalman.MAX_STD``]."),
        "a1": ("float", "AR2 coefficient A1 (used by ``motion=\"ar2\"`` only, checked "
                        "whatever the motion); with ``a2``, not explosive: |a2| <= 1 and "
                        "|a1| <= 1 − a2 (``trackers.models.dynamics.check_ar2_coefficients``, "
                        "as for the particle trackers)."),
        "a2": ("float", "AR2 coefficient A2 (see ``a1``)."),
        "velocity_std": ("float", "Initial velocity std, px/frame (objects start at rest), "
                                  "in (0, ``trackers.kalman.MAX_STD``]."),
        "r_gain": ("float", "Measurement variance per unit of mean squared difference, "
                            "px²/intensity², in [0, ``trackers.kalman.MAX_R``]."),
        "r_floor": ("float", "Smallest measurement variance, px², in "
                             "[``trackers.kalman.MIN_R_FLOOR``, ``trackers.kalman.MAX_R``]."),
        "search_radius": ("int", "Search window half-size around the predicted position, px, "
                                 "in [1, 200]."),
        "step": ("int", "Coarse-to-fine search stride, in [1, 8]; 1 is exhaustive. The coarse "
                        "grid of the default 2 is safe because of the blur (σ = 2 px smooths "
                        "textures below the grid's Nyquist limit; measured on "
                        "``shm-crossing``: the same errors as exhaustive search, about 2.5x "
                        "faster); with ``blur=0`` on fine textures use 1."),
        "min_visible": ("float", "Fraction of the template that must be compared for a match "
                                 "to count, in (0, 1]."),
        "support": (choices(SUPPORTS),
                    "Template support (``trackers.models.layered``); the ellipse inscribed in "
                    "the box fits round objects and keeps the background corners out of the "
                    "match."),
        "blur": ("float", "Gaussian pre-smoothing of frames and templates, std in px, in "
                          "[0, 20] (0 = none)."),
    }

    motion: str = "cv"
    process_std: float = 1.5
    a1: float = 2.0
    a2: float = -1.0
    velocity_std: float = 5.0
    r_gain: float = 0.01
    r_floor: float = 0.5
    search_radius: int = 12
    step: int = 2
    min_visible: float = 0.25
    support: str = "ellipse"
    blur: float = 2.0

    def __post_init__(self) -> None:
        check_choice(self, "motion", MOTIONS)
        # Bounded so that no accepted value overflows (1e300 did, in the squared noise).
        check_number(self, "process_std", low=0.0, high=MAX_STD)
        a1, a2 = check_ar2_coefficients(self.a1, self.a2)
        self._set("a1", a1)
        self._set("a2", a2)
        check_number(self, "velocity_std", low=0.0, low_open=True, high=MAX_STD)
        check_number(self, "r_gain", low=0.0, high=MAX_R)
        check_number(self, "r_floor", low=MIN_R_FLOOR, high=MAX_R)
        # Integral floats (12.0, as --param may give them) are stored as int first.
        check_integer(self, "search_radius", low=1, high=200)
        check_integer(self, "step", low=1, high=8)
        check_matcher_params(self.search_radius, self.step, self.min_visible, self.support,
                             self.blur)

    def motion_model(self) -> MotionModel:
        """The per-object motion model these parameters name.

        Returns
        -------
        MotionModel
            ``MotionModel.constant_velocity(accel_std=process_std, velocity_std=...)``
            for ``motion="cv"``, ``MotionModel.ar2(a1=..., a2=..., noise_std=process_std,
            velocity_std=...)`` for ``"ar2"``; state dimension 4, ``position_std`` 1 px.
        """
        return motion_model(self.motion, self.process_std, self.a1, self.a2,
                            self.velocity_std)

    def matcher_params(self) -> dict[str, Any]:
        """Keyword arguments of ``LayeredMatcher``.

        Returns
        -------
        dict of str to Any
            ``search_radius``, ``step``, ``min_visible``, ``support`` and ``blur``, as
            stored in these parameters.
        """
        return dict(search_radius=self.search_radius, step=self.step,
                    min_visible=self.min_visible, support=self.support, blur=self.blur)


@documented(extra=RNG_UNUSED)
class KalmanTracker(Tracker):
    """One Kalman filter per object on plain (unmasked) template-matching measurements.

    The parameters are the fields of ``KalmanParams``, and ``rng``.

    Parameters
    ----------
    {parameters}

    Notes
    -----
    ``Estimate.extras``: ``mse`` (K,), the mean squared difference per channel of each
    object's match (NaN if missed).

    Examples
    --------
    >>> import trackers
    >>> tracker = trackers.make("kalman", search_radius=12)
    """

    name = "kalman"
    Params = KalmanParams

    def _configure(self, params: KalmanParams) -> None:
        self.model = params.motion_model()
        self._matcher_params = params.matcher_params()

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self.matcher = LayeredMatcher(frame, boxes, **self._matcher_params)
        self._sizes = boxes[:, 2:].copy()
        self._origin = boxes[:, :2] + boxes[:, 2:] / 2
        k = boxes.shape[0]
        m = self.model
        # The state is the displacement from the first centre (the AR2 mean,
        # docs/algorithms.md §1.1).
        self.kf = KalmanFilter(
            np.zeros((k, m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) * self.params.r_floor
        )
        self._identity = np.arange(k, dtype=np.int64)[None, :]

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        self.kf.predict()
        predicted = self._origin + self.kf.x[:, :2]
        meas = self.matcher.measure(frame, predicted, self._identity, masking=False)
        z = meas.centres[0] - self._origin
        r = measurement_cov(meas.mse[0], self.params.r_gain, self.params.r_floor)
        self.kf.update(z, R=r)
        centres = self._origin + self.kf.x[:, :2]
        return Estimate(boxes=boxes_at(centres, self._sizes), extras={"mse": meas.mse[0].copy()})
