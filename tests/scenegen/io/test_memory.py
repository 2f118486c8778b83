"""Long sequences in bounded memory, and reads that cost in proportion to the range.

The slow test generates 20,000 frames of 640x480 in a subprocess and measures its peak
resident memory (its own ``VmHWM``, not counting the parent's:
``scenegen.lab.bench.reliability.peak_rss``); the fast ones check the same properties at
a small scale without timing anything: numpy memory traced during streaming writes does
not grow with the frame count, and the bytes read for a frame range grow with the range,
not the file.
"""

from __future__ import annotations

import dataclasses
import json
import os
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from scenegen.config import from_dict
from scenegen.io import frames_per_block, read, write, write_scenario
from scenegen.lab.bench.reliability import SCENE as BENCH_SCENE
from scenegen.lab.bench.reliability import peak_rss
from scenegen.render.plan import plan

# The bench's long 640x480 scene (two targets, an occluder, 30 clutter items), 100 frames.
SCENE = {**BENCH_SCENE, "n_frames": 100}
MB = 2**20


def small(n_frames: int, width: int = 160, height: int = 120):
    cfg = from_dict({**SCENE, "width": width, "height": height, "n_frames": n_frames})
    return dataclasses.replace(cfg, entities=tuple(
        dataclasses.replace(e, position=(e.position[0] / 4, e.position[1] / 4))
        for e in cfg.entities))  # fmt: skip


def bytes_read() -> int:
    """Bytes this process has read through system calls so far (Linux)."""
    for line in Path("/proc/self/io").read_text().splitlines():
        if line.startswith("rchar:"):
            return int(line.split()[1])
    raise AssertionError("no rchar in /proc/self/io")


def range_cost(path: Path, start: int, n: int) -> int:
    seq = read(path)  # ground truth is read here, before the measurement
    seq.frames[start]  # opens the file
    before = bytes_read()
    block = seq.frames[start : start + n]
    cost = bytes_read() - before
    assert block.shape[0] == n
    seq.frames.close()
    return cost


def peak_traced(fn) -> int:
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


needs_proc_io = pytest.mark.skipif(not Path("/proc/self/io").exists(), reason="Linux only")


def test_streaming_write_memory_does_not_grow_with_length(tmp_path):
    """numpy memory at peak while writing 40 vs 400 frames: one block either way."""
    short, long_ = plan(small(40), 1), plan(small(400), 1)
    for scn in (short, long_):
        scn.render(0, 1)  # compile and build the static layer outside the measurement
    a = peak_traced(lambda: write_scenario(tmp_path / "a.h5", short, chunk=16))
    b = peak_traced(lambda: write_scenario(tmp_path / "b.h5", long_, chunk=16))
    block = 16 * 160 * 120 * 5  # frames + labels of one block
    assert b < a + block  # 10x the frames, not even one more block of memory
    assert b < 2 * block


def test_block_size_respects_the_memory_bound():
    assert frames_per_block(480, 640) == 21
    assert frames_per_block(120, 160) == 64
    assert frames_per_block(8192, 8192) == 1


@needs_proc_io
def test_reading_a_range_costs_in_proportion_to_the_range(tmp_path):
    path = tmp_path / "s.h5"
    write_scenario(path, plan(small(300), 2), compression="none")
    ten, hundred = range_cost(path, 150, 10), range_cost(path, 150, 100)
    frame = 120 * 160 * 3
    assert 10 * frame <= ten < 10 * frame + 256 * 1024  # the chunks, plus some metadata
    assert 8 < hundred / ten < 11
    assert hundred < os.path.getsize(path) / 2.5


@needs_proc_io
def test_copying_a_lazy_sequence_reads_block_by_block(tmp_path):
    src, dst = tmp_path / "src.h5", tmp_path / "dst.h5"
    write_scenario(src, plan(small(200), 3))
    seq = read(src)
    peak = peak_traced(lambda: write(dst, seq))
    block = 64 * 160 * 120 * 5
    assert peak < block  # the whole sequence is three times that
    np.testing.assert_array_equal(read(dst).frames[199], seq.frames[199])


@needs_proc_io
def test_the_peak_is_the_childs_own_not_the_parents():
    # The same small command measured beside a parent holding 600 MB more reads about the
    # same (with the rusage of wait4 it would read above 600 MB).
    _, alone = peak_rss(["--help"])
    ballast = np.ones(600 * MB // 8)
    _, beside = peak_rss(["--help"])
    assert beside < min(alone + 100, 600), f"{alone:.0f} MB alone, {beside:.0f} MB beside"
    assert ballast.sum() > 0


@pytest.mark.slow
@needs_proc_io
def test_20000_frames_at_640x480_in_under_500_mb(tmp_path):
    config = tmp_path / "big.json"
    config.write_text(json.dumps(SCENE))
    out = tmp_path / "big.h5"
    _, mb = peak_rss(["generate", "--config", str(config), "--frames", "20000", "--seed", "1",
                      "-o", str(out)])  # fmt: skip
    assert mb < 500, f"peak RSS {mb:.0f} MB"
    assert read(out).n_frames == 20000
    # Reading a range of the 20,000-frame file costs in proportion to the range.
    ten, hundred = range_cost(out, 12_000, 10), range_cost(out, 12_000, 100)
    assert 8 < hundred / ten < 11
    assert hundred < os.path.getsize(out) / 50
    # Validating it streams too.
    _, mb = peak_rss(["validate", str(out)])  # raises unless it exits 0
    assert mb < 500, f"validate peak RSS {mb:.0f} MB"
