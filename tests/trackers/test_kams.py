"""KAMS (trackers.kams): the annealed PF plus mean shift."""

import numpy as np
import pytest

import trackers
from scenegen.evaluation.metrics import centre_error, tracked_fraction
from trackers.meanshift import set_distances


def sequence(scenegen_sequence, n_frames):
    seq = scenegen_sequence("kams-b", seed=1, frames=n_frames)
    boxes = np.asarray(seq.gt.box[0])[[seq.target_indices()[0], 5]].astype(np.float64)
    return np.asarray(seq.frames), boxes


@pytest.mark.parametrize("schedule", ["adaptive", "geometric"])
def test_zero_mean_shift_iterations_is_the_annealed_filter(scenegen_sequence, schedule):
    frames, boxes = sequence(scenegen_sequence, 15)
    common = {"n_particles": 40, "n_layers": 3, "sigma": 10.0, "schedule": schedule,
              "alpha": 0.6, "rng": 21}
    kams = trackers.track(trackers.make("kams", max_iter=0, **common), frames, boxes)
    annealed = trackers.track(trackers.make("annealed", **common), frames, boxes)
    np.testing.assert_array_equal(kams.boxes, annealed.boxes)
    for key in annealed.extras:
        np.testing.assert_array_equal(kams.extras[key], annealed.extras[key])


def test_mean_shift_moves_the_particles_onto_modes(scenegen_sequence):
    frames, boxes = sequence(scenegen_sequence, 2)
    plain = trackers.make("kams", max_iter=0, rng=4)
    shifted = trackers.make("kams", max_iter=10, rng=4)
    for tracker in (plain, shifted):
        tracker.init(frames[0], boxes)
        tracker.step(frames[1])
    obs = shifted.model.observe(frames[1])
    # Mean shift only climbs: the shifted particles match their models better.
    d_plain = set_distances(obs, plain.particles.swapaxes(0, 1), plain.sizes)
    d_shifted = set_distances(obs, shifted.particles.swapaxes(0, 1), shifted.sizes)
    assert np.mean(d_shifted) < np.mean(d_plain)


def tracked_fractions(scenegen_sequence, preset, name, seeds, **params):
    """Proportion of each run tracked before failure (see test_meanshift_scenes.py for
    "tracks to the end": the error never stays above the 15 px radius for 5 frames)."""
    out = []
    for seed in seeds:
        seq = scenegen_sequence(preset, seed=seed)
        k = seq.target_indices()[0]
        gt = np.asarray(seq.gt.box[:, k], dtype=np.float64)
        result = trackers.track(trackers.make(name, rng=seed, **params),
                                np.asarray(seq.frames), gt[:1])
        out.append(tracked_fraction(centre_error(result.boxes[:, 0], gt), 15.0))
    return np.array(out)


@pytest.mark.slow
def test_kams_with_40_particles_tracks_kams_d_to_the_end_in_most_runs(scenegen_sequence):
    # Measured: 8/10 runs tracked to the end on seeds 0-9 (16/20 on seeds 0-19; mean
    # tracked fraction 0.85). The other trackers of the family track none of seeds 0-9.
    fractions = tracked_fractions(scenegen_sequence, "kams-d", "kams", range(10),
                                  n_particles=40)
    assert np.mean(fractions == 1.0) >= 0.5


def test_kams_tracks_kams_d_to_the_end_on_three_seeds(scenegen_sequence):
    # The fast suite's share of the test above: seeds where kams tracks to the end.
    fractions = tracked_fractions(scenegen_sequence, "kams-d", "kams", range(3),
                                  n_particles=40)
    assert np.all(fractions == 1.0), fractions


@pytest.mark.slow
def test_kams_tracks_kams_d_longer_than_the_annealed_filter(scenegen_sequence):
    # The paper's robustness claim, with the same 40 particles and 3 layers (measured
    # mean tracked fraction over seeds 0-7: kams 0.81, annealed 0.22).
    seeds = range(8)
    kams = tracked_fractions(scenegen_sequence, "kams-d", "kams", seeds, n_particles=40)
    annealed = tracked_fractions(scenegen_sequence, "kams-d", "annealed", seeds,
                                 n_particles=40)
    assert kams.mean() > annealed.mean()
