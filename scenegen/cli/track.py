"""The ``track`` verb: run a tracker over a sequence and write a result file."""

from __future__ import annotations

import argparse
import json
from typing import Any

from scenegen.cli.progress import bar
from scenegen.errors import ConfigError

__all__ = ["parse_params", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("track", help="run a tracker over a sequence, write a result file")
    p.add_argument("file", help="scenegen .h5 file")
    p.add_argument("--tracker", required=True, help="tracker name (see trackers.names())")
    p.add_argument("--seed", type=int, default=0, help="tracker random seed (default 0)")
    p.add_argument(
        "--param", action="append", default=[], metavar="KEY=VALUE",
        help="tracker parameter; VALUE is read as JSON when it parses, else as a string",
    )  # fmt: skip
    p.add_argument("--sequence", default=None, help="sequence name if the file holds several")
    p.add_argument("-o", "--output", required=True, help="result .h5 file")
    p.set_defaults(func=cmd_track)


def parse_params(items: list[str]) -> dict[str, Any]:
    """``["n_particles=300", "model=hsv"]`` -> ``{"n_particles": 300, "model": "hsv"}``."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise ConfigError(f"--param must be KEY=VALUE, got {item!r}")
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out


def cmd_track(args: argparse.Namespace) -> int:
    from scenegen.io import read, write_result
    from scenegen.io.validate import require_valid
    from scenegen.lab.run import run_tracker

    if args.seed < 0:
        raise ConfigError(f"--seed must be >= 0, got {args.seed}")
    params = parse_params(args.param)
    require_valid(args.file)  # no computing on a damaged or inconsistent file
    seq = read(args.file, args.sequence)
    with bar(seq.n_frames - 1, f"track {args.tracker}", unit="frame") as pb:
        res = run_tracker(seq, args.tracker, params, args.seed, progress=lambda n: pb.update(1))
    if hasattr(seq.frames, "close"):
        seq.frames.close()
    write_result(args.output, res)
    print(f"wrote {args.output} ({args.tracker}, {res.boxes.shape[1]} targets)")
    return 0
