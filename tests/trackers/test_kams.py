"""KAMS (trackers.kams): the annealed PF plus mean shift."""

import numpy as np
import pytest

import trackers


def sequence(scenegen_sequence, n_frames):
    seq = scenegen_sequence("kams-b", seed=1, frames=n_frames)
    boxes = np.asarray(seq.gt.box[0])[[seq.target_indices()[0], 5]].astype(np.float64)
    return np.asarray(seq.frames), boxes


@pytest.mark.parametrize("schedule", ["adaptive", "geometric"])
def test_zero_mean_shift_iterations_is_the_annealed_filter(scenegen_sequence, schedule):
    frames, boxes = sequence(scenegen_sequence, 15)
    common = {"n_particles": 40, "n_layers": 3, "sigma": 10.0, "schedule": schedule, "rng": 21}
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
    obs = shifted.targets.observe(frames[1])
    # Mean shift only climbs: the shifted particles match their models better.
    d_plain = plain.targets.distances(obs, plain.particles)
    d_shifted = shifted.targets.distances(obs, shifted.particles)
    assert np.mean(d_shifted) < np.mean(d_plain)
