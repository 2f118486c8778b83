"""Mistakes a user can make with `experiment` and `fixtures`: one line, the right exit code,
and never a wrong result (each test names the defect it guards against)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from scenegen.cli import _interrupted, main
from scenegen.errors import ConfigError
from scenegen.lab.experiments import get
from scenegen.lab.experiments.runner import plan_tasks, tracker_params

FIXTURES = Path(__file__).resolve().parents[3] / "fixtures"


def test_a_method_given_twice_is_refused():
    # Its runs were counted twice: "3 of 3" became "6 of 6" and a verdict "reproduced".
    with pytest.raises(ConfigError, match="method 'KAMS' is given twice"):
        plan_tasks(get("kams-accuracy"), runs=1, scenes=1, seed=0, quick=True,
                   methods=["kams", "KAMS"])


def test_a_particle_count_set_by_the_user_wins_over_quick():
    # --quick capped n_particles after the override: records said 60, the folder 600.
    exp = get("dps-occlusion")
    kw = {"runs": 1, "scenes": 1, "seed": 0, "quick": True, "methods": ["dps"]}
    task = plan_tasks(exp, **kw, overrides={"n_particles": 600})[0]
    assert tracker_params(exp, task)["n_particles"] == 600
    plain = plan_tasks(exp, **kw)[0]
    assert tracker_params(exp, plain)["n_particles"] == exp.quick_particles


def test_a_pipe_in_a_claim_does_not_split_its_cell():
    # shm-depth's "mean max |P − 1/L|" put the numbers under the wrong headings.
    from scenegen.lab.experiments.tables import _cell
    from scenegen.lab.report import markdown_to_html

    md = "| claim | ours |\n|---|---|\n| " + _cell("max |P − 1/L| below 0.1") + " | 0.06 |"
    html = markdown_to_html(md)
    assert "<td>max |P − 1/L| below 0.1</td><td>0.06</td>" in html


def test_ctrl_c_inside_a_compiled_kernel_is_an_interruption():
    # numba turns it into SystemError(...) from KeyboardInterrupt: was "internal error".
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as err:
            raise SystemError("returned a result with an exception set") from err
    except SystemError as err:
        assert _interrupted(err)
    assert not _interrupted(ValueError("x"))


def test_a_usage_error_is_one_line(capsys):
    # argparse printed its usage block before the error.
    assert main(["experiment", "shm-depth", "--seed", "abc", "-o", "x"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "(see scenegen experiment --help)" in err


def test_outputs_that_are_files_or_hold_another_experiment_are_refused(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("hi")
    args = ["experiment", "shm-depth", "--quick", "--scenes", "1", "--runs", "1", "-o"]
    assert main([*args, str(afile)]) == 2  # was "internal error: FileExistsError"
    assert "cannot create the folder" in capsys.readouterr().err
    other = tmp_path / "other"
    other.mkdir()
    (other / "results.json").write_text(json.dumps({"experiment": "kams-robustness"}))
    assert main([*args, str(other)]) == 2  # was mixed in silently
    assert "holds the results of experiment 'kams-robustness'" in capsys.readouterr().err
    assert not (other / "runs").exists()


@pytest.fixture()
def fx(tmp_path):
    folder = tmp_path / "fx"
    shutil.copytree(FIXTURES, folder)
    return folder


def test_a_damaged_expected_output_is_named_and_regen_rewrites_it(fx, capsys):
    # verify and regen said "internal error: ValueError: ... pickled (object) data".
    (fx / "expected" / "one-pixel" / "kalman.npy").write_text("garbage")
    sel = ["--dir", str(fx), "--fixture", "one-pixel", "--tracker", "kalman"]
    assert main(["fixtures", "verify", *sel]) == 1
    out, err = capsys.readouterr()
    assert "kalman.npy is not a readable .npy file" in err
    # The hint names the folder and the selection, not the repository's fixtures.
    assert f"run `scenegen fixtures regen --dir {fx} --fixture one-pixel --tracker kalman`" in out
    assert main(["fixtures", "regen", *sel]) == 0
    assert main(["fixtures", "verify", *sel]) == 0, capsys.readouterr().err


def test_regen_repairs_a_damaged_fixture_file(fx, capsys):
    # regen said "nothing changed" and left the truncated file.
    path = fx / "one-pixel.h5"
    with open(path, "r+b") as f:
        f.truncate(3000)
    sel = ["--dir", str(fx), "--fixture", "one-pixel", "--tracker", "kalman"]
    assert main(["fixtures", "regen", *sel]) == 0
    assert "its file was damaged or edited" in capsys.readouterr().out
    assert main(["fixtures", "verify", *sel]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("edit", [
    lambda reg: reg["fixtures"]["one-pixel"].pop("config"),
    lambda reg: reg["fixtures"]["one-pixel"].update(seed="abc"),
])  # fmt: skip
def test_a_damaged_registry_entry_is_a_mismatch_line(fx, capsys, edit):
    # KeyError / ValueError were internal errors.
    reg = json.loads((fx / "registry.json").read_text())
    edit(reg)
    (fx / "registry.json").write_text(json.dumps(reg))
    sel = ["--dir", str(fx), "--fixture", "one-pixel", "--tracker", "kalman"]
    assert main(["fixtures", "verify", *sel]) == 1
    assert "fixture one-pixel: its registry entry is damaged" in capsys.readouterr().err
