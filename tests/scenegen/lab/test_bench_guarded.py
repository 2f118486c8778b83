"""The guarded-read rows of the bench: each check in this process against the same check
in a guarded child, and the first guarded read of a fresh process."""

import pytest

from scenegen.lab.bench import MODULES
from scenegen.lab.bench import guarded as bench


def test_guarded_rows_time_each_check_against_the_same_check_in_process():
    assert "scenegen.lab.bench.guarded" in MODULES
    rows = bench.run(1)
    assert [r.name for r in rows] == [
        "in this process (baseline)",
        "in a guarded child (running fork server)",
        "survey in this process, unguarded (baseline)",
        "preflight, a new file (running fork server)",
        "preflight, first of a process (starts the fork server)",
    ]
    check, pre = rows[:2], rows[2:]
    assert len({r.group for r in check}) == len({r.group for r in pre}) == 1
    assert check[0].group.startswith("require_valid's check of dps-synthetic seed 1 (")
    assert pre[0].group.startswith("read()'s metadata preflight of dps-synthetic seed 1 (")
    for base, others in ((check[0], check[1:]), (pre[0], pre[1:])):
        assert base.baseline == ""
        for r in others:
            assert r.baseline == base.name
            assert r.ratio == pytest.approx(base.seconds / r.seconds)
    for r in rows:
        assert r.seconds > 0 and r.rate == pytest.approx(1 / r.seconds)
        assert r.unit == "files/s" and r.goal == "" and r.met is None


def test_each_timed_call_gets_a_file_version_no_cache_has_seen(tmp_path):
    src = tmp_path / "src.h5"
    src.write_bytes(b"x" * 10)
    copies = bench._Copies(src, tmp_path)
    seen: list[str] = []
    bench._timed_on_copies(seen.append, copies, 3)
    assert len(seen) == len(set(seen)) == 4  # one warm-up call and three timed
    assert all((tmp_path / p).read_bytes() == b"x" * 10 for p in seen)
