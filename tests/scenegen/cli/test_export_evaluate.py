"""MOT round trip (export a result, evaluate the tracker file), benchmark layouts, rough edges."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest

from scenegen.cli import _parser, main
from scenegen.errors import ConfigError, DataError
from scenegen.io import TrackerResult, read, write_result
from scenegen.io.benchmarks import cover_level, export_benchmark
from scenegen.io.mot import (
    gt_keep,
    gt_rows,
    read_mot_tracker,
    read_mot_tracker_rows,
    write_mot_tracker,
)

FIXTURES = Path(__file__).resolve().parents[3] / "fixtures"


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def occluded():
    return read(FIXTURES / "full-occlusion.h5")


def test_result_round_trip_through_a_mot_file(tmp_path, capsys, occluded):
    seq = occluded
    boxes = np.load(FIXTURES / "expected" / "full-occlusion" / "kalman.npy").astype(np.float32)
    boxes[3, 0] = np.nan  # a frame without a box: no row
    b64 = boxes.astype(np.float64)
    ids = seq.entities.id[seq.initial_targets()]
    res = tmp_path / "r.h5"
    write_result(res, TrackerResult("kalman", {}, 0, seq.name, ids, boxes))
    txt = tmp_path / "kalman.txt"
    code, out, _ = run(capsys, "export", res, "--format", "mot", "-o", txt)
    assert code == 0 and "MOTChallenge" in out
    rows = np.loadtxt(txt, delimiter=",", ndmin=2)
    assert rows.shape == (seq.n_frames - 1, 10) and 4 not in rows[:, 0]
    np.testing.assert_array_equal(rows[:, 2:4], b64[rows[:, 0].astype(int) - 1, 0, :2] + 1.0)
    got_ids, got = read_mot_tracker(txt, seq.n_frames)
    assert got_ids.tolist() == ids.tolist()
    np.testing.assert_array_equal(got, b64)  # exact round trip
    for mode in ("amodal", "visible"):
        a = json.loads(run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", res, "--json",
                           "--gt-mode", mode)[1])  # fmt: skip
        b = json.loads(run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", txt, "--json",
                           "--gt-mode", mode)[1])  # fmt: skip
        assert a["overall"] | {"otb_average": 0} == b["overall"] | {"otb_average": 0}
        assert a["gt_mode"] == mode
    # amodal counts the two fully occluded frames, visible ignores them
    assert a["overall"]["tp"] + a["overall"]["fn"] == seq.n_frames - 2
    code, out, _ = run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", txt)
    assert code == 0 and "HOTA" in out and "IDSW" in out and "Frag" in out


def test_bad_tracker_files_name_file_and_line(tmp_path, capsys):
    seq_file = FIXTURES / "full-occlusion.h5"
    bad = tmp_path / "bad.txt"
    bad.write_text("1,1,2,3,4,5,1,-1,-1,-1\n2,1,x,3,4,5\n")
    code, _, err = run(capsys, "evaluate", seq_file, bad)
    assert code == 1 and "bad.txt:2" in err and len(err.strip().splitlines()) == 1
    bad.write_text("99,1,2,3,4,5\n")
    code, _, err = run(capsys, "evaluate", seq_file, bad)
    assert code == 1 and "frame 99 is outside 1..14" in err
    # A box value that is not a finite number, or a negative size, is not a box (it was
    # read as one: a NaN row as "lost", a negative width as a box). An inf or huge frame
    # or id was an internal error (OverflowError).
    for row, why in (("2,1,nan,3,4,5", "a box value is not a finite number"),
                     ("2,1,2,inf,4,5", "a box value is not a finite number"),
                     ("2,1,2,3,-4,5", "width and height must not be negative"),
                     ("inf,1,2,3,4,5", "frame and id must be integers"),
                     ("2,99999999999999999999,2,3,4,5", "id beyond ±9223372036854775807"),
                     ("2,1e20,2,3,4,5", "1e20 is written as a float beyond 2**53, which is "
                                        "not exact; write the integer")):  # fmt: skip
        bad.write_text(f"1,1,2,3,4,5\n{row}\n")
        code, _, err = run(capsys, "evaluate", seq_file, bad)
        assert code == 1 and err.strip() == (f"scenegen: error: {bad}:2: not a MOTChallenge "
                                             f"row ({why}): {row!r}")  # fmt: skip
    # Ids above 2**53 are read exactly (they were parsed as floats: two merged).
    bad.write_text("1,9007199254740993,2,3,4,5\n1,9007199254740992,2,3,4,5\n")
    from scenegen.io.mot import read_mot_tracker

    assert read_mot_tracker(bad, 14)[0].tolist() == [9007199254740992, 9007199254740993]
    # A duplicate names its line too.
    bad.write_text("1,1,2,3,4,5\n1,1,2,3,4,5\n")
    code, _, err = run(capsys, "evaluate", seq_file, bad)
    assert code == 1 and f"{bad}:2: track id 1 appears twice in frame 1" in err
    code, _, err = run(capsys, "evaluate", seq_file, bad, "--gt-mode", "visible",
                       "--visibility-threshold", "1.5")  # fmt: skip
    assert code == 2



def test_an_overflowing_box_and_a_non_hdf5_result_h5_are_refused(tmp_path, capsys):
    seq_file = FIXTURES / "full-occlusion.h5"
    # Finite values whose right edge overflows: four lines of numpy overflow warnings,
    # then scores and exit 0.
    bad = tmp_path / "huge.txt"
    row = "2,1,1e308,3,1e308,5"
    bad.write_text(f"1,1,2,3,4,5\n{row}\n")
    code, _, err = run(capsys, "evaluate", seq_file, bad)
    assert code == 1 and err.strip() == (
        f"scenegen: error: {bad}:2: not a MOTChallenge row (the box's right or bottom edge "
        f"overflows to infinity): {row!r}"
    )
    # An empty (or text) result.h5 was read as a MOTChallenge file: an empty one scored as
    # a tracker that gave no box, exit 0.
    for content in (b"", b"1,1,2,3,4,5\n"):
        result = tmp_path / "result.h5"
        result.write_bytes(content)
        code, out, err = run(capsys, "evaluate", seq_file, result)
        assert (code, out, err.strip()) == (1, "", f"scenegen: error: {result}: not an HDF5 file")


def test_gt_export_modes(tmp_path, capsys):
    src = FIXTURES / "distractor-on-target.h5"
    seq = read(src)
    for mode in ("amodal", "visible"):
        out = tmp_path / mode
        assert run(capsys, "export", src, "--format", "mot", "-o", out, "--gt-mode", mode)[0] == 0
        rows = np.loadtxt(out / "gt" / "gt.txt", delimiter=",", ndmin=2)
        if mode == "amodal":  # target rows only, all counted
            assert set(rows[:, 7]) == {1} and set(rows[:, 6]) == {1}
            assert len(rows) == int(seq.gt.present[:, seq.target_indices()].sum())
        else:  # distractor rows (class 8); fully occluded target rows conf 0
            assert 8 in rows[:, 7]
            hidden = (rows[:, 7] == 1) & (rows[:, 8] == 0)
            assert hidden.any() and set(rows[hidden, 6]) == {0}
    out = tmp_path / "jpg"
    assert run(capsys, "export", src, "--format", "mot", "-o", out, "--image-format", "jpg")[0] == 0
    assert "imExt=.jpg" in (out / "seqinfo.ini").read_text()
    assert len(list((out / "img1").glob("*.jpg"))) == seq.n_frames


def test_benchmark_layouts(tmp_path, capsys):
    src = FIXTURES / "enter-leave.h5"
    seq = read(src)
    names = []
    for kind in ("otb", "got10k", "vot"):
        out = tmp_path / kind
        code, _, _ = run(capsys, "export", src, "--format", kind, "-o", out)
        assert code == 0
        names = (out / "list.txt").read_text().split()
        assert len(names) == 2  # one sequence per target
        k = int(seq.target_indices()[1])  # target b enters late
        absent = ~np.asarray(seq.gt.present[:, k])
        assert absent.any()
        folder = out / names[1]
        gt_name = "groundtruth_rect.txt" if kind == "otb" else "groundtruth.txt"
        lines = (folder / gt_name).read_text().splitlines()
        assert len(lines) == seq.n_frames
        t = int(np.flatnonzero(~absent)[0])
        vals = [float(v) for v in lines[t].split(",")]
        offset = 1.0 if kind == "otb" else 0.0  # OTB is 1-based (MATLAB)
        np.testing.assert_allclose(vals, seq.gt.box[t, k] + [offset, offset, 0, 0], rtol=0)
        gone = lines[int(np.flatnonzero(absent)[0])]
        assert gone == ("nan,nan,nan,nan" if kind == "vot" else "0,0,0,0")
        frames = {"otb": "img/*.jpg", "got10k": "*.jpg", "vot": "color/*.png"}[kind]
        assert len(list(folder.glob(frames))) == seq.n_frames
    got = tmp_path / "got10k" / names[1]
    absence = (got / "absence.label").read_text().split()
    assert absence == [str(int(not p)) for p in seq.gt.present[:, seq.target_indices()[1]]]
    cut = (got / "cut_by_image.label").read_text().split()
    assert len(cut) == seq.n_frames and set(cut) <= {"0", "1"}
    assert "sequence" in {p.name for p in (tmp_path / "vot" / names[1]).iterdir()}
    code, _, _ = run(capsys, "export", src, "--format", "otb", "-o", tmp_path / "o2",
                     "--image-format", "png")  # fmt: skip
    assert code == 0 and len(list((tmp_path / "o2" / names[0] / "img").glob("*.png"))) == 12


def test_cover_levels_and_occlusion_tags(tmp_path, occluded):
    # Exact edges stored in float32 (0.9 -> 0.89999998) fall in the level they open.
    edges = np.float32([0.15, 0.3, 0.45, 0.6, 0.75, 0.9])
    assert [cover_level(v, True) for v in edges] == [2, 3, 4, 5, 6, 7]
    assert [cover_level(v, True) for v in (0, 0.1, 0.15, 0.3, 0.5, 0.89, 0.9, 1)] == [
        0, 1, 2, 3, 4, 6, 7, 8]  # fmt: skip
    assert cover_level(1.0, False) == 0
    done = []
    export_benchmark(occluded, tmp_path / "v", "vot", progress=done.append)
    assert done == list(range(1, occluded.n_frames + 1))
    (name,) = (tmp_path / "v" / "list.txt").read_text().split()
    tags = (tmp_path / "v" / name / "occlusion.tag").read_text().split()
    vis = occluded.gt.visibility[:, occluded.target_indices()[0]]
    assert tags == [str(int(v < 1)) for v in vis] and "1" in tags


def test_unwritable_output_names_the_target(tmp_path, capsys, monkeypatch):
    src = FIXTURES / "full-occlusion.h5"
    # The guarded read of the input starts its fork server with a temporary folder: done
    # here first, so that only the output's temporary files are denied (run alone, the
    # test had denied the guard's too and got an internal error).
    read(src)

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied", str(tmp_path / ".x.tmp-1@h-abc"))

    monkeypatch.setattr(tempfile, "mkdtemp", denied)
    monkeypatch.setattr(tempfile, "mkstemp", denied)
    for fmt, out in (("mot", tmp_path / "mot"), ("otb", tmp_path / "otb")):
        code, _, err = run(capsys, "export", src, "--format", fmt, "-o", out)
        assert (
            code == 2 and err.strip() == f"scenegen: error: {out}: cannot write: Permission denied"
        )
    with pytest.raises(Exception, match="trk.txt: cannot write: Permission denied"):
        write_mot_tracker(tmp_path / "trk.txt", np.zeros((2, 1, 4)), [1])


def test_every_verb_help_has_a_description(capsys):
    parser = _parser()
    sub = next(a for a in parser._actions if a.dest == "verb")
    assert {"export", "evaluate", "track"} <= set(sub.choices)
    for name, verb in sub.choices.items():
        assert verb.description and "\n" not in verb.description.strip(), name
        code = main([name, "--help"])
        out = capsys.readouterr().out
        assert code == 0 and verb.description.split()[0] in out, name


def test_zero_size_boxes_round_trip_through_a_mot_file(tmp_path, capsys, occluded):
    # export wrote a zero-width box that evaluate then refused.
    seq = occluded
    boxes = np.load(FIXTURES / "expected" / "full-occlusion" / "kalman.npy").astype(np.float32)
    boxes[3, 0, 2] = 0.0
    ids = seq.entities.id[seq.initial_targets()]
    res, txt = tmp_path / "r.h5", tmp_path / "r.txt"
    write_result(res, TrackerResult("kalman", {}, 0, seq.name, ids, boxes))
    assert run(capsys, "export", res, "--format", "mot", "-o", txt)[0] == 0
    a = json.loads(run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", res, "--json")[1])
    b = json.loads(run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", txt, "--json")[1])
    assert a["overall"] == b["overall"] and a["overall"]["fp"] >= 1


def test_a_target_entering_late_gives_the_same_overall_row(tmp_path, capsys):
    # The tracker file's overall AUC counted the late target, the result file's did not.
    from scenegen.config import from_dict
    from scenegen.render.plan import generate

    cfg = {"width": 80, "height": 60, "n_frames": 10, "background": {"kind": "noise"},
           "entities": [
               {"name": "ball", "role": "target", "position": [20, 30],
                "appearance": {"shape": "ellipse", "size": [14, 14]}},
               {"name": "late", "role": "target", "position": [50, 30], "appear": 3,
                "depth": 1, "appearance": {"shape": "rect", "size": [10, 12]}}]}  # fmt: skip
    seq = generate(from_dict(cfg), seed=0)
    from scenegen.io import write

    write(tmp_path / "late.h5", seq)
    ids = seq.entities.id[seq.initial_targets()]
    boxes = seq.gt.box[:, seq.initial_targets()].astype(np.float32)
    write_result(tmp_path / "r.h5", TrackerResult("gt", {}, 0, seq.name, ids, boxes))
    code = run(capsys, "export", tmp_path / "r.h5", "--format", "mot", "-o", tmp_path / "r.txt")
    assert code[0] == 0
    a = json.loads(run(capsys, "evaluate", tmp_path / "late.h5", tmp_path / "r.h5", "--json")[1])
    b = json.loads(run(capsys, "evaluate", tmp_path / "late.h5", tmp_path / "r.txt", "--json")[1])
    assert len(b["targets"]) == 2 and len(a["targets"]) == 1
    assert a["overall"] == b["overall"] and a["overall"]["auc"] > 0.9


def test_visibility_at_the_threshold_does_not_count(tmp_path, capsys):
    from scenegen.io.mot import visible_enough

    stored = np.float32(192 / 240)  # 80 % visible, as a file stores it: 0.80000001
    assert not visible_enough(stored, 0.8) and visible_enough(stored, 0.79)


def test_targets_whose_names_give_one_folder_each_get_their_own(tmp_path, capsys):
    # "box a" and "box-a" both became scene_box-a: one target's files overwrote the other's.
    from scenegen.config import from_dict
    from scenegen.render.plan import generate

    cfg = {"name": "scene", "width": 80, "height": 60, "n_frames": 3,
           "background": {"kind": "noise"},
           "entities": [
               {"name": "box a", "role": "target", "position": [30, 30], "depth": 1,
                "appearance": {"shape": "rect", "size": [20, 12]}},
               {"name": "box-a", "role": "target", "position": [30, 10], "depth": 2,
                "appearance": {"shape": "rect", "size": [10, 8]}}]}  # fmt: skip
    seq = generate(from_dict(cfg), seed=0)
    names = export_benchmark(seq, tmp_path / "got", "got10k")
    ids = [int(i) for i in seq.entities.id]
    assert names == [f"scene_box-a-id{ids[0]}", f"scene_box-a-id{ids[1]}"]
    assert (tmp_path / "got" / "list.txt").read_text().split() == names


@pytest.mark.parametrize("where", ["same", "inside"])
def test_an_export_never_replaces_its_input(tmp_path, capsys, where):
    # Exporting into the folder holding the input deleted the input.
    folder = tmp_path / "work"
    folder.mkdir()
    src = folder / "x.h5"
    src.write_bytes((FIXTURES / "full-occlusion.h5").read_bytes())
    out = src if where == "same" else folder
    code, _, err = run(capsys, "export", src, "--format", "mot", "-o", out)
    assert code == 2 and "would replace" in err and f"the input {src}" in err
    assert src.read_bytes() == (FIXTURES / "full-occlusion.h5").read_bytes()


def test_export_options_the_export_would_ignore_are_refused(tmp_path, capsys):
    # They were ignored without a word (exit 0).
    src = FIXTURES / "full-occlusion.h5"
    res = tmp_path / "res.h5"
    assert run(capsys, "track", src, "--tracker", "kalman", "-o", res)[0] == 0
    for argv, msg in (
        ([src, "--format", "otb", "--gt-mode", "visible"], "--gt-mode does not apply to "
         "--format otb"),
        ([src, "--format", "vot", "--visibility-threshold", "0.5"], "--visibility-threshold "
         "does not apply to --format vot"),
        ([res, "--format", "mot", "--image-format", "jpg"], "--image-format does not apply "
         "to a tracker result's export"),
        ([res, "--format", "mot", "--gt-mode", "amodal"], "--gt-mode does not apply to a "
         "tracker result's export"),
    ):  # fmt: skip
        out = tmp_path / "out.txt"
        code, _, err = run(capsys, "export", *argv, "-o", out)
        assert code == 2 and msg in err and not out.exists(), err


@pytest.mark.parametrize("row", ["1,1_0,1,1,5,5", "1,1,1_0,1,5,5", "1_0,1,1,1,5,5"])
def test_an_underscore_in_a_number_is_refused(tmp_path, row):
    # Python's int() and float() read "1_0" as 10: a row with one was scored as that number.
    path = tmp_path / "t.txt"
    path.write_text(f"1,1,1,1,5,5\n{row}\n")
    with pytest.raises(DataError, match=r"t.txt:2: not a MOTChallenge row \('_' is not part"):
        read_mot_tracker(path, 20)


@pytest.mark.parametrize(
    ("row", "cell"),
    [("\uff11,1,1,1,5,5", "\uff11"), ("1,\u0661,1,1,5,5", "\u0661"),
     ("1,1,\u0967\u0966,1,5,5", "\u0967\u0966"), ("1,1,1,1,5,\u00b2", "\u00b2")],
)  # fmt: skip
def test_digits_of_other_scripts_are_refused(tmp_path, row, cell):
    # Python's int() and float() read fullwidth, Arabic-Indic or Devanagari digits: the
    # row was scored as frame 1, id 1, ... (no tool writes them).
    path = tmp_path / "t.txt"
    path.write_text(f"1,1,1,1,5,5\n{row}\n", encoding="utf-8")
    with pytest.raises(DataError) as err:
        read_mot_tracker(path, 20)
    assert f"t.txt:2: not a MOTChallenge row ({cell!r} is not a number (ASCII digits, " \
           "sign, point, exponent))" in str(err.value)  # fmt: skip
    path.write_text("1,1,1.5e1,-.5,+5.,5E+0,-1,-1,-1,-1\n2,2,nan,1,5,5\n")
    with pytest.raises(DataError, match=r"t.txt:2: .*a box value is not a finite number"):
        read_mot_tracker(path, 20)  # ASCII forms still read; nan refused as before


def test_a_byte_order_mark_and_windows_line_ends_are_read(tmp_path, capsys):
    # A file saved with a UTF-8 byte-order mark (Notepad, Excel's "CSV UTF-8", PowerShell)
    # was refused: "could not convert string to float: '\ufeff1'" on line 1.
    seq_file = FIXTURES / "full-occlusion.h5"
    rows = "1,1,2,3,4,5,0.9,-1,-1,-1\r\n2,1,3,3,4,5,0.9,-1,-1,-1\r\n\r\n"
    plain, bom = tmp_path / "plain.txt", tmp_path / "bom.txt"
    plain.write_bytes(rows.encode())
    bom.write_bytes(b"\xef\xbb\xbf" + rows.encode())
    ids, boxes = read_mot_tracker(bom, 14)
    assert ids.tolist() == [1] and boxes[1, 0].tolist() == [2.0, 2.0, 4.0, 5.0]
    code, out, err = run(capsys, "evaluate", seq_file, bom, "--json")
    assert code == 0, err
    assert json.loads(out)["overall"] == json.loads(run(capsys, "evaluate", seq_file, plain,
                                                        "--json")[1])["overall"]  # fmt: skip


def test_a_row_not_separated_by_commas_is_named_as_such(tmp_path, capsys):
    # np.savetxt's default: ten columns separated by spaces were "fewer than 6 columns".
    bad = tmp_path / "spaces.txt"
    bad.write_text("1 1 2 3 4 5 1 -1 -1 -1\n")
    code, _, err = run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", bad)
    assert code == 1 and err.strip() == (f"scenegen: error: {bad}:1: not a MOTChallenge row "
                                         "(fewer than 6 comma-separated columns): "
                                         "'1 1 2 3 4 5 1 -1 -1 -1'")  # fmt: skip


def test_evaluate_refuses_tracker_with_a_tracker_file(tmp_path, capsys):
    # --tracker was ignored without a word for a MOTChallenge file (exit 0, the report
    # named the file's stem).
    txt = tmp_path / "mine.txt"
    txt.write_text("1,1,2,3,4,5\n")
    code, out, err = run(capsys, "evaluate", FIXTURES / "full-occlusion.h5", txt,
                         "--tracker", "kalman")  # fmt: skip
    assert (code, out) == (2, "") and err.strip() == (
        f"scenegen: error: --tracker does not apply to a MOTChallenge tracker file ({txt}); "
        "leave it out"
    )


@pytest.mark.parametrize("row, cell", [("1,1,2,3,4,5 1,-1,-1,-1", "5 1"),
                                       ("1 0,1,2,3,4,5", "1 0"), ("1,1,2 0,3,4,5", "2 0")])
def test_a_space_within_a_value_is_refused(tmp_path, row, cell):
    # Every space was deleted before splitting: "5 1" (a comma left out) was read as a
    # height of 51 and "1 0" as frame 10, and the file was scored.
    path = tmp_path / "t.txt"
    path.write_text(f"1, 1, 1, 1, 5, 5\n{row}\n")  # spaces around values are fine
    with pytest.raises(DataError) as err:
        read_mot_tracker(path, 20)
    assert str(err.value) == (f"{path}:2: not a MOTChallenge row ({cell!r} is not a number "
                              f"(ASCII digits, sign, point, exponent)): {row!r}")  # fmt: skip


def test_a_visibility_threshold_in_amodal_mode_is_refused(tmp_path, capsys):
    # It was accepted, recorded in the report and ignored (amodal counts every frame).
    seq_file = FIXTURES / "full-occlusion.h5"
    txt = tmp_path / "mine.txt"
    txt.write_text("1,1,2,3,4,5\n")
    needle = "visibility_threshold (0.5) applies to gt_mode 'visible' only"
    for argv in (("evaluate", seq_file, txt, "--visibility-threshold", "0.5"),
                 ("export", seq_file, "--format", "mot", "--visibility-threshold", "0.5",
                  "-o", tmp_path / "mot")):  # fmt: skip
        code, _, err = run(capsys, *argv)
        assert code == 2 and err.count("\n") == 1 and needle in err, err
    assert not (tmp_path / "mot").exists()
    code, _, err = run(capsys, "evaluate", seq_file, txt, "--gt-mode", "visible",
                       "--visibility-threshold", "0.5")  # fmt: skip
    assert code == 0, err


# `make mutate MODULES=mot-io` (2026-12-03, every mutant of scenegen/io/mot.py): what the
# reader and writer do at their edges; a mutant of each survived the tests above.


def test_tracker_rows_are_read_at_their_edges(tmp_path):
    # A blank line in the middle, the first and last frames, frames and ids written as
    # floats below 2**53, ids of magnitude 2**63 - 1, zero and sub-pixel sizes, columns
    # past the sixth that are not numbers (only six are read); the rank is each row's
    # place among its frame's rows, -1 where a track has none.
    big, exact = 2**63 - 1, 2**53 - 1
    path = tmp_path / "t.txt"
    path.write_text(f"3,7,1.5,2.5,0,0.5,1,-1,-1,-1\n\n3,2,11,21,3,4,\n1.0,-{big},1,1,0.25,0\n"
                    f"1,{exact}.0,4,5,6,7\n5,{big},1,1,2,2\n")  # fmt: skip
    ids, boxes, rank = read_mot_tracker_rows(path, 5)
    assert ids.tolist() == [-big, 2, 7, exact, big]
    want = np.full((5, 5, 4), np.nan)
    want_rank = np.full((5, 5), -1)
    for t, c, r, box in ((2, 2, 0, [0.5, 1.5, 0, 0.5]), (2, 1, 1, [10, 20, 3, 4]),
                         (0, 0, 0, [0, 0, 0.25, 0]), (0, 3, 1, [3, 4, 6, 7]),
                         (4, 4, 0, [0, 0, 2, 2])):  # fmt: skip
        want[t, c], want_rank[t, c] = box, r
    np.testing.assert_array_equal(boxes, want)
    np.testing.assert_array_equal(rank, want_rank)


@pytest.mark.parametrize(("row", "why"), [
    ("1,1,1,1,5", "fewer than 6 comma-separated columns"),
    ("1.5,1,1,1,5,5", "frame and id must be integers"),
    ("1,9007199254740992.0,1,1,5,5", "9007199254740992.0 is written as a float beyond "
                                     "2**53, which is not exact; write the integer"),
    ("1,9223372036854775808,1,1,5,5", "id beyond ±9223372036854775807"),
    ("1,-9223372036854775808,1,1,5,5", "id beyond ±9223372036854775807"),
    ("1,1,1,1,-0.5,5", "width and height must not be negative"),
    ("1,1,1,1,5,-0.5", "width and height must not be negative"),
    ("1,1,1,1e308,5,1e308", "the box's right or bottom edge overflows to infinity"),
    ("1,1,abcdefghijklmnopqrstuvwxyz,1,5,5",
     "'abcdefghijklmnopqrst' is not a number (ASCII digits, sign, point, exponent)"),
    ("1,1,1,1,-5,5," + ",".join(["-1"] * 40), "width and height must not be negative"),
])  # fmt: skip
def test_tracker_rows_refused_at_their_edges(tmp_path, row, why):
    path = tmp_path / "t.txt"
    path.write_text(f"1,1,1,1,5,5\n{row}\n")
    with pytest.raises(DataError) as err:
        read_mot_tracker_rows(path, 5)
    # The message quotes the row's first 80 characters.
    assert str(err.value) == f"{path}:2: not a MOTChallenge row ({why}): {row[:80]!r}"


def test_tracker_frame_zero_is_refused(tmp_path):
    path = tmp_path / "t.txt"
    path.write_text("1,1,1,1,5,5\n0,1,1,1,5,5\n")
    with pytest.raises(DataError) as err:
        read_mot_tracker_rows(path, 5)
    assert str(err.value) == f"{path}:2: frame 0 is outside 1..5"


def test_tracker_file_written_row_by_row(tmp_path):
    # A track without a box in a frame skips its row only, not the frame's other tracks;
    # integral values are written without ".0"; no tracks is an empty file.
    path = tmp_path / "t.txt"
    boxes = np.array([[[np.nan, 0, 0, 0], [0.5, 1, 2, 3]], [[-1, 2.25, 0, 1e-3], [9, 9, 9, 9]]])
    assert write_mot_tracker(path, boxes, [4, 1]) == 3
    assert path.read_text() == ("1,1,1.5,2,2,3,1,-1,-1,-1\n2,4,0,3.25,0,0.001,1,-1,-1,-1\n"
                                "2,1,10,10,9,9,1,-1,-1,-1\n")  # fmt: skip
    ids, got = read_mot_tracker(path, 2)
    assert ids.tolist() == [1, 4]
    want = boxes[:, ::-1].copy()
    want[0, 1] = np.nan  # all four values, as the row is left out
    np.testing.assert_array_equal(got, want)
    assert write_mot_tracker(path, np.zeros((3, 0, 4)), []) == 0 and path.read_text() == ""
    with pytest.raises(ConfigError, match=r"^MOTChallenge track ids start at 1, got 0$"):
        write_mot_tracker(path, np.zeros((1, 2, 4)), [1, 0])
    with pytest.raises(ConfigError, match=r"^boxes \(1, 2, 4\) do not fit 1 track ids$"):
        write_mot_tracker(path, np.zeros((1, 2, 4)), [1])


def test_gt_keep_counts_the_rows_gt_rows_counts():
    # gt_keep is the (T, K) form of the conf column of gt_rows: present boxes (amodal, the
    # default), or present boxes visible above the threshold.
    seq = read(FIXTURES / "distractor-on-target.h5")
    present = np.asarray(seq.gt.present, dtype=bool)
    ids = [int(i) for i in seq.entities.id]
    targets = np.asarray(seq.entities.role).astype(str) == "target"
    np.testing.assert_array_equal(gt_keep(seq), present)
    for mode, threshold in (("amodal", 0.0), ("visible", 0.0), ("visible", 0.5)):
        keep = gt_keep(seq, mode, threshold)
        counted = np.zeros_like(present)
        for t in range(seq.n_frames):
            for row in gt_rows(seq, t, mode, threshold):
                cell = row.split(",")
                counted[t, ids.index(int(cell[1]))] = cell[6] == "1"
        np.testing.assert_array_equal(keep[:, targets], counted[:, targets])
    hidden = present & ~gt_keep(seq, "visible")
    assert hidden[:, targets].any() and not gt_keep(seq, "visible", 0.5)[~present].any()


def test_gt_rows_keep_the_targets_after_other_entities():
    # Entities in file order: an occluder, a distractor and a clutter entity before the
    # target. amodal writes the target's row only, visible the rows of every MOT class
    # (clutter has none).
    from scenegen.config import from_dict
    from scenegen.render.plan import generate

    ents = [{"name": role, "role": role, "position": [8 + 14 * i, 20], "depth": i,
             "appearance": {"shape": "rect", "size": [6, 6]}}
            for i, role in enumerate(("occluder", "distractor", "clutter", "target"))]
    seq = generate(from_dict({"width": 80, "height": 40, "n_frames": 2,
                              "background": {"kind": "noise"}, "entities": ents}), seed=0)
    ids = [int(i) for i in seq.entities.id]
    for mode, want in (("amodal", [(ids[3], 1, 1)]),
                       ("visible", [(ids[0], 0, 9), (ids[1], 0, 8), (ids[3], 1, 1)])):
        for t in range(2):
            got = [tuple(int(c) for c in (r.split(",")[1], r.split(",")[6], r.split(",")[7]))
                   for r in gt_rows(seq, t, mode)]
            assert got == want, (mode, t)
