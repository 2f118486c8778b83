"""Benchmark rows: each tracker's step against its own histogram stage, in one run.

A tracker step is the histogram stage (the compiled observation kernels: quantising the
frame, the kernel-weighted histograms and their Bhattacharyya distances, and mean shift
for the trackers that climb) and the rest (sampling, dynamics, resampling, bookkeeping,
in compiled stages called from Python: docs/algorithms.md, implementation notes). Each
row times whole steps over the sequence and, in the same steps, the time spent inside the
histogram stage, as CPU time of the calling thread on one numba thread (so a loaded
machine's waiting does not count, and every kernel runs on the timed thread); the row's
``ratio`` is histogram stage / step, its name gives the non-histogram share
1 − histogram / step. Goal: ``dps`` at most 0.15.

Particle filters with 7 objects x 300 particles on dps-synthetic (360x288, 24 steps);
``kams``, ``annealed`` and ``hybrid`` with their default particle counts (kams: 40) on
kams-d.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator

import numpy as np

from scenegen.lab.bench.core import BenchRow
from scenegen.lab.bench.particle import threads
from scenegen.render.plan import generate
from trackers.models import observation
from trackers.registry import make

__all__ = ["TRACKERS", "histogram_clock", "run", "step_split"]

#: (tracker, preset, parameters) of the rows.
TRACKERS: tuple[tuple[str, str, dict], ...] = (
    ("dps", "dps-synthetic", {"n_particles": 300}),
    ("ps", "dps-synthetic", {"n_particles": 300}),
    ("joint-pf", "dps-synthetic", {"n_particles": 300}),
    ("condensation", "dps-synthetic", {"n_particles": 300}),
    ("kams", "kams-d", {"n_particles": 40}),
    ("annealed", "kams-d", {}),
    ("hybrid", "kams-d", {}),
)

# The histogram stage: every compiled observation call a tracker step makes.
_STAGE = ((observation.ColourModel, "quantize"), (observation.FrameObservation, "distances"),
          (observation.FrameObservation, "mean_shift"))


@contextlib.contextmanager
def histogram_clock() -> Iterator[list[float]]:
    """Inside, the calls of the histogram stage add their thread CPU time (s) to the
    yielded one-element list (the methods are wrapped for the duration only)."""
    spent = [0.0]
    saved = [(cls, name, cls.__dict__[name]) for cls, name in _STAGE]

    def timed(fn):
        def call(*args, **kwargs):
            t0 = time.thread_time()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[0] += time.thread_time() - t0
        return call

    for cls, name, fn in saved:
        setattr(cls, name, timed(fn))
    try:
        yield spent
    finally:
        for cls, name, fn in saved:
            setattr(cls, name, fn)


def step_split(name: str, preset: str, params: dict, repeats: int) -> tuple[float, float]:
    """(step, histogram stage) CPU seconds per step of ``name`` on ``preset`` (seed 0), the
    median run of ``repeats`` (after one untimed run), on one numba thread.

    Parameters
    ----------
    name : str
        Registered tracker name (``trackers.make``), built with ``rng=0``.
    preset : str
        Preset whose sequence is tracked from the ground-truth boxes of its targets.
    params : dict
        Keyword arguments of the tracker.
    repeats : int
        Timed runs (at least one); the run of median total time is kept.

    Returns
    -------
    step, histogram : float
        Thread CPU seconds per step: whole step, and inside the histogram stage
        (:func:`histogram_clock`).
    """
    seq = generate(preset, seed=0)
    frames = np.asarray(seq.frames)
    init = np.asarray(seq.gt.box[0, seq.target_indices()], dtype=np.float64)
    runs = []
    with threads(1):
        for r in range(max(1, repeats) + 1):
            tracker = make(name, rng=0, **params)
            tracker.init(frames[0], init)
            with histogram_clock() as spent:
                t0 = time.thread_time()
                for frame in frames[1:]:
                    tracker.step(frame)
                total = time.thread_time() - t0
            if r:
                runs.append((total, spent[0]))
    runs.sort()
    total, hist = runs[len(runs) // 2]
    n = frames.shape[0] - 1
    return total / n, hist / n


def run(repeats: int = 5) -> list[BenchRow]:
    """One row per tracker of ``TRACKERS``.

    Parameters
    ----------
    repeats : int, default 5
        Timed runs per tracker (:func:`step_split`).

    Returns
    -------
    list of BenchRow
        Per tracker: seconds per step, ``ratio`` = histogram stage / step, and in
        ``params`` the tracker, ``"histogram_seconds"`` and the non-histogram
        ``"share"``; goal for ``dps``: share <= 0.15.
    """
    group = "tracker step against its own histogram stage (CPU time, 1 thread)"
    rows = []
    for name, preset, params in TRACKERS:
        step, hist = step_split(name, preset, params, repeats)
        share = 1.0 - hist / step
        goal = "non-histogram share <= 0.15" if name == "dps" else ""
        rows.append(BenchRow(group, f"{name} ({preset}): non-histogram share {share:.3f}",
                             step, 1.0 / step, "frames/s", baseline="histogram stage",
                             ratio=hist / step, goal=goal,
                             met=(share <= 0.15) if goal else None,
                             params={"tracker": name, "histogram_seconds": hist,
                                     "share": share}))
    return rows
