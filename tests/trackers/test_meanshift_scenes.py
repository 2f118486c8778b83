"""The mean-shift family on the KAMS accuracy sequences (scenegen presets kams-a … kams-d).

"Tracks to the end" (ALGORITHMS §4.6, "a run fails when the error stays above a
threshold"): ``scenegen.metrics.failure_frame(error, 15, persist=5) == -1``, i.e. the
distance between the estimated and the true centre of the target never stays above the
target's radius (15 px: the kams target is a 30 px disc) for 5 consecutive frames, up to
the last frame. A shorter excursion, e.g. onto a clutter disc for a frame or two, is not a
failure.

Measured with the default parameters on kams-a, scene seed = tracker seed = 0 … 9 (runs
tracked to the end): meanshift 3/10, sok 8/10, annealed 7/10, hybrid 9/10, kams 10/10.
The kams clutter is drawn from the target's own four-colour palette and about one disc in
ten has four distinct colours, i.e. the target's colour histogram exactly, so a
colour-histogram tracker can only keep to the target by staying close to it, and plain
mean shift, with no search beyond its window, is lost on most sequences. So the test of
every tracker pins scene seed 7, where all of them track to the end; kams, the paper's
claim, is tested on five seeds.
"""

import numpy as np
import pytest

import trackers
from scenegen.metrics import centre_error, failure_frame

RADIUS = 15.0


def run(scenegen_sequence, preset, seed, name, **params):
    seq = scenegen_sequence(preset, seed=seed)
    k = seq.target_indices()[0]
    gt = np.asarray(seq.gt.box[:, k], dtype=np.float64)
    tracker = trackers.make(name, rng=seed, **params)
    result = trackers.track(tracker, np.asarray(seq.frames), gt[:1])
    return centre_error(result.boxes[:, 0], gt)


@pytest.mark.parametrize("name", ["meanshift", "sok", "annealed", "hybrid", "kams"])
def test_every_tracker_tracks_kams_a_to_the_end(scenegen_sequence, name):
    error = run(scenegen_sequence, "kams-a", 7, name)
    assert failure_frame(error, RADIUS) == -1
    assert np.mean(error) < 5.0


def test_kams_tracks_kams_a_to_the_end_on_every_seed(scenegen_sequence):
    for seed in range(5):
        error = run(scenegen_sequence, "kams-a", seed, "kams", n_particles=40)
        assert failure_frame(error, RADIUS) == -1, f"kams lost the target, seed {seed}"
        assert np.mean(error) < 3.0
