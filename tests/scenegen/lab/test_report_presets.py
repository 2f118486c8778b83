"""``validate`` on a demo report checks its preset files: a damaged sequence file, contact
sheet or preview is one line naming it (it said "valid report folder" for all three), and
so is any change of a preset file after it was written, against the sealed listing of
their digests (a GIF has no checksum: a flipped bit in its pixels could still decode)."""

from __future__ import annotations

import os
import shutil

import pytest

from scenegen.cli import main
from scenegen.lab.demo_presets import LISTING, generate_presets, presets_problems
from scenegen.lab.report import build_report

PRESET = "dps-synthetic"


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A report folder as ``scenegen demo`` leaves it, with one preset and no experiment."""
    root = tmp_path_factory.mktemp("report")
    (root / "experiments").mkdir()
    generate_presets(root, 0, [PRESET])
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


def _again(folder):
    return f"`scenegen demo -o {folder}` with the report's --seed writes it again"


def test_the_listing_gives_each_files_digest_in_the_order_written(report):
    import hashlib

    from scenegen.io.sealed import read_sealed_json

    doc = read_sealed_json(report / "presets" / LISTING)
    names = [f"{PRESET}{s}" for s in (".h5", ".png", ".gif")]
    assert doc == {"files": [
        f"{n} {hashlib.sha256((report / 'presets' / n).read_bytes()).hexdigest()}"
        for n in names]}  # fmt: skip


def test_a_flipped_bit_that_still_decodes_is_found(folder, capsys):
    """A bit flipped in a GIF's compressed pixels that Pillow still decodes: the digest
    differs from the listed one."""
    from scenegen.io.images import gif_problem

    path = folder / "presets" / f"{PRESET}.gif"
    data = bytearray(path.read_bytes())
    for at in range(len(data) // 2, len(data) - 2):  # the first flip that still decodes
        data[at] ^= 0x10
        if gif_problem(bytes(data)) is None:
            break
        data[at] ^= 0x10
    else:
        pytest.fail("no flipped bit of the preview decodes")
    path.write_bytes(bytes(data))
    want = (f"{path}: is not the file {LISTING} lists (damaged or edited: "
            f"{_again(folder)})")  # fmt: skip
    assert presets_problems(folder) == [want]
    assert main(["validate", str(folder)]) == 1
    assert capsys.readouterr().err.splitlines() == [want]


def test_the_listing_missing_damaged_or_a_fifo_is_one_line(folder, deadline):
    listing = folder / "presets" / LISTING
    text = listing.read_text()
    listing.write_text(text.replace(PRESET, "dps-synthetiC", 1))
    assert presets_problems(folder) == [
        f"{listing}: content does not match its sha256 digest (damaged or edited) "
        f"({_again(folder)})"]  # fmt: skip
    listing.unlink()
    assert presets_problems(folder) == [
        f"{listing}: missing: it lists the preset files' digests ({_again(folder)})"]
    os.mkfifo(listing)
    with deadline(60):
        assert presets_problems(folder) == [
            f"{listing}: is not a regular file (a FIFO) (remove it, then {_again(folder)})"]


def test_a_file_not_listed_or_a_listed_file_missing_is_one_line(folder):
    presets = folder / "presets"
    extra = presets / "other.png"
    shutil.copy(presets / f"{PRESET}.png", extra)
    assert presets_problems(folder) == [
        f"{extra}: not a file {LISTING} lists (remove it, or {_again(folder)})"]
    extra.unlink()
    (presets / f"{PRESET}.png").unlink()
    assert presets_problems(folder) == [f"{presets / PRESET}.png: missing ({_again(folder)})"]
