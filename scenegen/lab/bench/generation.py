"""Benchmark rows of the generator and of HDF5 writing.

Baselines measured in the same run: a plain numpy compositor (per entity, boolean-mask
assignment) for rendering, and h5py writing the same arrays with the same filter for I/O,
plainly and then made durable as ``scenegen.write`` makes it (written beside the target,
flushed to disk, renamed onto it, the folder flushed).
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import replace
from pathlib import Path

import cv2
import h5py
import numpy as np

from scenegen import presets
from scenegen.io import COMPRESSIONS, filter_options, write, write_scenario
from scenegen.io.atomic import _fsync as _flush  # the flush scenegen.write does
from scenegen.lab.bench.core import BenchRow, median_time
from scenegen.render.plan import generate, plan

__all__ = ["numpy_render", "realistic_rows", "run", "sizes", "write_rows"]


def numpy_render(scn) -> np.ndarray:
    """Reference compositor in plain numpy: every entity, every frame, back to front.

    Parameters
    ----------
    scn : scenegen.render.plan.Scenario
        A planned scenario (:func:`scenegen.render.plan.plan`): its background,
        templates, centres, depths and liveness are used; photometric effects are not.

    Returns
    -------
    ndarray of uint8, shape (T, H, W, 3)
        The frames, each template pasted at its rounded position where its alpha is
        non-zero.
    """
    t_n, k_n = scn.cx.shape
    h, w = scn.config.height, scn.config.width
    out = np.empty((t_n, h, w, 3), dtype=np.uint8)
    for t in range(t_n):
        img = scn.background.copy()
        for k in np.argsort(-scn.depth_value[t], kind="stable"):
            if not scn.alive[t, k]:
                continue
            tpl = scn.templates[k]
            th, tw = tpl.shape[:2]
            x0 = int(np.floor(scn.cx[t, k] - tw / 2 + 0.5))
            y0 = int(np.floor(scn.cy[t, k] - th / 2 + 0.5))
            r0, r1 = max(0, y0), min(h, y0 + th)
            c0, c1 = max(0, x0), min(w, x0 + tw)
            if r0 >= r1 or c0 >= c1:
                continue
            sub = tpl[r0 - y0 : r1 - y0, c0 - x0 : c1 - x0]
            mask = sub[..., 3] > 0
            img[r0:r1, c0:c1][mask] = sub[..., :3][mask]
        out[t] = img
    return out


def run(repeats: int = 5) -> list[BenchRow]:
    """All rows of this module; every figure is a median over ``repeats`` timings.

    Parameters
    ----------
    repeats : int, default 5
        Timings per figure (the baselines and HDF5 writes use ``max(1, repeats // 2)``).

    Returns
    -------
    list of BenchRow
        Generation of ``kams-d`` and ``dps-synthetic`` against :func:`numpy_render`, the
        rows of :func:`realistic_rows`, and writing ``kams-d`` with each compression
        against plain h5py (and plain h5py made durable, for comparison), all in
        frames/s.
    """
    rows: list[BenchRow] = []
    for preset, goal in (("kams-d", 2000.0), ("dps-synthetic", 1000.0)):
        t_n = presets.get(preset).n_frames
        ours = median_time(lambda p=preset: generate(p, seed=0), repeats)
        scn = plan(presets.get(preset), 0, preset=preset)
        base = median_time(lambda s=scn: numpy_render(s), max(1, repeats // 2))
        group = f"generate {preset} ({t_n} frames, file I/O excluded)"
        name_b = "numpy compositor (baseline)"
        rows.append(BenchRow(group, name_b, base / t_n, t_n / base, "frames/s"))
        rows.append(
            BenchRow(
                group, "scenegen.generate", ours / t_n, t_n / ours, "frames/s",
                baseline=name_b, ratio=base / ours,
                goal=f">= {goal:.0f} frames/s", met=t_n / ours >= goal,
            )
        )  # fmt: skip
    rows += realistic_rows(repeats)
    return rows + write_rows(repeats)


def write_rows(repeats: int = 5) -> list[BenchRow]:
    """Writing ``kams-d`` with each compression: plain h5py (the baseline), plain h5py
    made durable, and ``scenegen.write``.

    Parameters
    ----------
    repeats : int, default 5
        Each figure is a median over ``max(1, repeats // 2)`` timings.

    Returns
    -------
    list of BenchRow
        Three rows per compression of :data:`scenegen.io.COMPRESSIONS`, in frames/s; the
        last two with their ratio to the first, the last with the goal.
    """
    rows: list[BenchRow] = []
    seq = generate("kams-d", seed=0)
    t_n = seq.n_frames
    with tempfile.TemporaryDirectory() as d:
        for comp in COMPRESSIONS:
            filt = filter_options(comp)

            def raw(filt=filt, name="raw.h5"):
                # The same content written with plain h5py calls: frames and labels with
                # the filter, ground truth and one dataset per template.
                with h5py.File(Path(d) / name, "w") as f:
                    for key in ("frames", "labels"):
                        arr = getattr(seq, key)
                        f.create_dataset(key, data=arr, chunks=(1, *arr.shape[1:]), **filt)
                    for key, arr in seq.gt.as_dict().items():
                        f.create_dataset(f"gt/{key}", data=arr)
                    for eid, tpl in seq.templates.items():
                        f.create_dataset(f"templates/{eid}", data=tpl)

            def durable(filt=filt):
                # The same, made durable with scenegen.write's flush and os.replace: what
                # the atomic write costs beyond h5py without any of scenegen's seals.
                raw(filt, ".durable.h5.tmp")
                _flush(Path(d) / ".durable.h5.tmp")
                os.replace(Path(d) / ".durable.h5.tmp", Path(d) / "durable.h5")
                _flush(Path(d))

            def ours(comp=comp):
                write(Path(d) / "ours.h5", seq, compression=comp)

            b = median_time(raw, max(1, repeats // 2))
            b_d = median_time(durable, max(1, repeats // 2))
            o = median_time(ours, max(1, repeats // 2))
            group = f"write kams-d (frames, labels, gt, 601 templates), {comp}"
            name_b = "plain h5py, same content (baseline)"
            rows.append(BenchRow(group, name_b, b / t_n, t_n / b, "frames/s"))
            rows.append(
                BenchRow(
                    group, "plain h5py + fsync + rename + fsync of the folder", b_d / t_n,
                    t_n / b_d, "frames/s", baseline=name_b, ratio=b / b_d,
                )
            )  # fmt: skip
            rows.append(
                BenchRow(
                    group, "scenegen.write (atomic)", o / t_n, t_n / o,
                    "frames/s", baseline=name_b, ratio=b / o,
                    goal="~1x baseline (no more than h5py's own cost)", met=b / o >= 0.8,
                )
            )  # fmt: skip
    return rows


def realistic_rows(repeats: int = 5) -> list[BenchRow]:
    """The realistic preset ``tiger-like`` (320x240: textured target and clutter, camera
    pan, motion blur, JPEG) beside the flat ``kams-d`` at the same size, OpenCV on one
    thread: the ratio says what realism costs on the same machine in the same run.

    Parameters
    ----------
    repeats : int, default 5
        Timings per figure.

    Returns
    -------
    list of BenchRow
        Frames/s of ``kams-d`` (the baseline), ``tiger-like`` (goal >= 500 frames/s) and
        ``tiger-like`` without JPEG, with ratios against the baseline.
    """
    flat = presets.get("kams-d")
    real = presets.get("tiger-like")
    assert real.photometric is not None
    no_jpeg = replace(real, photometric=replace(real.photometric, jpeg_quality=None))
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        times = {
            label: (median_time(lambda c=cfg: generate(c, seed=0), repeats), cfg.n_frames)
            for label, cfg in (
                ("kams-d, flat colours (baseline)", flat),
                ("tiger-like: textures, camera pan, motion blur, JPEG q80", real),
                ("tiger-like without JPEG", no_jpeg),
            )
        }
    finally:
        cv2.setNumThreads(threads)
    group = "generate 320x240, flat vs realistic (one OpenCV thread, file I/O excluded)"
    base_name = next(iter(times))
    base = times[base_name][0] / times[base_name][1]
    rows = []
    for label, (sec, t_n) in times.items():
        per = sec / t_n
        goal = label.startswith("tiger-like:")
        rows.append(
            BenchRow(
                group, label, per, 1.0 / per, "frames/s",
                baseline="" if label == base_name else base_name, ratio=base / per,
                goal=">= 500 frames/s" if goal else "", met=(1.0 / per >= 500) if goal else None,
            )
        )  # fmt: skip
    return rows


def sizes() -> list[dict[str, object]]:
    """Stored size of frames and labels per compression, for a noisy and a clean preset.

    The presets are ``dps-synthetic``, ``kams-d`` and ``shm-crossing`` (seed 0), each
    written once per compression of :data:`scenegen.io.COMPRESSIONS` into a temporary
    folder.

    Returns
    -------
    list of dict
        One per preset and compression: ``"preset"``, ``"compression"``, and
        ``"frames_ratio"``, ``"labels_ratio"`` (raw bytes / stored bytes).
    """
    out = []
    with tempfile.TemporaryDirectory() as d:
        for preset in ("dps-synthetic", "kams-d", "shm-crossing"):
            seq = generate(preset, seed=0)
            raw_frames, raw_labels = seq.frames.nbytes, seq.labels.nbytes
            for comp in COMPRESSIONS:
                path = Path(d) / f"{preset}-{comp}.h5"
                write_scenario(path, plan(seq.config, 0, preset=preset), compression=comp)
                with h5py.File(path) as f:
                    g = f[f"sequences/{seq.name}"]
                    fr = g["frames"].id.get_storage_size()
                    lb = g["labels"].id.get_storage_size()
                out.append(
                    {
                        "preset": preset,
                        "compression": comp,
                        "frames_ratio": raw_frames / fr,
                        "labels_ratio": raw_labels / lb,
                    }
                )
    return out
