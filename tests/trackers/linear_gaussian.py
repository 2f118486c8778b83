"""The linear-Gaussian scene shared by the particle-filter oracle tests.

Objects move by constant velocity with N(0, sigma^2) noise per frame and coordinate and
are measured with N(0, r^2) noise; the filters see them through
``trackers.models.observation.PositionModel``. Imported by the test modules beside it.
"""

from __future__ import annotations

import numpy as np


def measurements(zseed: int, start: np.ndarray, n_frames: int, sigma: float, r_std: float,
                 salt: int) -> np.ndarray:
    """z (n_frames, K, 2): a constant-velocity track of each of the K ``start`` centres
    (K, 2), with noise ``sigma``, measured with noise ``r_std``; frame 0 is ``start``."""
    rng = np.random.default_rng([zseed, salt])
    k = start.shape[0]
    truth = np.empty((n_frames, k, 2))
    truth[0] = start
    prev = start.copy()
    for t in range(1, n_frames):
        truth[t] = 2 * truth[t - 1] - prev + sigma * rng.standard_normal((k, 2))
        prev = truth[t - 1]
    z = truth + r_std * rng.standard_normal(truth.shape)
    z[0] = start
    return z
