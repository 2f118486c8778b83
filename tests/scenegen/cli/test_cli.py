"""The CLI: verbs, exit codes (0 ok, 1 invalid data, 2 usage/config) and one-line errors."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from scenegen.cli import main
from scenegen.io import read


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_presets_json(capsys):
    code, out, _ = run(capsys, "presets", "--json")
    assert code == 0
    names = [p["name"] for p in json.loads(out)]
    assert names[:7] == ["dps-synthetic", "dps-occlusion", "kams-a", "kams-b", "kams-c",
                         "kams-d", "shm-crossing"]  # fmt: skip
    assert names[-3:] == ["faces-crossing", "tiger-like", "dps-synthetic-real"]
    assert set(names[7:-3]) >= {"dps-occlusion-2", "dps-dancers", "shm-clutter"}


def test_generate_inspect_validate_preview_export(tmp_path, capsys):
    out_h5 = tmp_path / "s.h5"
    code, out, _ = run(capsys, "generate", "--preset", "kams-b", "--seed", "2", "-o", out_h5,
                       "--frames", "6", "--compression", "lzf")  # fmt: skip
    assert code == 0 and out_h5.exists()
    seq = read(out_h5)
    assert seq.n_frames == 6 and seq.seed == 2
    code, out, _ = run(capsys, "inspect", out_h5, "--json")
    info = json.loads(out)
    assert code == 0 and info["sequences"][0]["compression"] == "lzf"
    assert info["sequences"][0]["entities"] == {"clutter": 300, "target": 1}
    assert run(capsys, "validate", out_h5)[0] == 0
    for ext in ("png", "gif"):
        code, _, _ = run(capsys, "preview", out_h5, "-o", tmp_path / f"p.{ext}")
        assert code == 0 and (tmp_path / f"p.{ext}").stat().st_size > 1000
    code, _, _ = run(capsys, "export", out_h5, "--format", "mot", "-o", tmp_path / "mot")
    assert code == 0
    rows = np.loadtxt(tmp_path / "mot" / "gt" / "gt.txt", delimiter=",", ndmin=2)
    assert rows.shape == (6, 9)
    assert rows[:, 0].tolist() == [1, 2, 3, 4, 5, 6] and set(rows[:, 1]) == {1}
    np.testing.assert_allclose(rows[:, 2:4] - 1, seq.gt.box[:, 0, :2])  # MOT pixels are 1-based
    np.testing.assert_allclose(rows[:, 4:6], seq.gt.box[:, 0, 2:])
    np.testing.assert_allclose(rows[:, 8], seq.gt.visibility[:, 0], atol=1e-6)
    ini = (tmp_path / "mot" / "seqinfo.ini").read_text()
    assert "seqLength=6" in ini and "imWidth=320" in ini
    assert len(list((tmp_path / "mot" / "img1").glob("*.png"))) == 6


def test_generate_from_yaml_config(tmp_path, capsys):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        "width: 40\nheight: 30\nn_frames: 4\nentities:\n"
        "  - {name: a, role: target, position: [20, 15], appearance: {size: [5, 5]}}\n"
    )
    code, _, _ = run(capsys, "generate", "--config", cfg, "-o", tmp_path / "c.h5")
    assert code == 0 and read(tmp_path / "c.h5").config.width == 40


@pytest.mark.parametrize(
    ("config", "field"),
    [
        ({"width": -3, "height": 10, "n_frames": 5}, "width"),
        ({"width": 30, "height": 10, "n_frames": 5,
          "entities": [{"name": "a", "role": "hero", "position": [1, 1]}]}, "entities[0].role"),
        ({"width": 30, "height": 10, "n_frames": 5,
          "entities": [{"name": "a", "role": "target", "position": [1, 1]},
                       {"name": "b", "role": "target", "position": [1, 1]}]}, "entities[1].depth"),
        ({"width": 30, "height": 10, "n_frames": 5,
          "entities": [{"name": "a", "role": "target", "position": [1, 1],
                        "motion": {"x": {"sigma": 1}, "y": {"sigma": 1, "boundary": "free"}}}]},
         "entities[0].motion.x.boundary"),
        # Explosive AR2s on unbounded axes: refused when planned, naming the AR2.
        ({"width": 30, "height": 10, "n_frames": 50,
          "entities": [{"name": "a", "role": "target", "position": [1, 1],
                        "motion": {"x": {"a1": 1000, "sigma": 1, "boundary": "free"},
                                   "y": {"sigma": 1, "boundary": "free"}}}]},
         "entities[0].motion.x: the AR2 path reaches"),
        ({"width": 30, "height": 10, "n_frames": 50,
          "entities": [{"name": "a", "role": "target", "position": [1, 1],
                        "motion": {"x": {"boundary": "free"}, "y": {"boundary": "free"},
                                   "scale": {"a1": 0, "a2": -30, "sigma": 0.1,
                                             "boundary": "free"}}}]},
         "entities[0].motion.scale: the AR2 path reaches"),
        # A free camera axis is refused outright (its view would stick at the extent).
        ({"width": 30, "height": 10, "n_frames": 50,
          "camera": {"extent": [4, 4], "x": {"a1": 1000, "sigma": 1, "boundary": "free"}}},
         "camera.x.boundary: free is not allowed on a camera"),
        ({"width": 30, "height": 10, "n_frames": 50,
          "photometric": {"gain": {"a1": 1000, "sigma": 0.1, "boundary": "free"}}},
         "photometric.gain: the AR2 path reaches"),
    ],
)  # fmt: skip
def test_bad_config_exits_2_with_one_line(tmp_path, capsys, config, field):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(config))
    code, out, err = run(capsys, "generate", "--config", path, "-o", tmp_path / "x.h5")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and field in err and "Traceback" not in err
    assert err.startswith(f"scenegen: error: {path}: "), err  # the file is named
    assert not (tmp_path / "x.h5").exists()


def test_usage_errors_exit_2(tmp_path, capsys):
    assert run(capsys, "generate", "--preset", "nope", "-o", tmp_path / "x.h5")[0] == 2
    assert run(capsys, "generate", "-o", tmp_path / "x.h5")[0] == 2
    assert run(capsys, "frobnicate")[0] == 2
    code, _, err = run(capsys, "generate", "--preset", "kams-a", "-o", tmp_path / "x.h5",
                       "--compression", "zstd")  # fmt: skip
    assert code == 2 and "--compression" in err
    code, _, err = run(capsys, "generate", "--preset", "kams-a", "-o", tmp_path / "no/dir/x.h5")
    assert code == 2 and "does not exist" in err


@pytest.mark.parametrize("argv", [
    ("generate", "--preset", "kams-a", "--se", "3"),  # --seed
    ("generate", "--pre", "kams-a"),  # --preset
    ("export", "x.h5", "--format", "mot", "--gt", "amodal"),  # --gt-mode
])
def test_an_abbreviated_flag_is_a_usage_error(tmp_path, capsys, argv):
    # Prefix matching would tie scripts to today's flag set: --gt means --gt-mode until a
    # second --gt... flag makes it ambiguous. Flags are spelt in full or refused, exit 2.
    code, out, err = run(capsys, *argv, "-o", tmp_path / "x")
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("verb", ["inspect", "validate"])
def test_bad_files_exit_1(tmp_path, capsys, verb):
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not hdf5 at all")
    code, _, err = run(capsys, verb, junk)
    assert code == 1 and len(err.strip().splitlines()) == 1 and "not an HDF5 file" in err
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["schema"] = "other/9"
    code, _, err = run(capsys, verb, other)
    assert code == 1 and "schema is 'other/9'" in err and "Traceback" not in err
    code, _, err = run(capsys, verb, tmp_path / "missing.h5")
    assert code == 1 and "no such file" in err


def test_a_closed_pipe_ends_quietly_with_1():
    # `scenegen presets | head -1`: the reader is gone before we write. No "internal
    # error", no "Exception ignored" at exit; 1 (the contract's codes are 0, 1 and 2).
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "scenegen.cli", "presets"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)  # fmt: skip
    proc.stdout.close()  # the child holds only the write end: its first write fails
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == 1 and err == b""


@pytest.mark.parametrize("verb", [["generate", "--preset", "kams-a", "-o", "x.h5"],
                                  ["track", "x.h5", "--tracker", "kams", "-o", "r.h5"],
                                  ["dataset", "kams", "-o", "d"], ["demo", "-o", "d"],
                                  ["experiment", "shm-depth", "-o", "e"]])  # fmt: skip
@pytest.mark.parametrize("value", ["-1", "18446744073709551616", "3.5", "x"])
def test_every_seed_option_takes_0_to_2_64_minus_1(verb, value, capsys):
    # Larger seeds ended in an internal error when written (a 64-bit attribute); every
    # verb's --seed is the same argument type, and a bad one is a usage error.
    assert main([*verb, "--seed", value]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"error: argument --seed: must be an integer in [0, 2**64 - 1], got {value!r} " in err


def test_demo_help_says_what_its_seed_seeds(capsys):
    # "seed of the preset sequences": the experiments run on preset sequences too, yet
    # always on base seed 0 (a demo folder of another seed has no rerun command).
    assert main(["demo", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "written to OUTPUT/presets/" in text
    assert "the experiments always run on base seed 0" in text


def test_the_largest_seed_is_written_and_read_back(tmp_path):
    out = tmp_path / "g.h5"
    assert main(["generate", "--preset", "kams-a", "--frames", "2", "--seed",
                 str(2**64 - 1), "-o", str(out)]) == 0  # fmt: skip
    assert read(out).seed == 2**64 - 1
    res = tmp_path / "r.h5"
    assert main(["track", str(out), "--tracker", "sok", "--seed", str(2**64 - 1), "-o",
                 str(res)]) == 0  # fmt: skip
    # The API refuses what no file can hold (it was an internal error when written).
    import scenegen
    from scenegen.errors import ConfigError

    with pytest.raises(ConfigError, match=r"seed must be an integer in \[0, 2\*\*64 - 1\]"):
        scenegen.generate("kams-a", seed=2**64, frames=2)


def test_bench_only_that_matches_nothing_is_a_usage_error(capsys):
    # It printed an empty table and exited 0.
    assert main(["bench", "--only", "nothing", "--repeats", "1"]) == 2
    assert capsys.readouterr().err.strip() == (
        "scenegen: error: --only 'nothing' matches no bench module; modules: generation, "
        "particle, stepshare, meanshift, shm, reliability, guarded, scaling, datasets")  # fmt: skip


def test_an_mp4_preview_of_frames_the_encoder_refuses_names_their_size(tmp_path, capsys):
    # It said "this OpenCV build cannot write MP4" (and the encoder printed its own lines).
    from scenegen.config import from_dict
    from scenegen.io import write
    from scenegen.render.plan import generate

    cfg = from_dict({"width": 1, "height": 30, "n_frames": 2})
    write(tmp_path / "one.h5", generate(cfg, seed=1))
    code = main(["preview", str(tmp_path / "one.h5"), "-o", str(tmp_path / "one.mp4")])
    err = capsys.readouterr().err
    assert code == 2 and "MP4 frames must be 2..8191 px a side, these are 1x30" in err, err
    assert not (tmp_path / "one.mp4").exists()


def test_a_sequence_or_tracker_the_file_lacks_is_a_usage_error(tmp_path, capsys):
    # The option picks it: exit 2 naming the option (it was exit 1, "name one of ...").
    import scenegen

    multi = tmp_path / "multi.h5"
    scenegen.write(multi, scenegen.generate("kams-a", seed=1, frames=3),
                   scenegen.generate(scenegen.presets.get("kams-b"), seed=2, frames=3))
    res = tmp_path / "r.h5"
    for argv, option in (
        (["track", multi, "--tracker", "kalman", "-o", res], "--sequence"),
        (["track", multi, "--sequence", "x", "--tracker", "kalman", "-o", res], "--sequence"),
        (["preview", multi, "-o", tmp_path / "p.gif"], "--sequence"),
        (["export", multi, "--format", "mot", "-o", tmp_path / "m"], "--sequence"),
    ):  # fmt: skip
        code, _, err = run(capsys, *argv)
        assert code == 2 and err.strip().endswith(f"(choose with {option})"), err
    assert run(capsys, "track", multi, "--sequence", "kams-a", "--tracker", "kalman",
               "-o", res)[0] == 0  # fmt: skip
    code, _, err = run(capsys, "evaluate", multi, res, "--sequence", "kams-a", "--tracker", "x")
    assert code == 2 and "no result for tracker 'x'; it holds kalman (choose with --tracker)" in err
    code, _, err = run(capsys, "export", res, "--format", "mot", "--tracker", "x",
                       "-o", tmp_path / "r.txt")  # fmt: skip
    assert code == 2 and err.strip().endswith("(choose with --tracker)")


def test_a_full_disk_is_one_line_naming_the_output(tmp_path, capsys, monkeypatch):
    # h5py reports a write that fails when HDF5 flushes a file (a full disk) as a
    # RuntimeError whose text holds the errno: it was an internal error, exit 1.
    import scenegen.io

    def full(*args, **kwargs):
        raise RuntimeError("Disable slist on flush dest failure failed (file write failed: "
                           "time = ...\n, errno = 28, error message = 'No space left')")

    monkeypatch.setattr(scenegen.io, "write_scenario", full)
    out = tmp_path / "x.h5"
    code, _, err = run(capsys, "generate", "--preset", "kams-a", "--frames", "2", "-o", out)
    line = f"scenegen: error: {out}: cannot write: No space left on device"
    assert (code, err.strip()) == (2, line)
