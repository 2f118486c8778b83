"""The ``dataset`` verb: generate a benchmark dataset from a scenario family."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from scenegen.cli.options import seed_arg

__all__ = ["cmd_dataset", "cmd_validate_dataset", "register"]


def register(sub: argparse._SubParsersAction) -> None:
    from scenegen.datasets import builtin_names

    p = sub.add_parser(
        "dataset",
        help="generate a dataset of sequences from a scenario family (sharded, resumable)",
        description="FAMILY is a family file (.yaml/.json), a built-in family ("
        + ", ".join(builtin_names())
        + ") or a preset name. Writes DIR/shard-NNNNN.h5 and DIR/manifest.json; running "
        "the same command again keeps the shards already made.",
    )
    p.add_argument("family", help="family file, built-in family or preset")
    p.add_argument("-o", "--output", type=Path, required=True, help="dataset folder DIR")
    p.add_argument("--count", type=int, default=None, help="sequences (default: the family's)")
    p.add_argument("--seed", type=seed_arg, default=None, help="base seed (default: the family's)")
    p.add_argument("--frames", type=int, default=None,
                   help="override every sequence's frame count")  # fmt: skip
    where = p.add_mutually_exclusive_group()
    where.add_argument("--jobs", type=int, default=None, help="local processes (default: all)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="dask.distributed scheduler, e.g. tcp://host:8786 (its workers "
                       "must see DIR)")  # fmt: skip
    p.add_argument("--shard-size", type=int, default=None,
                   help="sequences per shard file (default 4)")  # fmt: skip
    p.add_argument("--compression", default="gzip", help="gzip | lzf | none (default gzip)")
    p.set_defaults(func=cmd_dataset)


def cmd_dataset(args: argparse.Namespace) -> int:
    """Build the dataset and print its folder; 0 on success.

    Raises
    ------
    ConfigError
        A bad family (one line naming the file and field path), count, seed, jobs,
        shard size, or an unreachable scheduler; or DIR holds another dataset.
    """
    from scenegen.datasets import build_dataset
    from scenegen.datasets.build import DEFAULT_SHARD_SIZE

    made = [0]

    def count_made(res: dict) -> None:
        made[0] += 0 if res["reused"] else 1

    man = build_dataset(
        args.family,
        args.output,
        count=args.count,
        seed=args.seed,
        frames=args.frames,
        jobs=args.jobs,
        scheduler=args.scheduler,
        shard_size=DEFAULT_SHARD_SIZE if args.shard_size is None else args.shard_size,
        compression=args.compression,
        progress=sys.stderr.isatty(),
        on_shard=count_made,
    )
    kept = man["shards"] - made[0]
    print(
        f"dataset {man['family']}: {man['count']} sequences in {man['shards']} shards "
        f"({made[0]} made, {kept} kept); manifest: {args.output / 'manifest.json'}",
        file=sys.stderr,
    )
    print(str(Path(args.output).resolve()))
    return 0


def cmd_validate_dataset(args: argparse.Namespace) -> int:
    """``scenegen validate DIR`` on a dataset folder: 0 if valid, else 1 and one line each.

    With ``--deep`` (when the verb has it) every sequence is also generated again from its
    config and seed and compared with the manifest's digests.
    """
    from scenegen.cli.progress import bar
    from scenegen.datasets import read_manifest, validate_dataset

    try:
        shards = int(read_manifest(args.file).get("shards", 0))
    except Exception:  # reported by validate_dataset as a problem line
        shards = 0
    with bar(shards, f"validate {args.file}", unit="shard") as pb:
        problems = validate_dataset(args.file, deep=bool(getattr(args, "deep", False)),
                                    progress=lambda n: pb.update(n - pb.n))  # fmt: skip
    if problems:
        for line in problems:
            print(line, file=sys.stderr)
        return 1
    print(f"{args.file}: valid dataset")
    return 0
