"""The ``evaluate`` verb: score a tracker result file against its sequence."""

from __future__ import annotations

import argparse

__all__ = ["cmd_evaluate", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("evaluate", help="score a tracker result against the ground truth")
    p.add_argument("file", help="scenegen .h5 file holding the sequence")
    p.add_argument("result", help="result .h5 file written by `scenegen track`")
    p.add_argument("--sequence", default=None, help="sequence name if the file holds several")
    p.add_argument("--tracker", default=None, help="tracker name if the result holds several")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_evaluate)


def cmd_evaluate(args: argparse.Namespace) -> int:
    """Print the metrics of ``args.result`` on ``args.file``; 0 on success.

    Raises
    ------
    DataError
        If either file is invalid, or the result does not fit the sequence (frame count,
        target count or ids), naming the mismatch and the files.
    """
    from scenegen.errors import DataError
    from scenegen.evaluation.evaluate import evaluate, format_table, to_json
    from scenegen.io import read, read_result
    from scenegen.io.validate import require_valid

    require_valid(args.file)  # no computing on a damaged or inconsistent file
    require_valid(args.result)
    seq = read(args.file, args.sequence)
    res = read_result(args.result, args.tracker)
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
        )
    except DataError as err:
        raise DataError(f"{args.result} does not match {args.file}: {err}") from None
    print(to_json(report) if args.json else format_table(report))
    return 0
