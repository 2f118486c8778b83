"""Oracle: the particle filters on a linear-Gaussian model, against the exact Kalman posterior.

The model is the filters' own AR2 dynamics with A1 = 2, A2 = -1 (constant velocity,
noise sigma per coordinate and frame; the log scale is held fixed, sigma_a = 0) and the
Gaussian position likelihood ``trackers.models.observation.PositionModel`` plugged in
through the public ``observation=`` keyword: p(Z_t | X_k) = N(c(X_k); z_{t,k}, r^2 I).
Objects and coordinates are independent under this model, so the exact posterior of each
object's position is a 2-state Kalman filter per coordinate on (p_t, p_{t-1}) (filterpy),
started, as the particles are, at the initial centre with zero velocity (P0 = 0).

For every filter and configuration, ``REPS`` independent runs of ``N`` particles over
``T - 1`` steps give the weighted posterior mean and variance of every object's u and v
at every step; per object, three statistics of the runs:

- ``mean_t``: RMS over steps and coordinates of the t-statistic of the posterior-mean
  error over the runs (mean error / its Monte-Carlo standard error estimated from the
  runs): a biased filter drifts many standard errors away;
- ``var_ratio``: weighted posterior variance / Kalman variance, averaged over runs,
  steps and coordinates: a filter that counts a likelihood twice is too narrow;
- ``mc_error``: RMS posterior-mean error in units of the i.i.d. standard error
  sqrt(P / N): the filter's Monte-Carlo inefficiency, which a scrambled weight inflates.

Tolerances. The measured values (largest over objects and configurations) and the bounds:

=====================  ==========================  ==========================  ============
statistic              fast: N = 2000, 8 runs,     slow: N = 10000, 20 runs,   bound
                       zseed 1                     zseeds 1 and 3              fast / slow
=====================  ==========================  ==========================  ============
mean_t                 1.75                        1.60                        3.0 / 2.5
abs(var_ratio - 1)     0.06 (joint-pf 0.057)       0.011 (joint-pf 0.023)      0.10 / 0.04
                                                                               joint-pf
                                                                               0.15 / 0.08
mc_error               condensation 3.0,           condensation 2.9,           6 / 20 / 40
                       PS/DPS 9.4, joint-pf 16.8   PS/DPS 10.0, joint-pf 19.8  (both)
=====================  ==========================  ==========================  ============

The measurement sequence matters: over zseeds 0-7 at the fast setting, sequences with
large innovations (zseed 7) leave fewer effective particles and reach mc_error 26 (PS),
55 (joint-pf) and var_ratio 0.76-0.80 for the same correct code; zseeds 1 and 3 are the
well-conditioned ones, where the bounds have a margin of 2x or more. The variance
errors of the bugs below do not depend on the sequence (the Kalman variance does not).

The inefficiencies are the papers' point: Monte-Carlo error grows with the dimension of
the jointly weighted state (joint-pf, 12 dimensions here), PS cuts it by weighting one
object at a time, and condensation (3 independent 4-dimensional filters) is cheapest.

Each one-line error below fails the fast test in every configuration it touches
(checked by making the change in ``trackers/particle.py``, running this file, reverting):

- PS/DPS, weighted resampling without the pi / rho correction (``logpi`` not updated):
  the objects placed before the last are weighted twice; all 11 PS/DPS configurations
  fail (``mean_t`` 4-10; ``var_ratio`` 0.35-0.65 at zseed 0);
- PS/DPS, per-object likelihoods not re-indexed after weighted resampling (``ll``
  instead of ``ll[k]``): weights belong to other particles; all 11 fail (``var_ratio``
  0.71-1.38, ``mc_error`` 43-51);
- PS/DPS, the last stage's likelihood counted twice in the final weights: all 11 fail
  (``mean_t`` 4.5-8.8 or ``var_ratio`` 0.77-0.84);
- condensation, each likelihood counted twice (``2 * ll``), and joint-pf, the first
  object's likelihood counted twice: the one configuration of each fails.
"""

from __future__ import annotations

import linear_gaussian
import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

import trackers
from trackers.models.observation import PositionModel

SIGMA = 2.0      # dynamics noise, px per frame and coordinate
R_STD = 2.0      # measurement noise, px
T = 10           # frames: the init frame and 9 steps
START = np.array([[60.0, 50.0], [120.0, 70.0], [90.0, 130.0]])
K = len(START)


def measurements(zseed: int) -> np.ndarray:
    """z (T, K, 2): a constant-velocity track with noise sigma, measured with noise r."""
    return linear_gaussian.measurements(zseed, START, T, SIGMA, R_STD, salt=2024)


def kalman_posterior(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact posterior mean and variance (T - 1, K, 2) of every object's centre."""
    mean = np.empty((T - 1, K, 2))
    var = np.empty((T - 1, K, 2))
    for k in range(K):
        for c in range(2):
            kf = KalmanFilter(dim_x=2, dim_z=1)
            kf.x = np.array([z[0, k, c], z[0, k, c]])
            kf.P = np.zeros((2, 2))
            kf.F = np.array([[2.0, -1.0], [1.0, 0.0]])
            kf.Q = np.diag([SIGMA**2, 0.0])
            kf.H = np.array([[1.0, 0.0]])
            kf.R = np.array([[R_STD**2]])
            for t in range(1, T):
                kf.predict()
                kf.update(np.array([z[t, k, c]]))
                mean[t - 1, k, c] = kf.x[0]
                var[t - 1, k, c] = kf.P[0, 0]
    return mean, var


def particle_posterior(name: str, z: np.ndarray, n: int, seed: int, params: dict
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Weighted posterior mean and variance (T - 1, K, 2) of a filter's particle set."""
    boxes0 = np.column_stack([z[0] - 5.0, np.full((K, 2), 10.0)])
    frames = np.zeros((T, 200, 200, 3), np.uint8)  # the model never looks at pixels
    model = PositionModel(z, np.eye(2) * R_STD**2)
    tracker = trackers.make(name, n_particles=n, sigma=(SIGMA, SIGMA, 0.0),
                            observation=model, rng=seed, **params)
    tracker.init(frames[0], boxes0)
    mean = np.empty((T - 1, K, 2))
    var = np.empty((T - 1, K, 2))
    for t in range(1, T):
        tracker.step(frames[t])
        w = np.asarray(tracker.weights)
        w = w if w.ndim == 2 else np.repeat(w[:, None], K, axis=1)  # condensation: (N, K)
        x = tracker.particles[:, :, :2]
        m = np.einsum("nk,nkc->kc", w, x)
        mean[t - 1] = m
        var[t - 1] = np.einsum("nk,nkc->kc", w, (x - m) ** 2)
    return mean, var


def oracle_statistics(name: str, params: dict, n: int, reps: int, zseed: int):
    """Per object (K,): mean_t, var_ratio, mc_error (module docstring)."""
    z = measurements(zseed)
    km, kv = kalman_posterior(z)
    runs = [particle_posterior(name, z, n, 1000 + r, params) for r in range(reps)]
    means = np.array([m for m, _ in runs])
    vars_ = np.array([v for _, v in runs])
    err = (means - km) / np.sqrt(kv)                        # (reps, T - 1, K, 2)
    t_stat = err.mean(axis=0) / (err.std(axis=0, ddof=1) / np.sqrt(reps))
    mean_t = np.sqrt((t_stat**2).mean(axis=(0, 2)))
    var_ratio = (vars_ / kv).mean(axis=(0, 1, 3))
    mc_error = np.sqrt((err**2).mean(axis=(0, 1, 3)) * n)
    return mean_t, var_ratio, mc_error


CONFIGS = [
    ("condensation", {}),
    ("joint-pf", {}),
    ("ps", {"resampler": "systematic"}),
    ("ps", {"resampler": "multinomial"}),
    ("ps", {"resampler": "stratified"}),
    ("ps", {"resampler": "residual"}),
    ("ps", {"ordering": 1}),
    ("ps", {"ordering": 2}),
    ("ps", {"ordering": (1, 0, 2)}),
    ("ps", {"weighting": "placed"}),
    ("ps", {"weighting": "g-only", "ordering": 2}),
    ("ps", {"resample_scope": "placed"}),
    ("ps", {"resample_scope": "placed", "weighting": "placed", "ordering": 2}),
    ("dps", {"n_groups": 2}),                      # sizes 1000, 1000 (fast)
    ("dps", {"n_groups": 3}),                      # 667, 667, 666: unequal
    ("dps", {"n_groups": 7, "resampler": "stratified"}),   # 286 x 5, 285 x 2
    ("dps", {"n_groups": 3, "assignment": "interleaved", "resampler": "residual"}),
    ("dps", {"n_groups": 3, "assignment": "persistent"}),  # a mixture of three PS filters
    ("dps", {"n_groups": 3, "mixture": "prior"}),  # each group keeps its share
    ("dps", {"n_groups": 3, "assignment": "persistent", "mixture": "prior"}),
    ("dps", {"n_groups": 3, "weighting": "placed"}),
    ("dps", {"n_groups": 2, "weighting": "g-only", "resampler": "residual"}),
    ("dps", {"n_groups": 3, "resample_scope": "placed"}),
    ("dps", {"n_groups": 3, "resample_scope": "placed", "resampler": "residual"}),
]
IDS = [f"{name}-{'-'.join(f'{k}={v}' for k, v in p.items()) or 'default'}"
       for name, p in CONFIGS]

MC_BOUND = {"condensation": 6.0, "joint-pf": 40.0, "ps": 20.0, "dps": 20.0}


def check(name, params, n, reps, zseed, t_bound, var_bound):
    mean_t, var_ratio, mc_error = oracle_statistics(name, params, n, reps, zseed)
    if name == "joint-pf":
        var_bound *= 1.5 if var_bound > 0.05 else 2.0
    assert mean_t.max() <= t_bound, f"posterior mean off: t-RMS per object {mean_t}"
    assert np.abs(var_ratio - 1).max() <= var_bound, f"variance ratio per object {var_ratio}"
    assert mc_error.max() <= MC_BOUND[name], f"Monte-Carlo error per object {mc_error}"


@pytest.mark.parametrize(("name", "params"), CONFIGS, ids=IDS)
def test_posterior_matches_the_kalman_filter(name, params):
    check(name, params, n=2000, reps=8, zseed=1, t_bound=3.0, var_bound=0.10)


@pytest.mark.slow
@pytest.mark.parametrize("zseed", [1, 3])
@pytest.mark.parametrize(("name", "params"), CONFIGS, ids=IDS)
def test_posterior_matches_the_kalman_filter_sharply(name, params, zseed):
    check(name, params, n=10000, reps=20, zseed=zseed, t_bound=2.5, var_bound=0.04)


def test_the_kalman_reference_is_the_closed_form_first_step():
    # One step from a point prior: P = sigma^2, the posterior is the product of two
    # Gaussians; checks the reference itself.
    z = measurements(0)
    mean, var = kalman_posterior(z)
    gain = SIGMA**2 / (SIGMA**2 + R_STD**2)
    np.testing.assert_allclose(var[0], gain * R_STD**2)
    np.testing.assert_allclose(mean[0], START + gain * (z[1] - START))


@pytest.mark.parametrize("name", ["condensation", "joint-pf", "ps", "dps"])
def test_the_initial_set_is_the_init_boxes_at_rest_with_uniform_weights(name):
    z = measurements(0)
    boxes0 = np.column_stack([z[0] - 5.0, np.full((K, 2), 10.0)])
    tracker = trackers.make(name, n_particles=40, observation=PositionModel(z, np.eye(2)),
                            rng=0)
    tracker.init(np.zeros((T, 200, 200, 3), np.uint8)[0], boxes0)
    w = np.asarray(tracker.weights)
    assert w.shape == ((40, K) if name == "condensation" else (40,))
    np.testing.assert_array_equal(w, 1.0 / 40)
    np.testing.assert_array_equal(tracker.particles[:, :, :2], np.broadcast_to(z[0], (40, K, 2)))
    np.testing.assert_array_equal(tracker.particles[:, :, 2], 0.0)


def test_dps_takes_as_many_groups_as_particles():
    # One particle per mixture component (C = N = K): the smallest valid set.
    z = measurements(0)
    boxes0 = np.column_stack([z[0] - 5.0, np.full((K, 2), 10.0)])
    tracker = trackers.make("dps", n_particles=K, observation=PositionModel(z, np.eye(2)),
                            rng=0)
    tracker.init(np.zeros((200, 200, 3), np.uint8), boxes0)
    est = tracker.step(np.zeros((200, 200, 3), np.uint8))
    assert est.extras["mixture_weights"].shape == (K,)
    np.testing.assert_allclose(est.extras["mixture_weights"].sum(), 1.0)
