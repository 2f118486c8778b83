"""Our CLEAR MOT, identity and HOTA scores against TrackEval's, on committed MOT files.

``tests/data/trackeval/`` holds scenegen's MOT exports of six fixtures (ground truth in
both modes, and the tracker files of our 12 trackers plus a ``scrambled`` one made to
count every kind of error and a ``tied`` one whose matchings tie, broken by the order of
each frame's rows in the file) and ``oracle.json``, TrackEval's numbers on them
(``tools/trackeval/make_inputs.py`` then ``tools/trackeval/make_oracle.py`` in a side
environment with numpy < 1.24). Tolerance 1e-9 (absolute): the numbers agree to the last
bit today; the tolerance only allows for summation order.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from scenegen.evaluation import evaluate, evaluate_tracks
from scenegen.evaluation.mot import combine
from scenegen.evaluation.report import MotSummary
from scenegen.io import read
from scenegen.io.mot import gt_rows, read_mot_tracker, read_mot_tracker_rows

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data" / "trackeval"
ORACLE = json.loads((DATA / "oracle.json").read_text())
TOL = 1e-9
FIELDS = {
    "HOTA": "hota", "DetA": "deta", "AssA": "assa", "LocA": "loca", "MOTA": "mota",
    "MOTP": "motp", "MODA": "moda", "CLR_TP": "tp", "CLR_FN": "fn", "CLR_FP": "fp",
    "IDSW": "idsw", "MT": "mt", "PT": "pt", "ML": "ml", "Frag": "frag", "IDF1": "idf1",
    "IDP": "idp", "IDR": "idr",
}  # fmt: skip
REGEN = "rerun tools/trackeval/make_inputs.py and make_oracle.py"


def _seq(name: str):
    return read(ROOT / "fixtures" / f"{name}.h5")


@pytest.mark.parametrize("mode", ["amodal", "visible"])
def test_committed_ground_truth_is_our_export(mode):
    for folder in sorted((DATA / "gt" / mode).iterdir()):
        seq = _seq(folder.name)
        rows = [r for t in range(seq.n_frames) for r in gt_rows(seq, t, mode)]
        text = (folder / "gt" / "gt.txt").read_text()
        assert text == "".join(r + "\n" for r in rows), f"{folder}: stale; {REGEN}"


@pytest.mark.parametrize("mode", ["amodal", "visible"])
def test_scores_equal_trackeval(mode):
    table = ORACLE["modes"][mode]
    assert len(table) == 14 and all(len(s) == 6 for s in table.values())
    cache = {}
    diffs = []
    for tracker, seqs in table.items():
        for name, ref in seqs.items():
            seq = cache.setdefault(name, _seq(name))
            path = DATA / "trackers" / tracker / f"{name}.txt"
            ids, boxes, rank = read_mot_tracker_rows(path, seq.n_frames)
            got = evaluate_tracks(seq, boxes, ids, gt_mode=mode, rank=rank).overall.mot
            for field, attr in FIELDS.items():
                d = abs(float(getattr(got, attr)) - ref[field])
                if not d <= TOL:
                    diffs.append(
                        f"{tracker} on {name}: {field} {getattr(got, attr)} vs {ref[field]}"
                    )
    assert not diffs, "differs from TrackEval:\n" + "\n".join(diffs[:20])


@pytest.mark.parametrize("mode", ["amodal", "visible"])
def test_combined_scores_equal_trackeval(mode):
    """mot.combine over a tracker's six sequences equals TrackEval's COMBINED_SEQ row (its
    summary over a benchmark), and differs from the mean of the sequences' values."""
    table, combined = ORACLE["modes"][mode], ORACLE["combined"][mode]
    assert sorted(combined) == sorted(table)
    cache = {}
    diffs, apart = [], 0
    for tracker, ref in combined.items():
        parts = []
        for name in sorted(table[tracker]):  # TrackEval adds in its sorted sequence list
            seq = cache.setdefault(name, _seq(name))
            path = DATA / "trackers" / tracker / f"{name}.txt"
            ids, boxes, rank = read_mot_tracker_rows(path, seq.n_frames)
            parts.append(evaluate_tracks(seq, boxes, ids, gt_mode=mode, rank=rank)
                         .overall.mot.scores)  # fmt: skip
        got = MotSummary.from_scores(combine(parts))
        for field, attr in FIELDS.items():
            if not abs(float(getattr(got, attr)) - ref[field]) <= TOL:
                diffs.append(f"{tracker}: {field} {getattr(got, attr)} vs {ref[field]}")
        mean_mota = np.mean([table[tracker][n]["MOTA"] for n in table[tracker]])
        apart += abs(mean_mota - ref["MOTA"]) > 1e-3
    assert not diffs, "differs from TrackEval's COMBINED_SEQ:\n" + "\n".join(diffs[:20])
    assert apart >= 5  # the combined row is not the mean: the comparison is sharp


def test_oracle_counts_every_kind_of_error():
    """The scrambled tracker makes the comparison sharp: switches, fragments, FP, FN, and
    distractor matches that only the visible mode drops."""
    s = ORACLE["modes"]["amodal"]["scrambled"]
    assert all(r["IDSW"] >= 1 and r["CLR_FP"] >= 1 and r["CLR_FN"] >= 1 for r in s.values())
    assert sum(r["Frag"] for r in s.values()) >= 5
    v = ORACLE["modes"]["visible"]["scrambled"]["distractor-on-target"]
    assert v["CLR_FP"] < s["distractor-on-target"]["CLR_FP"]


def test_the_tied_tracker_needs_the_file_s_row_order():
    """Without the rows' order (column order instead) some tied matchings go the other
    way, and CLEAR or HOTA differ from TrackEval's: the ``tied`` files test the order."""
    differ = 0
    for mode in ("amodal", "visible"):
        for name, ref in ORACLE["modes"][mode]["tied"].items():
            seq = _seq(name)
            ids, boxes = read_mot_tracker(DATA / "trackers" / "tied" / f"{name}.txt",
                                          seq.n_frames)  # fmt: skip
            got = evaluate_tracks(seq, boxes, ids, gt_mode=mode).overall.mot
            differ += any(abs(float(getattr(got, a)) - ref[f]) > TOL for f, a in FIELDS.items())
    assert differ >= 3


@pytest.mark.parametrize("name", ["shm-crossing-small", "full-occlusion", "enter-leave"])
def test_result_and_its_tracker_file_score_the_same(name):
    """``evaluate FILE.h5 RESULT.h5`` and ``evaluate FILE.h5 TRACKER.txt`` agree.

    (A result holds the targets present at frame 0; a tracker file's report has a row per
    target of the sequence, so single-target averages differ where targets enter later.)
    """
    seq = _seq(name)
    ids0 = seq.entities.id[seq.initial_targets()]
    for tracker in ("kalman", "meanshift", "dps"):
        boxes = np.load(ROOT / "fixtures" / "expected" / name / f"{tracker}.npy")
        rep_a = evaluate(seq, boxes, ids0, gt_mode="visible")
        a = rep_a.overall
        ids, txt = read_mot_tracker(DATA / "trackers" / tracker / f"{name}.txt", seq.n_frames)
        rep_b = evaluate_tracks(seq, txt, ids, gt_mode="visible")
        b = rep_b.overall
        for attr in ("mota", "motp", "idf1", "hota", "deta", "assa", "fp", "fn", "idsw"):
            assert getattr(a.mot, attr) == pytest.approx(getattr(b.mot, attr), abs=TOL)
        if len(rep_a.targets) == len(rep_b.targets):  # else rows include untracked targets
            assert a.auc == pytest.approx(b.auc, abs=TOL)


@pytest.mark.slow
def test_oracle_reproduces_with_trackeval(tmp_path):
    """Rerun TrackEval on the committed files (needs its side environment: set
    TRACKEVAL_PYTHON to a Python with trackeval and numpy < 1.24)."""
    import os
    import subprocess

    python = os.environ.get("TRACKEVAL_PYTHON")
    if not python:
        pytest.skip("TRACKEVAL_PYTHON is not set (TrackEval's side environment)")
    out = tmp_path / "oracle.json"
    script = ROOT / "tools" / "trackeval" / "make_oracle.py"
    subprocess.run([python, str(script), "--out", str(out)], check=True, capture_output=True)
    assert json.loads(out.read_text())["modes"] == ORACLE["modes"]
