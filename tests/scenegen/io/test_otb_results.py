"""Single-object result files (OTB, GOT-10k): read as the inverse of the export, scored
as the same boxes in a result file, refused in one line when they do not fit."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.errors import ConfigError, DataError
from scenegen.evaluation.evaluate import evaluate, evaluate_target, pick_target
from scenegen.io import TrackerResult, read, write_result
from scenegen.io.benchmarks import export_benchmark, read_benchmark_result
from scenegen.lab.run import run as run_tracker

FIXTURES = Path(__file__).resolve().parents[3] / "fixtures"
ORIGIN = {"otb": 1.0, "got10k": 0.0}
GT_NAME = {"otb": "groundtruth_rect.txt", "got10k": "groundtruth.txt"}


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def write_boxes(path: Path, boxes: np.ndarray, kind: str) -> None:
    """One ``x,y,w,h`` line per frame at full precision, ``0,0,0,0`` for no box."""
    lines = []
    for x, y, w, h in np.asarray(boxes, dtype=np.float64).tolist():
        if np.isnan(x):
            lines.append("0,0,0,0")
        else:
            o = ORIGIN[kind]
            lines.append(f"{x + o!r},{y + o!r},{w!r},{h!r}")
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("kind", ["otb", "got10k"])
@pytest.mark.parametrize("name", ["full-occlusion", "enter-leave", "shm-crossing-small"])
def test_an_exported_annotation_read_as_a_result_scores_perfectly(tmp_path, capsys, kind, name):
    # An OTB / GOT-10k result file (one x,y,w,h line per frame, one target) was refused:
    # "fewer than 6 comma-separated columns".
    src = FIXTURES / f"{name}.h5"
    seq = read(src)
    folders = export_benchmark(seq, tmp_path / "out", kind)
    entity_ids = [int(i) for i in seq.entities.id]
    for target in (int(seq.entities.id[k]) for k in seq.initial_targets()):
        k = entity_ids.index(target)
        folder = next(f for f in folders if f.endswith(str(seq.entities.name[k])))
        gt_file = tmp_path / "out" / folder / GT_NAME[kind]
        boxes = read_benchmark_result(gt_file, seq.n_frames, kind)
        present = np.asarray(seq.gt.present[:, k])
        np.testing.assert_array_equal(boxes[present], np.asarray(seq.gt.box[:, k])[present])
        assert np.isnan(boxes[~present]).all()  # 0,0,0,0 is no box
        code, out, err = run(capsys, "evaluate", src, gt_file, "--format", kind,
                             "--target", target, "--json")  # fmt: skip
        assert code == 0, err
        report = json.loads(out)
        (row,) = report["targets"]
        assert row["id"] == target and row["frames"] == int(present.sum())
        assert row["tracked"] == 100.0 and row["mean_iou"] == 1.0 and row["failure_frame"] == -1
        assert row["precision_20"] == 1.0 and row["auc"] == pytest.approx(20 / 21)  # IoU > 1: no
        overall = report["overall"]
        assert (overall["mota"], overall["idf1"], overall["hota"]) == (1.0, 1.0, 1.0)
        assert (overall["fp"], overall["fn"], overall["idsw"]) == (0, 0, 0)
        assert overall["mean_iou"] == 1.0 and overall["precision_20"] == 1.0


@pytest.mark.parametrize("kind", ["otb", "got10k"])
def test_a_tracker_result_scores_as_the_same_boxes_in_a_result_file(tmp_path, capsys, kind):
    src = FIXTURES / "full-occlusion.h5"
    seq = read(src)
    result = run_tracker(seq, "kalman").result
    boxes = np.asarray(result.boxes, dtype=np.float64).copy()
    boxes[5] = np.nan  # a frame without a box
    h5, txt = tmp_path / "kalman.h5", tmp_path / "kalman.txt"
    write_result(h5, TrackerResult("kalman", {}, 0, seq.name, result.target_ids,
                                   boxes.astype(np.float32)))  # fmt: skip
    write_boxes(txt, boxes[:, 0], kind)
    np.testing.assert_array_equal(read_benchmark_result(txt, seq.n_frames, kind), boxes[:, 0])
    for extra in ((), ("--gt-mode", "visible"), ("--otb-average", "frames")):
        code, a, err = run(capsys, "evaluate", src, h5, "--json", *extra)
        assert code == 0, err
        code, b, err = run(capsys, "evaluate", src, txt, "--format", kind, "--json", *extra)
        assert code == 0, err
        assert json.loads(a) == json.loads(b)  # the file's stem is the tracker name: kalman
    code, out, _ = run(capsys, "evaluate", src, txt, "--format", kind)
    assert code == 0 and "walker" in out and "HOTA" in out


def test_one_target_of_several_scores_as_its_row_of_the_full_result():
    seq = read(FIXTURES / "shm-crossing-small.h5")
    result = run_tracker(seq, "kalman").result
    full = evaluate(seq, result.boxes, result.target_ids, tracker="kalman")
    for m, target in enumerate(int(i) for i in result.target_ids):
        one = evaluate_target(seq, result.boxes[:, m], target, tracker="kalman")
        assert one.targets == (full.targets[m],)
        assert one.overall.mot == full.targets[m].mot  # the overall row is that target's
    with pytest.raises(ConfigError, match=r"has 2 targets present at frame 0 \(ids 1, 2\)"):
        evaluate_target(seq, result.boxes[:, 0])
    with pytest.raises(DataError, match=r"shape \(T, 4\)"):
        evaluate_target(seq, result.boxes, 1)
    bad = np.asarray(result.boxes[:, 0], dtype=np.float64).copy()
    bad[2, 2] = -1.0
    with pytest.raises(DataError, match="frame 2"):
        evaluate_target(seq, bad, 1)


def test_pick_target_defaults_to_the_only_target_at_frame_0():
    seq = read(FIXTURES / "enter-leave.h5")  # target 2 enters later
    assert pick_target(seq) == 1 and pick_target(seq, 1) == 1
    with pytest.raises(ConfigError) as err:
        pick_target(seq, 2, "--target")
    assert str(err.value) == ("--target 2 is not a target present at frame 0 of sequence "
                              "'enter-leave', where a single-object tracker starts (ids 1)")


@pytest.mark.parametrize("bad", [True, np.True_, 1.0, "1"])
def test_a_target_id_that_is_not_an_integer_is_refused_naming_target_id(bad):
    # True was taken as target 1 and scored; 1.0 likewise; "1" was "target_id 1 is not a
    # target ... (ids 1)".
    seq = read(FIXTURES / "enter-leave.h5")
    boxes = np.asarray(seq.gt.box[:, 0], dtype=np.float64)
    with pytest.raises(ConfigError,
                       match=rf"^target_id must be an integer entity id, got {bad!r}$"):
        evaluate_target(seq, boxes, bad)
    assert evaluate_target(seq, boxes, np.int64(1)).targets[0].id == 1


def test_separators_nan_rows_byte_order_mark_and_line_ends_are_read(tmp_path):
    path = tmp_path / "r.txt"
    rows = ["1,2,3,4", "1\t2\t3\t4", "1 2  3 4", " 1, 2 ,3\t,4 ", "nan,nan,nan,nan",
            "NaN\tNaN\tNaN\tNaN", "0,0,0,0", "0,0,3,4"]  # fmt: skip
    path.write_bytes(b"\xef\xbb\xbf" + "\r\n".join(rows).encode() + b"\r\n\r\n\n")
    boxes = read_benchmark_result(path, len(rows), "otb")
    np.testing.assert_array_equal(boxes[:4], [[0.0, 1.0, 3.0, 4.0]] * 4)  # 1-based
    assert np.isnan(boxes[4:7]).all()
    np.testing.assert_array_equal(boxes[7], [-1.0, -1.0, 3.0, 4.0])  # a box, not "no box"
    np.testing.assert_array_equal(read_benchmark_result(path, len(rows), "got10k")[0],
                                  [1.0, 2.0, 3.0, 4.0])  # fmt: skip
    with pytest.raises(ConfigError, match="result kind must be one of otb, got10k; got 'vot'"):
        read_benchmark_result(path, len(rows), "vot")


@pytest.mark.parametrize("line, why", [
    ("1,2,x,4", "'x' is not a number (ASCII digits, sign, point, exponent)"),
    ("1,２,3,4", "'２' is not a number (ASCII digits, sign, point, exponent)"),
    ("1,2,3", "3 values; a line is x, y, w, h separated by commas, tabs or spaces"),
    ("1,2,3,4,5", "5 values; a line is x, y, w, h separated by commas, tabs or spaces"),
    ("1,,3,4", "'' is not a number (ASCII digits, sign, point, exponent)"),
    ("1,2,-3,4", "width and height must not be negative"),
    ("1,2,3,-0.5", "width and height must not be negative"),
    ("nan,2,3,4", "a box value is not a finite number (four NaN: no box)"),
    ("1,inf,3,4", "a box value is not a finite number (four NaN: no box)"),
    ("1e308,2,1e308,4", "the box's right or bottom edge overflows to infinity"),
    ("1_0,2,3,4", "'_' is not part of a number"),
    ("", "an empty line; a frame without a box is 0,0,0,0"),
])  # fmt: skip
def test_a_bad_line_is_one_line_naming_file_and_line(tmp_path, capsys, line, why):
    src = FIXTURES / "kams-a-small.h5"  # 8 frames, one target
    path = tmp_path / "r.txt"
    path.write_text("\n".join(["11,12,5,5", line] + ["11,12,5,5"] * 6) + "\n", "utf-8")
    code, out, err = run(capsys, "evaluate", src, path, "--format", "otb")
    assert (code, out) == (1, "")
    assert err == f"scenegen: error: {path}:2: not a box line of OTB results ({why}): {line!r}\n"


@pytest.mark.parametrize("n", [0, 7, 9])
def test_a_file_of_another_length_is_refused_with_both_counts(tmp_path, capsys, n):
    src = FIXTURES / "kams-a-small.h5"
    path = tmp_path / "r.txt"
    path.write_text("11,12,5,5\n" * n)
    code, out, err = run(capsys, "evaluate", src, path, "--format", "got10k")
    assert (code, out) == (1, "")
    assert err == (
        f"scenegen: error: {path}: {n} lines, but the sequence has 8 frames "
        "(GOT-10k results have one line per frame, the first for frame 0)\n"
    )


def test_options_that_do_not_fit_are_usage_errors(tmp_path, capsys):
    several = FIXTURES / "shm-crossing-small.h5"
    txt = tmp_path / "r.txt"
    txt.write_text("11,12,5,5\n" * 8)
    h5 = tmp_path / "r.h5"
    seq = read(FIXTURES / "kams-a-small.h5")
    write_result(h5, TrackerResult("k", {}, 0, seq.name, seq.entities.id[seq.initial_targets()],
                                   np.asarray(seq.init_boxes(), np.float32)[None].repeat(8, 0)))
    cases = [
        ((several, txt, "--format", "otb"), "sequence 'shm-crossing-small' has 2 targets "
         "present at frame 0 (ids 1, 2): choose the one the result follows with --target"),
        ((several, txt, "--format", "otb", "--target", "7"), "--target 7 is not a target "
         "present at frame 0 of sequence 'shm-crossing-small', where a single-object tracker "
         "starts (ids 1, 2)"),
        ((several, txt, "--format", "otb", "--target", "1", "--tracker", "k"),
         f"--tracker does not apply to an OTB result file ({txt}); leave it out"),
        ((several, txt, "--target", "1"), "--target applies to a single-object result "
         "(--format otb or got10k); leave it out"),
        ((FIXTURES / "kams-a-small.h5", h5, "--format", "mot"), f"--format mot reads a text "
         f"result file, but {h5} is an HDF5 result file; leave --format out"),
    ]  # fmt: skip
    for argv, msg in cases:
        code, out, err = run(capsys, "evaluate", *argv)
        assert (code, out, err) == (2, "", f"scenegen: error: {msg}\n"), argv
    code, _, err = run(capsys, "evaluate", several, txt, "--format", "otb", "--target", "2")
    assert code == 0, err


def test_a_tracker_file_stays_the_default_and_a_box_file_gets_a_hint(tmp_path, capsys):
    src = FIXTURES / "kams-a-small.h5"
    txt = tmp_path / "r.txt"
    txt.write_text("11,12,5,5\n" * 8)
    code, _, err = run(capsys, "evaluate", src, txt)
    assert code == 1 and err == (
        f"scenegen: error: {txt}:1: not a MOTChallenge row (fewer than 6 comma-separated "
        "columns): '11,12,5,5'; a single-object result (x,y,w,h per frame)? read it with "
        "--format otb (1-based) or got10k (0-based)\n"
    )
    mot = tmp_path / "m.txt"
    mot.write_text("1,1,11,12,5,5,1,-1,-1,-1\n")
    a = run(capsys, "evaluate", src, mot, "--json")
    b = run(capsys, "evaluate", src, mot, "--json", "--format", "mot")
    assert a[0] == 0 and a == b
