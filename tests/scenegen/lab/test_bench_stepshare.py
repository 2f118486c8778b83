"""The bench row of a tracker's step against its own histogram stage."""

from __future__ import annotations

import numpy as np

from scenegen.lab.bench.stepshare import histogram_clock
from trackers.models import observation
from trackers.registry import make


def test_histogram_clock_times_the_observation_calls_and_restores_them():
    before = observation.FrameObservation.__dict__["distances"]
    rng = np.random.default_rng(0)
    frames = rng.integers(0, 256, (3, 60, 80, 3), dtype=np.uint8)
    tracker = make("dps", n_particles=50, rng=0)
    tracker.init(frames[0], np.array([[20.0, 20.0, 16.0, 16.0]]))
    with histogram_clock() as spent:
        assert observation.FrameObservation.__dict__["distances"] is not before
        for f in frames[1:]:
            tracker.step(f)
    assert spent[0] > 0.0
    assert observation.FrameObservation.__dict__["distances"] is before
    with histogram_clock() as idle:
        pass
    assert idle[0] == 0.0
