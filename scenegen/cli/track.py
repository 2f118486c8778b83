"""The ``track`` verb: run a tracker over a sequence and write a result file."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
from typing import Any

from scenegen.cli.options import picked_by, seed_arg
from scenegen.cli.progress import bar
from scenegen.errors import ConfigError

__all__ = ["check_writable", "parse_params", "register"]


def _tracker_names() -> list[str]:
    import trackers

    return trackers.names()


def register(sub: argparse._SubParsersAction) -> None:
    names = ", ".join(_tracker_names())
    p = sub.add_parser(
        "track",
        help="run a tracker over a sequence, write a result file",
        description="Run a tracker over a sequence (its targets present at frame 0, started "
        "from their ground-truth boxes) and write a result file.",
        epilog=f"trackers: {names}; or MODULE:FACTORY (or FILE.py:FACTORY), a callable "
        "returning an object with init(frame, boxes) and step(frame) -> .boxes",
    )
    p.add_argument("file", help="scenegen .h5 file")
    p.add_argument(
        "--tracker", required=True, metavar="NAME|MODULE:FACTORY",
        help=f"one of: {names}; or a user's factory MODULE:FACTORY",
    )  # fmt: skip
    p.add_argument("--seed", type=seed_arg, default=0, help="tracker random seed (default 0)")
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


def check_writable(path: str | Path) -> None:
    """Raise ConfigError naming ``path`` if a file cannot be written there (missing or
    unwritable folder, or a folder in the way)."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if target.is_dir():
        raise ConfigError(f"{target}: cannot write the output: it is a directory")
    if not folder.is_dir():
        raise ConfigError(f"{target}: cannot write the output: no folder {folder}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ConfigError(f"{target}: cannot write the output: folder {folder} is not writable")


def cmd_track(args: argparse.Namespace) -> int:
    from scenegen.cli.data import _refuse_replacing_input
    from scenegen.io import read, write_result
    from scenegen.io.validate import require_valid
    from scenegen.lab.run import run_tracker, tracker_label

    params = parse_params(args.param)
    _refuse_replacing_input(Path(args.file), Path(args.output))  # the result would replace it
    require_valid(args.file)  # no computing on a damaged or inconsistent file
    check_writable(args.output)
    with picked_by("--sequence"):
        seq = read(args.file, args.sequence)
    label = tracker_label(args.tracker)
    with bar(seq.n_frames - 1, f"track {label}", unit="frame") as pb:
        res = run_tracker(seq, args.tracker, params, args.seed, progress=lambda n: pb.update(1))
    if hasattr(seq.frames, "close"):
        seq.frames.close()
    try:
        write_result(args.output, res)
    except OSError as err:
        raise ConfigError(
            f"{args.output}: cannot write the output: {err.strerror or err}"
        ) from None
    print(f"wrote {args.output} ({label}, {res.boxes.shape[1]} targets)")
    return 0
