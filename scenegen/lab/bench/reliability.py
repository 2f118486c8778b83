"""Benchmark rows of long sequences: streaming generation in bounded memory, and reads
whose cost is proportional to the frame range (equal per-frame cost for 10 and 100 frames,
wherever they lie in the file).

Generation runs ``scenegen generate`` in a subprocess so that its peak resident memory can
be measured on its own (its ``VmHWM`` on Linux, see :func:`peak_rss`); the import-only
peak of the same interpreter (``scenegen presets``) is the baseline. Reads of 10 and 100
frames from the middle, and of 10 frames from the end, of the generated file are timed
side by side.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from scenegen.io import read
from scenegen.lab.bench.core import BenchRow, median_time

__all__ = ["FRAMES", "RSS_GOAL_MB", "SCENE", "peak_rss", "run"]

FRAMES = 2000
RSS_GOAL_MB = 500.0

# 640x480, two moving targets, an occluder and 30 clutter items on a uniform background.
SCENE = {
    "name": "long", "width": 640, "height": 480, "n_frames": FRAMES,
    "background": {"kind": "uniform", "color": [200, 220, 255]},
    "entities": [
        {"name": "t1", "role": "target", "position": [100, 100], "depth": 0,
         "appearance": {"shape": "ellipse", "size": [40, 60], "pattern": "rings",
                        "colors": [[255, 0, 0], [0, 255, 0]]},
         "motion": {"x": {"boundary": "reflect", "sigma": 2, "a1": 1.9, "a2": -0.9},
                    "y": {"boundary": "reflect", "sigma": 2, "a1": 1.9, "a2": -0.9},
                    "velocity": [3, 2]}},
        {"name": "t2", "role": "target", "position": [500, 300], "depth": 1,
         "appearance": {"shape": "rect", "size": [50, 50], "pattern": "stripes",
                        "colors": [[0, 0, 255], [255, 255, 0]]},
         "motion": {"x": {"boundary": "reflect", "sigma": 2, "a1": 1.9, "a2": -0.9},
                    "y": {"boundary": "reflect", "sigma": 2, "a1": 1.9, "a2": -0.9},
                    "velocity": [-3, 1]}},
        {"name": "wall", "role": "occluder", "position": [320, 240], "depth": 2,
         "appearance": {"size": [60, 200], "colors": [[80, 80, 80]]}},
    ],
    "clutter": [{"count": 30, "appearance": {"shape": "ellipse", "size": [16, 16]}}],
}  # fmt: skip


# Run in the child: scenegen's CLI, then, at exit, the peak resident memory of this
# program alone: VmHWM of its own address space, which starts at exec. The rusage that
# wait4 returns would not do on Linux: the child's ru_maxrss carries the resident set of
# the process that forked it, so a child of a large parent (a long bench run, a pytest
# session) would read as large as its parent.
_PEAK_WRAPPER = """
import atexit, runpy, sys
def _peak(path=sys.argv.pop(1)):
    with open("/proc/self/status") as f:
        kib = next(ln.split()[1] for ln in f if ln.startswith("VmHWM:"))
    with open(path, "w") as out:
        out.write(kib)
atexit.register(_peak)
sys.argv[0] = "scenegen"
runpy.run_module("scenegen.cli", run_name="__main__")
"""


def peak_rss(args: list[str]) -> tuple[float, float]:
    """Run ``scenegen ARGS`` in a subprocess.

    Parameters
    ----------
    args : list of str
        The CLI arguments.

    Returns
    -------
    (seconds, megabytes) : (float, float)
        Wall time and peak resident memory of the subprocess: on Linux its own high-water
        mark (``VmHWM``), not counting the memory of the process that started it;
        elsewhere ``ru_maxrss`` from ``os.wait4``.

    Raises
    ------
    RuntimeError
        If the command fails.
    """
    own = Path("/proc/self/status").exists()
    with tempfile.TemporaryDirectory() as tmp:
        peak = Path(tmp) / "peak-kib"
        cmd = ([sys.executable, "-c", _PEAK_WRAPPER, str(peak), *args] if own
               else [sys.executable, "-m", "scenegen.cli", *args])  # fmt: skip
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        err = proc.stderr.read().decode(errors="replace").strip() if proc.stderr else ""
        if proc.stderr:
            proc.stderr.close()
        if proc.returncode != 0:
            raise RuntimeError(f"scenegen {' '.join(args)} failed: {err}")
        if own:
            return seconds, int(peak.read_text()) / 1024
    scale = 1 if sys.platform == "darwin" else 1024  # ru_maxrss: bytes on macOS, else KiB
    return seconds, usage.ru_maxrss * scale / 2**20


def run(repeats: int = 5) -> list[BenchRow]:
    """Rows: streaming generation (rate, peak RSS) and frame-range reads.

    Parameters
    ----------
    repeats : int
        Repeats of each timed read (generation runs once: it takes many seconds).

    Returns
    -------
    list of BenchRow
        The peak memory and rate of streaming generation against an import-only run,
        then per-frame read rates of 10 and 100 middle frames and of the last 10.
    """
    rows: list[BenchRow] = []
    with tempfile.TemporaryDirectory() as d:
        config = Path(d) / "long.json"
        config.write_text(json.dumps(SCENE))
        out = Path(d) / "long.h5"
        base_s, base_mb = peak_rss(["presets"])
        gen_s, gen_mb = peak_rss(["generate", "--config", str(config), "--seed", "0",
                                  "-o", str(out)])  # fmt: skip
        group = f"stream {FRAMES} frames 640x480 to HDF5 (gzip, subprocess)"
        rows.append(
            BenchRow(
                group, f"import only: scenegen presets, peak RSS {base_mb:.0f} MB", base_s,
                60 / base_s, "runs/min",
            )
        )  # fmt: skip
        rows.append(
            BenchRow(
                group, f"scenegen generate, peak RSS {gen_mb:.0f} MB", gen_s / FRAMES,
                FRAMES / gen_s, "frames/s",
                goal=f"peak RSS < {RSS_GOAL_MB:.0f} MB", met=gen_mb < RSS_GOAL_MB,
            )
        )  # fmt: skip

        seq = read(out)
        mid = FRAMES // 2
        t10 = median_time(lambda: seq.frames[mid : mid + 10], repeats)
        t100 = median_time(lambda: seq.frames[mid : mid + 100], repeats)
        t_end = median_time(lambda: seq.frames[FRAMES - 10 :], repeats)
        seq.frames.close()
        group = f"read a frame range of a {FRAMES}-frame 640x480 file (gzip)"
        name_b = f"frames {mid}:{mid + 10} (baseline)"
        rows.append(BenchRow(group, name_b, t10 / 10, 10 / t10, "frames/s"))
        # Per-frame times: equal per-frame cost means a cost in proportion to the range.
        for name, t, n in (
            (f"frames {mid}:{mid + 100}, {t100 / t10:.1f}x the time of 10", t100, 100),
            (f"frames {FRAMES - 10}:{FRAMES} (the end)", t_end, 10),
        ):
            ratio = (t10 / 10) / (t / n)
            rows.append(
                BenchRow(
                    group, name, t / n, n / t, "frames/s", baseline=name_b, ratio=ratio,
                    goal="~1x baseline per frame (cost in proportion to the range)",
                    met=0.5 <= ratio <= 2.0,
                )
            )  # fmt: skip
    return rows
