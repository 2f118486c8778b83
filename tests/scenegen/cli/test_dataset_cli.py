"""The dataset and benchmark verbs: exit codes, one-line errors, validate DIR."""

import json

import pytest

from scenegen.cli import main

TINY = {
    "name": "tiny",
    "base": "kams-a",
    "set": {"n_frames": 3, "width": 48, "height": 40, "entities[0].position": [24, 20],
            "entities[0].appearance.size": [10, 10],
            "entities[0].motion.x.margin": 1, "entities[0].motion.y.margin": 1},
    "sweep": {"clutter[0].count": [0, 6]},
    "count": 4,
}  # fmt: skip


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"sweep": {"clutter[0].colour": [1]}}, "sweep.clutter[0].colour: unknown field"),
        ({"vary": {"sensor_noise": {"uniform": [2, 2]}}}, "vary.sensor_noise: empty range"),
        ({"vary": {"clutter[0].min_size": {"loguniform": [1, 9]}}},
         "vary.clutter[0].min_size: loguniform draws real numbers"),
    ],
)  # fmt: skip
def test_bad_family_exits_2_with_one_line(tmp_path, capsys, change, named):
    family = tmp_path / "bad.yaml"
    family.write_text(json.dumps({**TINY, **change}))  # JSON is YAML
    assert main(["dataset", str(family), "-o", str(tmp_path / "ds")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and named in err and str(family) in err
    assert not (tmp_path / "ds").exists()


def test_dataset_then_validate(tmp_path, capsys):
    family = tmp_path / "tiny.json"
    family.write_text(json.dumps(TINY))
    out = tmp_path / "ds"
    assert main(["dataset", str(family), "-o", str(out), "--jobs", "1", "--shard-size", "3"]) == 0
    cap = capsys.readouterr()
    assert cap.out.strip() == str(out.resolve())
    assert "4 sequences in 2 shards (2 made, 0 kept)" in cap.err
    assert main(["dataset", str(family), "-o", str(out), "--jobs", "1", "--shard-size", "3"]) == 0
    assert "(0 made, 2 kept)" in capsys.readouterr().err
    assert main(["validate", str(out)]) == 0
    (out / "shard-00001.h5").unlink()
    assert main(["validate", str(out)]) == 1
    assert "shard-00001.h5: missing shard file" in capsys.readouterr().err


def test_bad_counts_exit_2(tmp_path, capsys):
    assert main(["dataset", "kams", "-o", str(tmp_path / "a"), "--count", "0"]) == 2
    assert "--count must be >= 1" in capsys.readouterr().err
    assert main(["dataset", "kams", "-o", str(tmp_path / "a"), "--jobs", "0"]) == 2
    assert main(["dataset", "nope", "-o", str(tmp_path / "a")]) == 2
    assert "unknown family 'nope'" in capsys.readouterr().err


def test_benchmark_errors(tmp_path, capsys):
    assert main(["benchmark", str(tmp_path), "--tracker", "sok", "-o", str(tmp_path / "b")]) == 1
    assert "not a dataset folder" in capsys.readouterr().err
    family = tmp_path / "tiny.json"
    family.write_text(json.dumps(TINY))
    out = tmp_path / "ds"
    assert main(["dataset", str(family), "-o", str(out), "--jobs", "1"]) == 0
    assert main(["benchmark", str(out), "--tracker", "nope", "-o", str(tmp_path / "b")]) == 2
    assert "unknown tracker 'nope'" in capsys.readouterr().err
    args = ["benchmark", str(out), "--tracker", "sok", "--param", "n_layers=3", "-o", "b"]
    assert main(args) == 2
    assert "--param n_layers: no tracker of sok takes this parameter" in capsys.readouterr().err


def test_unreachable_scheduler_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "ds"
    assert main(["dataset", "kams", "--count", "2", "-o", str(out),
                 "--scheduler", "tcp://127.0.0.1:9"]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert "cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'" in err and err.count("\n") == 1
    assert not out.exists()


def test_validate_an_unknown_folder_says_what_it_looked_for(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("x")
    assert main(["validate", str(tmp_path)]) == 1
    assert capsys.readouterr().err.strip() == (
        f"{tmp_path}: not a scenegen folder (no manifest.json of a dataset, results.json of "
        "an experiment, report or benchmark, or runs/)")  # fmt: skip


def test_outputs_that_cannot_be_created_exit_2(tmp_path, capsys):
    family = tmp_path / "tiny.json"
    family.write_text(json.dumps(TINY))
    (tmp_path / "afile").write_text("x")
    bad = tmp_path / "afile" / "out"
    assert main(["dataset", str(family), "-o", str(bad), "--count", "1", "--jobs", "1"]) == 2
    assert capsys.readouterr().err == (f"scenegen: error: -o {bad}: cannot create the folder "
                                       "(Not a directory)\n")  # fmt: skip
    out = tmp_path / "ds"
    assert main(["dataset", str(family), "-o", str(out), "--jobs", "1"]) == 0
    capsys.readouterr()
    assert main(["benchmark", str(out), "--tracker", "kalman", "-o", str(bad)]) == 2
    assert capsys.readouterr().err == (f"scenegen: error: -o {bad}: cannot create the folder "
                                       "(Not a directory)\n")  # fmt: skip


def test_a_shard_size_of_0_is_refused(tmp_path, capsys):
    args = ["dataset", "kams", "--count", "1", "-o", str(tmp_path / "a"), "--shard-size", "0"]
    assert main(args) == 2
    assert capsys.readouterr().err == "scenegen: error: --shard-size must be >= 1, got 0\n"
    assert not (tmp_path / "a").exists()


def test_a_damaged_manifest_entry_is_one_line_for_each_verb(tmp_path, capsys):
    family = tmp_path / "tiny.json"
    family.write_text(json.dumps(TINY))
    out = tmp_path / "ds"
    assert main(["dataset", str(family), "-o", str(out), "--jobs", "1"]) == 0
    capsys.readouterr()
    path = out / "manifest.json"
    man = json.loads(path.read_text())
    del man["sequences"][1]["name"]
    path.write_text(json.dumps(man))
    line = f"{path}: entry 1: no 'name'"
    assert main(["validate", str(out)]) == 1
    assert capsys.readouterr().err.splitlines()[0] == line
    assert main(["benchmark", str(out), "--tracker", "kalman", "-o", str(tmp_path / "b")]) == 1
    assert capsys.readouterr().err == f"scenegen: error: {line}\n"
    assert main(["dataset", str(family), "-o", str(out), "--jobs", "1"]) == 2
    assert capsys.readouterr().err == (f"scenegen: error: {line}; cannot resume the dataset in "
                                       f"{out}: remove the folder or choose another output "
                                       "folder\n")  # fmt: skip


def test_frames_with_a_swept_frame_count_exits_2(tmp_path, capsys):
    family = tmp_path / "nf.yaml"
    family.write_text("name: nf\nbase: kams-a\nsweep:\n  n_frames: [6, 7]\n")
    out = tmp_path / "nfd"
    assert main(["dataset", str(family), "-o", str(out), "--count", "2", "--frames", "3",
                 "--jobs", "1"]) == 2  # fmt: skip
    assert capsys.readouterr().err == (f"scenegen: error: --frames 3: {family}: sweep.n_frames: "
                                       "sets n_frames per sequence; it cannot be overridden\n")
    assert not out.exists()
