"""Benchmark rows of the DPS particle filters and their observation kernel.

- The likelihood stage of one frame: 7 objects × 300 particles (2,100 candidate boxes
  around the targets of a dps-synthetic 360x288 frame, as a tracker proposes them), each
  scored by the Bhattacharyya distance of its histogram to its object's template.
  (a) ours: the frame quantised once and one ``region_distances`` call (for the uniform
  kernel it takes, per object, the integral-histogram path when that is cheaper, as it is
  for a particle cloud; a row gives the direct path alone); (b) the
  baseline, a per-patch ``cv2.calcHist`` + ``cv2.compareHist`` loop; (c) a per-patch
  numpy ``bincount`` loop on the quantised frame. Ratios are against (b); goal: (a) ≥ 10x.
  Two groups: a 10x10x10 RGB histogram (one ``calcHist`` per patch: the simplest case
  for OpenCV), and the DPS trackers' HSV model with two spatial parts (four ``calcHist``
  per patch). Both use the uniform kernel, the only one ``calcHist`` has; the last rows
  give ours with the trackers' default Epanechnikov kernel, with the nested-rectangle
  ("box", L = 3) kernel that the integral histogram computes exactly, and the
  Epanechnikov kernel on 2 threads (every other row runs on one thread).
- Whole steps of ``condensation``, ``joint-pf``, ``ps`` and ``dps`` with 7 objects × 300
  particles on the dps-synthetic sequence, in frames per second (one thread unless a row
  says otherwise); goal: ``dps`` ≥ 150 frames/s. Ratios are against ``joint-pf``; rows
  give ``dps`` with the box kernel and on 2 threads (identical results for any thread
  count: tests/trackers/models/test_box_kernel.py).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import cv2
import numba
import numpy as np

from scenegen.lab.bench.core import BenchRow, median_time
from scenegen.render.plan import generate
from trackers.kernels.histogram import KERNEL_UNIFORM, quantize_rgb, region_distances
from trackers.models.observation import ColourModel
from trackers.registry import make

__all__ = ["run"]

_N_PARTICLES = 300


@contextlib.contextmanager
def threads(n: int) -> Iterator[int]:
    """Run the compiled kernels on ``n`` threads (at most what numba has) inside."""
    before = numba.get_num_threads()
    n = min(n, numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(n)
    try:
        yield n
    finally:
        numba.set_num_threads(before)


def _candidates(seq, rng):
    """Boxes (K * N, 4) scattered around the frame-1 targets, and their object (K * N,)."""
    ti = seq.target_indices()
    truth = np.asarray(seq.gt.box[1, ti], dtype=np.float64)
    k = truth.shape[0]
    boxes = np.repeat(truth, _N_PARTICLES, axis=0)
    boxes[:, :2] += rng.normal(0.0, 4.0, (k * _N_PARTICLES, 2))
    boxes[:, 2:] *= np.exp(rng.normal(0.0, 0.02, (k * _N_PARTICLES, 1)))
    return boxes, np.repeat(np.arange(k), _N_PARTICLES), truth


def _likelihood_rows(repeats: int) -> list[BenchRow]:
    seq = generate("dps-synthetic", seed=0)
    frames = np.asarray(seq.frames[:2])
    boxes, objects, truth = _candidates(seq, np.random.default_rng(0))
    refs = ColourModel("rgb", kernel="uniform", n_parts=1)
    refs.set_references(frames[0], np.asarray(seq.gt.box[0, seq.target_indices()]))
    q = refs.references
    frame = frames[1]
    # Integer pixel windows for the per-patch loops (OpenCV and numpy slice whole pixels;
    # the kernel takes the same pixels: those whose centres fall in the box).
    ib = np.round(boxes).astype(int)
    ib[:, 2:] = np.maximum(ib[:, 2:], 1)
    x0 = np.clip(ib[:, 0], 0, frame.shape[1] - 1)
    y0 = np.clip(ib[:, 1], 0, frame.shape[0] - 1)
    x1 = np.clip(ib[:, 0] + ib[:, 2], x0 + 1, frame.shape[1])
    y1 = np.clip(ib[:, 1] + ib[:, 3], y0 + 1, frame.shape[0])
    q_cv = q.reshape(-1, 10, 10, 10).astype(np.float32)
    sqrt_q = np.sqrt(q)

    def ours() -> None:
        region_distances(quantize_rgb(frame), boxes, q, objects, KERNEL_UNIFORM)

    def ours_direct() -> None:
        region_distances(quantize_rgb(frame), boxes, q, objects, KERNEL_UNIFORM,
                         method="direct")

    def opencv() -> None:
        for i in range(boxes.shape[0]):
            patch = frame[y0[i]:y1[i], x0[i]:x1[i]]
            h = cv2.calcHist([patch], [0, 1, 2], None, [10, 10, 10], [0, 256, 0, 256, 0, 256])
            h /= h.sum()
            cv2.compareHist(h, q_cv[objects[i]], cv2.HISTCMP_BHATTACHARYYA)

    def numpy_loop() -> None:
        bins = quantize_rgb(frame)
        for i in range(boxes.shape[0]):
            h = np.bincount(bins[y0[i]:y1[i], x0[i]:x1[i]].ravel(), minlength=1000)
            np.sqrt(max(0.0, 1.0 - float(np.sqrt(h / h.sum()) @ sqrt_q[objects[i]])))

    n = boxes.shape[0]
    group = f"likelihood stage, RGB 10^3, 7 objects x {_N_PARTICLES} particles @360x288"
    base = "(b) cv2.calcHist + compareHist per patch (baseline)"
    t_cv = median_time(opencv, repeats)
    rows = [BenchRow(group, base, t_cv, n / t_cv, "boxes/s")]
    for name, fn, goal in (
        ("(a) ours: quantise once + one numba call", ours, ">= 10x baseline"),
        ("ours, direct path only (no integral histogram)", ours_direct, ""),
        ("(c) numpy bincount per patch", numpy_loop, ""),
    ):
        t = median_time(fn, repeats)
        rows.append(BenchRow(group, name, t, n / t, "boxes/s", baseline=base, ratio=t_cv / t,
                             goal=goal, met=(t_cv / t >= 10.0) if goal else None))
    return rows + _hsv_rows(repeats, frames, boxes, objects, truth, ib)


def _hsv_rows(repeats, frames, boxes, objects, truth, ib):
    """The DPS trackers' own model: HSV (10x10 HS + 10 V bins) in two horizontal parts.

    OpenCV has no such histogram, so the baseline builds it per patch as a user would:
    the frame converted and the "coloured" mask computed once, then per patch and part
    one masked H–S ``calcHist`` and one V ``calcHist`` on the complementary mask.
    """
    frame = frames[1]
    model = ColourModel("hsv", kernel="uniform")
    model.set_references(frames[0], truth)
    q = model.references.astype(np.float32)
    h, w = frame.shape[:2]
    x0 = np.clip(ib[:, 0], 0, w - 1)
    y0 = np.clip(ib[:, 1], 0, h - 2)
    x1 = np.clip(ib[:, 0] + ib[:, 2], x0 + 1, w)
    y1 = np.clip(ib[:, 1] + ib[:, 3], y0 + 2, h)
    ym = (y0 + y1) // 2

    def ours() -> None:
        model.observe(frame).distances(boxes, objects)

    def opencv() -> None:
        hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV)
        coloured = ((hsv[..., 1] >= 26) & (hsv[..., 2] >= 51)).astype(np.uint8)
        grey = 1 - coloured
        for i in range(boxes.shape[0]):
            parts = []
            for ra, rb in ((y0[i], ym[i]), (ym[i], y1[i])):
                patch = hsv[ra:rb, x0[i]:x1[i]]
                hs = cv2.calcHist([patch], [0, 1], coloured[ra:rb, x0[i]:x1[i]], [10, 10],
                                  [0, 180, 0, 256])
                v = cv2.calcHist([patch], [2], grey[ra:rb, x0[i]:x1[i]], [10], [0, 256])
                part = np.concatenate([hs.ravel(), v.ravel()])
                parts.append(part / (2.0 * max(part.sum(), 1.0)))
            cv2.compareHist(np.concatenate(parts), q[objects[i]], cv2.HISTCMP_BHATTACHARYYA)

    def numpy_loop() -> None:
        bins = model.quantize(frame)
        sqrt_q = np.sqrt(model.references)
        for i in range(boxes.shape[0]):
            parts = []
            for ra, rb in ((y0[i], ym[i]), (ym[i], y1[i])):
                hist = np.bincount(bins[ra:rb, x0[i]:x1[i]].ravel(), minlength=110)
                parts.append(hist / (2.0 * hist.sum()))
            np.sqrt(max(0.0, 1.0 - float(np.sqrt(np.concatenate(parts)) @ sqrt_q[objects[i]])))

    n = boxes.shape[0]
    group = (f"likelihood stage, HSV 10x10+10 x 2 parts (DPS model), 7 objects x "
             f"{_N_PARTICLES} particles @360x288")
    base = "(b) cv2.calcHist (masked H-S + V, per part) + compareHist per patch (baseline)"
    t_cv = median_time(opencv, repeats)
    rows = [BenchRow(group, base, t_cv, n / t_cv, "boxes/s")]
    default = ColourModel("hsv")
    default.set_references(frames[0], truth)
    box = ColourModel("hsv", kernel="box", box_levels=3)
    box.set_references(frames[0], truth)

    def ours_default() -> None:
        default.observe(frame).distances(boxes, objects)

    def ours_box() -> None:
        box.observe(frame).distances(boxes, objects)

    two = min(2, numba.config.NUMBA_NUM_THREADS)
    for name, fn, goal, n_threads in (
        ("(a) ours: quantise once + one numba call", ours, ">= 10x baseline", 1),
        ("(c) numpy bincount per patch", numpy_loop, "", 1),
        ("ours with the trackers' default Epanechnikov kernel", ours_default, "", 1),
        ("ours with the box kernel (L = 3, integral histogram)", ours_box, "", 1),
        (f"ours, Epanechnikov kernel, {two} threads", ours_default, "", 2),
    ):
        with threads(n_threads):
            t = median_time(fn, repeats)
        rows.append(BenchRow(group, name, t, n / t, "boxes/s", baseline=base, ratio=t_cv / t,
                             goal=goal, met=(t_cv / t >= 10.0) if goal else None))
    return rows


def _step_rows(repeats: int) -> list[BenchRow]:
    seq = generate("dps-synthetic", seed=0)
    frames = np.asarray(seq.frames)
    init = np.asarray(seq.gt.box[0, seq.target_indices()], dtype=np.float64)
    n_frames = frames.shape[0] - 1
    group = f"tracker step, 7 objects x {_N_PARTICLES} particles, dps-synthetic 360x288"
    times = {}
    two = min(2, numba.config.NUMBA_NUM_THREADS)
    variants = [(name, name, {}, 1) for name in ("joint-pf", "condensation", "ps", "dps")]
    variants += [
        ("dps, box kernel (L = 3)", "dps", {"kernel": "box", "box_levels": 3}, 1),
        (f"dps, {two} threads", "dps", {}, 2),
        (f"dps, box kernel, {two} threads", "dps", {"kernel": "box", "box_levels": 3}, 2),
    ]
    for label, name, params, n_threads in variants:

        def track(name=name, params=params) -> None:
            tracker = make(name, n_particles=_N_PARTICLES, rng=0, **params)
            tracker.init(frames[0], init)
            for frame in frames[1:]:
                tracker.step(frame)

        with threads(n_threads):
            times[label] = median_time(track, repeats) / n_frames
    base = "joint-pf"
    rows = []
    for name, t in times.items():
        one_core = name.startswith("dps") and "thread" not in name
        goal = ">= 150 frames/s on one core" if one_core else ""
        rows.append(BenchRow(group, name, t, 1.0 / t, "frames/s",
                             baseline="" if name == base else base,
                             ratio=times[base] / t, goal=goal,
                             met=(1.0 / t >= 150.0) if goal else None))
    return rows


def _against_cv2(likelihood: list[BenchRow], steps: list[BenchRow]) -> list[BenchRow]:
    """Each step as a fraction of the per-patch cv2 loop a user would write for the same
    2,100 boxes of the trackers' own HSV model (the baseline of that group), measured in
    this run: ``ratio`` = cv2 loop time / step time (goal: the step <= 0.1 of the loop)."""
    base = next(r for r in likelihood if r.group.startswith("likelihood stage, HSV")
                and not r.baseline)
    group = "tracker step against the per-patch cv2 loop over the same boxes (HSV model)"
    rows = [BenchRow(group, base.name, base.seconds, 1.0 / base.seconds, "loops/s")]
    for r in steps:
        share = r.seconds / base.seconds
        rows.append(BenchRow(group, f"{r.name}: {share:.3f} of the loop's time", r.seconds,
                             r.rate, r.unit, baseline=base.name, ratio=base.seconds / r.seconds,
                             goal="step <= 0.1 of the loop" if r.name.startswith("dps") else "",
                             met=(share <= 0.1) if r.name.startswith("dps") else None))
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
        The likelihood-stage rows (RGB and HSV models, boxes/s), the tracker-step rows
        (frames/s), and each step against the per-patch cv2 loop of the HSV group.
    """
    likelihood = _likelihood_rows(repeats)
    steps = _step_rows(repeats)
    return likelihood + steps + _against_cv2(likelihood, steps)
