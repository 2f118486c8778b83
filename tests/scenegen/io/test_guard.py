"""The guard of reads of unknown files (:mod:`scenegen.io.guard`): a stall or a crash of
the HDF5 library in the child becomes one line; the child dies with its parent; every
verb that opens an input file answers on a file whose global heap is zeroed (the HDF5
library loops forever reading its strings)."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import pytest
from damage import old_format

import scenegen
from scenegen.cli import main
from scenegen.errors import ConfigError, DataError
from scenegen.io import guard, read, read_result
from scenegen.io.validate import check_file

FIXTURE = os.path.join(os.path.dirname(__file__), "..", "..", "..", "fixtures",
                       "dps-synthetic-small.h5")  # fmt: skip


def heap_zeroed(src: str, dst) -> None:
    """``src`` in the old format (strings on the global heap) with the body of its first
    global heap collection zeroed (the collection header kept): libhdf5 then loops
    reading the strings stored there."""
    old = dst.with_name("old.h5")
    old_format(Path(src), old)
    data = bytearray(old.read_bytes())
    at = data.find(b"GCOL")
    assert at > 0, "no variable-length strings in the old-format copy"
    data[at + 16 : at + 4096] = bytes(4096 - 16)
    dst.write_bytes(bytes(data))


@pytest.fixture
def looping(tmp_path, monkeypatch):
    monkeypatch.setenv("SCENEGEN_READ_TIMEOUT", "1")
    path = tmp_path / "heap.h5"
    heap_zeroed(FIXTURE, path)
    return path


def test_new_files_have_no_global_heap(tmp_path):
    """Strings are fixed-length: nothing for a damaged heap to corrupt or loop on."""
    path = tmp_path / "new.h5"
    scenegen.write(path, scenegen.read(FIXTURE))
    assert b"GCOL" not in path.read_bytes()


def test_results_and_errors_come_back():
    assert guard.call(int, "12", label="x") == 12
    with pytest.raises(DataError, match=r"^x: could not be read \(ValueError: invalid literal"):
        guard.call(int, "twelve", label="x")
    with pytest.raises(ConfigError, match="^bad$"):
        guard.call(_config_error, label="x")


def _config_error():
    raise ConfigError("bad")


def test_a_crash_is_one_line():
    with pytest.raises(guard.Unreadable) as err:
        guard.call(os.abort, label="f.h5")
    assert (
        str(err.value) == "f.h5: metadata unreadable: the HDF5 library crashed reading it (SIGABRT)"
    )


def test_a_stall_is_killed_at_the_deadline():
    with pytest.raises(guard.Unreadable) as err:
        guard.call(time.sleep, 600, label="f.h5", seconds=0.5)
    assert str(err.value) == (
        "f.h5: metadata unreadable: no answer from the HDF5 library within 0.5 s (damaged file)"
    )


def test_the_deadline_comes_from_the_environment(monkeypatch):
    monkeypatch.setenv("SCENEGEN_READ_TIMEOUT", "2.5")
    assert guard.timeout() == 2.5
    for bad in ("", "soon", "-1", "nan", "inf"):
        monkeypatch.setenv("SCENEGEN_READ_TIMEOUT", bad)
        assert guard.timeout() == guard.TIMEOUT


def test_the_survey_reads_a_sound_file_and_is_cached():
    guard.clear_cache()
    assert guard.call(guard.survey, FIXTURE, label="f") > 10
    guard.preflight(FIXTURE)
    assert len(guard._cache) == 1
    guard.preflight(FIXTURE)  # a second read of the same version: no child
    assert len(guard._cache) == 1


def test_every_reader_answers_on_a_looping_file(looping, tmp_path, capsys):
    line = f"{looping}: metadata unreadable: no answer from the HDF5 library within 1 s"
    assert check_file(looping, isolate=True)[0].startswith(line)
    for fn in (read, read_result):
        with pytest.raises(DataError, match="metadata unreadable"):
            fn(looping)
    out = tmp_path / "out"
    verbs = [
        ["validate", str(looping)],
        ["inspect", str(looping)],
        ["track", str(looping), "--tracker", "kalman", "-o", str(out / "r.h5")],
        ["preview", str(looping), "-o", str(out / "p.png")],
        ["export", str(looping), "--format", "mot", "-o", str(out / "mot")],
        ["evaluate", str(looping), str(looping)],
    ]
    for argv in verbs:
        assert main(argv) == 1, argv
        err = capsys.readouterr().err.splitlines()
        assert len(err) == 1 and "metadata unreadable" in err[0], (argv, err)
    assert not out.exists()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_no_child_outlives_its_parent(looping):
    """A parent killed while its guarded child loops inside libhdf5 (holding the GIL):
    the child dies too (PR_SET_PDEATHSIG once the fork server exits; else its alarm)."""
    code = textwrap.dedent(f"""
        import os, sys
        from scenegen.io import guard
        print(os.getpid(), flush=True)
        guard.call(guard.survey, {str(looping)!r}, label="x", seconds=300)
    """)
    parent = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        pid = int(parent.stdout.readline())
        kids = []
        for _ in range(600):  # the forkserver, then its child that loops
            kids = _descendants(pid)
            if len(kids) >= 3:
                break
            time.sleep(0.05)
        assert kids
    finally:
        parent.kill()
        parent.wait()
    for _ in range(400):
        alive = [k for k in kids if _alive(k)]
        if not alive:
            break
        time.sleep(0.05)
    assert alive == []


def _descendants(pid: int) -> list[int]:
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            if ppid == pid:
                out.append(int(entry))
    return out + [g for k in out for g in _descendants(k)]


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _guarded_int(text):
    return guard.call(int, text, label="x")


def test_a_pool_worker_can_start_a_guard():
    """Workers of a multiprocessing pool are daemonic; the guard still runs there."""
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.apply(_guarded_int, ("5",)) == 5


def _read_frame_count(path):
    return int(read(path).frames.shape[0])


def test_a_forked_worker_starts_a_guard_after_its_parent_did(tmp_path):
    """A DataLoader worker is forked after the parent read a file: the fork server it
    inherits is not its child, and every guarded read there failed (ChildProcessError)."""
    import multiprocessing

    for name in ("a.h5", "b.h5"):
        scenegen.write(tmp_path / name, scenegen.generate("kams-a", seed=1, frames=2))
    guard.clear_cache()  # files we did not write are surveyed in a guarded child
    assert _read_frame_count(tmp_path / "a.h5") == 2  # the parent's guard starts its server
    with multiprocessing.get_context("fork").Pool(1) as pool:
        assert pool.apply(_read_frame_count, (tmp_path / "b.h5",)) == 2


_READ_IN_A_FRESH_PROCESS = """
import sys, tempfile
from scenegen.cli import main
from scenegen.io import guard
if sys.argv[1] == "missing":
    tempfile.tempdir = sys.argv[2]  # as a program may set it
if sys.argv[1] == "none":
    tempfile.tempdir = sys.argv[2]
    guard._SYSTEM_TEMP_DIRS = ()  # and /tmp, /var/tmp unusable too
sys.exit(main(["validate", sys.argv[3]]))
"""


@pytest.mark.parametrize("case", ["missing", "long"])
def test_a_bad_temporary_folder_does_not_stop_a_guarded_read(tmp_path, case):
    # With tempfile.tempdir on a folder that cannot be written (missing here: root writes
    # anywhere), or TMPDIR longer than a Unix socket path allows, the fork server could not
    # listen: "internal error: FileNotFoundError: [Errno 2] No such file or directory:
    # '/.../pymp-...'", or "internal error: OSError: AF_UNIX path too long" (exit 1).
    long = tmp_path / ("x" * 100)
    long.mkdir()
    env = {**os.environ, "TMPDIR": str(long)} if case == "long" else dict(os.environ)
    done = subprocess.run([sys.executable, "-c", _READ_IN_A_FRESH_PROCESS, case,
                           str(tmp_path / "missing"), FIXTURE],
                          capture_output=True, text=True, env=env, timeout=120)  # fmt: skip
    assert (done.returncode, done.stderr) == (0, "")


def test_no_usable_temporary_folder_is_one_line_naming_tmpdir():
    # A short base, so that the folder is refused for being missing and not for its
    # length: pytest's tmp_path (longer under pytest-xdist, /popen-gwN/) may be too long
    # for a socket path already; that reason is checked by the test above.
    with tempfile.TemporaryDirectory(prefix="sg-", dir="/tmp") as short:
        missing = os.path.join(short, "missing")
        env = {**os.environ, "TMPDIR": missing}
        done = subprocess.run([sys.executable, "-c", _READ_IN_A_FRESH_PROCESS, "none",
                               missing, FIXTURE],
                              capture_output=True, text=True, env=env, timeout=120)  # fmt: skip
    assert done.returncode == 2
    assert done.stderr == (
        "scenegen: error: no usable temporary folder to start child processes in (TMPDIR="
        f"{missing!r}; {missing}: No such file or directory): "
        "set TMPDIR to a writable folder with a short path\n"
    )


_MODULES_IN_A_GUARDED_CHILD = """
import sys
from scenegen.io import guard

if __name__ == "__main__":
    # eval: a builtin, so the child runs it without importing anything of this script
    print(",".join(guard.call(eval, "sorted(set(PRELOAD) & set(sys.modules))", label="x")))
"""


def test_the_fork_server_has_imported_what_guarded_children_run(tmp_path):
    """A child forked by a fresh process's fork server finds the checks imported already
    (each child importing ``scenegen.io.validate`` itself cost ~0.11 s a check)."""
    from scenegen.io.validate import _checked

    assert {guard.survey.__module__, _checked.__module__} <= set(guard.PRELOAD)
    script = tmp_path / "probe.py"
    script.write_text(_MODULES_IN_A_GUARDED_CHILD)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)  # fmt: skip
    assert (done.returncode, done.stderr) == (0, "")
    # The forkserver ignores a module it cannot import: a misspelt name would show here.
    assert done.stdout.strip().split(",") == sorted(guard.PRELOAD)
