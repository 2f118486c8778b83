"""A batched linear-Gaussian Kalman filter, and the motion models the trackers use.

``KalmanFilter`` runs ``B`` independent filters that share the model matrices ``F``,
``Q`` and ``H`` (one per object for the plain tracker, one per depth-ordering hypothesis
for the SHM filter). Its equations and attribute names follow FilterPy's
``filterpy.kalman.KalmanFilter`` (Labbe), including the Joseph-form covariance update, so
that the two agree to rounding error; ``update(None)`` is a missed measurement.

``MotionModel`` builds the per-object matrices for a 2-D position (x, y): constant
velocity, or a second-order autoregression (AR2, docs/algorithms.md §1.1), and stacks them
block-diagonally for a joint state of several objects (SHM paper §2.2, eq. 2).

Examples
--------
>>> import numpy as np
>>> model = MotionModel.constant_velocity(accel_std=1.0)
>>> kf = KalmanFilter(np.zeros((3, 4)), np.tile(np.eye(4), (3, 1, 1)),
...                   model.F, model.Q, model.H, np.eye(2))
>>> kf.predict()
>>> kf.update(np.array([[1.0, 0.0], [np.nan, np.nan], [0.0, 2.0]]))  # filter 1 missed
>>> kf.x.shape
(3, 4)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from trackers.models.dynamics import check_ar2_coefficients

__all__ = ["KalmanFilter", "MotionModel"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class MotionModel:
    """Linear-Gaussian model of one object's 2-D position: x' = F x + n, z = H x + v.

    Attributes
    ----------
    F : ndarray of shape (n, n)
        State transition.
    Q : ndarray of shape (n, n)
        Process noise covariance.
    H : ndarray of shape (2, n)
        Measurement matrix: the state's position (x, y).
    P0 : ndarray of shape (n, n)
        Initial state covariance around a state at rest at the first position.
    kind : str
        ``"cv"`` or ``"ar2"``.
    """

    F: FloatArray
    Q: FloatArray
    H: FloatArray
    P0: FloatArray
    kind: str

    @property
    def dim(self) -> int:
        """State dimension n."""
        return self.F.shape[0]

    @classmethod
    def constant_velocity(
        cls, *, accel_std: float, position_std: float = 1.0, velocity_std: float = 5.0
    ) -> MotionModel:
        """Constant velocity, state (x, y, vx, vy), frame period 1.

        The process noise is a piecewise-constant white acceleration of std ``accel_std``
        (px/frame²) per coordinate, FilterPy's ``Q_discrete_white_noise(2, 1, var)``:
        ``Q = var [[1/4, 1/2], [1/2, 1]]`` per (position, velocity) pair.
        ``position_std`` (px) and ``velocity_std`` (px/frame) set ``P0``.

        Parameters
        ----------
        accel_std : float
            Acceleration noise std, px/frame², finite and >= 0 (keyword only).
        position_std : float, default 1.0
            Initial position std, px, finite and > 0.
        velocity_std : float, default 5.0
            Initial velocity std, px/frame, finite and > 0.

        Returns
        -------
        MotionModel
            ``kind="cv"``, n = 4: ``F``, ``Q``, ``P0`` of shape (4, 4), ``H`` (2, 4), and
            ``P0 = diag(position_std², position_std², velocity_std², velocity_std²)``.

        Raises
        ------
        ValueError
            For a std that is not finite or out of its range, naming it.
        """
        _check_positive("accel_std", accel_std, allow_zero=True)
        _check_positive("position_std", position_std)
        _check_positive("velocity_std", velocity_std)
        f = np.eye(4)
        f[0, 2] = f[1, 3] = 1.0
        q = np.zeros((4, 4))
        var = accel_std**2
        for p, v in ((0, 2), (1, 3)):
            q[p, p] = 0.25 * var
            q[p, v] = q[v, p] = 0.5 * var
            q[v, v] = var
        h = np.zeros((2, 4))
        h[0, 0] = h[1, 1] = 1.0
        p0 = np.diag([position_std**2, position_std**2, velocity_std**2, velocity_std**2])
        return cls(F=f, Q=q, H=h, P0=p0, kind="cv")

    @classmethod
    def ar2(
        cls,
        *,
        a1: float,
        a2: float,
        noise_std: float,
        position_std: float = 1.0,
        velocity_std: float = 5.0,
    ) -> MotionModel:
        """AR2 per coordinate, state (x_t, y_t, x_{t-1}, y_{t-1}).

        ``c_t = a1 c_{t-1} + a2 c_{t-2} + noise_std ε`` on the displacement from the first
        position (the AR2 mean c̄ of docs/algorithms.md §1.1 is the first position); with
        ``a1 + a2 = 1`` the mean drops out. ``a1 = 2, a2 = -1`` is constant velocity with
        acceleration noise. ``P0`` treats the previous position as the current one minus a
        velocity of std ``velocity_std``. Explosive coefficients (a root of
        z² − a1 z − a2 outside the unit circle) are refused, as by every tracker with AR2
        dynamics (``trackers.models.dynamics.check_ar2_coefficients``).

        Parameters
        ----------
        a1, a2 : float
            AR2 coefficients (keyword only), finite and not explosive.
        noise_std : float
            Std of the AR2 noise, px, finite and >= 0 (keyword only).
        position_std : float, default 1.0
            Initial position std, px, finite and > 0.
        velocity_std : float, default 5.0
            Initial velocity std, px/frame, finite and > 0.

        Returns
        -------
        MotionModel
            ``kind="ar2"``, n = 4: ``F``, ``Q``, ``P0`` of shape (4, 4), ``H`` (2, 4).

        Raises
        ------
        ValueError
            For a std that is not finite or out of its range, or for coefficients that
            are not finite or explosive, naming the parameter.
        """
        _check_positive("noise_std", noise_std, allow_zero=True)
        _check_positive("position_std", position_std)
        _check_positive("velocity_std", velocity_std)
        a1, a2 = check_ar2_coefficients(a1, a2)
        f = np.zeros((4, 4))
        f[0, 0] = f[1, 1] = a1
        f[0, 2] = f[1, 3] = a2
        f[2, 0] = f[3, 1] = 1.0
        q = np.zeros((4, 4))
        q[0, 0] = q[1, 1] = noise_std**2
        h = np.zeros((2, 4))
        h[0, 0] = h[1, 1] = 1.0
        pv, vv = position_std**2, velocity_std**2
        p0 = np.array(
            [[pv, 0, pv, 0], [0, pv, 0, pv], [pv, 0, pv + vv, 0], [0, pv, 0, pv + vv]],
            dtype=np.float64,
        )
        return cls(F=f, Q=q, H=h, P0=p0, kind="ar2")

    def joint(self, n_objects: int) -> MotionModel:
        """The block-diagonal model of ``n_objects`` independent objects.

        The joint state stacks the objects' states (object-major, dimension
        ``n_objects * n``); the joint measurement stacks their (x, y).

        Parameters
        ----------
        n_objects : int
            Number of objects K, >= 1.

        Returns
        -------
        MotionModel
            Of the same ``kind``: ``F``, ``Q``, ``P0`` of shape (K n, K n), ``H`` of shape
            (2 K, K n), each block-diagonal with K copies of this model's matrix
            (``numpy.kron``).

        Raises
        ------
        ValueError
            If ``n_objects`` is not an integer >= 1.
        """
        if isinstance(n_objects, (bool, np.bool_)) or not isinstance(n_objects, (int, np.integer)):
            raise ValueError(f"n_objects must be an integer, got {n_objects!r}")
        if n_objects < 1:
            raise ValueError(f"n_objects must be >= 1, got {n_objects}")
        eye = np.eye(n_objects)
        return MotionModel(
            F=np.kron(eye, self.F),
            Q=np.kron(eye, self.Q),
            H=np.kron(eye, self.H),
            P0=np.kron(eye, self.P0),
            kind=self.kind,
        )


def _check_positive(name: str, value: float, *, allow_zero: bool = False) -> None:
    # Only numbers: "1" and None failed in np.isfinite with numpy's own TypeError, and
    # True was read as 1.
    number = (not isinstance(value, (bool, np.bool_))
              and isinstance(value, (int, float, np.integer, np.floating)))
    ok = number and np.isfinite(value) and (value >= 0 if allow_zero else value > 0)
    if not ok:
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} must be finite and {bound}, got {value!r}")


class KalmanFilter:
    """``B`` Kalman filters sharing ``F``, ``Q``, ``H``; each may have its own ``R``.

    Parameters
    ----------
    x : array_like of shape (B, n)
        Initial state means.
    P : array_like of shape (B, n, n) or (n, n)
        Initial state covariances.
    F : array_like of shape (n, n)
        State transition.
    Q : array_like of shape (n, n)
        Process noise covariance.
    H : array_like of shape (m, n)
        Measurement matrix.
    R : array_like of shape (m, m) or (B, m, m)
        Measurement noise covariance.

    Attributes
    ----------
    x, P : ndarray of shape (B, n), (B, n, n)
        Current means and covariances (prior after ``predict``, posterior after
        ``update``); ``x_prior``, ``P_prior``, ``x_post``, ``P_post`` keep copies.
    y, S, K : ndarray of shape (B, m), (B, m, m), (B, n, m)
        Innovation, its covariance and the gain of the last ``update`` (zeros, and the
        prior's ``S``, for a missed measurement).
    log_likelihood : ndarray of shape (B,)
        log N(z; H x_prior, S) of the last update; 0 for a missed measurement.
    """

    def __init__(
        self,
        x: ArrayLike,
        P: ArrayLike,
        F: ArrayLike,
        Q: ArrayLike,
        H: ArrayLike,
        R: ArrayLike,
    ) -> None:
        self.x = np.array(x, dtype=np.float64)
        if self.x.ndim != 2:
            raise ValueError(f"x must have shape (B, n), got {self.x.shape}")
        b, n = self.x.shape
        self.F = _matrix("F", F, (n, n))
        self.Q = _matrix("Q", Q, (n, n))
        self.H = np.array(H, dtype=np.float64)
        if self.H.ndim != 2 or self.H.shape[1] != n:
            raise ValueError(f"H must have shape (m, {n}), got {self.H.shape}")
        m = self.H.shape[0]
        self.P = _batched("P", P, b, (n, n))
        self.R = _batched("R", R, b, (m, m))
        self._I = np.eye(n)
        self.x_prior = self.x.copy()
        self.P_prior = self.P.copy()
        self.x_post = self.x.copy()
        self.P_post = self.P.copy()
        self.y = np.zeros((b, m))
        self.S = np.zeros((b, m, m))
        self.K = np.zeros((b, n, m))
        self.log_likelihood = np.zeros(b)

    @property
    def batch(self) -> int:
        """Number of filters B."""
        return self.x.shape[0]

    def predict(self) -> None:
        """Propagate every filter one step."""
        # x = F x  (prior mean)
        self.x = self.x @ self.F.T
        # P = F P F' + Q  (prior covariance)
        self.P = self.F @ self.P @ self.F.T + self.Q
        self.x_prior = self.x.copy()
        self.P_prior = self.P.copy()

    def update(
        self,
        z: ArrayLike | None,
        R: ArrayLike | None = None,
        H: ArrayLike | None = None,
    ) -> None:
        """Incorporate measurements ``z`` of shape (B, m'); ``None`` = all missed.

        A row of ``z`` containing NaN is a missed measurement for that filter: its state
        stays the prior. ``R`` of shape (m', m') or (B, m', m') and ``H`` of shape (m', n)
        override ``self.R``/``self.H`` for this call only (a sub-block of the measurement
        may be processed this way, as in sequential updates of independent objects).

        Sets ``x``, ``P`` (and their copies ``x_post``, ``P_post``), ``y``, ``S``, ``K``
        and ``log_likelihood`` (0 for a missed measurement).

        Parameters
        ----------
        z : array_like of shape (B, m') or None
            One measurement per filter; a row with a NaN (or inf) is a missed measurement
            for that filter, and None misses them all.
        R : array_like of shape (m', m') or (B, m', m'), optional
            Measurement noise covariance for this call; None (the default): ``self.R``.
        H : array_like of shape (m', n), optional
            Measurement matrix for this call; None (the default): ``self.H``.

        Raises
        ------
        ValueError
            If ``H``, ``R`` or ``z`` has the wrong shape (for ``R``: not (m', m') for the
            ``H`` used, ``self.R`` included), or the innovation covariance S of a filter
            given a measurement is singular (say R = 0 and P = 0), naming the filter;
            ``x`` and ``P`` are then left as they were.
        """
        b, n = self.x.shape
        h = self.H if H is None else np.asarray(H, dtype=np.float64)
        if h.ndim != 2 or h.shape[1] != n:
            raise ValueError(f"H must have shape (m, {n}), got {h.shape}")
        m = h.shape[0]
        r = self.R if R is None else _batched("R", R, b, (m, m))
        if r.shape[1:] != (m, m):
            raise ValueError(f"R must have shape ({m}, {m}) for this H, got {r.shape[1:]}")
        self.log_likelihood = np.zeros(b)
        if z is None:
            self._missed(h, r, np.zeros(b, dtype=bool))
            return
        zz = np.asarray(z, dtype=np.float64)
        if zz.shape != (b, m):
            raise ValueError(f"z must have shape ({b}, {m}), got {zz.shape}")
        seen = np.all(np.isfinite(zz), axis=1)
        if not seen.any():
            self._missed(h, r, seen)
            return
        x, p, rr = self.x[seen], self.P[seen], r[seen]
        # y = z - H x  (innovation)
        y = zz[seen] - x @ h.T
        # PHT = P H'
        pht = p @ h.T
        # S = H P H' + R  (innovation covariance)
        s = h @ pht + rr
        # SI = S^-1
        try:
            si = np.linalg.inv(s)
        except np.linalg.LinAlgError:  # "Singular matrix", naming no filter
            i = next(j for j in range(s.shape[0]) if _singular(s[j]))
            raise ValueError(
                f"KalmanFilter.update: the innovation covariance S = H P H' + R of filter "
                f"{int(np.flatnonzero(seen)[i])} is singular (R and P leave no uncertainty "
                f"in a measured direction)"
            ) from None
        # K = P H' S^-1  (Kalman gain)
        k = pht @ si
        # x = x + K y  (posterior mean)
        x = x + (k @ y[:, :, None])[:, :, 0]
        # I_KH = I - K H
        i_kh = self._I - k @ h
        # P = (I - K H) P (I - K H)' + K R K'  (Joseph form: stays symmetric positive)
        p = i_kh @ p @ np.swapaxes(i_kh, 1, 2) + k @ rr @ np.swapaxes(k, 1, 2)
        # log N(y; 0, S) = -(m log 2π + log|S| + y' S^-1 y) / 2
        _, logdet = np.linalg.slogdet(s)
        maha = np.einsum("bi,bij,bj->b", y, si, y)
        self._missed(h, r, seen)
        self.x[seen] = x
        self.P[seen] = p
        self.y[seen] = y
        self.S[seen] = s
        self.K[seen] = k
        self.log_likelihood[seen] = -0.5 * (m * np.log(2 * np.pi) + logdet + maha)
        self.x_post = self.x.copy()
        self.P_post = self.P.copy()

    def _missed(self, h: FloatArray, r: FloatArray, seen: NDArray[np.bool_]) -> None:
        """Set the diagnostics of the filters in ``~seen`` to those of a missed update."""
        b, n = self.x.shape
        m = h.shape[0]
        if self.y.shape != (b, m):
            self.y = np.zeros((b, m))
            self.S = np.zeros((b, m, m))
            self.K = np.zeros((b, n, m))
        miss = ~seen
        self.y[miss] = 0.0
        self.S[miss] = h @ self.P[miss] @ h.T + r[miss]
        self.K[miss] = 0.0
        self.x_post = self.x.copy()
        self.P_post = self.P.copy()


def _singular(s: FloatArray) -> bool:
    """Whether ``np.linalg.inv`` refuses the square matrix ``s``."""
    try:
        np.linalg.inv(s)
    except np.linalg.LinAlgError:
        return True
    return False


def _matrix(name: str, value: ArrayLike, shape: tuple[int, int]) -> FloatArray:
    arr = np.array(value, dtype=np.float64)
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
    return arr


def _batched(name: str, value: ArrayLike, b: int, shape: tuple[int, int]) -> FloatArray:
    arr = np.array(value, dtype=np.float64)
    if arr.shape == shape:
        return np.broadcast_to(arr, (b, *shape)).copy()
    if arr.shape != (b, *shape):
        raise ValueError(f"{name} must have shape {shape} or {(b, *shape)}, got {arr.shape}")
    return arr
