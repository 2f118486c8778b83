"""Score the committed kept tracks of small benchmarks with TrackEval: ``oracle.json``.

Runs in TrackEval's side environment (see ``make_oracle.py``), after
``tools/trackeval/make_benchmark_inputs.py``::

    /tmp/trackeval-venv/bin/python tools/trackeval/score_benchmark.py [--commit SHA]

For each case folder ``tests/data/trackeval_benchmark/CASE/`` it hands the kept folder
``CASE/trackeval/`` to TrackEval as the documented command does (``BENCHMARK=scenegen``,
``SPLIT_TO_EVAL=all``, preprocessing on, HOTA, CLEAR and Identity; the default locations
of the seqmap and of the tracker files under the two ``mot_challenge`` folders), once with
the seqmap of every sequence and once with ``scenegen-multi.txt`` (the sequences with
several targets, which the leaderboard's "(combined)" columns take as one). It writes
``tests/data/trackeval_benchmark/oracle.json``: per case, tracker and sequence TrackEval's
HOTA, MOTA and IDF1 (and the counts behind them), and its ``COMBINED_SEQ`` row of each
seqmap (``combined_all``, ``combined_multi``), as fractions (TrackEval prints percents).
With ``--script PATH/TO/scripts/run_mot_challenge.py`` it also runs TrackEval's command
line as the docs give it, on a copy of each kept folder (every sequence, then the
multi-target ones through ``--SEQ_INFO``), and checks that the ``COMBINED`` HOTA, MOTA and
IDF1 of each tracker's ``pedestrian_summary.txt`` (percents, 3 decimals) are those of the
API above. This script does not import scenegen.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import trackeval
from make_oracle import _trackeval_commit, _value

HERE = Path(__file__).resolve().parent
DATA = HERE.parents[1] / "tests" / "data" / "trackeval_benchmark"
FIELDS = {
    "HOTA": ["HOTA", "DetA", "AssA"],
    "CLEAR": ["MOTA", "CLR_TP", "CLR_FN", "CLR_FP", "IDSW"],
    "Identity": ["IDF1", "IDTP", "IDFN", "IDFP"],
}


def seqmap(folder: Path, split: str) -> list[str]:
    """The sequences of the seqmap ``scenegen-SPLIT.txt`` of a kept folder."""
    lines = (folder / "gt" / "mot_challenge" / "seqmaps" / f"scenegen-{split}.txt").read_text()
    return [s for s in lines.splitlines()[1:] if s]


def score(folder: Path, split: str) -> tuple[dict, dict]:
    """TrackEval's per-sequence scores and ``COMBINED_SEQ`` row of the kept ``folder``
    with the seqmap of ``split``: ({tracker: {seq: fields}}, {tracker: fields})."""
    with tempfile.TemporaryDirectory() as out:
        eval_cfg = trackeval.Evaluator.get_default_eval_config()
        eval_cfg.update(USE_PARALLEL=False, PRINT_RESULTS=False, PRINT_CONFIG=False,
                        OUTPUT_SUMMARY=False, OUTPUT_DETAILED=False, PLOT_CURVES=False,
                        TIME_PROGRESS=False, OUTPUT_EMPTY_CLASSES=False)  # fmt: skip
        data_cfg = trackeval.datasets.MotChallenge2DBox.get_default_dataset_config()
        gt = folder / "gt" / "mot_challenge"
        data_cfg.update(
            GT_FOLDER=str(gt),
            TRACKERS_FOLDER=str(folder / "trackers" / "mot_challenge"),
            OUTPUT_FOLDER=out,
            BENCHMARK="scenegen",
            SPLIT_TO_EVAL="all",
            SEQMAP_FILE=str(gt / "seqmaps" / f"scenegen-{split}.txt"),
            DO_PREPROC=True,
            PRINT_CONFIG=False,
        )
        metrics = [
            trackeval.metrics.HOTA(),
            trackeval.metrics.CLEAR({"PRINT_CONFIG": False}),
            trackeval.metrics.Identity({"PRINT_CONFIG": False}),
        ]
        dataset = trackeval.datasets.MotChallenge2DBox(data_cfg)
        res, msg = trackeval.Evaluator(eval_cfg).evaluate([dataset], metrics)
    out_res, msg = res["MotChallenge2DBox"], msg["MotChallenge2DBox"]
    table: dict = {}
    combined: dict = {}
    for tracker in sorted(out_res):
        if msg[tracker] != "Success":
            raise SystemExit(f"TrackEval failed on {folder} {tracker}: {msg[tracker]}")
        for seq, r in out_res[tracker].items():
            fields = {f: _value(m, r["pedestrian"], f) for m, fs in FIELDS.items() for f in fs}
            if seq == "COMBINED_SEQ":
                combined[tracker] = fields
            else:
                table.setdefault(tracker, {})[seq] = fields
    return table, combined


def check_command_line(script: Path, folder: Path, split: str, combined: dict) -> None:
    """Run TrackEval's ``run_mot_challenge.py`` as the docs give it on a copy of the kept
    ``folder`` (the sequences of ``split``) and check its summaries against ``combined``
    (:func:`score`'s second value); exit with a message on a difference."""
    with tempfile.TemporaryDirectory() as tmp:
        kept = Path(tmp) / "trackeval"
        shutil.copytree(folder, kept)
        cmd = [sys.executable, str(script), "--BENCHMARK", "scenegen", "--SPLIT_TO_EVAL", "all",
               "--GT_FOLDER", str(kept / "gt" / "mot_challenge"),
               "--TRACKERS_FOLDER", str(kept / "trackers" / "mot_challenge"),
               "--DO_PREPROC", "True", "--USE_PARALLEL", "False", "--PLOT_CURVES", "False",
               "--PRINT_RESULTS", "False", "--PRINT_CONFIG", "False"]  # fmt: skip
        if split != "all":
            cmd += ["--SEQ_INFO", *seqmap(folder, split)]
        subprocess.run(cmd, check=True, capture_output=True, cwd=tmp)
        for tracker, want in combined.items():
            summary = kept / "trackers" / "mot_challenge" / "scenegen-all" / tracker
            head, values = (summary / "pedestrian_summary.txt").read_text().splitlines()[:2]
            got = dict(zip(head.split(), map(float, values.split()), strict=True))
            for field in ("HOTA", "MOTA", "IDF1"):
                if abs(got[field] - 100 * want[field]) > 5e-4:
                    raise SystemExit(f"{folder} {split} {tracker}: the command line gives "
                                     f"{field} {got[field]}, the API {100 * want[field]}")


def main() -> None:
    parser = argparse.ArgumentParser(description="Score the kept tracks with TrackEval.")
    parser.add_argument("--commit", help="TrackEval commit installed (when pip copied it)")
    parser.add_argument("--out", type=Path, default=DATA / "oracle.json", help="output file")
    parser.add_argument("--script", type=Path, help="TrackEval's run_mot_challenge.py: also "
                        "check its command line")  # fmt: skip
    args = parser.parse_args()
    oracle: dict = {
        "tool": "TrackEval",
        "trackeval": args.commit or _trackeval_commit(),
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "cases": {},
    }
    for case in sorted(p for p in DATA.iterdir() if (p / "trackeval").is_dir()):
        folder = case / "trackeval"
        table, combined = score(folder, "all")
        entry = {"sequences": table, "combined_all": combined, "combined_multi": None}
        if seqmap(folder, "multi"):
            entry["combined_multi"] = score(folder, "multi")[1]
        if args.script:
            check_command_line(args.script, folder, "all", combined)
            if entry["combined_multi"]:
                check_command_line(args.script, folder, "multi", entry["combined_multi"])
            print(f"{case.name}: the command line agrees")
        oracle["cases"][case.name] = entry
    args.out.write_text(json.dumps(oracle, indent=1, sort_keys=True) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
