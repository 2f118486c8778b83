"""Building datasets: the same bytes on any executor, resuming after a kill, validation."""

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import pytest

import scenegen
from scenegen.datasets import build_dataset, open_dataset, validate_dataset
from scenegen.errors import ConfigError
from scenegen.testing.fixtures import digests

TINY = {
    "name": "tiny",
    "base": "kams-a",
    "set": {"n_frames": 3, "width": 48, "height": 40, "entities[0].position": [24, 20],
            "entities[0].appearance.size": [10, 10],
            "entities[0].motion.x.margin": 1, "entities[0].motion.y.margin": 1},
    "sweep": {"clutter[0].count": [0, 6]},
    "vary": {"entities[0].position_noise": {"uniform": [0.0, 2.0]}},
    "count": 7,
}  # fmt: skip
SHARD = 2  # 7 sequences: shards of 2, 2, 2, 1


def files(folder: Path) -> dict[str, bytes]:
    """Every file of a dataset folder, by name (temporary files would show up too)."""
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("ref") / "ds"
    build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    return out


def test_layout_and_manifest(reference):
    names = sorted(files(reference))
    assert names == ["manifest.json"] + [f"shard-{j:05d}.h5" for j in range(4)]
    man = json.loads((reference / "manifest.json").read_text())
    assert man["complete"] and man["count"] == 7 and man["shards"] == 4
    entries = man["sequences"]
    assert [e["index"] for e in entries] == list(range(7))
    assert [e["file"] for e in entries] == ["shard-00000.h5"] * 2 + ["shard-00001.h5"] * 2 + [
        "shard-00002.h5"] * 2 + ["shard-00003.h5"]  # fmt: skip
    with h5py.File(reference / "shard-00001.h5") as f:
        assert sorted(f["sequences"]) == ["tiny-00002", "tiny-00003"]
    # The manifest's digests are those of the sequence generated from its config and seed.
    e = entries[3]
    seq = scenegen.read(reference / e["file"], e["name"])
    again = scenegen.generate(scenegen.config.to_dict(seq.config), seed=e["seed"])
    assert digests(again) == e["digests"] == digests(seq)
    assert e["params"]["clutter[0].count"] == 6


def test_same_bytes_with_two_local_processes(reference, tmp_path):
    build_dataset(TINY, tmp_path / "ds", jobs=2, shard_size=SHARD)
    assert files(tmp_path / "ds") == files(reference)


def test_same_bytes_on_a_dask_cluster(reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        build_dataset(TINY, tmp_path / "ds", scheduler=cluster.scheduler_address,
                      shard_size=SHARD)  # fmt: skip
    assert files(tmp_path / "ds") == files(reference)


class Interrupt(Exception):
    pass


def test_interrupted_build_resumes_without_redoing_shards(reference, tmp_path):
    out = tmp_path / "ds"
    seen = []

    def stop_after_two(res):
        seen.append(res)
        if len(seen) == 2:
            raise Interrupt

    with pytest.raises(Interrupt):
        build_dataset(TINY, out, jobs=1, shard_size=SHARD, on_shard=stop_after_two)
    man = json.loads((out / "manifest.json").read_text())
    assert not man["complete"] and len(man["sequences"]) == 4
    assert validate_dataset(out)[0].endswith("incomplete dataset (the build was interrupted); "
                                             "rerun it")  # fmt: skip
    stamps = {p.name: p.stat().st_mtime_ns for p in out.glob("shard-*.h5")}
    again = []
    build_dataset(TINY, out, jobs=1, shard_size=SHARD, on_shard=again.append)
    assert [r["reused"] for r in sorted(again, key=lambda r: r["shard"])] == [True, True,
                                                                               False, False]
    assert {p: (out / p).stat().st_mtime_ns for p in stamps} == stamps
    assert files(out) == files(reference)
    assert validate_dataset(out) == []
    assert validate_dataset(out, deep=True) == []  # every sequence generated again


def test_damaged_shard_is_made_again(reference, tmp_path):
    out = tmp_path / "ds"
    build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    target = out / "shard-00002.h5"
    data = bytearray(target.read_bytes())
    with h5py.File(target) as f:  # flip a byte inside the first frame's stored chunk
        offset = f["sequences/tiny-00004/frames"].id.get_chunk_info(0).byte_offset
    data[offset + 5] ^= 0xFF
    target.write_bytes(bytes(data))
    assert any("shard-00002.h5" in line for line in validate_dataset(out))
    again = []
    build_dataset(TINY, out, jobs=1, shard_size=SHARD, on_shard=again.append)
    assert [r["shard"] for r in again if not r["reused"]] == [2]
    assert files(out) == files(reference)


def test_validate_reports_missing_and_foreign_files(reference, tmp_path):
    out = tmp_path / "ds"
    build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    (out / "shard-00001.h5").unlink()
    (out / "shard-00009.h5").write_bytes(b"x")
    problems = validate_dataset(out)
    assert any("shard-00001.h5: missing shard file" in p for p in problems)
    assert any("shard-00009.h5: shard file not listed" in p for p in problems)
    os.mkfifo(out / "shard-00001.h5")  # was called a missing shard file
    assert f"{out / 'shard-00001.h5'}: is not a regular file (a FIFO) where a shard file " \
        f"belongs ({SHARD} sequences)" in validate_dataset(out)
    assert validate_dataset(tmp_path) == [f"{tmp_path}: not a dataset folder (no manifest.json)"]


def test_folder_of_another_dataset_is_refused(reference, tmp_path):
    out = tmp_path / "ds"
    build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    with pytest.raises(ConfigError, match="holds a different dataset"):
        build_dataset(TINY, out, jobs=1, shard_size=SHARD, seed=5)
    with pytest.raises(ConfigError, match="holds a different dataset"):
        build_dataset({**TINY, "sweep": {"clutter[0].count": [1]}}, out, shard_size=SHARD)


def test_a_larger_count_extends_the_dataset(reference, tmp_path):
    out = tmp_path / "ds"
    build_dataset(TINY, out, jobs=1, shard_size=SHARD, count=5)
    again = []
    build_dataset(TINY, out, jobs=1, shard_size=SHARD, on_shard=again.append)  # 7
    assert sorted((r["shard"], r["reused"]) for r in again) == [
        (0, True), (1, True), (2, False), (3, False)]  # fmt: skip
    assert files(out) == files(reference)
    with pytest.raises(ConfigError, match="may extend it .--count >= 7. but not shrink it"):
        build_dataset(TINY, out, jobs=1, shard_size=SHARD, count=3)


def test_open_dataset(reference):
    ds = open_dataset(reference)
    assert len(ds) == 7 and ds.params == ["clutter[0].count", "entities[0].position_noise"]
    seq = ds[4]
    assert seq.name == "tiny-00004" and seq.frames.shape == (3, 40, 48, 3)
    assert digests(seq) == ds.manifest["sequences"][4]["digests"]
    assert [e["index"] for e in ds.select(count=6).entries] == [1, 3, 5]
    noisy = ds.select(position_noise=(1.0, None))
    assert all(e["params"]["entities[0].position_noise"] >= 1.0 for e in noisy.entries)
    both = ds.select({"clutter[0].count": 0}, position_noise=lambda v: v < 1.0)
    assert all(e["params"]["clutter[0].count"] == 0 for e in both.entries)
    assert ds.select(count={0, 6}).entries == ds.entries
    with pytest.raises(ConfigError, match="no parameter 'speed'"):
        ds.select(speed=1)
    with pytest.raises(IndexError):
        ds[7]


def test_samples_read_frames_and_boxes_lazily(reference):
    import pickle

    ds = open_dataset(reference)
    whole = ds.samples()
    frames, boxes = whole[2]
    assert frames.shape == (3, 40, 48, 3) and frames.dtype.name == "uint8"
    assert boxes.shape == (3, 1, 4) and boxes.dtype.name == "float32"
    clips = pickle.loads(pickle.dumps(ds.samples(clip=2, stride=1)))
    assert len(clips) == 7 * 2
    f, b = clips[1]  # sequence 0, frames 1..2
    assert (f == whole[0][0][1:3]).all() and (b == whole[0][1][1:3]).all()
    assert sum(1 for _ in clips) == len(clips)


def _kill_test_command(out: Path, family: Path) -> list[str]:
    return [sys.executable, "-m", "scenegen.cli", "dataset", str(family), "-o", str(out),
            "--jobs", "1", "--shard-size", "1"]  # fmt: skip


def test_killed_dataset_command_resumes_identical(reference, tmp_path):
    family = tmp_path / "tiny.json"
    bigger = {**TINY["set"], "n_frames": 40, "width": 160, "height": 120}
    family.write_text(json.dumps({**TINY, "set": bigger, "count": 12}))
    full = tmp_path / "full"
    subprocess.run(_kill_test_command(full, family), check=True, capture_output=True)
    out = tmp_path / "killed"
    proc = subprocess.Popen(_kill_test_command(out, family), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)  # fmt: skip
    deadline = time.monotonic() + 120
    while not (out / "shard-00002.h5").exists() and proc.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL  # killed mid-run, not finished
    assert not json.loads((out / "manifest.json").read_text())["complete"]
    made = sorted(p.name for p in out.glob("shard-*.h5"))
    assert 3 <= len(made) < 12
    stamps = {name: (out / name).stat().st_mtime_ns for name in made}
    subprocess.run(_kill_test_command(out, family), check=True, capture_output=True)
    assert {n: (out / n).stat().st_mtime_ns for n in stamps} == stamps  # not made again
    assert files(out) == files(full)


def _edit_manifest(folder: Path, edit) -> Path:
    path = folder / "manifest.json"
    man = json.loads(path.read_text())
    edit(man)
    path.write_text(json.dumps(man))
    return path


def test_validate_draws_every_entry_again(reference, tmp_path):
    out = tmp_path / "ds"
    shutil.copytree(reference, out)
    assert validate_dataset(out, deep=True) == []

    def edit(man):
        seqs = man["sequences"]
        seqs[0]["params"]["clutter[0].count"] = 6  # the swept value of another grid point
        seqs[1]["n_frames"] = 99
        seqs[2]["targets"] = 3
        seqs[3]["width"], seqs[3]["preset"] = 64, "kams-b"
        seqs[4]["seed"] += 1

    path = _edit_manifest(out, edit)
    problems = validate_dataset(out, deep=True)
    assert problems == [
        f"{path}: entry of tiny-00000: params differs from its sequence "
        "(params['clutter[0].count']: 6 in the manifest, 0 drawn)",
        f"{path}: entry of tiny-00001: n_frames differs from its sequence (n_frames: 99 in "
        "the manifest, 3 drawn)",
        f"{path}: entry of tiny-00002: targets differs from its sequence (targets: 3 in the "
        "manifest, 1 drawn)",
        f"{path}: entry of tiny-00003: preset, width differ from its sequence (preset: "
        "'kams-b' in the manifest, 'kams-a' drawn)",
        f"{path}: entry of tiny-00004: seed differs from its sequence (seed: "
        f"{open_dataset(reference).entries[4]['seed'] + 1} in the manifest, "
        f"{open_dataset(reference).entries[4]['seed']} drawn)",
    ]  # fmt: skip
    # A rerun of the same build writes every entry again from the draws.
    build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    assert files(out) == files(reference)


@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (lambda m: m.update(params=["x"]), "params differs from what its family gives"),
        (lambda m: m["axes"][0]["values"].append([9]), "does not have its family_digest"),
        (lambda m: m["resolved"]["set"].pop(), "does not have its family_digest"),
        (lambda m: m.update(seed="1"), "seed must be a non-negative integer"),
        (lambda m: m.update(seed=2**64), "seed must be a non-negative integer below 2**64"),
    ],
)
def test_validate_checks_the_header_against_its_family(reference, tmp_path, edit, needle):
    out = tmp_path / "ds"
    shutil.copytree(reference, out)
    path = _edit_manifest(out, edit)
    (line,) = validate_dataset(out)
    assert line.startswith(f"{path}: ") and needle in line


def test_an_older_manifest_is_checked_by_its_spec_or_named(reference, tmp_path):
    man = json.loads((reference / "manifest.json").read_text())
    assert man["family_spec"] == TINY  # the family as given
    assert man["resolved"]["base"] == "kams-a" and ["n_frames", 3] in man["resolved"]["set"]
    # Written before the header held the resolved family: family_spec (written with sorted
    # keys) gives the family when its sections' keys were in sorted order ...
    one_key = {"name": "one", "base": "kams-a", "set": {"n_frames": 2}, "count": 2}
    out = tmp_path / "one"
    build_dataset(one_key, out, jobs=1)
    _edit_manifest(out, lambda m: m.pop("resolved"))
    assert validate_dataset(out) == []
    path = _edit_manifest(out, lambda m: m["sequences"][1].update(n_frames=4))
    assert validate_dataset(out) == [f"{path}: entry of one-00001: n_frames differs from its "
                                     "sequence (n_frames: 4 in the manifest, 2 drawn)"]  # fmt: skip
    # ... else validate says so, and the same build command updates the manifest.
    out = tmp_path / "ds"
    shutil.copytree(reference, out)
    path = _edit_manifest(out, lambda m: m.pop("resolved"))
    assert validate_dataset(out) == [
        f"{path}: no resolved family in the header (written by an older version of scenegen), "
        "and its family_spec does not give its family_digest: run the same `scenegen dataset` "
        "command again to update the manifest"]  # fmt: skip
    build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    assert files(out) == files(reference)


DAMAGED_ENTRIES = [
    (lambda s: s[1].pop("name"), "entry 1: no 'name'"),
    (lambda s: s[1].pop("index"), "entry 1 ('tiny-00001'): no 'index'"),
    (lambda s: s[1].pop("file"), "entry 1 ('tiny-00001'): no 'file'"),
    (lambda s: s[1].update(seed="abc"), "entry 1 ('tiny-00001'): seed must be an integer, "
     "got 'abc'"),
    (lambda s: s.__setitem__(1, 5), "entry 1: not an entry (a mapping), got 5"),
    (lambda s: s[1].update(index=0), "entry 1 ('tiny-00001'): index 0 listed twice"),
    (lambda s: s[1].update(params=[]), "entry 1 ('tiny-00001'): params must be a mapping"),
]  # fmt: skip


@pytest.mark.parametrize(("damage", "needle"), DAMAGED_ENTRIES)
def test_a_damaged_entry_is_one_line_for_every_reader(reference, tmp_path, damage, needle):
    from scenegen.errors import DataError

    out = tmp_path / "ds"
    shutil.copytree(reference, out)
    path = _edit_manifest(out, lambda m: damage(m["sequences"]))
    line = f"{path}: {needle}"
    assert validate_dataset(out)[0].startswith(line)
    with pytest.raises(DataError) as info:
        open_dataset(out)
    assert str(info.value).startswith(line) and "\n" not in str(info.value)
    with pytest.raises(ConfigError) as info:
        build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    assert str(info.value).startswith(line) and "cannot resume the dataset in" in str(info.value)


def test_frames_keeps_the_family_as_given_and_refuses_a_swept_frame_count(tmp_path):
    build_dataset(TINY, tmp_path / "ds", jobs=1, shard_size=SHARD, count=2, frames=2)
    man = json.loads((tmp_path / "ds" / "manifest.json").read_text())
    assert man["family_spec"] == TINY and ["n_frames", 2] in man["resolved"]["set"]
    assert [e["n_frames"] for e in man["sequences"]] == [2, 2]
    assert validate_dataset(tmp_path / "ds") == []
    swept = {"name": "nf", "base": "kams-a", "sweep": {"n_frames": [6, 7]}}
    drawn = {"name": "nf", "base": "kams-a", "vary": {"n_frames": {"randint": [6, 7]}}}
    for fam, where in ((swept, "sweep.n_frames"), (drawn, "vary.n_frames")):
        with pytest.raises(ConfigError) as info:
            build_dataset(fam, tmp_path / "nf", count=2, frames=3, jobs=1)
        assert str(info.value) == (f"--frames 3: family: {where}: sets n_frames per "
                                   "sequence; it cannot be overridden")  # fmt: skip
    assert not (tmp_path / "nf").exists()


def test_select_keeps_both_conditions_on_one_parameter(reference):
    ds = open_dataset(reference)
    assert ds.select({"clutter[0].count": 0}, count=6).entries == []
    both = ds.select({"clutter[0].count": (0, 6)}, count=6)
    assert [e["index"] for e in both.entries] == [1, 3, 5]


def _fake_dataset():
    from scenegen.datasets.reader import Dataset

    params = ["size", "count", "kind", "motion"]
    entries = [
        {"index": i, "n_frames": 4,
         "params": {"size": [10 + i, 10 + i], "count": i, "kind": ["uniform", "noise"][i % 2],
                    "motion": {"x": i}}}
        for i in range(3)
    ]  # fmt: skip
    return Dataset(Path("nowhere"), {"params": params}, entries)


def test_select_takes_lists_dicts_and_sets_of_them():
    # Sets of list values and ranges against dicts raised raw TypeErrors.
    ds = _fake_dataset()

    def idx(d):
        return [e["index"] for e in d.entries]

    assert idx(ds.select(size=[11, 11])) == [1] == idx(ds.select(size=(11, 11)))
    assert idx(ds.select(size={(10, 10), (12, 12)})) == [0, 2]
    assert idx(ds.select(motion={"x": 2})) == [2]
    assert idx(ds.select(count=(1, None), kind={"uniform"})) == [2]
    assert idx(ds.select(motion=(0, 5))) == []  # a dict is not in a range
    assert idx(ds.select(count=[1])) == []  # a list is a value, not a set of values


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda ds: ds.select(count=("a", 3)), "select: count=('a', 3): a range (low, high) "
         "takes numbers or None; give a set for several accepted values"),
        (lambda ds: ds.select(kind=([1], None)), "select: kind=([1], None): a range"),
        (lambda ds: ds.select(["count"]), "select: where must be a dict of parameter names"),
        (lambda ds: ds.samples(clip=2.5), "clip must be an integer >= 1 or None, got 2.5"),
        (lambda ds: ds.samples(clip="3"), "clip must be an integer >= 1 or None, got '3'"),
        (lambda ds: ds.samples(clip=True), "clip must be an integer >= 1 or None, got True"),
        (lambda ds: ds.samples(clip=2, stride=1.5), "stride must be an integer >= 1 or None"),
        (lambda ds: ds.samples(clip=0), "clip must be an integer >= 1 or None, got 0"),
        (lambda ds: ds.samples(gt=["box"]), "gt must be 'box' or 'visible_box', got ['box']"),
    ],
)  # fmt: skip
def test_bad_select_or_samples_arguments_are_one_line(call, message):
    with pytest.raises(ConfigError) as info:
        call(_fake_dataset())
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_samples_take_numpy_integers():
    import numpy as np

    samples = _fake_dataset().samples(clip=np.int64(2), stride=np.int32(1))
    assert len(samples) == 3 * 3 and samples.clip == 2 and type(samples.clip) is int


def test_a_seed_beyond_64_bits_is_refused_before_any_work(tmp_path):
    with pytest.raises(ConfigError, match=r"^--seed must be an integer in \[0, 2\*\*64 - 1\], "
                       r"got 18446744073709551616$"):  # fmt: skip
        build_dataset(TINY, tmp_path / "ds", jobs=1, seed=2**64)
    assert not (tmp_path / "ds").exists()


def test_a_scheduler_without_workers_is_one_line_not_a_hang(monkeypatch):
    # A reachable scheduler with no worker left `--scheduler` waiting forever.
    distributed = pytest.importorskip("distributed")
    from scenegen.datasets.executor import run_tasks

    monkeypatch.setenv("SCENEGEN_DASK_WORKER_TIMEOUT", "1")
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=None) as c:
        with pytest.raises(ConfigError, match="has no worker \\(waited 1 s"):
            run_tasks(abs, [1, 2], lambda t, r: None, scheduler=c.scheduler_address)
    monkeypatch.setenv("SCENEGEN_DASK_WORKER_TIMEOUT", "soon")
    with pytest.raises(ConfigError, match="SCENEGEN_DASK_WORKER_TIMEOUT must be a positive"):
        from scenegen.datasets.executor import worker_timeout

        worker_timeout()


def test_a_named_axis_of_one_field_records_its_grid_position(tmp_path):
    """``sweep: {sz: {path: [...]}}`` is a named axis like one of several fields: each entry
    records its grid position under ``sz`` (what ``select(sz=...)`` takes). Entries written
    before round 17 lack it and stay valid."""
    fam = {**TINY, "sweep": {"sz": {"entities[0].appearance.size": [[10, 10], [12, 12]]}}}
    out = tmp_path / "ds"
    build_dataset(fam, out, jobs=1, shard_size=SHARD, count=3)
    ds = open_dataset(out)
    assert [e["params"]["sz"] for e in ds.entries] == [0, 1, 0]
    assert [e["name"] for e in ds.select(sz=1).entries] == ["tiny-00001"]
    assert validate_dataset(out, deep=True) == []

    def older(man):
        for e in man["sequences"]:
            del e["params"]["sz"]

    _edit_manifest(out, older)
    assert validate_dataset(out, deep=True) == []

    def forged(man):
        man["sequences"][0]["params"]["entities[0].appearance.size"] = [12, 12]

    path = _edit_manifest(out, forged)
    assert validate_dataset(out, deep=True) == [
        f"{path}: entry of tiny-00000: params differs from its sequence "
        "(params['entities[0].appearance.size']: [12, 12] in the manifest, [10, 10] drawn)"
    ]


def test_a_sequence_that_fails_when_planned_names_its_index_and_parameters(tmp_path):
    # What validation cannot see (a runaway AR2 path, a missing image) surfaces when the
    # sequence is planned: before, the error named the field alone, not which sequence.
    family = {
        "name": "runaway", "count": 1,
        "base": {"width": 32, "height": 24, "n_frames": 40,
                 "entities": [{"name": "a", "role": "target", "position": [10, 10],
                               "appearance": {"size": [4, 4]},
                               "motion": {"x": {"boundary": "free", "sigma": 1},
                                          "y": {"boundary": "free"}}}]},
        "sweep": {"entities[0].motion.x.a1": [1000.0]},
    }  # fmt: skip
    with pytest.raises(ConfigError, match=r"^sequence 0 \(entities\[0\]\.motion\.x\.a1=1000\.0\): "
                       r"entities\[0\]\.motion\.x: the AR2 path reaches "):  # fmt: skip
        build_dataset(family, tmp_path / "ds", jobs=1)


@pytest.mark.parametrize("name", ["manifest.json", "results.json"])
def test_a_fifo_in_a_folder_is_refused_not_waited_on(tmp_path, name):
    # A FIFO manifest.json (or results.json, read to tell report folders apart) waited
    # for a writer for ever.
    os.mkfifo(tmp_path / name)
    try:
        done = subprocess.run(
            [sys.executable, "-m", "scenegen.cli", "validate", str(tmp_path)],
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        pytest.fail(f"validate on a folder with a FIFO {name} did not answer within 60 s")
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert f"{tmp_path / name}: is not a regular file (a FIFO)" in done.stderr


def test_telling_folders_apart_does_not_wait_on_a_fifo_results_json(tmp_path):
    # holds_report (asked before any run writes into -o) read a FIFO results.json for ever.
    os.mkfifo(tmp_path / "results.json")
    code = (
        "import sys; from scenegen.datasets.build import holds_report; "
        f"sys.exit(int(holds_report(__import__('pathlib').Path({str(tmp_path)!r}))))"
    )
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail("holds_report on a FIFO results.json did not answer within 60 s")
    assert done.returncode == 0, done.stderr


# h5py's error when HDF5 flushes a file on a full disk: a RuntimeError, its errno in text.
_H5_FULL = ("Disable slist on flush dest failure failed (file write failed: time = Thu Dec  3 "
            "07:13:17 2026\n, filename = '/x/.shard-00000.h5.tmp-1@h-abc', file descriptor = 3, "
            "errno = 28, error message = 'No space left on device', buf = 0x55, total write "
            "size = 9316, bytes this sub-write = 9316, offset = 20480)")  # fmt: skip


@pytest.mark.parametrize("error", [RuntimeError(_H5_FULL),
                                   OSError(28, "Can't synchronously write data (file write "
                                           "failed: time = ...\n, errno = 28)")])  # fmt: skip
def test_a_full_disk_is_one_line_naming_the_shard(tmp_path, monkeypatch, error):
    # It was "internal error: RuntimeError: Disable slist on flush dest failure failed
    # (file write failed: time = ..." (exit 1), or h5py's multi-line OSError text.
    def full(*args, **kwargs):
        raise error

    monkeypatch.setattr(scenegen.io, "write", full)
    out = tmp_path / "ds"
    with pytest.raises(ConfigError) as caught:
        build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    assert str(caught.value) == f"{out / 'shard-00000.h5'}: cannot write: No space left on device"


def test_a_read_only_folder_is_one_line_naming_the_manifest(tmp_path, monkeypatch):
    # It was "internal error: OSError: [Errno 30] Read-only file system:
    # '.../.manifest.json.tmp-PID@HOST-RANDOM.json'" (exit 1).
    import errno
    import tempfile

    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(tmp_path / ".m.tmp-1@h-abc"))

    out = tmp_path / "ds"
    out.mkdir()
    monkeypatch.setattr(tempfile, "mkstemp", read_only)
    with pytest.raises(ConfigError) as caught:
        build_dataset(TINY, out, jobs=1, shard_size=SHARD)
    assert str(caught.value) == f"{out / 'manifest.json'}: cannot write: Read-only file system"


# A driver script whose make_shard misbehaves in the pool's workers: the fork server and
# every worker import the main script, so the replacement is what the workers run.
_DRIVER = """
import faulthandler, os, signal, sys, time
from pathlib import Path

import scenegen.datasets.build as build

# SIGUSR1 prints every thread's stack, here and in the workers (make_shard): what a test
# that waited in vain reports.
faulthandler.register(signal.SIGUSR1, all_threads=True)

_make = build.make_shard


def make_shard(task):
    faulthandler.register(signal.SIGUSR1, all_threads=True)
    how = os.environ["MISBEHAVE"]
    if how == "die" and task.shard == 1:
        os.kill(os.getpid(), signal.SIGKILL)  # as the out-of-memory killer does
    if how == "sleep":
        time.sleep(300)
    if how == "write":  # a long write in progress: its temporary file exists
        from scenegen.io.atomic import atomic_path

        with atomic_path(Path(task.root) / task.file) as tmp:
            tmp.write_bytes(b"partial")
            time.sleep(300)
    return _make(task)


build.make_shard = make_shard

if __name__ == "__main__":
    # As started from a terminal, where Ctrl-C is live: a test suite run as a background
    # job (`make test &` in a script) passes SIGINT down ignored, and Python then installs
    # no KeyboardInterrupt handler, so the Ctrl-C test's SIGINT did nothing.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    from scenegen.cli import main

    sys.exit(main(sys.argv[1:]))
"""


def _driver(tmp_path: Path, how: str, out: Path, **popen) -> subprocess.Popen:
    script = tmp_path / "driver.py"
    script.write_text(_DRIVER)
    family = tmp_path / "tiny.json"
    family.write_text(json.dumps(TINY))
    cmd = [sys.executable, str(script), "dataset", str(family), "-o", str(out), "--jobs", "2",
           "--shard-size", str(SHARD)]  # fmt: skip
    return subprocess.Popen(cmd, env={**os.environ, "MISBEHAVE": how}, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **popen)  # fmt: skip


def _children() -> dict[int, list[int]]:
    kids: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            kids.setdefault(int(stat[stat.rfind(")") + 2 :].split()[1]), []).append(int(entry))
    return kids


def _descendants(pid: int) -> list[int]:
    kids, out, todo = _children(), [], [pid]
    while todo:
        for child in kids.get(todo.pop(), []):
            out.append(child)
            todo.append(child)
    return out


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rfind(")") + 2] != "Z"  # a zombie has exited


def _wait_for(condition, proc: subprocess.Popen, seconds: float = 120) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.02)


def test_a_dead_worker_is_one_line_naming_its_shard_and_a_rerun_completes(reference, tmp_path):
    # It was "internal error: BrokenProcessPool: A process in the process pool was
    # terminated abruptly while the future was running or pending." (exit 1).
    out = tmp_path / "ds"
    proc = _driver(tmp_path, "die", out)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 2, err
    assert err == ("scenegen: error: a worker process died (SIGKILL, as when the system runs out "
                   "of memory: fewer --jobs use less) while making shard-00001.h5 (sequences "
                   "2-3); run the same command again to resume (finished work is kept)\n")
    assert not json.loads((out / "manifest.json").read_text())["complete"]
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]  # no temporary file
    rerun = [sys.executable, "-m", "scenegen.cli", "dataset", str(tmp_path / "tiny.json"),
             "-o", str(out), "--jobs", "2", "--shard-size", str(SHARD)]  # fmt: skip
    again = subprocess.run(rerun, capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert files(out) == files(reference)


@pytest.mark.slow  # 9-11 s on a loaded 2-core machine, mostly starting the driver
@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc")
def test_workers_die_with_a_killed_driver(tmp_path):
    # The workers of a SIGKILLed `dataset --jobs 2` stayed alive, idle, for ever (they and
    # the fork server held each other's pipes open).
    proc = _driver(tmp_path, "sleep", tmp_path / "ds")
    workers: list[int] = []
    try:
        def started() -> bool:
            kids = _children()
            servers = kids.get(proc.pid, [])
            workers[:] = [w for s in servers for w in kids.get(s, [])]
            return len(workers) == 2

        _wait_for(started, proc)
        time.sleep(0.5)  # the workers have run their initializer and sleep in make_shard
        family = _descendants(proc.pid)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        deadline = time.monotonic() + 5
        while any(_alive(p) for p in family) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not [p for p in family if _alive(p)]
    finally:
        for p in _descendants(proc.pid) + workers:
            with contextlib.suppress(OSError):
                os.kill(p, signal.SIGKILL)


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc")
def test_ctrl_c_stops_running_shards_at_once_and_leaves_no_temporary_file(tmp_path):
    # Ctrl-C waited for every running shard to finish (here 300 s); it now takes 1-2.4 s.
    # On a timeout the test shows every process's stack.
    out = tmp_path / "ds"
    proc = _driver(tmp_path, "write", out, start_new_session=True)
    try:
        _wait_for(lambda: len(list(out.glob(".shard-*"))) == 2, proc)
        os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does
        try:
            _, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGUSR1)  # every process's stacks, to stderr
            time.sleep(2)
            os.killpg(proc.pid, signal.SIGKILL)
            pytest.fail(f"still running 60 s after Ctrl-C; stacks:\n{proc.communicate()[1]}")
    finally:
        with contextlib.suppress(OSError):
            os.killpg(proc.pid, signal.SIGKILL)
    assert (proc.returncode, err) == (130, "scenegen: interrupted\n")
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json"]
