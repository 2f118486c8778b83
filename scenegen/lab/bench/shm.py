"""Benchmark rows of the SHM trackers (docs/algorithms.md §4) on the ``shm-crossing`` preset.

Two targets on 360x288 frames, 120 frames, one core (OpenCV limited to one thread for the
run; the matching kernel is single-threaded). The baseline is the plain Kalman tracker,
measured in the same run: it makes the same template searches minus the extra orderings.
The goal is the issue's: ``shm-fast`` at 200 frames/s or more.
"""

from __future__ import annotations

import cv2
import numpy as np

from scenegen.lab.bench.core import BenchRow, median_time
from scenegen.render.plan import generate

__all__ = ["run"]

GOAL_FPS = 200.0


def run(repeats: int = 5) -> list[BenchRow]:
    """All rows of this module; every figure is a median over ``repeats`` timings.

    Parameters
    ----------
    repeats : int, default 5
        Timed runs of each tracker over the whole sequence.

    Returns
    -------
    list of BenchRow
        Frames/s of ``kalman`` (the baseline), ``shm``, ``shm-fast`` (goal
        :data:`GOAL_FPS`) and ``shm-fast`` with ``step=1``, ratios against the baseline.
    """
    import trackers

    seq = generate("shm-crossing", seed=0)
    ti = seq.target_indices()
    frames = np.asarray(seq.frames)
    boxes0 = np.asarray(seq.gt.box)[0, ti]
    t_n = len(frames)
    variants = (
        ("kalman", "kalman (baseline)", {}),
        ("shm", "shm (Gaussian sum, GPB2)", {}),
        ("shm-fast", "shm-fast", {}),
        ("shm-fast", "shm-fast, exhaustive search (step 1)", {"step": 1}),
    )
    group = f"track shm-crossing ({len(ti)} targets, 360x288, {t_n} frames, one core)"
    prev = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        times = {
            label: median_time(
                lambda n=name, p=params: trackers.track(trackers.make(n, **p), frames, boxes0),
                repeats,
            )
            for name, label, params in variants
        }
    finally:
        cv2.setNumThreads(prev)
    base_label = variants[0][1]
    base = times[base_label]
    rows = [BenchRow(group, base_label, base / t_n, t_n / base, "frames/s")]
    for name, label, _ in variants[1:]:
        sec = times[label]
        goal = name == "shm-fast" and label == "shm-fast"
        rows.append(
            BenchRow(
                group, label, sec / t_n, t_n / sec, "frames/s",
                baseline=base_label, ratio=base / sec,
                goal=f">= {GOAL_FPS:.0f} frames/s" if goal else "",
                met=(t_n / sec >= GOAL_FPS) if goal else None,
            )
        )  # fmt: skip
    return rows
