"""Score the committed MOTChallenge files with TrackEval and write ``oracle.json``.

TrackEval (github.com/JonathonLuiten/TrackEval) needs numpy < 1.24 (it uses ``np.float``
and ``np.int``), so it runs in a side environment, not in the project's::

    python3 -m venv /tmp/trackeval-venv
    /tmp/trackeval-venv/bin/pip install 'numpy<1.24' scipy
    /tmp/trackeval-venv/bin/pip install /path/to/a/checkout/of/TrackEval
    /tmp/trackeval-venv/bin/python tools/trackeval/make_oracle.py [--commit SHA] [--out oracle.json]

The inputs are made by ``tools/trackeval/make_inputs.py`` (scenegen's own exports of the
fixtures). Every tracker is scored on every sequence under both ground-truth modes with
TrackEval's MOTChallenge dataset (``BENCHMARK=MOT17``, preprocessing on: rows with
conf 0 are ignored and tracker boxes matched to distractors dropped) and its HOTA, CLEAR
and Identity metrics. ``oracle.json`` holds, per mode, tracker and sequence, TrackEval's
per-sequence numbers (full float precision), and under ``combined``, per mode and
tracker, its ``COMBINED_SEQ`` row (all the sequences taken as one), with the TrackEval
commit used.
This script does not import scenegen.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import trackeval

HERE = Path(__file__).resolve().parent
DATA = HERE.parents[1] / "tests" / "data" / "trackeval"
FIELDS = {
    "HOTA": ["HOTA", "DetA", "AssA", "LocA", "DetRe", "DetPr", "AssRe", "AssPr"],
    "CLEAR": [
        "MOTA",
        "MOTP",
        "MODA",
        "CLR_TP",
        "CLR_FN",
        "CLR_FP",
        "IDSW",
        "MT",
        "PT",
        "ML",
        "Frag",
    ],
    "Identity": ["IDF1", "IDP", "IDR", "IDTP", "IDFN", "IDFP"],
}


def _value(metric: str, res: dict, field: str) -> float:
    v = res[metric][field]
    if metric == "HOTA" and np.ndim(v) == 1:  # per-alpha arrays: TrackEval reports the mean
        return float(np.mean(v))
    return float(v)


def score(mode: str, trackers: list[str], seqs: list[str]) -> tuple[dict, dict]:
    with tempfile.TemporaryDirectory() as out:
        eval_cfg = trackeval.Evaluator.get_default_eval_config()
        eval_cfg.update(
            USE_PARALLEL=False,
            PRINT_RESULTS=False,
            PRINT_CONFIG=False,
            OUTPUT_SUMMARY=False,
            OUTPUT_DETAILED=False,
            PLOT_CURVES=False,
            TIME_PROGRESS=False,
            OUTPUT_EMPTY_CLASSES=False,
        )
        data_cfg = trackeval.datasets.MotChallenge2DBox.get_default_dataset_config()
        data_cfg.update(
            GT_FOLDER=str(DATA / "gt" / mode),
            TRACKERS_FOLDER=str(DATA / "trackers"),
            OUTPUT_FOLDER=out,
            TRACKERS_TO_EVAL=trackers,
            BENCHMARK="MOT17",
            SKIP_SPLIT_FOL=True,
            TRACKER_SUB_FOLDER="",
            SEQ_INFO={s: None for s in seqs},
            DO_PREPROC=True,
            PRINT_CONFIG=False,
        )
        metrics = [
            trackeval.metrics.HOTA(),
            trackeval.metrics.CLEAR({"PRINT_CONFIG": False}),
            trackeval.metrics.Identity({"PRINT_CONFIG": False}),
        ]
        evaluator = trackeval.Evaluator(eval_cfg)
        res, msg = evaluator.evaluate([trackeval.datasets.MotChallenge2DBox(data_cfg)], metrics)
    out_res = res["MotChallenge2DBox"]
    table: dict = {}
    combined: dict = {}
    for tracker in trackers:
        if msg["MotChallenge2DBox"][tracker] != "Success":
            raise SystemExit(f"TrackEval failed on {tracker}: {msg['MotChallenge2DBox'][tracker]}")
        for seq in seqs:
            r = out_res[tracker][seq]["pedestrian"]
            table.setdefault(tracker, {})[seq] = {
                f: _value(m, r, f) for m, fields in FIELDS.items() for f in fields
            }
        # TrackEval's scores of all the sequences taken as one (its summary row).
        r = out_res[tracker]["COMBINED_SEQ"]["pedestrian"]
        combined[tracker] = {f: _value(m, r, f) for m, fields in FIELDS.items() for f in fields}
    return table, combined


def _trackeval_commit() -> str:
    path = Path(trackeval.__file__).resolve().parents[1]
    try:
        return subprocess.run(
            ["git", "-C", str(path), "rev-parse", "HEAD"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return getattr(trackeval, "__version__", "unknown")


def main() -> None:
    parser = argparse.ArgumentParser(description="Score the committed MOT files with TrackEval.")
    parser.add_argument("--commit", help="TrackEval commit installed (when pip copied it)")
    parser.add_argument("--out", type=Path, default=DATA / "oracle.json", help="output file")
    args = parser.parse_args()
    trackers = sorted(p.name for p in (DATA / "trackers").iterdir() if p.is_dir())
    oracle: dict = {
        "tool": "TrackEval",
        "trackeval": args.commit or _trackeval_commit(),
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "modes": {},
        "combined": {},
    }
    for mode in ("amodal", "visible"):
        seqs = sorted(p.name for p in (DATA / "gt" / mode).iterdir() if p.is_dir())
        oracle["modes"][mode], oracle["combined"][mode] = score(mode, trackers, seqs)
    args.out.write_text(json.dumps(oracle, indent=1, sort_keys=True) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
