"""Benchmark rows of the mean-shift family (KAMS paper).

- One mean-shift iteration on one 30x30 window of a 320x240 kams-a frame: ours
  (``trackers.kernels.meanshift``: Comaniciu re-weighting, i.e. two kernel-weighted
  histograms, a Bhattacharyya distance and the weighted centroid) against one iteration of
  ``cv2.meanShift`` (the centroid of a fixed back-projection: less work), both on
  precomputed inputs (bin-index image, back-projection). The per-window cost of ours in a
  batch of 40 windows (one KAMS layer) is a third row.
- Whole ``kams`` steps (40 particles, 3 layers, up to 5 mean-shift iterations) on kams-a
  and kams-d, in frames per second; goal >= 100 frames/s on one core (the kernels are
  single-threaded).
"""

from __future__ import annotations

import cv2
import numpy as np

from scenegen.lab.bench.core import BenchRow, median_time
from scenegen.render.plan import generate
from trackers.kernels.histogram import KERNEL_CONE, quantize_rgb, region_histograms
from trackers.kernels.meanshift import mean_shift
from trackers.registry import make

__all__ = ["run"]

_CALLS = 200  # calls per timed sample: one call is a few microseconds


def _iteration_rows(repeats: int) -> list[BenchRow]:
    seq = generate("kams-a", seed=0)
    k = seq.target_indices()[0]
    frames = np.asarray(seq.frames)
    box0 = np.asarray(seq.gt.box[0, k], dtype=np.float64)
    box1 = np.asarray(seq.gt.box[1, k], dtype=np.float64)
    bins = quantize_rgb(frames[1])
    model = region_histograms(quantize_rgb(frames[0]), box0[None], 1000, KERNEL_CONE)
    start = (box0[:2] + box0[2:] / 2)[None]
    size = box1[None, 2:]

    # OpenCV: back-projection of the model's RGB histogram, then one centroid step.
    hist_cv = model.reshape(10, 10, 10).astype(np.float32) * 255.0 / model.max()
    backproj = cv2.calcBackProject([frames[1]], [0, 1, 2], hist_cv,
                                   [0, 256, 0, 256, 0, 256], 1.0)
    window = tuple(int(round(v)) for v in box0)
    criteria = (cv2.TERM_CRITERIA_COUNT, 1, 0.0)

    def cv_once() -> None:
        for _ in range(_CALLS):
            cv2.meanShift(backproj, window, criteria)

    def ours_once() -> None:
        for _ in range(_CALLS):
            mean_shift(bins, model, np.zeros(1, dtype=np.int64), start, size, max_iter=1,
                       eps=0.0, check_bins=False)

    rng = np.random.default_rng(0)
    n_batch = 40
    starts = start + rng.normal(0.0, 8.0, (n_batch, 2))
    sizes = np.repeat(size, n_batch, axis=0)
    index = np.zeros(n_batch, dtype=np.int64)

    def batch_once() -> None:
        for _ in range(_CALLS // 10):
            mean_shift(bins, model, index, starts, sizes, max_iter=1, eps=0.0,
                       check_bins=False)

    t_cv = median_time(cv_once, repeats) / _CALLS
    t_ours = median_time(ours_once, repeats) / _CALLS
    t_batch = median_time(batch_once, repeats) / (_CALLS // 10) / n_batch
    group = "one mean-shift iteration, 30x30 window @320x240"
    base = "cv2.meanShift (back-projection centroid, baseline)"
    return [
        BenchRow(group, base, t_cv, 1.0 / t_cv, "iterations/s"),
        BenchRow(group, "ours, one window per call (Comaniciu re-weighting)", t_ours,
                 1.0 / t_ours, "iterations/s", baseline=base, ratio=t_cv / t_ours),
        BenchRow(group, f"ours, per window in a batch of {n_batch}", t_batch, 1.0 / t_batch,
                 "iterations/s", baseline=base, ratio=t_cv / t_batch),
    ]


def _kams_rows(repeats: int) -> list[BenchRow]:
    rows = []
    n_frames = 40
    for preset in ("kams-a", "kams-d"):
        seq = generate(preset, seed=0)
        k = seq.target_indices()[0]
        frames = np.asarray(seq.frames[: n_frames + 1])
        box0 = np.asarray(seq.gt.box[0, k : k + 1], dtype=np.float64)

        def track(frames=frames, box0=box0) -> None:
            tracker = make("kams", n_particles=40, n_layers=3, rng=0)
            tracker.init(frames[0], box0)
            for frame in frames[1:]:
                tracker.step(frame)

        t = median_time(track, repeats) / n_frames
        rows.append(BenchRow(f"kams step, 40 particles x 3 layers, {preset} 320x240",
                             "trackers.make('kams')", t, 1.0 / t, "frames/s",
                             goal=">= 100 frames/s on one core", met=1.0 / t >= 100.0))
    return rows


def run(repeats: int = 5) -> list[BenchRow]:
    """All rows of this module; every figure is a median over ``repeats`` timings.

    Parameters
    ----------
    repeats : int, default 5
        Timings per figure.

    Returns
    -------
    list of BenchRow
        One mean-shift iteration (``cv2.meanShift`` baseline, ours per call, ours per
        window in a batch), in iterations/s; whole ``kams`` steps on kams-a and kams-d,
        in frames/s.
    """
    return _iteration_rows(repeats) + _kams_rows(repeats)
