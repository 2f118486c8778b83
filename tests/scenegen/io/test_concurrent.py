"""Concurrent use: many processes writing into one folder never collide, and a reader sees
either the old complete file or the new complete one, or a clear one-line error.

Writers never write at the target path (see :mod:`scenegen.io`), so there is no half-
written file to read. HDF5 SWMR is not used: a file that another (non-scenegen) process
holds open for writing is refused with "is being written by another process".
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time

import h5py
import numpy as np
import pytest

from scenegen import io
from scenegen.config import from_dict
from scenegen.errors import DataError
from scenegen.io import open_checked, read, temp_file_owner, temp_prefix, write_scenario
from scenegen.io.export import export_mot
from scenegen.io.validate import check_file
from scenegen.render.plan import plan

SCENE = {
    "name": "busy", "width": 320, "height": 240, "n_frames": 60,
    "background": {"kind": "noise", "low": 0, "high": 60},
    "entities": [
        {"name": "t", "role": "target", "position": [60, 60],
         "appearance": {"shape": "ellipse", "size": [30, 40], "pattern": "rings",
                        "colors": [[255, 0, 0], [0, 200, 0]]},
         "motion": {"x": {"boundary": "reflect", "sigma": 2}, "y": {"boundary": "reflect"},
                    "velocity": [2, 1]}},
        {"name": "o", "role": "occluder", "position": [160, 120], "depth": 1,
         "appearance": {"size": [20, 120], "colors": [[90, 90, 90]]}},
    ],
}  # fmt: skip


def cli(*args: object) -> list[str]:
    return [sys.executable, "-m", "scenegen.cli", *map(str, args)]


def start(*args: object) -> subprocess.Popen:
    return subprocess.Popen(cli(*args), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def finish(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0, err.decode()


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "busy.json"
    path.write_text(json.dumps(SCENE))
    return path


def test_many_writers_in_one_folder(tmp_path, config):
    """Six processes at once: three to their own files, three to the same file."""
    out = tmp_path / "out"
    out.mkdir()
    procs = [start("generate", "--config", config, "--seed", s, "-o", out / name)
             for s, name in ((1, "own1.h5"), (2, "own2.h5"), (3, "own3.h5"),
                             (4, "same.h5"), (5, "same.h5"), (6, "same.h5"))]  # fmt: skip
    finish(procs)
    assert sorted(p.name for p in out.iterdir()) == ["own1.h5", "own2.h5", "own3.h5", "same.h5"]
    for s in (1, 2, 3):
        assert check_file(out / f"own{s}.h5") == [] and read(out / f"own{s}.h5").seed == s
    assert check_file(out / "same.h5") == [] and read(out / "same.h5").seed in (4, 5, 6)


def test_reader_sees_whole_files_while_writers_replace_them(tmp_path, config):
    target = tmp_path / "live.h5"
    write_scenario(target, plan(from_dict(SCENE), 0))
    writers = [start("generate", "--config", config, "--seed", s, "-o", target)
               for s in (7, 8)]  # fmt: skip
    seen, problems = set(), []
    while any(p.poll() is None for p in writers) or not seen:
        seq = read(target)
        seen.add(seq.seed)
        frames = np.asarray(seq.frames)  # every frame of the file opened
        assert frames.shape == (60, 240, 320, 3)
        problems += check_file(target)
    finish(writers)
    assert problems == []
    assert seen <= {0, 7, 8} and read(target).seed in (7, 8)


def test_an_open_sequence_keeps_reading_the_file_it_opened(tmp_path):
    target = tmp_path / "s.h5"
    cfg = from_dict({**SCENE, "n_frames": 5})
    write_scenario(target, plan(cfg, 1))
    old = read(target)
    first = old.frames[2]
    write_scenario(target, plan(cfg, 2))  # replaced while ``old`` is open
    np.testing.assert_array_equal(old.frames[2], first)  # still the old, complete file
    assert read(target).seed == 2
    old.frames.close()
    with pytest.raises(DataError, match="was replaced or changed since it was read"):
        old.frames[0]


def test_a_replacement_between_ground_truth_and_pixels_is_never_mixed(tmp_path, monkeypatch):
    """The file is replaced after ``read`` has read the ground truth but before it opens
    the pixels: it reads again, and returns the new version consistently."""
    target = tmp_path / "s.h5"
    cfg = from_dict({**SCENE, "n_frames": 4})
    write_scenario(target, plan(cfg, 1))
    real = io.LazyArray.__init__
    calls = []

    def replace_first(self, *args, **kwargs):
        if not calls:
            write_scenario(target, plan(cfg, 2))
        calls.append(args)
        real(self, *args, **kwargs)

    monkeypatch.setattr(io.LazyArray, "__init__", replace_first)
    seq = read(target)
    assert len(calls) == 3  # the first attempt failed at its first lazy array
    new = plan(cfg, 2).render()
    assert seq.seed == 2
    np.testing.assert_array_equal(seq.frames[3], new.frames[3])
    np.testing.assert_array_equal(seq.gt.box, new.gt["box"])


@pytest.mark.skipif(
    os.environ.get("HDF5_USE_FILE_LOCKING", "").upper() == "FALSE",
    reason="HDF5 file locking is switched off",
)
def test_a_file_held_open_for_writing_is_refused_in_one_line(tmp_path, capsys):
    target = tmp_path / "held.h5"
    write_scenario(target, plan(from_dict({**SCENE, "n_frames": 3}), 1))
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import sys, time, h5py\n"
         "f = h5py.File(sys.argv[1], 'r+')\n"
         "print('open', flush=True)\n"
         "time.sleep(60)\n", str(target)],
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert holder.stdout.readline().strip() == "open"
        line = f"{target}: is being written by another process (the HDF5 file is locked)"
        with pytest.raises(DataError) as err:
            read(target)
        assert str(err.value) == line
        assert check_file(target) == [line]
        from scenegen.cli import main

        assert main(["inspect", str(target)]) == 1
        assert capsys.readouterr().err == f"scenegen: error: {line}\n"
    finally:
        holder.kill()
        holder.wait()


def test_a_temporary_file_being_written_is_refused(tmp_path, config):
    target = tmp_path / "big.h5"
    proc = start("generate", "--config", config, "--frames", 20000, "-o", target)
    try:
        deadline = time.monotonic() + 120
        while not (found := sorted(tmp_path.glob(".big.h5.tmp-*"))):
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
        with pytest.raises(DataError) as err:
            open_checked(found[0])
        assert str(err.value) == (
            f"{found[0]}: an unfinished temporary file of a write to 'big.h5' "
            f"(process {proc.pid} on {temp_file_owner(found[0])[2]}, running)"
        )
    finally:
        proc.kill()
        proc.wait()


def test_concurrent_exports_to_one_folder(tmp_path):
    """Three exports replace one existing folder at once: one complete folder remains."""
    sources = []
    for n in (4, 6, 8):
        path = tmp_path / f"s{n}.h5"
        write_scenario(path, plan(from_dict({**SCENE, "n_frames": n}), n))
        sources.append(path)
    out = tmp_path / "mot"
    export_mot(read(sources[0]), out)
    finish([start("export", s, "--format", "mot", "-o", out) for s in sources])
    n = len(list((out / "img1").glob("*.png")))
    assert n in (4, 6, 8)
    gt = np.loadtxt(out / "gt" / "gt.txt", delimiter=",", ndmin=2)
    assert gt[:, 0].max() == n and f"seqLength={n}" in (out / "seqinfo.ini").read_text()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_temporary_names_are_unique_per_process_and_call(tmp_path):
    """Two threads of one process writing the same target at once."""
    errors = []
    cfg = from_dict({**SCENE, "n_frames": 20})

    def write(seed):
        try:
            write_scenario(tmp_path / "t.h5", plan(cfg, seed))
        except Exception as err:  # reported below
            errors.append(err)

    threads = [threading.Thread(target=write, args=(s,)) for s in (1, 2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == [] and check_file(tmp_path / "t.h5") == []
    assert [p.name for p in tmp_path.iterdir()] == ["t.h5"]
    assert temp_prefix("t.h5").startswith(".t.h5.tmp-")
    with h5py.File(tmp_path / "t.h5") as f:
        assert f["sequences/busy"].attrs["seed"] in (1, 2)
