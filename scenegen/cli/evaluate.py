"""The ``evaluate`` verb: score a tracker result (scenegen .h5 or MOTChallenge .txt)."""

from __future__ import annotations

import argparse
from pathlib import Path

from scenegen.cli.options import picked_by

__all__ = ["cmd_evaluate", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "evaluate",
        help="score a tracker result (.h5 or MOTChallenge .txt) against the ground truth",
    )
    p.add_argument("file", help="scenegen .h5 file holding the sequence")
    p.add_argument(
        "result",
        help="result .h5 file written by `scenegen track`, or a MOTChallenge tracker .txt file",
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


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Print the metrics of ``args.result`` on ``args.file``; 0 on success.

    Raises
    ------
    DataError
        If either file is invalid, or the result does not fit the sequence (frame count,
        target count or ids), naming the mismatch and the files.
    ConfigError
        If ``--tracker`` is given with a MOTChallenge tracker file (it would be ignored).
    """
    from scenegen.errors import ConfigError, DataError
    from scenegen.evaluation.evaluate import (
        check_options,
        evaluate,
        evaluate_tracks,
        format_table,
    )
    from scenegen.io import read, read_result
    from scenegen.io.mot import read_mot_tracker_rows
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
    if not _is_hdf5(result):
        if args.tracker is not None:  # it would be ignored: a tracker file holds one tracker
            raise ConfigError(
                f"--tracker does not apply to a MOTChallenge tracker file ({result}); leave "
                "it out"
            )
        ids, boxes, rank = read_mot_tracker_rows(result, seq.n_frames)
        report = evaluate_tracks(seq, boxes, ids, tracker=result.stem, rank=rank, **options)
        print(report.to_json() if args.json else format_table(report))
        return 0
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
