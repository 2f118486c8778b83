"""The annealed particle filter (trackers.annealed)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import trackers
from trackers.annealed import survival_beta, survival_rate, weighted_estimate
from trackers.filters.resampling import resample_groups
from trackers.models.observation import ColourModel


def first_frames_and_boxes(scenegen_sequence, n_frames=12):
    seq = scenegen_sequence("kams-a", seed=3, frames=n_frames)
    frames = np.asarray(seq.frames)
    # The target and one clutter disc: two independently tracked objects.
    boxes = np.asarray(seq.gt.box[0])[[seq.target_indices()[0], 1]].astype(np.float64)
    return frames, boxes


def bootstrap_filter(frames, boxes, *, n_particles, sigma, lam, seed):
    """Plain SIR with random-walk noise, written out from the shared parts."""
    rng = np.random.default_rng(seed)
    model = ColourModel("rgb", bins=10, kernel="cone", lam=lam)
    model.set_references(frames[0], boxes)
    k, n = len(boxes), n_particles
    size = np.repeat(boxes[:, None, 2:], n, axis=1)
    x = np.repeat((boxes[:, :2] + boxes[:, 2:] / 2)[:, None, :], n, axis=1)
    w = np.full((k, n), 1.0 / n)
    out = []
    h, wd = frames.shape[1:3]
    for frame in frames[1:]:
        idx = resample_groups(w.ravel(), np.full(k, n), method="systematic", rng=rng)
        x = x.reshape(k * n, 2)[idx].reshape(k, n, 2)
        x = x + sigma * rng.standard_normal(x.shape)
        x[..., 0] = np.clip(x[..., 0], 0, wd)
        x[..., 1] = np.clip(x[..., 1], 0, h)
        cand = np.concatenate([x - size / 2, size], axis=-1).reshape(k * n, 4)
        ll = model.observe(frame).log_likelihoods(cand, np.repeat(np.arange(k), n))
        ll = ll.reshape(k, n)
        w = np.exp(ll - ll.max(axis=1, keepdims=True))
        w /= w.sum(axis=1, keepdims=True)
        centre = (w[..., None] * x).sum(axis=1)
        out.append(np.concatenate([centre - boxes[:, 2:] / 2, boxes[:, 2:]], axis=1))
    return np.array(out)


@pytest.mark.parametrize("schedule", ["adaptive", "geometric"])
def test_one_layer_with_beta_one_is_the_bootstrap_filter(scenegen_sequence, schedule):
    frames, boxes = first_frames_and_boxes(scenegen_sequence)
    tracker = trackers.make("annealed", n_particles=60, n_layers=1, sigma=7.0, lam=50.0,
                            schedule=schedule, rng=11)
    result = trackers.track(tracker, frames, boxes)
    expected = bootstrap_filter(frames, boxes, n_particles=60, sigma=7.0, lam=50.0, seed=11)
    np.testing.assert_allclose(result.boxes[1:], expected, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(result.extras["beta"][1:], 1.0)


def test_geometric_schedule_and_per_layer_noise(scenegen_sequence):
    frames, boxes = first_frames_and_boxes(scenegen_sequence, n_frames=4)
    tracker = trackers.make("annealed", n_layers=4, schedule="geometric", beta_ratio=0.3,
                            sigma=[9.0, 5.0, 2.0, 1.0], rng=0)
    np.testing.assert_array_equal(tracker.sigmas, [9.0, 5.0, 2.0, 1.0])
    result = trackers.track(tracker, frames, boxes)
    np.testing.assert_allclose(result.extras["beta"][1:], np.broadcast_to(
        [0.3**3, 0.3**2, 0.3, 1.0], (3, 2, 4)))
    decayed = trackers.make("annealed", n_layers=3, sigma=12.0, sigma_decay=0.5)
    np.testing.assert_array_equal(decayed.sigmas, [12.0, 6.0, 3.0])


def test_adaptive_beta_keeps_the_survival_rate():
    rng = np.random.default_rng(4)
    log_lik = -200.0 * rng.uniform(0.0, 0.5, (6, 80)) ** 2
    log_lik[0] = -0.001 * rng.uniform(size=80)  # flat: β = 1 keeps it above alpha
    beta = survival_beta(log_lik, 0.5)
    assert beta[0] == 1.0
    rate = survival_rate(beta[:, None] * log_lik)
    assert np.all(rate >= 0.5)
    assert np.all(rate[1:] < 0.51)  # the search's precision
    assert np.all(beta[1:] < 1.0)


def test_same_seed_same_result_other_seed_differs(scenegen_sequence):
    frames, boxes = first_frames_and_boxes(scenegen_sequence, n_frames=6)
    runs = [trackers.track(trackers.make("annealed", rng=s), frames, boxes).boxes
            for s in (5, 5, 6)]
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"n_particles": 0}, "n_particles"),
        ({"n_layers": 0}, "n_layers"),
        ({"lam": 0.0}, "lam"),
        ({"sigma": [1.0, 2.0]}, "sigma"),
        ({"sigma": -1.0}, "sigma"),
        ({"sigma_decay": 0.0}, "sigma_decay"),
        ({"schedule": "linear"}, "adaptive, geometric"),
        ({"estimate": "median"}, "mean, mode"),
        ({"alpha": 1.0}, "alpha"),
        ({"beta_ratio": 1.5}, "beta_ratio"),
        ({"resampler": "best"}, "systematic"),
        ({"kernel": "gauss"}, "cone"),
        ({"bins": 0}, "bins"),
    ],
)
def test_bad_parameters_raise_value_error(params, message):
    with pytest.raises(ValueError, match=message):
        trackers.make("annealed", **params)


def test_mode_estimate_ignores_a_second_mode():
    particles = np.array([[[10.0, 10.0], [11.0, 10.0], [60.0, 10.0], [61.0, 10.0]]])
    weights = np.array([[0.3, 0.3, 0.2, 0.2]])
    np.testing.assert_allclose(weighted_estimate(particles, weights), [[30.5, 10.0]])
    np.testing.assert_allclose(weighted_estimate(particles, weights, np.array([15.0])),
                               [[10.5, 10.0]])


def test_mode_estimate_is_the_mean_when_the_set_is_one_mode(scenegen_sequence):
    frames, boxes = first_frames_and_boxes(scenegen_sequence, n_frames=5)
    mean = trackers.make("annealed", n_particles=30, sigma=2.0, rng=3)
    mode = trackers.make("annealed", n_particles=30, sigma=2.0, estimate="mode", rng=3)
    for tracker in (mean, mode):
        tracker.init(frames[0], boxes)
    for frame in frames[1:]:
        a, b = mean.step(frame), mode.step(frame)
        # σ = 2 px keeps every particle well within the mode radius (15 px).
        np.testing.assert_allclose(a.boxes, b.boxes, atol=1e-9)


@settings(max_examples=10, deadline=None)
@given(
    n_layers=st.integers(1, 4),
    schedule=st.sampled_from(["adaptive", "geometric"]),
    alpha=st.floats(0.1, 0.9),
    beta_ratio=st.floats(0.05, 1.0),
    lam=st.sampled_from([20.0, 1000.0]),
    seed=st.integers(0, 2**32 - 1),
)
def test_layers_keep_valid_betas_weights_and_particles(scenegen_sequence, n_layers, schedule,
                                                       alpha, beta_ratio, lam, seed):
    frames, boxes = first_frames_and_boxes(scenegen_sequence, n_frames=4)
    tracker = trackers.make("annealed", n_particles=20, n_layers=n_layers, schedule=schedule,
                            alpha=alpha, beta_ratio=beta_ratio, lam=lam, rng=seed)
    result = trackers.track(tracker, frames, boxes)
    beta = result.extras["beta"][1:]
    assert beta.shape == (3, 2, n_layers)
    assert np.all((beta > 0) & (beta <= 1)) and np.all(beta[..., -1] == 1.0)
    np.testing.assert_allclose(tracker.weights.sum(axis=0), 1.0, atol=1e-12)
    h, w = frames.shape[1:3]
    assert np.all((tracker.particles >= 0) & (tracker.particles <= [w, h]))


@pytest.mark.parametrize("alpha", [0.2, 0.5, 0.8])
def test_the_chosen_beta_never_exceeds_the_survival_rule_on_many_sets(alpha):
    # Wherever the rate crosses alpha (in any of the fine grid's intervals, the last
    # included), the chosen β keeps a rate >= alpha, and a β 2 % larger would not.
    rng = np.random.default_rng(11)
    log_lik = -rng.uniform(50.0, 2000.0, (400, 1)) * rng.uniform(0.0, 0.5, (400, 60)) ** 2
    beta = survival_beta(log_lik, alpha)
    assert np.all(survival_rate(beta[:, None] * log_lik) >= alpha)
    inner = beta < 1.0
    assert inner.sum() > 300
    assert np.all(survival_rate((1.02 * beta[inner])[:, None] * log_lik[inner]) < alpha)


def test_layer_noise_may_be_zero_and_then_the_window_stays_at_the_box():
    # A box that is not square; without noise every particle stays at its centre.
    frame = np.full((90, 120, 3), 255, np.uint8)
    frame[30:44, 40:76] = (230, 30, 30)
    box = np.array([[40.0, 30.0, 36.0, 14.0]])
    for name in ("annealed", "kams"):
        tracker = trackers.make(name, sigma=0.0, n_particles=7, rng=0)
        tracker.init(frame, box)
        np.testing.assert_allclose(tracker.weights, np.full((7, 1), 1.0 / 7))
        est = tracker.step(frame)
        np.testing.assert_allclose(est.boxes, box, atol=1e-9)
