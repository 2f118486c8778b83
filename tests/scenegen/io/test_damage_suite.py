"""The damaged-file suite: seeded damaged variants (``damage.py``) of a sequence file
(uncompressed and gzip), a tracker result file and an old-format file (variable-length
strings, no digests), run through ``validate`` and the verbs that read files.

Every variant must be answered (no hang: each slow case runs in a guarded child with a
deadline), with no traceback and one line per problem; ``validate`` must reject every
variant whose readable content differs from the original (0 wrong "valid"), and
``validate --deep`` every edit whose digests were recomputed. Damage that falls on unused
bytes changes nothing readable: "valid" is then right ("harmless" below).

The fast suite runs a few dozen variants in this process; ``make test-slow`` runs 1,040,
each in its own guarded child, and prints the figures kept in the README.
"""

from __future__ import annotations

import os
import shutil
from collections import Counter

import numpy as np
import pytest
from damage import KINDS, RESULT_KINDS, content, old_format, run_case, variants

from scenegen.config import from_dict
from scenegen.errors import DataError
from scenegen.io import TrackerResult, guard, write_result, write_scenario
from scenegen.io.validate import check_file
from scenegen.render.plan import plan

SCENE = {
    "name": "small", "width": 48, "height": 40, "n_frames": 6,
    "background": {"kind": "noise"},
    "entities": [
        {"name": "a", "role": "target", "position": [10, 20], "depth": 1,
         "appearance": {"shape": "ellipse", "size": [9, 9], "colors": [[255, 0, 0]]},
         "motion": {"x": {"boundary": "reflect"}, "y": {"boundary": "reflect"},
                    "velocity": [3, 0]}},
        {"name": "b", "role": "distractor", "position": [38, 22], "depth": 2,
         "appearance": {"shape": "rect", "size": [7, 11], "colors": [[0, 0, 255]]}},
    ],
    "clutter": [{"count": 3, "name": "clutter"}],
}  # fmt: skip


@pytest.fixture(scope="module")
def sources(tmp_path_factory):
    d = tmp_path_factory.mktemp("sources")
    scn = plan(from_dict(SCENE), 3)
    out = {"seq-none": d / "seq-none.h5", "seq-gzip": d / "seq-gzip.h5"}
    write_scenario(out["seq-none"], scn, compression="none")
    write_scenario(out["seq-gzip"], scn, compression="gzip")
    out["result"] = d / "result.h5"
    write_result(out["result"], TrackerResult(
        tracker="shm", params={"n": 3}, seed=1, sequence="small",
        target_ids=np.array([1], np.int32), boxes=np.arange(24, dtype=np.float32).reshape(6, 1, 4),
        orderings=np.array([[0]], np.int16), order_prob=np.ones((6, 1), np.float32),
    ))  # fmt: skip
    out["old"] = d / "old.h5"
    old_format(out["seq-none"], out["old"])
    for p in out.values():
        assert check_file(p) == [], p
    return out


def _verbs(kind: str, path: str, sources, out: str, i: int) -> list[list[str]]:
    """The other verb run on variant ``i`` (one per variant, in rotation)."""
    if kind == "result":
        return [["evaluate", str(sources["seq-none"]), path]]
    choice = i % 6
    return [
        [["inspect", path]],
        [["track", path, "--tracker", "kalman", "-o", out + ".r.h5"]],
        [["export", path, "--format", "mot", "-o", out + ".mot"]],
        [["preview", path, "-o", out + ".png"]],
        [["evaluate", path, str(sources["result"])]],
        [["inspect", path, "--json"]],
    ][choice]


class Tally:
    def __init__(self) -> None:
        self.counts: Counter[str] = Counter()
        self.failures: list[str] = []

    def fail(self, what: str, line: str) -> None:
        self.counts[what] += 1
        self.failures.append(f"{what}: {line}")


def _one_line_each(results, path: str) -> bool:
    for code, err in results:
        if code not in (0, 1, 2) or "Traceback" in err or "internal error" in err:
            return False
        if code and not err.strip():
            return False
        if any(not (ln.startswith(path) or ln.startswith("scenegen: error: "))
               for ln in err.splitlines()):  # fmt: skip
            return False
    return True


def judge(tally, src_kind, src, v, dst, results, original, in_child=True):
    """Classify one variant's outcome into ``tally``."""
    path = str(dst)
    (vcode, verr), *others = results
    if not _one_line_each(results, path):
        tally.fail("traceback or garbled output", f"{v.name}: {results}")
        return
    if vcode == 1:
        tally.counts["reported by validate"] += 1
        return
    try:
        same = guard.call(content, path, label=path) == original
    except DataError:
        same = False
    if same:
        tally.counts["harmless (unused bytes)"] += 1
    elif src_kind == "old":
        tally.counts["old format: undetectable without digests"] += 1
    else:
        tally.fail("WRONG VALID", f"{src_kind} {v.name}: {verr.strip()}")


def _fast_variants(sources):
    for src_kind, per in (("seq-none", 13), ("seq-gzip", 6), ("result", 7)):
        kinds = RESULT_KINDS if src_kind == "result" else KINDS
        yield from ((src_kind, v) for v in variants(sources[src_kind], per, seed=11, kinds=kinds))


def test_fast_damaged_variants(sources, tmp_path, monkeypatch):
    """A few dozen variants, every kind, in this process: validate (and --deep where an
    edit was resealed) answers with one line per problem and no wrong "valid"."""
    monkeypatch.setenv("SCENEGEN_READ_TIMEOUT", "2")
    from scenegen.cli import main

    tally = Tally()
    originals = {k: guard.call(content, str(p), label="o") for k, p in sources.items()}
    for i, (src_kind, v) in enumerate(_fast_variants(sources)):
        dst = tmp_path / f"v{i}.h5"
        v.apply(dst)
        guard.clear_cache()
        argv = ["validate", *(["--deep"] if v.deep else []), str(dst)]
        results = run_case([argv], 2)
        if i % 5 == 0:  # and now and then another verb, in this process too
            results += run_case(_verbs(src_kind, str(dst), sources, str(tmp_path / f"o{i}"), i), 2)
        judge(tally, src_kind, sources[src_kind], v, dst, results, originals[src_kind])
    assert main(["validate", str(sources["seq-none"])]) == 0
    assert sum(tally.counts.values()) == 26
    assert tally.failures == []
    assert tally.counts["reported by validate"] >= 20


@pytest.mark.slow
def test_slow_damaged_variants(sources, tmp_path, capsys):
    """1,040 variants (13 kinds x 80 per kind, over four files), each in a guarded child
    with a 120 s deadline (inner reads 3 s): no hang, no traceback, no wrong "valid"."""
    tally = Tally()
    originals = {k: guard.call(content, str(p), label="o") for k, p in sources.items()}
    scale = int(os.environ.get("SCENEGEN_DAMAGE_SCALE", "52"))  # 52: 1,040 variants
    plan_ = [("seq-none", 7 * scale), ("seq-gzip", 5 * scale), ("result", 5 * scale),
             ("old", 3 * scale)]  # fmt: skip
    i = 0
    for src_kind, n in plan_:
        kinds = RESULT_KINDS if src_kind == "result" else KINDS
        for v in variants(sources[src_kind], n, seed=2026, kinds=kinds):
            dst = tmp_path / f"v{i % 4}.h5"
            v.apply(dst)
            argvs = [["validate", *(["--deep"] if v.deep else []), str(dst)]]
            argvs += _verbs(src_kind, str(dst), sources, str(tmp_path / "o"), i)
            try:
                results = guard.call(run_case, argvs, 3.0, label=str(dst), seconds=120)
            except guard.Unreadable as err:
                tally.fail("HANG", f"{src_kind} {v.name}: {err}")
            else:
                judge(tally, src_kind, sources[src_kind], v, dst, results, originals[src_kind])
            for extra in tmp_path.glob("o*"):
                shutil.rmtree(extra) if extra.is_dir() else extra.unlink()
            i += 1
    with capsys.disabled():
        print(f"\ndamaged variants tried: {i}; " + "; ".join(
            f"{k}: {n}" for k, n in sorted(tally.counts.items())))  # fmt: skip
        for line in tally.failures[:20]:
            print("  " + line)
    assert i == 20 * scale and len(KINDS) == 13
    assert tally.failures == []
