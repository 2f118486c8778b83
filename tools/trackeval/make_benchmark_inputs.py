"""Write small benchmarks with kept tracks, the inputs of the benchmark TrackEval oracle.

Run with the project's environment::

    .venv/bin/python tools/trackeval/make_benchmark_inputs.py

For each case of :data:`CASES` it builds the dataset, runs ``scenegen benchmark
--keep-tracks`` on it (one process) and writes, under ``tests/data/trackeval_benchmark/CASE/``:

* ``trackeval/``: the benchmark's kept folder (tracker files, ground truth, seqmaps),
  byte for byte;
* ``benchmark.json``: what the oracle is compared with, from the benchmark's
  ``results.json``: per tracker the leaderboard's ``(combined)`` columns, per run the
  sequence's name, target count and MOTA, IDF1 and HOTA, and the ``tracks`` listing.

Then run ``tools/trackeval/score_benchmark.py`` in TrackEval's side environment; the test
``test_kept_tracks_score_as_trackeval_does`` (tests/scenegen/lab/test_benchmark.py)
compares the two, and regenerates the small cases.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "data" / "trackeval_benchmark"

TWO: dict[str, Any] = {
    "width": 64, "height": 48, "n_frames": 5,
    "entities": [
        {"name": "a", "role": "target", "position": [18, 20], "depth": 0,
         "appearance": {"shape": "ellipse", "size": [12, 12], "pattern": "sectors",
                        "colors": [[230, 30, 30], [30, 60, 230]]},
         "motion": {"x": {"sigma": 0.5, "boundary": "reflect", "margin": 1},
                    "y": {"sigma": 0.5, "boundary": "reflect", "margin": 1}}},
        {"name": "b", "role": "target", "position": [44, 28], "depth": 1,
         "appearance": {"shape": "rect", "size": [10, 10], "pattern": "checker",
                        "colors": [[30, 170, 30], [240, 210, 0]]}},
    ],
    "clutter": [{"count": 0, "appearance": {"size": [6, 6]}, "min_size": 3}],
}  # fmt: skip
"""The two-target scene of ``tests/scenegen/lab/test_benchmark.py``."""

CASES: dict[str, dict[str, Any]] = {
    # The family, trackers and parameters of test_benchmark.py (its kept fixture).
    "two": {
        "family": {"name": "two", "base": TWO, "sweep": {"clutter[0].count": [0, 8]},
                   "vary": {"entities[a].position_noise": {"uniform": [0.0, 2.0]}},
                   "count": 4},  # fmt: skip
        "trackers": ["sok", "annealed"],
        "params": {"n_particles": 16, "n_layers": 2},
    },
    # A sequence with one target (b a distractor): not in the combined columns.
    "mixed": {
        "family": {"name": "mixed", "base": TWO,
                   "sweep": {"entities[b].role": ["target", "distractor"]},
                   "vary": {"entities[a].position_noise": {"uniform": [0.0, 2.0]}},
                   "count": 2},  # fmt: skip
        "trackers": ["sok", "annealed"],
        "params": {"n_particles": 16, "n_layers": 2},
    },
    # A built-in family: seven targets and a distractor, 20 frames.
    "dps-synthetic": {
        "family": "dps-synthetic",
        "count": 3,
        "frames": 20,
        "trackers": ["sok", "kalman"],
        "params": {},
    },
}
"""Each case: a family (a mapping, or a built-in family's name, with ``count`` and
``frames``), the trackers and their parameters."""


def make_dataset(case: dict[str, Any], out: Path) -> None:
    """Build the dataset of ``case`` into the folder ``out`` (one process, shards of 3)."""
    from scenegen.datasets import build_dataset

    build_dataset(case["family"], out, jobs=1, shard_size=3, count=case.get("count"),
                  frames=case.get("frames"))  # fmt: skip


def summary(results: dict[str, Any]) -> dict[str, Any]:
    """What the oracle is compared with, from a benchmark's ``results.json``.

    Parameters
    ----------
    results : dict
        The benchmark's results (:func:`scenegen.lab.benchmark.results_document`, with
        ``tracks``).

    Returns
    -------
    dict
        ``combined`` (per tracker, the leaderboard's three ``*_combined`` values),
        ``scores`` (per run: tracker, name, targets, mota, idf1, hota) and ``tracks``.
    """
    cols = ("mota_combined", "idf1_combined", "hota_combined")
    return {
        "combined": {e["tracker"]: {c: e.get(c) for c in cols} for e in results["leaderboard"]},
        "scores": [{k: r.get(k) for k in ("tracker", "name", "targets", "mota", "idf1", "hota")}
                   for r in results["scores"]],  # fmt: skip
        "tracks": results["tracks"],
    }


def run_case(name: str, work: Path) -> dict[str, Any]:
    """Build case ``name``'s dataset and benchmark under ``work``; return the results."""
    from scenegen.lab.benchmark import run_benchmark

    case = CASES[name]
    make_dataset(case, work / "dataset")
    return run_benchmark(work / "dataset", case["trackers"], work / "benchmark",
                         params=case["params"], jobs=1, keep_tracks=True)  # fmt: skip


def main() -> None:
    for name in CASES:
        with tempfile.TemporaryDirectory() as tmp:
            results = run_case(name, Path(tmp))
            dest = OUT / name
            shutil.rmtree(dest, ignore_errors=True)
            dest.mkdir(parents=True)
            shutil.copytree(Path(tmp) / "benchmark" / "trackeval", dest / "trackeval")
        text = json.dumps(summary(results), indent=1, sort_keys=True) + "\n"
        (dest / "benchmark.json").write_text(text)
        print(f"wrote {dest}")


if __name__ == "__main__":
    main()
