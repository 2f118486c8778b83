"""The damaged-file suite: seeded damaged variants (``damage.py``) of a sequence file
(uncompressed and gzip), a tracker result file and an old-format file (variable-length
strings, no digests), run through ``validate`` and the verbs that read files.

Every variant must be answered (no hang: each slow case runs in a guarded child with a
deadline), with no traceback and one line per problem; ``validate`` must reject every
variant whose readable content differs from the original (0 wrong "valid"), and
``validate --deep`` every edit whose digests were recomputed. Damage that falls on unused
bytes changes nothing readable: "valid" is then right ("harmless" below).

The same holds for experiment outputs (a folder of sealed run records, ``results.json``
and ``table.md``): ``validate DIR`` reports every damaged variant, a resumed
``scenegen experiment`` computes damaged runs again (with a warning) and ends with the
original ``results.json``, and the report refuses a damaged ``results.json`` in one line.

The fast suite runs a few dozen variants of each in this process; ``make test-slow`` runs
1,040 file variants and 260 folder variants, each in its own guarded child, and prints the
figures kept in the README.
"""

from __future__ import annotations

import os
import shutil
from collections import Counter

import numpy as np
import pytest
from damage import (
    BENCHMARK_FILES,
    EXPERIMENT_FILES,
    FOLDER_KINDS,
    KINDS,
    RESULT_KINDS,
    content,
    folder_content,
    folder_variants,
    old_format,
    run_case,
    run_folder_case,
    variants,
)

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
        self.by_kind: Counter[str] = Counter()

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


# ---------------------------------------------------------------------------------------
# Experiment outputs

EXP = "shm-depth"
EXP_ARGS = ["--runs", "1", "--scenes", "1", "--quick", "--jobs", "1", "--method", "kalman",
            "--method", "shm-fast"]  # fmt: skip
_RESEALED = ("resealed", "wrong_type", "delete_key", "replaced")


@pytest.fixture(scope="module")
def experiment(tmp_path_factory):
    """A small experiment folder (4 sealed runs, results.json, table.md) and its content."""
    from scenegen.cli import main

    d = tmp_path_factory.mktemp("experiment") / EXP
    assert main(["experiment", EXP, *EXP_ARGS, "-o", str(d)]) == 0
    assert main(["validate", str(d)]) == 0
    return d, folder_content(str(d)), (d / "results.json").read_bytes()


def _folder_argvs(v, dst, i: int) -> tuple[list[list[str]], bool]:
    """validate DIR, and in rotation a resumed experiment or the report (True)."""
    argvs = [["validate", str(dst)]]
    if i % 3 == 1:
        argvs.append(["experiment", EXP, *EXP_ARGS, "-o", str(dst)])
    return argvs, i % 3 == 2


def print_folder_tally(what: str, n: int, tally: Tally, extra: list[str]) -> None:
    """The README's figures of a folder damage run: counts by outcome and by kind."""
    print(f"\n{what}-folder variants tried: {n}; " + "; ".join(
        f"{k}: {c}" for k, c in sorted(tally.counts.items())))  # fmt: skip
    for k in FOLDER_KINDS:
        tried = sum(1 for i in range(n) if FOLDER_KINDS[i % len(FOLDER_KINDS)] == k)
        print(f"  {k}: tried {tried}, reported {tally.by_kind[k]}, harmless "
              f"{tally.by_kind[k + ' (harmless)']}")
    for line in [*extra, *tally.failures][:20]:
        print("  " + line)


def judge_validate(tally, v, path: str, result, original, layout) -> bool:
    """Classify ``validate DIR``'s (code, stderr) on a damaged folder: reported, harmless
    (nothing readable changed) or a wrong "valid"; False for a traceback or garbled
    output (then nothing else of the variant is judged)."""
    vcode, verr = result
    if vcode not in (0, 1) or "Traceback" in verr or (vcode and not verr.strip()) or any(
            not ln.startswith(path) for ln in verr.splitlines()):  # fmt: skip
        tally.fail("traceback or garbled output", f"{v.name}: {result}")
        return False
    if vcode == 1:
        tally.counts["reported by validate"] += 1
        tally.by_kind[v.kind] += 1
    elif folder_content(path, layout) == original:
        tally.counts["harmless (no readable change)"] += 1
        tally.by_kind[f"{v.kind} (harmless)"] += 1
    else:
        tally.fail("WRONG VALID", f"{v.name}: {verr.strip()}")
    return True


def judge_resume(tally, v, dst, vcode, result, lines, wrong, original_results) -> None:
    """A resumed run into a damaged folder: it must end with the original
    ``results.json`` (and not be ``wrong``), and say in a warning line that a damaged run
    record validate reported is computed again (a deleted one is simply not done yet)."""
    target = v.name.split(":", 1)[1]
    if wrong or (dst / "results.json").read_bytes() != original_results:
        tally.fail("RESUME WRONG", f"{v.name}: {result[0]} {result[1]!r}")
    elif target.startswith("runs/") and vcode == 1 and v.kind != "delete_file" and not any(
            ln.startswith(f"scenegen: warning: {dst / target}") for ln in lines):
        tally.fail("RESUME SILENT", f"{v.name}: {result[1]!r}")  # fmt: skip
    else:
        tally.counts["resumed: damaged runs recomputed, same results.json"] += 1


def judge_folder(tally, v, dst, results, original, original_results):
    """Classify one experiment-folder variant's outcome into ``tally``."""
    target = v.name.split(":", 1)[1]
    (vcode, _), *others = results
    if not judge_validate(tally, v, str(dst), results[0], original, EXPERIMENT_FILES):
        return
    for code, err in others:
        lines = err.splitlines()
        if code in (99, 2) or "Traceback" in err or len(lines) > 2:
            tally.fail("traceback or garbled output", f"{v.name}: {code} {err!r}")
        elif err.startswith("scenegen: warning:") or err.startswith(f"{EXP}:"):  # resumed
            judge_resume(tally, v, dst, vcode, (code, err), lines, code != 0, original_results)
        elif code == 1:  # the report
            if not err.startswith(str(dst / "results.json")):
                tally.fail("REPORT GARBLED", f"{v.name}: {err!r}")
            else:
                tally.counts["report refused results.json (one line)"] += 1
        elif target == "results.json" and vcode == 1 and v.kind not in (
                *_RESEALED, "delete_file"):  # fmt: skip
            tally.fail("REPORT ACCEPTED DAMAGE", f"{v.name}")
        else:
            tally.counts["report built"] += 1


def test_fast_damaged_experiment_outputs(experiment, tmp_path, monkeypatch):
    """26 variants of an experiment folder, every kind, in this process."""
    src, original, original_results = experiment
    tally = Tally()
    for i, v in enumerate(folder_variants(src, 26, seed=11)):
        report = tmp_path / f"r{i}"
        dst = report / "experiments" / EXP
        v.apply(dst)
        argvs, with_report = _folder_argvs(v, dst, i)
        results = run_folder_case(argvs, report if with_report else None)
        judge_folder(tally, v, dst, results, original, original_results)
    assert tally.failures == []
    assert sum(tally.counts[k] for k in ("reported by validate", "harmless (no readable "
                                         "change)")) == 26  # fmt: skip
    assert tally.counts["reported by validate"] >= 22
    assert tally.counts["resumed: damaged runs recomputed, same results.json"] >= 8


@pytest.mark.slow
def test_slow_damaged_experiment_outputs(experiment, tmp_path, capsys):
    """260 variants of an experiment folder (13 kinds x 20), each in a guarded child with a
    120 s deadline: validate reports each, a resume repairs it, the report refuses a
    damaged results.json; no hang, no traceback, no wrong "valid"."""
    src, original, original_results = experiment
    tally = Tally()
    n = int(os.environ.get("SCENEGEN_FOLDER_DAMAGE", "260"))
    for i, v in enumerate(folder_variants(src, n, seed=2026)):
        report = tmp_path / f"r{i % 4}"
        shutil.rmtree(report, ignore_errors=True)
        dst = report / "experiments" / EXP
        v.apply(dst)
        argvs, with_report = _folder_argvs(v, dst, i)
        try:
            results = guard.call(run_folder_case, argvs, report if with_report else None,
                                 label=str(dst), seconds=120)  # fmt: skip
        except guard.Unreadable as err:
            tally.fail("HANG", f"{v.name}: {err}")
        else:
            judge_folder(tally, v, dst, results, original, original_results)
    with capsys.disabled():
        print_folder_tally("experiment", n, tally, [])
    assert tally.failures == []


# ---------------------------------------------------------------------------------------
# Benchmark outputs: sealed records under runs/TRACKER/, results.json, scores.csv,
# leaderboard.md and index.html

BENCH_FAMILY = {"name": "small", "base": SCENE, "sweep": {"clutter[0].count": [0, 4]},
                "count": 2}  # fmt: skip
BENCH_TRACKERS = ["--tracker", "meanshift", "--tracker", "sok", "--jobs", "1"]


def _benchmark_folder(base, extra: list[str]):
    """A small benchmark folder made with the options ``extra``: its dataset, the folder,
    its content, its results.json and its layout (with kept tracks, their files are text
    files of the layout)."""
    from scenegen.cli import main
    from scenegen.datasets import build_dataset

    build_dataset(BENCH_FAMILY, base / "data", jobs=1)
    d = base / "bench"
    assert main(["benchmark", str(base / "data"), *BENCH_TRACKERS, "-o", str(d), *extra]) == 0
    assert main(["validate", str(d)]) == 0
    kept = sorted(p.relative_to(d).as_posix() for p in (d / "trackeval").rglob("*")
                  if p.is_file())  # fmt: skip
    layout = (BENCHMARK_FILES[0], (*BENCHMARK_FILES[1], *kept))
    return (base / "data", d, folder_content(str(d), layout),
            (d / "results.json").read_bytes(), layout)  # fmt: skip


@pytest.fixture(scope="module")
def benchmark(tmp_path_factory):
    """A small benchmark folder (4 sealed runs, results.json, three pages), its dataset
    and its content."""
    return _benchmark_folder(tmp_path_factory.mktemp("benchmark"), [])


@pytest.fixture(scope="module")
def kept_benchmark(tmp_path_factory):
    """The same benchmark made with ``--keep-tracks`` (11 more files under trackeval/)."""
    return _benchmark_folder(tmp_path_factory.mktemp("kept"), ["--keep-tracks"])


def judge_benchmark(tally, v, dst, results, original, original_results,
                    layout=BENCHMARK_FILES):  # fmt: skip
    """Classify one benchmark-folder variant's outcome into ``tally``: validate reports it
    (or it changed nothing readable); a resumed benchmark exits 0, warns in one line for a
    damaged run record and ends with the original ``results.json`` (and, with kept tracks,
    the original kept files)."""
    (vcode, _), *others = results
    if not judge_validate(tally, v, str(dst), results[0], original, layout):
        return
    for code, err in others:
        lines = [ln for ln in err.splitlines() if not ln.startswith("benchmark: ")]
        wrong = (code != 0 or "Traceback" in err or len(lines) > 1
                 or folder_content(str(dst), layout) != original)  # fmt: skip
        judge_resume(tally, v, dst, vcode, (code, err), lines, wrong, original_results)


def _bench_variants(benchmark, tmp_path, n: int, seed: int, run) -> Tally:
    data, src, original, original_results, layout = benchmark
    tally = Tally()
    for i, v in enumerate(folder_variants(src, n, seed=seed, layout=layout)):
        dst = tmp_path / f"b{i}"
        shutil.rmtree(dst, ignore_errors=True)
        v.apply(dst)
        argvs = [["validate", str(dst)]]
        if i % 2 == 1:
            argvs.append(["benchmark", str(data), *BENCH_TRACKERS, "-o", str(dst)])
        results = run(argvs, v, dst)
        if results is not None:
            judge_benchmark(tally, v, dst, results, original, original_results, layout)
    return tally


def test_fast_damaged_benchmark_outputs(benchmark, tmp_path):
    """26 variants of a benchmark folder, every kind, in this process."""
    tally = _bench_variants(benchmark, tmp_path, 26, 12, lambda a, v, d: run_case(a, 3.0))
    assert tally.failures == []
    assert sum(tally.counts[k] for k in ("reported by validate", "harmless (no readable "
                                         "change)")) == 26  # fmt: skip
    assert tally.counts["reported by validate"] >= 22
    assert tally.counts["resumed: damaged runs recomputed, same results.json"] == 13


def test_fast_damaged_kept_tracks(kept_benchmark, tmp_path):
    """26 variants of a benchmark folder with kept tracks (a byte-damaged or deleted file
    may be a tracker file, a gt.txt, a seqinfo.ini or a seqmap): validate reports each, and
    the same command without --keep-tracks repairs it, results.json and every kept file
    as before, even when results.json itself was the damaged file."""
    tally = _bench_variants(kept_benchmark, tmp_path, 26, 13,
                            lambda a, v, d: run_case(a, 3.0))  # fmt: skip
    assert tally.failures == []
    assert tally.counts["reported by validate"] + tally.counts[
        "harmless (no readable change)"] == 26  # fmt: skip
    assert tally.counts["reported by validate"] >= 22
    assert tally.counts["resumed: damaged runs recomputed, same results.json"] == 13
    assert sum(tally.by_kind[k] for k in tally.by_kind if not k.endswith("(harmless)")) >= 22


@pytest.mark.slow
@pytest.mark.parametrize("folder", ["benchmark", "kept_benchmark"])
def test_slow_damaged_benchmark_outputs(folder, request, tmp_path, capsys):
    """260 variants of a benchmark folder (13 kinds x 20), and of the same folder with kept
    tracks, each in a guarded child with a 120 s deadline: validate reports each, a
    resumed benchmark repairs it; no hang, no traceback, no wrong "valid"."""
    benchmark = request.getfixturevalue(folder)
    n = int(os.environ.get("SCENEGEN_FOLDER_DAMAGE", "260"))
    hung: list[str] = []

    def run(argvs, v, dst):
        try:
            return guard.call(run_case, argvs, 3.0, label=str(dst), seconds=120)
        except guard.Unreadable as err:
            hung.append(f"HANG: {v.name}: {err}")
            return None

    tally = _bench_variants(benchmark, tmp_path, n, 2027, run)
    with capsys.disabled():
        print_folder_tally(folder.replace("_", " "), n, tally, hung)
    assert hung == [] and tally.failures == []
