"""The papers' equivalences and measures as tests (DPS paper §3, MacCormick & Blake 2000).

- DPS with one mixture component is PS with the identity ordering, draw for draw;
- PS with one object is Condensation, and so is the joint PF with one object;
- weighted resampling (§3.2) leaves the represented distribution unchanged: weighted
  moments before and after agree, over many seeds, to a bounded z-score; plain resampling
  is unbiased for weighted moments too;
- uniqueness and effective dynamics (§3.1) on hand-made particle sets.
"""

from __future__ import annotations

import numpy as np
import pytest

from trackers.filters.diagnostics import effective_dynamics, uniqueness
from trackers.filters.resampling import (
    RESAMPLERS,
    resample_groups,
    weighted_resample,
    weighted_resample_groups,
)
from trackers.particle import (
    Condensation,
    DistributedPartitionedSampling,
    JointPF,
    PartitionedSampling,
)

COLOURS = [((220, 40, 40), (40, 60, 200)), ((30, 160, 60), (250, 220, 60)),
           ((200, 40, 200), (90, 230, 230))]


def scene(n_objects: int, n_frames: int = 5, seed: int = 0):
    """Two-colour 20x20 squares drifting on noise; frames (T, H, W, 3), boxes0 (K, 4)."""
    rng = np.random.default_rng(seed)
    h, w = 80, 110
    start = np.array([[15.0, 15.0], [70.0, 20.0], [30.0, 50.0]])[:n_objects]
    vel = rng.uniform(-1.5, 1.5, (n_objects, 2))
    frames = []
    for t in range(n_frames):
        f = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
        for k, (x, y) in enumerate(np.round(start + t * vel).astype(int)):
            f[y:y + 10, x:x + 20] = COLOURS[k][0]
            f[y + 10:y + 20, x:x + 20] = COLOURS[k][1]
        frames.append(f)
    return np.stack(frames), np.column_stack([start, np.full((n_objects, 2), 20.0)])


def run(tracker, frames, boxes0):
    """(particles, weights, boxes) after every step."""
    tracker.init(frames[0], boxes0)
    out = []
    for f in frames[1:]:
        est = tracker.step(f)
        out.append((tracker.particles.copy(), np.array(tracker.weights), est.boxes.copy()))
    return out


def assert_same(a, b, *, weights_b=lambda w: w):
    for (pa, wa, ba), (pb, wb, bb) in zip(a, b, strict=True):
        np.testing.assert_array_equal(pa, pb)
        np.testing.assert_array_equal(np.ravel(wa), np.ravel(weights_b(wb)))
        np.testing.assert_array_equal(ba, bb)


@pytest.mark.parametrize("resampler", RESAMPLERS)
@pytest.mark.parametrize("assignment", ["random", "interleaved"])
def test_dps_with_one_group_is_ps_draw_for_draw(resampler, assignment):
    frames, boxes0 = scene(3)
    params = dict(n_particles=70, resampler=resampler, rng=4, model="rgb", bins=6)
    a = run(DistributedPartitionedSampling(n_groups=1, assignment=assignment, **params),
            frames, boxes0)
    b = run(PartitionedSampling(ordering=0, **params), frames, boxes0)
    assert_same(a, b)
    dps = DistributedPartitionedSampling(n_groups=1, assignment=assignment, **params)
    dps.init(frames[0], boxes0)
    np.testing.assert_array_equal(dps.step(frames[1]).extras["mixture_weights"], [1.0])


@pytest.mark.parametrize("resampler", RESAMPLERS)
def test_ps_with_one_object_is_condensation_and_so_is_the_joint_pf(resampler):
    frames, boxes0 = scene(1)
    params = dict(n_particles=60, resampler=resampler, rng=9, model="rgb", bins=6)
    ps = run(PartitionedSampling(**params), frames, boxes0)
    cond = run(Condensation(**params), frames, boxes0)
    joint = run(JointPF(**params), frames, boxes0)
    assert_same(ps, cond)
    assert_same(joint, cond)
    # DPS with one object: every component has the same ordering (0,), the reassembled
    # set is not the same draw, but it is one object's filter all the same.
    dps = DistributedPartitionedSampling(n_groups=3, **params)
    dps.init(frames[0], boxes0)
    assert dps._orders.tolist() == [[0], [0], [0]]


def _moments(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted E[f(x)] for f = x, x^2, sin 3x, 1[x > 0.5]; shape (4,)."""
    w = w / w.sum()
    return np.array([w @ x, w @ x**2, w @ np.sin(3 * x), w @ (x > 0.5)])


def _moment_z_scores(method: str, sizes: np.ndarray, n_seeds: int, weighted: bool):
    """z-scores (C, 4) of the mean change of each group's weighted moments over seeds."""
    starts = np.cumsum(sizes) - sizes
    diffs = []
    for seed in range(n_seeds):
        rng = np.random.default_rng([seed, 17])
        n = int(sizes.sum())
        x = rng.normal(0.0, 1.0, n)
        pi = rng.gamma(2.0, 1.0, n)
        g = 0.2 + np.exp(-((x - 1.0) ** 2))  # away from the bulk, bounded below
        if weighted:
            idx, w = weighted_resample_groups(pi, g, sizes, method=method, rng=rng)
        else:
            idx = resample_groups(pi, sizes, method=method, rng=rng)
            w = np.ones(n)
        d = [_moments(x[idx][s:s + m], w[s:s + m]) - _moments(x[s:s + m], pi[s:s + m])
             for s, m in zip(starts, sizes, strict=True)]
        diffs.append(d)
    diffs = np.array(diffs)  # (seeds, C, 4)
    se = diffs.std(axis=0, ddof=1) / np.sqrt(n_seeds)
    return diffs.mean(axis=0) / se, np.abs(diffs).mean(axis=0)


@pytest.mark.parametrize("method", RESAMPLERS)
@pytest.mark.parametrize("sizes", [(150,), (40, 73, 17)])
def test_weighted_resampling_preserves_weighted_moments(method, sizes):
    z, _ = _moment_z_scores(method, np.array(sizes), 120, weighted=True)
    # Measured over these seeds: |z| <= 2.9 for every scheme, group and moment; a
    # missing pi / rho correction gives |z| > 40.
    assert np.abs(z).max() < 4.5, z


@pytest.mark.parametrize("method", RESAMPLERS)
def test_plain_resampling_is_unbiased_for_weighted_moments(method):
    z, _ = _moment_z_scores(method, np.array([60, 45]), 120, weighted=False)
    assert np.abs(z).max() < 4.5, z


def test_weighted_resampling_weights_are_pi_over_rho_exactly():
    rng = np.random.default_rng(3)
    pi = rng.gamma(2.0, 1.0, 9)
    g = rng.uniform(0.1, 2.0, 9)
    for method in RESAMPLERS:
        idx, w = weighted_resample(pi, g, method=method, rng=rng)
        rho = pi * g / (pi * g).sum()
        expected = (pi / pi.sum())[idx] / rho[idx]
        np.testing.assert_allclose(w, expected / expected.sum(), rtol=1e-12)


def test_uniqueness_counts_distinct_sub_states():
    p = np.zeros((6, 3, 3))
    # Object 0: one hypothesis copied six times.
    p[:, 0] = (4.0, 5.0, 0.0)
    # Object 1: u equal, v differs for three, a differs for one more: 4 distinct rows.
    p[:, 1] = (1.0, 2.0, 0.0)
    p[1, 1, 1] = 3.0
    p[2, 1, 1] = 4.0
    p[3, 1, 1] = 4.0          # a copy of row 2
    p[4, 1, 2] = 0.01
    # Object 2: all distinct, some sharing u only.
    p[:, 2, 0] = (0.0, 0.0, 1.0, 1.0, 2.0, 3.0)
    p[:, 2, 1] = (0.0, 1.0, 0.0, 1.0, 0.0, 0.0)
    np.testing.assert_array_equal(uniqueness(p), [1 / 6, 4 / 6, 1.0])
    np.testing.assert_array_equal(uniqueness(p[::-1]), [1 / 6, 4 / 6, 1.0])


def test_effective_dynamics_is_the_unweighted_variance_over_sigma_squared():
    p = np.zeros((4, 2, 3))
    p[:, 0, 0] = (0.0, 2.0, 4.0, 6.0)        # variance 5
    p[:, 0, 1] = (1.0, 1.0, 1.0, 1.0)        # variance 0
    p[:, 1, 0] = (1.0, -1.0, 1.0, -1.0)      # variance 1
    p[:, 1, 1] = (3.0, 3.0, 0.0, 0.0)        # variance 2.25
    p[:, 1, 2] = (0.1, 0.1, 0.1, 0.5)        # variance 0.03
    eff = effective_dynamics(p, (2.0, 0.5, 0.1))
    np.testing.assert_allclose(eff, [[5 / 4, 0.0, 0.0], [1 / 4, 2.25 / 0.25, 3.0]], rtol=1e-12)
    # σ = 0: no spread for the sampler to thin, 1 (0 / 0 was NaN).
    still = effective_dynamics(p, (1.0, 1.0, 0.0))
    assert still[:, 2].tolist() == [1.0, 1.0] and np.isfinite(still[:, :2]).all()


def test_tracker_diagnostics_are_the_measures_of_its_particle_set():
    frames, boxes0 = scene(2)
    tracker = PartitionedSampling(n_particles=80, rng=2, model="rgb", bins=6,
                                  sigma=(2.0, 3.0, 0.01))
    tracker.init(frames[0], boxes0)
    for f in frames[1:]:
        est = tracker.step(f)
        np.testing.assert_array_equal(est.extras["uniqueness"], uniqueness(tracker.particles))
        eff = effective_dynamics(tracker.particles, (2.0, 3.0, 0.01))
        np.testing.assert_allclose(est.extras["effective_dynamics"], eff[:, :2].mean(axis=1),
                                   rtol=1e-12)
    # PS impoverishes the object placed first: it went through one more weighted
    # resampling since it was propagated.
    assert est.extras["uniqueness"][0] < est.extras["uniqueness"][1]
