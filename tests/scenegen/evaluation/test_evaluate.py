"""scenegen.evaluation.evaluate and the ``evaluate`` verb on a small generated sequence."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pytest

import scenegen
from scenegen.cli import evaluate as cli_evaluate
from scenegen.errors import DataError
from scenegen.evaluation.evaluate import evaluate, format_table, to_json
from scenegen.io import TrackerResult, write_result


def _target(name, x, y, depth):
    return {
        "name": name,
        "role": "target",
        "position": [x, y],
        "appearance": {"shape": "rect", "size": [12, 12]},
        "motion": {
            "x": {"sigma": 1, "boundary": "reflect"},
            "y": {"sigma": 1, "boundary": "reflect"},
        },
        "depth": [[0, depth]],
    }


@pytest.fixture(scope="module")
def seq():
    cfg = {
        "name": "two",
        "width": 80,
        "height": 60,
        "n_frames": 12,
        "entities": [_target("a", 30, 30, 0), _target("b", 36, 32, 1)],
    }
    return scenegen.generate(cfg, seed=3)


def test_perfect_result_scores_perfectly(seq):
    gt = np.asarray(seq.gt.box[:, seq.target_indices()], dtype=np.float64)
    rep = evaluate(seq, gt, seq.target_ids(), tracker="oracle")
    assert rep.n_frames == 12 and rep.tracker == "oracle"
    for t in rep.targets:
        assert t.tracked == 100.0 and t.success and t.recovered
        assert t.precision == pytest.approx(100.0) and t.mean_centre_error == 0.0
        assert t.failure_frame == -1
        assert t.mot.mota == 1.0 and t.mot.hota == pytest.approx(1.0) and t.track_id == t.id
    o = rep.overall
    assert o.mot.mota == 1.0 and o.mot.idf1 == 1.0 and o.auc == pytest.approx(20 / 21)
    assert (o.mot.fp, o.mot.fn, o.mot.idsw, o.mot.mt, o.mot.ml) == (0, 0, 0, 2, 0)
    text = format_table(rep)
    assert "oracle" in text and "MOTA 1.000" in text and "HOTA 1.000" in text
    doc = json.loads(to_json(rep))
    assert doc == rep.to_dict()
    keys = {"mota", "motp", "idf1", "idp", "idr", "fp", "fn", "idsw", "hota", "deta", "assa",
            "auc", "precision_20"}  # fmt: skip
    assert keys <= set(doc["overall"]) and all(keys <= set(t) for t in doc["targets"])


def test_lost_target_is_reported(seq):
    est = np.array(seq.gt.box[:, seq.target_indices()], dtype=np.float64)
    est[4:, 1, :2] = [0.0, 0.0]  # target b jumps to the corner and stays there
    est[4:, 1, 2:] = [5.0, 5.0]
    rep = evaluate(seq, est, seq.target_ids(), persist=3)
    b = rep.targets[1]
    assert b.success is False and b.recovered is False
    assert b.tracked == pytest.approx(100 * 4 / 12)
    assert b.failure_frame == 4
    assert rep.overall.mot.mota < 1.0
    assert (b.mot.fp, b.mot.fn) == (8, 8) and rep.overall.mot.fn == 8


def test_depth_order_accuracy_of_true_ordering(seq):
    idx = seq.target_indices()
    depth = np.asarray(seq.gt.depth)[:, idx]
    orderings = np.array([[0, 1], [1, 0]])
    truth = (depth[:, 0] > depth[:, 1]).astype(int)  # row 1 when b is nearer
    prob = np.eye(2)[truth]
    est = seq.gt.box[:, idx]
    rep = evaluate(seq, est, seq.target_ids(), order_prob=prob, orderings=orderings)
    assert rep.overall.depth_order_accuracy == 100.0
    assert "depth_order_accuracy" in rep.to_dict()["overall"]
    rep = evaluate(seq, est, seq.target_ids(), order_prob=prob[:, ::-1], orderings=orderings)
    assert rep.overall.depth_order_accuracy == 0.0


def test_mismatches_raise_data_error_naming_them(seq):
    idx = seq.target_indices()
    est = np.asarray(seq.gt.box[:, idx], dtype=np.float64)
    with pytest.raises(DataError, match="11 frames but sequence 'two' has 12"):
        evaluate(seq, est[:11], seq.target_ids())
    with pytest.raises(DataError, match="tracks 1 targets but sequence 'two' has 2"):
        evaluate(seq, est[:, :1], seq.target_ids()[:1])
    with pytest.raises(DataError, match="target id 99"):
        evaluate(seq, est, [seq.target_ids()[0], 99])


def _cli(argv):
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers()
    cli_evaluate.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


def test_evaluate_verb_table_json_and_mismatch(seq, tmp_path, capsys):
    idx = seq.target_indices()
    data = tmp_path / "seq.h5"
    scenegen.write(data, seq)
    boxes = np.asarray(seq.gt.box[:, idx], dtype=np.float32)
    good = tmp_path / "good.h5"
    write_result(good, TrackerResult("kalman", {}, 0, seq.name, seq.target_ids(), boxes))
    assert _cli(["evaluate", str(data), str(good)]) == 0
    assert "kalman" in capsys.readouterr().out
    assert _cli(["evaluate", str(data), str(good), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["overall"]["mota"] == 1.0
    bad = tmp_path / "bad.h5"
    write_result(bad, TrackerResult("kalman", {}, 0, seq.name, seq.target_ids(), boxes[:5]))
    with pytest.raises(DataError, match="5 frames but sequence 'two' has 12") as err:
        _cli(["evaluate", str(data), str(bad)])
    assert "bad.h5" in str(err.value)


def test_cli_exit_codes(seq, tmp_path, capsys):
    from scenegen.cli import main

    data = tmp_path / "seq.h5"
    scenegen.write(data, seq)
    boxes = np.asarray(seq.gt.box[:, seq.target_indices()], dtype=np.float32)
    res = tmp_path / "res.h5"
    write_result(res, TrackerResult("kalman", {}, 0, seq.name, seq.target_ids()[:1], boxes[:, :1]))
    assert main(["evaluate", str(data), str(res)]) == 1
    err = capsys.readouterr().err
    assert "tracks 1 targets but sequence 'two' has 2" in err and "Traceback" not in err
    write_result(res, TrackerResult("kalman", {}, 0, seq.name, seq.target_ids(), boxes))
    assert main(["evaluate", str(data), str(res), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["overall"]["idf1"] == 1.0


def test_tracks_with_foreign_ids_pair_by_identity_and_otb_average(seq):
    from scenegen.evaluation import evaluate_tracks

    gt = np.asarray(seq.gt.box[:, seq.target_indices()], dtype=np.float64)
    est = gt[:, ::-1].copy()  # column 0 follows target b, column 1 target a
    est[6:, 0] = np.nan  # track 70 (on b) stops half way
    rep = evaluate_tracks(seq, est, [70, 80], tracker="other")
    assert [(t.id, t.track_id) for t in rep.targets] == [(1, 80), (2, 70)]
    assert rep.targets[0].mot.mota == 1.0 and rep.targets[1].mot.fn == 6
    assert rep.targets[1].auc == pytest.approx(0.5 * 20 / 21)
    assert rep.overall.auc == pytest.approx(np.mean([t.auc for t in rep.targets]))
    pooled = evaluate_tracks(seq, est, [70, 80], otb_average="frames").overall
    from scenegen.evaluation.metrics import otb_curves

    assert pooled.otb_average == "frames"
    assert pooled.auc == otb_curves(est[:, ::-1], gt).auc
    with pytest.raises(scenegen.errors.ConfigError, match="otb_average"):
        evaluate_tracks(seq, est, [70, 80], otb_average="mean")
    with pytest.raises(DataError, match="tracks span 5 frames"):
        evaluate_tracks(seq, est[:5], [70, 80])


def test_repeated_target_ids_are_refused_everywhere(seq, tmp_path):
    # A result naming target 1 twice was "valid" and scored target 1 twice (target 2 never).
    import h5py

    from scenegen.io.validate import check_file

    est = np.asarray(seq.gt.box[:, seq.target_indices()], dtype=np.float64)
    dup = np.array([1, 1])
    with pytest.raises(DataError, match="target_ids repeat id 1"):
        evaluate(seq, est, dup)
    # Tracks too: two columns of track 1 were scored as two tracks, each paired with a
    # target (both rows said track 1), where TrackEval sees one track.
    from scenegen.evaluation import evaluate_tracks

    with pytest.raises(DataError, match=r"^track_ids repeat id 1 \(one column per track: "
                                        r"merge its boxes\)$"):  # fmt: skip
        evaluate_tracks(seq, est, dup)
    bad = TrackerResult("kalman", {}, 0, seq.name, dup, est.astype(np.float32))
    assert bad.problems() == ["target_ids repeat id 1 (each target is tracked once)"]
    path = tmp_path / "res.h5"
    write_result(path, TrackerResult("kalman", {}, 0, seq.name, seq.target_ids(),
                                     est.astype(np.float32)))  # fmt: skip
    with h5py.File(path, "r+") as f:
        f["results/kalman/target_ids"][1] = 1
    assert any("target_ids repeat id 1" in p for p in check_file(path))


def test_fractional_ids_and_broken_boxes_are_refused_from_python(seq):
    # 7.6 was truncated to 7 and scored; a negative width, which the file readers refuse,
    # was scored from Python.
    from scenegen.evaluation import evaluate_tracks

    est = np.asarray(seq.gt.box[:, seq.target_indices()], dtype=np.float64)
    ids = seq.target_ids().astype(np.float64)
    for call, name in ((evaluate, "target_ids"), (evaluate_tracks, "track_ids")):
        assert call(seq, est, ids).targets  # integral floats are ids
        bools = np.ones(ids.size, dtype=bool)  # True was scored as id 1
        for bad in (ids + 0.6, np.where(np.arange(ids.size) == 0, np.nan, ids), bools):
            with pytest.raises(DataError, match=rf"^{name} must be integers, got "):
                call(seq, est, bad)
        broken = est.copy()
        broken[3, 1, 2] = -2.0
        with pytest.raises(DataError, match=r"boxes at frame 3, column 1: .* is neither a box"):
            call(seq, broken, ids)
        broken[3, 1] = [np.nan, 1.0, 2.0, 3.0]  # partly NaN
        with pytest.raises(DataError, match=r"boxes at frame 3, column 1: "):
            call(seq, broken, ids)


def test_frame_count_options_are_config_errors(seq):
    # persist=2.5 scored every run as never failing; persist=0 and recover_frames=0 were
    # metrics' ValueError, recover_frames=1.5 numpy's TypeError.
    from scenegen.evaluation.evaluate import evaluate_target, evaluate_tracks

    est = np.asarray(seq.gt.box[:, seq.target_indices()], dtype=np.float64)
    ids = seq.target_ids()
    calls = (
        lambda **kw: evaluate(seq, est, ids, **kw),
        lambda **kw: evaluate_tracks(seq, est, ids, **kw),
        lambda **kw: evaluate_target(seq, est[:, 0], int(ids[0]), **kw),
    )
    for call in calls:
        for option in ("persist", "recover_frames"):
            for bad in (0, 2.5, True):
                with pytest.raises(scenegen.errors.ConfigError,
                                   match=rf"^{option} must be an integer >= 1, got {bad!r}$"):
                    call(**{option: bad})


def test_failure_frame_is_a_frame_of_the_sequence():
    from scenegen.evaluation import evaluate_tracks

    cfg = {"name": "late", "width": 80, "height": 60, "n_frames": 30,
           "entities": [_target("a", 30, 30, 0), {**_target("b", 50, 30, 1), "appear": 4}]}
    late = scenegen.generate(cfg, seed=1)
    gt = np.asarray(late.gt.box[:, late.target_indices()], dtype=np.float64)
    est = gt.copy()
    est[:, 1] = np.nan  # target b (present from frame 4) is never tracked
    rep = evaluate_tracks(late, est, late.target_ids())
    assert rep.targets[1].failure_frame == 4  # its first frame, not its first scored index
    assert rep.targets[0].failure_frame == -1


def test_visible_mode_pairs_targets_on_the_scored_frames():
    # Track 100 follows the walker only while it is hidden (ignored frames), track 200
    # while it is visible: the walker pairs with 200, as the IDF1 matching does (it was
    # paired on every frame, ignored ones included, so with 100, scoring IoU 0).
    from scenegen.evaluation import evaluate_tracks
    from scenegen.io.mot import visible_enough

    cfg = {"name": "hide", "width": 80, "height": 40, "n_frames": 14, "entities": [
        {"name": "walker", "role": "target", "position": [10, 20], "depth": [[0, 1]],
         "appearance": {"shape": "rect", "size": [10, 10]},
         "motion": {"x": {"sigma": 0, "boundary": "free"},
                    "y": {"sigma": 0, "boundary": "free"}, "velocity": [3, 0]}},
        {"name": "wall", "role": "occluder", "position": [44, 20], "depth": [[0, 0]],
         "appearance": {"shape": "rect", "size": [40, 30]}}]}  # fmt: skip
    s = scenegen.generate(cfg, seed=0)
    gt = np.asarray(s.gt.box[:, 0], dtype=np.float64)
    seen = visible_enough(s.gt.visibility[:, 0], 0.6)
    assert 0 < seen.sum() < len(seen) / 2  # hidden longer than seen
    est = np.stack([np.where(seen[:, None], gt, np.nan), np.where(seen[:, None], np.nan, gt)],
                   axis=1)  # fmt: skip
    rep = evaluate_tracks(s, est, [200, 100], gt_mode="visible", visibility_threshold=0.6)
    assert rep.targets[0].track_id == 200 and rep.targets[0].mean_iou == 1.0
