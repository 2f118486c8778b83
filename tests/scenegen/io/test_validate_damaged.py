"""``validate`` on deliberately damaged files: every kind of damage is named in one line.

Each test copies a small valid file, damages it in one way (h5py edits, truncation, flipped
bytes inside a chunk) and asserts the exact problem line. The CLI prints one line per
problem and exits 1, never a traceback; a crash of the HDF5 library itself on corrupted
metadata becomes a problem line too (``validate`` checks in a child process).
"""

from __future__ import annotations

import dataclasses
import json
import os
import shlex
import shutil

import h5py
import numpy as np
import pytest

from scenegen.cli import main
from scenegen.config import from_dict
from scenegen.errors import ConfigError, DataError
from scenegen.io import TrackerResult, integrity, read, validate, write_result, write_scenario
from scenegen.io.validate import check_file
from scenegen.render.plan import plan

SCENE = {
    "name": "small",
    "width": 48,
    "height": 40,
    "n_frames": 8,
    "background": {"kind": "noise"},
    "entities": [
        {"name": "a", "role": "target", "position": [10, 20], "depth": 1,
         "appearance": {"shape": "ellipse", "size": [9, 9], "colors": [[255, 0, 0]]},
         "motion": {"x": {"boundary": "reflect"}, "y": {"boundary": "reflect"},
                    "velocity": [3, 0]}},
        {"name": "b", "role": "distractor", "position": [38, 22], "depth": 2,
         "appearance": {"shape": "rect", "size": [7, 11], "colors": [[0, 0, 255]]},
         "motion": {"x": {"boundary": "reflect"}, "y": {"boundary": "reflect"},
                    "velocity": [-3, 0]}},
        {"name": "wall", "role": "occluder", "position": [24, 12], "depth": 0,
         "appearance": {"size": [6, 14], "colors": [[90, 90, 90]]}},
    ],
}  # fmt: skip
SEQ = "sequence 'small'"


@pytest.fixture(scope="module")
def originals(tmp_path_factory):
    """One valid file per compression."""
    d = tmp_path_factory.mktemp("valid")
    scn = plan(from_dict(SCENE), 5)
    out = {}
    for comp in ("gzip", "lzf", "none"):
        out[comp] = d / f"small-{comp}.h5"
        write_scenario(out[comp], scn, compression=comp)
    return out


@pytest.fixture
def copy(tmp_path, originals):
    """``copy(comp="gzip") -> path`` of a fresh copy of the valid file."""

    def make(comp: str = "gzip"):
        path = tmp_path / f"damaged-{comp}.h5"
        shutil.copy(originals[comp], path)
        return path

    return make


def edit(path, fn):
    with h5py.File(path, "r+") as f:
        fn(f["sequences/small"], f)
    return path


def flip(path, dataset, index):
    """XOR bytes in the middle of the stored chunk ``index`` of ``dataset``."""
    with h5py.File(path, "r") as f:
        info = f[f"sequences/small/{dataset}"].id.get_chunk_info_by_coord(index)
    with open(path, "r+b") as fh:
        mid = info.byte_offset + info.size // 2
        fh.seek(mid)
        data = fh.read(4)
        fh.seek(mid)
        fh.write(bytes(b ^ 0x5A for b in data))
    return path


def test_the_valid_files_are_valid(originals):
    for path in originals.values():
        assert check_file(path) == []
        assert check_file(path, isolate=True) == []


def test_missing_schema(copy):
    p = copy()
    with h5py.File(p, "r+") as f:
        del f.attrs["schema"]
    assert check_file(p) == [f"{p}: missing schema attribute (expected 'scenegen/1')"]


def test_wrong_schema(copy):
    p = copy()
    with h5py.File(p, "r+") as f:
        f.attrs["schema"] = "scenegen/0"
    assert check_file(p) == [f"{p}: schema is 'scenegen/0', expected 'scenegen/1'"]


@pytest.mark.parametrize(
    "key", ["frames", "labels", "gt/box", "gt/present", "gt/depth", "entities/role"]
)
def test_missing_dataset(copy, key):
    p = edit(copy(), lambda g, f: g.__delitem__(key))
    assert check_file(p) == [f"{p}: {SEQ}: missing dataset {key}"]


def test_missing_attribute_and_group(copy):
    def damage(g, f):
        del g.attrs["n_frames"]

    p = edit(copy(), damage)
    assert check_file(p) == [f"{p}: {SEQ}: missing attribute n_frames"]
    p = edit(copy(), lambda g, f: g.__delitem__("templates"))
    assert check_file(p) == [f"{p}: {SEQ}: missing group templates"]
    p = edit(copy(), lambda g, f: g.__delitem__("templates/2"))
    assert check_file(p) == [f"{p}: {SEQ}: templates missing for ids 2"]


def replace(g, key, data, **kw):
    del g[key]
    g.create_dataset(key, data=data, **kw)


def test_shape_mismatch(copy):
    p = edit(copy(), lambda g, f: replace(g, "gt/box", g["gt/box"][:7]))
    assert check_file(p) == [f"{p}: {SEQ}: gt/box has shape (7, 3, 4), expected (8, 3, 4)"]
    p = edit(copy(), lambda g, f: replace(g, "labels", g["labels"][:, :, :47]))
    assert check_file(p) == [f"{p}: {SEQ}: labels has shape (8, 40, 47), expected (8, 40, 48)"]


def test_dtype_mismatch(copy):
    p = edit(copy(), lambda g, f: replace(g, "labels", g["labels"][()].astype(np.uint8)))
    assert check_file(p) == [f"{p}: {SEQ}: labels has dtype uint8, expected uint16"]
    p = edit(copy(), lambda g, f: replace(g, "gt/present", g["gt/present"][()].astype(np.int8)))
    assert check_file(p) == [f"{p}: {SEQ}: gt/present has dtype int8, expected bool"]
    p = edit(copy(), lambda g, f: replace(g, "entities/role", np.array([1, 2, 3])))
    assert check_file(p) == [f"{p}: {SEQ}: entities/role has dtype int64, expected string"]


def test_config_attribute(copy):
    def bad_json(g, f):
        g.attrs["config"] = "{not json"

    p = edit(copy(), bad_json)
    (line,) = check_file(p)
    assert line.startswith(f"{p}: {SEQ}: attribute config is not a valid config: ")

    def other_width(g, f):
        g.attrs["width"] = 50

    p = edit(copy(), other_width)
    problems = check_file(p)
    assert f"{p}: {SEQ}: attribute width=50 disagrees with the config's 48" in problems
    assert f"{p}: {SEQ}: frames has shape (8, 40, 48, 3), expected (8, 40, 50, 3)" in problems


def test_labels_naming_unknown_ids(copy):
    def damage(g, f):
        g["labels"][3, 0, 0] = 99

    p = edit(copy(), damage)
    assert check_file(p) == [f"{p}: {SEQ}: labels name ids not in entities/id at frames 3"]


def test_visible_box_disagrees_with_labels(copy):
    def damage(g, f):
        vb = g["gt/visible_box"][()]
        assert np.isfinite(vb[2, 0]).all()
        vb[2, 0, 2] -= 1  # narrower: still inside the box
        g["gt/visible_box"][...] = vb

    p = edit(copy(), damage)
    assert check_file(p) == [f"{p}: {SEQ}: gt/visible_box disagrees with labels at frames 2"]


def test_visible_box_outside_the_box_and_centre_off_the_box(copy):
    # Both were accepted without --deep (the centre had 0.5 px of slack).
    def damage(g, f):
        box, center = g["gt/box"][()], g["gt/center"][()]
        box[2, 0, 0] += 6
        center[2, 0, 0] += 6
        center[4, 0, 1] += 0.5
        g["gt/box"][...] = box
        g["gt/center"][...] = center

    p = edit(copy(), damage)
    problems = check_file(p)
    assert f"{p}: {SEQ}: gt/visible_box lies outside gt/box at frames 2" in problems
    assert f"{p}: {SEQ}: gt/center is not the centre of gt/box at frames 4" in problems


def test_visibility_below_what_the_labels_show(copy):
    # Visible pixels / box area bounds the visibility from below (amodal pixels fit in the
    # box): a twentieth where the labels show most of the object was accepted.
    def damage(g, f):
        vis = g["gt/visibility"][()]
        assert vis[5, 0] > 0.5
        vis[5, 0] = 0.05
        g["gt/visibility"][...] = vis

    p = edit(copy(), damage)
    assert check_file(p) == [
        f"{p}: {SEQ}: gt/visibility or gt/present disagree with labels at frames 5"]


def test_visibility_disagrees_with_labels(copy):
    def damage(g, f):
        vis = g["gt/visibility"][()]
        assert vis[5, 0] > 0
        vis[5, 0] = 0
        g["gt/visibility"][...] = vis

    p = edit(copy(), damage)
    assert check_file(p) == [
        f"{p}: {SEQ}: gt/visibility or gt/present disagree with labels at frames 5"
    ]


def test_nan_pattern_disagrees_with_present(copy):
    def nan_where_present(g, f):
        box = g["gt/box"][()]
        assert g["gt/present"][4, 1]
        box[4, 1] = np.nan
        g["gt/box"][...] = box

    p = edit(copy(), nan_where_present)
    assert check_file(p) == [
        f"{p}: {SEQ}: gt/box NaN pattern disagrees with gt/present at frames 4"
    ]

    def absent_but_finite(g, f):
        present = g["gt/present"][()]
        present[6, 0] = False
        g["gt/present"][...] = present

    p = edit(copy(), absent_but_finite)
    problems = check_file(p)
    for line in (
        "gt/box NaN pattern disagrees with gt/present at frames 6",
        "gt/center NaN pattern disagrees with gt/present at frames 6",
        "gt/visible_box is set where gt/present is false at frames 6",
        "gt/visibility is nonzero where absent at frames 6",
    ):
        assert f"{p}: {SEQ}: {line}" in problems


def test_center_and_ranges(copy):
    def damage(g, f):
        center = g["gt/center"][()]
        center[1, 0, 0] += 3
        g["gt/center"][...] = center
        vis = g["gt/visibility"][()]
        vis[7, 2] = 1.5
        g["gt/visibility"][...] = vis

    p = edit(copy(), damage)
    problems = check_file(p, check_pixels=False)
    assert problems == [
        f"{p}: {SEQ}: gt/visibility is outside [0, 1] at frames 7",
        f"{p}: {SEQ}: gt/center is not the centre of gt/box at frames 1",
    ]


def test_ids_must_be_unique(copy):
    p = edit(copy(), lambda g, f: replace(g, "entities/id", np.array([1, 1, 3], np.int32)))
    assert check_file(p) == [f"{p}: {SEQ}: entities/id must be unique and >= 1, got [1, 1, 3]"]


def test_an_id_labels_cannot_hold_is_named_at_once(copy):
    # Labels are uint16: an id above 65535 can name no pixel. The check used to size its
    # id tables by the largest id (16 GiB for 2**31 - 1) and was killed at the deadline as
    # "metadata unreadable".
    big = np.array([1, 2, 2**31 - 1], np.int32)
    p = edit(copy(), lambda g, f: replace(g, "entities/id", big))
    line = f"{p}: {SEQ}: entities/id must be at most 65535 (labels are uint16), got 2147483647"
    assert check_file(p) == [line]
    assert check_file(p, isolate=True) == [line]



def _limited_memory() -> None:  # a reader of /dev/zero must fail, not fill the machine
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))


@pytest.mark.skipif(not hasattr(os, "mkfifo") or not os.path.exists("/dev/zero"),
                    reason="needs FIFOs and /dev/zero")  # fmt: skip
def test_a_fifo_or_a_device_is_refused_at_once_by_every_reader(originals, tmp_path):
    # A FIFO kept HDF5 waiting until the 10 s deadline ("metadata unreadable ... damaged
    # file", 100 s with --deep); evaluate's result and a --config FIFO waited for a writer
    # for ever; /dev/zero as a tracker file or config was read until memory ran out.
    import subprocess
    import sys

    fifo = tmp_path / "scene.h5"
    os.mkfifo(fifo)
    link = tmp_path / "link.h5"
    link.symlink_to(fifo)
    zero = tmp_path / "zero.txt"
    zero.symlink_to("/dev/zero")
    cfg = tmp_path / "scene.yaml"
    os.mkfifo(cfg)
    seq = originals["gzip"]
    cases = [
        (["validate", fifo], 1, f"{fifo}: is not a regular file (a FIFO)"),
        (["validate", "--deep", link], 1, f"{link}: is not a regular file (a FIFO)"),
        (["track", link, "--tracker", "kalman", "-o", tmp_path / "r.h5"], 1, f"{link}: is not"),
        (["evaluate", seq, fifo], 1, f"{fifo}: is not a regular file (a FIFO)"),
        (["evaluate", seq, zero], 1, f"{zero}: is not a regular file (a device)"),
        (["generate", "--config", cfg, "-o", tmp_path / "g.h5"], 2, f"{cfg}: is not a regular"),
    ]
    # All at once (each is a new interpreter, most of its 2 s importing), each given 60 s.
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "scenegen.cli", *map(str, args)], stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE, text=True, preexec_fn=_limited_memory,
            env={**os.environ, "SCENEGEN_READ_TIMEOUT": "30"},
        )  # fmt: skip
        for args, _, _ in cases
    ]
    try:
        for proc, (args, code, needle) in zip(procs, cases, strict=True):
            try:
                _, stderr = proc.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                pytest.fail(f"scenegen {args[0]} on {args[-1]} did not answer within 60 s")
            assert (proc.returncode, stderr.count("\n")) == (code, 1), (args, stderr)
            assert needle in stderr and "Traceback" not in stderr
    finally:
        for proc in procs:
            proc.kill()
            proc.wait()
    with pytest.raises(DataError, match="is not a regular file"):
        read(link)


@pytest.mark.parametrize("cut", ["0", "8", "100", "half", "size-1"])
def test_truncated(copy, cut):
    p = copy()
    size = p.stat().st_size
    n = {"0": 0, "8": 8, "100": 100, "half": size // 2, "size-1": size - 1}[cut]
    os.truncate(p, n)
    (line,) = check_file(p)
    if n == 0:
        assert line == f"{p}: not an HDF5 file"
    elif n == 8:
        assert line.startswith(f"{p}: not a readable HDF5 file (truncated or corrupted: ")
    else:
        assert line == f"{p}: truncated HDF5 file ({n} of {size} bytes)"
    with pytest.raises(DataError) as err:
        read(p)
    assert str(err.value) == line


@pytest.mark.parametrize("comp", ["gzip", "lzf", "none"])
@pytest.mark.parametrize(("dataset", "index"), [("frames", (3, 0, 0, 0)), ("labels", (5, 0, 0))])
def test_flipped_bytes_in_a_chunk(copy, comp, dataset, index):
    p = flip(copy(comp), dataset, index)
    assert check_file(p) == [
        f"{p}: {SEQ}: {dataset} is damaged at frames {index[0]} (checksum or decompression failed)"
    ]
    seq = read(p)
    np.asarray(getattr(seq, dataset)[index[0] + 1])  # other frames still read
    with pytest.raises(DataError, match=rf"{dataset}\[{index[0]}\] is unreadable"):
        getattr(seq, dataset)[index[0]]


def test_flipped_bytes_in_ground_truth(copy):
    p = flip(copy("none"), "gt/box", (0, 0, 0))
    assert check_file(p) == [f"{p}: {SEQ}: gt/box is unreadable (checksum or decompression failed)"]
    with pytest.raises(DataError, match=r"sequence 'small' is damaged"):
        read(p)


def test_damage_without_checksums_is_still_caught(copy):
    """Files written without Fletcher-32 (other tools): labels are checked pixel by pixel,
    and zlib's own checksum catches changes to gzip-compressed frames."""

    def strip(g, f):
        integrity.strip(f)
        replace(g, "labels", g["labels"][()], chunks=(1, 40, 48))
        replace(g, "frames", g["frames"][()], chunks=(1, 40, 48, 3), compression="gzip")

    p = edit(copy(), strip)
    assert check_file(p) == []
    with h5py.File(p) as f:
        info = f["sequences/small/labels"].id.get_chunk_info_by_coord((3, 0, 0))
    with open(p, "r+b") as fh:
        fh.seek(info.byte_offset + 40)
        fh.write(b"\xff\xff\xff\xff")
    p = flip(p, "frames", (6, 0, 0, 0))
    assert check_file(p) == [
        f"{p}: {SEQ}: frames is damaged at frames 6 (checksum or decompression failed)",
        f"{p}: {SEQ}: labels name ids not in entities/id at frames 3",
    ]


def test_not_hdf5_folder_and_temp_file(copy, tmp_path):
    junk = tmp_path / "junk.h5"
    junk.write_text("hello")
    assert check_file(junk) == [f"{junk}: not an HDF5 file"]
    assert check_file(tmp_path) == [f"{tmp_path}: is a folder, not a scenegen file"]
    tmp = tmp_path / ".small.h5.tmp-4242@somehost-abc123"
    shutil.copy(copy(), tmp)
    assert check_file(tmp) == [
        f"{tmp}: an unfinished temporary file of a write to 'small.h5' (process 4242 on somehost)"
    ]


def test_result_files(tmp_path):
    res = TrackerResult(
        tracker="kalman", params={}, seed=0, sequence="small",
        target_ids=np.array([1], np.int32), boxes=np.zeros((8, 1, 4), np.float32),
    )  # fmt: skip
    p = tmp_path / "r.h5"
    write_result(p, res)
    assert check_file(p) == []
    with h5py.File(p, "r+") as f:
        del f["results/kalman/boxes"]
        f["results/kalman/boxes"] = np.zeros((8, 2, 4), np.float64)
    assert check_file(p) == [
        f"{p}: result 'kalman': boxes has shape (8, 2, 4), expected (8, 1, 4)",
        f"{p}: result 'kalman': boxes has dtype float64, expected float32",
    ]
    with h5py.File(p, "r+") as f:
        del f["results/kalman/boxes"]
    assert check_file(p) == [f"{p}: result 'kalman': missing dataset boxes"]
    # A row that is neither a box nor a lost target (all NaN) was valid.
    half = np.zeros((8, 1, 4), np.float32)
    half[5, 0, 2] = np.nan
    with h5py.File(p, "r+") as f:
        f["results/kalman/boxes"] = half
    assert check_file(p)[0] == (
        f"{p}: result 'kalman': boxes has rows that are neither finite with w, h >= 0 nor "
        "all NaN at frames 5"
    )
    with pytest.raises(ConfigError, match="result of tracker 'kalman': boxes has rows"):
        write_result(tmp_path / "r2.h5", dataclasses.replace(res, boxes=half))
    assert not (tmp_path / "r2.h5").exists()


def test_cli_prints_one_line_per_problem_and_exits_1(copy, capsys):
    p = edit(copy(), lambda g, f: g["labels"].__setitem__((3, 0, 0), 99))
    p = flip(p, "frames", (2, 0, 0, 0))
    code = main(["validate", str(p)])
    out, err = capsys.readouterr()
    assert code == 1 and out == ""
    assert err.splitlines() == [
        f"{p}: {SEQ}: frames is damaged at frames 2 (checksum or decompression failed)",
        f"{p}: {SEQ}: labels name ids not in entities/id at frames 3",
    ]
    size = p.stat().st_size
    os.truncate(p, 1000)
    code = main(["validate", str(p)])
    out, err = capsys.readouterr()
    assert code == 1 and err.splitlines() == [f"{p}: truncated HDF5 file (1000 of {size} bytes)"]


def test_other_verbs_on_a_damaged_chunk_exit_1_with_one_line(copy, tmp_path, capsys):
    p = flip(copy(), "frames", (4, 0, 0, 0))
    code = main(["export", str(p), "--format", "mot", "-o", str(tmp_path / "mot")])
    _, err = capsys.readouterr()
    assert code == 1
    assert err == (
        f"scenegen: error: {p}: sequences/small/frames[4] is unreadable "
        "(damaged file: checksum or decompression failed)\n"
    )
    assert not (tmp_path / "mot").exists()
    assert not list(tmp_path.glob(".mot.*"))  # the temporary folder is removed


def test_a_crash_of_the_hdf5_library_becomes_one_line(copy, monkeypatch):
    """Some corrupted metadata crashes libhdf5 itself (segmentation fault); the isolated
    check reports that instead of dying. Simulated: the guarded child aborts."""
    monkeypatch.setattr(validate, "_checked", _abort)
    p = copy()
    assert check_file(p, isolate=True) == [
        f"{p}: metadata unreadable: the HDF5 library crashed reading it (SIGABRT)"
    ]


def _abort(*args):
    os.abort()


def test_an_unexpected_error_in_the_isolated_check_is_one_line(copy, monkeypatch, capfd):
    monkeypatch.setattr(validate, "_checked", _memory_error)
    p = copy()
    assert check_file(p, isolate=True) == [f"{p}: could not be read (MemoryError: simulated)"]
    assert "Traceback" not in capfd.readouterr().err


def _memory_error(*args):
    raise MemoryError("simulated")


def test_random_byte_damage_never_raises(copy):
    """Seeded random flips anywhere in the file (metadata included): the isolated check
    always returns problem lines (or none, for flips in unused bytes), never raises."""
    p = copy()
    clean = p.read_bytes()
    rng = np.random.default_rng(8)
    for trial in range(24):
        data = bytearray(clean)
        span = 4096 if trial % 2 else len(data)  # half of the trials hit the metadata
        for pos in rng.integers(0, span, size=int(rng.integers(1, 12))):
            data[pos] ^= int(rng.integers(1, 256))
        p.write_bytes(bytes(data))
        problems = check_file(p, isolate=True)
        assert all(isinstance(line, str) and line.startswith(f"{p}: ") for line in problems)
        assert all("\n" not in line for line in problems)


def _nan_where_present(g, f):
    box = g["gt/box"][()]
    box[2, 0] = np.nan
    g["gt/box"][...] = box


@pytest.mark.parametrize(
    ("verb", "damage", "needle"),
    [
        ("track", _nan_where_present, "gt/box NaN pattern disagrees with gt/present at frames 2"),
        ("export", lambda g, f: replace(g, "gt/present", g["gt/present"][()].astype(np.int8)),
         "gt/present has dtype int8, expected bool"),
        ("preview", lambda g, f: replace(g, "gt/box", g["gt/box"][:5]),
         "gt/box has shape (5, 3, 4), expected (8, 3, 4)"),
        ("evaluate", lambda g, f: g["gt/depth"].__setitem__((1, 0), 9),
         "gt/depth does not match its digest"),
    ],
)  # fmt: skip
def test_verbs_refuse_bad_input_with_one_line(copy, tmp_path, capsys, verb, damage, needle):
    p = edit(copy(), damage)
    out = tmp_path / "out"
    argv = {
        "track": ["track", str(p), "--tracker", "kalman", "-o", str(out)],
        "export": ["export", str(p), "--format", "mot", "-o", str(out)],
        "preview": ["preview", str(p), "-o", str(out) + ".png"],
        "evaluate": ["evaluate", str(p), str(p)],
    }[verb]
    assert main(argv) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and needle in err[0], err
    assert not out.exists()


def test_a_result_file_with_a_wrong_dtype_is_refused_by_evaluate(originals, tmp_path, capsys):
    res = TrackerResult(
        tracker="kalman", params={}, seed=0, sequence="small",
        target_ids=np.array([1], np.int32), boxes=np.zeros((8, 1, 4), np.float32),
    )  # fmt: skip
    r = tmp_path / "r.h5"
    write_result(r, res)
    with h5py.File(r, "r+") as f:
        del f["results/kalman/boxes"]
        f["results/kalman/boxes"] = np.zeros((8, 1, 4), np.float64)
    assert main(["evaluate", str(originals["gzip"]), str(r)]) == 1
    (line,) = capsys.readouterr().err.splitlines()
    assert "boxes has dtype float64, expected float32" in line


def test_edits_with_valid_digests_are_caught_by_deep(copy):
    def rewrite(g, f):
        frame = g["frames"][3]
        frame[0, 0] ^= 1
        g["frames"][3] = frame
        g["gt/depth"][...] = 9
        for key in ("frames", "gt/depth"):
            integrity.put_text(g[key], integrity.DIGEST, integrity.digest(g[key][()]))

    p = edit(copy(), rewrite)
    assert check_file(p) == []
    assert check_file(p, deep=True) == [
        f"{p}: {SEQ}: frames differs from a re-render of its config and seed at frames 3",
        f"{p}: {SEQ}: gt/depth differs from a re-render of its config and seed at frames "
        "0, 1, 2, 3, 4 (+3 more)",
    ]
    assert check_file(copy(), deep=True) == []


def test_exotic_damage_is_one_clear_line_for_validate_and_read(copy):
    def oversized(g, f):  # 3.6 TiB declared, nothing stored: must not be read
        del g["templates/1"]
        ds = g.create_dataset("templates/1", shape=(10**6, 10**6, 4), dtype=np.uint8,
                              chunks=(1000, 1000, 4), fletcher32=True)  # fmt: skip
        integrity.put_text(ds, integrity.DIGEST, "0" * 64)

    def sequences_as_dataset(g, f):
        del f["sequences"]
        f["sequences"] = np.zeros(3)

    with h5py.File(copy(), "r") as f:
        held = f["sequences/small/templates"]
        others = sum(held[k].shape[0] * held[k].shape[1] for k in held if k != "1")
    cases = [
        (lambda g, f: f.attrs.__setitem__("schema", np.array([b"scenegen/1", b"x"])),
         "schema attribute is an array of shape (2,), expected the string 'scenegen/1'"),
        (sequences_as_dataset, "/sequences is not a group"),
        (oversized, f"{SEQ}: templates hold {10**12 + others} pixels, more than the "
                    "generator ever writes (16777216)"),
    ]  # fmt: skip
    for damage, line in cases:
        p = edit(copy(), damage)
        assert check_file(p) == [f"{p}: {line}"]
        with pytest.raises(DataError) as err:
            read(p)
        assert str(err.value).endswith(line.split(": ")[-1]), str(err.value)


def test_a_dataset_rewritten_without_its_checksum_filter_is_named(copy):
    """Same values, same attributes and digests: only the Fletcher-32 filter is gone, so
    a damaged chunk would read as wrong values instead of failing."""

    def unfiltered(g, f):
        for key in ("gt/box", "templates/1"):
            values, attrs = g[key][()], dict(g[key].attrs)
            del g[key]
            g.create_dataset(key, data=values)
            for name in ("description", "units", integrity.DIGEST, integrity.ATTRS_DIGEST):
                if name in attrs:
                    integrity.put_text(g[key], name, integrity.as_text(attrs[name]))

    p = edit(copy(), unfiltered)
    assert check_file(p) == [
        f"{p}: {SEQ}: gt/box is stored without the Fletcher-32 checksum",
        f"{p}: {SEQ}: templates/1 is stored without the Fletcher-32 checksum",
    ]


def test_zeroed_chunks_and_renamed_entities_are_caught(copy):
    p = copy("none")
    with h5py.File(p) as f:
        g = f["sequences/small"]
        infos = {k: g[k].id.get_chunk_info(0) for k in ("gt/depth", "templates/1")}
        names = g["entities/name"].id.get_chunk_info(0)
    data = bytearray(p.read_bytes())
    for info in infos.values():  # the data and its Fletcher-32 word: all zeros
        data[info.byte_offset : info.byte_offset + info.size] = bytes(info.size)
    at = data.index(b"wall", names.byte_offset)
    data[at : at + 4] = b"wXll"
    p.write_bytes(bytes(data))
    problems = check_file(p)
    for key in ("gt/depth", "templates/1"):
        assert any(f"{SEQ}: {key} " in line for line in problems), problems
    assert any("entities/name" in line for line in problems), problems


def test_old_files_with_variable_length_strings_stay_readable_and_valid(copy):
    p = copy()
    with h5py.File(p, "r+") as f:
        integrity.strip(f)
        for obj in (f, f["sequences/small"]):
            for key in list(obj.attrs):
                value = obj.attrs[key]
                if isinstance(value, bytes):
                    obj.attrs[key] = value.decode()  # variable-length, as older writers did
        g = f["sequences/small/entities"]
        for key in ("role", "name"):
            values = [v.decode() for v in g[key][()]]
            del g[key]
            g.create_dataset(key, data=values, dtype=h5py.string_dtype("utf-8"))
    assert check_file(p) == []
    seq = read(p)
    assert list(seq.entities.name) == ["a", "b", "wall"] and seq.preset == ""


# ---------------------------------------------------------------------------------------
# Sealed JSON documents and experiment folders (run records, results.json, table.md)

EXP_ARGS = ["shm-depth", "--runs", "1", "--scenes", "1", "--quick", "--jobs", "1",
            "--method", "kalman"]  # fmt: skip
CLUTTER = "runs/kalman__shm-clutter__s000__r000.json"
CROSSING = "runs/kalman__shm-crossing__s000__r000.json"


def test_sealed_documents_round_trip_and_name_each_problem(tmp_path, monkeypatch):
    from scenegen.io import sealed

    p = tmp_path / "doc.json"
    digest = sealed.write_sealed_json(p, {"b": (1, 2.5), "a": "λ"}, indent=1)
    assert sealed.read_sealed_json(p) == {"a": "λ", "b": [1, 2.5]}
    doc = json.loads(p.read_text())
    assert doc["sha256"] == digest == sealed.content_digest(doc)
    p.write_text(json.dumps(doc))  # another layout, the same content: still sound
    assert sealed.check_sealed_json(p) == []
    cases = {
        b"": "empty file (truncated?)",
        b'{"a": 1': "not a readable JSON file (Expecting ',' delimiter at line 1 column 8: "
                    "truncated or damaged)",
        b"\xff{}": "not a readable JSON file (not UTF-8 at byte 0)",
        b'{"a": 1, "a": 2}': "not a readable JSON file (duplicate key 'a')",
        b'{"a": NaN}': "not a readable JSON file (NaN is not JSON)",
        b"[" * 100_000 + b"]" * 100_000: "not a readable JSON file (nested too deeply)",
        b"[1]": "not a sealed JSON document (a JSON object is expected, found list)",
        b'{"a": 1, "sha256": "00"}': "malformed sha256 digest (damaged or edited)",
        b'{"a": 2, "sha256": "%s"}' % digest.encode(): "content does not match its sha256 "
                                                       "digest (damaged or edited)",
    }  # fmt: skip
    for raw, line in cases.items():
        p.write_bytes(raw)
        assert sealed.check_sealed_json(p) == [f"{p}: {line}"], raw[:20]
    p.write_text('{"a": 1}')
    with pytest.raises(sealed.Unsealed, match="no sha256 digest"):
        sealed.read_sealed_json(p)
    monkeypatch.setattr(sealed, "MAX_BYTES", 4)
    assert sealed.check_sealed_json(p) == [
        f"{p}: too large for a JSON document (8 bytes, at most 4)"
    ]


@pytest.fixture(scope="module")
def experiment_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("exp") / "shm-depth"
    assert main(["experiment", *EXP_ARGS, "-o", str(d)]) == 0
    return d


@pytest.fixture
def exp_copy(experiment_dir, tmp_path):
    d = tmp_path / "experiments" / "shm-depth"
    shutil.copytree(experiment_dir, d)
    return d


def _reseal(path, fn):
    from scenegen.io.sealed import seal

    doc = json.loads(path.read_text())
    fn(doc)
    path.write_text(json.dumps(seal(doc), indent=1))


def _validate(d, capsys, *extra):
    code = main(["validate", *extra, str(d)])
    out, err = capsys.readouterr()
    return code, err.splitlines(), out


def test_a_sound_experiment_folder_is_valid(exp_copy, capsys):
    code, err, out = _validate(exp_copy, capsys)
    assert (code, err, out.strip()) == (0, [], f"{exp_copy}: valid experiment folder")
    doc = json.loads((exp_copy / "results.json").read_text())
    assert [e.split()[0] for e in doc["records"]] == [CROSSING[5:], CLUTTER[5:]]
    assert all(len(e.split()[1]) == 64 for e in doc["records"])


def test_damaged_or_edited_experiment_files_are_one_line_each(exp_copy, capsys):
    rec = exp_copy / CLUTTER
    rec.write_text(rec.read_text().replace('"n_frames":45', '"n_frames":46'))
    _reseal(exp_copy / CROSSING, lambda d: d.__setitem__("tracker_seed", 1))
    code, err, _ = _validate(exp_copy, capsys)
    assert code == 1 and err == [
        f"{exp_copy / CROSSING}: is not the run results.json was computed from (edited or "
        "replaced since)",
        f"{exp_copy / CLUTTER}: content does not match its sha256 digest (damaged or edited)",
    ]


def _redo(folder) -> str:
    # EXP_ARGS, less the defaults of shm-depth (R = 1) and --jobs.
    return ("or written by another version of scenegen: `scenegen experiment shm-depth "
            f"--scenes 1 --quick --method kalman -o {folder}` recomputes it from the runs")


def test_the_command_the_check_names_recomputes_the_summary_and_table(exp_copy, capsys):
    # A summary and a table that the current code does not produce (as one written by
    # another version): the named command, run into the folder, makes it valid again and
    # computes no run again.
    _reseal(exp_copy / "results.json", lambda d: d["summary"].__setitem__("extra", 1))
    table = exp_copy / "table.md"
    table.write_text(table.read_text() + "\nwritten by another version\n")
    runs = {p.name: p.read_bytes() for p in (exp_copy / "runs").iterdir()}
    code, err, _ = _validate(exp_copy, capsys)
    assert code == 1 and len(err) == 2
    command = err[0].split("`")[1]
    assert command.startswith("scenegen experiment ") and err[1].split("`")[1] == command
    assert main(shlex.split(command)[1:]) == 0
    capsys.readouterr()
    assert {p.name: p.read_bytes() for p in (exp_copy / "runs").iterdir()} == runs
    assert _validate(exp_copy, capsys)[:2] == (0, [])


def test_an_edited_results_json_is_found_even_resealed(exp_copy, capsys):
    res = exp_copy / "results.json"
    _reseal(res, lambda d: d["summary"].__setitem__("extra", 1))
    code, err, _ = _validate(exp_copy, capsys)
    assert code == 1 and err == [f"{res}: summary differs from the summary of its runs "
                                 f"(edited, {_redo(exp_copy)})"]
    _reseal(res, lambda d: d.__setitem__("runs", "1"))
    code, err, _ = _validate(exp_copy, capsys)
    assert err == [f"{res}: not an experiment's results (runs is missing or not a int)"]


def test_results_json_names_the_software_that_computed_it(exp_copy, capsys):
    # Provenance, not a result: other versions alone are valid (the runs give the same
    # summary); older files without it stay valid; a summary that differs names the
    # versions that differ; a malformed entry is refused.
    import numpy as np

    import scenegen
    from scenegen.lab.experiments.outputs import written_by

    res = exp_copy / "results.json"
    doc = json.loads(res.read_text())
    assert doc["written_by"] == written_by()
    assert written_by()["scenegen"] == scenegen.__version__
    assert written_by()["numpy"] == np.__version__
    commit = ["scenegen commit"] if "scenegen commit" in written_by() else []
    assert list(written_by()) == ["scenegen", *commit, "python", "numpy", "scipy", "numba",
                                  "opencv", "scikit-image", "h5py"]  # fmt: skip
    table = exp_copy / "table.md"
    assert f"Computed with scenegen {scenegen.__version__}, " in table.read_text()
    assert f"numpy {np.__version__}, " in table.read_text()
    other = {**written_by(), "numpy": "0.0.1"}
    _reseal(res, lambda d: d.__setitem__("written_by", other))
    table.write_text(table.read_text().replace(f"numpy {np.__version__},", "numpy 0.0.1,"))
    assert _validate(exp_copy, capsys)[:2] == (0, [])
    _reseal(res, lambda d: d["summary"].__setitem__("extra", 1))
    code, err, _ = _validate(exp_copy, capsys)
    assert code == 1 and err == [
        f"{res}: summary differs from the summary of its runs (edited, "
        + _redo(exp_copy).replace("of scenegen:", f"of scenegen (numpy 0.0.1 there, "
                                  f"{np.__version__} here):") + ")"]  # fmt: skip
    _reseal(res, lambda d: (d.pop("written_by"), d["summary"].pop("extra")))
    table.write_text("\n".join(ln for ln in table.read_text().split("\n")
                               if not ln.startswith("Computed with")))  # fmt: skip
    # an older file: no versions, and its table never had the line (nor its blank line)
    text = table.read_text().replace("measure.\n\n\n", "measure.\n\n")
    table.write_text(text)
    assert _validate(exp_copy, capsys)[:2] == (0, [])
    _reseal(res, lambda d: d["summary"].__setitem__("extra", 1))
    err = _validate(exp_copy, capsys)[1]
    assert err[0].endswith(_redo(exp_copy).replace(
        "of scenegen:", "of scenegen (it records no versions: an older scenegen):") + ")")
    _reseal(res, lambda d: d.__setitem__("written_by", {"numpy": 2}))
    assert _validate(exp_copy, capsys)[1] == [
        f"{res}: not an experiment's results (written_by is not a mapping of names to "
        "versions)"]


def test_a_damaged_table_md_is_named(exp_copy, capsys):
    table = exp_copy / "table.md"
    table.write_text(table.read_text().replace("reproduced", "rEproduced", 1))
    code, err, _ = _validate(exp_copy, capsys)
    assert code == 1 and err == [f"{table}: is not the table of results.json (damaged, edited, "
                                 f"{_redo(exp_copy)})"]
    table.unlink()
    assert _validate(exp_copy, capsys)[1] == [f"{table}: missing"]


def test_deep_finds_a_run_forged_everywhere(exp_copy, capsys):
    """A record edited with its digest and results.json's listing recomputed (a field the
    summary does not use): only running it again can tell."""
    from scenegen.io.sealed import content_digest

    rec = exp_copy / CLUTTER
    _reseal(rec, lambda d: d.__setitem__("tracker_seed", 1))
    new = content_digest(json.loads(rec.read_text()))

    def relist(doc):
        doc["records"] = [e if not e.startswith(rec.name) else f"{rec.name} {new}"
                          for e in doc["records"]]  # fmt: skip

    _reseal(exp_copy / "results.json", relist)
    assert _validate(exp_copy, capsys)[0] == 0
    code, err, _ = _validate(exp_copy, capsys, "--deep")
    assert code == 1 and err == [f"{rec}: differs from the run computed again"]


def test_resume_recomputes_damaged_and_old_records_with_a_warning(exp_copy, capsys):
    from scenegen.io.sealed import SEAL

    original = (exp_copy / "results.json").read_bytes()
    rec = exp_copy / CLUTTER
    rec.write_bytes(rec.read_bytes()[:100])
    old = exp_copy / CROSSING
    doc = json.loads(old.read_text())
    del doc[SEAL]  # as the previous version wrote it
    old.write_text(json.dumps(doc))
    assert main(["experiment", *EXP_ARGS, "-o", str(exp_copy)]) == 0
    warnings = [ln for ln in capsys.readouterr().err.splitlines() if "warning" in ln]
    assert warnings == [
        f"scenegen: warning: {old}: no sha256 digest (written by an older version of "
        "scenegen, or edited); computing this run again",
        f"scenegen: warning: {rec}: not a readable JSON file (Unterminated string starting "
        "at line 1 column 100: truncated or damaged); computing this run again",
    ]
    assert (exp_copy / "results.json").read_bytes() == original
    assert _validate(exp_copy, capsys)[0] == 0


def test_old_results_json_is_refused_by_the_report_with_a_hint(exp_copy, capsys):
    from scenegen.io.sealed import SEAL
    from scenegen.lab.report import build_report

    root = exp_copy.parent.parent
    build_report(root)
    assert main(["validate", str(root)]) == 0
    assert capsys.readouterr().out.strip() == f"{root}: valid report folder"
    res = exp_copy / "results.json"
    doc = json.loads(res.read_text())
    del doc[SEAL]
    res.write_text(json.dumps(doc, indent=1))
    with pytest.raises(DataError) as err:
        build_report(root)
    assert str(err.value) == (
        f"{res}: no sha256 digest (written by an older version of scenegen, or edited): run "
        "the experiment again into its folder to recompute it"
    )
    code = main(["validate", str(root)])
    assert code == 1 and capsys.readouterr().err.splitlines() == [str(err.value)]


def test_deep_validation_of_a_scene_without_entities(tmp_path, capsys):
    # --deep called a fresh zero-entity file "damaged HDF5 metadata" (a reshape of K = 0).
    from scenegen.io import write
    from scenegen.render.plan import generate

    p = tmp_path / "z.h5"
    write(p, generate(from_dict({"width": 20, "height": 20, "n_frames": 2}), seed=1))
    assert main(["validate", "--deep", str(p)]) == 0, capsys.readouterr().err
