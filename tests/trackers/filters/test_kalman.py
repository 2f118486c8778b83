"""trackers.filters.kalman (batched Kalman filter) against FilterPy; the plain Kalman tracker."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FPKalmanFilter
from hypothesis import given, settings
from hypothesis import strategies as st

import trackers
from trackers.filters.kalman import KalmanFilter, MotionModel


def _spd(rng: np.random.Generator, n: int, scale: float) -> np.ndarray:
    a = rng.normal(size=(n, n))
    return scale * (a @ a.T / n + 0.1 * np.eye(n))


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    dim_x=st.integers(1, 6),
    dim_z=st.integers(1, 4),
    batch=st.integers(1, 4),
    steps=st.integers(1, 12),
)
def test_matches_filterpy_on_random_problems(seed, dim_x, dim_z, batch, steps):
    rng = np.random.default_rng(seed)
    f = np.eye(dim_x) + 0.3 * rng.normal(size=(dim_x, dim_x))
    q = _spd(rng, dim_x, 0.5)
    h = rng.normal(size=(dim_z, dim_x))
    r = rng.uniform(0.1, 3.0, size=(batch, dim_z, dim_z)) * np.eye(dim_z) + _spd(rng, dim_z, 0.2)
    x0 = rng.normal(size=(batch, dim_x))
    p0 = np.stack([_spd(rng, dim_x, 2.0) for _ in range(batch)])
    ours = KalmanFilter(x0, p0, f, q, h, r)
    refs = []
    for b in range(batch):
        ref = FPKalmanFilter(dim_x=dim_x, dim_z=dim_z)
        ref.x = x0[b][:, None].copy()
        ref.P = p0[b].copy()
        ref.F, ref.Q, ref.H, ref.R = f.copy(), q.copy(), h.copy(), r[b].copy()
        refs.append(ref)
    for _ in range(steps):
        ours.predict()
        for ref in refs:
            ref.predict()
        z = rng.normal(size=(batch, dim_z)) * 3
        missed = rng.random(batch) < 0.25
        z[missed] = np.nan
        ours.update(z)
        for b, ref in enumerate(refs):
            ref.update(None if missed[b] else z[b])
        for b, ref in enumerate(refs):
            np.testing.assert_allclose(ours.x[b], ref.x[:, 0], rtol=0, atol=1e-9)
            np.testing.assert_allclose(ours.P[b], ref.P, rtol=0, atol=1e-9)
            if not missed[b]:
                np.testing.assert_allclose(ours.S[b], ref.S, rtol=0, atol=1e-9)
                np.testing.assert_allclose(
                    ours.log_likelihood[b], ref.log_likelihood, rtol=1e-9, atol=1e-9
                )


@pytest.mark.parametrize(
    "model",
    [
        MotionModel.constant_velocity(accel_std=1.3),
        MotionModel.ar2(a1=1.8, a2=-0.85, noise_std=2.0),
    ],
    ids=["cv", "ar2"],
)
def test_motion_models_match_filterpy_over_a_simulated_track(model):
    rng = np.random.default_rng(7)
    r = np.eye(2) * 2.0
    ours = KalmanFilter(np.zeros((1, 4)), model.P0, model.F, model.Q, model.H, r)
    ref = FPKalmanFilter(dim_x=4, dim_z=2)
    ref.x = np.zeros((4, 1))
    ref.P, ref.F, ref.Q, ref.H, ref.R = model.P0.copy(), model.F, model.Q, model.H, r
    truth = np.zeros(4)
    chol = np.linalg.cholesky(model.Q + 1e-12 * np.eye(4))
    for t in range(60):
        truth = model.F @ truth + chol @ rng.normal(size=4)
        z = model.H @ truth + rng.normal(size=2) * np.sqrt(2.0)
        ours.predict()
        ref.predict()
        if t % 7 == 3:
            ours.update(None)
            ref.update(None)
        else:
            ours.update(z[None])
            ref.update(z)
        np.testing.assert_allclose(ours.x[0], ref.x[:, 0], rtol=0, atol=1e-9)
        np.testing.assert_allclose(ours.P[0], ref.P, rtol=0, atol=1e-9)


def test_missed_measurement_keeps_the_prior():
    model = MotionModel.constant_velocity(accel_std=1.0)
    kf = KalmanFilter(np.array([[0.0, 0.0, 2.0, -1.0]]), model.P0, model.F, model.Q, model.H,
                      np.eye(2))
    for _ in range(5):
        kf.predict()
        prior_x, prior_p = kf.x.copy(), kf.P.copy()
        kf.update(None)
        np.testing.assert_array_equal(kf.x, prior_x)
        np.testing.assert_array_equal(kf.P, prior_p)
    # Constant velocity keeps moving through missed measurements.
    np.testing.assert_allclose(kf.x[0, :2], [10.0, -5.0])
    assert np.all(np.diff(np.diag(kf.P[0])[:2]) == 0) and kf.P[0, 0, 0] > model.P0[0, 0]


def test_cv_equals_ar2_with_a1_2_a2_minus_1_in_position():
    # AR2 (2, -1) with noise on the position is constant velocity with acceleration noise
    # entering the position only; with zero noise both predict the same straight line.
    cv = MotionModel.constant_velocity(accel_std=0.0)
    ar2 = MotionModel.ar2(a1=2.0, a2=-1.0, noise_std=0.0)
    x_cv = np.array([3.0, 4.0, 1.5, -2.0])
    x_ar = np.array([3.0, 4.0, 3.0 - 1.5, 4.0 + 2.0])
    for _ in range(10):
        x_cv = cv.F @ x_cv
        x_ar = ar2.F @ x_ar
        np.testing.assert_allclose(cv.H @ x_cv, ar2.H @ x_ar)


def test_joint_model_is_block_diagonal():
    m = MotionModel.constant_velocity(accel_std=1.0).joint(3)
    assert m.F.shape == (12, 12) and m.H.shape == (6, 12)
    np.testing.assert_array_equal(m.F[4:8, 4:8], MotionModel.constant_velocity(accel_std=1.0).F)
    assert not m.F[0:4, 4:8].any()


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(x=np.zeros(4)), "x must have shape"),
        (dict(P=np.eye(3)), "P must have shape"),
        (dict(F=np.eye(3)), "F must have shape"),
        (dict(H=np.zeros((2, 3))), "H must have shape"),
        (dict(R=np.eye(3)), "R must have shape"),
    ],
)
def test_bad_shapes_raise(kwargs, match):
    args = dict(x=np.zeros((2, 4)), P=np.eye(4), F=np.eye(4), Q=np.eye(4),
                H=np.eye(2, 4), R=np.eye(2))
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        KalmanFilter(**args)


def test_bad_measurement_shape_raises():
    kf = KalmanFilter(np.zeros((2, 4)), np.eye(4), np.eye(4), np.eye(4), np.eye(2, 4), np.eye(2))
    with pytest.raises(ValueError, match="z must have shape"):
        kf.update(np.zeros((3, 2)))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(accel_std=-1.0), "accel_std"),
        (dict(accel_std=1.0, velocity_std=0.0), "velocity_std"),
        # Not numbers: "1" and None were numpy's TypeError from isfinite, True was 1.
        (dict(accel_std="1"), "accel_std must be finite and >= 0, got '1'"),
        (dict(accel_std=None), "accel_std must be finite and >= 0, got None"),
        (dict(accel_std=1.0, position_std=True), "position_std must be finite and > 0"),
    ],
)
def test_bad_model_parameters_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        MotionModel.constant_velocity(**kwargs)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(a1=1.0, a2=0.0, noise_std="2"), "noise_std must be finite and >= 0, got '2'"),
        (dict(a1=1.0, a2=0.0, noise_std=1.0, velocity_std=[5.0]), "velocity_std must be"),
    ],
)
def test_bad_ar2_model_parameters_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        MotionModel.ar2(**kwargs)


@pytest.mark.parametrize("n", [1.5, True, "2"])
def test_the_joint_model_needs_an_integer_count(n):
    # 1.5 was numpy's "'float' object cannot be interpreted as an integer" (TypeError).
    with pytest.raises(ValueError, match="n_objects must be an integer, got"):
        MotionModel.constant_velocity(accel_std=1.0).joint(n)


# --- the plain Kalman tracker ------------------------------------------------------------


def _scene(rng, n_frames, starts, velocities, size=30, h=120, w=160):
    """Smooth random background with textured squares moving at constant velocity."""
    import cv2

    def texture(hh, ww):
        t = rng.integers(0, 256, (hh // 4 + 2, ww // 4 + 2, 3)).astype(np.float32)
        big = cv2.resize(t, (ww + 8, hh + 8), interpolation=cv2.INTER_CUBIC)
        return big[4 : 4 + hh, 4 : 4 + ww].clip(0, 255).astype(np.uint8)

    bg = texture(h, w)
    tpls = [texture(size, size) for _ in starts]
    frames = np.empty((n_frames, h, w, 3), np.uint8)
    centres = np.full((n_frames, len(starts), 2), np.nan)
    for t in range(n_frames):
        f = bg.copy()
        for k, ((x0, y0), (vx, vy)) in enumerate(zip(starts, velocities, strict=True)):
            x, y = int(round(x0 + vx * t)), int(round(y0 + vy * t))
            xs, ys = max(x, 0), max(y, 0)
            xe, ye = min(x + size, w), min(y + size, h)
            if xe > xs and ye > ys:
                f[ys:ye, xs:xe] = tpls[k][ys - y : ye - y, xs - x : xe - x]
            centres[t, k] = (x + size / 2, y + size / 2)
        frames[t] = f
    boxes0 = np.array([[x, y, size, size] for x, y in starts], dtype=float)
    return frames, boxes0, centres


def test_kalman_tracker_follows_moving_objects():
    rng = np.random.default_rng(3)
    frames, boxes0, centres = _scene(rng, 30, [(10, 20), (100, 70)], [(2.0, 1.0), (-1.5, 0.5)])
    res = trackers.track(trackers.make("kalman"), frames, boxes0)
    est = res.boxes[:, :, :2] + res.boxes[:, :, 2:] / 2
    err = np.linalg.norm(est - centres, axis=2)
    assert err.max() < 1.5
    assert res.extras["mse"].shape == (30, 2)


def test_kalman_tracker_keeps_predicting_when_object_leaves_frame():
    rng = np.random.default_rng(4)
    frames, boxes0, centres = _scene(rng, 40, [(100, 40)], [(3.0, 0.0)])
    tracker = trackers.make("kalman")
    res = trackers.track(tracker, frames, boxes0)
    est = res.boxes[:, 0, :2] + res.boxes[:, 0, 2:] / 2
    inside = centres[:, 0, 0] < 150
    assert np.abs(est[inside] - centres[inside, 0]).max() < 1.5
    # Gone: measurements are missed, the filter keeps its velocity, boxes stay clipped.
    assert np.isnan(res.extras["mse"][-5:]).all()
    assert np.all(est[:, 0] <= 160) and np.all(np.isfinite(est))
    assert tracker.kf.x[0, 2] == pytest.approx(3.0, abs=0.2)


def test_kalman_tracker_ar2_motion_tracks():
    rng = np.random.default_rng(5)
    frames, boxes0, centres = _scene(rng, 25, [(20, 30)], [(2.0, 1.0)])
    res = trackers.track(trackers.make("kalman", motion="ar2"), frames, boxes0)
    est = res.boxes[:, 0, :2] + res.boxes[:, 0, 2:] / 2
    assert np.abs(est - centres[:, 0]).max() < 1.5


@pytest.mark.parametrize(
    "params, match",
    [
        (dict(motion="spline"), "unknown motion 'spline'; valid: cv, ar2"),
        (dict(process_std=-1.0), r"process_std must be in \[0, 1e\+06\]"),
        (dict(r_floor=0.0), "r_floor"),
        (dict(r_gain=np.nan), "r_gain"),
        (dict(search_radius=0), "search_radius"),
        (dict(step=0), "step"),
        (dict(min_visible=0.0), "min_visible"),
        (dict(support="circle"), "unknown support 'circle'; valid: box, ellipse"),
        (dict(blur=-1.0), "blur"),
    ],
)
def test_kalman_tracker_bad_parameters(params, match):
    with pytest.raises(ValueError, match=match):
        trackers.make("kalman", **params)


def test_kalman_tracker_rejects_step_before_init():
    with pytest.raises(ValueError, match="init"):
        trackers.make("kalman").step(np.zeros((10, 10, 3), np.uint8))


def test_constant_velocity_matrices_are_the_white_acceleration_model():
    # Q = var G G' per axis with G = (1/2, 1)' (the acceleration over one frame moves the
    # position by a/2 and the velocity by a); P0 = diag of the given stds squared.
    m = MotionModel.constant_velocity(accel_std=3.0, position_std=2.0, velocity_std=7.0)
    g = np.zeros((4, 2))
    g[0, 0] = g[1, 1] = 0.5
    g[2, 0] = g[3, 1] = 1.0
    np.testing.assert_allclose(m.Q, 9.0 * g @ g.T)
    np.testing.assert_allclose(m.P0, np.diag([4.0, 4.0, 49.0, 49.0]))
    np.testing.assert_array_equal(m.F, [[1, 0, 1, 0], [0, 1, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]])
    np.testing.assert_array_equal(m.H, np.eye(2, 4))
    default = MotionModel.constant_velocity(accel_std=1.0)
    np.testing.assert_allclose(default.P0, np.diag([1.0, 1.0, 25.0, 25.0]))


def test_ar2_matrices_follow_from_position_and_velocity():
    # State (x_t, y_t, x_{t-1}, y_{t-1}): the previous position is the current one minus a
    # velocity, both independent Gaussians, so P0 = A diag(pv, pv, vv, vv) A'; the noise
    # enters the current position only.
    m = MotionModel.ar2(a1=1.7, a2=-0.7, noise_std=3.0, position_std=2.0, velocity_std=7.0)
    a = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [1, 0, -1, 0], [0, 1, 0, -1]], dtype=float)
    np.testing.assert_allclose(m.P0, a @ np.diag([4.0, 4.0, 49.0, 49.0]) @ a.T)
    np.testing.assert_allclose(m.Q, np.diag([9.0, 9.0, 0.0, 0.0]))
    np.testing.assert_allclose(m.F, [[1.7, 0, -0.7, 0], [0, 1.7, 0, -0.7], [1, 0, 0, 0],
                                     [0, 1, 0, 0]])
    default = MotionModel.ar2(a1=2.0, a2=-1.0, noise_std=1.0)
    np.testing.assert_allclose(default.P0, a @ np.diag([1.0, 1.0, 25.0, 25.0]) @ a.T)


def test_the_joint_model_of_one_object_is_the_model():
    m = MotionModel.ar2(a1=1.7, a2=-0.7, noise_std=3.0)
    one = m.joint(1)
    for name in ("F", "Q", "H", "P0"):
        np.testing.assert_array_equal(getattr(one, name), getattr(m, name))
    two = m.joint(2)
    np.testing.assert_array_equal(two.P0[4:, 4:], m.P0)
    assert not two.P0[:4, 4:].any()
    with pytest.raises(ValueError, match="n_objects must be >= 1, got 0"):
        m.joint(0)


def test_a_missed_measurement_leaves_the_prior_and_zero_diagnostics():
    m = MotionModel.constant_velocity(accel_std=1.0)
    rng = np.random.default_rng(2)
    kf = KalmanFilter(rng.normal(size=(2, 4)), m.P0, m.F, m.Q, m.H, np.eye(2) * 4.0)
    kf.predict()
    x, p = kf.x.copy(), kf.P.copy()
    kf.update(np.array([[np.nan, np.nan], [1.0, 2.0]]))
    np.testing.assert_array_equal(kf.x[0], x[0])
    np.testing.assert_array_equal(kf.P[0], p[0])
    np.testing.assert_array_equal(kf.y[0], [0.0, 0.0])
    np.testing.assert_array_equal(kf.K[0], np.zeros((4, 2)))
    np.testing.assert_allclose(kf.S[0], m.H @ p[0] @ m.H.T + 4.0 * np.eye(2))
    assert kf.log_likelihood[0] == 0.0
    assert kf.y[1].any() and kf.K[1].any()


@pytest.mark.parametrize("kwargs, match", [
    ({"H": np.eye(2)}, r"H must have shape \(m, 4\), got \(2, 2\)"),
    ({"H": np.ones(4)}, r"H must have shape \(m, 4\), got \(4,\)"),
    ({"R": np.eye(3)}, r"R must have shape \(2, 2\) or \(2, 2, 2\), got \(3, 3\)"),
    ({"H": np.eye(1, 4)}, r"R must have shape \(1, 1\) for this H, got \(2, 2\)$"),
])
def test_bad_update_overrides_raise(kwargs, match):
    kf = KalmanFilter(np.zeros((2, 4)), np.eye(4), np.eye(4), np.eye(4), np.eye(2, 4), np.eye(2))
    with pytest.raises(ValueError, match=match):
        kf.update(None, **kwargs)


@pytest.mark.parametrize("name", ["a1", "a2"])
def test_ar2_coefficients_must_be_finite(name):
    kwargs = {"a1": 2.0, "a2": -1.0, "noise_std": 1.0, name: np.nan}
    with pytest.raises(ValueError, match=f"{name} must be finite, got nan"):
        MotionModel.ar2(**kwargs)


@pytest.mark.parametrize("a1, a2", [(2.5, -0.5), (100.0, 0.0), (0.0, 1.5), (-2.1, -1.0)])
def test_ar2_explosive_coefficients_are_refused(a1, a2):
    # The one definition of "explosive" (check_ar2_coefficients) holds for the building
    # block too: the covariance of such a model grows without bound (NaN boxes).
    with pytest.raises(ValueError, match="a1, a2 must not be explosive"):
        MotionModel.ar2(a1=a1, a2=a2, noise_std=1.0)


@pytest.mark.parametrize("a1, a2", [(2.0, -1.0), (0.0, 1.0), (-2.0, -1.0), (1.9, -0.9)])
def test_ar2_coefficients_on_the_stable_boundary_are_accepted(a1, a2):
    assert MotionModel.ar2(a1=a1, a2=a2, noise_std=1.0).F[0, 0] == a1


def test_a_singular_innovation_covariance_is_one_error_naming_the_filter():
    # R = 0 and P = 0 made S = 0: a raw numpy LinAlgError "Singular matrix".
    model = MotionModel.constant_velocity(accel_std=1.0)
    p = np.zeros((3, 4, 4))
    p[0] = p[2] = np.eye(4)
    kf = KalmanFilter(np.zeros((3, 4)), p, model.F, np.zeros((4, 4)), model.H, np.zeros((2, 2)))
    z = np.zeros((3, 2))
    with pytest.raises(ValueError, match="covariance S = H P H' \\+ R of filter 1 is singular"
                       ) as info:
        kf.update(z)
    assert type(info.value) is ValueError
    assert np.array_equal(kf.P, p) and np.array_equal(kf.x, np.zeros((3, 4)))
    z[1] = np.nan  # filter 1 missed: only the others are updated
    kf.update(z)
