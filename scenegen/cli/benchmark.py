"""The ``benchmark`` verb: run trackers over a dataset; leaderboard and difficulty curves."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["cmd_benchmark", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "benchmark",
        help="run trackers over a dataset: per-sequence scores, leaderboard, curves",
        description="Runs every --tracker on every sequence of the dataset DIR (made by "
        "`scenegen dataset`) and writes OUT/index.html (leaderboard and metric-vs-difficulty "
        "figures), OUT/results.json and OUT/scores.csv. Finished runs are kept under "
        "OUT/runs/; running the same command again resumes.",
    )
    p.add_argument("dataset", type=Path, help="dataset folder DIR")
    p.add_argument("--tracker", action="append", required=True, metavar="NAME",
                   help="tracker name, or a user's factory MODULE:FACTORY or "
                   "path/to/file.py:FACTORY (repeatable; see trackers in the README)")  # fmt: skip
    p.add_argument(
        "--param", action="append", default=[], metavar="KEY=VALUE",
        help="tracker parameter given to every tracker that takes it (e.g. n_particles=100); "
        "VALUE is read as JSON when it parses",
    )  # fmt: skip
    where = p.add_mutually_exclusive_group()
    where.add_argument("--jobs", type=int, default=None, help="local processes (default: all)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="dask.distributed scheduler, e.g. tcp://host:8786 (its workers "
                       "read DIR; this process writes OUT)")  # fmt: skip
    p.add_argument("-o", "--output", type=Path, required=True, help="output folder OUT")
    p.add_argument("--keep-tracks", action="store_true",
                   help="also write OUT/trackeval/: every tracker's output as MOTChallenge "
                   "tracker files and the dataset's ground truth (amodal), laid out for "
                   "TrackEval's run_mot_challenge.py (see docs/evaluation.md); on an OUT "
                   "made without it, runs the finished pairs again for their tracks")  # fmt: skip
    p.set_defaults(func=cmd_benchmark)


def cmd_benchmark(args: argparse.Namespace) -> int:
    """Run the benchmark and print the report page's path; 0 on success.

    Raises
    ------
    ConfigError
        Unknown tracker or parameter, bad --jobs, unreachable scheduler, incomplete dataset.
    DataError
        DIR is not a dataset folder, or a shard is damaged.
    """
    from scenegen.cli.track import parse_params
    from scenegen.lab.benchmark import NONE_SCORED, run_benchmark, scored

    res = run_benchmark(
        args.dataset,
        args.tracker,
        args.output,
        params=parse_params(args.param),
        jobs=args.jobs,
        scheduler=args.scheduler,
        progress=sys.stderr.isatty(),
        keep_tracks=args.keep_tracks,
    )
    board = res["leaderboard"]
    if not scored(board):
        print(f"benchmark: {len(res['scores'])} runs; {NONE_SCORED}", file=sys.stderr)
    elif board[0]["auc"] is None:
        print(f"benchmark: {len(res['scores'])} runs; no AUC was computed", file=sys.stderr)
    else:
        print(f"benchmark: {len(res['scores'])} runs; best AUC {board[0]['tracker']} "
              f"({board[0]['auc']})", file=sys.stderr)  # fmt: skip
    print(str((args.output / "index.html").resolve()))
    return 0
