"""Atomic writes: a writer killed with SIGKILL mid-write leaves no file at the target path
and an earlier file there untouched; its leftover temporary file is removed by the next
write of the same target.

Real subprocesses are killed: ``generate`` and ``export`` while their temporary output
grows, and every writer (``generate``, ``track``, ``export``) at a fixed point inside its
write by a hook that SIGKILLs its own process.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from scenegen.config import from_dict
from scenegen.errors import ConfigError
from scenegen.io import (
    atomic_path,
    clean_temp_files,
    read,
    temp_file_owner,
    temp_prefix,
    write,
    write_scenario,
)
from scenegen.io.validate import check_file
from scenegen.render.plan import plan

# 640x480 on a uniform background: ~7 ms a frame with gzip, so 20,000 frames run for
# minutes, long enough to be killed mid-write.
LONG = {
    "name": "long", "width": 640, "height": 480, "n_frames": 20000,
    "background": {"kind": "uniform", "color": [200, 220, 255]},
    "entities": [
        {"name": "t", "role": "target", "position": [100, 100],
         "appearance": {"shape": "ellipse", "size": [40, 60], "pattern": "rings",
                        "colors": [[255, 0, 0], [0, 200, 0]]},
         "motion": {"x": {"boundary": "reflect", "sigma": 2, "a1": 1.9, "a2": -0.9},
                    "y": {"boundary": "reflect", "sigma": 2, "a1": 1.9, "a2": -0.9},
                    "velocity": [3, 2]}},
    ],
}  # fmt: skip
SMALL = {**LONG, "name": "small", "width": 64, "height": 48, "n_frames": 6}
SMALL["entities"] = [{**LONG["entities"][0], "position": [30, 20],
                      "appearance": {"shape": "rect", "size": [9, 9]}}]  # fmt: skip


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def tree_digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): digest(p) for p in folder.rglob("*") if p.is_file()}


def cli(*args: object) -> list[str]:
    return [sys.executable, "-m", "scenegen.cli", *map(str, args)]


def temps(folder: Path, name: str) -> list[Path]:
    return sorted(folder.glob(f".{name}.tmp-*"))


def wait_for_temp(proc: subprocess.Popen, folder: Path, name: str, ready) -> Path:
    """The temporary output of ``proc`` once ``ready(path)``; fails if it never is."""
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        assert proc.poll() is None, proc.stderr.read()
        found = temps(folder, name)
        if found and ready(found[0]):
            return found[0]
        time.sleep(0.02)
    proc.kill()
    pytest.fail(f"no temporary {name} appeared")


def kill(proc: subprocess.Popen) -> None:
    os.kill(proc.pid, signal.SIGKILL)
    assert proc.wait(timeout=30) == -signal.SIGKILL


@pytest.fixture
def small_file(tmp_path):
    path = tmp_path / "small.h5"
    write_scenario(path, plan(from_dict(SMALL), 1))
    return path


@pytest.fixture
def long_config(tmp_path):
    path = tmp_path / "long.json"
    path.write_text(json.dumps(LONG))
    return path


def test_generate_killed_mid_write(tmp_path, long_config, small_file):
    """Two writers killed mid-write at once: one over an earlier file, one to a new path."""
    earlier, fresh = tmp_path / "earlier.h5", tmp_path / "fresh.h5"
    earlier.write_bytes(small_file.read_bytes())
    before = digest(earlier)
    procs = {
        target: subprocess.Popen(
            cli("generate", "--config", long_config, "--seed", 3, "-o", target),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )  # fmt: skip
        for target in (earlier, fresh)
    }
    leftovers = {}
    for target, proc in procs.items():
        big = lambda p: p.stat().st_size > 500_000  # noqa: E731 - frames on disk
        leftovers[target] = wait_for_temp(proc, tmp_path, target.name, big)
        kill(proc)
    assert digest(earlier) == before and check_file(earlier) == []
    assert not fresh.exists()
    for target, tmp in leftovers.items():
        # The leftover names its writer, and validate says what it is.
        assert temp_file_owner(tmp)[:2] == (target.name, procs[target].pid)
        assert f"an unfinished temporary file of a write to '{target.name}'" in check_file(tmp)[0]
    # Rerunning the command removes the leftover and writes a complete file.
    done = subprocess.run(
        cli("generate", "--config", long_config, "--frames", 3, "-o", fresh),
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert check_file(fresh) == [] and temps(tmp_path, "fresh.h5") == []
    assert temps(tmp_path, "earlier.h5") == [leftovers[earlier]]  # another target's: kept


def test_export_killed_mid_write(tmp_path, small_file):
    seq_path = tmp_path / "long.h5"
    write_scenario(seq_path, plan(from_dict({**LONG, "n_frames": 200}), 2), compression="lzf")
    out = tmp_path / "mot"
    subprocess.run(cli("export", small_file, "--format", "mot", "-o", out), check=True)
    before = tree_digest(out)
    proc = subprocess.Popen(
        cli("export", seq_path, "--format", "mot", "-o", out),
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    tmp = wait_for_temp(proc, tmp_path, "mot", lambda p: len(list(p.glob("img1/*.png"))) > 5)
    kill(proc)
    assert tree_digest(out) == before and len(before) == 6 + 2  # 6 frames, gt.txt, ini
    assert tmp.is_dir()
    done = subprocess.run(
        cli("export", small_file, "--format", "mot", "-o", out), capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert temps(tmp_path, "mot") == [] and tree_digest(out) == before


# Run the CLI with one function of the writing code replaced by a SIGKILL of the process.
HOOK = """
import importlib, os, signal, sys
module = importlib.import_module(sys.argv[1])
setattr(module, sys.argv[2], lambda *a, **k: os.kill(os.getpid(), signal.SIGKILL))
from scenegen.cli import main
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.parametrize(
    ("verb", "module", "name"),
    [
        ("generate", "scenegen.io.hdf5", "_write_templates"),  # frames and gt on disk
        ("track", "scenegen.io.results", "_write_header"),  # the result file just created
        ("export", "scenegen.io.export", "_replace_dir"),  # every frame written, not swapped
    ],
)
def test_killed_inside_the_write(tmp_path, small_file, verb, module, name):
    """Each writer killed at a fixed point inside its write: the earlier output stays
    byte for byte, the target is never partial, one temporary leftover remains."""
    out = tmp_path / ("mot" if verb == "export" else "out.h5")
    first = {
        "generate": ["generate", "--preset", "kams-a", "--frames", 3, "-o", out],
        "track": ["track", small_file, "--tracker", "kalman", "-o", out],
        "export": ["export", small_file, "--format", "mot", "-o", out],
    }[verb]
    subprocess.run(cli(*first), check=True, capture_output=True)
    before = tree_digest(out) if out.is_dir() else digest(out)
    again = list(first)
    if verb == "export":
        again[1] = tmp_path / "other.h5"
        write_scenario(again[1], plan(from_dict({**SMALL, "n_frames": 4}), 9))
    proc = subprocess.run(
        [sys.executable, "-c", HOOK, module, name, *map(str, again)],
        capture_output=True, text=True,
    )  # fmt: skip
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    assert (tree_digest(out) if out.is_dir() else digest(out)) == before
    assert len(temps(tmp_path, out.name)) == 1


def test_failed_write_leaves_nothing(tmp_path):
    target = tmp_path / "x.h5"
    target.write_bytes(b"earlier")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_bytes(b"partial")
        raise RuntimeError("boom")
    assert target.read_bytes() == b"earlier" and list(tmp_path.iterdir()) == [target]
    with atomic_path(target) as tmp:
        tmp.write_bytes(b"new")
    assert target.read_bytes() == b"new" and list(tmp_path.iterdir()) == [target]
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's private 0o600
    with pytest.raises(ConfigError, match="does not exist"), atomic_path(tmp_path / "no" / "x"):
        pass
    with pytest.raises(ConfigError, match="is a folder"), atomic_path(tmp_path):
        pass
    # A file where a folder of the path should be is named (it "did not exist").
    afile = tmp_path / "afile"
    afile.write_text("x")
    for out in (afile / "x", afile / "sub" / "x"):
        with pytest.raises(ConfigError, match=rf"^{out}: {afile} is a file, not a folder$"):
            with atomic_path(out):
                pass


def test_clean_temp_files_removes_only_stale_leftovers(tmp_path):
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    host = temp_file_owner(temp_prefix("a.h5"))[2]

    def leftover(pid, rand, target="a.h5", where=host):
        return tmp_path / f".{target}.tmp-{pid}@{where}-{rand}"

    stale = leftover(gone.pid, "x1")
    stale_dir = leftover(gone.pid, "d2")
    live = leftover(os.getppid(), "x3")  # pytest's parent: running
    own = leftover(os.getpid(), "x4")  # this process may still be writing it
    other_host = leftover(gone.pid, "x5", where="elsewhere")
    other_target = leftover(gone.pid, "x6", target="b.h5")
    for p in (stale, live, own, other_host, other_target):
        p.write_bytes(b"")
    (stale_dir / "img1").mkdir(parents=True)
    assert clean_temp_files(tmp_path, "a.h5") == sorted([stale, stale_dir])
    assert clean_temp_files(tmp_path) == [other_target]
    assert sorted(tmp_path.iterdir()) == sorted([live, own, other_host])


def test_rewriting_a_file_from_its_own_lazy_read(tmp_path, small_file):
    """``write(p, read(p))``: the lazy frames keep reading the old file while the new one
    is written beside it, then the new one replaces it."""
    seq = read(small_file)
    frames = np.asarray(seq.frames)
    write(small_file, seq, compression="lzf")
    back = read(small_file)
    np.testing.assert_array_equal(np.asarray(back.frames), frames)
    assert check_file(small_file) == [] and temps(small_file.parent, small_file.name) == []


def test_write_text_json_npy_helpers(tmp_path):
    from scenegen.io.atomic import write_json, write_npy, write_text

    write_text(tmp_path / "a.md", "héllo\n")
    assert (tmp_path / "a.md").read_text(encoding="utf-8") == "héllo\n"
    write_json(tmp_path / "b.json", {"z": 1, "a": [1.5, None]})
    assert (tmp_path / "b.json").read_text() == '{"a":[1.5,null],"z":1}\n'
    write_json(tmp_path / "c.json", {"z": 1, "a": 2}, indent=1, sort_keys=False)
    assert (tmp_path / "c.json").read_text() == '{\n "z": 1,\n "a": 2\n}\n'
    with pytest.raises(ValueError):
        write_json(tmp_path / "b.json", {"x": float("nan")})
    assert (tmp_path / "b.json").read_text() == '{"a":[1.5,null],"z":1}\n'  # untouched
    arr = np.array([[1.0, np.nan]], np.float32)
    write_npy(tmp_path / "deep" / "er" / "x.npy", arr, parents=True)
    back = np.load(tmp_path / "deep" / "er" / "x.npy")
    assert back.dtype == np.float32 and np.array_equal(back, arr, equal_nan=True)
    with pytest.raises(ConfigError, match="does not exist"):
        write_text(tmp_path / "missing" / "a.txt", "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.md", "b.json", "c.json", "deep"]


def test_a_device_or_fifo_is_never_replaced_and_a_link_is_written_through(tmp_path, capsys):
    # `generate -o /dev/null` replaced the machine's /dev/null with a regular file.
    from scenegen.cli import main
    from scenegen.io.atomic import write_text

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(ConfigError, match="fifo: is not a regular file"):
        write_text(fifo, "x")
    assert fifo.is_fifo()
    code = main(["generate", "--preset", "kams-a", "--frames", "2", "-o", str(fifo)])
    assert code == 2 and "is not a regular file" in capsys.readouterr().err and fifo.is_fifo()
    real = tmp_path / "real.txt"
    real.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(real)
    write_text(link, "new")
    assert link.is_symlink() and real.read_text() == "new"


def test_read_regular_refuses_a_fifo_a_device_and_a_folder_at_once(tmp_path, deadline):
    # Path.read_bytes() on a FIFO waits for a writer for ever: `scenegen validate` hung on
    # a FIFO in place of an output folder's table.md, leaderboard.md or index.html.
    from scenegen.io.atomic import SpecialFile, read_regular, read_regular_text

    fifo = tmp_path / "table.md"
    os.mkfifo(fifo)
    link = tmp_path / "link.md"
    link.symlink_to(fifo)
    with deadline(10):
        for p in (fifo, link):
            with pytest.raises(SpecialFile, match=f"^{p}: is not a regular file \\(a FIFO\\)$"):
                read_regular(p)
        if os.path.exists("/dev/zero"):
            with pytest.raises(SpecialFile, match="/dev/zero: is not a regular file \\(a dev"):
                read_regular_text("/dev/zero")
    with pytest.raises(IsADirectoryError, match=str(tmp_path)):
        read_regular(tmp_path)
    with pytest.raises(FileNotFoundError):
        read_regular(tmp_path / "none")
    text = tmp_path / "crlf.md"
    text.write_bytes(b"a\r\nb\rc\n\xc3\xa9")
    assert read_regular(text) == text.read_bytes()
    assert read_regular_text(text) == text.read_text(encoding="utf-8") == "a\nb\nc\né"
    text.write_bytes(b"\xff")
    with pytest.raises(UnicodeDecodeError):
        read_regular_text(text)
