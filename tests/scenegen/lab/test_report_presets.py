"""``validate`` on a demo report checks its preset files: a damaged sequence file, contact
sheet or preview is one line naming it (it said "valid report folder" for all three)."""

from __future__ import annotations

import os
import shutil

import pytest

from scenegen.cli import main
from scenegen.lab.report import build_report, presets_problems

PRESET = "dps-synthetic"


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A report folder as ``scenegen demo`` leaves it, with one preset and no experiment."""
    from scenegen.cli.demo import _write_sheet
    from scenegen.io import write
    from scenegen.io.preview import write_preview
    from scenegen.render.plan import generate

    root = tmp_path_factory.mktemp("report")
    (root / "experiments").mkdir()
    (root / "presets").mkdir()
    seq = generate(PRESET, seed=0)
    write(root / "presets" / f"{PRESET}.h5", seq)
    _write_sheet(seq, root / "presets" / f"{PRESET}.png")
    write_preview(seq, root / "presets" / f"{PRESET}.gif", max_frames=80)
    build_report(root)
    return root


@pytest.fixture
def folder(report, tmp_path):
    out = tmp_path / "r"
    shutil.copytree(report, out)
    return out


def test_a_sound_report_and_one_without_presets(folder, capsys):
    assert presets_problems(folder) == []
    assert main(["validate", str(folder)]) == 0
    assert capsys.readouterr().out.strip() == f"{folder}: valid report folder"
    shutil.rmtree(folder / "presets")  # a report of `scenegen experiment all`
    assert presets_problems(folder) == []


def _cut(n):
    return lambda p: p.write_bytes(p.read_bytes()[:-n])


def _fifo(p):
    p.unlink()
    os.mkfifo(p)


def _middle_cut_gif(p):
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2] + b";")  # the trailer is there, a frame is not


@pytest.mark.parametrize(("suffix", "damage", "what"), [
    (".png", _cut(3), "not a whole PNG image (it does not end with the IEND chunk) (damaged: "),
    (".png", lambda p: p.write_bytes(b"GIF89a" + p.read_bytes()), "not a PNG file (damaged: "),
    (".gif", _cut(1), "not a whole GIF image (it does not end with the GIF trailer) (damaged: "),
    (".gif", _middle_cut_gif, "not a whole GIF image (image file is truncated"),
    (".gif", lambda p: p.write_bytes(b"\x89PNG" + p.read_bytes()), "not a GIF file (damaged: "),
    (".h5", lambda p: p.write_bytes(p.read_bytes()[:9000]), "truncated HDF5 file (9000 of "),
    (".gif", _fifo, "is not a regular file (a FIFO) (remove it, then "),
    (".h5", _fifo, "is not a regular file (a FIFO) (remove it, then "),
])
def test_a_damaged_preset_file_is_one_line(folder, capsys, deadline, suffix, damage, what):
    path = folder / "presets" / f"{PRESET}{suffix}"
    damage(path)
    again = f"`scenegen demo -o {folder}` with the report's --seed writes it again)"
    with deadline(120):  # a FIFO is never opened
        problems = presets_problems(folder)
        assert len(problems) == 1, problems
        assert problems[0].startswith(f"{path}: {what}")
        assert problems[0].endswith(again)
        capsys.readouterr()
        assert main(["validate", str(folder)]) == 1
    assert capsys.readouterr().err.splitlines() == problems
