"""Our OTB success and precision scores against the got10k toolkit's, on committed files.

``tests/data/otb/oracle.json`` holds, for the TrackEval oracle's MOT files
(``tests/data/trackeval/``: amodal ground truth of six fixtures, the files of our 12
trackers, ``scrambled`` and ``tied``), the success curve (21 IoU thresholds), precision
curve (51 pixel thresholds), AUC and P@20 of got10k 0.1.3's ``ExperimentOTB``
(``_calc_metrics``, ``_calc_curves``) for every (tracker, sequence, target, track) case,
and pysot-toolkit's OPE as a second opinion (``tools/otb/make_oracle.py``, run in a side
environment). ``scored`` is the reference under scenegen's frame conventions (frames with
ground truth only, the tracker's own frame 0); ``got10k``, ``frame0``, ``absent`` and
``pysot_all`` are the tools' own conventions, whose effects docs/evaluation.md states.
Tolerance 1e-12 (absolute): the curves are fractions of frames, and agree exactly today.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from scenegen.evaluation import evaluate, evaluate_tracks, metrics
from scenegen.io import read
from scenegen.io.mot import read_mot_tracker, read_mot_tracker_rows

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data" / "trackeval"
ORACLE = json.loads((ROOT / "tests" / "data" / "otb" / "oracle.json").read_text())
CASES = ORACLE["cases"]
TOL = 1e-12
OURS = ("annealed", "condensation", "dps", "hybrid", "joint-pf", "kalman", "kams",
        "meanshift", "ps", "shm", "shm-fast", "sok")  # fmt: skip


def _seq(name: str):
    return read(ROOT / "fixtures" / f"{name}.h5")


def _gt(seq, target: int) -> np.ndarray:
    """Target ``target``'s amodal boxes (T, 4), NaN where it is not in the scene."""
    k = int(np.flatnonzero(np.asarray(seq.entities.id) == target)[0])
    present = np.asarray(seq.gt.present, dtype=bool)[:, k]
    return np.where(present[:, None], np.asarray(seq.gt.box, dtype=np.float64)[:, k], np.nan)


def _all_cases():
    for tracker, seqs in CASES.items():
        for name, targets in seqs.items():
            for target, tracks in targets.items():
                for track, ref in tracks.items():
                    yield tracker, name, int(target), track, ref


def test_oracle_covers_every_case():
    """Every tracker and sequence of the TrackEval files, every target against every
    track of the file and against none; got10k's version is recorded."""
    assert ORACLE["got10k"] == "0.1.3" and ORACLE["pysot_toolkit"]
    assert sorted(CASES) == sorted(p.name for p in (DATA / "trackers").iterdir())
    assert all(len(s) == 6 for s in CASES.values())
    assert sum(1 for _ in _all_cases()) == 431


def test_otb_curves_equal_got10k():
    """``metrics.otb_curves`` on scenegen's reading of the files: both curves, the AUC
    and P@20 of every case equal got10k's under the mapped conventions."""
    cache: dict = {}
    diffs, n = [], 0
    for tracker, name, target, track, ref in _all_cases():
        seq = cache.setdefault(name, _seq(name))
        key = (tracker, name)
        if key not in cache:
            cache[key] = read_mot_tracker(DATA / "trackers" / tracker / f"{name}.txt",
                                          seq.n_frames)  # fmt: skip
        ids, boxes = cache[key]
        gt = _gt(seq, target)
        est = (np.full_like(gt, np.nan) if track == "none"
               else boxes[:, list(ids).index(int(track))])  # fmt: skip
        got = metrics.otb_curves(est, gt)
        r = ref["scored"]
        d = max(
            float(np.max(np.abs(got.success - np.asarray(r["success"])))),
            float(np.max(np.abs(got.precision - np.asarray(r["precision"])))),
            abs(got.auc - r["auc"]),
            abs(got.precision_20 - r["p20"]),
        )
        n += 1
        if not d <= TOL:
            diffs.append(f"{tracker} on {name}, target {target}, track {track}: {d}")
    assert n == 431
    assert not diffs, "differs from got10k:\n" + "\n".join(diffs[:20])


def _ref(tracker: str, name: str, target_id: int, track_id: int | None) -> dict:
    return CASES[tracker][name][str(target_id)]["none" if track_id is None else str(track_id)]


@pytest.mark.parametrize("otb_average", ["sequence", "frames"])
def test_evaluate_reports_got10k_scores(otb_average):
    """``evaluate FILE.h5 TRACKER.txt`` (amodal): each target row's AUC and P@20 are
    got10k's on the track it was paired with; the overall row is their mean over the
    targets present at frame 0 (got10k's mean over sequences), or with ``frames`` the
    frame-weighted mean (got10k's curves on the pooled frames)."""
    diffs = []
    for tracker, seqs in CASES.items():
        for name in seqs:
            seq = _seq(name)
            path = DATA / "trackers" / tracker / f"{name}.txt"
            ids, boxes, rank = read_mot_tracker_rows(path, seq.n_frames)
            rep = evaluate_tracks(seq, boxes, ids, rank=rank, otb_average=otb_average)
            initial = set(np.asarray(seq.entities.id)[seq.initial_targets()].tolist())
            refs = []
            for row in rep.targets:
                ref = _ref(tracker, name, row.id, row.track_id)
                if abs(row.auc - ref["scored"]["auc"]) > TOL:
                    diffs.append(f"{tracker} {name} {row.id}: AUC {row.auc} vs {ref}")
                if abs(row.precision_20 - ref["scored"]["p20"]) > TOL:
                    diffs.append(f"{tracker} {name} {row.id}: P@20 {row.precision_20}")
                if row.id in initial:
                    refs.append(ref)
            w = (np.ones(len(refs)) if otb_average == "sequence"
                 else np.array([r["frames"] for r in refs], dtype=float))  # fmt: skip
            auc = float(np.average([r["scored"]["auc"] for r in refs], weights=w))
            p20 = float(np.average([r["scored"]["p20"] for r in refs], weights=w))
            if abs(rep.overall.auc - auc) > TOL or abs(rep.overall.precision_20 - p20) > TOL:
                diffs.append(f"{tracker} {name} overall: {rep.overall.auc} vs {auc}")
    assert not diffs, "differs from got10k:\n" + "\n".join(diffs[:20])


@pytest.mark.parametrize("tracker", ["kalman", "meanshift", "dps"])
def test_result_file_reports_got10k_scores(tracker):
    """``evaluate FILE.h5 RESULT.h5``: the fixture's expected boxes of our tracker score
    got10k's numbers on the track of the target's own id."""
    for name in CASES[tracker]:
        seq = _seq(name)
        ids0 = np.asarray(seq.entities.id)[seq.initial_targets()]
        boxes = np.load(ROOT / "fixtures" / "expected" / name / f"{tracker}.npy")
        for row in evaluate(seq, boxes, ids0).targets:
            ref = _ref(tracker, name, row.id, row.id)["scored"]
            assert row.auc == pytest.approx(ref["auc"], abs=TOL), (name, row.id)
            assert row.precision_20 == pytest.approx(ref["p20"], abs=TOL), (name, row.id)


def _shift(variant: str, cases) -> tuple[int, float, int, float]:
    """Cases whose AUC / P@20 move from ``scored`` under ``variant``, and the largest move."""
    da = [c[variant]["auc"] - c["scored"]["auc"] for c in cases]
    dp = [c[variant]["p20"] - c["scored"]["p20"] for c in cases]
    big_a = max(da, key=abs)
    big_p = max(dp, key=abs)
    return (sum(abs(d) > TOL for d in da), round(big_a, 3),
            sum(abs(d) > TOL for d in dp), round(big_p, 3))  # fmt: skip


def test_convention_effects_are_the_documented_ones():
    """The numbers docs/evaluation.md ("OTB scores against got10k and pysot") quotes."""
    own = [c for tr, _, t, k, c in _all_cases() if tr in OURS and k == str(t)]
    every = [c for *_, c in _all_cases()]
    assert len(own) == 108
    # got10k's boxes[0] = anno[0]: nothing on our trackers (they report the initial box)
    assert _shift("frame0", own) == (0, 0.0, 0, 0.0)
    assert _shift("frame0", every)[0] == 290 and _shift("frame0", every)[1] == 0.119
    # absent frames counted as failures (0,0,0,0 rows): the targets that leave the scene
    assert _shift("absent", own) == (12, -0.221, 12, -0.25)
    assert _shift("got10k", every)[:2] == (309, -0.221)
    # pysot on the frames we score: the same except ground-truth boxes with a 1-based
    # coordinate <= 0 (a target entering at the left edge), which it masks as failures
    pysot = [{"scored": c["scored"], "p": c["scored"]["pysot"]} for c in every]
    assert _shift("p", pysot) == (3, -0.081, 0, 0.0)
    # pysot on every frame: absent rows fail the success curve but pass precision
    assert _shift("pysot_all", own) == (12, -0.221, 2, 0.083)


@pytest.mark.slow
def test_oracle_reproduces_with_got10k(tmp_path):
    """Rerun got10k (and pysot) on the committed files (needs the side environment: set
    OTB_PYTHON to a Python with got10k 0.1.3 and OTB_PYSOT to a pysot-toolkit checkout)."""
    import os
    import subprocess

    python, pysot = os.environ.get("OTB_PYTHON"), os.environ.get("OTB_PYSOT")
    if not python or not pysot:
        pytest.skip("OTB_PYTHON / OTB_PYSOT are not set (got10k's side environment)")
    out = tmp_path / "oracle.json"
    script = ROOT / "tools" / "otb" / "make_oracle.py"
    cmd = [python, str(script), "--pysot", pysot, "--out", str(out)]
    subprocess.run(cmd, check=True, capture_output=True)
    assert json.loads(out.read_text())["cases"] == CASES
