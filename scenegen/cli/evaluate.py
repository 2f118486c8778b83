"""The ``evaluate`` verb: score a tracker result (scenegen .h5, MOTChallenge .txt, or a
single-object OTB / GOT-10k result with ``--format``)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from scenegen.cli.options import picked_by

__all__ = ["cmd_evaluate", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "evaluate",
        help="score a tracker result (.h5, MOTChallenge .txt, or an OTB / GOT-10k "
        "single-object .txt) against the ground truth",
    )
    p.add_argument("file", help="scenegen .h5 file holding the sequence")
    p.add_argument(
        "result",
        help="result .h5 file written by `scenegen track`, or a text result file: a "
        "MOTChallenge tracker file (default) or, with --format otb|got10k, a single-object one",
    )
    p.add_argument(
        "--format",
        choices=["mot", "otb", "got10k"],
        default=None,
        help="how to read a text result: mot (MOTChallenge tracker file, the default); otb "
        "or got10k: one x,y,w,h line per frame for one target, 1-based (otb) or 0-based "
        "(got10k), 0,0,0,0 or NaN for no box (what `export --format otb|got10k` writes)",
    )
    p.add_argument(
        "--target",
        type=int,
        default=None,
        metavar="ID",
        help="--format otb|got10k: entity id of the target the result follows (default: "
        "the sequence's only target present at frame 0)",
    )
    p.add_argument("--sequence", default=None, help="sequence name if the file holds several")
    p.add_argument("--tracker", default=None, help="tracker name if the result holds several")
    p.add_argument(
        "--gt-mode",
        choices=["amodal", "visible"],
        default="amodal",
        help="amodal: every frame a target is in the scene counts (default); visible: "
        "MOTChallenge's convention, targets with visibility <= the threshold are ignored",
    )
    p.add_argument(
        "--visibility-threshold",
        type=float,
        default=0.0,
        help="visible mode: a target counts where its visible fraction exceeds this (default 0)",
    )
    p.add_argument(
        "--otb-average",
        choices=["sequence", "frames"],
        default="sequence",
        help="overall AUC and P@20: mean over targets as OTB averages sequences (default), "
        "or pooled frames",
    )
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_evaluate)


def _is_hdf5(path: Path) -> bool:
    from scenegen.io.atomic import describe_special_file

    if describe_special_file(path) is not None:  # opening a FIFO would wait for a writer
        return False  # the MOT reader refuses it in one line
    if path.suffix.lower() in (".h5", ".hdf5"):  # even empty or damaged: never read as MOT
        return True
    try:
        with open(path, "rb") as f:
            return f.read(8) == b"\x89HDF\r\n\x1a\n"
    except OSError:  # unreadable: the MOT reader says why in one line
        return False


def _read_mot(path: Path, n_frames: int) -> tuple[Any, Any, Any]:
    """:func:`scenegen.io.mot.read_mot_tracker_rows`; a first line of 4 values (an OTB or
    GOT-10k result read as a MOTChallenge file) gets a hint to use ``--format``."""
    from scenegen.errors import DataError
    from scenegen.io.benchmarks import first_box_values
    from scenegen.io.mot import read_mot_tracker_rows

    try:
        return read_mot_tracker_rows(path, n_frames)
    except DataError as err:
        if ":1: " not in str(err) or first_box_values(path) != 4:
            raise
        raise DataError(
            f"{err}; a single-object result (x,y,w,h per frame)? read it with --format otb "
            "(1-based) or got10k (0-based)"
        ) from None


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Print the metrics of ``args.result`` on ``args.file``; 0 on success.

    Raises
    ------
    DataError
        If either file is invalid, or the result does not fit the sequence (frame count,
        target count or ids), naming the mismatch and the files.
    ConfigError
        If ``--tracker`` is given with a text result file, ``--target`` with anything but
        ``--format otb|got10k`` (either would be ignored), ``--format`` with an HDF5
        result, or ``--target`` is missing or not a target present at frame 0.
    """
    from scenegen.errors import ConfigError, DataError
    from scenegen.evaluation.evaluate import (
        check_options,
        evaluate,
        evaluate_target,
        evaluate_tracks,
        format_table,
        pick_target,
    )
    from scenegen.io import read, read_result
    from scenegen.io.validate import require_valid

    require_valid(args.file)  # no computing on a damaged or inconsistent file
    check_options(args.gt_mode, args.visibility_threshold, args.otb_average)
    with picked_by("--sequence"):
        seq = read(args.file, args.sequence)
    options = {
        "gt_mode": args.gt_mode,
        "visibility_threshold": args.visibility_threshold,
        "otb_average": args.otb_average,
    }
    result = Path(args.result)
    fmt = args.format
    if args.target is not None and fmt not in ("otb", "got10k"):  # it would be ignored
        raise ConfigError(
            "--target applies to a single-object result (--format otb or got10k); leave it out"
        )
    if not _is_hdf5(result):
        what = {"otb": "an OTB result file", "got10k": "a GOT-10k result file"}.get(
            fmt or "mot", "a MOTChallenge tracker file"
        )
        if args.tracker is not None:  # it would be ignored: a text file holds one tracker
            raise ConfigError(f"--tracker does not apply to {what} ({result}); leave it out")
        if fmt in ("otb", "got10k"):
            from scenegen.io.benchmarks import read_benchmark_result

            target = pick_target(seq, args.target, "--target")
            boxes = read_benchmark_result(result, seq.n_frames, fmt)
            report = evaluate_target(seq, boxes, target, tracker=result.stem, **options)
        else:
            ids, tracks, rank = _read_mot(result, seq.n_frames)
            report = evaluate_tracks(seq, tracks, ids, tracker=result.stem, rank=rank, **options)
        print(report.to_json() if args.json else format_table(report))
        return 0
    if fmt is not None:
        raise ConfigError(
            f"--format {fmt} reads a text result file, but {result} is an HDF5 result "
            "file; leave --format out"
        )
    require_valid(result)
    with picked_by("--tracker"):
        res = read_result(result, args.tracker)
    if res.sequence and res.sequence != seq.name:
        raise DataError(
            f"{args.result}: result is for sequence {res.sequence!r}, but {args.file} holds "
            f"{seq.name!r}"
        )
    try:
        report = evaluate(
            seq,
            res.boxes,
            res.target_ids,
            tracker=res.tracker,
            order_prob=res.order_prob,
            orderings=res.orderings,
            **options,
        )
    except DataError as err:
        raise DataError(f"{args.result} does not match {args.file}: {err}") from None
    print(report.to_json() if args.json else format_table(report))
    return 0
