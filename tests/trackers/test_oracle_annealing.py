"""Oracle: the annealing schedule of the annealed PF and KAMS (Deutscher, Blake & Reid 2000).

- adaptive schedule: every layer weights by w^beta with the beta chosen for the survival
  rate alpha = 1 / (N sum w^2) of the normalised weights (to 1 %; measured at most
  0.43 % for the annealed PF, 0.71 % for KAMS, alpha = 0.3, 0.5, 0.8), except where that
  would lower beta below the previous layer's (then beta stays, and the rate is below
  alpha); the weights reported are the weights the layer resampled by, recomputed here
  from the particles the layer weighted;
- beta never decreases from layer to layer and the last layer's is 1;
- one layer with beta = 1 is the bootstrap (SIR) filter, draw for draw, every resampler.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import trackers
from trackers.annealed import AnnealedPF, survival_rate
from trackers.filters.resampling import RESAMPLERS, resample_groups
from trackers.kams import KAMS
from trackers.meanshift import set_log_likelihoods
from trackers.models.observation import ColourModel


def scene(n_frames: int = 8, seed: int = 0):
    """Two-colour discs on a smooth colourful background: a target moving 4 px a frame
    and a similar distractor. Frames (T, H, W, 3) and initial boxes (2, 4)."""
    rng = np.random.default_rng(seed)
    h, w = 90, 120
    small = rng.integers(0, 256, (h // 10 + 2, w // 10 + 2, 3)).astype(np.float32)
    bg = cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC).clip(0, 255)
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    frames = np.empty((n_frames, h, w, 3), np.uint8)
    for t in range(n_frames):
        f = bg.copy()
        for cx, cy, top, bottom in ((25.0 + 4 * t, 40.0, (230, 40, 40), (40, 40, 220)),
                                    (85.0, 50.0, (210, 60, 50), (60, 50, 200))):
            disc = (xx - cx) ** 2 + (yy - cy) ** 2 < 10.0**2
            f[disc & (yy < cy)] = top
            f[disc & (yy >= cy)] = bottom
        frames[t] = np.clip(f + rng.normal(0, 4.0, f.shape), 0, 255).astype(np.uint8)
    boxes0 = np.array([[15.0, 30.0, 20.0, 20.0], [75.0, 40.0, 20.0, 20.0]])
    return frames, boxes0


def recording(cls):
    """A subclass that records, per layer, the log-likelihoods of the particles it weights
    (through the documented ``_move`` hook, after the move)."""

    class Recording(cls):
        def _init(self, frame, boxes):
            super()._init(frame, boxes)
            self.layers = []

        def _move(self, obs, sets):
            super()._move(obs, sets)
            self.layers.append(set_log_likelihoods(obs, sets.copy(), self.sizes))

    return Recording


def run_layers(cls, params, frames, boxes0):
    tracker = recording(cls)(**params)
    tracker.init(frames[0], boxes0)
    out = []
    for frame in frames[1:]:
        tracker.layers.clear()
        est = tracker.step(frame)
        out.append((est.extras["beta"], est.extras["survival"], list(tracker.layers)))
    return out


# KAMS's mean shift packs the particles on the disc, where d is nearly 0: a sharper
# likelihood keeps its betas below 1 (at lam = 1000 every layer already keeps alpha at 1).
@pytest.mark.parametrize(("cls", "lam"), [(AnnealedPF, 200.0), (KAMS, 20000.0)],
                         ids=["annealed", "kams"])
@pytest.mark.parametrize("alpha", [0.3, 0.5, 0.8])
def test_adaptive_layers_keep_the_survival_rate_they_were_chosen_for(cls, lam, alpha):
    frames, boxes0 = scene()
    params = dict(n_particles=120, n_layers=4, alpha=alpha, lam=lam, sigma=8.0, rng=3)
    n_exact = n_held = 0
    for beta, survival, layers in run_layers(cls, params, frames, boxes0):
        # beta: non-decreasing along the layers, 1 at the last.
        assert np.all(np.diff(beta, axis=1) >= 0)
        np.testing.assert_array_equal(beta[:, -1], 1.0)
        for j, log_lik in enumerate(layers):
            # The reported rate is that of the weights w^beta of the particles weighted.
            np.testing.assert_allclose(survival[:, j], survival_rate(beta[:, j, None] * log_lik),
                                       rtol=1e-9)
            if j == len(layers) - 1:
                continue
            # beta = 1 already keeps the rate (a flat layer), or beta was held.
            held = (beta[:, j] == (beta[:, j - 1] if j else -1.0)) & (beta[:, j] < 1.0)
            chosen = ~held & (beta[:, j] < 1.0)
            np.testing.assert_allclose(survival[chosen, j], alpha, rtol=0.01)
            # A layer whose beta was held at the previous one's: the rule wanted less.
            assert np.all(survival[held, j] <= alpha * 1.01)
            n_exact += chosen.sum()
            n_held += held.sum()
    assert n_exact >= 20


def test_beta_is_held_where_the_survival_rule_would_lower_it():
    frames, boxes0 = scene()
    params = dict(n_particles=120, n_layers=4, alpha=0.5, lam=20000.0, sigma=8.0,
                  sigma_decay=1.0, rng=3)
    held = 0
    for beta, survival, layers in run_layers(KAMS, params, frames, boxes0):
        assert np.all(np.diff(beta, axis=1) >= 0)
        for j in range(1, len(layers) - 1):
            same = (beta[:, j] == beta[:, j - 1]) & (beta[:, j] < 1.0)
            held += same.sum()
            assert np.all(survival[same, j] <= 0.505)
    # With constant noise, mean shift spreads the particles again: the rule would have
    # lowered beta at least once here (measured: 20 times).
    assert held >= 3


def test_geometric_schedule_uses_beta_ratio_powers():
    frames, boxes0 = scene(n_frames=4)
    params = dict(n_particles=80, n_layers=3, schedule="geometric", beta_ratio=0.4,
                  lam=200.0, rng=1)
    for beta, survival, layers in run_layers(AnnealedPF, params, frames, boxes0):
        np.testing.assert_allclose(beta, np.broadcast_to([0.16, 0.4, 1.0], beta.shape),
                                   rtol=1e-15)
        for j, log_lik in enumerate(layers):
            np.testing.assert_allclose(survival[:, j],
                                       survival_rate(beta[:, j, None] * log_lik), rtol=1e-9)


def bootstrap(frames, boxes0, *, n, sigma, lam, resampler, seed):
    """SIR with random-walk noise ``sigma``, written from the shared parts."""
    rng = np.random.default_rng(seed)
    model = ColourModel("rgb", bins=10, kernel="cone", lam=lam)
    model.set_references(frames[0], boxes0)
    k = len(boxes0)
    size = np.repeat(boxes0[:, None, 2:], n, axis=1)
    x = np.repeat((boxes0[:, :2] + boxes0[:, 2:] / 2)[:, None, :], n, axis=1)
    w = np.full((k, n), 1.0 / n)
    h, wd = frames.shape[1:3]
    out = []
    for frame in frames[1:]:
        idx = resample_groups(w.ravel(), np.full(k, n), method=resampler, rng=rng)
        x = x.reshape(k * n, 2)[idx].reshape(k, n, 2)
        x = x + sigma * rng.standard_normal(x.shape)
        x[..., 0] = np.clip(x[..., 0], 0, wd)
        x[..., 1] = np.clip(x[..., 1], 0, h)
        cand = np.concatenate([x - size / 2, size], axis=-1).reshape(k * n, 4)
        ll = model.observe(frame).log_likelihoods(cand, np.repeat(np.arange(k), n))
        w = np.exp(ll.reshape(k, n) - ll.reshape(k, n).max(axis=1, keepdims=True))
        w /= w.sum(axis=1, keepdims=True)
        out.append((x.copy(), w.copy()))
    return out


@pytest.mark.parametrize("resampler", RESAMPLERS)
def test_one_layer_with_beta_one_is_the_bootstrap_filter(resampler):
    frames, boxes0 = scene(n_frames=5)
    tracker = trackers.make("annealed", n_particles=50, n_layers=1, sigma=6.0, lam=80.0,
                            resampler=resampler, rng=7)
    tracker.init(frames[0], boxes0)
    expected = bootstrap(frames, boxes0, n=50, sigma=6.0, lam=80.0, resampler=resampler,
                         seed=7)
    for frame, (x, w) in zip(frames[1:], expected, strict=True):
        est = tracker.step(frame)
        np.testing.assert_array_equal(est.extras["beta"], 1.0)
        # The tracker's sets are (N, K, 2) and (N, K); the reference's object-major.
        np.testing.assert_allclose(tracker.particles, x.swapaxes(0, 1), rtol=0, atol=1e-12)
        np.testing.assert_allclose(tracker.weights, w.swapaxes(0, 1), rtol=1e-12,
                                   atol=1e-300)


def test_mode_estimate_and_confidence_are_computed_from_the_final_layer():
    # Targets of different sizes: the mode radius is half of each target's own smaller
    # side; the confidence is 1 - d of the estimated window, scored independently here.
    frames, boxes0 = scene(n_frames=5)
    boxes0 = boxes0.copy()
    boxes0[1, 2:] = (36.0, 30.0)
    tracker = trackers.make("annealed", n_particles=80, n_layers=2, sigma=10.0, lam=10.0,
                            estimate="mode", rng=2)
    tracker.init(frames[0], boxes0)
    model = ColourModel("rgb", bins=10, kernel="cone", lam=10.0)
    ring = 0.0
    model.set_references(frames[0], boxes0)
    for frame in frames[1:]:
        est = tracker.step(frame)
        x, w = tracker.particles.swapaxes(0, 1), tracker.weights.swapaxes(0, 1)  # (K, N)
        for k, radius in enumerate((10.0, 15.0)):
            best = x[k, np.argmax(w[k])]
            r = np.hypot(*(x[k] - best).T)
            near = r <= radius
            ring += w[k, (r > radius - 5.0) & near].sum()
            centre = (w[k, near, None] * x[k, near]).sum(axis=0) / w[k, near].sum()
            np.testing.assert_allclose(est.boxes[k, :2] + est.boxes[k, 2:] / 2, centre,
                                       rtol=0, atol=1e-9)
        d = model.observe(frame).distances(est.boxes, np.arange(2))
        np.testing.assert_allclose(est.extras["confidence"], 1.0 - d, rtol=0, atol=1e-9)
    assert ring > 0.05  # the radius matters: weight lies near the edge of the mode
