"""Switching hypothesized measurements (SHM) trackers: positions and depth order.

Wang, Tan & Loe, "Switching hypothesized measurements: a dynamic model with applications
to occlusion adaptive joint tracking" (IJCAI 2007); docs/algorithms.md §4.

Model (§2.2). ``M`` objects, ``L = M!`` depth orderings ``s_t`` (``self.orderings``, each
row nearest first). ``s_t`` is a first-order Markov chain (eq. 1) that stays with
probability ``p_stay`` and otherwise moves uniformly to another ordering (**open**). The
joint state ``x_t`` stacks the objects' motion states (``trackers.filters.kalman.MotionModel``,
constant velocity or AR2), linear Gaussian (eq. 2). Every frame gives ``L`` hypothesized
measurements ``y^j`` with squared-difference means ``e^{j,m}`` (§3.1,
``trackers.models.layered``): under the true ordering ``j``, ``y^j = H x + v`` with
``v ~ N(0, R^j)``, ``R^{j,m} = (r_floor + r_gain e^{j,m}) I₂`` (proportional to ``e``, §3.1,
plus a floor); the other orderings' measurements are uniform (eq. 3), so they cancel.

Evidence of the squared-difference means (§3.3, the "generalised measurement"): under the
true ordering the squared-difference mean follows an exponential density, giving the factor
``exp(−lam E_j / ē)``. Which mean (**open**, parameter ``evidence``):

- ``"union"`` (default): ``E_j = Σ_m n^{j,m} e^{j,m} / Σ_m n^{j,m}``, the mean squared
  difference of the composed layers over every pixel they cover, ``n^{j,m}`` being the
  pixels compared for object m under ordering j. Every covered pixel is scored once under
  each ordering, by the object the ordering puts in front there. With ``ē`` a single
  scale: the moving average of ``min_j E_j``.
- ``"objects"``: the paper's per-object exponentials, ``Σ_m e^{j,m} / ē_m`` with one scale
  per object. Masking removes pixels from the mean of the object behind, so these means
  are taken over different pixel sets under different orderings, which makes it the
  weaker test when appearance varies. Measured on ``shm-crossing`` seeds 0–3 (share of
  overlap frames whose most probable ordering is the true one): with the default
  matching (ellipse support, blur 2) both give 1.00; with box support and no blur,
  ``"union"`` gives 0.82–1.00 and ``"objects"`` 0.41–0.70.

The scales are exponential moving averages (rate ``mse_rate``) of the smallest mean over
orderings — the exponential density's mean under the true ordering — floored at
``mse_floor``; ``lam`` sharpens or flattens the evidence. An object missed under an
ordering (hidden behind the objects in front, or outside the frame) covers no pixel
(``"union"``) or counts as ``e = ē_m`` (``"objects"``); its position measurement is
uniform over the frame.

Because non-overlapping objects give identical measurements under every ordering, the
ordering probabilities then only follow the (symmetric) Markov chain towards equality.

``SHMTracker`` ("shm", §3.2): a Gaussian-sum filter with one Gaussian per ordering. Each
step predicts every Gaussian ``i``, updates it with every ordering's measurement ``j``
(``L²`` Kalman updates, objects processed sequentially as independent blocks), weights
the pair by ``Π_ij P(i) N(y^j; H x̂_i, S_ij)`` (times the ``e`` evidence if ``use_mse``),
and collapses the pairs into one Gaussian per ``j`` by moment matching (GPB2, Murphy
1998). The estimate is the mixture mean.

``FastSHMTracker`` ("shm-fast", §3.3): the measurement noise under the true ordering is
taken as small, so the ordering posterior comes from the ``e`` evidence and the Markov
prior only, and the measurements become a mixture over orderings which is moment-matched
into one measurement per object, ``ŷ_m = Σ_j P(j) y^{j,m}`` with covariance
``Σ_j P(j) (R^{j,m} + (y^{j,m} − ŷ_m)(y^{j,m} − ŷ_m)')`` (``r_gain = 0`` and a small
``r_floor`` give the paper's zero-noise limit), fed to one Kalman filter per object; no
collapsing stage. Approximations (chosen here): the mixture's cross-object covariance is
dropped, and an object whose measurement is missing under orderings of total probability
> 1/2 is a missed measurement; otherwise (measured under at least half, a tie included)
the orderings where it was measured are used.

Cost: ``L`` orderings need up to ``M L`` template searches per frame (``M`` when no objects
are close) and the Gaussian-sum filter ``M L²`` Kalman updates of dimension ``4 M``; more
than 4 objects (24 orderings) is refused. Measured on a 2-core machine under load: two
objects on 360x288 (``shm-crossing``) about 2–3 ms per frame for either tracker; four
objects (two crossing, 30x30 px) about 12 ms per frame for ``shm-fast`` and 70 ms for
``shm`` (576 ordering pairs, state dimension 16).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from trackers.base import Estimate, Tracker
from trackers.filters.kalman import KalmanFilter
from trackers.filters.weights import normalised_weights
from trackers.kalman import KalmanParams, boxes_at, measurement_cov
from trackers.models.layered import LayeredMatcher, orderings
from trackers.params import RNG_UNUSED, FieldDoc, check_choice, check_number, choices, documented

__all__ = [
    "EVIDENCES",
    "FastSHMTracker",
    "FastShmParams",
    "SHMTracker",
    "ShmParams",
    "transition_matrix",
]


def transition_matrix(n_orderings: int, p_stay: float) -> NDArray[np.float64]:
    """Markov transition Π (L, L) of the ordering: stay ``p_stay``, else uniform (eq. 1).

    Parameters
    ----------
    n_orderings : int
        Number of orderings L >= 1.
    p_stay : float
        Probability of keeping the ordering, in [0, 1] (not checked; ignored when L = 1).

    Returns
    -------
    ndarray of float64, shape (L, L)
        Π[i, j] = P(s_t = j | s_{t−1} = i): ``p_stay`` on the diagonal,
        (1 − p_stay) / (L − 1) elsewhere; each row sums to 1.

    Examples
    --------
    >>> transition_matrix(3, 0.8).round(6).tolist()
    [[0.8, 0.1, 0.1], [0.1, 0.8, 0.1], [0.1, 0.1, 0.8]]
    """
    if n_orderings == 1:
        return np.ones((1, 1))
    pi = np.full((n_orderings, n_orderings), (1.0 - p_stay) / (n_orderings - 1))
    np.fill_diagonal(pi, p_stay)
    return pi


EVIDENCES = ("union", "objects")

#: Bounds of the evidence parameters: ``lam`` in [0, MAX_LAM], ``mse_floor`` >=
#: MIN_MSE_FLOOR (intensity²), so that the log evidence −lam Σ e / ē (e <= 255², at most 4
#: objects) stays finite, below about 2.6e17 in magnitude. lam = 1e308 overflowed it (NaN
#: boxes and ordering probabilities on ``shm-crossing``), and so did mse_floor = 5e-324
#: (e / ē = inf after an exact match; times lam = 0 it was NaN). Both are far beyond any
#: use: at lam = 1e6, orderings whose means differ by 1e-4 ē differ in evidence by a
#: factor e^100.
MAX_LAM = 1e6
MIN_MSE_FLOOR = 1e-6


class _OrderingEvidence:
    """Markov prior and squared-difference evidence of the orderings (§2.2, §3.3)."""

    def __init__(
        self, n_orderings: int, p_stay: float, lam: float, rate: float, floor: float, kind: str
    ) -> None:
        self.pi = transition_matrix(n_orderings, p_stay)
        self.log_pi = np.log(np.maximum(self.pi, 1e-300))
        self.lam = lam
        self.rate = rate
        self.floor = floor
        self.kind = kind
        self.scale: NDArray[np.float64] | None = None

    def log_evidence(
        self, mse: NDArray[np.float64], counts: NDArray[np.int64]
    ) -> NDArray[np.float64]:
        """log evidence per ordering, shape (L,), from ``mse`` and ``counts`` (L, M).

        Updates the scales afterwards, so a frame's own matches do not rescale its
        evidence.
        """
        if self.kind == "union":
            n = counts.sum(axis=1)
            sse = (np.nan_to_num(mse) * counts).sum(axis=1)
            e = np.where(n > 0, sse / np.maximum(n, 1), np.nan)[:, None]  # (L, 1)
        else:
            e = mse
        valid = np.isfinite(e)
        best = np.min(np.where(valid, e, np.inf), axis=0)
        seen = np.isfinite(best)
        if self.scale is None:
            self.scale = np.full(e.shape[1], self.floor)
            self.scale[seen] = np.maximum(best[seen], self.floor)
        ratio = np.where(valid, e, self.scale[None, :]) / self.scale[None, :]
        out = -self.lam * ratio.sum(axis=1)
        # The scale is the mean of e under the true ordering: average the best ordering's.
        upd = (1 - self.rate) * self.scale + self.rate * np.where(seen, best, self.scale)
        self.scale = np.maximum(upd, self.floor)
        return out


@documented()
@dataclass(frozen=True)
class FastShmParams(KalmanParams):
    """Parameters of "shm-fast": ``KalmanParams`` and the ordering evidence's.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "p_stay": ("float", "Probability that the depth ordering stays the same from one "
                            "frame to the next, in (0, 1] (**open**). The order cannot be "
                            "observed while the objects are apart and may change then, so "
                            "the belief should relax towards uniform within a few frames (by "
                            "a factor ``(L p_stay − 1) / (L − 1)`` per frame). Measured on "
                            "``shm-crossing`` seeds 0–7: depth-order accuracy 100% for 0.5 to "
                            "0.9; mean ``max |P − 1/L|`` on frames where the targets are "
                            "apart 0.04 at 0.8, 0.11 at 0.9."),
        "lam": ("float", "Sharpness of the squared-difference evidence ``exp(−lam e / ē)``, "
                         "in [0, ``trackers.shm.MAX_LAM``]."),
        "mse_rate": ("float", "Rate of the moving average ``ē`` of the best squared-difference "
                              "mean, in (0, 1]."),
        "mse_floor": ("float", "Smallest ``ē``, intensity², finite and >= ``MIN_MSE_FLOOR`` "
                               "(so exact synthetic matches do not give ē = 0)."),
        "evidence": (choices(EVIDENCES),
                     "Which squared-difference mean is scored (``trackers.shm`` module "
                     "docstring)."),
    }

    p_stay: float = 0.8
    lam: float = 1.0
    mse_rate: float = 0.1
    mse_floor: float = 25.0
    evidence: str = "union"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_choice(self, "evidence", EVIDENCES)
        check_number(self, "p_stay", low=0.0, high=1.0, low_open=True)
        check_number(self, "lam", low=0.0, high=MAX_LAM)
        check_number(self, "mse_rate", low=0.0, high=1.0, low_open=True)
        check_number(self, "mse_floor", low=MIN_MSE_FLOOR)


@documented()
@dataclass(frozen=True)
class ShmParams(FastShmParams):
    """Parameters of "shm": ``FastShmParams`` and ``use_mse``.

    Parameters
    ----------
    {parameters}
    """

    FIELD_DOCS: ClassVar[dict[str, FieldDoc]] = {
        "use_mse": ("bool", "Include the squared-difference evidence in the hypothesis "
                            "weights (§3.3's generalised measurement); False is the plain "
                            "§3.2 filter on positions only. True, False, a numpy bool, 0 or 1; "
                            "stored as ``bool``."),
    }

    use_mse: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.use_mse not in (True, False):  # bool, numpy bool, 0 or 1
            raise ValueError(f"use_mse must be True or False, got {self.use_mse!r}")
        self._set("use_mse", bool(self.use_mse))


class _SHMBase(Tracker):
    """Parameter handling and measurement shared by the two SHM trackers."""

    def _configure(self, params: FastShmParams) -> None:
        self.model = params.motion_model()
        self._matcher_params = params.matcher_params()

    def _init_common(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        # orderings() refuses more than 4 objects with a message saying what to do.
        self.orderings = orderings(boxes.shape[0])
        self._rows = self.orderings.astype(np.int64)
        self.matcher = LayeredMatcher(frame, boxes, **self._matcher_params)
        self._sizes = boxes[:, 2:].copy()
        self._origin = boxes[:, :2] + boxes[:, 2:] / 2
        n_order = self.orderings.shape[0]
        self.order_prob = np.full(n_order, 1.0 / n_order)
        p = self.params
        self._evidence = _OrderingEvidence(
            n_order, p.p_stay, p.lam, p.mse_rate, p.mse_floor, p.evidence
        )
        self._log_u = -np.log(float(frame.shape[0] * frame.shape[1]))


@documented(extra=RNG_UNUSED)
class SHMTracker(_SHMBase):
    """SHM filter (§3.2): Gaussian sum over depth orderings with GPB2 collapsing.

    The parameters are the fields of ``ShmParams``, and ``rng``. ``init`` refuses more than
    ``trackers.models.layered.MAX_OBJECTS`` (4) targets with a ``ValueError``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    orderings : ndarray of shape (L, M), int16
        Depth orderings after ``init``, each row nearest first.
    order_prob : ndarray of shape (L,)
        P(ordering) after the last step (also ``Estimate.extras["order_prob"]``).

    Examples
    --------
    >>> import trackers
    >>> tracker = trackers.make("shm", p_stay=0.8)
    """

    name = "shm"
    Params = ShmParams

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self._init_common(frame, boxes)
        n_obj = boxes.shape[0]
        n_order = self.orderings.shape[0]
        self.joint = self.model.joint(n_obj)
        d = self.model.dim
        self._pos = np.array([[m * d, m * d + 1] for m in range(n_obj)])  # (M, 2) indices
        # One Gaussian per ordering; the state is the displacement from the first centres.
        self.kf = KalmanFilter(
            np.zeros((n_order, self.joint.dim)), self.joint.P0, self.joint.F, self.joint.Q,
            self.joint.H, np.eye(2 * n_obj) * self.params.r_floor,
        )
        ii, jj = np.divmod(np.arange(n_order * n_order), n_order)
        self._ii, self._jj = ii, jj
        self._blocks = [self.joint.H[2 * m : 2 * m + 2] for m in range(n_obj)]

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        n_order = self.orderings.shape[0]
        kf = self.kf
        kf.predict()
        mean = self.order_prob @ kf.x
        meas = self.matcher.measure(frame, self._origin + mean[self._pos], self._rows)
        z = meas.centres - self._origin[None]
        r = measurement_cov(meas.mse, self.params.r_gain, self.params.r_floor)
        ii, jj = self._ii, self._jj
        # Prediction i updated with measurement j, for every pair (i, j).
        pairs = KalmanFilter(kf.x[ii], kf.P[ii], kf.F, kf.Q, kf.H, kf.R[ii])
        loglik = np.zeros(ii.size)
        for m, h in enumerate(self._blocks):
            zm = z[jj, m]
            pairs.update(zm, R=r[jj, m], H=h)
            missed = np.isnan(zm).any(axis=1)
            # A missed object contributes the uniform density of an improper measurement.
            loglik += np.where(missed, self._log_u, pairs.log_likelihood)
        logw = (
            self._evidence.log_pi[ii, jj]
            + np.log(np.maximum(self.order_prob, 1e-300))[ii]
            + loglik
        )
        if self.params.use_mse:
            logw = logw + self._evidence.log_evidence(meas.mse, meas.counts)[jj]
        logw = logw.reshape(n_order, n_order)  # [i, j]
        top = logw.max()
        log_pj = top + np.log(np.exp(logw - top).sum(axis=0))
        self.order_prob = normalised_weights(log_pj)
        # Collapse (moment matching) over the previous ordering i, per ordering j.
        w = normalised_weights(logw, axis=0)  # P(i | j)
        mu = pairs.x.reshape(n_order, n_order, -1)
        cov = pairs.P.reshape(n_order, n_order, *pairs.P.shape[1:])
        new_mu = np.einsum("ij,ijn->jn", w, mu)
        dev = mu - new_mu[None]
        new_cov = np.einsum("ij,ijab->jab", w, cov + dev[..., :, None] * dev[..., None, :])
        kf.x = new_mu
        kf.P = new_cov
        kf.x_post, kf.P_post = new_mu.copy(), new_cov.copy()
        centres = self._origin + (self.order_prob @ new_mu)[self._pos]
        return Estimate(
            boxes=boxes_at(centres, self._sizes),
            extras={"order_prob": self.order_prob.copy()},
        )


@documented(extra=RNG_UNUSED)
class FastSHMTracker(_SHMBase):
    """Fast SHM filter (§3.3): ordering posterior from the matches, one Kalman filter.

    The parameters are the fields of ``FastShmParams``, and ``rng``. ``init`` refuses more than
    ``trackers.models.layered.MAX_OBJECTS`` (4) targets with a ``ValueError``.

    Parameters
    ----------
    {parameters}

    Attributes
    ----------
    orderings : ndarray of shape (L, M), int16
        Depth orderings after ``init``, each row nearest first.
    order_prob : ndarray of shape (L,)
        P(ordering) after the last step (also ``Estimate.extras["order_prob"]``).

    Examples
    --------
    >>> import trackers
    >>> tracker = trackers.make("shm-fast", search_radius=12)
    """

    name = "shm-fast"
    Params = FastShmParams

    def _init(self, frame: NDArray[np.uint8], boxes: NDArray[np.float64]) -> None:
        self._init_common(frame, boxes)
        m = self.model
        self.kf = KalmanFilter(
            np.zeros((boxes.shape[0], m.dim)), m.P0, m.F, m.Q, m.H, np.eye(2) * self.params.r_floor
        )

    def _step(self, frame: NDArray[np.uint8]) -> Estimate:
        kf = self.kf
        kf.predict()
        meas = self.matcher.measure(frame, self._origin + kf.x[:, :2], self._rows)
        # P(s_t = j | Y_t) ∝ exp(−lam E_j / ē) Σ_i Π_ij P(s_{t−1} = i)  (§3.3)
        prior = self.order_prob @ self._evidence.pi
        log_ev = self._evidence.log_evidence(meas.mse, meas.counts)
        logp = np.log(np.maximum(prior, 1e-300)) + log_ev
        self.order_prob = normalised_weights(logp)
        valid = np.isfinite(meas.mse)  # (L, M)
        q = self.order_prob[:, None] * valid
        mass = q.sum(axis=0)  # (M,)
        # At least half the probability (1e-9 allows for the rounding of the sum: 12 of
        # 24 equal probabilities add up to 0.49999999999999994).
        seen = mass >= 0.5 - 1e-9
        q = q / np.where(mass > 0, mass, 1.0)
        y = np.nan_to_num(meas.centres - self._origin[None])  # (L, M, 2)
        r = measurement_cov(meas.mse, self.params.r_gain, self.params.r_floor)  # (L, M, 2, 2)
        # Moment-matched mixture of the hypothesized measurements, per object.
        y_hat = np.einsum("lm,lmc->mc", q, y)
        dev = y - y_hat[None]
        r_hat = np.einsum("lm,lmab->mab", q, r + dev[..., :, None] * dev[..., None, :])
        y_hat[~seen] = np.nan
        kf.update(y_hat, R=r_hat)
        centres = self._origin + kf.x[:, :2]
        return Estimate(
            boxes=boxes_at(centres, self._sizes),
            extras={"order_prob": self.order_prob.copy()},
        )
