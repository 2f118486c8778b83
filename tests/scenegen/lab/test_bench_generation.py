"""The write rows of the generation bench: plain h5py, plain h5py made durable, ours."""

import os

import pytest

from scenegen.lab.bench import generation as bench

COMPRESSIONS = ("none", "lzf")  # gzip would only take longer


def test_write_rows_time_plain_durable_and_atomic_writes(monkeypatch):
    events: list[tuple[str, str]] = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        events.append(("fsync", os.readlink(f"/proc/self/fd/{fd}").rsplit("/", 1)[-1]))
        return real_fsync(fd)

    def replace(src, dst):
        events.append(("replace", os.fspath(dst).rsplit("/", 1)[-1]))
        return real_replace(src, dst)

    monkeypatch.setattr(bench.os, "fsync", fsync)
    monkeypatch.setattr(bench.os, "replace", replace)
    monkeypatch.setattr(bench, "COMPRESSIONS", COMPRESSIONS)
    rows = bench.write_rows(1)
    assert len(rows) == 3 * len(COMPRESSIONS)
    for i, comp in enumerate(COMPRESSIONS):
        plain, durable, ours = rows[3 * i : 3 * i + 3]
        assert {r.group for r in (plain, durable, ours)} == {
            f"write kams-d (frames, labels, gt, 601 templates), {comp}"}
        assert plain.baseline == "" and durable.baseline == ours.baseline == plain.name
        for r in (durable, ours):
            assert r.ratio == pytest.approx(plain.seconds / r.seconds)
        assert plain.rate == pytest.approx(1 / plain.seconds)  # frames/s of seconds a frame
        assert [r.goal != "" for r in (plain, durable, ours)] == [False, False, True]
        assert ours.met == (ours.ratio >= 0.8)
    # The durable baseline flushes its file, renames it onto the target, flushes the folder.
    at = events.index(("replace", "durable.h5"))
    assert events[at - 1] == ("fsync", ".durable.h5.tmp")
    assert events[at + 1][0] == "fsync" and events[at + 1][1] not in ("durable.h5", "")
